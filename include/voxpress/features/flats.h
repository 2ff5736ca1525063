// voxpress/features/flats.h — flats by plane voting (max tiles) and junction
// points (Pressing, Chica et al., Section 3), and the Pressing pipeline that
// uses them (Section 4, last paragraph).
//
// A flat is a plane together with a connected set of sticks it stabs (a
// plane stabs a stick when it separates the stick's two samples). Its
// vertices are frozen where the plane crosses their sticks, strictly inside
// them, so the in/out guarantee is kept. Detection:
//
//  1. Estimate. The surface is pressed once without flats; its vertices and
//     normals are the local estimate (Pressing's are ~0.5 deg accurate, the
//     midpoint surface's 20 deg, which would force wide vote cones).
//  2. Vote. Every vertex whose normal agrees with its neighbours' within
//     `cone` votes for the plane cells (direction cell, offset bin) near its
//     normal: directions on an equal-angle cube map (no pile-up at poles),
//     offsets in bins of one cell. Votes are sorted into an accumulator.
//  3. Grow, greedily from the best cell (Section 3: "repeat by removing the
//     sticks of previous planes"): the cell's voters seed a cluster; the
//     cluster grows over surface edges to every unassigned stick whose
//     estimated vertex lies within `tolerance` of the plane and which the
//     plane stabs, or misses by at most 5 % of the stick (a row of sticks
//     the current plane just misses would otherwise cut the face in bands;
//     the refit below must then stab them all); the plane is
//     refitted (below) and the growth repeated until it stops. A cluster is a
//     flat if its area is at least `min_area`, its width at least
//     `min_width`, its normals' median angle to the plane's at most
//     `max_spread` and their linear trend across it at most `max_bend`
//     (these reject the strips where a plane is tangent to a curved surface),
//     and, beyond the paper, if no quadric fitted to its neighbourhood stabs
//     more than `curved_gain` times as many of the neighbourhood's sticks as
//     the plane (a strip of a curved face the estimate could not reveal).
//     The sticks of a flat leave the accumulator; the next best cell follows.
//  4. Refine. The best-fitting plane (least squares of the cluster's
//     estimated vertices) among those that stab every cluster stick with the
//     margin: a minimum-norm point of a polytope in 3 unknowns (Seidel's LP
//     method). When no plane stabs them all, the members the current plane
//     misses leave the cluster and the plane moves from the current one
//     towards the least-squares one as far as feasibility allows (an exact
//     line search: the constraints are linear in (n, c)).
//  5. Rim. The flat finally takes the stabbed sticks within `rim_rings`
//     surface edges of its core, so it reaches its edges, where the estimate
//     was rounded. Beyond the paper, once the junctions are known, the rim
//     is taken back next to smooth borders onto a tangent curved face
//     (`rim_tangent_angle`), where it had run onto a fillet.
//  6. Merge (beyond the paper). Two adjacent flats whose normals are within
//     `merge_angle` become one when a single plane stabs both cores and 90 %
//     of their members (one face the growth took in two pieces).
//  7. Crease refit (beyond the paper, final pass). Each plane must also keep
//     the samples along its sharp creases on their side (inside samples of
//     a convex crease inside every plane there, an outside sample outside
//     the one plane it is not clearly inside of; concave the reverse); a
//     plane that does not is refitted with them as one-sided constraints.
//     This pins the tilt of faces nearly containing a lattice axis, which
//     their own sticks leave loose. With `center_planes`, every plane is
//     then moved to the centre of its feasible set (members and crease
//     samples), not left where the least squares of the estimate put it.
//
// Junctions (Section 3): for an edge joining a frozen vertex of flat F and a
// fresh vertex V, the normal of the least-squares plane of the fresh vertices
// in V's 2-ring is compared with F's normal; above `junction_angle` V is a
// junction (the edge crosses a sharp feature); so is a fresh vertex with
// fewer than three fresh vertices in its 2-ring (squeezed between flats,
// whatever the angle). Beyond the paper, a would-be junction whose curved
// side fits a quadric whose normal at the flat is the flat's is a tangent
// border (a fillet), not a junction. Frozen vertices next to a junction along a slice
// curve become barriers: the smoothing cuts the curves there, so no virtual
// neighbour is taken across the sharp feature (the open pieces keep a
// clamped bilaplacian; the paper's Fig. 7 alignment was tried and dropped:
// it never converged, docs/BENCHMARKS.md, Flats and junctions). Instead,
// beyond the paper, fit_creases places the
// fresh vertices near a junction from a quadric fitted to the curved side
// farther away, extrapolated up to the flat, and fit_curved_creases places
// the creases between two curved faces from quadrics fitted on both sides,
// those vertices also cutting the slice curves (press_with_flats alternates
// both with short presses of the rest).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/features/passes.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress {

struct FlatOptions {
  double min_area = 100;       ///< smallest flat, in cell areas (index space)
  double junction_angle = 30;  ///< degrees between a flat and its curved neighbour above which their border is sharp (paper: 30)
  double margin = 0.01;        ///< frozen t kept in [margin, 1 - margin]
  PassSet passes;              ///< the layer's passes (voxpress/features/passes.h)
  Progress* progress = nullptr;
};

