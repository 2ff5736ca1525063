// Flats by plane voting and junction points (Chica et al., Section 3).
// Theory of operation: include/voxpress/features/flats.h. Everything here
// works in index space (planes are affine-invariant); normals and angles
// that are compared with user thresholds are taken in the physical frame.
// find_flats runs Stage::detect's passes (the table in passes.cpp): votes
// and greedy extraction (flats), merge (here), then the extension to the
// sharp edges (junctions) and the rim release (flat_junctions.cpp), then
// the sizes and barriers; they share a FlatsContext (flat_detector.h).
#include "core/timing.h"
#include "feature_context.h"
#include "flat_detector.h"
#include "flat_geometry.h"
#include "smooth/quadric.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
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
#include <unordered_map>
#include "core/parallel.h"

namespace voxpress {

using detail::seconds_since;
using namespace flats_impl;

size_t FlatSegmentation::frozen_count() const {
  size_t c = 0;
  for (int32_t r : region) c += r >= 0;
  return c;
}

namespace flats_impl {

bool Detector::accept(const std::vector<uint32_t>& core, const Plane& P) const {
  if (area_of(core) < o.min_area) return false;
  // Spread of the normals about the plane's, robust to the rounded rims:
  // the median angle. A strip where a plane is tangent to a curved surface
  // is *defined* by the cone, so its normals fill it (median ~ cone / 2 at
  // any resolution, whether the strip is straight or a torus's ring); a
  // face's sit near the plane's normal. (Measured: strips 1.4-2.5 deg,
  // faces 0.2-1.25 deg with the default 3 deg cone.)
  std::vector<double> spread(core.size());
  for (size_t q = 0; q < core.size(); ++q) spread[q] = std::acos(std::clamp(S.nrm[core[q]].dot(P.n), -1.0, 1.0));
  std::nth_element(spread.begin(), spread.begin() + ptrdiff_t(spread.size() / 2), spread.end());
  // At 64^3 the estimate of a box is a pillow and its smaller faces spread
  // up to 1.8 deg: they are missed (docs/BENCHMARKS.md).
  if (spread[spread.size() / 2] > detail::kFlatMaxSpread * kPi / 180) return false;
  Vec3 u, v;
  frame(P.n, u, v);
  // In-plane coordinates, centred.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (uint32_t q : core) mean += Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v));
  mean /= double(core.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  // Normal bend: tangential normal components regressed on position,
  // (nu, nv) = A + B (pu, pv); B's largest singular value is a curvature.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
  for (uint32_t q : core) {
    const Eigen::Vector2d p = Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v)) - mean;
    cov += p * p.transpose();
    const Eigen::Vector3d a(1, p.x(), p.y());
    ata += a * a.transpose();
    atb += a * Eigen::RowVector2d(S.nrm[q].dot(u), S.nrm[q].dot(v));
  }
  cov /= double(core.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> pe(cov);
  if (std::sqrt(12 * std::max(0.0, pe.eigenvalues()(0))) < min_width(o)) return false;
  const Eigen::Matrix<double, 3, 2> coef = ata.ldlt().solve(atb);
  Eigen::Matrix2d B = coef.bottomRows<2>().transpose();  // rows: nu, nv; columns: d/dpu, d/dpv
  const Eigen::Matrix2d sym = 0.5 * (B + B.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> be(sym);
  const int big = std::abs(be.eigenvalues()(0)) > std::abs(be.eigenvalues()(1)) ? 0 : 1;
  const double kappa = std::abs(be.eigenvalues()(big));
  const Eigen::Vector2d dir = be.eigenvectors().col(big);
  double lo = 1e300, hi = -1e300;
  for (uint32_t q : core) {
    const double s = Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v)).dot(dir);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  return kappa * (hi - lo) <= detail::kFlatMaxBend * kPi / 180;
}

FlatsContext::FlatsContext(const StickSurface& surface, const std::vector<double>& estimate, const FlatOptions& options,
                           FlatSegmentation& out, const detail::Adjacency& graph)
    : s(surface),
      o(options),
      seg(out),
      n(surface.stick_count()),
      S(make_surface(surface, estimate, graph)),
      cone(detail::kFlatCone * kPi / 180),
      cos_cone(std::cos(cone)),
      M(surface.lattice.index_to_physical_matrix()),
      Minv_t(M.inverse().transpose()),
      cell(std::cbrt(std::abs(M.determinant()))),
      cos_j(std::cos(options.junction_angle * kPi / 180)),
      det{S, o, seg.region, std::vector<uint32_t>(n, 0), 0, cos_cone, std::vector<uint8_t>(n, 0)} {}

Flat FlatsContext::flat_of(const Plane& P) const {
  Flat f;
  f.index_normal = P.n;
  f.index_offset = P.c;
  // Physical plane: n_i . M^-1 (x - origin) = c.
  const Vec3 np = Minv_t * P.n;
  f.normal = np.normalized();
  f.offset = (P.c + np.dot(s.lattice.origin)) / np.norm();
  return f;
}

// Members were stabbed with the margin; only rounding could put t a hair
// outside it, so clamp (the sign test cannot fail: see crossing).
double FlatsContext::frozen_t(uint32_t v, const Plane& P) const {
  const double t = detail::leave(P, S.inside(v), S.outside(v));
  if (!(t >= 0 && t <= 1)) throw std::logic_error("find_flats: a flat's plane does not cross one of its sticks");
  return std::clamp(t, o.margin, 1 - o.margin);
}

}  // namespace flats_impl

namespace {

// The voters of cell c not in a flat yet, into `out`: whether they are
// enough to seed a cluster (kSeedShare).
bool seeds_of(const FlatsContext& ctx, const Votes& V, size_t c, std::vector<uint32_t>& out) {
  out.clear();
  for (uint32_t i = V.cell_begin[c]; i < V.cell_begin[c + 1]; ++i)
    if (ctx.seg.region[V.voter[i]] < 0) out.push_back(V.voter[i]);
  return double(out.size()) >= kSeedShare * ctx.o.min_area;
}

// Drops the stick's votes from the accumulator.
void unvote(Votes& V, uint32_t v) {
  for (uint32_t q = 0; q < V.count[v]; ++q) {
    const uint32_t cc = V.vote_cell[v * kMaxVotes + q];
    if (V.cell_count[cc] > 0) --V.cell_count[cc];
  }
  V.count[v] = 0;
}

// The accumulator's cells, best first (lazy max-heap of (count, -cell):
// ties by cell index).
using CellHeap = std::priority_queue<std::pair<uint32_t, int64_t>>;

// One cell's try: Detector::cluster_from's result and counters.
struct Try {
  size_t cell = 0;
  Plane P;
  std::vector<uint32_t> members, rejected;
  size_t rim_begin = 0, restabbed = 0, refused_curved = 0;
};

// The greedy loop is serial by definition (each flat takes its sticks
// from the later cells' seeds), but a try reads only the regions, which
// change only when a try is accepted, so the next cells the heap would
// pop are tried ahead, in parallel, each by its own detector (a sphere
// rejects ~1,700 cells at 256^3, a CAD part accepts 8 of ~180). A result
// is used only when no flat was accepted since it was computed; the
// order of the loop, and so the output, are those of the serial loop.
// Results are kept until a flat is accepted: a rejected core's unvotes
// reorder the heap, so a cell tried ahead is often popped a batch later.
// Tries after an accepted flat are mostly wasted (often the same face
// from a neighbouring cell), so the look-ahead starts at one cell after
// each acceptance and doubles with each rejection.
class Lookahead {
 public:
  Lookahead(const FlatsContext& ctx, const Votes& V)
      : ctx_(ctx), V_(V),
        threads_(std::min(size_t(tbb::this_task_arena::max_concurrency()),
                          tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))),
        detectors_([&ctx] {
          return Detector{ctx.S, ctx.o, ctx.seg.region, std::vector<uint32_t>(ctx.n, 0), 0, ctx.cos_cone,
                          std::vector<uint8_t>(ctx.n, 0)};
        }) {}

