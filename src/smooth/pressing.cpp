// Pressing: constrained bilaplacian smoothing on axis slices (Chica et al.,
// Section 4). Theory of operation: see include/voxpress/smooth/pressing.h.
//
// Data layout. The iteration renumbers the vertices in 8^3-brick Morton
// order (so that the curves of one plane touch a small working set) and
// works per plane family in the plane's 2D index coordinates: curve-vertex
// k of a family sits at base[k] + t[ids[k]] * e_mov[k]; only t is gathered
// per iteration (with software prefetch, as the curve order is not the
// vertex order). A vertex's two proposals live in prop[2 v + slot], slot 0
// for the lower of its two plane families, and the family writes them through
// a precomputed index dst[k]. Frozen vertices are simply skipped by the
// update pass: they keep their t, and curves use them as fixed points.
//
// Anisotropic or sheared lattices: arc lengths use the plane's metric (the
// Gram matrix of the two index-to-physical columns), so positions, arc
// lengths and Laplacians are physical; the Laplacian is linear, so it is the
// same computed in index coordinates. d is arc_length times the geometric
// mean of the two cell sides of the curve's plane (the side of the square
// with the cell's area).
#include "voxpress/smooth/pressing.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <numbers>
#include <stdexcept>

#include "core/timing.h"
#include "smooth/curve_kernel.h"

namespace voxpress {

using detail::Family;
using detail::Metric;
using detail::seconds_since;

namespace {

constexpr size_t kAhead = 32;  // prefetch distance, in curve vertices

// PressOptions::levels resolved (its comment has the rule). Only for 0 are
// the n sticks' lower samples, lower(i) (D index coordinates), read: the
// extent is the longest side of the box of the sticks' samples, a stick's
// upper sample lying one past its lower one.
template <size_t D, class Lower>
int resolve_levels(int requested, size_t n, const Lower& lower) {
  if (requested > 0) return requested;
  using Box = std::array<int64_t, 2 * D>;  // min, then max, of each coordinate
  Box empty;
  for (size_t a = 0; a < D; ++a) empty[a] = INT64_MAX, empty[a + D] = INT64_MIN;
  const auto merge = [](Box& b, const auto& x) {
    for (size_t a = 0; a < D; ++a) b[a] = std::min<int64_t>(b[a], x[a]), b[a + D] = std::max<int64_t>(b[a + D], x[a + D]);
  };
  const Box box = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, n, 1 << 14), empty,
      [&](const tbb::blocked_range<size_t>& r, Box b) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          const auto l = lower(i);
          Box point;
          for (size_t a = 0; a < D; ++a) point[a] = point[a + D] = l[a];
          merge(b, point);
        }
        return b;
      },
      [&](Box x, const Box& y) {
        merge(x, y);
        return x;
      });
  int64_t extent = 0;
  for (size_t a = 0; n > 0 && a < D; ++a) extent = std::max(extent, box[a + D] + 1 - box[a]);
  return press_levels_for_extent(requested, extent);
}

}  // namespace

