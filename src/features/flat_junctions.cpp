// Flats' junctions and borders (Chica et al., Section 3, and beyond the
// paper): Stage::detect's passes after the growth (find_flats.cpp). The
// junction test, the extension of the flats to their sharp edges
// (junctions), the rim's release from tangent fillets (rim-tangent), the
// flats' sizes and the barriers. Theory of
// operation: include/voxpress/features/flats.h.
#include "core/timing.h"
#include "feature_context.h"
#include "flat_detector.h"
#include "flat_geometry.h"
#include "smooth/quadric.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include "core/parallel.h"

namespace voxpress::flats_impl {

namespace {

// The tangent and junction tests' rings: fresh vertices (in no flat).
struct Fresh {
  const std::vector<int32_t>& region;
  bool operator()(uint32_t w) const { return region[w] < 0; }
};

// The flat of v's first frozen neighbour, or -1.
int32_t first_flat(const FlatsContext& ctx, size_t v) {
  const Surface& S = ctx.S;
  int32_t f0 = -1;
  for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1] && f0 < 0; ++k) f0 = ctx.seg.region[S.adj[k]];
  return f0;
}

// Beyond the paper: whether the curved side of fresh vertex v continues
// flat f tangentially within `cos_max`: a quadric fitted to the fresh
// vertices kTangentRings away (on the estimate) fits within
// tangent_residual and its normal, where v projects onto the flat, is
// within that angle of the flat's. A fillet passes; at a true crease the
// estimate is rounded, so the fit is poor or its normal there leans. With
// min_rise > 0 the fitted points must also reach that many cells off the
// flat's plane.
bool tangent(const FlatsContext& ctx, uint32_t v, int32_t f, double cos_max, double min_rise, detail::RingScratch& rs,
             std::vector<Vec3>& pts) {
  const Surface& S = ctx.S;
  const Mat3& M = ctx.M;
  detail::rings_around(v, kTangentRings[1], S.adj_off, S.adj, Fresh{ctx.seg.region}, rs);
  pts.clear();
  Vec3 outward = Vec3::Zero();
  for (const auto& [w, d] : rs.out)
    if (d >= kTangentRings[0]) {
      pts.push_back(M * S.x[w]);
      outward += M * (S.outside(w) - S.inside(w));
    }
  detail::Quadric Q;
  const Flat& F = ctx.seg.flats[size_t(f)];
  if (min_rise > 0) {
    double rise = 0;
    for (const auto& [w, d] : rs.out)
      if (d >= kTangentRings[0]) rise = std::max(rise, std::abs(ctx.height(F, S.x[w])));
    if (rise < min_rise * ctx.cell) return false;
  }
  if (!Q.fit(pts, outward) || Q.residual > detail::kTangentResidual * ctx.cell) return false;
  const Vec3 foot = M * S.x[v] - ctx.height(F, S.x[v]) * F.normal;
  return std::abs(Q.normal_at(foot).dot(F.normal)) >= cos_max;
}

