#include "bvh.h"

#include <algorithm>

namespace voxpress::detail {

Bvh::Bvh(std::span<const Aabb> boxes) : boxes_(boxes.begin(), boxes.end()) {
  const uint32_t n = uint32_t(boxes_.size());
  if (n == 0) return;
  order_.resize(n);
  for (uint32_t i = 0; i < n; ++i) order_[i] = i;
  std::vector<Vec3> centre(n);
  for (uint32_t i = 0; i < n; ++i) centre[i] = 0.5 * (boxes_[i].lo + boxes_[i].hi);
  nodes_.reserve(2 * (n / kLeafSize + 1));

  // A node's index is allocated when its job is popped. Jobs form a stack and
  // the right job is pushed before the left one, so the left child always
  // lands right after its parent and each subtree is contiguous (depth-first).
  struct Job {
    uint32_t parent;  // UINT32_MAX for the root
    bool is_right;
    uint32_t first, count;
  };
  std::vector<Job> jobs{{UINT32_MAX, false, 0, n}};
  while (!jobs.empty()) {
    const Job job = jobs.back();
    jobs.pop_back();
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    if (job.is_right) nodes_[job.parent].right = index;
    Aabb box, cbox;
    for (uint32_t i = job.first; i < job.first + job.count; ++i) {
      box.grow(boxes_[order_[i]]);
      cbox.grow(centre[order_[i]]);
    }
    nodes_[index].box = box;
    const Vec3 ext = cbox.hi - cbox.lo;
    int axis = 0;
    if (ext[1] > ext[axis]) axis = 1;
    if (ext[2] > ext[axis]) axis = 2;
    if (job.count <= kLeafSize || !(ext[axis] > 0)) {
      nodes_[index].first = job.first;
      nodes_[index].count = job.count;
      continue;
    }
    const uint32_t half = job.count / 2;
    auto begin = order_.begin() + job.first;
    std::nth_element(begin, begin + half, begin + job.count, [&](uint32_t a, uint32_t b) {
      return centre[a][axis] < centre[b][axis] || (centre[a][axis] == centre[b][axis] && a < b);
    });
    jobs.push_back({index, true, job.first + half, job.count - half});
    jobs.push_back({index, false, job.first, half});
  }
}

std::vector<std::pair<uint32_t, uint32_t>> Bvh::pair_tasks() const {
  // Expand (root, root) a few levels into independent node pairs.
  std::vector<std::pair<uint32_t, uint32_t>> tasks{{0, 0}}, next;
  for (int level = 0; level < 6; ++level) {
    next.clear();
    bool split = false;
    for (auto [a, b] : tasks) {
      const Node& A = nodes_[a];
      const Node& B = nodes_[b];
      if (a == b && !A.count) {
        next.push_back({a + 1, a + 1});
        next.push_back({A.right, A.right});
        next.push_back({a + 1, A.right});
        split = true;
      } else if (a != b && !A.count && A.box.overlaps(B.box)) {
        next.push_back({a + 1, b});
        next.push_back({A.right, b});
        split = true;
      } else {
        next.push_back({a, b});
      }
    }
    tasks.swap(next);
    if (!split) break;
  }
  return tasks;
}

}  // namespace voxpress::detail
