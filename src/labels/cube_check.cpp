// The exact check of a shared surface cube by cube. Theory of operation:
// cube_check.h.
#include "cube_check.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>

#include "core/clearance.h"
#include "core/parallel.h"

namespace voxpress::detail {

Cubes cubes_of(const Mesh& m, const std::vector<Vec3>& x0, const std::vector<uint8_t>* only) {
  Cubes c;
  const size_t nt = m.triangles.size();
  std::vector<std::pair<std::array<int64_t, 3>, uint32_t>> key(nt);
  detail::parallel_for(nt, [&](size_t f) {
    const Triangle& t = m.triangles[f];
    const Vec3 g = (x0[t[0]] + x0[t[1]] + x0[t[2]]) / 3;
    key[f] = {{int64_t(std::floor(g[0])), int64_t(std::floor(g[1])), int64_t(std::floor(g[2]))}, uint32_t(f)};
  });
  tbb::parallel_sort(key.begin(), key.end());
  for (size_t i = 0; i < nt; ++i) {
    if (i > 0 && key[i].first != key[i - 1].first) c.offsets.push_back(uint32_t(i));
    c.tris.push_back(key[i].second);
  }
  if (nt > 0) c.offsets.push_back(uint32_t(nt));
  std::vector<std::pair<uint32_t, uint32_t>> vg;  // (vertex, group)
  for (uint32_t g = 0; g + 1 < c.offsets.size(); ++g)
    for (uint32_t k = c.offsets[g]; k < c.offsets[g + 1]; ++k)
      for (uint32_t v : m.triangles[c.tris[k]])
        if (!only || (*only)[v]) vg.push_back({v, g});
  tbb::parallel_sort(vg.begin(), vg.end());
  vg.erase(std::unique(vg.begin(), vg.end()), vg.end());
  c.vertex_offsets.assign(x0.size() + 1, 0);
  for (const auto& [v, g] : vg) ++c.vertex_offsets[v + 1], c.vertex_groups.push_back(g);
  for (size_t v = 0; v < x0.size(); ++v) c.vertex_offsets[v + 1] += c.vertex_offsets[v];
  return c;
}

namespace {

// Is the surface inside cube group g valid once stored in float32?
bool cube_ok(const Mesh& m, const Cubes& c, uint32_t g, const std::vector<Vec3>& x, double delta) {
  for (uint32_t i = c.offsets[g]; i < c.offsets[g + 1]; ++i) {
    const Triangle& a = m.triangles[c.tris[i]];
    const Vec3 pa[3] = {x[a[0]], x[a[1]], x[a[2]]};
    if (triangle_too_thin(pa[0], pa[1], pa[2], delta)) return false;
    const uint32_t ia[3] = {a[0], a[1], a[2]};
    for (uint32_t j = c.offsets[g]; j < i; ++j) {
      const Triangle& b = m.triangles[c.tris[j]];
      const Vec3 pb[3] = {x[b[0]], x[b[1]], x[b[2]]};
      const uint32_t ib[3] = {b[0], b[1], b[2]};
      if (triangles_clash(pa, ia, pb, ib, delta)) return false;
    }
  }
  return true;
}

}  // namespace

std::vector<uint32_t> failing_cubes(const Mesh& m, const Cubes& c, const std::vector<uint32_t>& groups,
                                    const std::vector<Vec3>& x, double delta) {
  std::vector<uint8_t> bad(groups.size(), 0);
  detail::parallel_for(groups.size(), [&](size_t k) { bad[k] = !cube_ok(m, c, groups[k], x, delta); });
  std::vector<uint32_t> out;
  for (size_t k = 0; k < groups.size(); ++k)
    if (bad[k]) out.push_back(groups[k]);
  return out;
}

size_t put_back(const Mesh& m, const Cubes& c, std::vector<uint32_t> bad, std::vector<Vec3>& x,
                const std::vector<Vec3>& back, std::vector<uint8_t>& reset, double delta) {
  size_t count = 0;
  while (!bad.empty()) {
    std::vector<uint32_t> touched;
    for (uint32_t g : bad) {
      bool fresh = false;  // a cube already all back cannot do better: left as it is
      for (uint32_t k = c.offsets[g]; k < c.offsets[g + 1]; ++k)
        for (uint32_t v : m.triangles[c.tris[k]]) fresh = fresh || !reset[v];
      count += fresh;
      if (!fresh) continue;
      for (uint32_t k = c.offsets[g]; k < c.offsets[g + 1]; ++k)
        for (uint32_t v : m.triangles[c.tris[k]]) {
          if (reset[v]) continue;
          reset[v] = 1;
          x[v] = back[v];
          touched.insert(touched.end(), c.vertex_groups.begin() + c.vertex_offsets[v],
                         c.vertex_groups.begin() + c.vertex_offsets[v + 1]);
        }
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    bad = failing_cubes(m, c, touched, x, delta);
  }
  return count;
}

}  // namespace voxpress::detail
