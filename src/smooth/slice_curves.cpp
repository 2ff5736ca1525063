// The curves Pressing runs on (Chica et al., Section 4): the lattice-plane
// cuts of a stick surface, and the 2D contours of an image (marching
// squares). Theory of operation: include/voxpress/smooth/pressing.h.

#include <algorithm>
#include <stdexcept>

#include "core/sentinel.h"
#include "voxpress/extract/cube_cases.h"
#include "voxpress/smooth/pressing.h"
#include "core/parallel.h"

namespace voxpress {

using detail::kNone;

SliceCurves build_slice_curves(const StickSurface& s) {
  const size_t n = s.stick_count();
  std::vector<std::array<int64_t, 3>> lo(n);
  detail::parallel_for(n, [&](size_t i) { lo[i] = s.lower_index(i); });
  // Two neighbours per stick and plane slot.
  std::vector<uint32_t> nb(4 * n, kNone);
  auto link = [&](uint32_t u, uint32_t v, int slot) {
    uint32_t* x = &nb[4 * size_t(u) + 2 * size_t(slot)];
    if (x[0] == v || x[1] == v) return;
    if (x[0] == kNone)
      x[0] = v;
    else if (x[1] == kNone)
      x[1] = v;
    else
      throw std::logic_error("slice curves: a stick has more than two neighbours in a plane");
  };
  for (const Triangle& t : s.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t u = t[size_t(e)], v = t[size_t((e + 1) % 3)];
      const int au = s.axis(u), av = s.axis(v);
      for (int a = 0; a < 3; ++a)
        if (a != au && a != av && lo[u][size_t(a)] == lo[v][size_t(a)]) {
          link(u, v, SliceCurves::slot(a, au));
          link(v, u, SliceCurves::slot(a, av));
          break;
        }
    }
  SliceCurves c;
  for (int a = 0; a < 3; ++a) {
    std::vector<uint8_t> seen(n, 0);
    struct Curve {
      int64_t plane;
      uint32_t begin, size;
    };
    std::vector<Curve> curves;
    std::vector<uint32_t> ids;
    for (uint32_t s0 = 0; s0 < n; ++s0) {
      if (s.axis(s0) == a || seen[s0]) continue;
      const uint32_t begin = uint32_t(ids.size());
      uint32_t prev = kNone, cur = s0;
      do {
        seen[cur] = 1;
        ids.push_back(cur);
        const uint32_t* x = &nb[4 * size_t(cur) + 2 * size_t(SliceCurves::slot(a, s.axis(cur)))];
        if (x[0] == kNone || x[1] == kNone)
          throw std::logic_error("slice curves: a stick lacks a neighbour in a plane (open cut)");
        const uint32_t next = x[0] != prev ? x[0] : x[1];
        prev = cur;
        cur = next;
      } while (cur != s0);
      curves.push_back({lo[s0][size_t(a)], begin, uint32_t(ids.size()) - begin});
    }
    std::stable_sort(curves.begin(), curves.end(), [](const Curve& x, const Curve& y) { return x.plane < y.plane; });
    c.offsets[a].push_back(0);
    for (const Curve& cv : curves) {
      c.ids[a].insert(c.ids[a].end(), ids.begin() + cv.begin, ids.begin() + cv.begin + cv.size);
      c.offsets[a].push_back(uint32_t(c.ids[a].size()));
    }
  }
  return c;
}

// --------------------------------------------------------------------- 2D
std::array<double, 2> Contours2D::position(size_t v) const {
  std::array<double, 2> p{double(lower[v][0]), double(lower[v][1])};
  p[axis[v]] += t[v];
  return p;
}

Contours2D extract_contours(int64_t w, int64_t h, std::vector<uint8_t> inside) {
  if (w < 1 || h < 1 || inside.size() != size_t(w * h)) throw std::invalid_argument("extract_contours: bad image");
  Contours2D c;
  c.width = w;
  c.height = h;
  c.inside = std::move(inside);
  auto at = [&](int64_t x, int64_t y) { return x >= 0 && y >= 0 && x < w && y < h && c.inside[size_t(y * w + x)]; };
  // Stick ids: x-sticks (x, y)-(x+1, y) for x in [-1, w-1], y in [0, h-1];
  // y-sticks (x, y)-(x, y+1) for x in [0, w-1], y in [-1, h-1].
  std::vector<uint32_t> xid(size_t((w + 1) * h), kNone), yid(size_t(w * (h + 1)), kNone);
  for (int64_t y = -1; y <= h; ++y)
    for (int64_t x = -1; x <= w; ++x) {
      if (y >= 0 && y < h && x < w && at(x, y) != at(x + 1, y)) {
        xid[size_t(y * (w + 1) + x + 1)] = uint32_t(c.lower.size());
        c.lower.push_back({x, y});
        c.axis.push_back(0);
      }
      if (x >= 0 && x < w && y < h && at(x, y) != at(x, y + 1)) {
        yid[size_t((y + 1) * w + x)] = uint32_t(c.lower.size());
        c.lower.push_back({x, y});
        c.axis.push_back(1);
      }
    }
  c.t.assign(c.lower.size(), 0.5);
  std::vector<uint32_t> next(c.lower.size(), kNone);
  for (int64_t y = -1; y < h; ++y)
    for (int64_t x = -1; x < w; ++x) {
      const bool q[4] = {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)};
      unsigned mask = 0;
      for (int k = 0; k < 4; ++k) mask |= unsigned(q[k]) << k;
      const SquareCase& sc = square_case(mask);
      auto edge = [&](int e) -> uint32_t {  // square edge e joins corners e and e + 1
        switch (e) {
          case 0: return xid[size_t(y * (w + 1) + x + 1)];
          case 1: return yid[size_t((y + 1) * w + x + 1)];
          case 2: return xid[size_t((y + 1) * (w + 1) + x + 1)];
          default: return yid[size_t((y + 1) * w + x)];
        }
      };
      for (int k = 0; k < sc.count; ++k) next[edge(sc.segments[size_t(k)][0])] = edge(sc.segments[size_t(k)][1]);
    }
  std::vector<uint8_t> seen(c.lower.size(), 0);
  c.offsets.push_back(0);
  for (uint32_t v0 = 0; v0 < c.lower.size(); ++v0) {
    if (seen[v0]) continue;
    uint32_t v = v0;
    do {
      if (v == kNone) throw std::logic_error("extract_contours: open contour");
      seen[v] = 1;
      c.ids.push_back(v);
      v = next[v];
    } while (v != v0);
    c.offsets.push_back(uint32_t(c.ids.size()));
  }
  return c;
}

}  // namespace voxpress