// Whether fresh vertex v, next to flat f0 (its first frozen neighbour's),
// is a junction: the plane of its fresh 2-ring leans past junction_angle
// from a neighbouring flat, and (tangent-borders) the curved side does not
// continue that flat tangentially. Counts the smooth borders and the
// off-plane junction planes into ctx.
bool is_junction(FlatsContext& ctx, size_t v, int32_t f0, detail::RingScratch& rs, std::vector<Vec3>& pts) {
  const Surface& S = ctx.S;
  const FlatSegmentation& seg = ctx.seg;
  const FlatOptions& o = ctx.o;
  const Mat3& M = ctx.M;
  // Fresh vertices of the 2-ring (v included), in physical space.
  detail::rings_around(uint32_t(v), 2, S.adj_off, S.adj, Fresh{seg.region}, rs);
  bool sharp = true;  // too few fresh vertices for a plane: squeezed between flats
  if (rs.out.size() >= 3) {
    pts.clear();
    // Beyond the paper: fresh vertices on the plane of v's (first)
    // flat are its rim stopped short, not the curved side. Left in,
    // where a rim stopped a cell or two short of a crease the plane
    // leaned halfway between the two sides, under junction_angle
    // (a boss's rim), so no junction
    // marked the crease and the flat never reached it. Without them
    // the points can be a thin row along the crease, whose plane is
    // any plane through it (the crease refit then moves the face
    // by its error); then all of them are used.
    Pca q;
    bool off_plane = false;  // q is the plane of the points off the flat's plane
    if (o.passes.on(Pass::ring_off_plane)) {
      const Flat& F = seg.flats[size_t(f0)];
      for (const auto& [w, d] : rs.out) {
        if (w == v || std::abs(ctx.height(F, S.x[w])) > detail::kJunctionRingOffPlane * ctx.cell)
          pts.push_back(M * S.x[w]);
      }
      if (pts.size() >= 3) {
        q = pca(pts);
        off_plane = q.eigenvalues(1) >= kThinRow * q.eigenvalues(2);
        if (off_plane) ++ctx.off_plane_junctions;
      }
    }
    if (!off_plane) {
      pts.clear();
      for (const auto& [w, d] : rs.out) pts.push_back(M * S.x[w]);
      q = pca(pts);
    }
    if (q.eigenvalues(1) > 1e-9 * std::max(1.0, q.eigenvalues(2))) {  // not collinear
      const Vec3 ns = q.normal;
      // The neighbouring flats the plane leans past the angle from.
      std::array<int32_t, 4> leaning{};
      size_t leaning_count = 0;
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
        const int32_t f = seg.region[S.adj[k]];
        if (f < 0 || std::abs(ns.dot(seg.flats[size_t(f)].normal)) >= ctx.cos_j) continue;
        if (std::find(leaning.begin(), leaning.begin() + leaning_count, f) == leaning.begin() + leaning_count &&
            leaning_count < leaning.size())
          leaning[leaning_count++] = f;
      }
      // Beyond the paper: a curved face tangent to the flat (a
      // fillet) leans past the angle a couple of rings from the border
      // once the flat's rim has reached onto it. The estimate is not
      // rounded there (there is no crease to round), so the tangent
      // test's quadric is good and its normal at the flat is the
      // flat's: smooth. Each flat is judged on its own: a fillet
      // tangent to one flat can meet another at a crease (a
      // vertex between two flats can lean 35 degrees from one and 75
      // from the other: judging the tangent one alone leaves a gap
      // in the other's crease).
      sharp = false;
      for (size_t i = 0; i < leaning_count && !sharp; ++i)
        sharp = !(o.passes.on(Pass::tangent_borders) && tangent(ctx, uint32_t(v), leaning[i], ctx.cos_j, 0, rs, pts));
      if (!sharp && leaning_count > 0) ++ctx.smooth_borders;
    }
  }
  return sharp;
}

// Beyond the paper (round-borders, issue 75): a border the lattice
// resolves as a fillet is no crease. Junction vertices are grouped into
// chains (connected junctions between the same two flats: v's first flat
// and the flat nearest v within kRoundBorderRings rings). A chain's samples
// bound how round the edge of the two planes may be (cutting_radius, as
// round-chains judges the sharpening's chains: at a convex edge no inside
// sample of the chain's sticks and their 1-rings may lie outside the
// fillet, at a concave one no outside sample), and must demand a rounding
// they allow (a sample of the other kind kRoundEvidence inside both planes
// that such a fillet cuts off; near a corner a third face cuts off samples
// no fillet of the two planes reaches: releasing those short chains had
// left the CAD part's sharp edges unlabelled at their ends, RoundingEvidence::
// round_between, `build/bench/bench_compare --quick --only pressing`). A chain
// allowing kRoundBorderRadius or more is a resolved fillet: its vertices
// are no junctions, so the extension does not freeze the fillet's start
// onto a flat's plane (at r = 2-3 cells that flattening was most of the
// error with and without sharpening). Chains beside one flat are judged by
// round_one_flat_borders. Returns the vertices released.
size_t round_one_flat_borders(FlatsContext& ctx, const std::vector<std::array<int32_t, 2>>& pair);

// The connected vertices w from v0 that same(w) admits and `seen` does not
// hold yet, v0 first (all marked seen): a chain of junctions.
template <class Same>
void grow_chain(const Surface& S, uint32_t v0, Same same, std::vector<uint8_t>& seen, std::vector<uint32_t>& chain) {
  chain.assign(1, v0);
  seen[v0] = 1;
  for (size_t k = 0; k < chain.size(); ++k)
    for (uint32_t q = S.adj_off[chain[k]]; q < S.adj_off[chain[k] + 1]; ++q)
      if (const uint32_t w = S.adj[q]; !seen[w] && same(w)) seen[w] = 1, chain.push_back(w);
}

