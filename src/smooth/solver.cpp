// Pressing's solver: the fixed point of the constrained bilaplacian map and
// how it is reached (Chica et al., Section 4; the acceleration is beyond
// the paper). Theory of operation: include/voxpress/smooth/pressing.h.
//
// The fixed point. One application of the paper's map T at arc length d:
// every curve proposes s^2 L^2(C) for each of its fresh vertices (curve_step),
// projected onto the vertex's stick; a vertex's two proposals are combined
// (PressOptions::weighting) and the vertex moves to
//   T(t)_i = clamp(t_i + dt_i, margin, 1 - margin);
// frozen vertices keep their t. The press approaches t* = T(t*); the
// residual max_i |T(t)_i - t_i| (a fraction of the stick) says how close
// (PressStats::residual), and a residual at most PressOptions::tolerance
// ends the solve.
//
// How it is approached (beyond the paper): the sweeps are split evenly into
// coarse-to-fine stages (d times 2^(levels-1), ..., 2, 1) with heavy-ball
// momentum on each change of t; the last stage is the map at d, and the
// solve stops there as soon as the residual is met, or at the sweep cap.
// The residual is always measured on the map at d at the returned t.
// Why it is slow (docs/BENCHMARKS.md, Pressing: the solver): the fixed
// point is nearly singular. The bilaplacian's null space (curves locally
// cubic) is pinned only by the few vertices at their clamps (under 1 %), so
// the map's exact Jacobian has a global smooth direction of eigenvalue
// ~1e-4 along which its quadratic term dominates: Newton on it, Anderson
// acceleration, multigrids over the map at 2d or over a subsampled volume,
// and frozen-weight energies were measured and dropped, and a pull towards
// the midpoint surface that makes it well posed costs fidelity (the
// midpoint's long waves follow the lattice's terraces). A heavier momentum
// only makes the residual ring.
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/timing.h"
#include "smooth/curve_kernel.h"
#include "core/parallel.h"

namespace voxpress {

using detail::Family;
using detail::Metric;
using detail::seconds_since;

namespace {

constexpr size_t kAhead = 32;  // prefetch distance, in curve vertices

// Curve c of a family as the pieces the kernel runs on: f(count, closed,
// free_ends, kof, elo, ehi) with kof(i) the curve-vertex index of the
// piece's point i and [elo, ehi) the points that propose.
template <class F>
void for_each_piece(const Family& fam, size_t c, const std::vector<uint8_t>& frozen,
                    const std::vector<uint8_t>& barrier, bool free_ends, F&& f) {
  const uint32_t* ids = fam.ids->data();
  const uint32_t b = (*fam.offsets)[c], m = (*fam.offsets)[c + 1] - b;
  // A curve, or a piece, whose vertices are all frozen proposes nothing
  // anyone reads (on a CAD part most of the vertices are frozen flats, cut
  // off by their barriers): skipped.
  const auto any_free = [&](uint32_t from, uint32_t count) {
    if (frozen.empty()) return true;
    for (uint32_t i = 0; i < count; ++i)
      if (!frozen[ids[b + (from + i) % m]]) return true;
    return false;
  };
  const auto straight = [b](uint32_t i) { return b + i; };
  if (!fam.spans.empty() && fam.spans[c].open) {  // an open polyline with context ends
    const Family::Span& sp = fam.spans[c];
    if (any_free(sp.lo, sp.hi - sp.lo)) f(m, false, sp.free != 0, straight, sp.lo, sp.hi);
    return;
  }
  // The curve, or its open pieces between barrier vertices, each piece
  // starting and ending at a barrier (cyclically).
  uint32_t first_barrier = m;
  if (!barrier.empty())
    for (uint32_t i = 0; i < m && first_barrier == m; ++i)
      if (barrier[ids[b + i]]) first_barrier = i;
  if (first_barrier == m) {
    if (any_free(0, m)) f(m, true, false, straight, 0, m);
    return;
  }
  // Open pieces from barrier to barrier; the barrier ends stay fixed.
  for (uint32_t k = 0; k < m;) {
    uint32_t len = 1;
    while (!barrier[ids[b + (first_barrier + k + len) % m]]) ++len;
    if (any_free(first_barrier + k + 1, len - 1)) {
      // Free ends: the piece without its two barriers (PressOptions::free_ends).
      const bool loose = free_ends && len >= detail::kFreePiece;
      const uint32_t lo = loose ? 1 : 0, count = loose ? len - 1 : len + 1;
      const uint32_t from = first_barrier + k + lo;
      f(count, false, loose, [=](uint32_t i) { return b + (from + i) % m; }, 1 - lo, len - lo);
    }
    k += len;
  }
}

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
    combine(x.size(), step);
  }

