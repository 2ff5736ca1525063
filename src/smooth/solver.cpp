// Pressing's solver: the fixed point of the constrained bilaplacian map and
// how it is reached (Chica et al., Section 4; the acceleration is beyond
// the paper). Theory of operation: include/voxpress/smooth/pressing.h.
//
// The fixed point. One application of the paper's map T at arc length d:
// every curve proposes s^2 L^2(C) for each of its fresh vertices (curve_step),
// projected onto the vertex's stick; a vertex's two proposals are combined
// (PressOptions::weighting) and the vertex moves to
//   T(t)_i = clamp(t_i + dt_i, margin, 1 - margin);
// frozen vertices keep their t. The press's result is t* = T(t*), reached
// when the residual max_i |T(t)_i - t_i| (a fraction of the stick) is below
// PressOptions::tolerance; PressOptions::iterations is only a safety cap.
//
// How it is reached. (1) Warm start: the coarse stages of the coarse-to-fine
// schedule (d times 2^(levels-1), ..., 2) with heavy-ball momentum bring
// the long waves near their place in a few sweeps; they are a different
// map, so they only choose where the fine solve starts. (2) The fine solve:
// Anderson acceleration (type II, Walker & Ni 2011) of T at d, depth
// kAndersonDepth: each step is the combination of the last maps whose
// residuals combine to the least-squares smallest, projected on the box;
// the history restarts when the residual grows. The bilaplacian's slow
// modes (a curve's long waves damp by (k d)^4 per sweep) are what it
// removes. Every reduction is summed over fixed blocks in block order, so
// the result is the same for any thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <numbers>

#include "core/timing.h"
#include "smooth/curve_kernel.h"

namespace voxpress {

using detail::Family;
using detail::Metric;
using detail::seconds_since;

namespace {

constexpr size_t kAhead = 32;  // prefetch distance, in curve vertices
// Solver constants (measured: docs/BENCHMARKS.md, Pressing: the solver;
// `build/bench/bench_converge`).
constexpr int kWarmSweeps = 20;      // heavy-ball sweeps per coarse stage (the warm start)
constexpr int kAndersonDepth = 12;   // maps combined per Anderson step
constexpr int kMaxDepth = 32;        // the deepest history VP_DEPTH may ask
constexpr double kRestartGrowth = 4; // the history restarts when the residual's norm grows this much in one step
constexpr size_t kBlock = 1 << 13;   // vertices per block of the deterministic sums

// One sweep of the map at arc length d * scale: step[i] = the combined
// proposal of vertex i at positions x (0 for frozen vertices).
class Sweeper {
 public:
  Sweeper(const std::vector<Family>& families, int per_vertex, const std::vector<uint8_t>& frozen,
          const std::vector<uint8_t>& barrier, const PressOptions& o, size_t n)
      : fams_(families), per_vertex_(per_vertex), frozen_(frozen), barrier_(barrier), o_(o),
        weighted_(o.weighting != PressOptions::Weighting::equal), prop_(size_t(per_vertex) * n, 0),
        weight_(weighted_ ? size_t(per_vertex) * n : 0, 0) {
    s2_ = o.step * o.step;
    correction_ = 1 - std::cos(std::clamp(o.circle_correction, 0.0, 90.0) * std::numbers::pi / 180);
  }

  void operator()(const std::vector<double>& x, double scale, std::vector<double>& step) {
    for (const Family& fam : fams_) family(fam, x, scale);
    combine(x.size(), step, weighted_);
  }
 private:
  void combine(size_t n, std::vector<double>& step, bool weighted) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!frozen_.empty() && frozen_[i]) {
          step[i] = 0;
          continue;
        }
        const double* p = &prop_[size_t(per_vertex_) * i];
        if (per_vertex_ == 1) {
          step[i] = p[0];
        } else if (weighted) {
          const double w0 = weight_[2 * i], w1 = weight_[2 * i + 1];
          step[i] = w0 + w1 > 0 ? (w0 * p[0] + w1 * p[1]) / (w0 + w1) : 0;
        } else {
          step[i] = 0.5 * (p[0] + p[1]);
        }
      }
    });
  }

  void family(const Family& fam, const std::vector<double>& x, double scale);

  const std::vector<Family>& fams_;
  int per_vertex_;
  const std::vector<uint8_t>& frozen_;
  const std::vector<uint8_t>& barrier_;
  const PressOptions& o_;
  bool weighted_;
  double s2_ = 0, correction_ = 0;
  std::vector<double> prop_, weight_;
};

