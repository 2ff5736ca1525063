// Private to the sharpening (Section 5): the Sharpener — the state of one
// sharpen() call, on which Stage::sharpen's passes run (the table in
// passes.cpp; their steps beside their code): sharpen_labels.cpp (regions
// and planes), sharpen_creases.cpp (walls, crease fits, curved creases),
// sharpen_moves.cpp (subdivision and the checked move), sharpen_chains.cpp
// (round chains) and sharpen.cpp (the run, the moves and the output). Index space throughout. Theory of operation:
// include/voxpress/features/sharpen.h.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <unordered_map>

#include <tbb/enumerable_thread_specific.h>

#include "core/clearance.h"
#include "core/predicates.h"
#include "core/sentinel.h"
#include "crease_fit.h"
#include "feature_tuning.h"
#include "smooth/quadric.h"
#include "smooth/stick_solid.h"
#include "smooth/surface_graph.h"

#include "voxpress/features/sharpen.h"

namespace voxpress::sharpen_impl {

using detail::degrees_between;
using detail::kNone;
using detail::Plane;
constexpr double kPi = std::numbers::pi;
constexpr int kBucket = 2;       // cells per side of the buckets of the local intersection test
constexpr int kNearBlock = 4;    // cells per side of the blocks that decide which triangles it sees
constexpr int kBisections = 8;   // steps when a move is cut back
// Cells: a new vertex on a crease between two curved faces moves at most
// this far (their tangent planes are fitted, not detected; the bunny's false
// creases lay up to 2 cells off: build/bench/bench_compare, bunny.off).
constexpr double kCurvedCreaseMove = 0.5;
constexpr int kRounds = 8;       // passes over the new vertices' moves (then up to as many cutting back)
constexpr double kAdvance = 1e-3;  // cells: a cut-back round where no vertex advances more is the last
// join_leftovers' marks of curved vertices that join a flat.
constexpr uint8_t kLeftover = 1;  // joins and is projected onto the flat's plane
constexpr uint8_t kStrip = 2;     // joins the label only (thin_strips)
constexpr uint8_t kRimStrip = 3;  // in a strip's pocket next to a curved face (thin_strips)

inline uint64_t edge_key(uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); }

// Is z in the closed tetrahedron (a, b, c, d)? A flat tetrahedron counts z
// when z is coplanar with it (conservative).
inline bool in_closed_tet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z) {
  const int o = detail::orient3d(a, b, c, d);
  if (o == 0) return detail::orient3d(a, c, d, z) == 0 || detail::orient3d(b, c, d, z) == 0;
  return detail::tetrahedron_side(a, b, c, d, z, o) >= 0;
}

// The point nearest x0 that best satisfies the planes in the least-squares
// sense: x0 + pinv(A) (b - A x0) with A = sum n n^T, b = sum n c, and
// eigenvalues below `floor` truncated (those directions keep x0) — the
// dual-contouring QEF solve. For two planes it is the closest point of their
// intersection line to x0; for three, their common point.
Vec3 solve_planes(const Plane* planes, int count, const Vec3& x0, double floor);  // features/sharpen.cpp

struct NewVertex {
  uint32_t a = kNone, b = kNone;  // edge vertex: the chamfer edge's ends; corner: kNone
  bool corner = false;            // a corner vertex (three chamfer edges), not an edge vertex
  Vec3 target = Vec3::Zero();
  Vec3 along = Vec3::Zero();      // edge vertex between two planes: their intersection line's direction
  bool moves = false;             // has a target away from where it was inserted
  bool sharp = false;             // on a labelled sharp crease
  bool on_flats = false;          // its target lies on flats' planes only (not a curved side's fit)
  double angle = 0;               // edge vertex: degrees between its two planes' normals
  double u = 0.5;                 // edge vertex: inserted at x[a] + u (x[b] - x[a])
  std::array<uint32_t, 3> from{kNone, kNone, kNone};  // corner: its three edge vertices
};


