// Beyond the paper: the fresh vertices next to a sharp flat border placed by
// the curved side's own surface, extrapolated up to the flat. Theory of
// operation: include/voxpress/features/flats.h (fit_creases).
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <numeric>
#include <cmath>
#include <limits>

#include "crease_fit.h"
#include "feature_tuning.h"
#include "smooth/quadric.h"
#include "smooth/stick_solid.h"
#include "smooth/surface_graph.h"
#include "feature_context.h"
#include "voxpress/features/flats.h"
#include "core/parallel.h"

namespace voxpress {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr size_t kSidePoints = 12;  // fewest points of a curved crease's side (Quadric::fit's minimum)
constexpr uint32_t kChainGap = 2;  // rings a curved crease's chain may skip (a vertex whose sides' fit failed)

// Whether a sample of v or its 1-ring lies kRoundEvidence past both the
// flat's plane and the side's surface Q, on the wrong side for a crease
// (crease_targets).
bool denies_crease(const StickSurface& sticks, const Flat& f, const detail::Quadric& Q, bool convex, uint32_t v,
                   const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj) {
  const double norm = f.index_normal.norm(), eps = detail::kRoundEvidence;
  for (uint32_t k = off[v]; k <= off[v + 1]; ++k) {
    const uint32_t w = k == off[v + 1] ? v : adj[k];
    const Vec3 p = convex ? sticks.outside_sample(w) : sticks.inside_sample(w);
    const double hf = (f.index_normal.dot(p) - f.index_offset) / norm;
    const double hq = Q.height_above(p);
    if (convex ? (hf < -eps && hq < -eps) : (hf > eps && hq > eps)) return true;
  }
  return false;
}

}  // namespace

namespace detail {

std::vector<std::pair<uint32_t, double>> crease_targets(const StickSurface& sticks, const std::vector<Flat>& flats,
                                                        const std::vector<int32_t>& region,
                                                        const std::vector<uint8_t>& junction,
                                                        const std::vector<Vec3>& x, const std::vector<uint32_t>& off,
                                                        const std::vector<uint32_t>& adj, const CreaseFit& c) {
  const size_t n = region.size();
  // Ring distance of each curved vertex from the junctions (over curved
  // vertices) up to R, beyond that kUnreached, and the flat of the junction
  // it was reached from.
  std::vector<uint32_t> dist(n, kUnreached);
  std::vector<int32_t> flat(n, -1);
  std::vector<uint32_t> front;
  for (size_t v = 0; v < n; ++v) {
    if (region[v] >= 0 || !junction[v]) continue;
    for (uint32_t k = off[v]; k < off[v + 1] && flat[v] < 0; ++k) flat[v] = region[adj[k]];
    if (flat[v] < 0) continue;
    dist[v] = 0;
    front.push_back(uint32_t(v));
  }
  const uint32_t R = uint32_t(c.rings), F = uint32_t(c.fit_rings);
  spread_rings(std::move(front), 0, R, off, adj, dist, [&](uint32_t v, uint32_t w) {
    if (region[w] >= 0) return false;
    flat[w] = flat[v];
    return true;
  });
  std::vector<uint32_t> members;
  for (size_t v = 0; v < n; ++v)
    if (dist[v] <= R) members.push_back(uint32_t(v));
  std::vector<double> t_new(members.size(), std::numeric_limits<double>::quiet_NaN());
  tbb::enumerable_thread_specific<RingScratch> scratch;
  detail::parallel_ranges(members.size(), 64, [&](detail::IndexRange r) {
    RingScratch& rs = scratch.local();
    std::vector<Vec3> pts;
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const uint32_t v = members[i];
      // Anchors: curved vertices beyond the zone, within R + F rings of v.
      rings_around(v, R + F, off, adj, [&](uint32_t w) { return region[w] < 0; }, rs);
      pts.clear();
      Vec3 outward = Vec3::Zero();
      for (const auto& [w, d] : rs.out)
        if (dist[w] > R) {
          pts.push_back(x[w]);
          outward += sticks.outside_sample(w) - sticks.inside_sample(w);
        }
      Quadric Q;
      if (!Q.fit(pts, outward) || Q.residual > c.residual) continue;
      const Vec3 in = sticks.inside_sample(v), out = sticks.outside_sample(v);
      const double tv = (x[v] - in).dot(out - in);
      const double tc = Q.exit(in, out, tv, -1, 2);
      if (std::isnan(tc)) continue;
      // The flat's plane (index space) and the rule between the two sides.
      const Flat& f = flats[size_t(flat[v])];
      double tf = leave(Plane{f.index_normal, f.index_offset}, in, out);
      if (std::isnan(tf)) tf = -kInf;  // the stick enters the flat's half-space: never in it before
      const bool convex = f.index_normal.dot(Q.m) < f.index_offset;
      // The samples deny the crease when one of v's or its 1-ring's lies
      // kRoundEvidence on the wrong side of both (an outside sample inside
      // the flat's half-space and under the side's surface at a convex
      // crease, an inside one above both at a concave one): the border is
      // rounder than the crease of the flat and the side's far surface (a
      // fillet the flat meets tangentially); v keeps its pressed place.
      if (denies_crease(sticks, f, Q, convex, v, off, adj)) continue;
      const double t = std::clamp(convex ? std::min(tc, tf) : std::max(tc, tf), c.margin, 1 - c.margin);
      if (std::abs(t - tv) <= c.max_move) t_new[i] = t;
    }
  });
  std::vector<std::pair<uint32_t, double>> targets;
  for (size_t i = 0; i < members.size(); ++i)
    if (!std::isnan(t_new[i])) targets.push_back({members[i], t_new[i]});
  return targets;
}

