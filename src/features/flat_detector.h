// Private to the flats (Section 3): the greedy detector — cluster growth
// from an accumulator cell, acceptance tests, the stabbing refit and the
// curvature test. Theory of operation: include/voxpress/features/flats.h.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include "flat_geometry.h"
#include "smooth/quadric.h"
#include "core/parallel.h"

namespace voxpress::flats_impl {

// ---------------------------------------------------------------- detection
struct Detector {
  const Surface& S;
  const FlatOptions& o;
  std::vector<int32_t>& region;  // -1 unassigned
  std::vector<uint32_t> mark;    // per vertex: stamp of the cluster being grown
  uint32_t stamp = 0;

  double cos_cone;
  std::vector<uint8_t> rim;  // per vertex: added by a rim growth (not a core member)
  size_t rim_begin = 0;      // where the last rim growth's vertices start in its cluster
  size_t restabbed = 0, refused_curved = 0;  // cores the stab refit changed, flats the curved test refused
  // A core vertex: its stick stabbed, its estimated vertex within tol of the
  // plane and its estimated normal within the cone of the plane's.
  // With `slack` > 0 the plane may miss the stick by up to that fraction of
  // it (the growth's test, see kGrowSlack).
  bool near(uint32_t v, const Plane& P, double tol, double slack = 0) const {
    if (S.nrm[v].dot(P.n) < cos_cone || std::abs(P.n.dot(S.x[v]) - P.c) > tol) return false;
    if (slack <= 0) return !std::isnan(crossing(S, v, P, o.margin));
    const double t = detail::leave(P, S.inside(v), S.outside(v));  // +-inf, NaN fail the test
    return t >= o.margin - slack && t <= 1 - o.margin + slack;
  }

  // Breadth-first growth of `cluster` (all marked with the current stamp)
  // over unassigned neighbours accepted by `ok`, at most `rings` rings (-1: no limit).
  template <class Ok>
  void grow(std::vector<uint32_t>& cluster, size_t from, int rings, Ok ok) {
    size_t begin = from, end = cluster.size();
    for (int r = 0; rings < 0 || r < rings; ++r) {
      for (size_t q = begin; q < end; ++q) {
        const uint32_t v = cluster[q];
        for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
          const uint32_t w = S.adj[k];
          if (mark[w] == stamp || region[w] >= 0 || !ok(w)) continue;
          mark[w] = stamp;
          cluster.push_back(w);
        }
      }
      if (cluster.size() == end) break;
      begin = end;
      end = cluster.size();
    }
  }

  // The rim: the stabbed sticks within rim_rings of `cluster`, flagged.
  void grow_rim(std::vector<uint32_t>& cluster, const Plane& P) {
    const size_t before = rim_begin = cluster.size();
    grow(cluster, 0, detail::kRimRings, [&](uint32_t w) { return !std::isnan(crossing(S, w, P, o.margin)); });
    for (size_t i = before; i < cluster.size(); ++i) rim[cluster[i]] = 1;
  }

