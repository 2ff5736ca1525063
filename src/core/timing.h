// Private: wall-clock seconds for the stats structs of the library stages.
#pragma once

#include <chrono>

namespace voxpress::detail {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace voxpress::detail
