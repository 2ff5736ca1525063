#include "mesh_query.h"

#include <algorithm>
#include <cmath>

namespace voxpress::detail {
namespace {

double diagonal(const Vec3& a, const Vec3& b, const Vec3& c) {
  return (a.cwiseMax(b).cwiseMax(c) - a.cwiseMin(b).cwiseMin(c)).norm();
}

double box_dist2(const Aabb& b, const Vec3& p) {
  const Vec3 d = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0);
  return d.squaredNorm();
}

uint64_t mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

double uniform(uint64_t seed, uint64_t index) {
  return double(mix(seed * 0x9e3779b97f4a7c15ull + mix(index + 0x632be59bd9b4e019ull)) >> 11) * 0x1.0p-53;
}

Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) return a;  // degenerate triangle
  return a + ab * (vb * denom) + ac * (vc * denom);
}

void MeshQuery::make_prims() {
  const auto& P = mesh_.positions;
  const size_t F = mesh_.triangles.size();
  std::vector<double> diag(F);
  Aabb all;
  for (size_t f = 0; f < F; ++f) {
    const auto& t = mesh_.triangles[f];
    diag[f] = diagonal(P[t[0]], P[t[1]], P[t[2]]);
    for (uint32_t v : t) all.grow(P[v]);
  }
  prims_.reserve(F);
  if (F == 0) return;
  std::vector<double> sorted = diag;
  std::nth_element(sorted.begin(), sorted.begin() + long(F / 2), sorted.end());
  const double limit = std::max(4 * sorted[F / 2], (all.hi - all.lo).norm() / 16);
  std::vector<Piece> todo;
  for (size_t f = 0; f < F; ++f) {
    if (diag[f] <= limit) {
      prims_.push_back({uint32_t(f), -1});
      continue;
    }
    const auto& t = mesh_.triangles[f];
    todo.push_back({P[t[0]], P[t[1]], P[t[2]], uint32_t(f)});
    int budget = 256;  // pieces per face at most
    while (!todo.empty()) {
      Piece q = todo.back();
      todo.pop_back();
      if (diagonal(q.a, q.b, q.c) <= limit || budget <= 1) {
        prims_.push_back({q.face, int32_t(pieces_.size())});
        pieces_.push_back(q);
        continue;
      }
      // Bisect the longest edge: rotate so that it is (a, b).
      const double ab = (q.b - q.a).squaredNorm(), bc = (q.c - q.b).squaredNorm(), ca = (q.a - q.c).squaredNorm();
      if (bc >= ab && bc >= ca)
        q = {q.b, q.c, q.a, q.face};
      else if (ca >= ab && ca >= bc)
        q = {q.c, q.a, q.b, q.face};
      const Vec3 m = 0.5 * (q.a + q.b);
      todo.push_back({q.a, m, q.c, q.face});
      todo.push_back({m, q.b, q.c, q.face});
      --budget;
    }
  }
}

std::vector<Aabb> MeshQuery::prim_boxes() const {
  std::vector<Aabb> boxes(prims_.size());
  for (size_t i = 0; i < prims_.size(); ++i) {
    const Vec3 *a, *b, *c;
    corners(prims_[i], a, b, c);
    boxes[i].grow(*a);
    boxes[i].grow(*b);
    boxes[i].grow(*c);
  }
  return boxes;
}

// prims_ and pieces_ are declared (so constructed) before bvh_, which is built
// from them once make_prims() has filled them.
MeshQuery::MeshQuery(const Mesh& mesh) : mesh_(mesh), bvh_((make_prims(), prim_boxes())) {
  normals_.resize(mesh.triangles.size());
  cumulative_.resize(mesh.triangles.size());
  double acc = 0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Vec3 n = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    const double len = n.norm();
    normals_[f] = len > 0 ? Vec3(n / len) : Vec3::Zero();
    acc += 0.5 * len;
    cumulative_[f] = acc;
  }
}

MeshQuery::Hit MeshQuery::closest(const Vec3& p) const { return closest(p, Vec3::Zero()); }

