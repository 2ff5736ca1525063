// Private: "no such vertex" in the library's uint32_t index arrays.
#pragma once

#include <cstdint>

namespace voxpress::detail {

inline constexpr uint32_t kNone = UINT32_MAX;

}  // namespace voxpress::detail