PressStats detail::iterate(std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                   const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& barrier, const PressOptions& o,
                   int levels) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = t.size();
  PressStats st;
  for (const Family& f : families) st.curves += f.offsets->size() - 1;
  for (uint8_t x : frozen) st.frozen += x != 0;
  st.fresh = n - st.frozen;
  st.levels = levels;
  if (n == 0) return st;
  const double s2 = o.step * o.step;
  const double correction = 1 - std::cos(std::clamp(o.circle_correction, 0.0, 90.0) * std::numbers::pi / 180);
  const bool weighted = o.weighting != PressOptions::Weighting::equal;
  std::vector<double> prop(size_t(per_vertex) * n, 0), weight(weighted ? size_t(per_vertex) * n : 0, 0);
  std::vector<double> velocity(o.momentum != 0 ? n : 0, 0.0);
  ProgressCounter progress(o.progress, "pressing", uint64_t(std::max(o.iterations, 0)));
  for (int it = 0; it < o.iterations; ++it) {
    // Stage of the coarse-to-fine schedule: d * 2^(levels - 1 - stage).
    const int stage = std::min(levels - 1, it * levels / std::max(o.iterations, 1));
    const double scale = double(1 << (levels - 1 - stage));
    for (const Family& fam : families) {
      const uint32_t* ids = fam.ids->data();
      const auto& off = *fam.offsets;
      const size_t total = fam.ids->size();
      const Metric& g = fam.g;
      // dt per unit displacement along u and v, for a stick along u (row 0) or v (row 1).
      const double proj[2][2] = {{1, g.g01 / g.g00}, {g.g01 / g.g11, 1}};
      const double d = o.arc_length * scale * fam.cell;
      tbb::parallel_for(tbb::blocked_range<size_t>(0, off.size() - 1, 32), [&](const tbb::blocked_range<size_t>& r) {
        detail::Scratch<Vec2> w;
        for (size_t c = r.begin(); c < r.end(); ++c) {
          const uint32_t b = off[c], m = off[c + 1] - b;
          auto emit = [&](uint32_t k, const Vec2& disp, const Vec2& tangent) {  // k: curve-vertex index
            const int mv = fam.mov[k];
            const uint32_t q = fam.dst[k];
            prop[q] = proj[mv][0] * disp.x() + proj[mv][1] * disp.y();
            if (weighted) {
              // |cos| between the stick and the curve tangent, both unit in the metric.
              const Vec2 e = mv == 0 ? Vec2(1 / std::sqrt(g.g00), 0) : Vec2(0, 1 / std::sqrt(g.g11));
              const double cs = std::min(1.0, std::abs(g.dot(e, tangent)));
              weight[q] = o.weighting == PressOptions::Weighting::tangent ? cs : std::sqrt(1 - cs * cs);
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
            detail::curve_step(m, false, d, s2, o.resample, weighted, correction, g, w, sp.free != 0);
            for (uint32_t i = sp.lo; i < sp.hi; ++i) emit(b + i, w.disp[i], w.tangent[i]);
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
            detail::curve_step(m, true, d, s2, o.resample, weighted, correction, g, w);
            for (uint32_t i = 0; i < m; ++i) emit(b + i, w.disp[i], w.tangent[i]);
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
            const bool loose = o.free_ends && len >= detail::kFreePiece;
            const uint32_t lo = loose ? 1 : 0, count = loose ? len - 1 : len + 1;
            w.resize(count);
            for (uint32_t i = 0; i < count; ++i) gather(i, b + (first_barrier + k + lo + i) % m);
            detail::curve_step(count, false, d, s2, o.resample, weighted, correction, g, w, loose);
            for (uint32_t i = 1; i < len; ++i) emit(b + (first_barrier + k + i) % m, w.disp[i - lo], w.tangent[i - lo]);
            k += len;
          }
        }
      });
    }
    const double max_change = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, 1 << 14), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double acc) {
          for (size_t i = r.begin(); i < r.end(); ++i) {
            if (!frozen.empty() && frozen[i]) continue;
            const double* p = &prop[size_t(per_vertex) * i];
            double dt;
            if (per_vertex == 1) {
              dt = p[0];
            } else if (weighted) {
              const double w0 = weight[2 * i], w1 = weight[2 * i + 1];
              dt = w0 + w1 > 0 ? (w0 * p[0] + w1 * p[1]) / (w0 + w1) : 0;
            } else {
              dt = 0.5 * (p[0] + p[1]);
            }
            if (!velocity.empty()) dt += o.momentum * velocity[i];
            const double t_new = std::clamp(t[i] + dt, o.margin, 1 - o.margin);
            acc = std::max(acc, std::abs(t_new - t[i]));
            if (!velocity.empty()) velocity[i] = t_new - t[i];
            t[i] = t_new;
          }
          return acc;
        },
        [](double x, double y) { return std::max(x, y); });
    st.iterations = it + 1;
    st.last_max_change = max_change;
    st.least_max_change = it == 0 ? max_change : std::min(st.least_max_change, max_change);
    progress.add(1);
    if (max_change < o.tolerance) break;
  }
  st.seconds = seconds_since(t0);
  return st;
}


