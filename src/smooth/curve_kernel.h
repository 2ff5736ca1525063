// Pressing's curve kernel (Chica et al., Section 4, Fig. 4-6), shared by
// the binary surface (pressing.cpp), the 2D contours and the shared surfaces
// of label maps (labels/shared_press.cpp): one bilaplacian on arc length
// for curves in a lattice plane (Vec2, the plane's metric) or in space
// (Vec3, physical coordinates), and the iteration over families of slice
// curves whose vertices slide along their sticks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "voxpress/core/types.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress::detail {

// PressOptions::free_ends: pieces from barrier to barrier of at least this
// many segments (7 vertices between the barriers) get free ends. Measured
// 4 / 6 / 8 / 12: 8 keeps most of fandisk's gain without costing the small
// holes of plate_holes at 128^3 (their rows of `build/bench/bench_compare
// --quick --only pressing`).
inline constexpr uint32_t kFreePiece = 8;

// A location on a polyline: point k + f (point k + 1 - point k); past a
// free end (PressOptions::free_ends), that location reflected through the
// end (mirror 1: the last point, 2: the first).
struct Where {
  uint32_t k;
  double f;
  uint8_t mirror = 0;
};

// The metric of a plane's index coordinates (u, v): |(du, dv)|^2 =
// g00 du^2 + 2 g01 du dv + g11 dv^2 in physical units (the Gram matrix of
// the lattice's two index-to-physical columns spanning the plane).
struct Metric {
  double g00, g01, g11;
  double norm(const Vec2& x) const { return std::sqrt(g00 * x.x() * x.x() + 2 * g01 * x.x() * x.y() + g11 * x.y() * x.y()); }
  double dot(const Vec2& x, const Vec2& y) const {
    return g00 * x.x() * y.x() + g01 * (x.x() * y.y() + x.y() * y.x()) + g11 * x.y() * y.y();
  }
};

// The metric of physical coordinates, for curves in space (junction lines).
struct Euclid {
  double norm(const Vec3& x) const { return x.norm(); }
  double dot(const Vec3& x, const Vec3& y) const { return x.dot(y); }
};

template <class V>
struct Scratch {
  std::vector<V> pos, lap, disp, tangent;
  std::vector<double> len, inv;  // segment lengths and their reciprocals
  std::vector<double> shrink;    // per vertex: the circle correction's 1 - cos(theta)
  std::vector<Where> fwd, bwd;
  void resize(size_t n) {  // grows only: the kernel uses the first n entries
    if (pos.size() >= n) return;
    for (auto* v : {&pos, &lap, &disp, &tangent}) v->resize(n);
    len.resize(n);
    inv.resize(n);
    shrink.resize(n);
    fwd.resize(n);
    bwd.resize(n);
  }
};

