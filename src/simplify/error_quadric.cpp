// The error quadric (Garland and Heckbert 1997): planes summed, evaluated,
// minimised. Theory of operation: error_quadric.h.
#include "simplify/error_quadric.h"

#include <Eigen/Dense>
#include <algorithm>

namespace voxpress::detail {

ErrorQuadric ErrorQuadric::plane(const Vec3& n, double c, double w) {
  const double d = -c;
  ErrorQuadric q;
  const double v[4] = {n.x(), n.y(), n.z(), d};
  int k = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) q.a[k++] = w * v[i] * v[j];
  return q;
}

ErrorQuadric& ErrorQuadric::operator+=(const ErrorQuadric& o) {
  for (int k = 0; k < 10; ++k) a[k] += o.a[k];
  return *this;
}

double ErrorQuadric::operator()(const Vec3& p) const {
  const double x = p.x(), y = p.y(), z = p.z();
  const double e = a[0] * x * x + 2 * a[1] * x * y + 2 * a[2] * x * z + 2 * a[3] * x + a[4] * y * y +
                   2 * a[5] * y * z + 2 * a[6] * y + a[7] * z * z + 2 * a[8] * z + a[9];
  return std::max(0.0, e);
}

bool ErrorQuadric::minimise(Vec3& x) const {
  Mat3 A;
  A << a[0], a[1], a[2], a[1], a[4], a[5], a[2], a[5], a[7];
  const Vec3 b(-a[3], -a[6], -a[8]);
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(A);  // closed form: the pushes after each collapse solve a few of these
  const Vec3 ev = es.eigenvalues();
  // Well conditioned: the smallest eigenvalue is not lost in the largest's
  // rounding (a flat region or a straight crease is singular: endpoints).
  if (!(ev.maxCoeff() > 0) || ev.minCoeff() <= 1e-6 * ev.maxCoeff()) return false;
  x = es.eigenvectors() * ((es.eigenvectors().transpose() * b).cwiseQuotient(ev));
  return x.allFinite();
}

}  // namespace voxpress::detail
