// voxpress/core/types.h — small geometric vocabulary shared by every module.
//
// Vec3 / Mat3 are Eigen fixed-size types (no alignment requirement, so they
// are safe in std::vector). A std::vector<Vec3> is a contiguous #V by 3 array
// of doubles, x fastest, which the Python binding exposes without copying.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

namespace voxpress {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec3i = Eigen::Matrix<int64_t, 3, 1>;
using Mat3 = Eigen::Matrix3d;
using Triangle = std::array<uint32_t, 3>;

}  // namespace voxpress