// One family's curves: every fresh vertex's proposal, in its slot.
void Sweeper::family(const Family& fam, const std::vector<double>& x, double scale) {
  const uint32_t* ids = fam.ids->data();
  const auto& off = *fam.offsets;
  const size_t total = fam.ids->size();
  const Metric& g = fam.g;
  const double* t = x.data();
  double* prop = prop_.data();
  // dt per unit displacement along u and v, for a stick along u (row 0) or v (row 1).
  const double proj[2][2] = {{1, g.g01 / g.g00}, {g.g01 / g.g11, 1}};
  const double d = o_.arc_length * scale * fam.cell;
  const auto& frozen = frozen_;
  const auto& barrier = barrier_;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, off.size() - 1, 32), [&](const tbb::blocked_range<size_t>& r) {
    detail::Scratch<Vec2> w;
    for (size_t c = r.begin(); c < r.end(); ++c) {
      const uint32_t b = off[c], m = off[c + 1] - b;
      auto emit = [&](uint32_t k, uint32_t i) {  // k: curve-vertex index, i: its place in the scratch
        const int mv = fam.mov[k];
        const uint32_t q = fam.dst[k];
        const Vec2& disp = w.disp[i];
        const Vec2& tangent = w.tangent[i];
        prop[q] = proj[mv][0] * disp.x() + proj[mv][1] * disp.y();
        if (weighted_) {
          // |cos| between the stick and the curve tangent, both unit in the metric.
          const Vec2 e = mv == 0 ? Vec2(1 / std::sqrt(g.g00), 0) : Vec2(0, 1 / std::sqrt(g.g11));
          const double cs = std::min(1.0, std::abs(g.dot(e, tangent)));
          weight_[q] = o_.weighting == PressOptions::Weighting::tangent ? cs : std::sqrt(1 - cs * cs);
        }
      };
      auto gather = [&](uint32_t i, uint32_t k) {
        // The curve-vertex order is not the vertex order: prefetch the
        // gathered t and the scattered proposal a little ahead.
        if (k + kAhead < total) {
          __builtin_prefetch(&t[ids[k + kAhead]]);
          __builtin_prefetch(&prop[fam.dst[k + kAhead]], 1);
        }
        const double tk = t[ids[k]], mv = double(fam.mov[k]);
        w.pos[i] = Vec2(fam.base[k].x() + (1 - mv) * tk, fam.base[k].y() + mv * tk);
      };
      auto apply = [&](uint32_t count, bool closed, bool free_ends) {
        detail::curve_step(count, closed, d, s2_, o_.resample, weighted_, correction_, g, w, free_ends);
      };
      // A curve, or a piece, whose vertices are all frozen proposes
      // nothing anyone reads (on a CAD part most of the vertices are
      // frozen flats, cut off by their barriers): skipped.
      const auto any_free = [&](uint32_t from, uint32_t count) {
        if (frozen.empty()) return true;
        for (uint32_t i = 0; i < count; ++i)
          if (!frozen[ids[b + (from + i) % m]]) return true;
        return false;
      };
      if (!fam.spans.empty() && fam.spans[c].open) {  // an open polyline with context ends
        const Family::Span& sp = fam.spans[c];
        if (!any_free(sp.lo, sp.hi - sp.lo)) continue;
        w.resize(m);
        for (uint32_t i = 0; i < m; ++i) gather(i, b + i);
        apply(m, false, sp.free != 0);
        for (uint32_t i = sp.lo; i < sp.hi; ++i) emit(b + i, i);
        continue;
      }
      // The curve, or its open pieces between barrier vertices, each
      // piece starting and ending at a barrier (cyclically).
      uint32_t first_barrier = m;
      if (!barrier.empty())
        for (uint32_t i = 0; i < m && first_barrier == m; ++i)
          if (barrier[ids[b + i]]) first_barrier = i;
      if (first_barrier == m) {
        if (!any_free(0, m)) continue;
        w.resize(m);
        for (uint32_t i = 0; i < m; ++i) gather(i, b + i);
        apply(m, true, false);
        for (uint32_t i = 0; i < m; ++i) emit(b + i, i);
        continue;
      }
      // Open pieces from barrier to barrier; the barrier ends stay fixed.
      for (uint32_t k = 0; k < m;) {
        uint32_t len = 1;
        while (!barrier[ids[b + (first_barrier + k + len) % m]]) ++len;
        if (!any_free(first_barrier + k + 1, len - 1)) {
          k += len;
          continue;
        }
        // Free ends: the piece without its two barriers (PressOptions::free_ends).
        const bool loose = o_.free_ends && len >= detail::kFreePiece;
        const uint32_t lo = loose ? 1 : 0, count = loose ? len - 1 : len + 1;
        w.resize(count);
        for (uint32_t i = 0; i < count; ++i) gather(i, b + (first_barrier + k + lo + i) % m);
        apply(count, false, loose);
        for (uint32_t i = 1; i < len; ++i) emit(b + (first_barrier + k + i) % m, i - lo);
        k += len;
      }
    }
  });
}