  // The try of cell c, the first of `heap`'s next cells; `accepted`: the
  // flats accepted so far, `streak`: rejections since the last acceptance.
  // The result leaves the look-ahead (each cell is tried once).
  Try result_of(size_t c, const CellHeap& heap, size_t accepted, size_t streak) {
    if (tries_version_ != accepted) {
      tries_.clear();
      tries_version_ = accepted;
    }
    if (auto node = tries_.extract(c)) return std::move(node.mapped());
    const std::vector<size_t> cells = next_cells(c, heap, streak);
    std::vector<Try> batch(cells.size());
    detail::parallel_for(cells.size(), [&](size_t k) {
      Try& t = batch[k];
      t.cell = cells[k];
      std::vector<uint32_t> own;
      if (!seeds_of(ctx_, V_, t.cell, own)) return;  // the loop skips it
      Detector& d = detectors_.local();
      const size_t restabbed = d.restabbed, refused = d.refused_curved;
      t.members = d.cluster_from(own, t.P, t.rejected);
      t.rim_begin = d.rim_begin;
      t.restabbed = d.restabbed - restabbed;
      t.refused_curved = d.refused_curved - refused;
    });
    for (Try& t : batch)
      if (t.cell != c) tries_.emplace(t.cell, std::move(t));
    return std::move(batch.front());
  }