struct Sharpener {
  const StickSurface& s;
  const FlatSegmentation& seg;
  const SharpenOptions& o;
  size_t n = 0;
  Mat3 Minv_t;
  const std::vector<uint32_t>& adj_off;     // original vertex adjacency: the surface's, built once
  const std::vector<uint32_t>& adj;
  std::vector<Vec3> x;                      // positions (index space): original, then new
  std::vector<Triangle> tris;               // the refined triangles
  std::vector<NewVertex> nv;                // new vertex n + k
  std::vector<std::array<uint32_t, 2>> feature_edges;  // new edges between new vertices
  std::vector<int32_t> label;               // per original vertex: flat id or -1 (seg.region + leftovers)
  std::vector<uint32_t> leftovers;          // curved junction vertices that joined a flat
  std::vector<uint8_t> junction;            // per original vertex: seg.junction, and the rim pockets' (join_leftovers)
  std::vector<int8_t> plane_state;          // per original vertex: 0 unknown, 1 has plane, -1 none
  std::vector<uint8_t> on_wall;             // per original vertex: 1 placed on a thin wall's plane (sharpen_walls.cpp)
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
  // Part of a larger surface (labels/shared_sharpen.cpp; null: all): chamfer edges
  // only between two `editable` triangles; `fixed` original vertices never move.
  const std::vector<uint8_t>*editable = nullptr, *fixed = nullptr;
  std::vector<uint32_t> parent;  // per refined triangle: the original triangle it came from

