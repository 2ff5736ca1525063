// A label's own binary view of the shared surface. Theory of operation:
// label_view.h.
#include "label_view.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include "core/parallel.h"

namespace voxpress::detail {
namespace {

// The same triangle turned so that its smallest vertex comes first.
Triangle canonical(const Triangle& t) {
  const int i = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
  return {t[size_t(i)], t[size_t((i + 1) % 3)], t[size_t((i + 2) % 3)]};
}

}  // namespace

Cube floor_of(const Vec3& p) {
  return {int64_t(std::floor(p[0])), int64_t(std::floor(p[1])), int64_t(std::floor(p[2]))};
}

std::vector<size_t> listed_labels(const SharedSurface& s, const std::vector<LabelInfo>& labels) {
  std::vector<size_t> at(s.labels.size(), SIZE_MAX);
  for (size_t i = 0; i < labels.size(); ++i) {
    const auto it = std::lower_bound(s.labels.begin(), s.labels.end(), uint32_t(labels[i].value));
    if (it != s.labels.end() && it != s.labels.begin() && double(*it) == labels[i].value) at[size_t(it - s.labels.begin())] = i;
  }
  return at;
}

Vec3 element_centre(const SharedSurface& s, uint32_t v) {
  Vec3 p(double(s.corner[v][0]), double(s.corner[v][1]), double(s.corner[v][2]));
  const int k = s.kind[v];
  if (k < 3) {
    p[k] += 0.5;
  } else if (k < 6) {
    p[(k - 3 + 1) % 3] += 0.5;
    p[(k - 3 + 2) % 3] += 0.5;
  } else {
    p.array() += 0.5;
  }
  return p;
}

Ownership ownership(const SharedSurface& s, const std::vector<uint8_t>& takes_part) {
  Ownership c;
  const size_t nt = s.mesh.triangles.size();
  c.tris.resize(nt);
  detail::parallel_for(nt, [&](size_t f) {
    const Triangle& t = s.mesh.triangles[f];
    c.tris[f] = {floor_of((element_centre(s, t[0]) + element_centre(s, t[1]) + element_centre(s, t[2])) / 3), uint32_t(f)};
  });
  tbb::parallel_sort(c.tris.begin(), c.tris.end());
  for (size_t i = 1; i <= nt; ++i)
    if (i == nt || c.tris[i].first != c.tris[i - 1].first) c.offsets.push_back(i);
  if (nt == 0) c.offsets.assign(1, 0);
  c.owner.assign(c.offsets.size() - 1, UINT32_MAX);
  detail::parallel_for(c.owner.size(), [&](size_t g) {
    const auto pair = [&](size_t k) {
      const auto& sd = s.sides[c.tris[k].second];
      return std::array<uint32_t, 2>{std::min(sd[0], sd[1]), std::max(sd[0], sd[1])};
    };
    const auto p = pair(c.offsets[g]);
    for (size_t k = c.offsets[g]; k < c.offsets[g + 1]; ++k) {
      if (pair(k) != p) return;
      for (uint32_t v : s.mesh.triangles[c.tris[k].second])
        if (s.kind[v] >= 3) return;
    }
    uint32_t owner = UINT32_MAX;
    for (uint32_t l : p)
      if (l != 0 && takes_part[l] && (owner == UINT32_MAX || s.labels[l] > s.labels[owner])) owner = l;
    c.owner[g] = owner;
  });
  c.mine.resize(s.labels.size());
  for (uint32_t g = 0; g < c.owner.size(); ++g)
    if (c.owner[g] != UINT32_MAX) c.mine[c.owner[g]].push_back(g);
  c.degree.assign(s.mesh.positions.size(), 0);
  for (const Triangle& t : s.mesh.triangles)
    for (uint32_t v : t) ++c.degree[v];
  return c;
}

LabelView label_view(const SharedSurface& s, const Ownership& groups, const SharedSticks& sticks,
                     const BinaryVolume& mask, const std::array<int64_t, 3>& lo, uint32_t L) {
  LabelView e;
  e.label = L;
  e.lo = lo;
  e.surf = extract_sticks(mask);
  StickSurface& surf = e.surf;
  const size_t n = surf.stick_count();
  e.idx.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const uint32_t v = sticks.find(surf, k, lo);
    if (v == UINT32_MAX) throw std::logic_error("label_view: a label's stick is not on the shared surface");
    e.idx[k] = v;
    // Its place as pressed on the shared surface.
    surf.t[k] = s.lattice.to_index(s.mesh.positions[v])[surf.axis(k)] - double(s.corner[v][size_t(surf.axis(k))]);
  }
  // The label's own triangles by cube (shared lattice).
  std::vector<std::pair<Cube, uint32_t>> own(surf.triangles.size());
  for (uint32_t f = 0; f < surf.triangles.size(); ++f) {
    Vec3 g = Vec3::Zero();
    for (uint32_t k : surf.triangles[f]) {
      const auto l = surf.lower_index(k);
      Vec3 c(double(l[0] + lo[0]), double(l[1] + lo[1]), double(l[2] + lo[2]));
      c[surf.axis(k)] += 0.5;
      g += c / 3;
    }
    own[f] = {floor_of(g), f};
  }
  e.cube.resize(own.size());
  for (const auto& [c, f] : own) e.cube[f] = c;
  std::sort(own.begin(), own.end());
  // A cube it owns is editable where its shared triangles are its own
  // binary triangles (oriented outwards from L).
  e.editable.assign(surf.triangles.size(), 0);
  e.shared_of.assign(surf.triangles.size(), UINT32_MAX);
  const Ownership& cubes = groups;
  std::vector<std::pair<Triangle, uint32_t>> a, b;
  for (uint32_t g : groups.mine[L]) {
    const Cube& c = cubes.tris[cubes.offsets[g]].first;
    auto first = std::lower_bound(own.begin(), own.end(), std::pair<Cube, uint32_t>{c, 0});
    auto last = first;
    while (last != own.end() && last->first == c) ++last;
    if (size_t(last - first) != cubes.offsets[g + 1] - cubes.offsets[g]) continue;
    a.clear();
    b.clear();
    for (auto it = first; it != last; ++it) {
      const Triangle& t = surf.triangles[it->second];
      a.push_back({canonical({e.idx[t[0]], e.idx[t[1]], e.idx[t[2]]}), it->second});
    }
    for (size_t k = cubes.offsets[g]; k < cubes.offsets[g + 1]; ++k) {
      const uint32_t f = cubes.tris[k].second;
      Triangle t = s.mesh.triangles[f];
      if (s.sides[f][0] != L) std::swap(t[1], t[2]);
      b.push_back({canonical(t), f});
    }
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    bool same = true;
    for (size_t i = 0; i < a.size() && same; ++i) same = a[i].first == b[i].first;
    if (!same) continue;
    ++e.cubes;
    for (size_t i = 0; i < a.size(); ++i) {
      e.editable[a[i].second] = 1;
      e.shared_of[a[i].second] = b[i].second;
    }
  }

  // A stick vertex may move only when all its shared triangles are editable.
  std::vector<uint32_t> count(n, 0);
  for (uint32_t f = 0; f < surf.triangles.size(); ++f)
    if (e.editable[f])
      for (uint32_t k : surf.triangles[f]) ++count[k];
  e.fixed.resize(n);
  for (size_t k = 0; k < n; ++k) e.fixed[k] = count[k] != groups.degree[e.idx[k]];
  return e;
}

}  // namespace voxpress::detail
