// Sharp edge recovery (Chica et al., Section 5). Theory of operation:
// include/voxpress/smooth/sharpen.h. Geometry is done in index space, where
// the lattice samples are the integer points; angles compared with user
// thresholds are taken in the physical frame.
#include "voxpress/smooth/sharpen.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/clearance.h"
#include "core/predicates.h"
#include "core/sentinel.h"
#include "crease_fit.h"
#include "feature_tuning.h"
#include "quadric.h"
#include "surface_graph.h"

namespace voxpress {
namespace {

using detail::degrees_between;
using detail::kNone;
using detail::Plane;
constexpr double kPi = std::numbers::pi;
constexpr int kBucket = 2;       // cells per side of the buckets of the local intersection test
constexpr int kNearBlock = 4;    // cells per side of the blocks that decide which triangles it sees
constexpr int kBisections = 8;   // steps when a move is cut back
// A new vertex on a crease between two curved faces moves at most this far
// (cells): their tangent planes are fitted, not detected, and on the
// bunny's false creases their line lay up to 2 cells off (result -> truth
// max 0.72 -> 1.49 at 128^3). 0.5: bunny 128 / 256 0.1221 / 0.1006 ->
// 0.1166 / 0.0995, fandisk 128 seeds 1-4 unchanged (0.0592 / 0.0590).
constexpr double kCurvedCreaseMove = 0.5;
constexpr int kRounds = 8;       // passes over the new vertices' moves (then up to as many cutting back)
constexpr double kAdvance = 1e-3;  // cells: a cut-back round where no vertex advances more is the last
// join_leftovers' marks of curved vertices that join a flat.
constexpr uint8_t kLeftover = 1;  // joins and is projected onto the flat's plane
constexpr uint8_t kStrip = 2;     // joins the label only (thin_strips)
constexpr uint8_t kRimStrip = 3;  // in a strip's pocket next to a curved face (thin_strips)

uint64_t edge_key(uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); }

// Is z in the closed tetrahedron (a, b, c, d)? A flat tetrahedron counts z
// when z is coplanar with it (conservative).
bool in_closed_tet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z) {
  const int o = detail::orient3d(a, b, c, d);
  if (o == 0) return detail::orient3d(a, c, d, z) == 0 || detail::orient3d(b, c, d, z) == 0;
  return detail::orient3d(z, b, c, d) * o >= 0 && detail::orient3d(a, z, c, d) * o >= 0 &&
         detail::orient3d(a, b, z, d) * o >= 0 && detail::orient3d(a, b, c, z) * o >= 0;
}

// The point nearest x0 that best satisfies the planes in the least-squares
// sense: x0 + pinv(A) (b - A x0) with A = sum n n^T, b = sum n c, and
// eigenvalues below `floor` truncated (those directions keep x0) — the
// dual-contouring QEF solve. For two planes it is the closest point of their
// intersection line to x0; for three, their common point.
Vec3 solve_planes(const Plane* planes, int count, const Vec3& x0, double floor) {
  Mat3 A = Mat3::Zero();
  Vec3 r = Vec3::Zero();
  for (int i = 0; i < count; ++i) {
    A += planes[i].n * planes[i].n.transpose();
    r += planes[i].n * (planes[i].c - planes[i].n.dot(x0));
  }
  Eigen::SelfAdjointEigenSolver<Mat3> es(A);
  Vec3 dx = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double l = es.eigenvalues()[k];
    if (l < floor) continue;
    const Vec3 e = es.eigenvectors().col(k);
    dx += e * (e.dot(r) / l);
  }
  return x0 + dx;
}

struct NewVertex {
  uint32_t a = kNone, b = kNone;  // edge vertex: the chamfer edge's ends; corner: kNone
  bool corner = false;            // a corner vertex (three chamfer edges), not an edge vertex
  Vec3 target = Vec3::Zero();
  Vec3 along = Vec3::Zero();      // edge vertex between two planes: their intersection line's direction
  bool moves = false;             // has a target away from where it was inserted
  bool sharp = false;             // on a labelled sharp crease
  bool on_flats = false;          // its target lies on flats' planes only (not a curved side's fit)
  double angle = 0;               // edge vertex: degrees between its two planes' normals
};

struct Sharpener {
  const StickSurface& s;
  const FlatSegmentation& seg;
  const SharpenOptions& o;
  size_t n = 0;
  Mat3 Minv_t;
  std::vector<uint32_t> adj_off, adj;       // original vertex adjacency
  std::vector<Vec3> x;                      // positions (index space): original, then new
  std::vector<Triangle> tris;               // the refined triangles
  std::vector<NewVertex> nv;                // new vertex n + k
  std::vector<std::array<uint32_t, 2>> feature_edges;  // new edges between new vertices
  std::vector<int32_t> label;               // per original vertex: flat id or -1 (seg.region + leftovers)
  std::vector<uint32_t> leftovers;          // curved junction vertices that joined a flat
  std::vector<uint8_t> junction;            // per original vertex: seg.junction, and the rim pockets' (join_leftovers)
  std::vector<int8_t> plane_state;          // per original vertex: 0 unknown, 1 has plane, -1 none
  std::vector<uint8_t> on_wall;             // per original vertex: 1 placed on a thin wall's plane (fit_walls)
  std::vector<Plane> plane;
  detail::RingScratch rings;                // scratch of rings_around (tangent_plane, thin_strips)
  std::vector<uint32_t> fan_off, fan;       // triangles around each vertex (CSR)
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;  // refined triangles by their first vertex's bucket
  // Per refined triangle: its first vertex where index() bucketed it (float:
  // the bucket and the reach below both use this rounded point).
  std::vector<Eigen::Vector3f> anchor;
  double anchor_reach = 0;   // cells: farthest any triangle's vertex has been from its anchor (max norm)
  // Cells: the clearance every move keeps (samples, altitudes, triangle
  // pairs) so that float32 output keeps the guarantee (core/clearance.h).
  double delta = 0;
  SharpenStats st;

  Sharpener(const StickSurface& surface, const FlatSegmentation& f, const SharpenOptions& opts)
      : s(surface), seg(f), o(opts), n(surface.stick_count()) {
    Minv_t = s.lattice.index_to_physical_matrix().inverse().transpose();
    delta = detail::float32_clearance(s.lattice, detail::kMaxMove + 1);
  }

