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
    if (job.count <= kLeafSize) {
      nodes_[index].first = job.first;
      nodes_[index].count = job.count;
      continue;
    }
    // Binned surface-area heuristic: 16 bins per axis over the centroid
    // bounds; cost = area(L) * |L| + area(R) * |R|. It keeps large faces
    // (slivers) away from small ones, which median splits mix into leaves
    // whose boxes then swallow every nearby query.
    constexpr int kBins = 16;
    auto half_area = [](const Aabb& b) {
      const Vec3 e = b.hi - b.lo;
      return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    double best_cost = INFINITY;
    int best_axis = -1, best_bin = 0;
    // One pass over the node's primitives fills the bins of all three axes.
    Aabb bin_box[3][kBins];
    uint32_t bin_count[3][kBins] = {};
    Vec3 inv_ext;
    for (int axis = 0; axis < 3; ++axis) {
      const double ext = cbox.hi[axis] - cbox.lo[axis];
      inv_ext[axis] = ext > 0 ? kBins / ext : 0;
    }
    for (uint32_t i = job.first; i < job.first + job.count; ++i) {
      const uint32_t p = order_[i];
      for (int axis = 0; axis < 3; ++axis) {
        const int b = std::min(kBins - 1, int((centre[p][axis] - cbox.lo[axis]) * inv_ext[axis]));
        bin_box[axis][b].grow(boxes_[p]);
        ++bin_count[axis][b];
      }
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (inv_ext[axis] == 0) continue;
      double right_area[kBins];
      uint32_t right_count[kBins];
      Aabb acc;
      uint32_t count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        if (bin_count[axis][b]) acc.grow(bin_box[axis][b]);
        count += bin_count[axis][b];
        right_area[b] = count ? half_area(acc) : 0;
        right_count[b] = count;
      }
      acc = Aabb();
      count = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        if (bin_count[axis][b]) acc.grow(bin_box[axis][b]);
        count += bin_count[axis][b];
        if (count == 0 || right_count[b + 1] == 0) continue;
        const double cost = half_area(acc) * count + right_area[b + 1] * right_count[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis < 0) {  // all centroids coincide: split in the middle of the order
      nodes_[index].first = job.first;
      nodes_[index].count = job.count;
      if (job.count > 4 * kLeafSize) {
        nodes_[index].count = 0;
        const uint32_t half = job.count / 2;
        jobs.push_back({index, true, job.first + half, job.count - half});
        jobs.push_back({index, false, job.first, half});
      }
      continue;
    }
    const double lo = cbox.lo[best_axis], inv = inv_ext[best_axis];
    auto begin = order_.begin() + job.first;
    auto mid_it = std::partition(begin, begin + job.count, [&](uint32_t p) {
      return std::min(kBins - 1, int((centre[p][best_axis] - lo) * inv)) <= best_bin;
    });
    const uint32_t half = uint32_t(mid_it - begin);
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