 private:
  // The cells the loop would try after `first` if no flat were accepted
  // (those not tried yet).
  std::vector<size_t> next_cells(size_t first, const CellHeap& heap, size_t streak) const {
    const auto& cell_count = V_.cell_count;
    std::vector<size_t> cells{first};
    // Up to 4 per thread: enough to keep every thread busy.
    const size_t batch = threads_ <= 1 ? 1 : std::min(4 * threads_, size_t(1) << std::min<size_t>(streak, 10));
    if (batch == 1) return cells;
    auto h = heap;
    // Cells sharing no voter with the cells before them in the batch: a
    // rejection there does not lower their counts, so the loop pops them
    // before the next acceptance (a neighbouring cell's often falls below
    // the seed share and its try would be wasted).
    if (taken_.empty()) taken_.assign(ctx_.n, 0);  // only where batches run
    const uint32_t stamp = ++stamp_;
    const auto disjoint = [&](size_t c) {
      for (uint32_t i = V_.cell_begin[c]; i < V_.cell_begin[c + 1]; ++i)
        if (taken_[V_.voter[i]] == stamp) return false;
      return true;
    };
    const auto take = [&](size_t c) {
      for (uint32_t i = V_.cell_begin[c]; i < V_.cell_begin[c + 1]; ++i) taken_[V_.voter[i]] = stamp;
    };
    take(first);
    size_t scanned = 0;
    while (!h.empty() && cells.size() < batch && scanned++ < 8 * batch) {
      const auto [cnt, neg] = h.top();
      h.pop();
      const size_t c = size_t(-neg);
      if (std::find(cells.begin(), cells.end(), c) != cells.end() || tries_.count(c)) continue;
      if (cnt != cell_count[c]) {
        if (cell_count[c] > 0) h.push({cell_count[c], neg});
        continue;
      }
      if (double(cnt) < kSeedShare * ctx_.o.min_area) break;
      if (!disjoint(c)) continue;
      take(c);
      cells.push_back(c);
    }
    return cells;
  }