  Vec3 physical_normal(const Vec3& index_normal) const { return (Minv_t * index_normal).normalized(); }
  // Signed distance (index space, outward positive) from flat f's plane to p.
  double height(int32_t f, const Vec3& p) const {
    return seg.flats[size_t(f)].index_normal.dot(p) - seg.flats[size_t(f)].index_offset;
  }
  // Where along v's stick (0 inside, 1 outside sample) it leaves the
  // half-space below `p`: its crossing (unclamped) when it runs outwards
  // through the plane; +inf when the whole stick lies below a plane it does
  // not climb (it never leaves), -inf when it lies wholly above one (it is
  // never in); NaN when it enters the half-space on its way out.
  double leaves_at(uint32_t v, const Plane& p) const {
    const double hi = p.n.dot(s.inside_sample(v)) - p.c, ho = p.n.dot(s.outside_sample(v)) - p.c;
    if (ho > hi) return -hi / (ho - hi);
    if (hi < 0) return INFINITY;
    if (ho > 0) return -INFINITY;
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Where the plane normal . p = c crosses v's stick outwards (leaves_at's
  // crossing); NaN when it is not crossed outwards.
  double stick_crossing(uint32_t v, const Vec3& normal, double c) const {
    const double t = leaves_at(v, Plane{normal, c});
    return std::isfinite(t) ? t : std::numeric_limits<double>::quiet_NaN();
  }
  double flat_crossing(uint32_t v, int32_t f) const {
    return stick_crossing(v, seg.flats[size_t(f)].index_normal, seg.flats[size_t(f)].index_offset);
  }
  // A crossing this far beyond either sample still counts as on the stick (a
  // plane through a sample corner); slide() clamps it.
  static bool on_stick(double t) { return t > -kPastSample && t < 1 + kPastSample; }
  static constexpr double kPastSample = 0.1;
  // Puts v on its stick at t, kept in [margin, 1 - margin] (no sample
  // changes side: Pressing's guarantee).
  void slide(uint32_t v, double t) {
    const Vec3 in = s.inside_sample(v);
    x[v] = in + std::clamp(t, o.margin, 1 - o.margin) * (s.outside_sample(v) - in);
  }
  double angle_deg(const Vec3& na, const Vec3& nb) const { return degrees_between(physical_normal(na), physical_normal(nb)); }

  // Beyond the paper: the 2-ring plane is a secant of a curved side, so on a
  // cylinder of radius R its line with the flat lies ~ d^2 / 2R inside the
  // crease (d ~ 2 cells from the crease to the ring's centre: 0.15 cell on
  // the CAD part's hole at 128^3). Instead, the quadric (height field) of the
  // fresh, non-junction vertices within `curved_fit_rings` rings of v over
  // curved vertices, when it fits within `curved_fit_residual`, gives its
  // tangent plane where v projects onto it; v is next to the crease, so that
  // plane's line with the flat is within ~ (0.5 cell)^2 / 2R of it.
  bool tangent_plane(uint32_t v, Plane& out) {
    if (!o.passes.on(Pass::tangent_planes)) return false;
    detail::rings_around(v, uint32_t(detail::kCurvedFitRings), adj_off, adj, [&](uint32_t w) { return label[w] < 0; }, rings);
    std::vector<Vec3> pts;
    Vec3 outward = Vec3::Zero();
    for (const auto& [w, d] : rings.out)
      if (!junction[w]) {
        pts.push_back(x[w]);
        outward[s.axis(w)] += s.lower_inside(w) ? 1 : -1;
      }
    detail::Quadric Q;
    if (!Q.fit(pts, outward) || Q.residual > detail::kCurvedFitResidual) return false;
    const Vec3 foot = Q.foot(x[v]);
    out.n = Q.normal_at(foot);
    out.c = out.n.dot(foot);
    return true;
  }

  // The plane of an original vertex's side (Section 5), oriented outwards
  // (along the sticks' inside -> outside directions): its flat's plane; for
  // a curved vertex the paper's ring_plane, or beyond the paper its side's
  // quadric tangent plane when the side fits one (tangent_plane).
  const Plane* plane_of(uint32_t v) {
    if (plane_state[v] != 0) return plane_state[v] > 0 ? &plane[v] : nullptr;
    plane_state[v] = -1;
    const int32_t r = label[v];
    if (r >= 0) {
      const Flat& f = seg.flats[size_t(r)];
      plane[v] = {f.index_normal, f.index_offset};
      plane_state[v] = 1;
      return &plane[v];
    }
    if (tangent_plane(v, plane[v])) {
      ++st.tangent_planes;
    } else if (!ring_plane(v, plane[v])) {
      return nullptr;
    }
    plane_state[v] = 1;
    return &plane[v];
  }

  // Section 5's plane of a curved vertex: the least-squares plane of the
  // fresh, non-junction vertices in its 2-ring (all fresh ones when fewer
  // than 3); false when there are fewer than 3 or they are collinear.
  bool ring_plane(uint32_t v, Plane& out) const {
    std::vector<uint32_t> ring{v};
    detail::grow_rings(ring, 2, adj_off, adj);
    std::vector<Vec3> pts;
    Vec3 towards = Vec3::Zero();
    for (int pass = 0; pass < 2 && pts.size() < 3; ++pass) {
      pts.clear();
      towards.setZero();
      for (uint32_t q : ring)
        if (label[q] < 0 && (pass == 1 || !junction[q])) {
          pts.push_back(x[q]);
          towards[s.axis(q)] += s.lower_inside(q) ? 1 : -1;
        }
    }
    if (pts.size() < 3) return false;
    const detail::Pca p = detail::pca(pts);
    if (!(p.eigenvalues[1] > 1e-6)) return false;  // collinear points
    out = detail::oriented_plane(p, towards);
    return true;
  }

  // Section 5: an edge whose ends lie on two different faces (two flats, or
  // a flat and a curved junction vertex; beyond the paper, the two sides of
  // a curved/curved crease, curved_creases).
  bool chamfer(uint32_t u, uint32_t v) const {
    const int32_t a = label[u], b = label[v];
    if (a < 0 && b < 0 && crease_side[u] && crease_side[v])  // a curved/curved crease (curved_creases)
      return angle_deg(plane[u].n, plane[v].n) >= o.sharp_angle;
    if (a == b) return false;
    if (a >= 0 && b >= 0) {
      return degrees_between(seg.flats[size_t(a)].normal, seg.flats[size_t(b)].normal) >= detail::kMinAngle;
    }
    return junction[a < 0 ? u : v] != 0;
  }

  // Marks (kStrip) the curved vertices of thin strips: a vertex at most
  // `strip_rings` rings (over curved vertices) from a flat whose curved
  // neighbours within `strip_rings` rings are all that close too. The
  // flats' rims stop a few rings short of a crease the estimate rounded
  // widely (the CAD part's 45-degree chamfer: strips 3-5 vertices wide, so
  // neither side is a junction and the crease had no chamfer edge at all),
  // and of a face crossed by a lattice row nearly in its plane. A real
  // curved face is deeper than that a few rings in, so only its ragged
  // border's pockets could qualify (docs/ARCHITECTURE.md: 2 rings measured
  // best). Strip vertices join a flat's label but are not projected onto
  // its plane: on the fandisk, whose flats include gently curved faces, the
  // projection cost more accuracy than it gained.
  // A thin vertex with a curved vertex within `strip_rings` rings that is
  // not thin itself is in a pocket of a flat's ragged rim next to a real
  // curved face (kRimStrip), not in a strip between flats: join_leftovers
  // lets it join only when the flat's plane crosses its stick.
  void thin_strips(std::vector<uint8_t>& mark) {
    const uint32_t W = uint32_t(o.passes.on(Pass::strips) ? detail::kStripRings : 0);
    if (W == 0) return;
    std::vector<uint32_t> depth(n, detail::kUnreached), front;
    for (uint32_t v = 0; v < n; ++v) {
      if (label[v] >= 0) continue;
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
        if (label[adj[k]] >= 0) {
          depth[v] = 1;
          front.push_back(v);
          break;
        }
    }
    detail::spread_rings(std::move(front), 1, W + 1, adj_off, adj, depth,
                         [&](uint32_t, uint32_t w) { return label[w] < 0; });
    std::vector<uint8_t> thin(n, 0);
    for (uint32_t v = 0; v < n; ++v) {
      if (label[v] >= 0 || mark[v] || depth[v] > W) continue;
      detail::rings_around(v, W, adj_off, adj, [&](uint32_t w) { return label[w] < 0; }, rings);
      bool ok = true;
      for (const auto& [w, d] : rings.out) ok = ok && depth[w] <= W;
      thin[v] = ok;
    }
    // The curved vertices within W rings of one that is neither thin nor
    // marked (ring distance over curved vertices is symmetric).
    std::vector<uint32_t> near_deep(n, detail::kUnreached), deep;
    if (o.passes.on(Pass::rim_pockets)) {
      for (uint32_t v = 0; v < n; ++v)
        if (label[v] < 0 && !thin[v] && !mark[v]) {
          near_deep[v] = 0;
          deep.push_back(v);
        }
      detail::spread_rings(std::move(deep), 0, W, adj_off, adj, near_deep,
                           [&](uint32_t, uint32_t w) { return label[w] < 0; });
    }
    for (uint32_t v = 0; v < n; ++v)
      if (thin[v]) mark[v] = near_deep[v] == detail::kUnreached ? kStrip : kRimStrip;
  }

  // Calls f(patch) for each connected patch of curved vertices (label < 0).
  template <class F>
  void for_each_curved_patch(F&& f) const {
    std::vector<uint32_t> comp, stack;
    std::vector<uint8_t> seen(n, 0);
    for (uint32_t v0 = 0; v0 < n; ++v0) {
      if (label[v0] >= 0 || seen[v0]) continue;
      comp.clear();
      stack.assign(1, v0);
      seen[v0] = 1;
      while (!stack.empty()) {
        const uint32_t v = stack.back();
        stack.pop_back();
        comp.push_back(v);
        for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
          if (label[adj[k]] < 0 && !seen[adj[k]]) seen[adj[k]] = 1, stack.push_back(adj[k]);
      }
      f(comp);
    }
  }

  // Beyond the paper: where the solid of the flats around v crosses v's
  // stick. The flats are those with a member within `reach` rings; their
  // solid is the intersection of their half-spaces when their members lie
  // inside each other's planes (a convex crease or corner: at least 3 to 1),
  // the union when outside (concave), else undecided. Along the stick from
  // its inside sample (s = 0) to its outside one (s = 1) the intersection is
  // left at the first plane crossed outwards, the union at the last. False
  // when undecided or when the crossing misses the stick by more than
  // `snap_tolerance` cells along that plane's normal (or, with
  // `need_crease`, when no two of the flats meet at `min_angle` or more);
  // else s in [margin, 1 - margin] (clamped) and the flat whose plane it is on.
  struct SnapScratch {
    detail::RingScratch rings;
    std::vector<int32_t> near_flats;
  };
  bool solid_crossing(uint32_t v, bool need_crease, uint32_t reach, SnapScratch& scratch, int32_t& flat,
                      double& s_out) const {
    const auto& ring = scratch.rings.out;
    std::vector<int32_t>& near_flats = scratch.near_flats;
    detail::rings_around(v, reach, adj_off, adj, [](uint32_t) { return true; }, scratch.rings);
    near_flats.clear();
    detail::add_flats(ring, seg.region, near_flats);
    if (near_flats.empty()) return false;
    if (need_crease) {
      bool crease = false;
      for (size_t i = 0; i < near_flats.size() && !crease; ++i)
        for (size_t j = i + 1; j < near_flats.size() && !crease; ++j)
          crease = angle_deg(seg.flats[size_t(near_flats[i])].index_normal,
                             seg.flats[size_t(near_flats[j])].index_normal) >= detail::kMinAngle;
      if (!crease) return false;
    }
    // One flat: its half-space.
    const int kind = detail::crease_kind(
        ring, seg.region, near_flats, [&](uint32_t w) { return x[w]; },
        [&](int32_t f, const Vec3& p) { return height(f, p); });
    if (kind == 0) return false;  // undecided
    const bool convex = kind > 0;
    const Vec3 I = s.inside_sample(v), O = s.outside_sample(v);
    double best = convex ? INFINITY : -INFINITY, miss = 0;
    for (int32_t f : near_flats) {
      const double h0 = height(f, I), h1 = height(f, O);
      // Where the stick leaves the half-space, and by how much (along the
      // normal) that misses the stick. A stick that never crosses the plane
      // outwards leaves at its inside end when it starts outside (h0 >= 0;
      // at = -h0, so that of several the farthest outside leaves first), else
      // at its outside end: a sample a hair on the wrong side of a flat's
      // plane (a face through a sample) must not hide the crossing.
      double at, miss_f;
      if (h1 > h0) {
        at = h0 / (h0 - h1);
        miss_f = at < 0 ? h0 : at > 1 ? -h1 : 0;
      } else if (h0 >= 0) {
        at = -h0, miss_f = h0;
      } else {
        at = 1 - h1, miss_f = -h1;
      }
      if (convex ? at < best : at > best) best = at, flat = f, miss = miss_f;
    }
    if (miss > detail::kSnapTolerance) return false;  // every plane gave a finite `at`
    s_out = std::clamp(best, o.margin, 1 - o.margin);
    return true;
  }

  // Beyond the paper: the flats' rims stop a few rings short of a crease or
  // a corner the estimate rounded, leaving a curved band or patch that the
  // chamfer triangles would cut as a wide bevel. A curved patch whose
  // sticks the flats' solid (solid_crossing) explains, all but a share
  // `1 - snap_share`, is such a band, not a curved face (a fillet of radius
  // r leaves its sticks ~0.4 r outside the solid); its explained vertices
  // go, along their sticks, onto the solid and join the flat whose plane
  // they reach. Flat members within 2 rings of another region whose stick
  // the solid crosses on another flat's plane (the rim ran past the crease)
  // move there too. Every vertex stays in its stick, so no sample changes
  // side (Pressing's guarantee), and the creases then lie between vertices
  // on the two planes.
  void snap_to_flats() {
    if (!o.passes.on(Pass::snap)) return;
    // Candidates: curved vertices, and members up to 2 rings from a border.
    const std::vector<uint32_t> depth = detail::region_border_rings(seg.region, 2, adj_off, adj);
    std::vector<int32_t> flat(n, -1);  // the flat whose plane the solid crosses v's stick on
    std::vector<double> t(n, 0);
    tbb::enumerable_thread_specific<SnapScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(n), 256), [&](const tbb::blocked_range<uint32_t>& r) {
      SnapScratch& sc = scratch.local();
      for (uint32_t v = r.begin(); v < r.end(); ++v) {
        const bool member = seg.region[v] >= 0;
        if (member && depth[v] > 2) continue;
        if (!solid_crossing(v, member, uint32_t(detail::kSnapRings), sc, flat[v], t[v]) || flat[v] == seg.region[v])
          flat[v] = -1;
      }
    });
    SnapScratch wide;
    for_each_curved_patch([&](const std::vector<uint32_t>& patch) {
      size_t explained = 0;
      for (uint32_t v : patch) explained += flat[v] >= 0;
      // A corner patch whose third face's flat stops more than snap_rings
      // rings away: the two near flats explain most of it, the rest only
      // with the third (box 128 seeds 39 and 48). Its unexplained vertices
      // look twice as far; a curved face, mostly unexplained, is not retried.
      if (explained >= patch.size() / 2 && double(explained) < detail::kSnapShare * double(patch.size()))
        for (uint32_t v : patch)
          if (flat[v] < 0) {
            if (solid_crossing(v, false, 2 * uint32_t(detail::kSnapRings), wide, flat[v], t[v])) {
              ++explained;
            } else {
              flat[v] = -1;
            }
          }
      if (double(explained) < detail::kSnapShare * double(patch.size()))
        for (uint32_t v : patch) flat[v] = -1;
    });
    for (uint32_t v = 0; v < n; ++v) {
      if (flat[v] < 0) continue;
      slide(v, t[v]);  // t is already in [margin, 1 - margin]
      label[v] = flat[v];
      ++st.snapped;
    }
  }

  // Beyond the paper: curved vertices that are not part of a curved face
  // join a flat. They are the vertices of small curved patches (fewer than
  // `min_curved`: slivers of chamfer the flats' planes did not stab near
  // edges and corners, or holes inside a flat), of thin strips (thin_strips:
  // a crease the flats stopped short of, or a seam inside a flat) and
  // curved junction vertices with no curved surface around them (fewer than
  // 3 fresh vertices in their 2-ring, so no plane of their own). Each joins
  // the flat within 3 rings whose plane is nearest and, except in a strip,
  // is later projected onto it (a checked move), so creases lie between
  // flats and real curved faces only.
  void join_leftovers() {
    std::vector<uint8_t> small(n, 0);
    for_each_curved_patch([&](const std::vector<uint32_t>& patch) {
      if (patch.size() < size_t(detail::kMinCurved))
        for (uint32_t v : patch) small[v] = kLeftover;
    });
    thin_strips(small);
    std::vector<std::pair<uint32_t, int32_t>> joins;
    std::vector<uint32_t> ring;
    for (uint32_t v = 0; v < n; ++v) {
      Plane unused;
      if (label[v] >= 0 || !(small[v] || (junction[v] && !ring_plane(v, unused)))) continue;
      int32_t best = -1;
      double best_d = INFINITY;
      // Every flat with a member within 3 rings competes: taking the first
      // ring that reaches one had a vertex of the CAD part's bottom rim
      // (128 seed 5) join the bottom's flat 1.04 cells below its plane
      // while 0.15 from the side face's, and the crease chain detoured
      // 0.94 voxel around it.
      ring.assign(1, v);
      detail::grow_rings(ring, 3, adj_off, adj);
      for (uint32_t q : ring) {
        const int32_t f = label[q];
        if (f < 0) continue;
        const double d = std::abs(height(f, x[v]));
        if (d < best_d) best_d = d, best = f;
      }
      if (best >= 0) joins.push_back({v, best});
    }
    // A rim pocket's vertex joins only when the flat's plane crosses its
    // stick from the inside sample to the outside one (up to 0.1 cell
    // beyond either sample: a plane through a sample corner; a plane with
    // the outside sample below it does not bound the solid there), and
    // slides along the stick onto it, so no sample changes
    // side. Otherwise it lies past the crease, on the curved face: left on
    // the flat, off its plane, the crease vertex inserted next to it had to
    // move back past it, which turned triangles over, and that move was
    // cut back (CAD part 128: 110-160 crease vertices per seed, left about
    // 0.3 cell off the crease). It stays curved, and a junction when it has a flat and a
    // curved junction neighbour (the border there is sharp).
    std::vector<uint32_t> pocket;
    for (const auto& [v, f] : joins) {
      if (small[v] == kRimStrip) {
        const double t = flat_crossing(v, f);  // NaN unless crossed outwards
        if (!on_stick(t)) {
          pocket.push_back(v);
          continue;
        }
        slide(v, t);
      }
      label[v] = f;
      if (small[v] == kLeftover) leftovers.push_back(v);  // a thin strip's vertices keep their place
    }
    for (uint32_t v : pocket) {
      bool flat = false, sharp = false;
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
        flat |= label[adj[k]] >= 0;
        sharp |= label[adj[k]] < 0 && seg.junction[adj[k]];
      }
      junction[v] |= flat && sharp;
    }
  }

  // Beyond the paper: a curved junction that joined a flat (snap_to_flats,
  // join_leftovers) and lies on its plane moved the flat's border onto its
  // curved neighbours, so those that pass Section 3's junction test (their
  // 2-ring plane meets the flat at sharp_angle or more) become junctions,
  // as past_creases does for its joins. Otherwise their edges to the joined
  // vertex are no chamfer edges (chamfer()) and the sharp curve has a gap
  // there (CAD part 128 seed 1: 2 cells of the boss's rim, true -> labelled
  // 1.0 voxel). A thin strip's vertex joins off the plane (join_leftovers)
  // and moves no border: at 64^3 its heirs labelled a false crease.
  void inherit_junctions() {
    if (!o.passes.on(Pass::inherit_junctions)) return;
    std::vector<uint32_t> heirs;
    for (uint32_t v = 0; v < n; ++v)
      if (label[v] >= 0 && seg.region[v] < 0 && junction[v] && std::abs(height(label[v], x[v])) <= kPastSample)
        sharp_neighbours(v, heirs);
    st.inherited_junctions += mark_junctions(heirs);
  }
  // Section 3's junction test on the border a vertex v that joined a flat
  // moved: its curved, non-junction neighbours whose 2-ring plane meets the
  // flat's at sharp_angle or more are appended to `out`.
  void sharp_neighbours(uint32_t v, std::vector<uint32_t>& out) const {
    const Vec3& normal = seg.flats[size_t(label[v])].index_normal;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      Plane p;
      if (const uint32_t q = adj[k];
          label[q] < 0 && !junction[q] && ring_plane(q, p) && angle_deg(p.n, normal) >= o.sharp_angle)
        out.push_back(q);
    }
  }
  // The flat of v's 1-ring members whose plane is nearest to v (-1: none),
  // and that distance.
  int32_t nearest_neighbour_flat(uint32_t v, double& distance) const {
    int32_t f = -1;
    distance = INFINITY;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
      if (const int32_t r = label[adj[k]]; r >= 0 && std::abs(height(r, x[v])) < distance)
        distance = std::abs(height(r, x[v])), f = r;
    return f;
  }
  // Makes them junctions; returns how many were not yet.
  size_t mark_junctions(const std::vector<uint32_t>& vertices) {
    size_t fresh = 0;
    for (uint32_t q : vertices) {
      fresh += !junction[q];
      junction[q] = 1;
    }
    return fresh;
  }

  // Beyond the paper: thin walls. A plate a few cells thick has its rim
  // between two nearly opposite flats; the rim's fresh vertices are all
  // junctions with too few fresh neighbours for a plane of their own, so they
  // joined the flats (join_leftovers), and the chamfer between two parallel
  // planes has no line: one crease was labelled along the middle of the rim,
  // a cell from both true edges (1002_tray_bottom at 256^3: none of its
  // sharp length within half a voxel of a label). A fresh vertex reached,
  // over fresh vertices, from members of two flats A, B whose normals are at
  // least 170 degrees apart (a plate's faces; 150 also took fandisk's curved
  // faces between its two nearly opposite sides), and lying between their
  // planes at most `wall_thickness` cells apart, is on such a wall; beyond
  // 12 cells the samples resolve the wall's own surface, and its 2-ring
  // plane must be within 10 degrees of perpendicular to the flats (on
  // fandisk's curved faces it is not: without this test a bound of 24 took
  // them, r->t 0.0732 -> 0.0762 at 128^3). Its
  // plane: the widest separator of the inside samples of the sticks of the
  // wall vertices within 2 rings (over wall vertices) from those sticks'
  // outside samples that lie between A's and B's planes (outside because of
  // the wall, not of a flat): a maximum-margin line in the plane
  // perpendicular to A's normal, searched over its angle, c in the middle of
  // the margin (the centre of the feasible set, like the flats' centring).
  // Where no line separates them (the rim turns: the tray's corners, small
  // holes) the 1-ring's samples are used. The pressed rim is no guide:
  // squeezed between the flats, its vertices sit up to a cell inside. The
  // vertex then slides along its stick onto that plane when its own outside
  // sample is between A and B, and becomes a curved junction whose plane is
  // the wall's, so the chamfers on both sides cut along wall ∩ A and wall ∩
  // B. Fixed 2- or 3-ring fits were measured worse than 1 ring (their
  // infeasible fits left vertices out); 3 rings first, then 2 and 1, is no
  // better than 2 then 1 (docs/ARCHITECTURE.md). Rim vertices on a flat's
  // stick (its outside sample above a face) that joined a flat, and the
  // flats' own vertices next to the wall, go where their stick first leaves
  // the solid, through the wall or the flat; left on a flat mid-rim, they
  // kinked it.
  void fit_walls() {
    if (!o.passes.on(Pass::walls)) return;
    constexpr uint32_t kWallFitRings = 2;
    constexpr double kResolvedWall = 12;  // cells
    constexpr double kFlatGap = 0.1;      // cells: a fitted flat's plane may be this far off near its rim
    const double opposite = std::cos(170 * kPi / 180), kWallLean = std::sin(10 * kPi / 180);
    // The flats (up to kNear, smallest ids) that reach each fresh vertex over
    // fresh vertices within wall_thickness + 2 rings, each with the ring it
    // first arrived at. Jacobi rounds, so the result does not depend on the
    // visiting order; each round recomputes only the fresh neighbours of the
    // vertices the last round changed (an organic shape's fresh vertices far
    // from any flat are never visited).
    constexpr size_t kNear = 4;
    struct Reach {
      int32_t flat = -1, ring = 0;
      bool operator==(const Reach&) const = default;
    };
    using Near = std::array<Reach, kNear>;
    auto add = [](Near& a, Reach r) {
      for (Reach& g : a) {
        if (g.flat == r.flat) {
          g.ring = std::min(g.ring, r.ring);
          return;
        }
        if (g.flat < 0 || r.flat < g.flat) std::swap(g, r);
        if (r.flat < 0) return;
      }
    };
    std::vector<Near> near(n);
    std::vector<uint32_t> fresh, changed, todo;
    for (uint32_t v = 0; v < n; ++v)
      if (seg.region[v] < 0) {
        fresh.push_back(v);
        for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
          if (seg.region[adj[k]] >= 0) add(near[v], {seg.region[adj[k]], 1});
        if (near[v][0].flat >= 0) changed.push_back(v);
      }
    std::vector<uint32_t> queued(n, detail::kUnreached);
    std::vector<Near> next;
    for (uint32_t round = 0; round < uint32_t(std::ceil(detail::kWallThickness)) + 1 && !changed.empty(); ++round) {
      todo.clear();
      for (uint32_t v : changed)
        for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
          const uint32_t w = adj[k];
          if (seg.region[w] < 0 && queued[w] != round) {
            queued[w] = round;
            todo.push_back(w);
          }
        }
      std::sort(todo.begin(), todo.end());
      next.resize(todo.size());
      for (size_t i = 0; i < todo.size(); ++i) {
        const uint32_t v = todo[i];
        next[i] = near[v];
        for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
          if (seg.region[adj[k]] < 0)
            for (const Reach& r : near[adj[k]])
              if (r.flat >= 0) add(next[i], {r.flat, r.ring + 1});
      }
      changed.clear();
      for (size_t i = 0; i < todo.size(); ++i)
        if (next[i] != near[todo[i]]) {
          near[todo[i]] = next[i];
          changed.push_back(todo[i]);
        }
    }
    std::vector<std::array<int32_t, 2>> pair(n, {-1, -1});
    std::vector<uint32_t> cand;
    for (uint32_t v : fresh) {
      const Near& a = near[v];
      for (size_t i = 0; i < kNear && a[i].flat >= 0 && pair[v][0] < 0; ++i)
        for (size_t j = i + 1; j < kNear && a[j].flat >= 0; ++j) {
          const Flat &fa = seg.flats[size_t(a[i].flat)], &fb = seg.flats[size_t(a[j].flat)];
          const double ha = height(a[i].flat, x[v]) / fa.index_normal.norm(),
                       hb = height(a[j].flat, x[v]) / fb.index_normal.norm(), thickness = -(ha + hb);
          const Vec3 na = fa.index_normal.normalized();
          // Between the two planes, and across the wall from both flats (a
          // rim is crossed in about as many rings as it has cells, plus the
          // rings the flats' rims stop short of the creases).
          if (!(na.dot(fb.index_normal.normalized()) <= opposite && ha < 0.5 && hb < 0.5 &&
                thickness <= detail::kWallThickness && std::max(a[i].ring, a[j].ring) <= 1.5 * thickness + 4))
            continue;
          Plane own;
          if (thickness > kResolvedWall && !(ring_plane(v, own) && std::abs(own.n.normalized().dot(na)) < kWallLean))
            continue;
          pair[v] = {a[i].flat, a[j].flat};
          cand.push_back(v);
          break;
        }
    }
    // An outside sample between A's and B's planes (by more than `gap`
    // cells) is outside because of the wall, not of a flat.
    auto between = [&](int32_t A, int32_t B, const Vec3& p, double gap = 0) {
      return height(A, p) < -gap * seg.flats[size_t(A)].index_normal.norm() &&
             height(B, p) < -gap * seg.flats[size_t(B)].index_normal.norm();
    };
    std::vector<Plane> wall(cand.size());
    std::vector<uint8_t> ok(cand.size(), 0);
    tbb::enumerable_thread_specific<detail::RingScratch> scratch;
    tbb::parallel_for(size_t(0), cand.size(), [&](size_t k) {
      const uint32_t v = cand[k];
      const auto [A, B] = pair[v];
      const Vec3 na = seg.flats[size_t(A)].index_normal.normalized();
      const Vec3 u = na.cross(std::abs(na.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)).normalized(), w = na.cross(u);
      std::vector<Eigen::Vector2d> in, out;
      double lo = 0, hi = 0;
      auto margin = [&](double a) {
        const Eigen::Vector2d d(std::cos(a), std::sin(a));
        lo = -INFINITY;
        hi = INFINITY;
        for (const auto& p : in) lo = std::max(lo, d.dot(p));
        for (const auto& p : out) hi = std::min(hi, d.dot(p));
        return hi - lo;
      };
      detail::RingScratch& rs = scratch.local();
      // (rings, gap) tried in turn; the gap only for a vertex that joined a
      // flat (a strip or leftover vertex mid-rim: otherwise a kink).
      constexpr std::pair<uint32_t, double> kAttempts[] = {
          {kWallFitRings, 0.0}, {1, 0.0}, {kWallFitRings, kFlatGap}, {1, kFlatGap}};
      for (const auto& [rings_fit, gap] : kAttempts) {
        if (gap > 0 && label[v] < 0) break;
        in.clear();
        out.clear();
        detail::rings_around(v, rings_fit, adj_off, adj, [&](uint32_t q) { return pair[q] == pair[v]; }, rs);
        for (const auto& [q, d] : rs.out) {
          const Vec3 pi = s.inside_sample(q), po = s.outside_sample(q);
          in.emplace_back(u.dot(pi), w.dot(pi));
          if (between(A, B, po, gap)) out.emplace_back(u.dot(po), w.dot(po));
        }
        if (in.size() < 3 || out.size() < 3) continue;
        double best = -INFINITY, best_a = 0;
        for (int i = 0; i < 180; ++i) {  // every 2 degrees, then halving steps
          const double a = 2 * kPi * i / 180, m = margin(a);
          if (m > best) best = m, best_a = a;
        }
        for (double step = kPi / 180; step > 1e-4; step /= 2)
          for (const double a : {best_a - step, best_a + step}) {
            const double m = margin(a);
            if (m > best) best = m, best_a = a;
          }
        if (!(best > 0)) continue;  // no line separates them: the rim turns here
        margin(best_a);
        wall[k] = {std::cos(best_a) * u + std::sin(best_a) * w, 0.5 * (lo + hi)};
        ok[k] = 1;
        return;
      }
    });
    enum : uint8_t { kUnplaced, kOnFlat, kOnWall };
    std::vector<uint8_t> placed(n, kUnplaced);
    auto make_wall = [&](uint32_t v, double t, const Plane& p) {
      slide(v, t);
      label[v] = -1;
      junction[v] = 1;
      plane[v] = p;
      plane_state[v] = 1;
      placed[v] = kOnWall;
      on_wall[v] = 1;
      ++st.wall_vertices;
    };
    for (size_t k = 0; k < cand.size(); ++k) {
      const uint32_t v = cand[k];
      const auto [A, B] = pair[v];
      if (!ok[k]) continue;
      const double t = stick_crossing(v, wall[k].n, wall[k].c);  // NaN unless crossed outwards
      if (between(A, B, s.outside_sample(v))) {
        if (!std::isnan(t)) make_wall(v, t, wall[k]);
        continue;
      }
      // A flat's stick. A vertex that joined a flat mid-rim (a strip or
      // leftover; left there, the rim kinks) goes where its stick first
      // leaves the solid: through the wall's plane or a flat's. Other
      // curved vertices stay: at a rounded edge neither plane bounds the
      // solid (plate_holes.STL at 256^3: moved onto a flat's plane, 0.8
      // voxel out).
      if (label[v] < 0) continue;
      int32_t first = -1;
      double tf = std::isnan(t) ? INFINITY : t;
      for (const int32_t f : {A, B}) {
        const double tc = flat_crossing(v, f);
        if (tc > -kPastSample && tc < tf) tf = tc, first = f;
      }
      if (first < 0) {
        if (!std::isnan(t)) make_wall(v, t, wall[k]);
      } else if (on_stick(tf)) {
        slide(v, tf);
        label[v] = first;
        placed[v] = kOnFlat;
      }
    }
    // A flat's vertex (frozen or joined) next to a wall vertex of that flat
    // whose stick crosses the wall's plane before its flat's: the surface
    // leaves the solid through the wall, and the flat's plane there lies
    // beyond the rim (up to 0.6 voxel out on examples/plate.obj at 64^3).
    // Decided from the walls above only, so the order does not matter.
    struct ToWall {
      uint32_t v, by;  // by: the wall vertex whose plane v takes
      double t;
    };
    std::vector<ToWall> to_wall;
    for (uint32_t v = 0; v < n; ++v) {
      const int32_t f = label[v];
      if (f < 0 || placed[v] != kUnplaced) continue;
      double t_first = flat_crossing(v, f);
      if (std::isnan(t_first)) continue;
      uint32_t by = kNone;
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
        const uint32_t w = adj[k];
        if (placed[w] != kOnWall || (pair[w][0] != f && pair[w][1] != f)) continue;
        const double tw = stick_crossing(v, plane[w].n, plane[w].c);
        if (tw > -kPastSample && tw < t_first) t_first = tw, by = w;
      }
      if (by != kNone) to_wall.push_back({v, by, t_first});
    }
    for (const ToWall& m : to_wall) make_wall(m.v, m.t, plane[m.by]);
    std::erase_if(leftovers, [&](uint32_t v) { return placed[v] != kUnplaced; });
  }

  uint32_t add_vertex(const NewVertex& v, const Vec3& at) {
    nv.push_back(v);
    x.push_back(at);
    return uint32_t(n + nv.size() - 1);
  }

  // Beyond the paper: press_with_flats placed the curved vertices next to
  // its junctions by the crease fit (fit_creases), but snapping, the
  // leftovers and the rim pockets moved the flats' rims since, and where a
  // rim had stopped short of a crease (a smooth-looking bevel, no junction
  // then) the curved side was pressed in to 0.3-0.4 cell below its true
  // surface (the CAD part's rounded corners at 128^3). With the labels
  // final, the same fit places them again, along their sticks (so no sample
  // changes side); a move longer than `final_crease_max_move` is refused:
  // it is the quadric extrapolated wrongly, not a rounded crease
  // (fixed_top.ply's faceted walls), and without the re-press that follows
  // fit_creases a long move leaves a kink.
  void final_crease_fit() {
    if (!o.passes.on(Pass::final_crease)) return;
    const detail::CreaseFit c{.rings = detail::kFinalCreaseRings,
                              .fit_rings = detail::kFinalCreaseFitRings,
                              .residual = detail::kFinalCreaseResidual,
                              .margin = o.margin,
                              .max_move = detail::kFinalCreaseMaxMove};
    for (const auto& [v, t] : detail::crease_targets(s, seg.flats, label, junction, x, adj_off, adj, c)) {
      slide(v, t);
      ++st.final_crease_vertices;
    }
  }

  // past_creases: how much sooner (cells along the stick) a member's stick
  // must leave the solid on the curved side's plane. 0.2 left the labels
  // farther from the true creases at 128^3 (mean labelled -> true 0.746 /
  // 0.621 on the CAD part / cylinders, against 0.737 / 0.567).
  static constexpr double kLeaveMargin = 0.05;

  // +1 when the non-junction curved vertices within 2 rings of v lie below
  // flat f's plane (a convex crease; at least 3 to 1), -1 above, else 0.
  int crease_kind_near(uint32_t v, int32_t f, std::vector<uint32_t>& ring) const {
    size_t below = 0, above = 0;
    ring.assign(1, v);
    detail::grow_rings(ring, 2, adj_off, adj);
    for (uint32_t w : ring)
      if (label[w] < 0 && !junction[w]) (height(f, x[w]) < 0 ? below : above) += 1;
    return below > 0 && below >= 3 * above ? 1 : above > 0 && above >= 3 * below ? -1 : 0;
  }

  // Beyond the paper: vertices on the wrong side of their crease. Where a
  // face passes through a sample, the sticks from that sample all meet the
  // surface at it; a curved junction vertex among them, pressed a little
  // in, can lie on the flat's face, and the crease vertices inserted on its
  // edges, whose targets lie beyond it, were cut back around it (CAD part
  // 128: chains detouring 0.8-0.96 voxel off the true crease, its sharp
  // Hausdorff). Conversely a flat's rim runs past the crease onto the curved
  // face where the flat's plane still stabs the sticks there. Each vertex
  // next to a flat/curved border is judged by the local solid of the flat's
  // plane and the curved side's quadric tangent plane (tangent_plane;
  // falling back on the 2-ring plane as plane_of does made the CAD part at
  // 64^3 worse, result -> truth 0.0662 -> 0.0684 on bench/compare's
  // rotation): their intersection at a convex crease, their union at a
  // concave one (crease_kind_near). Decided for all first, then applied.
  //  * A curved junction vertex whose stick leaves that solid on the flat's
  //    plane joins the flat there (a slide along the stick: no sample
  //    changes side). A stick that never climbs the side's plane and lies
  //    below it leaves the solid on the flat's plane (leaves_at: CAD part
  //    128 seed 10, a curved junction at a sample 0.76 voxel from the
  //    crease; left curved, the chain detoured 0.85 voxel around it). A
  //    stick nearly parallel to the flat may not cross its plane at all
  //    (CAD part 128 seed 13: two curved vertices at a sample 1.3 voxels
  //    from the crease, the chain looping out to them): when the vertex
  //    lies within kPastSample of the flat's plane and more than that
  //    inside the side's half-space (outside at a concave crease), it joins
  //    where it is.
  //  * A flat member next to a curved junction, whose side's tangent plane
  //    meets the flat at sharp_angle or more, leaves the flat when its stick
  //    leaves the solid on that tangent plane at least kLeaveMargin before
  //    the flat's plane; it slides there.
  // The curved neighbours of a joined vertex, and a leaving vertex, become
  // junctions.
  void past_creases() {
    if (!o.passes.on(Pass::past_crease)) return;
    struct Move {
      uint32_t v;
      int32_t label;  // the flat it joins, or -1 (it leaves its flat)
      double t;       // where on its stick it goes (NaN: it stays where it is)
    };
    std::vector<Move> moves;
    std::vector<uint32_t> ring;
    for (uint32_t v = 0; v < n; ++v) {
      if (label[v] < 0 && junction[v]) {  // a curved junction: past the crease on the flat?
        double best;
        const int32_t f = nearest_neighbour_flat(v, best);
        if (f < 0) continue;
        const double tf = flat_crossing(v, f);
        const bool crossed = on_stick(tf);
        if (!crossed && best > kPastSample) continue;
        Plane side;  // uncached (plane_of's cache would keep curved_creases from setting it)
        if (!tangent_plane(v, side)) continue;
        const int kind = crease_kind_near(v, f, ring);
        if (crossed) {
          const double tc = leaves_at(v, side);
          if ((kind > 0 && tf < tc) || (kind < 0 && tf > tc)) moves.push_back({v, f, tf});
        } else {
          const double hc = side.n.dot(x[v]) - side.c;  // on the flat's plane already: where is the side's?
          if ((kind > 0 && hc < -kPastSample) || (kind < 0 && hc > kPastSample)) moves.push_back({v, f, NAN});
        }
      } else if (const int32_t f = label[v]; f >= 0) {  // a member: past the crease on the curved face?
        uint32_t w = kNone;  // its nearest curved junction neighbour
        double d2 = INFINITY;
        for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
          if (const uint32_t q = adj[k]; label[q] < 0 && junction[q] && (x[q] - x[v]).squaredNorm() < d2)
            d2 = (x[q] - x[v]).squaredNorm(), w = q;
        if (w == kNone) continue;
        Plane side;
        if (!tangent_plane(w, side) || angle_deg(side.n, seg.flats[size_t(f)].index_normal) < o.sharp_angle) continue;
        const int kind = crease_kind_near(v, f, ring);
        const double tf = flat_crossing(v, f), tc = stick_crossing(v, side.n, side.c);
        if (!on_stick(tc) || !std::isfinite(tf)) continue;
        if ((kind > 0 && tc < tf - kLeaveMargin) || (kind < 0 && tc > tf + kLeaveMargin)) moves.push_back({v, -1, tc});
      }
    }
    for (const Move& m : moves) {
      if (std::isfinite(m.t)) slide(m.v, m.t);
      label[m.v] = m.label;
      if (m.label >= 0) {
        ++st.past_crease;
      } else {
        junction[m.v] = 1;
        ++st.left_flat;
      }
    }
    for (const Move& m : moves)
      if (m.label >= 0)
        for (uint32_t k = adj_off[m.v]; k < adj_off[m.v + 1]; ++k)
          if (label[adj[k]] < 0) junction[adj[k]] = 1;
  }

  // Beyond the paper: creases between two curved faces (fandisk). Once the
  // labels are final, the band vertices of such creases are placed again by
  // their two sides' quadrics (detail::curved_crease_targets, as in
  // press_with_flats' rounds), along their sticks; each keeps its side's
  // tangent plane, and a curved neighbour whose normal is closer to the
  // other side's takes that one. Edges between two such vertices whose
  // planes meet at `sharp_angle` or more are chamfer edges (chamfer()), so
  // subdivide() inserts the crease as for a flat border.
  std::vector<uint8_t> crease_side;  // per original vertex: 1 placed on a curved crease, 2 its other side's neighbour
  void curved_creases() {
    crease_side.assign(n, 0);
    if (!o.passes.on(Pass::curved_creases)) return;
    detail::CurvedCreaseFit c;
    c.sharp_angle = o.sharp_angle;
    c.margin = o.margin;
    // A thin wall's vertices are junctions on their wall's fitted plane, a
    // face of their own: they stay, but are the wall's side of a crease
    // with a curved face (fandisk 128 seed 1: a wall's 60-90 degree crease
    // with a curved face was unlabelled for 9 voxels; without its vertices
    // the 2-means saw one side only).
    std::vector<uint8_t> role(n);
    for (size_t v = 0; v < n; ++v)
      role[v] = !junction[v] ? detail::kCreaseFree : on_wall[v] ? detail::kCreaseSide : detail::kCreaseSkip;
    std::vector<Vec3> normal;
    const auto found = detail::curved_crease_targets(s, label, role, x, adj_off, adj, c, &normal);
    for (const auto& f : found) {
      slide(f.v, f.t);
      if (plane_state[f.v] != 0) continue;
      crease_side[f.v] = 1;
      plane[f.v] = f.chosen;
      plane_state[f.v] = 1;
    }
    st.curved_crease_vertices = found.size();
    for (const auto& f : found) {
      const uint32_t v = f.v;
      if (crease_side[v] != 1) continue;
      const Vec3 mine = physical_normal(f.chosen.n), theirs = physical_normal(f.other.n);
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
        const uint32_t w = adj[k];
        if (label[w] >= 0 || junction[w] || plane_state[w] != 0) continue;
        if (normal[w].dot(theirs) > normal[w].dot(mine)) {
          crease_side[w] = 2;
          plane[w] = f.other;
          plane_state[w] = 1;
        }
      }
    }
  }

  // Beyond the paper: the two planes of a flat/curved chamfer edge (a, b)
  // must agree with the samples they are meant to explain. At a convex
  // crease (each end inside the other's plane) the local solid is the intersection of
  // the two half-spaces, so no outside sample of the sticks of a, b and
  // their 1-rings on the two sides may lie inside both planes; at a concave
  // one (each end outside) no inside sample may lie outside both. A curved
  // side's plane (its 2-ring secant or quadric tangent) can lean too far
  // where the estimate rounded the crease: on the fandisk its planes met
  // the flat's at 110-122 degrees where the true crease has 90, their line
  // lay 1-2 cells out, and the new vertex ended 1.3 voxels off the truth
  // with no sample crossed. Such a sample deeper than kWedgeSlack moves
  // the curved side's plane along its normal until the sample lies on it
  // (a flat's plane is the better fit and stays), and the edge vertex goes
  // to the new line when the other samples stay on their sides and it is
  // within max_move; otherwise it stays where it was inserted. False: stay.
  // Edges between two flats or two curved sides are not checked: left in
  // place there, box 128 seed 48 (faces 1.2 degrees off z) went from 0.013
  // to 0.69 voxel.
  bool sample_wedge(uint32_t a, uint32_t b, const Plane& pa, const Plane& pb, const Vec3& start, double floor2,
                    Vec3& target) {
    if ((label[a] < 0) == (label[b] < 0)) return true;  // two flats or two curved sides: no plane to move
    const double sa = pa.n.dot(x[b]) - pa.c, sb = pb.n.dot(x[a]) - pb.c;
    const int kind = sa < 0 && sb < 0 ? 1 : sa > 0 && sb > 0 ? -1 : 0;  // convex, concave, undecided
    if (kind == 0) return true;
    std::vector<uint32_t>& near = wedge_scratch;  // a, b and their 1-rings on the edge's two regions
    near.clear();
    for (uint32_t e : {a, b}) {
      near.push_back(e);
      for (uint32_t k = adj_off[e]; k < adj_off[e + 1]; ++k)
        if (label[adj[k]] == label[a] || label[adj[k]] == label[b]) near.push_back(adj[k]);
    }
    // The samples the solid must leave out (convex) or keep in (concave),
    // and how deep past both planes a sample lies.
    auto wrong = [&](uint32_t q) { return kind > 0 ? s.outside_sample(q) : s.inside_sample(q); };
    auto depth = [&](const Plane& A, const Plane& B, const Vec3& p) {
      const double da = A.n.dot(p) - A.c, db = B.n.dot(p) - B.c;
      return kind > 0 ? std::min(-da, -db) : std::min(da, db);
    };
    bool bad = false;
    for (uint32_t q : near) bad |= depth(pa, pb, wrong(q)) > kWedgeSlack;
    if (!bad) return true;
    ++st.wedge_checks;
    const bool a_curved = label[a] < 0;
    const Plane& A = a_curved ? pb : pa;  // the flat's
    Plane B = a_curved ? pa : pb;         // the curved side's, moved
    for (uint32_t q : near)
      if (depth(A, B, wrong(q)) > kWedgeSlack)
        B.c = kind > 0 ? std::min(B.c, B.n.dot(wrong(q))) : std::max(B.c, B.n.dot(wrong(q)));
    for (uint32_t q : near) {  // the other samples stay on their sides of the moved plane
      const double d = B.n.dot(kind > 0 ? s.inside_sample(q) : s.outside_sample(q)) - B.c;
      if (kind > 0 ? d > kWedgeSlack : d < -kWedgeSlack) return false;
    }
    const Plane pl[2] = {A, B};
    const Vec3 moved = solve_planes(pl, 2, start, floor2);
    if ((moved - start).norm() > detail::kMaxMove) return false;
    target = moved;
    ++st.wedge_shifts;
    return true;
  }
  static constexpr double kWedgeSlack = 0.1;  // cells: planes are good to ~0.05 (flats), so a sample must be deeper
  std::vector<uint32_t> wedge_scratch;

  // Figure 8: split the chamfer triangles; new vertices start on their
  // edges (the surface is unchanged until they move).
  void subdivide() {
    std::unordered_map<uint64_t, uint32_t> on_edge;
    const double floor2 = 1 - std::cos(detail::kMinAngle * kPi / 180);
    auto edge_vertex = [&](uint32_t a, uint32_t b) {
      auto [it, fresh] = on_edge.try_emplace(edge_key(a, b), kNone);
      if (!fresh) return it->second;
      ++st.chamfer_edges;
      NewVertex v;
      v.a = std::min(a, b);
      v.b = std::max(a, b);
      const Vec3 xa = x[v.a], xb = x[v.b];
      const Plane* pa = plane_of(v.a);
      const Plane* pb = plane_of(v.b);
      v.on_flats = label[v.a] >= 0 && label[v.b] >= 0;
      double u = 0.5;
      Vec3 start = xa + u * (xb - xa);
      if (pa && pb) {
        const Plane pl[2] = {*pa, *pb};
        // Start where the edge comes closest to both planes (least squares in u).
        double num = 0, den = 0;
        for (const Plane& p : pl) {
          const double g = p.n.dot(xb - xa), h = p.c - p.n.dot(xa);
          num += g * h;
          den += g * g;
        }
        if (den > 1e-12) u = std::clamp(num / den, 0.1, 0.9);
        start = xa + u * (xb - xa);
        const double angle = angle_deg(pa->n, pb->n);
        v.angle = angle;
        v.sharp = angle >= o.sharp_angle;
        if (1 - pa->n.dot(pb->n) >= floor2) {
          v.target = solve_planes(pl, 2, start, floor2);
          const bool curved = label[v.a] < 0 && label[v.b] < 0;  // a curved/curved crease
          v.moves = (v.target - start).norm() <= (curved ? std::min(kCurvedCreaseMove, detail::kMaxMove) : detail::kMaxMove);
          if (v.moves && o.passes.on(Pass::sample_wedges)) v.moves = sample_wedge(v.a, v.b, *pa, *pb, start, floor2, v.target);
          v.along = pa->n.cross(pb->n).normalized();
        }
      }
      if (!v.moves) {
        v.target = start;
        ++st.fallbacks;
      }
      return it->second = add_vertex(v, start);
    };
    for (size_t f = 0; f < s.triangles.size(); ++f) {
      const Triangle& t = s.triangles[f];
      uint32_t m[3];
      int k = 0;
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
        m[e] = chamfer(a, b) ? edge_vertex(a, b) : kNone;
        k += m[e] != kNone;
      }
      auto emit = [&](uint32_t a, uint32_t b, uint32_t c) { tris.push_back({a, b, c}); };
      if (k == 0) {
        emit(t[0], t[1], t[2]);
        continue;
      }
      ++st.chamfer_triangles;
      if (k == 1) {  // Fig. 8a: two triangles
        const int e = m[0] != kNone ? 0 : m[1] != kNone ? 1 : 2;
        const uint32_t pa = t[size_t(e)], pb = t[size_t((e + 1) % 3)], pc = t[size_t((e + 2) % 3)];
        emit(pa, m[e], pc);
        emit(m[e], pb, pc);
      } else if (k == 2) {  // Fig. 8b: three triangles; the apex is where the two chamfer edges meet
        const int free_edge = m[0] == kNone ? 0 : m[1] == kNone ? 1 : 2;
        const int apex = (free_edge + 2) % 3;
        const uint32_t p0 = t[size_t(apex)], p1 = t[size_t((apex + 1) % 3)], p2 = t[size_t((apex + 2) % 3)];
        const uint32_t m01 = m[apex], m20 = m[(apex + 2) % 3];
        emit(p0, m01, m20);
        if ((x[m01] - x[p2]).squaredNorm() <= (x[p1] - x[m20]).squaredNorm()) {
          emit(m01, p1, p2);
          emit(m01, p2, m20);
        } else {
          emit(m01, p1, m20);
          emit(p1, p2, m20);
        }
        feature_edges.push_back({m01, m20});
      } else {  // Fig. 8c: six triangles around a corner vertex
        NewVertex c;
        c.corner = true;
        const Vec3 start = (x[m[0]] + x[m[1]] + x[m[2]]) / 3;
        const Plane* p[3] = {plane_of(t[0]), plane_of(t[1]), plane_of(t[2])};
        c.on_flats = label[t[0]] >= 0 && label[t[1]] >= 0 && label[t[2]] >= 0;
        c.target = start;
        if (p[0] && p[1] && p[2]) {
          const Plane pl[3] = {*p[0], *p[1], *p[2]};
          c.target = solve_planes(pl, 3, start, floor2);
          c.moves = (c.target - start).norm() <= detail::kMaxMove;
          if (!c.moves) c.target = start;
        }
        // Beyond the paper: where a corner's third plane is missing (a
        // curved junction without a fit of its own, squeezed between two
        // flats), it goes onto the line of the other two; left at the
        // centroid, its three labelled edges made a spur off the crease
        // (CAD part 128 seed 128: 0.67 voxel off a crease of two flats).
        // Where all three planes meet too far away it stays: the line of
        // two flats then runs on past the end of their crease (seed 26:
        // 0.59 -> 0.66 voxel from any true crease had it moved there).
        if (!c.moves && (p[0] != nullptr) + (p[1] != nullptr) + (p[2] != nullptr) == 2) {
          const int i = p[0] ? 0 : 1, j = p[2] ? 2 : 1;
          if (1 - std::abs(p[i]->n.dot(p[j]->n)) >= floor2) {
            const Plane pl[2] = {*p[i], *p[j]};
            const Vec3 q = solve_planes(pl, 2, start, floor2);
            if ((q - start).norm() <= detail::kMaxMove) {
              c.target = q;
              c.moves = true;
              c.on_flats = label[t[size_t(i)]] >= 0 && label[t[size_t(j)]] >= 0;
            }
          }
        }
        if (!c.moves) ++st.fallbacks;
        c.sharp = true;
        const uint32_t w = add_vertex(c, start);
        ++st.corners;
        for (int e = 0; e < 3; ++e) {
          emit(t[size_t(e)], m[e], w);
          emit(m[e], t[size_t((e + 1) % 3)], w);
          feature_edges.push_back({w, m[e]});
        }
      }
    }
    st.inserted = nv.size() - st.corners;
  }

  // The cell of a grid of `side`-cell cubes that holds p.
  static std::array<int64_t, 3> grid_cell(const Vec3& p, int side) {
    return {int64_t(std::floor(p.x() / side)), int64_t(std::floor(p.y() / side)), int64_t(std::floor(p.z() / side))};
  }
  static uint64_t bucket_key(const std::array<int64_t, 3>& b) {
    return (uint64_t(b[0] + (1 << 20)) << 42) | (uint64_t(b[1] + (1 << 20)) << 21) | uint64_t(b[2] + (1 << 20));
  }

  // Triangles around every vertex, and the buckets of refined triangles
  // near the chamfers (for the local intersection test): those whose first
  // vertex lies within a kNearBlock-cell block of a triangle with a new vertex.
  void index() {
    const size_t nvert = x.size();
    fan_off.assign(nvert + 1, 0);
    for (const Triangle& t : tris)
      for (uint32_t v : t) ++fan_off[v + 1];
    for (size_t v = 0; v < nvert; ++v) fan_off[v + 1] += fan_off[v];
    fan.resize(fan_off[nvert]);
    std::vector<uint32_t> fill(fan_off.begin(), fan_off.end() - 1);
    for (uint32_t f = 0; f < tris.size(); ++f)
      for (uint32_t v : tris[f]) fan[fill[v]++] = f;
    std::unordered_map<uint64_t, uint8_t> near;
    for (size_t f = 0; f < tris.size(); ++f) {
      bool touches_new = false;
      for (uint32_t v : tris[f]) touches_new |= v >= n;
      if (!touches_new) continue;
      const auto b = grid_cell(x[tris[f][0]], kNearBlock);
      for (int64_t dz = -1; dz <= 1; ++dz)
        for (int64_t dy = -1; dy <= 1; ++dy)
          for (int64_t dx = -1; dx <= 1; ++dx) near[bucket_key({b[0] + dx, b[1] + dy, b[2] + dz})] = 1;
    }
    anchor.resize(tris.size());
    anchor_reach = 0;
    for (uint32_t f = 0; f < tris.size(); ++f) {
      anchor[f] = x[tris[f][0]].cast<float>();
      const Vec3 a = anchor[f].cast<double>();
      if (!near.count(bucket_key(grid_cell(a, kNearBlock)))) continue;
      buckets[bucket_key(grid_cell(a, kBucket))].push_back(f);
      for (uint32_t v : tris[f]) anchor_reach = std::max(anchor_reach, (x[v] - a).cwiseAbs().maxCoeff());
    }
  }

  // After v moved: its triangles' vertices may now lie farther from their
  // anchors, which widens every later search.
  void widen(uint32_t v) {
    for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k)
      anchor_reach = std::max(anchor_reach, (x[v] - anchor[fan[k]].cast<double>()).cwiseAbs().maxCoeff());
  }

  // May vertex v move from x[v] to q? (Section 5 beyond the paper: the
  // guarantee and a valid mesh.)
  bool allowed(uint32_t v, const Vec3& q) const {
    const Vec3 p = x[v];
    auto at = [&](uint32_t w) -> const Vec3& { return w == v ? q : x[w]; };
    Vec3 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
    for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k) {
      const Triangle& t = tris[fan[k]];
      const int i = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const Vec3& a = x[t[size_t((i + 1) % 3)]];
      const Vec3& b = x[t[size_t((i + 2) % 3)]];
      const Vec3 nn = (a - q).cross(b - q);
      if (!(nn.squaredNorm() > 1e-20) || nn.dot((a - p).cross(b - p)) <= 0) return false;  // turned over
      if (detail::triangle_degenerate(q, a, b) || detail::triangle_altitude(q, a, b) < delta) return false;
      lo = lo.cwiseMin(a).cwiseMin(b);
      hi = hi.cwiseMax(a).cwiseMax(b);
      // No lattice sample in the swept tetrahedron (p, q, a, b), nor within
      // the clearance of the moved triangle (q, a, b).
      const Vec3 tl = p.cwiseMin(q).cwiseMin(a).cwiseMin(b).array() - delta,
                 th = p.cwiseMax(q).cwiseMax(a).cwiseMax(b).array() + delta;
      for (double zz = std::ceil(tl.z()); zz <= th.z(); ++zz)
        for (double yy = std::ceil(tl.y()); yy <= th.y(); ++yy)
          for (double xx = std::ceil(tl.x()); xx <= th.x(); ++xx) {
            const Vec3 z(xx, yy, zz);
            if (in_closed_tet(p, q, a, b, z) || detail::point_triangle_distance2(z, q, a, b) <= delta * delta)
              return false;
          }
    }
    lo.array() -= delta;
    hi.array() += delta;
    // The fan does not fold onto itself, and no refined triangle nearby meets
    // it or comes within the clearance (boxes farther apart are).
    auto too_close = [&](const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3]) {
      const Vec3 alo = ta[0].cwiseMin(ta[1]).cwiseMin(ta[2]), ahi = ta[0].cwiseMax(ta[1]).cwiseMax(ta[2]);
      const Vec3 blo = tb[0].cwiseMin(tb[1]).cwiseMin(tb[2]), bhi = tb[0].cwiseMax(tb[1]).cwiseMax(tb[2]);
      if ((alo.array() > bhi.array() + delta).any() || (blo.array() > ahi.array() + delta).any()) return false;
      return detail::triangles_intersect(ta, ia, tb, ib) || detail::triangles_within(ta, ia, tb, ib, delta);
    };
    for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k)
      for (uint32_t k2 = k + 1; k2 < fan_off[v + 1]; ++k2) {
        const Triangle& t = tris[fan[k]];
        const Triangle& u = tris[fan[k2]];
        const Vec3 fb[3] = {at(t[0]), at(t[1]), at(t[2])};
        const Vec3 ub[3] = {at(u[0]), at(u[1]), at(u[2])};
        const uint32_t fi[3] = {t[0], t[1], t[2]}, ui[3] = {u[0], u[1], u[2]};
        if (too_close(fb, fi, ub, ui)) return false;
      }
    // A triangle meeting the box [lo, hi] has its anchor within anchor_reach
    // of it (plus a hair for the rounding of the differences).
    const Vec3 pad = Vec3::Constant(anchor_reach + 1e-6);
    const auto b0 = grid_cell(lo - pad, kBucket), b1 = grid_cell(hi + pad, kBucket);
    for (int64_t bz = b0[2]; bz <= b1[2]; ++bz)
      for (int64_t by = b0[1]; by <= b1[1]; ++by)
        for (int64_t bx = b0[0]; bx <= b1[0]; ++bx) {
          const auto it = buckets.find(bucket_key({bx, by, bz}));
          if (it == buckets.end()) continue;
          for (uint32_t g : it->second) {
            const Triangle& tg = tris[g];
            if (tg[0] == v || tg[1] == v || tg[2] == v) continue;
            const Vec3 gb[3] = {x[tg[0]], x[tg[1]], x[tg[2]]};
            const Vec3 glo = gb[0].cwiseMin(gb[1]).cwiseMin(gb[2]), ghi = gb[0].cwiseMax(gb[1]).cwiseMax(gb[2]);
            if ((glo.array() > hi.array()).any() || (ghi.array() < lo.array()).any()) continue;
            if (detail::triangle_degenerate(gb[0], gb[1], gb[2])) continue;
            const uint32_t gi[3] = {tg[0], tg[1], tg[2]};
            for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k) {
              const Triangle& t = tris[fan[k]];
              const Vec3 fb[3] = {at(t[0]), at(t[1]), at(t[2])};
              const uint32_t fi[3] = {t[0], t[1], t[2]};
              if (too_close(fb, fi, gb, gi)) return false;
            }
          }
        }
    return true;
  }

  // Moves v to q if allowed; otherwise, when `partial`, as far towards q as
  // allowed (bisection on the fraction: the allowed fractions form an
  // interval from 0, as the swept tetrahedra nest). Returns true at q.
  bool move(uint32_t v, const Vec3& q, bool partial = true) {
    const Vec3 p = x[v];
    if (q == p) return true;
    if (allowed(v, q)) {
      x[v] = q;
      widen(v);
      return true;
    }
    if (!partial) return false;
    ++st.cut_back;
    double lo = 0, hi = 1;
    for (int i = 0; i < kBisections; ++i) {
      const double mid = (lo + hi) / 2;
      (allowed(v, p + mid * (q - p)) ? lo : hi) = mid;
    }
    if (lo > 0) {
      x[v] = p + lo * (q - p);
      widen(v);
    }
    return false;
  }

  // The chains: each new vertex's neighbours along the new edges.
  std::vector<std::array<uint32_t, 2>> chain_nb;
  std::vector<uint8_t> chain_degree;
  void build_chains() {
    const size_t m = nv.size();
    chain_nb.assign(m, {kNone, kNone});
    chain_degree.assign(m, 0);
    for (const auto& e : feature_edges)
      for (int k = 0; k < 2; ++k) {
        const uint32_t a = e[size_t(k)] - uint32_t(n), b = e[size_t(1 - k)];
        if (chain_degree[a] < 2) chain_nb[a][chain_degree[a]] = b;
        ++chain_degree[a];
      }
  }
  bool inner(uint32_t i) const { return chain_degree[i] == 2 && !nv[i].corner; }

  // Beyond the paper: targets on an intersection line are the projections
  // of where the vertices were inserted, which bunch up (or even swap) where
  // the staircase runs across the crease, folding the triangles between
  // them. Before moving, inner chain vertices slide along their line towards
  // the mean of their neighbours' targets (Jacobi, a few rounds), which
  // evens out their spacing without leaving the line.
  void spread_targets() {
    std::vector<Vec3> next(nv.size());
    for (int it = 0; it < 10; ++it) {
      for (uint32_t i = 0; i < nv.size(); ++i) {
        next[i] = nv[i].target;
        if (!inner(i) || !nv[i].moves || nv[i].along.isZero()) continue;
        const uint32_t a = chain_nb[i][0] - uint32_t(n), b = chain_nb[i][1] - uint32_t(n);
        const Vec3 d = (nv[a].target + nv[b].target) / 2 - nv[i].target;
        next[i] += 0.5 * d.dot(nv[i].along) * nv[i].along;
      }
      for (uint32_t i = 0; i < nv.size(); ++i) nv[i].target = next[i];
    }
  }

  // Section 5, last paragraph: the new vertices form chains along the new
  // edges; chain vertices (not ends, not corners) are smoothed with a
  // bilaplacian, moving across the chain only and within a flat's plane.
  void smooth_chains() {
    const size_t m = nv.size();
    std::vector<Vec3> L(m), step(m);
    for (int it = 0; it < detail::kChainIterations; ++it) {
      for (uint32_t i = 0; i < m; ++i)
        L[i] = inner(i) ? Vec3((x[chain_nb[i][0]] + x[chain_nb[i][1]]) / 2 - x[n + i]) : Vec3::Zero();
      for (uint32_t i = 0; i < m; ++i) {
        step[i].setZero();
        if (!inner(i)) continue;
        const NewVertex& v = nv[i];
        const int32_t ra = label[v.a], rb = label[v.b];
        if (ra >= 0 && rb >= 0) continue;  // on the exact line of two flats
        // -L^2 = L(v) - mean of the neighbours' L; 1/4 damps a zigzag in one step.
        Vec3 d = 0.25 * (L[i] - (L[chain_nb[i][0] - n] + L[chain_nb[i][1] - n]) / 2);
        const Vec3 tangent = (x[chain_nb[i][1]] - x[chain_nb[i][0]]).normalized();
        d -= d.dot(tangent) * tangent;
        if (ra >= 0 || rb >= 0) {
          const Vec3& fn = seg.flats[size_t(ra >= 0 ? ra : rb)].index_normal;
          d -= d.dot(fn) * fn;
        }
        step[i] = d;
      }
      for (uint32_t i = 0; i < m; ++i)
        if (step[i].squaredNorm() > 0) move(uint32_t(n + i), x[n + i] + step[i]);
    }
  }

  SharpenResult run() {
    const auto t0 = std::chrono::steady_clock::now();
    detail::vertex_adjacency(n, s.triangles, adj_off, adj);
    x.resize(n);
    for (size_t v = 0; v < n; ++v) x[v] = s.index_position(v);
    plane_state.assign(n, 0);
    on_wall.assign(n, 0);
    plane.resize(n);
    label = seg.region;
    junction = seg.junction;
    junction.resize(n, 0);
    // Each step timed as its pass (the base steps as `sharpen`).
    auto timed = [&](Pass p, auto&& step) {
      const auto t = std::chrono::steady_clock::now();
      step();
      st.passes.add(p, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    };
    if (!seg.flats.empty()) {
      timed(Pass::snap, [&] { snap_to_flats(); });
      timed(Pass::strips, [&] { join_leftovers(); });
      timed(Pass::inherit_junctions, [&] { inherit_junctions(); });
      timed(Pass::walls, [&] { fit_walls(); });
      timed(Pass::final_crease, [&] { final_crease_fit(); });
      timed(Pass::past_crease, [&] { past_creases(); });
      timed(Pass::curved_creases, [&] { curved_creases(); });
      timed(Pass::sharpen, [&] { subdivide(); });
    } else {
      tris = s.triangles;
    }
    if (!nv.empty()) {
      index();
      build_chains();
      spread_targets();
      // The moves, in order: leftovers onto their flat, edge vertices onto
      // their crease, then corners (Section 5). A move blocked by a
      // neighbour that has not moved yet is retried in the next round; from
      // round kRounds on, the remaining moves are cut back to what is
      // allowed; those whose target lies on flats' planes only are retried
      // (neighbours' cut-back moves may unblock them) while any vertex still
      // advances, for up to kRounds more rounds. Targets from a curved
      // side's fit are not pushed further (a leaning curved side's plane
      // would carry the vertex past the truth).
      std::vector<std::pair<uint32_t, Vec3>> jobs;
      std::vector<uint8_t> retry;
      for (uint32_t v : leftovers) {
        jobs.push_back({v, x[v] - height(label[v], x[v]) * seg.flats[size_t(label[v])].index_normal});
        retry.push_back(1);
      }
      for (int corners = 0; corners < 2; ++corners)
        for (size_t i = 0; i < nv.size(); ++i)
          if (nv[i].moves && nv[i].corner == bool(corners)) {
            jobs.push_back({uint32_t(n + i), nv[i].target});
            retry.push_back(nv[i].on_flats);
          }
      std::vector<uint8_t> done(jobs.size(), 0);
      // Neighbours that block each other (two vertices of one thin triangle)
      // get there together: a blocked vertex goes half way instead.
      for (int round = 0; round < 2 * kRounds; ++round) {
        const bool cut = round + 1 >= kRounds;
        bool advanced = false;
        for (size_t j = 0; j < jobs.size(); ++j) {
          if (done[j] || (round >= kRounds && !retry[j])) continue;
          const uint32_t v = jobs[j].first;
          const Vec3 before = x[v];
          done[j] = move(v, jobs[j].second, cut);
          if (!done[j] && !cut) move(v, (x[v] + jobs[j].second) / 2, false);
          advanced |= (x[v] - before).squaredNorm() > kAdvance * kAdvance;
        }
        if (cut && !advanced) break;
      }
      smooth_chains();
    }
    SharpenResult r;
    r.mesh = output();
    st.passes.count[size_t(Pass::snap)] = st.snapped;
    st.passes.count[size_t(Pass::walls)] = st.wall_vertices;
    st.passes.count[size_t(Pass::final_crease)] = st.final_crease_vertices;
    st.passes.count[size_t(Pass::past_crease)] = st.past_crease + st.left_flat;
    st.passes.count[size_t(Pass::inherit_junctions)] = st.inherited_junctions;
    st.passes.count[size_t(Pass::curved_creases)] += st.curved_crease_vertices;
    st.passes.count[size_t(Pass::tangent_planes)] = st.tangent_planes;
    st.passes.count[size_t(Pass::sample_wedges)] = st.wedge_shifts;
    st.passes.count[size_t(Pass::sharpen)] = st.inserted;
    st.sharp_edges = r.mesh.edges.size();
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double others = 0;
    for (size_t p = 0; p < size_t(Pass::count); ++p)
      if (Pass(p) != Pass::sharpen) others += st.passes.seconds[p];
    st.passes.seconds[size_t(Pass::sharpen)] = st.seconds - others;
    r.stats = st;
    return r;
  }

  Mesh output() const {
    Mesh m;
    const Mat3 M = s.lattice.index_to_physical_matrix();
    m.positions.resize(x.size());
    for (size_t v = 0; v < x.size(); ++v) m.positions[v] = s.lattice.origin + M * x[v];
    m.triangles = tris;
    if (s.lattice.flips_orientation())
      for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
    MeshAttribute region{"region", ScalarType::i32, std::vector<double>(x.size(), -1)};
    MeshAttribute junction_flag{"junction", ScalarType::u8, std::vector<double>(x.size(), 0)};
    MeshAttribute feature{"feature", ScalarType::u8, std::vector<double>(x.size(), 0)};
    for (size_t v = 0; v < n; ++v) {
      region.values[v] = label[v];
      junction_flag.values[v] = junction[v];
    }
    // Sharp feature edges: new edges whose edge vertex lies on a sharp crease.
    for (const auto& e : feature_edges) {
      const NewVertex& a = nv[e[0] - n];
      const NewVertex& b = nv[e[1] - n];
      const bool sharp = (a.corner || a.sharp) && (b.corner || b.sharp);
      if (!sharp) continue;
      m.edges.push_back(e);
      feature.values[e[0]] = feature.values[e[1]] = 1;
    }
    // A face belongs to flat f when all its original vertices do (so flats'
    // faces are planar); otherwise it is curved.
    MeshAttribute face_region{"region", ScalarType::i32, std::vector<double>(tris.size(), -1)};
    for (size_t f = 0; f < tris.size(); ++f) {
      int32_t r = -2;
      for (uint32_t v : tris[f]) {
        if (v >= n) continue;
        const int32_t rv = label[v];
        r = r == -2 || r == rv ? rv : -1;
      }
      face_region.values[f] = r < 0 ? -1 : r;
    }
    if (o.colors) {
      m.colors.resize(x.size());
      for (size_t v = 0; v < x.size(); ++v)
        m.colors[v] = feature.values[v] ? std::array<uint8_t, 4>{200, 20, 20, 255}
                                        : region_color(int32_t(region.values[v]), junction_flag.values[v] != 0);
    }
    m.vertex_attributes = {std::move(region), std::move(junction_flag), std::move(feature)};
    m.face_attributes = {std::move(face_region)};
    return m;
  }
};

}  // namespace

SharpenResult sharpen(const StickSurface& surface, const FlatSegmentation& flats, const SharpenOptions& options) {
  if (!flats.region.empty() && flats.region.size() != surface.stick_count())
    throw std::invalid_argument("sharpen: segmentation does not match the surface");
  FlatSegmentation none;  // no segmentation: every vertex curved
  if (flats.region.empty()) none.region.assign(surface.stick_count(), -1);
  Sharpener sh(surface, flats.region.empty() ? none : flats, options);
  return sh.run();
}

}  // namespace voxpress