  // A cluster from the voters of one accumulator cell; empty if rejected.
  // `rejected` receives the core of a rejected cluster.
  std::vector<uint32_t> cluster_from(const std::vector<uint32_t>& seeds, Plane& P, std::vector<uint32_t>& rejected) {
    std::vector<Vec3> pts;
    Vec3 mean_n = Vec3::Zero();
    for (uint32_t v : seeds) {
      pts.push_back(S.x[v]);
      mean_n += S.nrm[v];
    }
    P = fit_plane(pts, mean_n);
    // The largest connected set of seeds the plane holds.
    std::vector<uint32_t> best;
    const uint32_t seed_mark = ++stamp, visited = ++stamp;
    for (uint32_t v : seeds)
      if (near(v, P, detail::kFlatTolerance)) mark[v] = seed_mark;
    for (uint32_t v : seeds) {
      if (mark[v] != seed_mark) continue;
      std::vector<uint32_t> comp{v};
      mark[v] = visited;
      for (size_t q = 0; q < comp.size(); ++q)
        for (uint32_t k = S.adj_off[comp[q]]; k < S.adj_off[comp[q] + 1]; ++k) {
          const uint32_t w = S.adj[k];
          if (mark[w] == seed_mark) {
            mark[w] = visited;
            comp.push_back(w);
          }
        }
      if (comp.size() > best.size()) best.swap(comp);
    }
    if (best.size() < 3) return {};
    ++stamp;
    for (uint32_t v : best) mark[v] = stamp;
    std::vector<uint32_t> core = std::move(best);
    for (int round = 0; round < 12; ++round) {
      const size_t before = core.size();
      grow(core, 0, -1, [&](uint32_t w) { return near(w, P, detail::kFlatTolerance, kGrowSlack); });
      S.positions(core, pts);
      Plane next;
      if (!constrained_fit(S, core, pts, P.n, o.margin, next)) {
        // Fallback (no plane stabs them all): keep the members the current
        // plane stabs and move it towards the least-squares one as far as
        // feasibility allows.
        std::erase_if(core, [&](uint32_t v) { return std::isnan(crossing(S, v, P, o.margin)); });
        S.positions(core, pts);
        const Plane F = fit_plane(pts, P.n);
        next = lerp(P, F, feasible_step(S, core, P, F, o.margin));
      }
      const double moved = (next.n - P.n).norm() + std::abs(next.c - P.c);
      P = next;
      if (core.size() == before && moved < 1e-7) break;
    }
    // The stabbing refit (restab). An accepted core keeps its result only
    // when it explains its neighbourhood: next to a gently curved face
    // (fandisk) the search tilts the plane into it. A refused core whose
    // pillowed estimate failed the spread or bend test is rescued the same
    // way: a plane tangent to a curved surface stabs a strip and misses its
    // sides (measured with a 10-degree window, which holds fewer of a
    // strip's sides than the 15 used: cylinders at 128-256 0.58-0.79 of the
    // candidates, torus 0.74-0.85; pillowed box faces and the CAD part's
    // chamfer 0.93-1.0).
    bool ok = accept(core, P);
    if (o.passes.on(Pass::stab_refit) && (ok || area_of(core) >= o.min_area)) {
      std::vector<uint32_t> again = core;
      Plane Q = P;
      if (restab(again, Q, !ok) >= kRestabTrigger) {
        core.swap(again);
        P = Q;
        ok = true;
        ++restabbed;
      }
    }
    if (ok && o.passes.on(Pass::curved_test) && curved(core, P)) {
      ok = false;
      ++refused_curved;
    }
    if (!ok) {
      rejected = std::move(core);
      return {};
    }
    ++stamp;  // restab marked its candidates: only the core may stay marked
    for (uint32_t v : core) mark[v] = stamp;
    grow_rim(core, P);
    return core;
  }

  // Beyond the paper: whether the plane of an accepted core is a tangent
  // strip of a curved face. The estimate cannot always tell: a small
  // cylinder's strip at 256^3 (the CAD part's rounded corners, 20 cells of
  // radius) passes the spread test, the stabbing refit rescues it (its plane
  // stabs 0.98 of the candidates), and in a second pass its frozen estimate
  // is exactly planar. The sticks can tell: around a face, the lattice turns
  // at its edges and no smooth surface stabs much more than the plane does;
  // around a strip, the curved face goes on, and a quadric fitted to the
  // neighbourhood's estimate stabs the sticks on both sides of the strip.
  // Measured (quadric / plane stabbed sticks): faces of boxes, cylinders
  // and the CAD part at 64-256 0.55-1.09, one piece of a box 64 face 1.21;
  // the CAD part's corner strips at 256^3 1.77-1.81; fandisk's flats at
  // 256^3 a continuum up to 2.24, those on its gently curved faces from
  // ~1.3. The default gain (FlatOptions::curved_gain) is 1.3: it refuses
  // most flats on fandisk's gently curved faces at 256^3, which lowers its
  // error, and leaves the generated shapes unchanged, where 1.2 would refuse
  // the box piece (measured by `build/bench/bench_flats --model
  // ../shared/data/meshes/fandisk.off --res 256 --seeds 3` and
  // `build/bench/bench_flats`; docs/BENCHMARKS.md, Flats and junctions).
  bool curved(const std::vector<uint32_t>& core, const Plane& P) {
    std::vector<uint32_t> ext;
    neighbourhood(core, P, kCurvedRings, kCurvedWindow, ext);
    std::vector<Vec3> pts;
    S.positions(ext, pts);
    detail::Quadric Q;
    if (!Q.fit(pts, P.n)) return false;
    size_t by_quadric = 0;
    for (uint32_t v : ext) by_quadric += !std::isnan(detail::stab(Q, S.inside(v), S.outside(v), 0.5, o.margin));
    return double(by_quadric) > detail::kCurvedGain * double(stabbed_by(ext, P));
  }

