// Quadric-error edge collapse (Garland and Heckbert 1997) that keeps a closed
// 2-manifold closed and 2-manifold.
//
// Each vertex carries the sum of its faces' plane quadrics (area weighted);
// edges between faces with different keys (voxel colours) add, for both
// faces, the plane through the edge perpendicular to the face (the paper's
// "preserve boundaries" penalty, applied to colour borders), so collapses
// slide along colour borders instead of across them. The cheapest edge
// collapses first to the quadric's minimiser (or the best of its endpoints
// and midpoint when the system is singular or the minimiser strays). A
// collapse is refused when the edge fails the link condition (the common
// neighbours of its ends must be exactly the two opposite corners), when an
// opposite corner has only three neighbours (a tetrahedron would fold), or
// when a surviving face would flip or degenerate. Serial, so deterministic.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <queue>

#include "voxpress/voxart/polygonize.h"

namespace voxpress {
namespace {

using Quadric = Eigen::Matrix4d;

Quadric plane_quadric(const Vec3& n, const Vec3& p, double weight) {
  Eigen::Vector4d q(n.x(), n.y(), n.z(), -n.dot(p));
  return weight * q * q.transpose();
}

double cost(const Quadric& q, const Vec3& x) {
  Eigen::Vector4d h(x.x(), x.y(), x.z(), 1);
  return std::max(0.0, h.dot(q * h));
}

}  // namespace

void simplify_mesh(Mesh& mesh, uint64_t target, const std::vector<uint32_t>& face_keys) {
  const size_t nv = mesh.positions.size(), nf = mesh.triangles.size();
  if (nf <= target) return;
  std::vector<Vec3>& pos = mesh.positions;
  std::vector<Triangle>& tri = mesh.triangles;
  std::vector<Quadric> Q(nv, Quadric::Zero());
  std::vector<std::vector<uint32_t>> vf(nv);
  auto normal = [&](const Triangle& t) { return Vec3((pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]])); };
  for (uint32_t f = 0; f < nf; ++f) {
    const Vec3 n = normal(tri[f]);
    const double a2 = n.norm();
    if (a2 > 0)
      for (uint32_t v : tri[f]) Q[v] += plane_quadric(n / a2, pos[tri[f][0]], a2 / 2);
    for (uint32_t v : tri[f]) vf[v].push_back(f);
  }
  // Edges (a < b) with their two faces, from sorted half-edges.
  struct HalfEdge {
    uint32_t a, b, face;
  };
  std::vector<HalfEdge> he;
  he.reserve(3 * nf);
  for (uint32_t f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = tri[f][size_t(c)], b = tri[f][size_t((c + 1) % 3)];
      he.push_back({std::min(a, b), std::max(a, b), f});
    }
  std::sort(he.begin(), he.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return std::tie(x.a, x.b, x.face) < std::tie(y.a, y.b, y.face);
  });
  std::vector<std::array<uint32_t, 2>> edges;
  for (size_t i = 0; i < he.size(); ++i) {
    if (i > 0 && he[i].a == he[i - 1].a && he[i].b == he[i - 1].b) {
      if (!face_keys.empty() && face_keys[he[i].face] != face_keys[he[i - 1].face]) {
        const Vec3 e = pos[he[i].b] - pos[he[i].a];
        const double len2 = e.squaredNorm();
        for (uint32_t f : {he[i].face, he[i - 1].face}) {
          Vec3 m = e.cross(normal(tri[f]));
          if (m.norm() == 0) continue;
          m.normalize();
          const Quadric k = plane_quadric(m, pos[he[i].a], len2);
          Q[he[i].a] += k;
          Q[he[i].b] += k;
        }
      }
      continue;
    }
    edges.push_back({he[i].a, he[i].b});
  }
  he = {};

  std::vector<uint32_t> version(nv, 0);
  std::vector<uint8_t> face_alive(nf, 1), vertex_alive(nv, 1);
  struct Candidate {
    double cost;
    uint32_t a, b, va, vb;
    Vec3 x;
    bool operator<(const Candidate& o) const {  // min-heap on cost, then on the edge
      if (cost != o.cost) return cost > o.cost;
      return std::tie(a, b) > std::tie(o.a, o.b);
    }
  };
  auto evaluate = [&](uint32_t a, uint32_t b) {
    const Quadric q = Q[a] + Q[b];
    const Vec3 mid = (pos[a] + pos[b]) / 2;
    const double len = (pos[a] - pos[b]).norm();
    Candidate c{INFINITY, std::min(a, b), std::max(a, b), 0, 0, mid};
    c.va = version[c.a];
    c.vb = version[c.b];
    const Eigen::Matrix3d A = q.topLeftCorner<3, 3>();
    const Eigen::Vector3d rhs = -q.topRightCorner<3, 1>();
    Eigen::Matrix3d inv;
    bool invertible = false;
    // Closed-form inverse; "singular" relative to the quadric's scale.
    A.computeInverseWithCheck(inv, invertible, 1e-12 * std::max(1e-300, A.cwiseAbs().maxCoeff() * A.cwiseAbs().maxCoeff() * A.cwiseAbs().maxCoeff()));
    if (invertible) {
      const Vec3 x = inv * rhs;
      if ((x - mid).norm() <= 2 * len) {
        c.x = x;
        c.cost = cost(q, x);
      }
    }
    for (const Vec3& x : {pos[a], pos[b], mid}) {
      const double e = cost(q, x);
      if (e < c.cost) {
        c.cost = e;
        c.x = x;
      }
    }
    return c;
  };
  std::priority_queue<Candidate> heap;
  for (const auto& e : edges) heap.push(evaluate(e[0], e[1]));
  edges = {};

  uint64_t alive = nf;
  std::vector<uint32_t> na, nb, common;
  auto neighbours = [&](uint32_t v, std::vector<uint32_t>& out) {
    out.clear();
    for (uint32_t f : vf[v])
      for (uint32_t w : tri[f])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };
  while (alive > target && !heap.empty()) {
    const Candidate c = heap.top();
    heap.pop();
    if (!vertex_alive[c.a] || !vertex_alive[c.b] || version[c.a] != c.va || version[c.b] != c.vb) continue;
    const uint32_t a = c.a, b = c.b;
    // Link condition.
    neighbours(a, na);
    neighbours(b, nb);
    common.clear();
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
    std::vector<uint32_t> shared;  // faces holding both a and b
    for (uint32_t f : vf[a])
      if (tri[f][0] == b || tri[f][1] == b || tri[f][2] == b) shared.push_back(f);
    if (shared.size() != 2 || common.size() != 2) continue;
    bool ok = true;
    for (uint32_t w : common) {
      std::vector<uint32_t> nw;
      neighbours(w, nw);
      if (nw.size() <= 3) ok = false;
    }
    if (na.size() + nb.size() - 2 <= 4) ok = false;  // would leave a component of under four vertices
    // Surviving faces must neither flip nor degenerate.
    for (uint32_t v : {a, b}) {
      if (!ok) break;
      for (uint32_t f : vf[v]) {
        if (f == shared[0] || f == shared[1]) continue;
        Triangle t = tri[f];
        const Vec3 before = normal(t);
        const Vec3 p0 = t[0] == a || t[0] == b ? c.x : pos[t[0]];
        const Vec3 p1 = t[1] == a || t[1] == b ? c.x : pos[t[1]];
        const Vec3 p2 = t[2] == a || t[2] == b ? c.x : pos[t[2]];
        const Vec3 after = (p1 - p0).cross(p2 - p0);
        const double lb = before.norm(), la = after.norm();
        if (la <= 1e-12 * std::max(1.0, lb) || after.dot(before) <= 0.2 * la * lb) {
          ok = false;
          break;
        }
      }
    }
    if (!ok) continue;
    for (uint32_t f : shared) {
      face_alive[f] = 0;
      --alive;
      for (uint32_t v : tri[f]) vf[v].erase(std::remove(vf[v].begin(), vf[v].end(), f), vf[v].end());
    }
    for (uint32_t f : vf[b]) {
      for (uint32_t& v : tri[f])
        if (v == b) v = a;
      vf[a].push_back(f);
    }
    vf[b].clear();
    vertex_alive[b] = 0;
    pos[a] = c.x;
    Q[a] += Q[b];
    ++version[a];  // invalidates a's queued edges; the others' costs did not change
    neighbours(a, na);
    for (uint32_t w : na) heap.push(evaluate(a, w));
  }
  // Compact.
  std::vector<uint32_t> remap(nv, UINT32_MAX);
  std::vector<Vec3> p2;
  std::vector<Triangle> t2;
  for (uint32_t f = 0; f < nf; ++f) {
    if (!face_alive[f]) continue;
    Triangle t = tri[f];
    for (uint32_t& v : t) {
      if (remap[v] == UINT32_MAX) {
        remap[v] = uint32_t(p2.size());
        p2.push_back(pos[v]);
      }
      v = remap[v];
    }
    t2.push_back(t);
  }
  Mesh out;
  out.positions = std::move(p2);
  out.triangles = std::move(t2);
  mesh = std::move(out);
}

}  // namespace voxpress