// Sums over [0, n) in fixed blocks added in block order: the same bits for
// any thread count. `terms(i, acc)` adds vertex i's K terms into acc.
template <int K, class Terms>
std::array<double, K> block_sums(size_t n, const Terms& terms) {
  const size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::array<double, K>> part(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    std::array<double, K> acc{};
    const size_t end = std::min(n, (b + 1) * kBlock);
    for (size_t i = b * kBlock; i < end; ++i) terms(i, acc);
    part[b] = acc;
  });
  std::array<double, K> sum{};
  for (const auto& p : part)
    for (int k = 0; k < K; ++k) sum[size_t(k)] += p[size_t(k)];
  return sum;
}

double max_abs(const std::vector<double>& f) {
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, f.size(), 1 << 14), 0.0,
      [&](const tbb::blocked_range<size_t>& r, double acc) {
        for (size_t i = r.begin(); i < r.end(); ++i) acc = std::max(acc, std::abs(f[i]));
        return acc;
      },
      [](double a, double b) { return std::max(a, b); });
}

// Anderson acceleration's history: the last `depth` differences of
// residuals (dF) and of maps (dG), a ring buffer, with their Gram matrix.
struct History {
  History(size_t size, int depth) : n(size), dF(size_t(depth)), dG(size_t(depth)), gram(depth, depth) {}
  size_t n;
  int count = 0, head = 0;  // columns held; the next column to overwrite
  std::vector<std::vector<double>> dF, dG;
  Eigen::MatrixXd gram;
  int depth() const { return int(dF.size()); }

  void clear() { count = head = 0; }
  // Adds the column (f - f_prev, g - g_prev).
  void push(const std::vector<double>& f, const std::vector<double>& fp, const std::vector<double>& g,
            const std::vector<double>& gp) {
    const size_t c = size_t(head);
    if (dF[c].empty()) dF[c].resize(n), dG[c].resize(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) dF[c][i] = f[i] - fp[i], dG[c][i] = g[i] - gp[i];
    });
    head = (head + 1) % depth();
    count = std::min(count + 1, depth());
    const auto dots = block_sums<kMaxDepth>(n, [&](size_t i, auto& acc) {
      for (int j = 0; j < count; ++j) acc[size_t(j)] += dF[c][i] * dF[size_t(j)][i];
    });
    for (int j = 0; j < count; ++j) gram(int(c), j) = gram(j, int(c)) = dots[size_t(j)];
  }
};

}  // namespace