size_t round_borders(FlatsContext& ctx) {
  const Surface& S = ctx.S;
  FlatSegmentation& seg = ctx.seg;
  const size_t n = ctx.n;
  std::vector<std::array<int32_t, 2>> pair(n, {-1, -1});
  detail::parallel_ranges(n, 256, [&](detail::IndexRange r) {
    detail::RingScratch& rs = ctx.scratch.local();
    for (size_t v = r.begin(); v < r.end(); ++v) {
      if (!seg.junction[v]) continue;
      const int32_t f0 = first_flat(ctx, v);
      if (f0 < 0) continue;
      detail::rings_around(uint32_t(v), uint32_t(detail::kRoundBorderRings), S.adj_off, S.adj, [](uint32_t) { return true; }, rs);
      int32_t g = -1;
      uint32_t best = UINT32_MAX;
      for (const auto& [w, d] : rs.out)
        if (const int32_t f = seg.region[w]; f >= 0 && f != f0 && (d < best || (d == best && f < g))) g = f, best = d;
      if (g >= 0) pair[v] = {std::min(f0, g), std::max(f0, g)};
    }
  });
  std::vector<uint8_t> seen(n, 0);
  std::vector<uint32_t> chain;
  size_t released = 0;
  for (uint32_t v0 = 0; v0 < n; ++v0) {
    if (!seg.junction[v0] || seen[v0] || pair[v0][0] < 0) continue;
    grow_chain(S, v0, [&](uint32_t w) { return seg.junction[w] && pair[w] == pair[v0]; }, seen, chain);
    const Flat& FA = seg.flats[size_t(pair[v0][0])];
    const Flat& FB = seg.flats[size_t(pair[v0][1])];
    const Plane A{FA.index_normal, FA.index_offset}, B{FB.index_normal, FB.index_offset};
    const int kind = detail::edge_kind(A, B, chain, [&](uint32_t v) { return S.x[v]; });
    if (kind == 0) continue;
    detail::RoundingEvidence evidence;
    evidence.add_rings(A, B, kind, chain, S.adj_off, S.adj, [&](uint32_t w) { return S.inside(w); },
                       [&](uint32_t w) { return S.outside(w); });
    if (!evidence.round_between(detail::kRoundBorderRadius)) continue;
    for (uint32_t v : chain) seg.junction[v] = 0;
    released += chain.size();
  }
  return released + round_one_flat_borders(ctx, pair);
}

// The plane of flat F's curved side: the fresh vertices of `ring` (a
// vertex's fresh rings, rings_around's output) at ring distance [lo, hi]
// off F's plane, moved to touch them (a tangent plane of the side; a
// secant through a fillet would leave part of it outside and allow no
// rounding). `below`: the side falls inside F's plane (1) or outside (-1).
// False without a plane (too few points, a thin row).
bool side_plane(const FlatsContext& ctx, const std::vector<std::pair<uint32_t, uint32_t>>& ring, const Flat& F,
                uint32_t lo, uint32_t hi, std::vector<Vec3>& pts, Plane& out, int8_t& below) {
  const Surface& S = ctx.S;
  pts.clear();
  Vec3 outward = Vec3::Zero();
  double rise = 0;
  for (const auto& [w, d] : ring) {
    if (d < lo || d > hi) continue;
    const double h = ctx.height(F, S.x[w]);
    if (std::abs(h) <= detail::kJunctionRingOffPlane * ctx.cell) continue;
    pts.push_back(S.x[w]);
    outward += S.outside(w) - S.inside(w);
    rise += h;
  }
  if (pts.size() < 3) return false;
  const Pca q = pca(pts);
  if (!(q.eigenvalues(1) >= kThinRow * q.eigenvalues(2))) return false;
  below = rise < 0 ? 1 : -1;
  const Plane P = detail::oriented_plane(q, outward);
  double c = below > 0 ? -INFINITY : INFINITY;
  for (const Vec3& x : pts) c = below > 0 ? std::max(c, P.n.dot(x)) : std::min(c, P.n.dot(x));
  out = {P.n, c};
  return true;
}