struct Flat {
  Vec3 normal{0, 0, 1};  ///< unit, outward, physical frame: the plane is normal . x = offset
  double offset = 0;
  Vec3 index_normal{0, 0, 1};  ///< the same plane in index space (unit in index space)
  double index_offset = 0;
  size_t sticks = 0;       ///< sticks frozen on the plane
  double area = 0;         ///< physical area of the flat's vertices' share of the surface
  double area_cells = 0;   ///< the same in cell areas (index space)
};

struct FlatStats {
  size_t votes = 0, voters = 0, cells = 0, tried = 0;
  size_t junctions = 0, barriers = 0;
  size_t rim_released = 0;  ///< rim members given back to a tangent curved side (rim_tangent_angle; last pass)
  double seconds_estimate = 0, seconds_detect = 0, seconds_junctions = 0;
  size_t crease_vertices = 0;  ///< vertices fit_creases placed (last round)
  size_t curved_crease_vertices = 0;  ///< vertices fit_curved_creases placed (last round)
  double seconds_creases = 0;  ///< all rounds of fit_creases and fit_curved_creases
  /// Stage::detect's passes and rules (flats ... rim-tangent): what each
  /// changed in the last detection (cores refit, flats refused or merged,
  /// borders judged smooth, junction planes, planes refit or centred, rim
  /// vertices given back), the seconds of every detection, and the trace.
  PassTimes passes;
};

/// The segmentation of a stick surface into flats and the curved rest.
struct FlatSegmentation {
  std::vector<Flat> flats;
  std::vector<int32_t> region;     ///< per stick: flat id, or -1 (curved)
  std::vector<double> t;           ///< per stick: the frozen t on its flat (NaN when curved)
  std::vector<uint8_t> junction;   ///< per stick: fresh vertex at a sharp flat border
  std::vector<uint8_t> barrier;    ///< per stick: frozen vertex where slice curves are cut
  FlatStats stats;
  size_t frozen_count() const;
};

/// Detects flats and junctions. `estimate` holds one t per stick (a pressed
/// copy of the surface); the surface's own t are not used.
FlatSegmentation find_flats(const StickSurface& surface, const SliceCurves& curves, const std::vector<double>& estimate,
                            const FlatOptions& options = {});

/// Sets the frozen vertices of `surface` on their flats and every fresh
/// vertex to t = 0.5: the "midpoint + tiles" surface of Table 2.
void apply_flats(StickSurface& surface, const FlatSegmentation& flats);

/// Beyond the paper: places the fresh vertices within `crease_rings` rings of
/// a junction at the crossing of their stick with the piecewise surface
/// there: the flat's plane and a quadric fitted to the fresh vertices just
/// beyond (the curved side extrapolated), nearest the inside sample at a
/// convex edge, farthest at a concave one. Returns how many moved; `zone`
/// (optional) flags them.
size_t fit_creases(StickSurface& surface, const FlatSegmentation& flats, const FlatOptions& options,
                   std::vector<uint8_t>* zone = nullptr);

/// Beyond the paper: places the curved vertices of creases between two
/// curved faces (a band where the normals turn fast, whose two sides fit
/// quadrics meeting at `junction_angle` or more) where their sticks leave
/// the two quadrics' solid; vertices already `fixed` (the flat crease zone)
/// and junctions are left alone. Flags the placed ones in `fixed` and, when
/// given, in `placed`; returns how many.
size_t fit_curved_creases(StickSurface& surface, const FlatSegmentation& flats, const FlatOptions& options,
                          std::vector<uint8_t>& fixed, std::vector<uint8_t>* placed = nullptr);

struct FeaturePressStats {
  PressStats press;  ///< the final press (seconds 0 when it is the first estimate, kept)
  FlatStats flats;
  PassTimes passes;  ///< the detection's and the crease rounds' passes (press time), with their counts and trace
};

/// The flats and junctions of `surface` from its estimates (the first half
/// of press_with_flats: press a copy, detect, press again with the flats
/// frozen, detect); the surface is not changed. Its first estimate is
/// shorter than press_with_flats' (which may keep it as the final press):
/// it only has to show the flats.
FlatSegmentation segment_flats(const StickSurface& surface, const SliceCurves& curves, const PressOptions& options,
                               const FlatOptions& flat_options);

/// The whole Pressing pipeline: estimate (press a copy), find flats and
/// junctions, freeze, press the fresh vertices with barriers. Without flats
/// (flat_options == nullptr) it is press() alone. `segmentation` (optional)
/// receives the flats.
FeaturePressStats press_with_flats(StickSurface& surface, const SliceCurves& curves, const PressOptions& options,
                                   const FlatOptions* flat_options, FlatSegmentation* segmentation = nullptr);

/// Per-vertex outputs for the mesh of `surface` (vertex s = stick s):
/// "region" (int32: flat id, -1 curved) and "junction" (uint8) attributes,
/// and, when `colors`, a colour per region (curved grey, junctions orange).
void add_region_attributes(Mesh& mesh, const FlatSegmentation& flats, bool colors);

/// The preview colour of a region: a distinct hue per flat id, grey for
/// curved (-1), orange for junctions.
std::array<uint8_t, 4> region_color(int32_t region, bool junction);

}  // namespace voxpress
