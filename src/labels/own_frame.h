// A shared surface on its own box (private to src/labels; issue 74, item 2):
// the same arithmetic for any shift, pad or crop of the label map.
#pragma once


#include <algorithm>
#include <array>
#include <cstdint>

#include "voxpress/labels/shared_surface.h"
#include "core/parallel.h"

namespace voxpress::detail {

// The surface's corners relative to its lowest one and its lattice's origin
// moved there, for the lifetime of the object (the physical positions do
// not change); the corners and the origin's bits come back after.
class OwnFrame {
 public:
  explicit OwnFrame(SharedSurface& s) : s_(s), origin_(s.lattice.origin) {
    base_.fill(0);
    if (!s.corner.empty()) {
      base_ = s.corner[0];
      for (const auto& c : s.corner)
        for (size_t a = 0; a < 3; ++a) base_[a] = std::min(base_[a], c[a]);
    }
    shift(-1);
    s.lattice.origin = s.lattice.to_physical(Vec3(double(base_[0]), double(base_[1]), double(base_[2])));
  }
  ~OwnFrame() {
    shift(1);
    s_.lattice.origin = origin_;
  }
  OwnFrame(const OwnFrame&) = delete;
  OwnFrame& operator=(const OwnFrame&) = delete;

 private:
  void shift(int64_t sign) {
    detail::parallel_for(s_.corner.size(), [&](size_t v) {
      for (size_t a = 0; a < 3; ++a) s_.corner[v][a] += sign * base_[a];
    });
  }
  SharedSurface& s_;
  Vec3 origin_;
  std::array<int64_t, 3> base_;
};

}  // namespace voxpress::detail