  // The core and the unassigned vertices within `rings` rings of it whose
  // estimated normal is within `window` degrees of the plane's, into `out`
  // (restab's candidates, curved's neighbourhood). Returns the stamp they
  // all carry in `mark`.
  uint32_t neighbourhood(const std::vector<uint32_t>& core, const Plane& P, int rings, double window,
                         std::vector<uint32_t>& out) {
    const uint32_t m = ++stamp;
    for (uint32_t v : core) mark[v] = m;
    out = core;
    const double cos_window = std::cos(window * kPi / 180);
    grow(out, 0, rings, [&](uint32_t w) { return S.nrm[w].dot(P.n) >= cos_window; });
    return m;
  }

  // How many of the sticks of `vs` the plane stabs (with the margin).
  size_t stabbed_by(const std::vector<uint32_t>& vs, const Plane& P) const {
    size_t k = 0;
    for (uint32_t v : vs) k += !std::isnan(crossing(S, v, P, o.margin));
    return k;
  }

  // Beyond the paper: the plane that stabs the most sticks around an
  // accepted core, found without the estimate's positions. Near a lattice
  // axis (a face 2 degrees off z is terraces ~28 cells wide) or near a plane
  // containing one, the estimate of a face between sharp edges is a pillow:
  // Pressing bulges it up to a cell outwards over ten cells, since the
  // sticks of such a face bound its slope only loosely. The core then holds
  // a piece of the face, tilted 1-3 degrees (several such pieces instead of
  // the faces). The truth stabs every stick of the face
  // whatever the estimate, so: when the plane stabs less than
  // kRestabTrigger of the candidates (the core and the unassigned vertices
  // within kRestabRings rings whose normal is within kRestabWindow of the
  // plane's), search the directions within kRestabRange of it for the plane
  // stabbing the most candidates (per direction, the offsets that stab a
  // stick form an interval: a sweep over their ends), and when it stabs
  // kRestabGain as many, take its connected stabbed set as the core and
  // refit (least squares inside the feasible set, as always). Repeat while
  // the core grows. `force`: a core the acceptance tests refused, searched
  // only when its plane already stabs kRestabForced of the candidates.
  // Returns the share of the final candidates the final plane stabs (the
  // caller keeps the result only when it is at least kRestabTrigger).
  double restab(std::vector<uint32_t>& core, Plane& P, bool force) {
    // Within kRestabRange of a low-index lattice direction (an axis, a face
    // or a body diagonal) the share says little: the lattice's samples lie
    // in layers across such a normal, so a plane tilted a little from it
    // crosses few layers, and a plane along the direction through one of
    // them stabs most of the face's sticks while lying up to half a cell
    // off. A face 2 degrees off z that rises a cell across has an
    // axis-aligned plane through one terrace stabbing some 90 % of its
    // candidates (or, once a flat took that terrace, a plane through the
    // next one 70 %); a face a degree off a face diagonal can leave a
    // plane 3 degrees off through one layer as an extra flat. An accepted core's plane there is always searched; a
    // refused core's still from kRestabForced (cylinders' tangent strips
    // near a diagonal would cost their detection 80 % more). The result is
    // still kept only when it reaches kRestabTrigger; a face on the
    // direction gains nothing from the search and keeps its plane.
    const double cos_range = std::cos(kRestabRange * kPi / 180);
    const bool near_lattice = std::any_of(kLowIndex.begin(), kLowIndex.end(),
                                       [&](const Vec3& d) { return std::abs(P.n.dot(d)) > cos_range; });
    std::vector<uint32_t> cand, next;
    std::vector<Vec3> pts;
    for (int round = 0;; ++round) {
      const uint32_t core_mark = neighbourhood(core, P, kRestabRings, kRestabWindow, cand);
      const double share = double(stabbed_by(cand, P)) / double(cand.size());
      // Not forced (an accepted core), a plane that explains its
      // neighbourhood stays, and one far from explaining it (next to a
      // gently curved face: 0.46-0.68 on fandisk) is not searched: the
      // search would tilt it into that face. Forced (a rejected core), the
      // plane is searched from kRestabForced: a 45-degree chamfer a
      // few cells wide is rounded from both sides, its cores lean
      // 3-4 degrees, are refused, and stab 0.70-0.74 (at 0.9 they were not
      // searched, at 0.6 tori and fandisk at 256 paid 2-3x the detection
      // time for nothing). Cylinders reject hundreds of tangent-strip cores,
      // but a search only keeps what ends at kRestabTrigger.
      const bool stop = force ? share < kRestabForced
                              : !near_lattice && ((round == 0 && share >= kRestabTrigger) || share < kRestabGiveUp);
      if (round == kRestabRounds || stop) return share;
      Plane Q;
      size_t now = 0;
      const size_t best = most_stabbing(cand, P, Q, now);
      if (double(best) < kRestabGain * double(now)) return share;
      // The connected set of candidates (still marked core_mark: grow
      // marked them so) that Q stabs, from the core's stabbed vertices.
      const uint32_t taken = ++stamp;
      next.clear();
      for (uint32_t v : core)
        if (!std::isnan(crossing(S, v, Q, o.margin))) {
          mark[v] = taken;
          next.push_back(v);
        }
      grow(next, 0, -1, [&](uint32_t w) { return mark[w] == core_mark && !std::isnan(crossing(S, w, Q, o.margin)); });
      if (next.size() <= core.size()) return share;
      S.positions(next, pts);
      if (!constrained_fit(S, next, pts, Q.n, o.margin, P)) P = Q;
      core.swap(next);
    }
  }

