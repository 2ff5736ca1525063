// The Garland-Heckbert error quadric of the simplifier (collapser.h).
#pragma once

#include "voxpress/core/types.h"

namespace voxpress::detail {

/// Symmetric 4x4 error quadric (Garland and Heckbert 1997): 10 coefficients
/// xx xy xz xw yy yz yw zz zw ww. (Not smooth/quadric.h's Quadric, a height
/// field: one name for two classes in one namespace would break the ODR.)
struct ErrorQuadric {
  double a[10] = {};
  /// weight * (n.x - c)^2 with n unit.
  static ErrorQuadric plane(const Vec3& n, double c, double weight);
  ErrorQuadric& operator+=(const ErrorQuadric& o);
  double operator()(const Vec3& x) const;
  /// The minimiser when the 3x3 part is well conditioned.
  bool minimise(Vec3& x) const;
};

}  // namespace voxpress::detail