  const FlatsContext& ctx_;
  const Votes& V_;
  const size_t threads_;
  std::unordered_map<size_t, Try> tries_;  // since the last acceptance, by cell
  mutable std::vector<uint32_t> taken_;    // per vertex: the batch stamp of a cell it votes in
  mutable uint32_t stamp_ = 0;
  size_t tries_version_ = SIZE_MAX;        // `accepted` when tries_ were computed
  tbb::enumerable_thread_specific<Detector> detectors_;
};

// ---- Greedy extraction, best cell first (lazy max-heap; ties by cell index).
void extract_flats(FlatsContext& ctx, Votes& V, ProgressCounter& progress) {
  FlatSegmentation& seg = ctx.seg;
  Detector& det = ctx.det;
  auto& cell_count = V.cell_count;
  CellHeap heap;
  for (size_t c = 0; c < V.cell_key.size(); ++c) heap.push({cell_count[c], -int64_t(c)});
  Lookahead ahead(ctx, V);
  std::vector<uint32_t> seeds;
  size_t accepted = 0, streak = 0;  // streak: rejections since the last acceptance
  while (!heap.empty()) {
    const auto [cnt, neg] = heap.top();
    heap.pop();
    const size_t c = size_t(-neg);
    if (cnt != cell_count[c]) {
      if (cell_count[c] > 0) heap.push({cell_count[c], neg});
      continue;
    }
    // Too few voters to seed a cluster: nothing left can (kSeedShare).
    if (double(cnt) < kSeedShare * ctx.o.min_area) break;
    ++seg.stats.tried;
    cell_count[c] = 0;  // used: accepted or not, this cell is done
    if (!seeds_of(ctx, V, c, seeds)) continue;
    const Try tr = ahead.result_of(c, heap, accepted, streak);
    const Plane& P = tr.P;
    const std::vector<uint32_t>& rejected = tr.rejected;
    const std::vector<uint32_t>& members = tr.members;
    det.restabbed += tr.restabbed;
    det.refused_curved += tr.refused_curved;
    // A rejected core's vertices stop voting (they may still join a flat
    // grown from elsewhere): without this a cylinder's wall is tried once per
    // direction cell along its circle of normals.
    for (uint32_t v : rejected) unvote(V, v);
    if (members.empty()) {
      ++streak;
      continue;
    }
    streak = 0;
    const int32_t id = int32_t(seg.flats.size());
    for (size_t i = tr.rim_begin; i < members.size(); ++i) det.rim[members[i]] = 1;
    for (uint32_t v : members) {
      seg.region[v] = id;
      seg.t[v] = ctx.frozen_t(v, P);
      unvote(V, v);
    }
    seg.flats.push_back(ctx.flat_of(P));
    ++accepted;  // the region changed: the batch's other results are stale
    progress.add(1);
  }
}

// The members of flats a and b that plane P stabs.
std::vector<uint32_t> members_stabbed(const FlatsContext& ctx, const std::vector<std::vector<uint32_t>>& members,
                                      size_t a, size_t b, const Plane& P) {
  std::vector<uint32_t> stabbed;
  for (size_t f : {a, b})
    for (uint32_t v : members[f])
      if (!std::isnan(crossing(ctx.S, v, P, ctx.o.margin))) stabbed.push_back(v);
  return stabbed;
}

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
std::vector<uint32_t> joint(const FlatsContext& ctx, const std::vector<std::vector<uint32_t>>& members,
                            const std::vector<Plane>& planes, detail::RingScratch& rs, size_t a, size_t b, double need,
                            Plane& P) {
  const Surface& S = ctx.S;
  std::vector<uint32_t> core, stabbed;
  std::vector<Vec3> pts;
  for (const uint32_t inner : {0u, 3u}) {
    core.clear();
    for (size_t f : {a, b})
      for (uint32_t v : members[f]) {
        if (!ctx.det.near(v, planes[f], detail::kFlatTolerance)) continue;
        bool in = true;
        if (inner > 0) {
          detail::rings_around(v, inner, S.adj_off, S.adj, [](uint32_t) { return true; }, rs);
          for (const auto& [w, d] : rs.out) in &= ctx.seg.region[w] == int32_t(f);
        }
        if (in) core.push_back(v);
      }
    S.positions(core, pts);
    if (core.size() < 3 || !constrained_fit(S, core, pts, planes[a].n, ctx.o.margin, P)) continue;
    stabbed = members_stabbed(ctx, members, a, b, P);
    break;
  }
  for (const size_t f : {a, b}) {
    if (double(stabbed.size()) >= need) break;
    std::vector<uint32_t> own = members_stabbed(ctx, members, a, b, planes[f]);
    if (own.size() > stabbed.size()) {
      stabbed = std::move(own);
      P = planes[f];
    }
  }
  return stabbed;
}

// ---- Merge (beyond the paper): the greedy growth can take one face as
// two flats, each fitted to a piece whose estimate leans its own way (a
// piece of a plate's side a few degrees off). Adjacent
// flats whose normals are within merge_angle become one when one plane
// stabs the sticks of both cores (the constrained fit) and, of their
// members, at least 90 %; the rim is then grown again around them.
void merge_flats(FlatsContext& ctx) {
  const Surface& S = ctx.S;
  FlatSegmentation& seg = ctx.seg;
  Detector& det = ctx.det;
  const double cos_merge = std::cos(detail::kMergeAngle * kPi / 180);
  detail::RingScratch rs;
  std::vector<std::vector<uint32_t>> members(seg.flats.size());
  for (size_t v = 0; v < ctx.n; ++v)
    if (seg.region[v] >= 0) members[size_t(seg.region[v])].push_back(uint32_t(v));
  std::vector<Plane> planes(seg.flats.size());
  for (size_t f = 0; f < planes.size(); ++f) planes[f] = {seg.flats[f].index_normal, seg.flats[f].index_offset};
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
        std::vector<uint32_t> both = joint(ctx, members, planes, rs, a, b, need, P);
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
    kept.push_back(ctx.flat_of(planes[f]));
    for (uint32_t v : members[f]) seg.t[v] = ctx.frozen_t(v, planes[f]);
  }
  for (size_t v = 0; v < ctx.n; ++v)
    if (seg.region[v] >= 0) seg.region[v] = id[size_t(seg.region[v])];
  seg.flats = std::move(kept);
}

}  // namespace

