// Clearance distances (see clearance.h). The closest-point routines follow
// Ericson, Real-Time Collision Detection (2005), Sections 5.1.5 and 5.1.9.
#include "core/clearance.h"

#include "core/predicates.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

namespace voxpress::detail {

double float32_clearance(const Lattice& lattice, double reach) {
  // Half an ulp of x is at most 2^-24 |x|.
  constexpr double kHalfUlp = 0x1p-24;
  const Mat3 M = lattice.index_to_physical_matrix();
  double largest = 0;
  for (int corner = 0; corner < 8; ++corner) {
    Vec3 ijk;
    for (int a = 0; a < 3; ++a)
      ijk[a] = (corner >> a) & 1 ? double(lattice.dims[size_t(a)] - 1) + reach : -reach;
    largest = std::max(largest, (lattice.origin + M * ijk).cwiseAbs().maxCoeff());
  }
  // ||M^-1||_2 <= ||M^-1||_F: physical -> index lengths, bounded above.
  const double rounding = std::sqrt(3.0) * kHalfUlp * largest * M.inverse().norm();  // index cells, worst vector
  return std::max(4 * rounding, 1e-12);
}

double float32_clearance_around(const Lattice& lattice, const std::vector<Vec3>& index_points, double reach) {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  if (!index_points.empty()) {
    lo = hi = index_points[0];
    for (const Vec3& x : index_points) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  }
  Lattice box = lattice;
  box.origin = lattice.to_physical(Vec3(lo.array().floor()));
  for (size_t a = 0; a < 3; ++a) box.dims[a] = int64_t(std::floor(hi[int(a)]) - std::floor(lo[int(a)])) + 2;
  return float32_clearance(box, reach);
}

double float32_rounding(const Lattice& lattice, double reach) {
  constexpr double kHalfUlp = 0x1p-24;
  const Mat3 M = lattice.index_to_physical_matrix();
  Vec3 largest = Vec3::Zero();  // per physical axis, over the box's corners (the coordinates are affine)
  for (int corner = 0; corner < 8; ++corner) {
    Vec3 ijk;
    for (int a = 0; a < 3; ++a)
      ijk[a] = (corner >> a) & 1 ? double(lattice.dims[size_t(a)] - 1) + reach : -reach;
    largest = largest.cwiseMax((lattice.origin + M * ijk).cwiseAbs());
  }
  const Vec3 per_axis = M.inverse().cwiseAbs() * (kHalfUlp * largest);  // index cells on each axis
  return std::max(per_axis.norm(), 1e-12);
}

double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + ab * (d1 / (d1 - d3)))).squaredNorm();
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + ac * (d2 / (d2 - d6)))).squaredNorm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).squaredNorm();
  const double denom = va + vb + vc;
  if (!(denom > 0)) {  // degenerate triangle: its three sides
    return std::min({segment_distance2(p, p, a, b), segment_distance2(p, p, b, c), segment_distance2(p, p, c, a)});
  }
  const double v = vb / denom, w = vc / denom;
  return (p - (a + ab * v + ac * w)).squaredNorm();
}

double segment_distance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) return r.squaredNorm();
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + d1 * s) - (q0 + d2 * t)).squaredNorm();
}

double triangle_altitude(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double longest = std::sqrt(std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()}));
  return longest > 0 ? (b - a).cross(c - a).norm() / longest : 0;
}

namespace {
// Boxes of the point sets farther apart than d in some axis: their points are.
template <size_t A, size_t B>
bool boxes_apart(const Vec3* (&a)[A], const Vec3* (&b)[B], double d) {
  for (int k = 0; k < 3; ++k) {
    double alo = (*a[0])[k], ahi = alo, blo = (*b[0])[k], bhi = blo;
    for (size_t i = 1; i < A; ++i) alo = std::min(alo, (*a[i])[k]), ahi = std::max(ahi, (*a[i])[k]);
    for (size_t i = 1; i < B; ++i) blo = std::min(blo, (*b[i])[k]), bhi = std::max(bhi, (*b[i])[k]);
    if (alo > bhi + d || blo > ahi + d) return true;
  }
  return false;
}
}  // namespace

bool triangles_within(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3],
                      double d) {
  auto shared = [](uint32_t v, const uint32_t (&ids)[3]) { return v == ids[0] || v == ids[1] || v == ids[2]; };
  // Each triangle's corners not shared with the other.
  int own_a[3], own_b[3], na = 0, nb = 0;
  for (int k = 0; k < 3; ++k) {
    if (!shared(ia[k], ib)) own_a[na++] = k;
    if (!shared(ib[k], ia)) own_b[nb++] = k;
  }
  const double d2 = d * d;
  const Vec3* A[3] = {&ta[0], &ta[1], &ta[2]};
  const Vec3* B[3] = {&tb[0], &tb[1], &tb[2]};
  auto point_near = [&](const Vec3& p, const Vec3* (&t)[3]) {
    const Vec3* P[1] = {&p};
    return !boxes_apart(P, t, d) && point_triangle_distance2(p, *t[0], *t[1], *t[2]) <= d2;
  };
  for (int k = 0; k < na; ++k)
    if (point_near(ta[own_a[k]], B)) return true;
  for (int k = 0; k < nb; ++k)
    if (point_near(tb[own_b[k]], A)) return true;
  if (na <= 1) return false;  // a shared edge (apexes only), or the same triangle
  // Edges: both triangles' edges when disjoint; with one shared vertex, each
  // one's far edge (its two own corners) against the other's three sides.
  auto edge_near = [&](const Vec3& p, const Vec3& q, const Vec3* (&t)[3]) {
    for (int k = 0; k < 3; ++k) {
      const Vec3* S[2] = {&p, &q};
      const Vec3* E[2] = {t[k], t[(k + 1) % 3]};
      if (!boxes_apart(S, E, d) && segment_distance2(p, q, *E[0], *E[1]) <= d2) return true;
    }
    return false;
  };
  if (na == 3) {
    for (int k = 0; k < 3; ++k)
      if (edge_near(ta[k], ta[(k + 1) % 3], B)) return true;
    return false;
  }
  return edge_near(ta[own_a[0]], ta[own_a[1]], B) || edge_near(tb[own_b[0]], tb[own_b[1]], A);
}

bool triangle_too_thin(const Vec3& a, const Vec3& b, const Vec3& c, double d) {
  return triangle_degenerate(a, b, c) || triangle_altitude(a, b, c) < d;
}

bool triangles_clash(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3],
                     double d) {
  return triangles_intersect(ta, ia, tb, ib) || triangles_within(ta, ia, tb, ib, d);
}

}  // namespace voxpress::detail
