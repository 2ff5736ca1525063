// voxpress/smooth/pressing.h — constrained bilaplacian smoothing on axis
// slices (Pressing, Chica et al., Section 4).
//
// Every vertex slides along its stick only, t in [margin, 1 - margin], so the
// surface becomes smooth yet can never cross a lattice sample: a triangle
// whose corners lie inside the edges of one cell cannot contain a cell
// corner, so no sample's winding number changes while vertices move.
//
// The 3D smoothing is decomposed into curve smoothing on the lattice planes
// (Section 4, Fig. 3): the surface meets each lattice plane in closed
// polylines whose vertices are the plane's sticks (SliceCurves, built once).
// One application of the map T computes, on every curve and for every fresh
// vertex C:
//   virtual neighbours C-, C+ at arc length d on either side (Fig. 6),
//   L(C) = (C- + C+) / 2 - C, then L^2(C) = L(C) - (L(C-) + L(C+)) / 2 with
//   L interpolated at the virtual points (Fig. 4, Eq. 1, two passes),
//   the displacement s^2 L^2(C) projected onto the stick's line;
// each stick lies in two planes, so it gets two proposals, which are averaged
// (equal weights by default) before the clamp to [margin, 1 - margin].
// The press approaches the fixed point t* = T(t*) (frozen vertices kept):
// coarse-to-fine stages with momentum, then the map at d until its residual
// max |T(t) - t| is at most PressOptions::tolerance or the sweeps run out
// (src/smooth/solver.cpp; PressStats::residual says how close it came).
// Every sweep is simultaneous (Jacobi), so the result does not depend on
// the order or the thread count; positions are relative to the sticks'
// box, so it does not depend on where the volume lies either.
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/progress.h"
#include "voxpress/extract/sticks.h"