PressStats detail::iterate(std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                           const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& barrier,
                           const PressOptions& o, int levels) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = t.size();
  PressStats st;
  for (const Family& f : families) st.curves += f.offsets->size() - 1;
  for (uint8_t x : frozen) st.frozen += x != 0;
  st.fresh = n - st.frozen;
  st.levels = levels;
  if (n == 0 || st.fresh == 0) return st;
  Sweeper sweep(families, per_vertex, frozen, barrier, o, n);
  std::vector<double> step(n);
  const double lo = o.margin, hi = 1 - o.margin;
  const int cap = std::max(o.iterations, 0);
  ProgressCounter progress(o.progress, "pressing", uint64_t(cap));
  // (1) The warm start: heavy-ball sweeps on the coarse stages.
  std::vector<double> velocity(o.momentum != 0 && levels > 1 ? n : 0, 0.0);
  const int warm = std::getenv("VP_WARM") ? std::atoi(std::getenv("VP_WARM")) : kWarmSweeps;
  for (int stage = 0; stage + 1 < levels && cap > 0; ++stage) {
    const double scale = double(1 << (levels - 1 - stage));
    for (int k = 0; k < warm; ++k) {
      sweep(t, scale, step);
      tbb::parallel_for(size_t(0), n, [&](size_t i) {
        double dt = step[i];
        if (!velocity.empty()) dt += o.momentum * velocity[i];
        const double t_new = frozen.empty() || !frozen[i] ? std::clamp(t[i] + dt, lo, hi) : t[i];
        if (!velocity.empty()) velocity[i] = t_new - t[i];
        t[i] = t_new;
      });
      ++st.warm_sweeps;
    }
  }
  velocity = {};
  // (2) The fine solve: the Anderson-accelerated map at d, until the residual is met.
  std::vector<double> g(n), f(n), gp(n), fp(n);
  History hist(n, std::getenv("VP_DEPTH") ? std::atoi(std::getenv("VP_DEPTH")) : kAndersonDepth);
  double prev_norm = 0;
  for (int it = 0;; ++it) {
    sweep(t, 1, step);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      g[i] = frozen.empty() || !frozen[i] ? std::clamp(t[i] + step[i], lo, hi) : t[i];
      f[i] = g[i] - t[i];
    });
    st.residual = max_abs(f);
    if (std::getenv("VP_TRACE")) {
      size_t c1 = 0, c2 = 0, c3 = 0, atb = 0;
      for (size_t i = 0; i < n; ++i) {
        const double a = std::abs(f[i]);
        c1 += a > 0.1 * st.residual; c2 += a > 0.01 * st.residual; c3 += a > 1e-3 * st.residual;
        atb += (t[i] <= lo || t[i] >= hi);
      }
      std::fprintf(stderr, "it %d residual %.3e  >10%%: %zu >1%%: %zu >0.1%%: %zu  at bounds %zu of %zu\n", it, st.residual, c1, c2, c3, atb, n);
    }
    st.least_residual = it == 0 ? st.residual : std::min(st.least_residual, st.residual);
    if (st.residual <= o.tolerance || it >= cap) break;  // t is the point whose residual is reported
    st.iterations = it + 1;
    progress.add(1);
    const double norm = std::sqrt(block_sums<1>(n, [&](size_t i, auto& acc) { acc[0] += f[i] * f[i]; })[0]);
    if (it > 0 && norm > kRestartGrowth * prev_norm) {
      hist.clear();
      ++st.restarts;
    } else if (it > 0) {
      hist.push(f, fp, g, gp);
    }
    prev_norm = norm;
    std::swap(f, fp);
    std::swap(g, gp);  // fp, gp: this step's residual and map
    if (hist.count == 0) {
      t = gp;
      continue;
    }
    // gamma = argmin |f - dF gamma|: the normal equations, slightly regularised.
    const int m = hist.count;
    const auto rhs = block_sums<kMaxDepth>(n, [&](size_t i, auto& acc) {
      for (int j = 0; j < m; ++j) acc[size_t(j)] += hist.dF[size_t(j)][i] * fp[i];
    });
    Eigen::MatrixXd A = hist.gram.topLeftCorner(m, m);
    Eigen::VectorXd b(m);
    for (int j = 0; j < m; ++j) b[j] = rhs[size_t(j)];
    A.diagonal().array() += 1e-10 * A.diagonal().maxCoeff() + 1e-300;
    const Eigen::VectorXd gamma = A.ldlt().solve(b);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!frozen.empty() && frozen[i]) continue;
        double x = gp[i];
        for (int j = 0; j < m; ++j) x -= gamma[j] * hist.dG[size_t(j)][i];
        t[i] = std::clamp(x, lo, hi);
      }
    });
  }
  st.seconds = seconds_since(t0);
  return st;
}

}  // namespace voxpress