// The same for a border between a flat and a curved side (no second flat
// within kRoundBorderRings): a filleted cylinder's rim, a plate's rounded
// end. Chains are connected junctions of the same flat, all convex (the
// side falls inside the flat's plane) or all concave. What the samples
// allow is judged against the side's plane next to the border (the
// junction test's 2-ring: at a crease it is the side's own plane there, so
// the crease's samples forbid a rounding), what they demand against the
// side's plane beyond (kTangentRings: a fillet's far side, whose corner
// with the flat the fillet cuts off).
size_t round_one_flat_borders(FlatsContext& ctx, const std::vector<std::array<int32_t, 2>>& pair) {
  const Surface& S = ctx.S;
  FlatSegmentation& seg = ctx.seg;
  const size_t n = ctx.n;
  std::vector<std::array<Plane, 2>> side(n);  // near, far
  std::vector<int32_t> flat(n, -1);
  std::vector<int8_t> below(n, 0);
  detail::parallel_ranges(n, 256, [&](detail::IndexRange r) {
    detail::RingScratch& rs = ctx.scratch.local();
    std::vector<Vec3> pts;
    for (size_t v = r.begin(); v < r.end(); ++v) {
      if (!seg.junction[v] || pair[v][0] >= 0) continue;
      const int32_t f0 = first_flat(ctx, v);
      if (f0 < 0) continue;
      const Flat& F = seg.flats[size_t(f0)];
      int8_t near_below = 0, far_below = 0;
      detail::rings_around(uint32_t(v), kTangentRings[1], S.adj_off, S.adj, Fresh{seg.region}, rs);
      if (!side_plane(ctx, rs.out, F, 0, 2, pts, side[v][0], near_below) ||
          !side_plane(ctx, rs.out, F, kTangentRings[0], kTangentRings[1], pts, side[v][1], far_below) ||
          near_below != far_below)
        continue;
      below[v] = near_below;
      flat[v] = f0;
    }
  });
  std::vector<uint8_t> seen(n, 0);
  std::vector<uint32_t> chain;
  size_t released = 0;
  for (uint32_t v0 = 0; v0 < n; ++v0) {
    if (flat[v0] < 0 || seen[v0]) continue;
    grow_chain(S, v0, [&](uint32_t w) { return flat[w] == flat[v0]; }, seen, chain);
    const int kind = below[v0];
    if (std::any_of(chain.begin(), chain.end(), [&](uint32_t v) { return below[v] != kind; })) continue;
    const Flat& F = seg.flats[size_t(flat[v0])];
    const Plane A{F.index_normal, F.index_offset};
    detail::RoundingEvidence near, far;
    for (uint32_t v : chain)
      for (int k = 0; k < 2; ++k)
        (k == 0 ? near : far).add_rings(A, side[v][size_t(k)], kind, {v}, S.adj_off, S.adj,
                                        [&](uint32_t w) { return S.inside(w); }, [&](uint32_t w) { return S.outside(w); });
    near.need = far.need;
    if (!near.round_between(detail::kRoundBorderRadius)) continue;
    for (uint32_t v : chain) seg.junction[v] = 0;
    released += chain.size();
  }
  return released;
}

// ---- Junctions (Section 3): fresh vertices next to a frozen one whose
// fresh 2-ring plane leans more than junction_angle from the flat. Resets
// and recounts ctx's smooth borders and off-plane junctions.
void detect_junctions(FlatsContext& ctx) {
  FlatSegmentation& seg = ctx.seg;
  std::fill(seg.junction.begin(), seg.junction.end(), 0);
  ctx.smooth_borders = 0;
  ctx.off_plane_junctions = 0;
  detail::parallel_ranges(ctx.n, 1024, [&](detail::IndexRange r) {
    std::vector<Vec3> pts;
    detail::RingScratch& rs = ctx.scratch.local();
    for (size_t v = r.begin(); v < r.end(); ++v) {
      if (seg.region[v] >= 0) continue;
      const int32_t f0 = first_flat(ctx, v);
      if (f0 < 0) continue;
      seg.junction[v] = is_junction(ctx, v, f0, rs, pts);
    }
  });
  if (ctx.o.passes.on(Pass::round_borders)) ctx.round_borders = round_borders(ctx);
}

}  // namespace

