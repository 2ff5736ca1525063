// The box of a set of sticks' lower samples, and its extent (private):
// what the press and on_own_box take positions relative to.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace voxpress::detail {

// The box of the n sticks' lower samples, lower(i) (D index coordinates):
// min, then max, of each coordinate. Positions and the vertex order of the
// iteration are taken relative to its min, so that a shifted, padded or
// cropped volume gives the same arithmetic, hence the same t.
template <size_t D>
using IndexBox = std::array<int64_t, 2 * D>;

template <size_t D, class Lower>
IndexBox<D> stick_box(size_t n, const Lower& lower) {
  IndexBox<D> empty;
  for (size_t a = 0; a < D; ++a) empty[a] = n ? INT64_MAX : 0, empty[a + D] = n ? INT64_MIN : -1;
  const auto merge = [](IndexBox<D>& b, const IndexBox<D>& x) {
    for (size_t a = 0; a < D; ++a) b[a] = std::min(b[a], x[a]), b[a + D] = std::max(b[a + D], x[a + D]);
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, n, 1 << 14), empty,
      [&](const tbb::blocked_range<size_t>& r, IndexBox<D> b) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          const auto l = lower(i);
          IndexBox<D> point;
          for (size_t a = 0; a < D; ++a) point[a] = point[a + D] = l[a];
          merge(b, point);
        }
        return b;
      },
      [&](IndexBox<D> x, const IndexBox<D>& y) {
        merge(x, y);
        return x;
      });
}

// The box's extent: its longest side in cells (a stick's upper sample lies
// one past its lower one), what PressOptions::levels is resolved by.
template <size_t D>
int64_t extent_of(const IndexBox<D>& box) {
  int64_t extent = 0;
  for (size_t a = 0; a < D; ++a) extent = std::max(extent, box[a + D] + 1 - box[a]);
  return extent;
}

}  // namespace voxpress::detail
