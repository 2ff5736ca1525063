// Private to the flats (Section 3): the detector's constants, its view of
// the estimated surface, the direction cells of the vote and the plane fits
// (least squares inside the set of planes that stab a cluster). Index space
// throughout. Theory of operation: include/voxpress/features/flats.h.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "feature_tuning.h"
#include "smooth/stick_solid.h"
#include "smooth/surface_graph.h"
#include "voxpress/features/flats.h"

namespace voxpress::flats_impl {

// The narrowest flat: a share of the smallest flat's side, capped (cells).
inline double min_width(const FlatOptions& o) {
  return std::min(detail::kFlatMaxWidth, detail::kFlatWidthShare * std::sqrt(o.min_area));
}

constexpr double kPi = std::numbers::pi;
constexpr int kCube = 64;  // cube-map cells per face side: ~1.4 degrees
constexpr int kNormalRings = 3;  // smoothing rounds of the estimated normals
// The growth also takes a stick the current plane misses by up to this
// fraction of it (the refit must then stab it, or it leaves): the sticks a
// plane a hair off misses come in lattice rows that would cut a face in
// bands (measured by `build/bench/bench_flats --shape box --res 64 --seeds
// 30`: more boxes with exactly six flats, a lower stick error); 0.1 and 0.2
// found fewer faces on the CAD part at 64^3 (`--shape cad-part --res 64`).
constexpr double kGrowSlack = 0.05;
constexpr int kExtendRounds = 4;  // rounds of flat extension up to sharp edges
// An accumulator cell seeds a cluster when it has at least this share of
// min_area voters; the flat itself must still reach min_area after growth
// (accept). Voters are the vertices whose estimated normal lies within the
// cone of the cell's direction, so a face whose estimate its rounded edges
// bend has far fewer voters than sticks: a face of several hundred cells
// between rounded edges can have only a few dozen in its best cell, and a
// share of 1 never tries it (measured by `build/bench/bench_flats`'s fandisk
// rows and `--shape cad-part --res 64 --seeds 60`: more faces found).
constexpr double kSeedShare = 0.3;
// The curvature test (Detector::curved, FlatOptions::curved_gain): a flat's
// neighbourhood is its core grown kCurvedRings rings over the vertices whose
// normal is within kCurvedWindow degrees of the plane's.
constexpr int kCurvedRings = 10;
constexpr double kCurvedWindow = 30;
constexpr uint32_t kTangentRings[2] = {2, 6};  // the curved side's rings fitted by the tangent test
constexpr uint32_t kRimJunctionRings = 2;      // rim members this close to a junction stay (rim_tangent_angle)
// Cells: how far from the flat's plane the tangent side's fitted points must
// rise for the rim to leave it (a fillet does; the rounded estimate along a
// box's crease stays within ~0.6 and fits a quadric that looks tangent).
constexpr double kRimFilletRise = 1.5;
// Junction test: points whose middle PCA eigenvalue is below this share of
// the largest are a row (their plane is arbitrary).
constexpr double kThinRow = 0.15;
// Detector::restab (near-axis faces): candidates within kRestabRings rings
// whose normal is within kRestabWindow degrees; searched when the plane stabs
// less than kRestabTrigger of them (not below kRestabGiveUp), or always when
// it lies within kRestabRange of a low-index direction (kLowIndex); a core
// the acceptance tests refused, when it stabs at least kRestabForced; over directions
// within kRestabRange degrees (kRestabSteps coarse steps each way, then two
// 5 x 5 grids 4 and 16 times finer), with at most kRestabSample sticks;
// taken when it stabs kRestabGain x as many; at most kRestabRounds rounds.
// Measured on boxes, cylinders, tori, the CAD part and fandisk by
// `build/bench/bench_flats` (docs/BENCHMARKS.md, Flats and junctions).
constexpr int kRestabRings = 10;
constexpr double kRestabWindow = 15;
constexpr double kRestabTrigger = 0.9;
constexpr double kRestabGiveUp = 0.75;
constexpr double kRestabForced = 0.7;
constexpr double kRestabRange = 4;
constexpr int kRestabSteps = 4;
constexpr size_t kRestabSample = 2000;
constexpr double kRestabGain = 1.02;
constexpr int kRestabRounds = 6;
// The low-index lattice directions, one of each +- pair: the 3 axes, the 6
// face diagonals and the 4 body diagonals (restab's near-lattice search).
const std::array<Vec3, 13> kLowIndex = [] {
  std::array<Vec3, 13> d;
  size_t k = 0;
  for (int a = 0; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c)
        if (a > 0 || b > 0 || (b == 0 && c > 0)) d[k++] = Vec3(a, b, c).normalized();
  return d;
}();


// Equal-angle cube-map cell of a direction, and back (flat_geometry.cpp).
uint32_t direction_cell(const Vec3& d);

Vec3 cell_direction(uint32_t c);

// Unit vectors spanning the plane orthogonal to unit n.
void frame(const Vec3& n, Vec3& u, Vec3& v);

constexpr int kDirections = 7;  // a vertex's vote directions: its normal's cell and six around it
// Each direction votes in two offset bins, one of each of two grids of unit
// bins staggered by half a bin: a plane whose offsets straddle one grid's
// bin border lies inside a bin of the other, so where the lattice's origin
// falls does not split a face's votes (and a shifted volume votes alike).
constexpr int kMaxVotes = 2 * kDirections;
int votes_of(const Vec3& n, const Vec3& x, double cone, uint64_t* out);

// ---------------------------------------------------------------- planes
using detail::fit_plane;
using detail::Pca;
using detail::pca;
using detail::Plane;

// The surface data the detector reads.
struct Surface {
  const StickSurface* s;
  std::vector<Vec3> x, nrm;         // estimated vertex positions and unit normals (index space)
  std::vector<double> area;         // a third of the incident triangle areas (index space)
  const std::vector<uint32_t>& adj_off;  // vertex adjacency (CSR): the surface's, built once
  const std::vector<uint32_t>& adj;
  // The estimated positions of vertices vs, into pts.
  void positions(const std::vector<uint32_t>& vs, std::vector<Vec3>& pts) const {
    pts.resize(vs.size());
    for (size_t q = 0; q < vs.size(); ++q) pts[q] = x[vs[q]];
  }
  // Samples of stick v: inside and outside endpoints.
  Vec3 inside(size_t v) const { return s->inside_sample(v); }
  Vec3 outside(size_t v) const { return s->outside_sample(v); }
};

// The accumulator (Section 3): each vertex's votes, grouped in cells (a
// direction cell and an offset bin), cells in key order, each cell's voters
// in vertex order.
struct Votes {
  std::vector<uint8_t> count;       // per vertex: its votes still counted (0: not voting)
  std::vector<uint32_t> vote_cell;  // per vertex and vote slot (kMaxVotes each): the cell
  std::vector<uint64_t> cell_key;   // per cell: direction cell << 32 | offset bin
  std::vector<uint32_t> cell_begin; // per cell: its voters are voter[cell_begin[c] .. cell_begin[c + 1])
  std::vector<uint32_t> cell_count; // per cell: its voters still counted
  std::vector<uint32_t> voter;
  size_t votes = 0, voters = 0;
};
Votes cast_votes(const Surface& S, double cone);

// t (from the inside sample) where the plane crosses stick v, or NaN when it
// does not cross it with the margin.
double crossing(const Surface& S, size_t v, const Plane& P, double margin);
// The largest lambda in [0, 1] such that (1 - lambda) P0 + lambda P1 stabs
// every stick of `cluster` with the margin (P0 does).
double feasible_step(const Surface& S, const std::vector<uint32_t>& cluster, const Plane& P0, const Plane& P1,
                     double m);

// A sample a plane must leave strictly on one side (crease_refit).

struct SideConstraint {
  Vec3 p;
  bool outside;
  auto operator<=>(const SideConstraint& o) const {
    return std::tie(p.x(), p.y(), p.z(), outside) <=> std::tie(o.p.x(), o.p.y(), o.p.z(), o.outside);
  }
  bool operator==(const SideConstraint&) const = default;
};
constexpr double kSideMargin = 1e-6;  // cells: how strictly a SideConstraint's sample is on its side

constexpr int kCenterRounds = 4;  // chord-midpoint sweeps of constrained_fit's centring

// Section 3's plane refinement, our choice of "best": least squares inside
// the feasible set. With n = n_F + a u + b v (n_F the least-squares normal
// of the points, u, v orthonormal to it) and the plane n . (x - m) = c'
// through the points' mean m, the squared residuals are a quadratic in
// z = (a, b, c') minimised at z = 0, and "the plane stabs stick s with the
// margin" is two linear inequalities in z. With H = L L^T the residuals'
// Hessian and w = L^T z this is the minimum-norm point of a polytope.
// `sides` adds one-sided constraints (crease_refit), linear in z as well.
// With `center_within`, the plane then moves to the centre of the feasible
// set (see there). Returns false when the cluster is infeasible or the solver fails
// numerically (the caller keeps a feasible plane).

// Section 3's plane refinement: least squares inside the feasible set
// (flat_geometry.cpp).
bool constrained_fit(const Surface& S, const std::vector<uint32_t>& cluster, const std::vector<Vec3>& pts,
                     const Vec3& towards, double margin, Plane& out, const std::vector<SideConstraint>& sides = {},
                     const std::vector<uint32_t>* center_within = nullptr);
Plane lerp(const Plane& a, const Plane& b, double l);

// The estimate's surface data: positions, smoothed normals, areas, adjacency.
Surface make_surface(const StickSurface& s, const std::vector<double>& t, const detail::Adjacency& graph);

// The crease refit (crease_refit.cpp).
bool crease_refit(const Surface& S, const FlatOptions& o, FlatSegmentation& seg, std::vector<Plane>& planes,
                  std::vector<uint8_t>& moved);

}  // namespace voxpress::flats_impl

