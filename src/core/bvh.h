// A compact bounding-volume hierarchy over axis-aligned boxes (private).
//
// Built top-down with the binned surface-area heuristic (16 bins per axis),
// iteratively (no recursion whose depth grows with the data), leaves of at
// most kLeafSize primitives (more only when their centroids coincide). Nodes are stored depth-first; the left
// child of an inner node is the next node, `right` names the other. Used for
// self-intersection tests and, later, closest-point queries.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "voxpress/core/types.h"

namespace voxpress::detail {

struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void grow(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void grow(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool overlaps(const Aabb& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
};

class Bvh {
 public:
  static constexpr uint32_t kLeafSize = 4;
  struct Node {
    Aabb box;
    uint32_t right = 0;  // inner: index of the right child; leaf: unused
    uint32_t first = 0;  // leaf: first entry in order()
    uint32_t count = 0;  // leaf: number of primitives (0 for inner nodes)
  };

  explicit Bvh(std::span<const Aabb> boxes);

  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<uint32_t>& order() const { return order_; }
  const std::vector<Aabb>& boxes() const { return boxes_; }
  bool empty() const { return nodes_.empty(); }

  /// Calls f(i, j), i != j, once for every unordered pair of primitives whose
  /// boxes overlap. Pairs are grouped into independent tasks run in parallel;
  /// f must be thread-safe.
  template <class F>
  void for_each_overlapping_pair(F&& f) const;

 private:
  std::vector<Aabb> boxes_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
  // Node pairs to traverse, split so they can run in parallel.
  std::vector<std::pair<uint32_t, uint32_t>> pair_tasks() const;
  template <class F>
  void traverse(uint32_t a, uint32_t b, F& f) const;
};

template <class F>
void Bvh::traverse(uint32_t a0, uint32_t b0, F& f) const {
  std::vector<std::pair<uint32_t, uint32_t>> stack{{a0, b0}};
  while (!stack.empty()) {
    auto [a, b] = stack.back();
    stack.pop_back();
    const Node& A = nodes_[a];
    const Node& B = nodes_[b];
    if (a == b) {
      if (A.count) {
        for (uint32_t i = 0; i < A.count; ++i)
          for (uint32_t j = i + 1; j < A.count; ++j) {
            const uint32_t p = order_[A.first + i], q = order_[A.first + j];
            if (boxes_[p].overlaps(boxes_[q])) f(p, q);
          }
      } else {
        stack.push_back({a + 1, a + 1});
        stack.push_back({A.right, A.right});
        stack.push_back({a + 1, A.right});
      }
      continue;
    }
    if (!A.box.overlaps(B.box)) continue;
    if (A.count && B.count) {
      for (uint32_t i = 0; i < A.count; ++i)
        for (uint32_t j = 0; j < B.count; ++j) {
          const uint32_t p = order_[A.first + i], q = order_[B.first + j];
          if (boxes_[p].overlaps(boxes_[q])) f(p, q);
        }
    } else if (!A.count && (B.count || (A.box.hi - A.box.lo).sum() >= (B.box.hi - B.box.lo).sum())) {
      stack.push_back({a + 1, b});
      stack.push_back({A.right, b});
    } else {
      stack.push_back({a, b + 1});
      stack.push_back({a, B.right});
    }
  }
}

}  // namespace voxpress::detail

#include "core/parallel.h"

template <class F>
void voxpress::detail::Bvh::for_each_overlapping_pair(F&& f) const {
  if (nodes_.empty()) return;
  const auto tasks = pair_tasks();
  detail::parallel_for(tasks.size(), [&](size_t t) { traverse(tasks[t].first, tasks[t].second, f); });
}
