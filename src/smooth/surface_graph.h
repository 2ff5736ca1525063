// Private helpers shared by the flats detector and the sharpener: oriented
// planes, least-squares plane fits, and the vertex adjacency of a triangle
// set (index space throughout).
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <type_traits>
#include <vector>

#include "voxpress/core/progress.h"
#include "voxpress/core/types.h"

namespace voxpress::detail {

// Degrees between unit vectors a and b.
inline double degrees_between(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / std::numbers::pi;
}

// Oriented plane n . x = c (index space), inside at n . x < c.
struct Plane {
  Vec3 n{0, 0, 1};
  double c = 0;
};

// Principal axes of points: mean, eigenvalues ascending, the smallest's axis.
struct Pca {
  Vec3 mean, eigenvalues, normal;
};
Pca pca(const std::vector<Vec3>& pts);  // smooth/quadric_fit.cpp

// The least-squares plane of a PCA, oriented along `towards`.
inline Plane oriented_plane(const Pca& q, const Vec3& towards) {
  const Vec3 n = q.normal.dot(towards) < 0 ? Vec3(-q.normal) : q.normal;
  return {n, n.dot(q.mean)};
}

// Least-squares plane (orthogonal PCA) of points, oriented along `towards`.
inline Plane fit_plane(const std::vector<Vec3>& pts, const Vec3& towards) { return oriented_plane(pca(pts), towards); }

// Grows `ring` (sorted, unique vertex ids) by `rings` rings of neighbours.
inline void grow_rings(std::vector<uint32_t>& ring, int rings, const std::vector<uint32_t>& off,
                       const std::vector<uint32_t>& adj) {
  for (int k = 0; k < rings; ++k) {
    const size_t end = ring.size();
    for (size_t i = 0; i < end; ++i)
      for (uint32_t q = off[ring[i]]; q < off[ring[i] + 1]; ++q) ring.push_back(adj[q]);
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
}

// Rings around v: out receives (vertex, ring) for v (ring 0) and every
// vertex reached through vertices accepted by `ok` within `depth` rings.
// `seen` (one stamp per vertex, all below `stamp` on entry) is scratch
// reused between calls; `stamp` is advanced.
struct RingScratch {
  std::vector<uint32_t> seen;
  uint32_t stamp = 0;
  std::vector<std::pair<uint32_t, uint32_t>> out;
};
template <class Ok>
void rings_around(uint32_t v, uint32_t depth, const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj, Ok ok,
                  RingScratch& r) {
  if (r.seen.size() + 1 < off.size()) r.seen.assign(off.size() - 1, 0);
  if (++r.stamp == 0) {  // wrapped: clear
    std::fill(r.seen.begin(), r.seen.end(), 0);
    r.stamp = 1;
  }
  r.out.assign(1, {v, 0});
  r.seen[v] = r.stamp;
  for (size_t q = 0; q < r.out.size(); ++q) {
    const auto [a, d] = r.out[q];
    if (d == depth) continue;
    for (uint32_t k = off[a]; k < off[a + 1]; ++k) {
      const uint32_t w = adj[k];
      if (r.seen[w] == r.stamp || !ok(w)) continue;
      r.seen[w] = r.stamp;
      r.out.push_back({w, d + 1});
    }
  }
}

// Breadth-first rings from several sources at once: `front` holds the
// vertices at ring distance `first` (already set in `dist`); each ring adds
// the neighbours w of its vertices v that are unreached (dist[w] ==
// kUnreached) and that enter(v, w) admits (it may record what w inherits
// from v), with dist[w] = ring, up to ring `last`. Visits in a fixed order.
constexpr uint32_t kUnreached = UINT32_MAX;
template <class Enter>
void spread_rings(std::vector<uint32_t> front, uint32_t first, uint32_t last, const std::vector<uint32_t>& off,
                  const std::vector<uint32_t>& adj, std::vector<uint32_t>& dist, Enter enter) {
  std::vector<uint32_t> next;
  for (uint32_t d = first; d < last && !front.empty(); ++d) {
    next.clear();
    for (uint32_t v : front)
      for (uint32_t k = off[v]; k < off[v + 1]; ++k) {
        const uint32_t w = adj[k];
        if (dist[w] != kUnreached || !enter(v, w)) continue;
        dist[w] = d + 1;
        next.push_back(w);
      }
    front.swap(next);
  }
}

// Ring distance of every vertex from a border between regions (a vertex
// with a neighbour of another region is at 0), up to `rings`; kUnreached
// beyond.
inline std::vector<uint32_t> region_border_rings(const std::vector<int32_t>& region, uint32_t rings,
                                                 const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj) {
  const size_t n = region.size();
  std::vector<uint32_t> depth(n, kUnreached), front;
  for (uint32_t v = 0; v < n; ++v)
    for (uint32_t k = off[v]; k < off[v + 1]; ++k)
      if (region[adj[k]] != region[v]) {
        depth[v] = 0;
        front.push_back(v);
        break;
      }
  spread_rings(std::move(front), 0, rings, off, adj, depth, [](uint32_t, uint32_t) { return true; });
  return depth;
}

// Appends to `out` the regions >= 0 (flats) of the vertices of `ring`
// (rings_around's output) that it does not hold yet, in ring order.
inline void add_flats(const std::vector<std::pair<uint32_t, uint32_t>>& ring, const std::vector<int32_t>& region,
                      std::vector<int32_t>& out) {
  for (const auto& [w, d] : ring)
    if (const int32_t r = region[w]; r >= 0 && std::find(out.begin(), out.end(), r) == out.end()) out.push_back(r);
}

// How the flats `near` meet around `ring`: their solid is the intersection
// of their half-spaces (convex, +1) when the members in the ring lie inside
// the other flats' planes, at least 3 to 1 (or when there is one flat), the
// union (concave, -1) when outside, 3 to 1; else undecided (0). pos(w) is
// member w's position (a Vec3, not an Eigen expression of temporaries),
// height(f, p) the signed distance of p to flat f.
template <class Pos, class Height>
int crease_kind(const std::vector<std::pair<uint32_t, uint32_t>>& ring, const std::vector<int32_t>& region,
                const std::vector<int32_t>& near, Pos pos, Height height) {
  static_assert(std::is_same_v<std::invoke_result_t<Pos, uint32_t>, Vec3>, "pos must return a Vec3 by value");
  size_t inside = 0, outside = 0;
  for (const auto& [w, d] : ring)
    if (const int32_t r = region[w]; r >= 0) {
      const Vec3 x = pos(w);
      for (int32_t f : near)
        if (f != r) (height(f, x) < 0 ? inside : outside) += 1;
    }
  const bool convex = near.size() == 1 || inside >= 3 * outside;
  const bool concave = near.size() > 1 && outside >= 3 * inside;
  return convex == concave ? 0 : convex ? 1 : -1;
}

// Vertex adjacency of `n` vertices from triangles (CSR: the neighbours of v
// are adj[off[v] .. off[v + 1]), sorted, each once).
inline void vertex_adjacency(size_t n, const std::vector<Triangle>& triangles, std::vector<uint32_t>& off,
                             std::vector<uint32_t>& adj) {
  off.assign(n + 1, 0);
  for (const Triangle& tr : triangles)
    for (uint32_t v : tr) off[v + 1] += 2;
  for (size_t v = 0; v < n; ++v) off[v + 1] += off[v];
  adj.resize(off[n]);
  std::vector<uint32_t> fill(off.begin(), off.end() - 1);
  for (const Triangle& tr : triangles)
    for (int e = 0; e < 3; ++e) {
      adj[fill[tr[size_t(e)]]++] = tr[size_t((e + 1) % 3)];
      adj[fill[tr[size_t(e)]]++] = tr[size_t((e + 2) % 3)];
    }
  // Deduplicate each list in place, then compact.
  uint32_t out = 0;
  for (size_t v = 0; v < n; ++v) {
    const uint32_t b = off[v], e = off[v + 1];
    std::sort(adj.begin() + b, adj.begin() + e);
    const uint32_t start = out;
    for (uint32_t k = b; k < e; ++k)
      if (k == b || adj[k] != adj[k - 1]) adj[out++] = adj[k];
    off[v] = start;
  }
  off[n] = out;
  adj.resize(out);
}

// A surface's vertex adjacency (CSR, as vertex_adjacency), built once per
// surface and shared by every stage that walks its rings (the triangles do
// not change while the feature layer runs).
struct Adjacency {
  std::vector<uint32_t> off, adj;
  Adjacency() = default;
  Adjacency(size_t n, const std::vector<Triangle>& triangles) { vertex_adjacency(n, triangles, off, adj); }
};

// Gauss-Seidel umbrella relaxation (Bade Section 4; Gibson's nets): each
// iteration visits the vertices in order and sets x[v] = project(v, mean of
// its neighbours' current positions); stops once no vertex moved more than
// `threshold` within one iteration, or after max_iterations. Serial, so the
// result does not depend on the thread count. Vertices without neighbours
// stay put.
struct Relaxation {
  int iterations = 0;
  double last_max_change = 0;
  bool converged = false;
};
template <class Project>
Relaxation relax(std::vector<Vec3>& x, const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj,
                 Project&& project, double threshold, int max_iterations, ProgressCounter& progress) {
  Relaxation r;
  for (int it = 0; it < max_iterations; ++it) {
    double max_change = 0;
    for (size_t v = 0; v + 1 < off.size(); ++v) {
      const uint32_t b = off[v], e = off[v + 1];
      if (b == e) continue;
      Vec3 s = Vec3::Zero();
      for (uint32_t k = b; k < e; ++k) s += x[adj[k]];
      const Vec3 next = project(v, Vec3(s / double(e - b)));
      max_change = std::max(max_change, (next - x[v]).squaredNorm());
      x[v] = next;
    }
    r.iterations = it + 1;
    r.last_max_change = std::sqrt(max_change);
    progress.add(1);
    if (r.last_max_change < threshold) {
      r.converged = true;
      break;
    }
  }
  return r;
}

}  // namespace voxpress::detail