// Vertex normals vn (physical) of the surface at x, and the band: the free
// curved vertices whose normal turns by c.band_angle or more to a curved
// neighbour (band flags and their list, `members`).
void band_of(const StickSurface& sticks, const std::vector<int32_t>& region, const std::vector<uint8_t>& role,
             const std::vector<Vec3>& x, const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj,
             const CurvedCreaseFit& c, const Mat3& Minv_t, std::vector<Vec3>& vn, std::vector<uint8_t>& band,
             std::vector<uint32_t>& members) {
  const size_t n = region.size();
  vn.assign(n, Vec3::Zero());
  for (const Triangle& t : sticks.triangles) {
    const Vec3 fn = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
    for (uint32_t v : t) vn[v] += fn;
  }
  for (auto& v : vn) v = (Minv_t * v).normalized();
  band.assign(n, 0);
  for (size_t v = 0; v < n; ++v) {
    if (region[v] >= 0 || role[v] != kCreaseFree) continue;
    double mx = 0;
    for (uint32_t k = off[v]; k < off[v + 1]; ++k)
      if (region[adj[k]] < 0) mx = std::max(mx, degrees_between(vn[v], vn[adj[k]]));
    band[v] = mx >= c.band_angle;
  }
  members.clear();
  for (size_t v = 0; v < n; ++v)
    if (band[v]) members.push_back(uint32_t(v));
}