// The first half of curve_step: the virtual neighbours w.fwd, w.bwd, the
// Laplacian w.lap, the circle correction's w.shrink and the tangents; false
// (every w.disp and w.tangent zero) on a degenerate curve.
template <class V, class G>
bool curve_locate(size_t n, bool closed, double d, bool resample, bool tangents, double correction, const G& g,
                  Scratch<V>& w, bool free_ends) {
  const V* p = w.pos.data();
  double* len = w.len.data();
  Where* fwd = w.fwd.data();
  Where* bwd = w.bwd.data();
  V* lap = w.lap.data();
  const auto next = [n](size_t k) { return k + 1 == n ? size_t(0) : k + 1; };
  const size_t segs = closed ? n : n - 1;
  double perimeter = 0;
  for (size_t i = 0; i < segs; ++i) {
    perimeter += (len[i] = g.norm(p[next(i)] - p[i]));
    w.inv[i] = len[i] > 0 ? 1 / len[i] : 0;
  }
  if (!(perimeter > 0) || n < 3) {
    for (size_t i = 0; i < n; ++i) w.disp[i] = w.tangent[i] = V::Zero();
    return false;
  }
  // A closed curve shorter than 4d (Fig. 6 does not say): the virtual
  // neighbours at a quarter of its perimeter, so d shrinks continuously
  // with the loop. Wrapping d around the loop jumped as the perimeter
  // crossed d: a loop around one sample then flipped in a 2-cycle and kept
  // the CAD part's residual at 4e-2 (bench_converge, issue 74).
  const double dd = closed ? std::min(d, perimeter / 4) : d;
  for (size_t i = 0; i < n; ++i) {
    if (!resample) {
      // Plain bilaplacian: the actual neighbours (open ends: themselves).
      fwd[i] = {uint32_t(closed ? next(i) : std::min(i + 1, n - 1)), 0};
      bwd[i] = {uint32_t(closed ? (i == 0 ? n - 1 : i - 1) : (i == 0 ? 0 : i - 1)), 0};
      continue;
    }
    // Forward: walk dd along the curve.
    double r = dd;
    size_t j = i;
    for (;;) {
      if (!closed && j + 1 >= n) {
        fwd[i] = {uint32_t(n - 1), 0};
        // Free end: the point r before the end, reflected through it.
        if (free_ends)
          for (size_t h = n - 1; h > 0; --h) {
            if (r <= len[h - 1] || h == 1) {
              fwd[i] = {uint32_t(h - 1), std::max(0.0, 1 - r * w.inv[h - 1]), 1};
              break;
            }
            r -= len[h - 1];
          }
        break;
      }
      if (r <= len[j]) {
        fwd[i] = {uint32_t(j), r * w.inv[j]};
        break;
      }
      r -= len[j];
      j = next(j);
    }
    // Backward.
    r = dd;
    j = i;
    for (;;) {
      if (!closed && j == 0) {
        bwd[i] = {0, 0};
        if (free_ends)
          for (size_t h = 0; h + 1 < n; ++h) {
            if (r <= len[h] || h + 2 == n) {
              bwd[i] = {uint32_t(h), std::min(1.0, r * w.inv[h]), 2};
              break;
            }
            r -= len[h];
          }
        break;
      }
      const size_t k = j == 0 ? n - 1 : j - 1;
      if (r <= len[k]) {
        bwd[i] = {uint32_t(k), len[k] > 0 ? 1 - r * w.inv[k] : 0};
        break;
      }
      r -= len[k];
      j = k;
    }
  }
  const auto point = [&](const Where& x) {
    const V q = p[x.k] + x.f * (p[next(x.k)] - p[x.k]);
    return x.mirror == 0 ? q : V(2 * p[x.mirror == 1 ? n - 1 : 0] - q);
  };
  // Pass 1: Laplacian towards the virtual neighbours (and, for the circle
  // correction below, 1 - cos of the turning angle between the chords).
  double* shrink = w.shrink.data();
  for (size_t i = 0; i < n; ++i) {
    const V f = point(fwd[i]), b = point(bwd[i]);
    lap[i] = 0.5 * (f + b) - p[i];
    if (correction > 0) {
      const V a = f - p[i], c = p[i] - b;
      const double aa = g.dot(a, a) * g.dot(c, c);
      shrink[i] = aa > 0 ? std::clamp(1 - g.dot(a, c) / std::sqrt(aa), 0.0, correction) : 0;
    } else {
      shrink[i] = 0;
    }
    if (tangents) {
      const V tg = f - b;
      const double l = g.norm(tg);
      w.tangent[i] = l > 0 ? V(tg / l) : V::Zero();
    }
  }
  return true;
}

// Displacement proposals s^2 L^2(C) for the n vertices w.pos of one curve
// (closed, or open with fixed or free ends), in the plane's index coordinates, and
// unit tangents (index coordinates, unit in the metric) for the weightings.
// Section 4, Fig. 4-6: virtual neighbours at arc length d, two Laplacian passes.
template <class V, class G>
void curve_step(size_t n, bool closed, double d, double s2, bool resample, bool tangents, double correction,
                const G& g, Scratch<V>& w, bool free_ends = false) {
  if (!curve_locate(n, closed, d, resample, tangents, correction, g, w, free_ends)) return;
  const auto next = [n](size_t k) { return k + 1 == n ? size_t(0) : k + 1; };
  const V* lap = w.lap.data();
  const double* shrink = w.shrink.data();
  const Where* fwd = w.fwd.data();
  const Where* bwd = w.bwd.data();
  // Pass 2: the Laplacian of the Laplacian, interpolated at the same places.
  // Past a free end the Laplacian is taken as 0 (the end's own, since its
  // virtual neighbours are each other's reflection).
  const auto lap_at = [&](const Where& x) {
    return x.mirror != 0 ? V(V::Zero()) : V(lap[x.k] + x.f * (lap[next(x.k)] - lap[x.k]));
  };
  // Beyond the paper (PressOptions::circle_correction): on a circle of
  // radius R the virtual neighbours' Laplacians are the vertex's turned by
  // the chords' turning angle theta = d / R, so the second pass leaves
  // L(C) (1 - cos theta) ~ d^4 / (4 R^3) inwards every iteration and tight
  // curves end pressed against the inner ends of their sticks. Subtracting
  // L(C) (1 - cos theta), theta measured between the chords to the two
  // virtual neighbours and capped (`correction` = 1 - cos of the cap),
  // makes circles fixed points; on straight stretches theta = 0 and the
  // iteration is the paper's.
  for (size_t i = 0; i < n; ++i) w.disp[i] = s2 * ((1 - shrink[i]) * lap[i] - 0.5 * (lap_at(fwd[i]) + lap_at(bwd[i])));
}

