// The flats' crease refit (beyond the paper). Theory of operation: below
// and include/voxpress/features/flats.h.
#include "flat_geometry.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <tuple>
#include "core/parallel.h"

namespace voxpress::flats_impl {

// Beyond the paper: the flats' planes refitted with their creases' samples
// (measured by `build/bench/bench_flats --shape box --res 64 --seeds 30`:
// a lower stick error after smoothing). A flat's own sticks pin its
// plane poorly about a lattice axis the face nearly contains (a tenth of
// a degree, a tenth of a cell off at its corners, all its sticks still
// stabbed), but the samples along its sharp edges know more. At a convex
// crease the solid is the intersection of the flats' half-spaces, so each
// inside sample there is inside every plane, and each outside sample is
// outside at least one: the one plane it is not clearly (kRefitClear)
// inside of, when there is one. At a concave crease (the union) the roles
// swap. The samples considered are those of the junctions and members
// within kRefitRings rings of two or more flats, and within kRefitWindow
// of the plane they constrain. A flat whose plane leaves such a sample on
// the wrong side is refitted: least squares of its members near the plane,
// inside the set stabbing all its members and keeping every constraint
// (constrained_fit), taken when it moves less than kRefitTurn degrees.
// With FlatOptions::center_planes every flat is refitted in the first round
// and its plane moved to the centre of that feasible set (every member the
// least-squares plane stabs staying stabbed).
// Rounds until no plane moves. Returns whether any moved.
constexpr int kRefitRings = 2;
constexpr int kRefitReach = 8;
constexpr double kRefitWindow = 0.25;  // cells
constexpr double kRefitClear = 0.1;    // cells
constexpr double kRefitTurn = 1;       // degrees
constexpr int kRefitRounds = 3;
bool crease_refit(const Surface& S, const FlatOptions& o, FlatSegmentation& seg, std::vector<Plane>& planes,
                  std::vector<uint8_t>& moved) {
  const size_t n = S.x.size(), F = planes.size();
  moved.assign(F, 0);
  if (F < 2) return false;
  auto height = [&](int32_t f, const Vec3& p) { return planes[size_t(f)].n.dot(p) - planes[size_t(f)].c; };
  std::vector<std::vector<uint32_t>> members(F);
  for (size_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0) members[size_t(seg.region[v])].push_back(uint32_t(v));
  bool any = false;
  struct Scratch {
    detail::RingScratch rs, wide;
    std::vector<int32_t> near, wider;
    std::vector<std::pair<int32_t, SideConstraint>> sides;
    std::vector<uint8_t> broken;
  };
  // The constraints that junction or member v adds (see above).
  auto gather = [&](uint32_t v, Scratch& sc) {
    const int32_t own = seg.region[v];
    auto add = [&](int32_t f, const Vec3& p, bool outside) {
      const double h = height(f, p) * (outside ? 1 : -1);  // > 0: on its side
      if (h < -kRefitWindow) return;
      sc.sides.push_back({f, {p, outside}});
      if (h <= 0) sc.broken[size_t(f)] = 1;
    };
    detail::rings_around(v, kRefitRings, S.adj_off, S.adj, [](uint32_t) { return true; }, sc.rs);
    std::vector<int32_t>& near = sc.near;
    near.clear();
    detail::add_flats(sc.rs.out, seg.region, near);
    if (near.size() < 2) return;
    // Convex or concave: the members here (on their planes) lie inside the other flats' planes, or outside.
    const int kind = detail::crease_kind(
        sc.rs.out, seg.region, near, [&](uint32_t w) -> Vec3 { return S.inside(w) + seg.t[w] * (S.outside(w) - S.inside(w)); },
        height);
    if (kind == 0) return;
    const bool convex = kind > 0;
    // Every plane but v's own keeps the sample that must be on its side of all of them.
    const Vec3 all = convex ? S.inside(v) : S.outside(v);
    for (int32_t g : near)
      if (g != own) add(g, all, !convex);
    if (own >= 0) return;  // a member's own plane separates its samples: the disjunction holds
    // The disjunction must know every plane that may bound the solid here
    // (a corner's third face, whose rim may stop a few rings short).
    detail::rings_around(v, kRefitReach, S.adj_off, S.adj, [](uint32_t) { return true; }, sc.wide);
    sc.wider = near;
    detail::add_flats(sc.wide.out, seg.region, sc.wider);
    // The sample that must be on the other side of one plane: the plane it is not clearly inside (outside) of.
    const Vec3 one = convex ? S.outside(v) : S.inside(v);
    const double sg = convex ? 1 : -1;
    int32_t pick = -1;
    bool clear = true;
    for (int32_t g : sc.wider)
      if (sg * height(g, one) > -kRefitClear) {
        if (pick >= 0) clear = false;
        pick = g;
      }
    if (pick >= 0 && clear) add(pick, one, convex);
  };
  std::vector<Vec3> pts;
  for (int round = 0; round < kRefitRounds; ++round) {
    // Ring distance to a border between regions (flats, curved): beyond
    // kRefitRings, no other flat is near and a member is inner.
    const std::vector<uint32_t> depth = detail::region_border_rings(seg.region, kRefitRings, S.adj_off, S.adj);
    tbb::enumerable_thread_specific<Scratch> scratch([F] {
      Scratch sc;
      sc.broken.assign(F, 0);
      return sc;
    });
    detail::parallel_ranges(uint32_t(n), 1024, [&](detail::IndexRange r) {
      Scratch& sc = scratch.local();
      for (uint32_t v = r.begin(); v < r.end(); ++v)
        if ((seg.region[v] >= 0 || seg.junction[v]) && depth[v] != detail::kUnreached) gather(v, sc);
    });
    // Merged, then sorted: the same constraints in the same order for any number of threads.
    std::vector<std::vector<SideConstraint>> sides(F);
    std::vector<uint8_t> broken(F, 0);
    for (const Scratch& sc : scratch) {
      for (const auto& [f, q] : sc.sides) sides[size_t(f)].push_back(q);
      for (size_t f = 0; f < F; ++f) broken[f] |= sc.broken[f];
    }
    bool again = false;
    for (size_t f = 0; f < F; ++f) {
      if (!broken[f] && !(o.passes.on(Pass::center_planes) && round == 0)) continue;
      std::sort(sides[f].begin(), sides[f].end());
      sides[f].erase(std::unique(sides[f].begin(), sides[f].end()), sides[f].end());
      // Fitted: the members more than kRefitRings rings from any other
      // region (next to one, a member may be another face's stick the rim
      // took, which no plane near the true one stabs); the least squares
      // over those near the plane.
      std::vector<uint32_t> inner, core;
      for (uint32_t v : members[f]) {
        if (depth[v] != detail::kUnreached) continue;
        inner.push_back(v);
        if (std::abs(planes[f].n.dot(S.x[v]) - planes[f].c) <= detail::kFlatTolerance) core.push_back(v);
      }
      if (core.size() < 3) continue;
      S.positions(core, pts);
      Plane P;
      if (!constrained_fit(S, inner, pts, planes[f].n, kSideMargin, P, sides[f], o.passes.on(Pass::center_planes) ? &members[f] : nullptr))
        continue;
      if (detail::degrees_between(P.n, planes[f].n) > kRefitTurn) continue;
      planes[f] = P;
      moved[f] = 1;
      again = true;
      ++seg.stats.passes.count[size_t(broken[f] ? Pass::crease_refit : Pass::center_planes)];
      // The members it no longer stabs with the margin leave (the extension
      // may give them to a neighbour; Pressing places them).
      std::vector<uint32_t> kept;
      for (uint32_t v : members[f]) {
        if (std::isnan(crossing(S, v, P, o.margin))) {
          seg.region[v] = -1;
          seg.t[v] = std::numeric_limits<double>::quiet_NaN();
        } else {
          kept.push_back(v);
        }
      }
      members[f] = std::move(kept);
    }
    if (!again) break;
    any = true;
  }
  return any;
}

}  // namespace voxpress::flats_impl