PressStats press(StickSurface& s, const SliceCurves& curves, const PressOptions& o, const std::vector<uint8_t>& frozen,
                 const std::vector<uint8_t>& barrier) {
  const size_t n = s.stick_count();
  if (!frozen.empty() && frozen.size() != n) throw std::invalid_argument("press: frozen flags do not match the sticks");
  if (!barrier.empty() && barrier.size() != n) throw std::invalid_argument("press: barrier flags do not match the sticks");
  for (size_t i = 0; i < barrier.size(); ++i)
    if (barrier[i] && (frozen.empty() || !frozen[i])) throw std::invalid_argument("press: a barrier vertex must be frozen");
  // Renumber the vertices in 8^3-brick Morton order for the iteration. The
  // canonical (row) order puts consecutive vertices of an x-plane curve a
  // whole row apart, so every access misses the cache; in brick order a
  // plane's curves touch a few hundred KiB, reused by the next plane.
  // Keys are unique, so the order (and the result) is deterministic.
  std::vector<std::pair<uint64_t, uint32_t>> sorted(n);  // (brick Morton code, canonical id)
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    const auto l = s.lower_index(i);
    uint64_t m = 0;
    for (int b = 0; b < 16; ++b)
      for (int a = 0; a < 3; ++a) m |= ((uint64_t(l[size_t(a)] + 1) >> (3 + b)) & 1) << (3 * b + a);
    sorted[i] = {m, uint32_t(i)};
  });
  tbb::parallel_sort(sorted.begin(), sorted.end());
  std::vector<uint32_t> old_of(n), new_of(n);
  std::vector<double> t(n);
  std::vector<uint8_t> fz(frozen.empty() ? 0 : n), br(barrier.empty() ? 0 : n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    const uint32_t old = sorted[i].second;
    old_of[i] = old;
    new_of[old] = uint32_t(i);
    t[i] = s.t[old];
    if (!fz.empty()) fz[i] = frozen[old];
    if (!br.empty()) br[i] = barrier[old];
  });
  const Mat3 M = s.lattice.index_to_physical_matrix();
  std::vector<Family> families(3);
  std::vector<uint32_t> ids[3];
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    Family& f = families[size_t(a)];
    const size_t m = curves.ids[a].size();
    ids[a].resize(m);
    f.ids = &ids[a];
    f.offsets = &curves.offsets[a];
    f.g = {M.col(u).squaredNorm(), M.col(u).dot(M.col(v)), M.col(v).squaredNorm()};
    f.cell = std::sqrt(s.lattice.spacing[u] * s.lattice.spacing[v]);
    f.base.resize(m);
    f.mov.resize(m);
    f.dst.resize(m);
    tbb::parallel_for(size_t(0), m, [&](size_t k) {
      const uint32_t id = curves.ids[a][k];
      const auto l = s.lower_index(id);
      ids[a][k] = new_of[id];
      f.base[k] = Vec2(double(l[size_t(u)]), double(l[size_t(v)]));
      f.mov[k] = uint8_t(s.axis(id) == u ? 0 : 1);
      f.dst[k] = 2 * new_of[id] + uint32_t(SliceCurves::slot(a, s.axis(id)));
    });
  }
  const PressStats st = detail::iterate(t, families, 2, fz, br, o, press_levels(s, o.levels));
  tbb::parallel_for(size_t(0), n, [&](size_t i) { s.t[old_of[i]] = t[i]; });
  return st;
}

int press_levels_for_extent(int requested, int64_t extent) {
  if (requested > 0) return requested;
  int levels = 2;
  for (int64_t e = 192; extent >= e && levels < 8; e *= 2) ++levels;
  return levels;
}

int press_levels(const StickSurface& s, int requested) {
  return resolve_levels<3>(requested, s.stick_count(), [&](size_t i) { return s.lower_index(i); });
}

PressStats press(StickSurface& surface, const PressOptions& options) {
  return press(surface, build_slice_curves(surface), options);
}

// --------------------------------------------------------------------- 2D
PressStats press(Contours2D& c, const PressOptions& o) {
  std::vector<Family> families(1);
  Family& f = families[0];
  f.ids = &c.ids;
  f.offsets = &c.offsets;
  f.g = {1, 0, 1};
  f.cell = 1;
  f.base.resize(c.ids.size());
  f.mov.resize(c.ids.size());
  f.dst = c.ids;
  for (size_t k = 0; k < c.ids.size(); ++k) {
    const uint32_t v = c.ids[k];
    f.base[k] = Vec2(double(c.lower[v][0]), double(c.lower[v][1]));
    f.mov[k] = c.axis[v];
  }
  const int levels = resolve_levels<2>(o.levels, c.lower.size(), [&](size_t v) { return c.lower[v]; });
  return detail::iterate(c.t, families, 1, {}, {}, o, levels);
}

}  // namespace voxpress
