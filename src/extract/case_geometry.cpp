// The geometry the case derivations share (cube_cases.cpp, label_cases.cpp).
#include "case_geometry.h"

#include <functional>
#include <stdexcept>

#include "../core/predicates.h"

namespace voxpress::detail {

namespace {


int corner_of(int axis, int side, int su, int sv) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  return (side << axis) | (su << u) | (sv << v);
}

int edge_between(int c0, int c1) {
  for (int e = 0; e < 12; ++e) {
    const int a = cube_edge_corner(e, 0), b = cube_edge_corner(e, 1);
    if ((a == c0 && b == c1) || (a == c1 && b == c0)) return e;
  }
  throw std::logic_error("corners are not adjacent");
}

// Bit set of the faces an edge lies on.
unsigned edge_faces(int e) {
  unsigned m = 0;
  const int a = cube_edge_axis(e);
  const int c = cube_edge_corner(e, 0);
  for (int axis = 0; axis < 3; ++axis) {
    if (axis == a) continue;
    const int side = (c >> axis) & 1;
    m |= 1u << (2 * axis + side);
  }
  return m;
}

}  // namespace

std::array<Face, 6> make_faces() {
  std::array<Face, 6> faces{};
  static const int sq[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Face& f = faces[2 * axis + side];
      f.axis = axis;
      f.side = side;
      for (int s = 0; s < 4; ++s) f.corner[s] = corner_of(axis, side, sq[s][0], sq[s][1]);
      for (int s = 0; s < 4; ++s) f.edge[s] = edge_between(f.corner[s], f.corner[(s + 1) & 3]);
    }
  return faces;
}

unsigned vertex_faces(int v) {
  if (v < 12) return edge_faces(v);
  return v < 18 ? 1u << (v - 12) : 0u;
}

Vec3 edge_point(int e, double t) {
  const int c = cube_edge_corner(e, 0);
  Vec3 p(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  p[cube_edge_axis(e)] = t;
  return p;
}

uint64_t splitmix(uint64_t& s) {
  uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}


bool valid_geometry(const std::vector<Tri>& tris, std::span<const Vec3> pos) { return valid_with({}, tris, pos); }

bool valid_with(const std::vector<Tri>& base, const std::vector<Tri>& added, std::span<const Vec3> pos) {
  for (const Tri& t : added)
    if (detail::triangle_degenerate(pos[t[0]], pos[t[1]], pos[t[2]])) return false;
  auto intersect = [&](const Tri& s, const Tri& t) {
    const Vec3 a[3] = {pos[s[0]], pos[s[1]], pos[s[2]]};
    const Vec3 b[3] = {pos[t[0]], pos[t[1]], pos[t[2]]};
    const uint32_t ia[3] = {s[0], s[1], s[2]};
    const uint32_t ib[3] = {t[0], t[1], t[2]};
    return detail::triangles_intersect(a, ia, b, ib);
  };
  for (size_t i = 0; i < added.size(); ++i) {
    for (size_t j = i + 1; j < added.size(); ++j)
      if (intersect(added[i], added[j])) return false;
    for (const Tri& b : base)
      if (intersect(added[i], b)) return false;
  }
  return true;
}

void triangulations(const std::vector<int>& loop, std::vector<std::vector<Tri>>& out) {
  const int n = int(loop.size());
  auto diagonal_ok = [&](int i, int j) {
    if (j - i == 1 || (i == 0 && j == n - 1)) return true;  // polygon edge
    return (vertex_faces(loop[i]) & vertex_faces(loop[j])) == 0;
  };
  std::function<void(int, int, std::vector<Tri>&, std::function<void(std::vector<Tri>&)>)> rec;
  // Triangulate sub-polygon i..j (base edge i-j), then call k.
  rec = [&](int i, int j, std::vector<Tri>& acc, std::function<void(std::vector<Tri>&)> k) {
    if (j - i < 2) {
      k(acc);
      return;
    }
    for (int m = i + 1; m < j; ++m) {
      if (!diagonal_ok(i, m) || !diagonal_ok(m, j)) continue;
      acc.push_back({uint8_t(loop[i]), uint8_t(loop[m]), uint8_t(loop[j])});
      rec(i, m, acc, [&](std::vector<Tri>& a2) { rec(m, j, a2, k); });
      acc.pop_back();
    }
  };
  std::vector<Tri> acc;
  rec(0, n - 1, acc, [&](std::vector<Tri>& done) { out.push_back(done); });
}

double total_area(const std::vector<Tri>& tris, std::span<const Vec3> pos) {
  double a = 0;
  for (const Tri& t : tris) a += (pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]]).norm();
  return 0.5 * a;
}

}  // namespace voxpress::detail