  // The plane with normal within kRestabRange of P0's stabbing the most
  // sticks of `cand` (every stride-th, at most kRestabSample): a coarse then
  // a fine grid of directions; per direction, the best offset by a sweep.
  // Returns its count on those sticks; `now` receives P0's.
  size_t most_stabbing(const std::vector<uint32_t>& cand, const Plane& P0, Plane& out, size_t& now) const {
    const size_t stride = std::max<size_t>(1, cand.size() / kRestabSample);
    std::vector<uint32_t> use;
    for (size_t q = 0; q < cand.size(); q += stride) use.push_back(cand[q]);
    now = stabbed_by(use, P0);
    Vec3 u, v;
    frame(P0.n, u, v);
    struct Best {
      size_t count = 0;
      double c = 0;
    };
    // Starts and ends sorted apart and merged, a start first at equal
    // offsets; the best offset lies halfway to the next event.
    auto sweep = [&](const Vec3& d) {
      std::vector<double> starts, ends;
      starts.reserve(use.size());
      ends.reserve(use.size());
      for (uint32_t q : use) {
        const double a = d.dot(S.inside(q)), b = d.dot(S.outside(q));
        if (!(b > a)) continue;
        starts.push_back(a + o.margin * (b - a));
        ends.push_back(b - o.margin * (b - a));
      }
      std::sort(starts.begin(), starts.end());
      std::sort(ends.begin(), ends.end());
      Best r;
      size_t i = 0, j = 0;
      for (size_t open = 0; i < starts.size(); ++i) {
        while (ends[j] < starts[i]) ++j, --open;  // every start has its end at or after it
        if (++open > r.count) {
          r.count = open;
          const double next = i + 1 < starts.size() ? std::min(starts[i + 1], ends[j]) : ends[j];
          r.c = 0.5 * (starts[i] + next);
        }
      }
      return r;
    };
    Vec3 centre = P0.n;
    Best best = sweep(centre);
    Vec3 best_d = centre;
    const double coarse = kRestabRange / kRestabSteps;
    for (const auto& [step, half] : {std::pair{coarse, kRestabSteps}, std::pair{coarse / 4, 2}, std::pair{coarse / 16, 2}}) {
      const int side = 2 * half + 1;
      std::vector<Best> res(size_t(side * side));
      std::vector<Vec3> dir(res.size());
      const double h = std::tan(step * kPi / 180);
      for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) dir[size_t(i * side + j)] = (centre + (i - half) * h * u + (j - half) * h * v).normalized();
      detail::parallel_for(res.size(), [&](size_t k) { res[k] = sweep(dir[k]); });
      for (size_t k = 0; k < res.size(); ++k)  // fixed order: deterministic
        if (res[k].count > best.count) {
          best = res[k];
          best_d = dir[k];
        }
      centre = best_d;
      frame(centre, u, v);
    }
    out = {best_d, best.c};
    return best.count;
  }

  // Section 3's minimum size, plus width and bend (beyond the paper: without
  // them a plane tangent to a cylinder holds a long strip of its sticks).
  double area_of(const std::vector<uint32_t>& vs) const {
    double area = 0;
    for (uint32_t v : vs) area += S.area[v];
    return area;
  }

  bool accept(const std::vector<uint32_t>& core, const Plane& P) const;  // features/find_flats.cpp
};

