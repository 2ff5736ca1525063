// Private helper of fit_creases (press time) and of sharpen's final crease fit:
// where the sticks near a sharp flat/curved border leave the piecewise solid
// of the flat's half-space and the curved side's quadric (index space).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "smooth/surface_graph.h"
#include "voxpress/core/types.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/features/flats.h"

namespace voxpress::detail {

struct CreaseFit {
  int rings;            // the zone: curved vertices up to this many rings (over curved vertices) from a junction
  int fit_rings;        // the quadric's points: curved vertices beyond the zone, within rings + fit_rings of the vertex
  double residual;      // largest RMS residual of a trusted fit (cells)
  double margin;        // t kept in [margin, 1 - margin]
  double max_move = 1;  // farthest a vertex may move along its stick (cells; 1: no limit)
};

// The zone's new stick parameters (from the inside sample, 0, to the outside
// one, 1), in vertex order: sticks = the surface whose sticks the vertices
// lie on, region = flat id or -1 per vertex, junction = junction flags, x =
// positions (index space), off / adj = the vertex adjacency. A junction is
// a curved vertex with a junction flag and a flat neighbour; each zone
// vertex takes the flat of the junction it was reached from.
std::vector<std::pair<uint32_t, double>> crease_targets(const StickSurface& sticks, const std::vector<Flat>& flats,
                                                        const std::vector<int32_t>& region,
                                                        const std::vector<uint8_t>& junction,
                                                        const std::vector<Vec3>& x, const std::vector<uint32_t>& off,
                                                        const std::vector<uint32_t>& adj, const CreaseFit& c);

// Beyond the paper: creases between two curved faces (the fandisk's
// curved/curved edges; the paper's sharpening only knows flat borders).
// A curved vertex is in the crease band when its normal and a curved
// neighbour's differ by `band_angle` or more (fandisk 128: the band
// vertices within a voxel of an unlabelled crease have p10 17.8, p50 29
// degrees; curved vertices farther than 2.5 voxels from any crease p90 7.3,
// p99 17.4). Its two sides are the curved, non-band, non-skipped vertices
// within `rings` rings, split by 2-means on their normals (seeded by the
// normal farthest from the vertex's and the one farthest from that); each
// side gets a quadric (height field, least squares), trimmed `trim_rounds`
// times (points to the nearer quadric, those farther than `trim` cells from
// both dropped, both refitted), trusted at most `residual` cells RMS, then
// refitted to separate its sticks' samples by `stab_eps` (Quadric::stab).
// A side whose mean normal is within `sharp_angle` of the other's, a
// disagreement on convexity, tangent planes at the new point within
// `sharp_angle` (a fillet split in two), a new point farther than
// `other_distance` cells from the other side's quadric (no crease within
// reach) or a move longer than `max_move` along its stick rejects the
// vertex. Measured on fandisk by the `curved-creases` row of
// `build/bench/bench_ablation --cases fandisk.off` (docs/BENCHMARKS.md, Ablation).
struct CurvedCreaseFit {
  double band_angle = 15;  // degrees (physical)
  uint32_t rings = 6;
  uint32_t trim_rounds = 2;
  double trim = 0.1;       // cells
  double residual = 0.05;  // cells
  double stab_eps = 0.05;  // cells
  double stab_weight = 100;
  double sharp_angle = 30;    // degrees (physical)
  double other_distance = 1;  // cells
  double margin = 0.01;       // t kept in [margin, 1 - margin]
  double max_move = 0.5;      // of the stick
  bool network = true;        // keep only creases that continue a proven one (Pass::crease_network)
};

struct CurvedCrease {
  uint32_t v;
  double t;             // new stick parameter, from the inside sample (0) to the outside one (1)
  Plane chosen, other;  // tangent planes (index space, outward) at the new point: v's side's and the other side's
};

// What curved_crease_targets may do with a curved vertex.
enum CreaseRole : uint8_t {
  kCreaseFree = 0,  // a band vertex when its normal turns, else a side point
  kCreaseSkip = 1,  // neither placed nor a side point (junctions, the flat crease zone)
  kCreaseSide = 2,  // a side point only (a thin wall's vertex, on its fitted plane)
};

// The band vertices placed where their stick leaves the two sides' solid
// (intersection of the quadrics' insides at a convex crease, union at a
// concave one), in vertex order; region = flat id or -1 per vertex, role =
// CreaseRole per vertex, x = positions (index space), off / adj = vertex
// adjacency. `normals` (optional) receives the physical vertex normals used,
// `unproven` (optional) the number of creases found but dropped because no
// proven crease continues into them (c.network).
std::vector<CurvedCrease> curved_crease_targets(const StickSurface& sticks, const std::vector<int32_t>& region,
                                                const std::vector<uint8_t>& role, const std::vector<Vec3>& x,
                                                const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj,
                                                const CurvedCreaseFit& c, std::vector<Vec3>* normals = nullptr,
                                                size_t* unproven = nullptr);

}  // namespace voxpress::detail
