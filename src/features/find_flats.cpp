// Flats by plane voting and junction points (Chica et al., Section 3).
// Theory of operation: include/voxpress/features/flats.h. Everything here
// works in index space (planes are affine-invariant); normals and angles
// that are compared with user thresholds are taken in the physical frame.
#include "core/timing.h"
#include "flat_detector.h"
#include "flat_geometry.h"
#include "smooth/quadric.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <tuple>

namespace voxpress {

using detail::seconds_since;
using namespace flats_impl;

size_t FlatSegmentation::frozen_count() const {
  size_t c = 0;
  for (int32_t r : region) c += r >= 0;
  return c;
}

FlatSegmentation find_flats(const StickSurface& s, const SliceCurves& curves, const std::vector<double>& estimate,
                            const FlatOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.stick_count();
  if (estimate.size() != n) throw std::invalid_argument("find_flats: the estimate does not match the sticks");
  FlatSegmentation seg;
  seg.region.assign(n, -1);
  seg.t.assign(n, std::numeric_limits<double>::quiet_NaN());
  seg.junction.assign(n, 0);
  seg.barrier.assign(n, 0);
  if (n == 0) return seg;
  const Surface S = make_surface(s, estimate);
  const double cone = detail::kFlatCone * kPi / 180, cos_cone = std::cos(cone);

  // ---- Votes (Section 3).
  Votes V = cast_votes(S, cone);
  seg.stats.votes = V.votes;
  seg.stats.voters = V.voters;
  seg.stats.cells = V.cell_key.size();
  const auto& cell_key = V.cell_key;
  const auto& cell_begin = V.cell_begin;
  auto& cell_count = V.cell_count;
  auto& count = V.count;

  // ---- Greedy extraction, best cell first (lazy max-heap; ties by cell index).
  std::priority_queue<std::pair<uint32_t, int64_t>> heap;
  for (size_t c = 0; c < cell_key.size(); ++c) heap.push({cell_count[c], -int64_t(c)});
  Detector det{S, o, seg.region, std::vector<uint32_t>(n, 0), 0, cos_cone, std::vector<uint8_t>(n, 0)};
  ProgressCounter progress(o.progress, "flats", 0);
  const Mat3 M = s.lattice.index_to_physical_matrix();
  const Mat3 Minv_t = M.inverse().transpose();
  auto flat_of = [&](const Plane& P) {
    Flat f;
    f.index_normal = P.n;
    f.index_offset = P.c;
    // Physical plane: n_i . M^-1 (x - origin) = c.
    const Vec3 np = Minv_t * P.n;
    f.normal = np.normalized();
    f.offset = (P.c + np.dot(s.lattice.origin)) / np.norm();
    return f;
  };
  // Members were stabbed with the margin; only rounding could put t a hair
  // outside it, so clamp (the sign test cannot fail: see crossing).
  auto frozen_t = [&](uint32_t v, const Plane& P) {
    const double t = detail::leave(P, S.inside(v), S.outside(v));
    if (!(t >= 0 && t <= 1)) throw std::logic_error("find_flats: a flat's plane does not cross one of its sticks");
    return std::clamp(t, o.margin, 1 - o.margin);
  };
  // The voters of cell c not in a flat yet, into `out`: whether they are
  // enough to seed a cluster (kSeedShare).
  auto seeds_of = [&](size_t c, std::vector<uint32_t>& out) {
    out.clear();
    for (uint32_t i = cell_begin[c]; i < cell_begin[c + 1]; ++i)
      if (seg.region[V.voter[i]] < 0) out.push_back(V.voter[i]);
    return double(out.size()) >= kSeedShare * o.min_area;
  };
  std::vector<uint32_t> seeds;
  auto unvote = [&](uint32_t v) {  // drops the stick's votes from the accumulator
    for (uint32_t q = 0; q < count[v]; ++q) {
      const uint32_t cc = V.vote_cell[v * kMaxVotes + q];
      if (cell_count[cc] > 0) --cell_count[cc];
    }
    count[v] = 0;
  };
  // The greedy loop is serial by definition (each flat takes its sticks
  // from the later cells' seeds), but a try reads only the regions, which
  // change only when a try is accepted, so the next cells the heap would
  // pop are tried ahead, in parallel, each by its own detector (a sphere
  // rejects ~1,700 cells at 256^3, a CAD part accepts 8 of ~180). A result
  // is used only when no flat was accepted since it was computed; the
  // order of the loop, and so the output, are those of the serial loop.
  // Tries after an accepted flat are mostly wasted (often the same face
  // from a neighbouring cell), so the look-ahead starts at one cell after
  // each acceptance and doubles with each rejection.
  struct Try {
    size_t cell = 0;
    Plane P;
    std::vector<uint32_t> members, rejected;
    size_t rim_begin = 0, restabbed = 0, refused_curved = 0;
  };
  const size_t threads = size_t(tbb::this_task_arena::max_concurrency());
  std::vector<Try> tries;
  size_t accepted = 0, tries_version = SIZE_MAX, streak = 0;  // streak: rejections since the last acceptance
  tbb::enumerable_thread_specific<Detector> detectors([&] {
    return Detector{S, o, seg.region, std::vector<uint32_t>(n, 0), 0, cos_cone, std::vector<uint8_t>(n, 0)};
  });
  // The cells the loop would try after `first` if no flat were accepted.
  auto next_cells = [&](size_t first) {
    std::vector<size_t> cells{first};
    // Up to 4 per thread: enough to keep every thread busy.
    const size_t batch = threads == 1 ? 1 : std::min(4 * threads, size_t(1) << std::min<size_t>(streak, 10));
    if (batch == 1) return cells;
    auto h = heap;
    while (!h.empty() && cells.size() < batch) {
      const auto [cnt, neg] = h.top();
      h.pop();
      const size_t c = size_t(-neg);
      if (std::find(cells.begin(), cells.end(), c) != cells.end()) continue;
      if (cnt != cell_count[c]) {
        if (cell_count[c] > 0) h.push({cell_count[c], neg});
        continue;
      }
      if (double(cnt) < kSeedShare * o.min_area) break;
      cells.push_back(c);
    }
    return cells;
  };
  auto result_of = [&](size_t c) -> const Try& {
    if (tries_version == accepted)
      for (const Try& t : tries)
        if (t.cell == c) return t;
    const std::vector<size_t> cells = next_cells(c);
    tries.assign(cells.size(), Try{});
    tbb::parallel_for(size_t(0), cells.size(), [&](size_t k) {
      Try& t = tries[k];
      t.cell = cells[k];
      std::vector<uint32_t> own;
      if (!seeds_of(t.cell, own)) return;  // the loop skips it
      Detector& d = detectors.local();
      const size_t restabbed = d.restabbed, refused = d.refused_curved;
      t.members = d.cluster_from(own, t.P, t.rejected);
      t.rim_begin = d.rim_begin;
      t.restabbed = d.restabbed - restabbed;
      t.refused_curved = d.refused_curved - refused;
    });
    tries_version = accepted;
    return tries.front();
  };
  while (!heap.empty()) {
    const auto [cnt, neg] = heap.top();
    heap.pop();
    const size_t c = size_t(-neg);
    if (cnt != cell_count[c]) {
      if (cell_count[c] > 0) heap.push({cell_count[c], neg});
      continue;
    }
    // Too few voters to seed a cluster: nothing left can (kSeedShare).
    if (double(cnt) < kSeedShare * o.min_area) break;
    ++seg.stats.tried;
    cell_count[c] = 0;  // used: accepted or not, this cell is done
    if (!seeds_of(c, seeds)) continue;
    const Try& tr = result_of(c);
    const Plane& P = tr.P;
    const std::vector<uint32_t>& rejected = tr.rejected;
    const std::vector<uint32_t>& members = tr.members;
    det.restabbed += tr.restabbed;
    det.refused_curved += tr.refused_curved;
    // A rejected core's vertices stop voting (they may still join a flat
    // grown from elsewhere): without this a cylinder's wall is tried once per
    // direction cell along its circle of normals.
    for (uint32_t v : rejected) unvote(v);
    if (members.empty()) {
      ++streak;
      continue;
    }
    streak = 0;
    const int32_t id = int32_t(seg.flats.size());
    for (size_t i = tr.rim_begin; i < members.size(); ++i) det.rim[members[i]] = 1;
    for (uint32_t v : members) {
      seg.region[v] = id;
      seg.t[v] = frozen_t(v, P);
      unvote(v);
    }
    seg.flats.push_back(flat_of(P));
    ++accepted;  // the region changed: the batch's other results are stale
    progress.add(1);
  }
  // ---- Merge (beyond the paper): the greedy growth can take one face as
  // two flats, each fitted to a piece whose estimate leans its own way (a
  // piece of a plate's side a few degrees off). Adjacent
  // flats whose normals are within merge_angle become one when one plane
  // stabs the sticks of both cores (the constrained fit) and, of their
  // members, at least 90 %; the rim is then grown again around them.
  const auto t_merge = std::chrono::steady_clock::now();
  if (o.passes.on(Pass::merge) && seg.flats.size() > 1) {
    const double cos_merge = std::cos(detail::kMergeAngle * kPi / 180);
    detail::RingScratch rs;
    std::vector<std::vector<uint32_t>> members(seg.flats.size());
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) members[size_t(seg.region[v])].push_back(uint32_t(v));
    std::vector<Plane> planes(seg.flats.size());
    for (size_t f = 0; f < planes.size(); ++f) planes[f] = {seg.flats[f].index_normal, seg.flats[f].index_offset};
    // The members of flats a and b that plane P stabs.
    auto members_stabbed = [&](size_t a, size_t b, const Plane& P) {
      std::vector<uint32_t> stabbed;
      for (size_t f : {a, b})
        for (uint32_t v : members[f])
          if (!std::isnan(crossing(S, v, P, o.margin))) stabbed.push_back(v);
      return stabbed;
    };
    // The plane stabbing the cores of flats a and b: their members near
    // their own plane, then (when no plane stabs them all) only those
    // `inner` rings inside their flat, since a tilted plane's core reaches
    // past the face's rounded edges. When that plane stabs fewer than `need`
    // of their members (or none stabs the cores), each flat's own plane is
    // tried too: a face split into an accurate piece and one whose core
    // reaches onto a rounded edge (a chamfer's two pieces a quarter of a
    // degree apart, no plane stabbing both cores, each plane stabbing
    // nearly all of the other's members). Returns the members
    // the chosen plane P stabs.
    auto joint = [&](size_t a, size_t b, double need, Plane& P) {
      std::vector<uint32_t> core, stabbed;
      std::vector<Vec3> pts;
      for (const uint32_t inner : {0u, 3u}) {
        core.clear();
        for (size_t f : {a, b})
          for (uint32_t v : members[f]) {
            if (!det.near(v, planes[f], detail::kFlatTolerance)) continue;
            bool in = true;
            if (inner > 0) {
              detail::rings_around(v, inner, S.adj_off, S.adj, [](uint32_t) { return true; }, rs);
              for (const auto& [w, d] : rs.out) in &= seg.region[w] == int32_t(f);
            }
            if (in) core.push_back(v);
          }
        S.positions(core, pts);
        if (core.size() < 3 || !constrained_fit(S, core, pts, planes[a].n, o.margin, P)) continue;
        stabbed = members_stabbed(a, b, P);
        break;
      }
      for (const size_t f : {a, b}) {
        if (double(stabbed.size()) >= need) break;
        std::vector<uint32_t> own = members_stabbed(a, b, planes[f]);
        if (own.size() > stabbed.size()) {
          stabbed = std::move(own);
          P = planes[f];
        }
      }
      return stabbed;
    };
    for (bool merged = true; merged;) {
      merged = false;
      for (size_t a = 0; a < members.size() && !merged; ++a) {
        std::vector<uint8_t> touches(members.size(), 0);
        for (uint32_t v : members[a])
          for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k)
            if (const int32_t r = seg.region[S.adj[k]]; r >= 0) touches[size_t(r)] = 1;
        for (size_t b = a + 1; b < members.size() && !merged; ++b) {
          if (!touches[b] || planes[a].n.dot(planes[b].n) < cos_merge) continue;
          Plane P;
          const double need = 0.9 * double(members[a].size() + members[b].size());
          std::vector<uint32_t> both = joint(a, b, need, P);
          if (double(both.size()) < need) continue;
          for (size_t f : {a, b})
            for (uint32_t v : members[f]) {
              seg.region[v] = -1;
              seg.t[v] = std::numeric_limits<double>::quiet_NaN();
              det.rim[v] = 0;
            }
          ++det.stamp;
          for (uint32_t v : both) det.mark[v] = det.stamp;
          det.grow_rim(both, P);
          for (uint32_t v : both) seg.region[v] = int32_t(a);
          members[a] = std::move(both);
          members[b].clear();
          planes[a] = P;
          merged = true;
          ++seg.stats.passes.count[size_t(Pass::merge)];
        }
      }
    }
    // Renumber the survivors in order, with their planes and frozen t.
    std::vector<Flat> kept;
    std::vector<int32_t> id(members.size(), -1);
    for (size_t f = 0; f < members.size(); ++f) {
      if (members[f].empty()) continue;
      id[f] = int32_t(kept.size());
      kept.push_back(flat_of(planes[f]));
      for (uint32_t v : members[f]) seg.t[v] = frozen_t(v, planes[f]);
    }
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) seg.region[v] = id[size_t(seg.region[v])];
    seg.flats = std::move(kept);
  }
  seg.stats.passes.seconds[size_t(Pass::merge)] = seconds_since(t_merge);
  seg.stats.passes.count[size_t(Pass::stab_refit)] = det.restabbed;
  seg.stats.passes.count[size_t(Pass::curved_test)] = det.refused_curved;
  seg.stats.seconds_detect = seconds_since(t0);

  // ---- Junctions (Section 3): fresh vertices next to a frozen one whose
  // fresh 2-ring plane leans more than junction_angle from the flat.
  const auto t1 = std::chrono::steady_clock::now();
  const double cos_j = std::cos(o.junction_angle * kPi / 180);
  const double cell = std::cbrt(std::abs(M.determinant()));
  tbb::enumerable_thread_specific<detail::RingScratch> scratch;
  // Beyond the paper: whether the curved side of fresh vertex v continues
  // flat f tangentially within `cos_max`: a quadric fitted to the fresh
  // vertices kTangentRings away (on the estimate) fits within
  // tangent_residual and its normal, where v projects onto the flat, is
  // within that angle of the flat's. A fillet passes; at a true crease the
  // estimate is rounded, so the fit is poor or its normal there leans. With
  // min_rise > 0 the fitted points must also reach that many cells off the
  // flat's plane.
  const auto fresh = [&](uint32_t w) { return seg.region[w] < 0; };
  // The flat of v's first frozen neighbour, or -1.
  const auto first_flat = [&](size_t v) {
    int32_t f0 = -1;
    for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1] && f0 < 0; ++k) f0 = seg.region[S.adj[k]];
    return f0;
  };
  auto tangent = [&](uint32_t v, int32_t f, double cos_max, double min_rise, detail::RingScratch& rs,
                     std::vector<Vec3>& pts) {
    detail::rings_around(v, kTangentRings[1], S.adj_off, S.adj, fresh, rs);
    pts.clear();
    Vec3 outward = Vec3::Zero();
    for (const auto& [w, d] : rs.out)
      if (d >= kTangentRings[0]) {
        pts.push_back(M * S.x[w]);
        outward += M * (S.outside(w) - S.inside(w));
      }
    detail::Quadric Q;
    const Flat& F = seg.flats[size_t(f)];
    if (min_rise > 0) {
      double rise = 0;
      for (const Vec3& p : pts) rise = std::max(rise, std::abs(F.normal.dot(p) - F.offset));
      if (rise < min_rise * cell) return false;
    }
    if (!Q.fit(pts, outward) || Q.residual > detail::kTangentResidual * cell) return false;
    const Vec3 p = M * S.x[v];
    const Vec3 foot = p - (F.normal.dot(p) - F.offset) * F.normal;
    return std::abs(Q.normal_at(foot).dot(F.normal)) >= cos_max;
  };
  // The last detection's smooth borders (tangent-borders) and junction
  // planes of the off-plane points (ring-off-plane).
  std::atomic<size_t> smooth_borders{0}, off_plane_junctions{0};
  auto detect_junctions = [&] {
    std::fill(seg.junction.begin(), seg.junction.end(), 0);
    smooth_borders = 0;
    off_plane_junctions = 0;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<Vec3> pts;
      detail::RingScratch& rs = scratch.local();
      for (size_t v = r.begin(); v < r.end(); ++v) {
        if (seg.region[v] >= 0) continue;
        const int32_t f0 = first_flat(v);
        if (f0 < 0) continue;
        // Fresh vertices of the 2-ring (v included), in physical space.
        detail::rings_around(uint32_t(v), 2, S.adj_off, S.adj, fresh, rs);
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
              const Vec3 p = M * S.x[w];
              if (w == v || std::abs(F.normal.dot(p) - F.offset) > detail::kJunctionRingOffPlane * cell) pts.push_back(p);
            }
            if (pts.size() >= 3) {
              q = pca(pts);
              off_plane = q.eigenvalues(1) >= kThinRow * q.eigenvalues(2);
              if (off_plane) ++off_plane_junctions;
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
              if (f < 0 || std::abs(ns.dot(seg.flats[size_t(f)].normal)) >= cos_j) continue;
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
              sharp = !(o.passes.on(Pass::tangent_borders) && tangent(uint32_t(v), leaning[i], cos_j, 0, rs, pts));
            if (!sharp && leaning_count > 0) ++smooth_borders;
          }
        }
        seg.junction[v] = sharp;
      }
    });
  };
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
  // Beyond the paper: flats reach their sharp edges. At a convex edge the
  // solid is the intersection of the two half-spaces, so every stick there
  // is stabbed by at least one of the planes and its true crossing is the
  // one nearest its inside sample; at a concave edge (union) the farthest.
  // A fresh vertex flagged as a junction joins a neighbouring flat whose
  // plane stabs its stick, and a frozen vertex moves to a neighbouring flat
  // when that rule prefers it; a few rounds, junctions recomputed each time.
  // Smooth borders (no junction) are left to the smoothing.
  auto prefer = [&](int32_t f, double tf, int32_t g, double tg) {
    // true when (g, tg) is the better crossing than (f, tf) for this stick
    const bool convex = planes[size_t(g)].n.dot(centroid[size_t(f)]) < planes[size_t(g)].c;
    return convex ? tg < tf : tg > tf;
  };
  std::vector<uint8_t> refitted;
  bool stale = true;  // regions changed since the junctions were last detected
  for (int round = 0; round < kExtendRounds && !seg.flats.empty(); ++round) {
    if (stale) detect_junctions();
    stale = false;
    // Beyond the paper: the planes also keep their creases' samples on the right side.
    const auto t_refit = std::chrono::steady_clock::now();
    const bool refit = o.passes.on(Pass::crease_refit) && crease_refit(S, o, seg, planes, refitted);
    seg.stats.passes.seconds[size_t(Pass::crease_refit)] += seconds_since(t_refit);
    if (refit) {
      for (size_t f = 0; f < planes.size(); ++f)
        if (refitted[f]) seg.flats[f] = flat_of(planes[f]);
      for (size_t v = 0; v < n; ++v)
        if (const int32_t f = seg.region[v]; f >= 0 && refitted[size_t(f)]) seg.t[v] = frozen_t(uint32_t(v), planes[size_t(f)]);
      detect_junctions();
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
  if (stale) detect_junctions();
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
  const auto t_rim = std::chrono::steady_clock::now();
  if (o.passes.on(Pass::rim_tangent) && !seg.flats.empty()) {
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
      if (const int32_t f0 = first_flat(v); f0 >= 0) borders.push_back({v, f0});
    }
    // The smooth borders that are tangent (in parallel; each test reads the
    // regions only).
    std::vector<uint8_t> is_tangent(borders.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, borders.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<Vec3> pts;
      detail::RingScratch& rs = scratch.local();
      for (size_t i = r.begin(); i < r.end(); ++i)
        is_tangent[i] = tangent(borders[i].first, borders[i].second, cos_t, kRimFilletRise, rs, pts);
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
      if (seg.region[v] >= 0 && det.rim[v] && near_tangent[v] != detail::kUnreached &&
          near_junction[v] == detail::kUnreached) {
        seg.region[v] = -1;
        seg.t[v] = std::numeric_limits<double>::quiet_NaN();
        ++released;
      }
    seg.stats.rim_released = released;
    seg.stats.passes.count[size_t(Pass::rim_tangent)] = released;
    if (released > 0) detect_junctions();
  }
  seg.stats.passes.seconds[size_t(Pass::rim_tangent)] = seconds_since(t_rim);
  // Sizes, once the extension has settled the members. Index-space area ->
  // physical: |det M| |M^-T n| for a plane of unit index normal n.
  for (Flat& f : seg.flats) f.sticks = 0, f.area_cells = 0;
  for (size_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0) {
      Flat& f = seg.flats[size_t(seg.region[v])];
      ++f.sticks;
      f.area_cells += S.area[v];
    }
  for (Flat& f : seg.flats) f.area = f.area_cells * std::abs(M.determinant()) * (Minv_t * f.index_normal).norm();
  // Barriers: frozen vertices next to a junction along a slice curve.
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
  for (size_t v = 0; v < n; ++v) {
    seg.stats.junctions += seg.junction[v];
    seg.stats.barriers += seg.barrier[v];
  }
  seg.stats.passes.count[size_t(Pass::tangent_borders)] = smooth_borders;
  seg.stats.passes.count[size_t(Pass::ring_off_plane)] = off_plane_junctions;
  seg.stats.seconds_junctions = seconds_since(t1);
  return seg;
}


}  // namespace voxpress