// ------------------------------------------------------------ find_flats' stages
// What the stages of find_flats share: the input, the estimate's surface,
// the segmentation being built and the serial detector (its rim flags).
// Detection (votes, greedy extraction, merge) is in find_flats.cpp; the
// junctions, the extension to the sharp edges, the rim release, the sizes
// and the barriers in flat_junctions.cpp.
struct FlatsContext {
  FlatsContext(const StickSurface& surface, const std::vector<double>& estimate, const FlatOptions& options,
               FlatSegmentation& out, const detail::Adjacency& graph);
  const StickSurface& s;
  const FlatOptions& o;
  FlatSegmentation& seg;
  const size_t n;  // sticks
  const Surface S;
  const double cone, cos_cone;  // the voting cone (kFlatCone), in radians, and its cosine
  const Mat3 M, Minv_t;         // index -> physical, and its inverse transposed
  const double cell;            // the physical cell's size (cube root of its volume)
  const double cos_j;           // cosine of junction_angle
  Detector det;                 // the greedy loop's: accepted flats' rim flags; the merge grows with it
  tbb::enumerable_thread_specific<detail::RingScratch> scratch;  // the junction and tangent tests' rings
  // The last detection's smooth borders (tangent-borders) and junction
  // planes of the off-plane points (ring-off-plane).
  std::atomic<size_t> smooth_borders{0}, off_plane_junctions{0};
  size_t round_borders = 0;  // the last detection's junction vertices released by round-borders

  Flat flat_of(const Plane& P) const;
  // Physical height of index point x over flat F's plane, from its index
  // plane: F.offset includes the lattice's origin and the tests' points
  // (M x) do not, and the index plane does not depend on where the lattice
  // lies (Invariance.MovedOriginGivesTheSameT).
  double height(const Flat& F, const Vec3& x) const {
    return (F.index_normal.dot(x) - F.index_offset) / (Minv_t * F.index_normal).norm();
  }
  double frozen_t(uint32_t v, const Plane& P) const;
};

// The detection's steps after the growth (flat_junctions.cpp), in find_flats' order.
void extend_to_edges(FlatsContext& ctx);
size_t release_rim(FlatsContext& ctx);  // the members released
void measure_flats(FlatsContext& ctx);
void mark_barriers(FlatsContext& ctx, const SliceCurves& curves);

}  // namespace voxpress::flats_impl