// The crease network's search (curved_crease_targets): fit(i) for the
// members within c.rings rings of a proven feature, then, wave by wave, for
// the unfitted members within kChainGap rings of one found (found[i].t not
// NaN); without the network, for every member. Returns which were fitted.
// A member no wave reaches could only have been dropped, so the kept
// creases are those of fitting every member, then chaining (each fit
// depends on the inputs only). On organs most band vertices are far from
// any proven feature: their fits were most of a label map's sharpening
// (`final-curved-creases`, docs/BENCHMARKS.md, Speed of press).
template <class Fit>
std::vector<uint8_t> fit_in_waves(const std::vector<uint32_t>& members, const std::vector<int32_t>& region,
                                  const std::vector<uint8_t>& role, const std::vector<uint32_t>& off,
                                  const std::vector<uint32_t>& adj, const CurvedCreaseFit& c,
                                  const std::vector<CurvedCrease>& found, Fit&& fit) {
  const size_t n = region.size();
  std::vector<uint8_t> fitted(members.size(), 0);
  std::vector<uint32_t> wave;
  if (!c.network) {
    wave.resize(members.size());
    std::iota(wave.begin(), wave.end(), 0u);
  } else {
    // Within c.rings rings of a proven feature: one search from all of them.
    std::vector<uint32_t> depth(n, kUnreached), front;
    for (uint32_t v = 0; v < n; ++v)
      if (role[v] != kCreaseFree && region[v] < 0) depth[v] = 0, front.push_back(v);
    spread_rings(std::move(front), 0, uint32_t(c.rings), off, adj, depth, [](uint32_t, uint32_t) { return true; });
    for (uint32_t i = 0; i < members.size(); ++i)
      if (depth[members[i]] != kUnreached) wave.push_back(i);
  }
  std::vector<int32_t> member_of(c.network ? n : 0, -1);
  if (c.network)
    for (uint32_t i = 0; i < members.size(); ++i) member_of[members[i]] = int32_t(i);
  RingScratch rs;
  while (!wave.empty()) {
    for (uint32_t i : wave) fitted[i] = 1;
    detail::parallel_ranges(wave.size(), 16, [&](detail::IndexRange r) {
      for (size_t k = r.begin(); k < r.end(); ++k) fit(wave[k]);
    });
    if (!c.network) break;
    // The next wave: unfitted members within kChainGap rings of a found one.
    std::vector<uint32_t> next;
    for (uint32_t i : wave) {
      if (std::isnan(found[i].t)) continue;
      rings_around(members[i], kChainGap, off, adj, [](uint32_t) { return true; }, rs);
      for (const auto& [w, d] : rs.out)
        if (const int32_t j = member_of[w]; j >= 0 && !fitted[size_t(j)]) {
          fitted[size_t(j)] = 1;
          next.push_back(uint32_t(j));
        }
    }
    std::sort(next.begin(), next.end());
    wave.swap(next);
  }
  return fitted;
}