namespace voxpress::detail {

// A point at depths u, v >= 0 inside two half-spaces whose outward normals
// have cosine c: is it cut off by the fillet of radius r tangent to both
// planes (between its arc and the planes' edge)? In the cross-section the
// point minus the fillet's centre is w = alpha n_a + beta n_b (n . w = r -
// depth); it is cut when w points into the arc's sector (alpha, beta >= 0)
// beyond the arc.
inline bool cut_by_fillet(double u, double v, double c, double r) {
  const double du = r - u, dv = r - v, g = 1 - c * c;
  const double alpha = (du - c * dv) / g, beta = (dv - c * du) / g;
  return alpha >= 0 && beta >= 0 && (du * du + dv * dv - 2 * c * du * dv) / g > r * r;
}

// The smallest fillet radius that cuts the point off (the fillets' solids
// nest, so bisection); `cap` when none up to it does or when the point is
// outside a half-space (no fillet reaches it).
inline double cutting_radius(double u, double v, double c, double cap) {
  if (u < 0 || v < 0 || !cut_by_fillet(u, v, c, cap)) return cap;
  double lo = 0, hi = cap;
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cut_by_fillet(u, v, c, mid) ? hi : lo) = mid;
  }
  return hi;
}

// What a crease's samples say of its rounding, gathered stick by stick
// (round-chains over a sharpening chain, round-borders over a junction
// chain). Between planes a and b meeting at a convex crease (kind 1) the
// inside samples lie in the true solid, so the smallest fillet radius that
// cuts one off bounds the rounding (`allow`, kRoundCap when none does); an
// outside sample more than kRoundEvidence inside both planes, where only a
// rounded edge puts it, demands one. At a concave crease (kind -1) the two
// samples swap parts.
constexpr double kRoundCap = 16;  // cells: no sample bounds the rounding at all (leaning planes, not a fillet)
struct RoundingEvidence {
  double allow = kRoundCap;
  double need = kRoundCap;  // the smallest rounding that cuts off a demanding sample
  void add(const Plane& a, const Plane& b, int kind, const Vec3& inside, const Vec3& outside) {
    const Vec3& keep = kind > 0 ? inside : outside;
    const Vec3& gone = kind > 0 ? outside : inside;
    const double c = a.n.dot(b.n);
    allow = std::min(allow, cutting_radius(-kind * (a.n.dot(keep) - a.c), -kind * (b.n.dot(keep) - b.c), c, kRoundCap));
    const double u = -kind * (a.n.dot(gone) - a.c), v = -kind * (b.n.dot(gone) - b.c);
    if (std::min(u, v) > kRoundEvidence) need = std::min(need, cutting_radius(u, v, c, kRoundCap));
  }
  // The sticks of the vertices `vs` and of their 1-rings (adjacency off,
  // adj), with each stick's inside and outside samples.
  template <class Inside, class Outside>
  void add_rings(const Plane& a, const Plane& b, int kind, const std::vector<uint32_t>& vs,
                 const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj, Inside inside, Outside outside) {
    for (uint32_t v : vs)
      for (uint32_t q = off[v]; q <= off[v + 1]; ++q) {  // v's 1-ring, then v
        const uint32_t w = q == off[v + 1] ? v : adj[q];
        add(a, b, kind, inside(w), outside(w));
      }
  }
  // Round: the samples allow at least `radius` and demand a rounding, and
  // some sample bounds it.
  bool round(double radius) const { return need < kRoundCap && allow >= radius && allow < kRoundCap; }
  // Round, on one pair of planes: also, a rounding the samples allow cuts
  // off a demanding sample (one deep inside both planes that no allowed
  // fillet reaches is cut off by something else, a third face at a corner).
  // A sharpening chain's vertices each bring their own planes, so there
  // only round() is asked.
  bool round_between(double radius) const { return round(radius) && need <= allow; }
  // Sharp: some sample forbids a rounding of `radius` (whether or not one is demanded).
  bool forbids(double radius) const { return allow < radius; }
};

// The kind of the edge of planes a and b that points pos(v) for v in `vs`
// lie along: convex (1) when they lie inside both planes 3 to 1 against
// outside both, concave (-1) the other way, else 0; parallel planes have
// no edge (0).
template <class Pos>
int edge_kind(const Plane& a, const Plane& b, const std::vector<uint32_t>& vs, Pos pos) {
  if (std::abs(a.n.dot(b.n)) > 0.999) return 0;
  int convex = 0, concave = 0;
  for (uint32_t v : vs) {
    const Vec3 p = pos(v);
    const double ha = a.n.dot(p) - a.c, hb = b.n.dot(p) - b.c;
    convex += ha < 0 && hb < 0;
    concave += ha > 0 && hb > 0;
  }
  return convex >= 3 * std::max(concave, 1) ? 1 : concave >= 3 * std::max(convex, 1) ? -1 : 0;
}

}  // namespace voxpress::detail