// Beyond the paper: flats reach their sharp edges. At a convex edge the
// solid is the intersection of the two half-spaces, so every stick there
// is stabbed by at least one of the planes and its true crossing is the
// one nearest its inside sample; at a concave edge (union) the farthest.
// A fresh vertex flagged as a junction joins a neighbouring flat whose
// plane stabs its stick, and a frozen vertex moves to a neighbouring flat
// when that rule prefers it; a few rounds, junctions recomputed each time.
// Smooth borders (no junction) are left to the smoothing. Leaves the
// junctions detected on the final regions.
void extend_to_edges(FlatsContext& ctx) {
  const Surface& S = ctx.S;
  const FlatOptions& o = ctx.o;
  FlatSegmentation& seg = ctx.seg;
  const size_t n = ctx.n;
  std::vector<Plane> planes(seg.flats.size());
  std::vector<Vec3> centroid(seg.flats.size(), Vec3::Zero());
  {
    std::vector<size_t> members(seg.flats.size(), 0);
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) {
        centroid[size_t(seg.region[v])] += S.x[v];
        ++members[size_t(seg.region[v])];
      }
    for (size_t f = 0; f < planes.size(); ++f) {
      planes[f] = {seg.flats[f].index_normal, seg.flats[f].index_offset};
      centroid[f] /= double(std::max<size_t>(members[f], 1));
    }
  }
  auto prefer = [&](int32_t f, double tf, int32_t g, double tg) {
    // true when (g, tg) is the better crossing than (f, tf) for this stick
    const bool convex = planes[size_t(g)].n.dot(centroid[size_t(f)]) < planes[size_t(g)].c;
    return convex ? tg < tf : tg > tf;
  };
  std::vector<uint8_t> refitted;
  bool stale = true;  // regions changed since the junctions were last detected
  for (int round = 0; round < kExtendRounds && !seg.flats.empty(); ++round) {
    if (stale) detect_junctions(ctx);
    stale = false;
    // Beyond the paper: the planes also keep their creases' samples on the right side.
    const auto t_refit = std::chrono::steady_clock::now();
    const bool refit = o.passes.on(Pass::crease_refit) && crease_refit(S, o, seg, planes, refitted);
    seg.stats.passes.seconds[size_t(Pass::crease_refit)] += detail::seconds_since(t_refit);
    if (refit) {
      for (size_t f = 0; f < planes.size(); ++f)
        if (refitted[f]) seg.flats[f] = ctx.flat_of(planes[f]);
      for (size_t v = 0; v < n; ++v)
        if (const int32_t f = seg.region[v]; f >= 0 && refitted[size_t(f)])
          seg.t[v] = ctx.frozen_t(uint32_t(v), planes[size_t(f)]);
      detect_junctions(ctx);
    }
    std::vector<std::pair<uint32_t, int32_t>> moves;
    for (size_t v = 0; v < n; ++v) {
      const int32_t cur = seg.region[v];
      if (cur < 0 && !seg.junction[v]) continue;
      int32_t best = cur;
      double tb = cur >= 0 ? crossing(S, v, planes[size_t(cur)], 0) : 0;
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
        const int32_t g = seg.region[S.adj[k]];
        if (g < 0 || g == best) continue;
        const double tg = crossing(S, v, planes[size_t(g)], o.margin);
        if (std::isnan(tg)) continue;
        if (best < 0 || prefer(best, tb, g, tg)) {
          best = g;
          tb = tg;
        }
      }
      if (best != cur) moves.push_back({uint32_t(v), best});
    }
    if (moves.empty() && !refit) break;
    for (const auto& [v, f] : moves) {
      seg.region[v] = f;
      seg.t[v] = crossing(S, v, planes[size_t(f)], o.margin);
    }
    stale = !moves.empty();
  }
  if (stale) detect_junctions(ctx);
}