// The shared iteration over vertices on sticks, t[i] in [0, 1], grouped in
// curve families (a 3D plane family, or the one 2D family). Each vertex lies
// on `per_vertex` curves (2 in 3D, 1 in 2D), so it has per_vertex proposal
// slots; a family's curve-vertex k writes its proposal into slot dst[k]
// (layout: the top of pressing.cpp). A displacement D = (du, dv) projects onto
// the stick's physical line as dt = <D, e_mov>_g / <e_mov, e_mov>_g.
struct Family {
  const std::vector<uint32_t>* ids;
  const std::vector<uint32_t>* offsets;
  std::vector<Vec2> base;
  std::vector<uint8_t> mov;
  std::vector<uint32_t> dst;  // per curve-vertex: its proposal's index, per_vertex * id + slot
  Metric g;
  double cell;  // cell side of the family's planes (d = arc_length * cell)
  /// Per curve, optional (empty: every curve is a cycle cut at barriers):
  /// an open polyline whose curve-vertices [lo, hi) propose and the others
  /// are context only (the shared surface's pieces continued through a
  /// junction point by the piece that continues them); free: its ends are
  /// free ends (PressOptions::free_ends).
  struct Span {
    uint32_t lo = 0, hi = 0;
    uint8_t open = 0, free = 0;
  };
  std::vector<Span> spans;
};


// Runs the iteration (PressOptions) on t, a family's curve-vertex k at
// base[k] + t[ids[k]] e_mov[k]. Vertices flagged in `frozen` keep their t
// and are fixed points of the curves; `barrier` vertices (frozen ones) cut
// the curves into open pieces (PressOptions::free_ends). `levels` as
// press_levels resolved it. Jacobi updates: deterministic for any thread count.
/// The press's layout of a surface: vertices in brick Morton order relative
/// to the sticks' box (new_of[stick] = vertex, old_of[vertex] = stick), the
/// three plane families, and the box's extent (for the press's levels).
struct Layout {
  std::vector<uint32_t> old_of, new_of;
  std::vector<uint32_t> ids[3];
  std::vector<Family> families;
  int64_t extent = 0;
  Layout() = default;
  Layout(const Layout&) = delete;
  Layout& operator=(const Layout&) = delete;
};
void make_layout(const StickSurface& s, const SliceCurves& curves, Layout& out);
/// press() on a layout made once for the surface (make_layout), so that the
/// presses of one run (estimates, final press, crease rounds) share it.
PressStats press_on(StickSurface& s, const Layout& L, const PressOptions& o, const std::vector<uint8_t>& frozen = {},
                    const std::vector<uint8_t>& barrier = {});

/// Sweeps [first, last) of the schedule iterate() runs with the same
/// options (the stage of sweep k is the whole run's), from a given momentum
/// state: what a block pressed with a halo runs between exchanges of its
/// border (chunk/rounds.cpp). No residual ends it: the caller decides on
/// every block's residuals, so the result is the whole run's sweeps.
struct SweepWindow {
  int first = 0, last = 0;
  std::vector<double>* velocity = nullptr;  ///< in and out, one per vertex (momentum 0: unused)
  const std::vector<uint8_t>* counted = nullptr;  ///< the vertices whose residual counts (null: all)
  /// Out: per sweep of the window, the residual over the counted vertices
  /// when the sweep is in the last stage (NaN before it).
  std::vector<double> residuals;
};
PressStats iterate(std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                   const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& barrier, const PressOptions& o,
                   int levels, SweepWindow* window = nullptr);
/// The residual max |T(t) - t| of the map at d over the counted vertices
/// (null: all fresh ones).
double residual_at(const std::vector<double>& t, const std::vector<Family>& families, int per_vertex,
                   const PressOptions& o, const std::vector<uint8_t>* counted);

}  // namespace voxpress::detail