namespace detail {

size_t flats_step(FeatureContext& c) {
  FlatsContext& ctx = *c.detect;
  FlatSegmentation& seg = ctx.seg;
  Votes V = cast_votes(ctx.S, ctx.cone);
  seg.stats.votes = V.votes;
  seg.stats.voters = V.voters;
  seg.stats.cells = V.cell_key.size();
  ProgressCounter progress(ctx.o.progress, "flats", 0);
  extract_flats(ctx, V, progress);
  c.times.count[size_t(Pass::stab_refit)] = ctx.det.restabbed;
  c.times.count[size_t(Pass::curved_test)] = ctx.det.refused_curved;
  return 0;  // press_with_flats counts the final flats
}

size_t merge_step(FeatureContext& c) {
  if (c.detect->seg.flats.size() > 1) merge_flats(*c.detect);
  return 0;  // merge_flats counts the merges
}

}  // namespace detail

FlatSegmentation find_flats(const StickSurface& s, const SliceCurves& curves, const std::vector<double>& estimate,
                            const FlatOptions& o) {
  return detail::find_flats(s, curves, estimate, o, detail::Adjacency(s.stick_count(), s.triangles));
}

FlatSegmentation detail::find_flats(const StickSurface& s, const SliceCurves& curves, const std::vector<double>& estimate,
                                    const FlatOptions& o, const Adjacency& graph) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.stick_count();
  if (estimate.size() != n) throw std::invalid_argument("find_flats: the estimate does not match the sticks");
  FlatSegmentation seg;
  seg.region.assign(n, -1);
  seg.t.assign(n, std::numeric_limits<double>::quiet_NaN());
  seg.junction.assign(n, 0);
  seg.barrier.assign(n, 0);
  if (n == 0) return seg;
  FlatsContext ctx(s, estimate, o, seg, graph);
  detail::FeatureContext fc{o.passes, seg.stats.passes};
  fc.detect = &ctx;
  detail::run_stage(Stage::detect, fc);
  // The detection's output: the flats' sizes and the slice curves' barriers.
  measure_flats(ctx);
  mark_barriers(ctx, curves);
  seg.stats.passes.count[size_t(Pass::tangent_borders)] = ctx.smooth_borders;
  seg.stats.passes.count[size_t(Pass::ring_off_plane)] = ctx.off_plane_junctions;
  seg.stats.passes.count[size_t(Pass::round_borders)] = ctx.round_borders;
  const PassTimes& p = seg.stats.passes;
  seg.stats.seconds_detect = p.seconds[size_t(Pass::flats)] + p.seconds[size_t(Pass::merge)];
  seg.stats.seconds_junctions = seconds_since(t0) - seg.stats.seconds_detect;
  return seg;
}

}  // namespace voxpress