  Sharpener(const StickSurface& surface, const FlatSegmentation& f, const SharpenOptions& opts,
            const detail::Adjacency& graph)
      : s(surface), seg(f), o(opts), n(surface.stick_count()), adj_off(graph.off), adj(graph.adj) {
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
    return detail::leave(p, s.inside_sample(v), s.outside_sample(v));
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
    if (fixed && (*fixed)[v]) return;
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
    if (!o.passes.on(Pass::tangent_planes)) return false;  // a rule
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
  const Plane* plane_of(uint32_t v);

  // Section 5's plane of a curved vertex: the least-squares plane of the
  // fresh, non-junction vertices in its 2-ring (all fresh ones when fewer
  // than 3); false when there are fewer than 3 or they are collinear.
  bool ring_plane(uint32_t v, Plane& out) const;

  // Section 5: an edge whose ends lie on two different faces (two flats, or
  // a flat and a curved junction vertex; beyond the paper, the two sides of
  // a curved/curved crease, curved_creases).
  bool chamfer(uint32_t u, uint32_t v) const;

  // Marks (kStrip) the curved vertices of thin strips: a vertex at most
  // `strip_rings` rings (over curved vertices) from a flat whose curved
  // neighbours within `strip_rings` rings are all that close too. The
  // flats' rims stop a few rings short of a crease the estimate rounded
  // widely (the CAD part's 45-degree chamfer: strips 3-5 vertices wide, so
  // neither side is a junction and the crease had no chamfer edge at all),
  // and of a face crossed by a lattice row nearly in its plane. A real
  // curved face is deeper than that a few rings in, so only its ragged
  // border's pockets could qualify (2 rings measured best; the pass's effect:
  // the `strips` row of build/bench/bench_ablation). Strip vertices join a
  // flat's label but are not projected onto its plane: on the fandisk, whose
  // flats include gently curved faces, the projection cost more accuracy
  // than it gained.
  // A thin vertex with a curved vertex within `strip_rings` rings that is
  // not thin itself is in a pocket of a flat's ragged rim next to a real
  // curved face (kRimStrip), not in a strip between flats: join_leftovers
  // lets it join only when the flat's plane crosses its stick.
  void thin_strips(std::vector<uint8_t>& mark);
  // Beyond the paper (round-strips, issue 75): a strip is judged as a whole,
  // with its pockets: a resolved fillet between two flats stays curved.
  // See sharpen_labels.cpp. Returns the strips kept curved.
  size_t round_strips(std::vector<uint8_t>& mark);

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
        at = detail::leave_heights(h0, h1);
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
  void snap_to_flats();

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
  void join_leftovers();

  // Beyond the paper: a curved junction that joined a flat (snap_to_flats,
  // join_leftovers) and lies on its plane moved the flat's border onto its
  // curved neighbours, so those that pass Section 3's junction test (their
  // 2-ring plane meets the flat at sharp_angle or more) become junctions,
  // as past_creases does for its joins. Otherwise their edges to the joined
  // vertex are no chamfer edges (chamfer()) and the sharp curve has a gap
  // there. A thin strip's vertex joins off the plane (join_leftovers)
  // and moves no border: at 64^3 its heirs labelled a false crease.
  void inherit_junctions();
  // Section 3's junction test on the border a vertex v that joined a flat
  // moved: its curved, non-junction neighbours whose 2-ring plane meets the
  // flat's at sharp_angle or more are appended to `out`.
  void sharp_neighbours(uint32_t v, std::vector<uint32_t>& out) const;
  // The flat of v's 1-ring members whose plane is nearest to v (-1: none),
  // and that distance.
  int32_t nearest_neighbour_flat(uint32_t v, double& distance) const;
  // Makes them junctions; returns how many were not yet.
  size_t mark_junctions(const std::vector<uint32_t>& vertices);

  uint32_t add_vertex(const NewVertex& v, const Vec3& at);

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
  void final_crease_fit();

  // past_creases: how much sooner (cells along the stick) a member's stick
  // must leave the solid on the curved side's plane. 0.2 left the labels
  // farther from the true creases at 128^3 (mean labelled -> true 0.746 /
  // 0.621 on the CAD part / cylinders, against 0.737 / 0.567).
  static constexpr double kLeaveMargin = 0.05;

  // +1 when the non-junction curved vertices within 2 rings of v lie below
  // flat f's plane (a convex crease; at least 3 to 1), -1 above, else 0.
  int crease_kind_near(uint32_t v, int32_t f, std::vector<uint32_t>& ring) const;

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
  //    below it leaves the solid on the flat's plane (leaves_at; left
  //    curved, the chain detours around such a vertex). A stick nearly
  //    parallel to the flat may not cross its plane at all (the chain
  //    then loops out to vertices at a sample a voxel from the crease):
  //    when the vertex
  //    lies within kPastSample of the flat's plane and more than that
  //    inside the side's half-space (outside at a concave crease), it joins
  //    where it is.
  //  * A flat member next to a curved junction, whose side's tangent plane
  //    meets the flat at sharp_angle or more, leaves the flat when its stick
  //    leaves the solid on that tangent plane at least kLeaveMargin before
  //    the flat's plane; it slides there.
  // The curved neighbours of a joined vertex, and a leaving vertex, become
  // junctions.
  void past_creases();

  // Beyond the paper: creases between two curved faces (fandisk). Once the
  // labels are final, the band vertices of such creases are placed again by
  // their two sides' quadrics (detail::curved_crease_targets, as in
  // press_with_flats' rounds), along their sticks; each keeps its side's
  // tangent plane, and a curved neighbour whose normal is closer to the
  // other side's takes that one. Edges between two such vertices whose
  // planes meet at `sharp_angle` or more are chamfer edges (chamfer()), so
  // subdivide() inserts the crease as for a flat border.
  std::vector<uint8_t> crease_side;  // per original vertex: 1 placed on a curved crease, 2 its other side's neighbour
  void curved_creases();

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
  // Edges between two flats or two curved sides are not checked (a chamfer
  // between faces a degree off an axis, left in place, lies most of a voxel
  // from the crease).
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
  void subdivide();

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
  void index();

  // After v moved: its triangles' vertices may now lie farther from their
  // anchors, which widens every later search.
  void widen(uint32_t v);

  // May vertex v move from x[v] to q? (Section 5 beyond the paper: the
  // guarantee and a valid mesh.)
  bool allowed(uint32_t v, const Vec3& q) const;

  // Moves v to q if allowed; otherwise, when `partial`, as far towards q as
  // allowed (bisection on the fraction: the allowed fractions form an
  // interval from 0, as the swept tetrahedra nest). Returns true at q.
  bool move(uint32_t v, const Vec3& q, bool partial = true);

  // The chains: each new vertex's neighbours along the new edges.
  std::vector<std::array<uint32_t, 2>> chain_nb;
  std::vector<uint8_t> chain_degree;
  void build_chains();
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

  void judge_chains();  // beyond the paper: resolved fillets stay round (sharpen_chains.cpp)
  std::vector<std::pair<uint32_t, Vec3>> pocket_slides;  // slid rim pockets and where they were

  // Section 5, last paragraph: the new vertices form chains along the new
  // edges; chain vertices (not ends, not corners) are smoothed with a
  // bilaplacian, moving across the chain only and within a flat's plane.
  void smooth_chains();

  // Stage::sharpen's passes (the table in passes.cpp), then the output.
  SharpenResult run();
  // The moves pass: the leftovers onto their flats, the new vertices onto
  // their creases (each move checked), then the chains smoothed; returns
  // the moves that reached their target.
  size_t move_all();

  Mesh output() const;
};

}  // namespace voxpress::sharpen_impl