std::vector<CurvedCrease> curved_crease_targets(const StickSurface& sticks, const std::vector<int32_t>& region,
                                                const std::vector<uint8_t>& role, const std::vector<Vec3>& x,
                                                const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj,
                                                const CurvedCreaseFit& c, std::vector<Vec3>* normals, size_t* unproven) {
  const Mat3 Minv_t = sticks.lattice.index_to_physical_matrix().inverse().transpose();
  std::vector<Vec3> vn;
  std::vector<uint8_t> band;
  std::vector<uint32_t> members;
  band_of(sticks, region, role, x, off, adj, c, Minv_t, vn, band, members);
  std::vector<CurvedCrease> found(members.size(), CurvedCrease{0, std::numeric_limits<double>::quiet_NaN(), {}, {}});
  struct Work {  // one thread's scratch
    RingScratch rs;
    std::vector<uint32_t> P;
    std::vector<uint8_t> side, keep;
    std::vector<Vec3> pa, pb, ia, xa, ib, xb;
  };
  tbb::enumerable_thread_specific<Work> scratch;
  // found[i]: the crease through members[i], if its two sides' quadrics
  // meet at one (t NaN otherwise).
  const auto fit_member = [&](size_t i) {
    Work& wk = scratch.local();
    RingScratch& rs = wk.rs;
    std::vector<uint32_t>& P = wk.P;
    std::vector<uint8_t>&side = wk.side, &keep = wk.keep;
    std::vector<Vec3>&pa = wk.pa, &pb = wk.pb, &ia = wk.ia, &xa = wk.xa, &ib = wk.ib, &xb = wk.xb;
    const uint32_t v = members[i];
    rings_around(v, c.rings, off, adj, [&](uint32_t w) { return region[w] < 0; }, rs);
    P.clear();
    for (const auto& [w, d] : rs.out)
      if (!band[w] && role[w] != kCreaseSkip) P.push_back(w);
    if (P.size() < 2 * kSidePoints) return;
    // Two sides: 2-means on the normals, seeded by the normal farthest
    // from v's and the one farthest from that.
    uint32_t a = P[0], b = P[0];
    for (uint32_t w : P)
      if (vn[w].dot(vn[v]) < vn[a].dot(vn[v])) a = w;
    for (uint32_t w : P)
      if (vn[w].dot(vn[a]) < vn[b].dot(vn[a])) b = w;
    Vec3 ma = vn[a], mb = vn[b];
    side.assign(P.size(), 0);
    for (int it = 0; it < 4; ++it) {
      Vec3 sa = Vec3::Zero(), sb = Vec3::Zero();
      for (size_t k = 0; k < P.size(); ++k) {
        side[k] = vn[P[k]].dot(ma) < vn[P[k]].dot(mb);
        (side[k] ? sb : sa) += vn[P[k]];
      }
      if (sa.isZero() || sb.isZero()) break;
      ma = sa.normalized();
      mb = sb.normalized();
    }
    if (degrees_between(ma, mb) < c.sharp_angle) return;
    // Each side's points (kept ones), their sticks' samples and the
    // side's outward direction (the sum of its sticks' inside -> outside
    // directions).
    keep.assign(P.size(), 1);
    Vec3 oa, ob;
    auto split = [&] {
      for (auto* list : {&pa, &pb, &ia, &xa, &ib, &xb}) list->clear();
      oa.setZero();
      ob.setZero();
      for (size_t k = 0; k < P.size(); ++k) {
        if (!keep[k]) continue;
        const Vec3 in = sticks.inside_sample(P[k]), out = sticks.outside_sample(P[k]);
        (side[k] ? pb : pa).push_back(x[P[k]]);
        (side[k] ? ib : ia).push_back(in);
        (side[k] ? xb : xa).push_back(out);
        (side[k] ? ob : oa) += out - in;
      }
      return pa.size() >= kSidePoints && pb.size() >= kSidePoints;
    };
    Quadric QA, QB;
    if (!split() || !QA.fit(pa, oa) || !QB.fit(pb, ob)) return;
    // Trimming: each point goes to the nearer quadric, and points farther
    // than `trim` from both (the rounded crease the band threshold left
    // in) are dropped; then both are refitted.
    bool fitted = true;
    for (uint32_t round = 0; round < c.trim_rounds && fitted; ++round) {
      for (size_t k = 0; k < P.size(); ++k) {
        const Vec3& p = x[P[k]];
        const double da = std::abs(QA.height_above(p)), db = std::abs(QB.height_above(p));
        side[k] = db < da;
        keep[k] = std::min(da, db) <= c.trim;
      }
      fitted = split() && QA.fit(pa, oa) && QB.fit(pb, ob);
    }
    if (!fitted || QA.residual > c.residual || QB.residual > c.residual) return;
    Vec3 ca = Vec3::Zero(), cb = Vec3::Zero();
    for (const Vec3& p : pa) ca += p;
    for (const Vec3& p : pb) cb += p;
    ca /= double(pa.size());
    cb /= double(pb.size());
    QA.stab(pa, ia, xa, c.stab_eps, c.stab_weight, kStabSolves);
    QB.stab(pb, ib, xb, c.stab_eps, c.stab_weight, kStabSolves);
    const double ga = QA.height_above(cb), gb = QB.height_above(ca);
    if ((ga < 0) != (gb < 0)) return;
    const bool convex = ga < 0;
    const Vec3 in = sticks.inside_sample(v), out = sticks.outside_sample(v);
    const double tv = (x[v] - in).dot(out - in);
    // Where the stick leaves each side's solid.
    const double ta = leave(QA, in, out, tv), tb = leave(QB, in, out, tv);
    if (std::isnan(ta) || std::isnan(tb)) return;
    const double t = std::clamp(convex ? std::min(ta, tb) : std::max(ta, tb), c.margin, 1 - c.margin);
    if (std::abs(t - tv) > c.max_move) return;
    const bool a_side = convex ? ta <= tb : ta >= tb;
    const Vec3 q = in + t * (out - in);
    const Quadric& C = a_side ? QA : QB;
    const Quadric& O = a_side ? QB : QA;
    if (std::abs(O.height_above(q)) > c.other_distance) return;  // no crease here
    CurvedCrease& f = found[i];
    f.v = v;
    f.t = t;
    Vec3 foot = C.foot(q);
    f.chosen.n = C.normal_at(foot);
    f.chosen.c = f.chosen.n.dot(foot);
    foot = O.foot(q);
    f.other.n = O.normal_at(foot);
    f.other.c = f.other.n.dot(foot);
    if (degrees_between((Minv_t * f.chosen.n).normalized(), (Minv_t * f.other.n).normalized()) < c.sharp_angle)
      f.t = std::numeric_limits<double>::quiet_NaN();
  };
  // Evidence: a crease between two curved faces is kept only where it
  // continues a proven crease. Locally it proves nothing: at 128^3 a tight
  // fold of an organic solid (a bunny's neck, a heart's grooves) fits two
  // quadrics meeting at a sharp angle as well as a CAD part's curved
  // crease does, and the sharp-vs-rounded stick test cannot tell them
  // apart either (docs/ARCHITECTURE.md, Curved creases). What does is the
  // crease network: a CAD part's curved creases run into the sharp borders
  // of its flats. So a found vertex seeds a chain when a vertex of a proven
  // feature (role kCreaseSkip or kCreaseSide: a flat's junction, its crease
  // zone, a thin wall) lies within the side fit's c.rings rings (closer in,
  // the fit has too few side points to find the crease), and the chain
  // goes on through found vertices at most kChainGap rings apart.
  // The search follows that rule (fit_in_waves).
  const std::vector<uint8_t> fitted =
      fit_in_waves(members, region, role, off, adj, c, found, [&](size_t i) { fit_member(i); });
  std::vector<CurvedCrease> out;
  if (unproven) *unproven = 0;
  for (size_t i = 0; i < members.size(); ++i) {
    if (!std::isnan(found[i].t)) {
      out.push_back(found[i]);
    } else if (unproven && !fitted[i]) {
      ++*unproven;  // a band vertex no proven crease reaches
    }
  }
  if (normals) *normals = std::move(vn);
  return out;
}

}  // namespace detail