// Beyond the paper: the rim leaves the tangent fillets. The rim takes the
// stabbed sticks two rings past the core so that a flat reaches its
// creases, where the estimate was rounded; at a smooth border onto a
// curved face tangent to the flat it runs onto that face instead, where a
// plane stabs sticks as long as the face stays within a stick of it, and
// freezes them up to ~0.4 cell off the truth (a 6-cell fillet two cells
// past its foot). Where the curved side passes the tangent test within
// rim_tangent_angle and rises kRimFilletRise off the plane, the rim's
// members next to the border (one ring) go back to the curved side, unless
// a junction is within two rings (the rim is the flat's reach to that
// crease).
size_t release_rim(FlatsContext& ctx) {
  const Surface& S = ctx.S;
  FlatSegmentation& seg = ctx.seg;
  const size_t n = ctx.n;
  const double cos_t = std::cos(detail::kRimTangentAngle * kPi / 180);
  std::vector<uint32_t> near_junction(n, detail::kUnreached), near_tangent(n, detail::kUnreached), junctions;
  std::vector<std::pair<uint32_t, int32_t>> borders;  // a smooth border's fresh vertex and its first flat neighbour
  for (uint32_t v = 0; v < n; ++v) {
    if (seg.region[v] >= 0) continue;
    if (seg.junction[v]) {
      near_junction[v] = 0;
      junctions.push_back(v);
      continue;
    }
    if (const int32_t f0 = first_flat(ctx, v); f0 >= 0) borders.push_back({v, f0});
  }
  // The smooth borders that are tangent (in parallel; each test reads the
  // regions only).
  std::vector<uint8_t> is_tangent(borders.size(), 0);
  detail::parallel_ranges(borders.size(), 256, [&](detail::IndexRange r) {
    std::vector<Vec3> pts;
    detail::RingScratch& rs = ctx.scratch.local();
    for (size_t i = r.begin(); i < r.end(); ++i)
      is_tangent[i] = tangent(ctx, borders[i].first, borders[i].second, cos_t, kRimFilletRise, rs, pts);
  });
  std::vector<uint32_t> tangent_borders;
  for (size_t i = 0; i < borders.size(); ++i)
    if (is_tangent[i]) {
      near_tangent[borders[i].first] = 0;
      tangent_borders.push_back(borders[i].first);
    }
  const auto any = [](uint32_t, uint32_t) { return true; };
  detail::spread_rings(std::move(junctions), 0, kRimJunctionRings, S.adj_off, S.adj, near_junction, any);
  detail::spread_rings(std::move(tangent_borders), 0, 1, S.adj_off, S.adj, near_tangent, any);
  size_t released = 0;
  for (uint32_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0 && ctx.det.rim[v] && near_tangent[v] != detail::kUnreached &&
        near_junction[v] == detail::kUnreached) {
      seg.region[v] = -1;
      seg.t[v] = std::numeric_limits<double>::quiet_NaN();
      ++released;
    }
  seg.stats.rim_released = released;
  if (released > 0) detect_junctions(ctx);
  return released;
}

// Sizes, once the extension has settled the members. Index-space area ->
// physical: |det M| |M^-T n| for a plane of unit index normal n.
void measure_flats(FlatsContext& ctx) {
  FlatSegmentation& seg = ctx.seg;
  for (Flat& f : seg.flats) f.sticks = 0, f.area_cells = 0;
  for (size_t v = 0; v < ctx.n; ++v)
    if (seg.region[v] >= 0) {
      Flat& f = seg.flats[size_t(seg.region[v])];
      ++f.sticks;
      f.area_cells += ctx.S.area[v];
    }
  for (Flat& f : seg.flats)
    f.area = f.area_cells * std::abs(ctx.M.determinant()) * (ctx.Minv_t * f.index_normal).norm();
}

// Barriers: frozen vertices next to a junction along a slice curve. Counts
// the junctions and the barriers.
void mark_barriers(FlatsContext& ctx, const SliceCurves& curves) {
  FlatSegmentation& seg = ctx.seg;
  for (int a = 0; a < 3; ++a) {
    const auto& ids = curves.ids[a];
    const auto& off = curves.offsets[a];
    for (size_t cv = 0; cv + 1 < off.size(); ++cv) {
      const uint32_t b = off[cv], m = off[cv + 1] - b;
      for (uint32_t i = 0; i < m; ++i) {
        const uint32_t p = ids[b + i], q = ids[b + (i + 1) % m];
        if (seg.region[p] >= 0 && seg.junction[q]) seg.barrier[p] = 1;
        if (seg.region[q] >= 0 && seg.junction[p]) seg.barrier[q] = 1;
      }
    }
  }
  for (size_t v = 0; v < ctx.n; ++v) {
    seg.stats.junctions += seg.junction[v];
    seg.stats.barriers += seg.barrier[v];
  }
}

}  // namespace voxpress::flats_impl

namespace voxpress::detail {

size_t junctions_step(FeatureContext& c) {
  flats_impl::extend_to_edges(*c.detect);
  return 0;  // mark_barriers counts the junctions
}

size_t rim_tangent_step(FeatureContext& c) {
  return c.detect->seg.flats.empty() ? 0 : flats_impl::release_rim(*c.detect);
}

}  // namespace voxpress::detail
