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

#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <numbers>
#include <stdexcept>

#include "core/timing.h"
#include "extract/stick_box.h"
#include "smooth/curve_kernel.h"
#include "core/parallel.h"

namespace voxpress {

using detail::Family;
using detail::IndexBox;
using detail::Metric;
using detail::extent_of;
using detail::stick_box;
using detail::seconds_since;

void detail::make_layout(const StickSurface& s, const SliceCurves& curves, Layout& out) {
  const size_t n = s.stick_count();
  // Renumber the vertices in 8^3-brick Morton order for the iteration. The
  // canonical (row) order puts consecutive vertices of an x-plane curve a
  // whole row apart, so every access misses the cache; in brick order a
  // plane's curves touch a few hundred KiB, reused by the next plane.
  // Keys are unique, so the order (and the result) is deterministic.
  // Codes and positions are relative to the sticks' box (translation-free).
  const auto lower = [&](size_t i) { return s.lower_index(i); };
  const IndexBox<3> box = stick_box<3>(n, lower);
  std::vector<std::pair<uint64_t, uint32_t>> sorted(n);  // (brick Morton code, canonical id)
  detail::parallel_for(n, [&](size_t i) {
    const auto l = s.lower_index(i);
    uint64_t m = 0;
    for (int b = 0; b < 16; ++b)
      for (int a = 0; a < 3; ++a) m |= ((uint64_t(l[size_t(a)] - box[size_t(a)]) >> (3 + b)) & 1) << (3 * b + a);
    sorted[i] = {m, uint32_t(i)};
  });
  tbb::parallel_sort(sorted.begin(), sorted.end());
  auto& old_of = out.old_of;
  auto& new_of = out.new_of;
  old_of.resize(n);
  new_of.resize(n);
  detail::parallel_for(n, [&](size_t i) {
    const uint32_t old = sorted[i].second;
    old_of[i] = old;
    new_of[old] = uint32_t(i);
  });
  const Mat3 M = s.lattice.index_to_physical_matrix();
  auto& families = out.families;
  families.assign(3, Family{});
  auto& ids = out.ids;
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
    detail::parallel_for(m, [&](size_t k) {
      const uint32_t id = curves.ids[a][k];
      const auto l = s.lower_index(id);
      ids[a][k] = new_of[id];
      f.base[k] = Vec2(double(l[size_t(u)] - box[size_t(u)]), double(l[size_t(v)] - box[size_t(v)]));
      f.mov[k] = uint8_t(s.axis(id) == u ? 0 : 1);
      f.dst[k] = 2 * new_of[id] + uint32_t(SliceCurves::slot(a, s.axis(id)));
    });
  }
  out.extent = extent_of<3>(box);
}

PressStats press(StickSurface& s, const SliceCurves& curves, const PressOptions& o, const std::vector<uint8_t>& frozen,
                 const std::vector<uint8_t>& barrier) {
  detail::Layout L;
  detail::make_layout(s, curves, L);
  return detail::press_on(s, L, o, frozen, barrier);
}

PressStats detail::press_on(StickSurface& s, const Layout& L, const PressOptions& o, const std::vector<uint8_t>& frozen,
                            const std::vector<uint8_t>& barrier) {
  const size_t n = s.stick_count();
  if (L.old_of.size() != n) throw std::invalid_argument("press: the layout does not match the sticks");
  if (!frozen.empty() && frozen.size() != n) throw std::invalid_argument("press: frozen flags do not match the sticks");
  if (!barrier.empty() && barrier.size() != n) throw std::invalid_argument("press: barrier flags do not match the sticks");
  for (size_t i = 0; i < barrier.size(); ++i)
    if (barrier[i] && (frozen.empty() || !frozen[i])) throw std::invalid_argument("press: a barrier vertex must be frozen");
  std::vector<double> t(n);
  std::vector<uint8_t> fz(frozen.empty() ? 0 : n), br(barrier.empty() ? 0 : n);
  detail::parallel_for(n, [&](size_t i) {
    const uint32_t old = L.old_of[i];
    t[i] = s.t[old];
    if (!fz.empty()) fz[i] = frozen[old];
    if (!br.empty()) br[i] = barrier[old];
  });
  const PressStats st = detail::iterate(t, L.families, 2, fz, br, o, press_levels_for_extent(o.levels, L.extent));
  detail::parallel_for(n, [&](size_t i) { s.t[L.old_of[i]] = t[i]; });
  return st;
}

int press_levels_for_extent(int requested, int64_t extent) {
  if (requested > 0) return requested;
  int levels = 2;
  for (int64_t e = 192; extent >= e && levels < 8; e *= 2) ++levels;
  return levels;
}

int press_levels(const StickSurface& s, int requested) {
  return press_levels_for_extent(
      requested, extent_of<3>(stick_box<3>(s.stick_count(), [&](size_t i) { return s.lower_index(i); })));
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
  const IndexBox<2> box = stick_box<2>(c.lower.size(), [&](size_t v) { return c.lower[v]; });
  for (size_t k = 0; k < c.ids.size(); ++k) {
    const uint32_t v = c.ids[k];
    f.base[k] = Vec2(double(c.lower[v][0] - box[0]), double(c.lower[v][1] - box[1]));
    f.mov[k] = c.axis[v];
  }
  const int levels = press_levels_for_extent(o.levels, extent_of<2>(box));
  return detail::iterate(c.t, families, 1, {}, {}, o, levels);
}

}  // namespace voxpress