 private:
  // step[i]: vertex i's proposals combined (PressOptions::weighting).
  void combine(size_t n, std::vector<double>& step) {
    detail::parallel_ranges(n, 1 << 14, [&](detail::IndexRange r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!frozen_.empty() && frozen_[i]) {
          step[i] = 0;
          continue;
        }
        const double* p = &prop_[size_t(per_vertex_) * i];
        if (per_vertex_ == 1) {
          step[i] = p[0];
        } else if (weighted_) {
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
  detail::parallel_ranges(off.size() - 1, 32, [&](detail::IndexRange r) {
    detail::Scratch<Vec2> w;
    for (size_t c = r.begin(); c < r.end(); ++c) {
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
      for_each_piece(fam, c, frozen, barrier, o_.free_ends, [&](uint32_t count, bool closed, bool loose, auto&& kof,
                                                                 uint32_t elo, uint32_t ehi) {
        w.resize(count);
        for (uint32_t i = 0; i < count; ++i) gather(i, kof(i));
        detail::curve_step(count, closed, d, s2_, o_.resample, weighted_, correction_, g, w, loose);
        for (uint32_t i = elo; i < ehi; ++i) emit(kof(i), i);
      });
    }
  });
}

// max over the fresh vertices (of those `counted`, when given) of
// |T(t)_i - t_i|, T(t) = clamp(t + step).
double residual_of(const std::vector<double>& t, const std::vector<double>& step, const std::vector<uint8_t>& frozen,
                   double lo, double hi, const std::vector<uint8_t>* counted = nullptr) {
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, t.size(), 1 << 14), 0.0,
      [&](const tbb::blocked_range<size_t>& r, double acc) {
        for (size_t i = r.begin(); i < r.end(); ++i)
          if ((frozen.empty() || !frozen[i]) && (!counted || (*counted)[i]))
            acc = std::max(acc, std::abs(std::clamp(t[i] + step[i], lo, hi) - t[i]));
        return acc;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace

double detail::residual_at(const std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                          const PressOptions& o, const std::vector<uint8_t>* counted) {
  if (t.empty()) return 0;
  const std::vector<uint8_t> none;  // no frozen vertex, no barrier (the Sweeper holds references)
  Sweeper sweep(families, per_vertex, none, none, o, t.size());
  std::vector<double> step(t.size());
  sweep(t, 1, step);
  return residual_of(t, step, {}, o.margin, 1 - o.margin, counted);
}

PressStats detail::iterate(std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                           const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& barrier,
                           const PressOptions& o, int levels, SweepWindow* window) {
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
  std::vector<double> own_velocity;
  std::vector<double>& velocity = window && window->velocity ? *window->velocity : own_velocity;
  if (o.momentum == 0) velocity.clear();
  else if (velocity.size() != n) velocity.assign(n, 0.0);
  const double lo = o.margin, hi = 1 - o.margin;
  const int cap = std::max(o.iterations, 0);
  const int first = window ? std::clamp(window->first, 0, cap) : 0;
  const int last = window ? std::clamp(window->last, first, cap) : cap;
  if (window) window->residuals.assign(size_t(last - first), std::numeric_limits<double>::quiet_NaN());
  ProgressCounter progress(o.progress, "pressing", uint64_t(last - first));
  bool measured = false;  // st.residual is the residual at the current t
  bool any = false;       // a residual was measured
  for (int it = first; it < last; ++it) {
    // Stage of the coarse-to-fine schedule: d * 2^(levels - 1 - stage).
    const int stage = std::min(levels - 1, it * levels / std::max(cap, 1));
    sweep(t, double(1 << (levels - 1 - stage)), step);
    if (stage == levels - 1) {  // the map at d: its residual is the stopping rule
      st.residual = residual_of(t, step, frozen, lo, hi, window ? window->counted : nullptr);
      st.least_residual = any ? std::min(st.least_residual, st.residual) : st.residual;
      any = measured = true;
      if (window) window->residuals[size_t(it - first)] = st.residual;
      else if (st.residual <= o.tolerance) break;
    }
    detail::parallel_ranges(n, 1 << 14, [&](detail::IndexRange r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!frozen.empty() && frozen[i]) continue;
        double dt = step[i];
        if (!velocity.empty()) dt += o.momentum * velocity[i];
        const double t_new = std::clamp(t[i] + dt, lo, hi);
        if (!velocity.empty()) velocity[i] = t_new - t[i];
        t[i] = t_new;
      }
    });
    measured = false;
    st.iterations = it + 1;
    progress.add(1);
  }
  if (window) {  // the caller measures where the whole run stops
    st.seconds = seconds_since(t0);
    return st;
  }
  if (!measured) {  // the cap ended the solve: the residual at the returned t
    sweep(t, 1, step);
    st.residual = residual_of(t, step, frozen, lo, hi);
    st.least_residual = any ? std::min(st.least_residual, st.residual) : st.residual;
  }
  st.seconds = seconds_since(t0);
  return st;
}

}  // namespace voxpress
