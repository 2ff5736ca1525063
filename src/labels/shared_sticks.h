// The stick vertices of a shared surface by global stick key (private to
// src/labels): a label's own surface (extract_sticks of its mask on its box)
// names its sticks the same way, which maps its flats and its sharpening
// onto the shared vertices.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "voxpress/extract/sticks.h"
#include "voxpress/labels/shared_surface.h"

namespace voxpress::detail {

class SharedSticks {
 public:
  explicit SharedSticks(const SharedSurface& s) : dims_(s.lattice.dims) {
    for (uint32_t v = 0; v < s.mesh.positions.size(); ++v)
      if (s.kind[v] < 3) sticks_.push_back({key(s.corner[v], s.kind[v]), v});
    std::sort(sticks_.begin(), sticks_.end());
  }
  /// The shared vertex of stick k of `surface`, the surface of a mask whose
  /// sample (0, 0, 0) is sample `lo` of the shared lattice; UINT32_MAX when
  /// the shared surface has no such stick.
  uint32_t find(const StickSurface& surface, size_t k, const std::array<int64_t, 3>& lo) const {
    std::array<int64_t, 3> lower = surface.lower_index(k);
    for (int a = 0; a < 3; ++a) lower[size_t(a)] += lo[size_t(a)];
    const uint64_t want = key(lower, surface.axis(k));
    const auto it = std::lower_bound(sticks_.begin(), sticks_.end(), std::pair<uint64_t, uint32_t>{want, 0});
    return it == sticks_.end() || it->first != want ? UINT32_MAX : it->second;
  }

 private:
  uint64_t key(const std::array<int64_t, 3>& lower, int axis) const {
    return stick_key(dims_, {lower[0] + 1, lower[1] + 1, lower[2] + 1}, axis);
  }
  std::array<int64_t, 3> dims_;
  std::vector<std::pair<uint64_t, uint32_t>> sticks_;
};

/// The lower corner of a label's box with the one sample around it (the
/// mask label_mask makes, not clipped to the volume), in the shared lattice.
inline std::array<int64_t, 3> mask_origin(const std::array<int64_t, 3>& label_lo) {
  return {label_lo[0] - 1, label_lo[1] - 1, label_lo[2] - 1};
}

}  // namespace voxpress::detail
