// bench/organic.h — the 256^3 organic benchmark volume shared by the
// benchmarks: a gyroid (period 46 voxels) clipped by a ball of radius 120,
// about 1 M sticks.
#pragma once

#include <cmath>

#include "voxpress/core/volume.h"

namespace voxpress::bench {

inline const BinaryVolume& organic() {
  static const BinaryVolume v = [] {
    BinaryVolume b;
    const int64_t n = 256;
    b.lattice.dims = {n, n, n};
    b.inside.resize(size_t(n * n * n));
    const double w = 2 * M_PI / 46.0;
    for (int64_t k = 0; k < n; ++k)
      for (int64_t j = 0; j < n; ++j)
        for (int64_t i = 0; i < n; ++i) {
          const double x = double(i) - 127.5, y = double(j) - 127.3, z = double(k) - 127.1;
          const double g = std::sin(w * x) * std::cos(w * y) + std::sin(w * y) * std::cos(w * z) +
                           std::sin(w * z) * std::cos(w * x);
          b.inside[b.lattice.linear(i, j, k)] = x * x + y * y + z * z < 120.0 * 120.0 && g > 0.2;
        }
    b.source = "organic 256^3 (gyroid in a ball)";
    return b;
  }();
  return v;
}

}  // namespace voxpress::bench