MeshQuery::Hit MeshQuery::closest(const Vec3& p, const Vec3& hint) const {
  Hit best;
  best.dist2 = INFINITY;
  if (bvh_.empty()) return best;
  // Faces within a relative 1e-12 of the best distance are ties (the closest
  // point is shared); among them the hint picks the best-aligned normal.
  constexpr int kTies = 16;
  uint32_t tie_face[kTies];
  double tie_d2[kTies];
  int nties = 0;
  auto tie_limit = [&] { return best.dist2 * (1 + 1e-12) + 1e-300; };
  const auto& nodes = bvh_.nodes();
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t n = stack[--top];
    const auto& node = nodes[n];
    if (box_dist2(node.box, p) > tie_limit()) continue;
    if (node.count) {
      for (uint32_t k = 0; k < node.count; ++k) {
        const Prim& pr = prims_[bvh_.order()[node.first + k]];
        const Vec3 *a, *b, *c;
        corners(pr, a, b, c);
        const Vec3 q = closest_on_triangle(p, *a, *b, *c);
        const double d2 = (q - p).squaredNorm();
        if (d2 < best.dist2) {
          best = {q, pr.face, d2};
          int kept = 0;  // earlier candidates still tied with the new best
          for (int t = 0; t < nties; ++t)
            if (tie_d2[t] <= tie_limit()) {
              tie_face[kept] = tie_face[t];
              tie_d2[kept++] = tie_d2[t];
            }
          nties = kept;
        }
        if (d2 <= tie_limit() && nties < kTies) {
          tie_face[nties] = pr.face;
          tie_d2[nties++] = d2;
        }
      }
      continue;
    }
    const uint32_t l = n + 1, r = node.right;
    const double dl = box_dist2(nodes[l].box, p), dr = box_dist2(nodes[r].box, p);
    if (top + 2 > 128) continue;  // cannot happen for a tree of < 2^60 leaves
    if (dl < dr) {
      stack[top++] = r;
      stack[top++] = l;
    } else {
      stack[top++] = l;
      stack[top++] = r;
    }
  }
  if (nties > 1 && hint != Vec3::Zero()) {
    double best_dot = -INFINITY;
    for (int t = 0; t < nties; ++t) {
      const double d = normals_[tie_face[t]].dot(hint);
      if (d > best_dot || (d == best_dot && tie_face[t] < best.face)) {
        best_dot = d;
        best.face = tie_face[t];
      }
    }
  }
  return best;
}

void MeshQuery::segment_hits(const Vec3& a, const Vec3& b, std::vector<double>& out) const {
  out.clear();
  if (bvh_.empty()) return;
  Aabb seg;
  seg.grow(a);
  seg.grow(b);
  const Vec3 d = b - a;
  const auto& nodes = bvh_.nodes();
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const uint32_t n = stack.back();
    stack.pop_back();
    const auto& node = nodes[n];
    if (!node.box.overlaps(seg)) continue;
    if (!node.count) {
      stack.push_back(n + 1);
      stack.push_back(node.right);
      continue;
    }
    for (uint32_t k = 0; k < node.count; ++k) {
      const Vec3 *pa, *pb, *pc;
      corners(prims_[bvh_.order()[node.first + k]], pa, pb, pc);
      const Vec3 &v0 = *pa, &v1 = *pb, &v2 = *pc;
      const Vec3 e1 = v1 - v0, e2 = v2 - v0, h = d.cross(e2);
      const double det = e1.dot(h);
      if (det == 0) continue;
      const double inv = 1 / det;
      const Vec3 s = a - v0;
      const double u = inv * s.dot(h);
      if (u < 0 || u > 1) continue;
      const Vec3 q = s.cross(e1);
      const double v = inv * d.dot(q);
      if (v < 0 || u + v > 1) continue;
      const double t_hit = inv * e2.dot(q);
      if (t_hit >= 0 && t_hit <= 1) out.push_back(t_hit);
    }
  }
}

MeshQuery::Hit MeshQuery::sample(uint64_t seed, uint64_t index) const {
  const double target = uniform(seed, 3 * index) * area();
  const uint32_t f = uint32_t(std::min<size_t>(
      size_t(std::upper_bound(cumulative_.begin(), cumulative_.end(), target) - cumulative_.begin()),
      cumulative_.size() - 1));
  double u = uniform(seed, 3 * index + 1), v = uniform(seed, 3 * index + 2);
  if (u + v > 1) {
    u = 1 - u;
    v = 1 - v;
  }
  const auto& t = mesh_.triangles[f];
  const Vec3 p = mesh_.positions[t[0]] + u * (mesh_.positions[t[1]] - mesh_.positions[t[0]]) +
                 v * (mesh_.positions[t[2]] - mesh_.positions[t[0]]);
  return {p, f, 0};
}

}  // namespace voxpress::detail