size_t fit_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o, std::vector<uint8_t>* zone) {
  return detail::fit_creases(s, seg, o, zone, detail::Adjacency(s.stick_count(), s.triangles));
}

size_t detail::fit_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o, std::vector<uint8_t>* zone,
                           const Adjacency& graph) {
  const size_t n = s.stick_count();
  if (zone) zone->assign(n, 0);
  if (seg.flats.empty() || !o.passes.on(Pass::crease_fit)) return 0;
  const std::vector<uint32_t>&off = graph.off, &adj = graph.adj;
  std::vector<Vec3> x(n);
  detail::parallel_for(n, [&](size_t v) { x[v] = s.index_position(v); });
  const detail::CreaseFit c{
      .rings = detail::kCreaseRings, .fit_rings = detail::kCreaseFitRings, .residual = detail::kCreaseResidual, .margin = o.margin};
  const auto targets = detail::crease_targets(s, seg.flats, seg.region, seg.junction, x, off, adj, c);
  for (const auto& [v, t] : targets) {
    s.t[v] = s.lower_inside(v) ? t : 1 - t;
    if (zone) (*zone)[v] = 1;
  }
  return targets.size();
}

size_t fit_curved_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o,
                          std::vector<uint8_t>& fixed, std::vector<uint8_t>* placed) {
  return detail::fit_curved_creases(s, seg, o, fixed, placed, detail::Adjacency(s.stick_count(), s.triangles));
}

size_t detail::fit_curved_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o,
                                  std::vector<uint8_t>& fixed, std::vector<uint8_t>* placed, const Adjacency& graph) {
  const size_t n = s.stick_count();
  if (!o.passes.on(Pass::curved_creases) || seg.region.size() != n) return 0;
  const std::vector<uint32_t>&off = graph.off, &adj = graph.adj;
  std::vector<Vec3> x(n);
  detail::parallel_for(n, [&](size_t v) { x[v] = s.index_position(v); });
  fixed.resize(n, 0);
  std::vector<uint8_t> role(n);
  for (size_t v = 0; v < n; ++v)
    role[v] = fixed[v] || (!seg.junction.empty() && seg.junction[v]) ? detail::kCreaseSkip : detail::kCreaseFree;
  detail::CurvedCreaseFit c;
  c.sharp_angle = o.junction_angle;
  c.margin = o.margin;
  c.network = o.passes.on(Pass::crease_network);
  const auto found = detail::curved_crease_targets(s, seg.region, role, x, off, adj, c);
  for (const auto& f : found) {
    s.t[f.v] = s.lower_inside(f.v) ? f.t : 1 - f.t;
    fixed[f.v] = 1;
    if (placed) (*placed)[f.v] = 1;
  }
  return found.size();
}

}  // namespace voxpress