namespace voxpress {

/// The lattice-plane cuts of a stick surface, as closed polylines of stick ids.
/// Each stick lies in exactly two planes (those whose normal axis differs
/// from its own), so it belongs to exactly two curves.
struct SliceCurves {
  /// Curves of plane family `a` (planes normal to axis a): curve c of
  /// family a holds sticks ids[a][offsets[a][c] .. offsets[a][c + 1]), in
  /// order along the curve; the last joins the first. Sorted by plane coordinate.
  std::vector<uint32_t> ids[3];
  std::vector<uint32_t> offsets[3];
  size_t curve_count() const { return offsets[0].size() + offsets[1].size() + offsets[2].size() - 3; }
  /// Which of the two curves of a stick along axis `axis` the curve of
  /// family `a` is: 0 for the lower of its two families, 1 for the other.
  static int slot(int a, int axis) { return a < 3 - a - axis ? 0 : 1; }
};

/// Builds the slice curves from the surface's triangles (a triangle edge whose
/// two sticks share a lattice plane is a segment of that plane's cut). Throws
/// std::logic_error if a stick does not have two neighbours in a plane
/// (impossible for surfaces from extract_sticks).
SliceCurves build_slice_curves(const StickSurface& surface);

struct PressOptions {
  /// Sweeps (all stages; chosen by measurement: docs/BENCHMARKS.md).
  int iterations = 100;
  /// Stop once the residual of the map at d, max |T(t) - t| (a fraction
  /// of the stick), is at most this (checked in the last stage).
  double tolerance = 1e-4;
  double step = 0.85;          ///< s in C'' = C + s^2 L^2(C) (paper: 0.85)
  double arc_length = 0.75;    ///< d, in cells of the curve's plane (paper: 0.75)
  double margin = 0.01;        ///< t is kept in [margin, 1 - margin]
  /// How the two proposals of a stick are combined (paper, Section 4):
  /// equal weights, or weights proportional to |stick . curve normal| or to
  /// |stick . curve tangent| in each plane.
  enum class Weighting { equal, normal, tangent } weighting = Weighting::equal;
  /// Beyond the paper — acceleration (docs/BENCHMARKS.md has the measurements):
  /// coarse-to-fine: the sweeps are split evenly into `levels` stages with
  /// d multiplied by 2^(levels - 1), ..., 2, 1 (1: the paper's single d).
  /// 0 = by the surface's extent E, the longest side of its bounding box in
  /// cells: 2 stages while E < 192, one more each time E doubles (3 up to
  /// 383, 4 up to 767, ...), so the coarsest d spans about the same share of
  /// the solid at every resolution (measured: docs/BENCHMARKS.md, Pressing,
  /// Levels by extent);
  int levels = 0;
  /// heavy-ball momentum: each update adds momentum times the vertex's
  /// previous change of t (0: the paper's plain iteration).
  double momentum = 0.8;
  /// Arc-length resampling (paper, Fig. 5-6). false: the plain bilaplacian of
  /// the actual curve neighbours, kept to reproduce Fig. 5's comparison.
  bool resample = true;
  /// Beyond the paper (Section 4, Fig. 7: junction-aware smoothing): an
  /// open piece of curve between two barrier vertices (frozen flat vertices
  /// next to a junction) is smoothed without them, its ends free: a virtual
  /// neighbour past an end is the point as far back from the end, reflected
  /// through it. So the curved side of a sharp crease follows its own shape
  /// up to the crease instead of being pulled towards the flat's corner.
  /// Pieces with fewer than 7 vertices between their barriers (a thin
  /// wall's rim, a small hole) keep the barriers as fixed ends, as do all
  /// pieces when false. press_with_flats turns it off for its estimates
  /// (with free ends the estimates find other flats and the CAD part's sharp
  /// edges get worse: `bench/press_eval cad-part 128 N`; the gain of free ends
  /// in the final press: the `free-ends` row of build/bench/bench_ablation).
  bool free_ends = true;
  /// Beyond the paper: the circle correction, in degrees (0: the paper's
  /// bilaplacian). The bilaplacian is not zero on a circle: it moves a
  /// circle of radius R inwards by about s^2 d^4 / (4 R^3) per iteration,
  /// so tight curves end pressed against the inner ends of their sticks
  /// (a disk of radius 9.3 pixels: mean radius 0.09 px short; 0.01 px long
  /// with the correction). Each vertex's own Laplacian is scaled by
  /// cos(theta), theta the angle between its chords to its two virtual
  /// neighbours (at most this cap), which makes circles of radius above
  /// d / sin(cap) fixed points and leaves straight stretches to the paper's
  /// iteration. Measured: docs/BENCHMARKS.md, Pressing, Iterations
  /// (`bench/press_eval sphere 128 1 --circle-correction DEG`).
  /// Values outside [0, 90] are clamped to it. The CLI accepts [0, 45]: at
  /// staircase and crease corners the chords turn 45 degrees or more, and
  /// only the uncorrected operator removes those.
  double circle_correction = 12;
  Progress* progress = nullptr;
};

struct PressStats {
  int iterations = 0;              ///< sweeps run (all stages)
  int levels = 0;                  ///< coarse-to-fine stages used (PressOptions::levels resolved)
  double residual = 0;             ///< max |T(t) - t| of the map at d at the result, a fraction of the stick
  double least_residual = 0;       ///< the smallest residual met in the last stage
  size_t curves = 0, fresh = 0, frozen = 0;
  double seconds = 0;
};

/// Smooths the surface in place (its t values). Vertices whose `frozen` flag
/// is set (frozen.size() == stick_count(); empty = none) never move; curves
/// pass through them as fixed points. `barrier` vertices (a subset of the
/// frozen ones; empty = none) additionally cut the curves: a curve through
/// barriers is smoothed as open pieces ending at them, so no virtual
/// neighbour is taken across a barrier (used at sharp features).
PressStats press(StickSurface& surface, const SliceCurves& curves, const PressOptions& options = {},
                 const std::vector<uint8_t>& frozen = {}, const std::vector<uint8_t>& barrier = {});

/// Convenience: builds the curves and presses.
PressStats press(StickSurface& surface, const PressOptions& options = {});

/// PressOptions::levels resolved for this surface (0: by its extent).
int press_levels(const StickSurface& surface, int requested);
/// The same for a surface whose sticks' samples span `extent` cells along
/// their longest side (what press_levels measures).
int press_levels_for_extent(int requested, int64_t extent);

/// Beyond the paper: a local quadric fit after pressing. The bilaplacian's
/// fixed points are not circles, so tight curves stay pressed towards the
/// inner ends of their sticks (a cylinder of radius 4 cells at 128^3: 0.03
/// voxel inwards, 0.066 RMS). Each fresh vertex (`region` < 0 and no
/// `junction` flag; empty vectors: every vertex) is a site or next to one
/// (sites chosen by priorities that only each vertex's neighbourhood
/// decides, so neither the lattice's placement nor the stick order does).
/// Each site gets the quadric height field of the fresh vertices within
/// `rings` rings of it, trusted when its RMS residual is at most `residual`
/// cells, refitted so that each of those vertices' stick samples lies at
/// least `stab_eps` cells on its side (inside below, outside above); each
/// fresh vertex moves to the mean of where its stick leaves the solids of
/// the trusted sites' quadrics within two rings, t kept in [margin, 1 -
/// margin] (so, as in pressing, no sample changes side). All vertices are
/// fitted from the pressed positions (Jacobi: the result does not depend on
/// the order or the thread count).
/// Measured: the `quadric-fit` row of build/bench/bench_ablation
/// (docs/BENCHMARKS.md, Ablation).
struct QuadricFitOptions {
  int rings = 5;            ///< the fit's neighbourhood (0: no fit)
  double residual = 0.08;   ///< cells: largest RMS residual of a trusted fit
  double stab_eps = 0.03;   ///< cells: how far each stick sample stays on its side of the fit
  double margin = 0.01;     ///< t kept in [margin, 1 - margin]
};

struct QuadricFitStats {
  size_t fitted = 0;  ///< vertices with a trusted quadric around
  size_t moved = 0;   ///< of those, vertices that moved
  double seconds = 0;
};

/// `only` (optional, per stick): the vertices that may move; only the
/// sites they read are fitted (a label's part of a shared
/// surface, shared_fit.h). The result is the same for them as without.
QuadricFitStats fit_local_quadrics(StickSurface& surface, const std::vector<int32_t>& region,
                                   const std::vector<uint8_t>& junction, const QuadricFitOptions& options = {},
                                   const std::vector<uint8_t>* only = nullptr);

// ----------------------------------------------------------------- 2D
/// A binary image's contours, pressed: the 2D counterpart, through the same
/// curve kernel. Pixels are samples at integer (x, y), y down; outside the
/// image is background.
struct Contours2D {
  int64_t width = 0, height = 0;
  std::vector<uint8_t> inside;                 ///< width * height, row-major
  // One vertex per stick (an edge between two differing pixels, the image
  // padded by one background pixel); vertex v at lower + t * e_axis.
  std::vector<std::array<int64_t, 2>> lower;
  std::vector<uint8_t> axis;                   ///< 0: along x, 1: along y
  std::vector<double> t;
  std::vector<uint32_t> ids, offsets;          ///< closed curves (CSR), inside on the left
  std::array<double, 2> position(size_t v) const;
};

/// Marching-squares contours of a binary image (square_case: the same rule as 3D).
Contours2D extract_contours(int64_t width, int64_t height, std::vector<uint8_t> inside);
/// Presses the contours in place (each vertex lies on one curve only).
PressStats press(Contours2D& contours, const PressOptions& options = {});

}  // namespace voxpress
