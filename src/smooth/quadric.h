// Private helper of the flats' tangent test, the crease fit and sharpen's
// curved-side planes: a quadric height field fitted to surface points by
// least squares, its surface point and normal over a point, and where a
// stick leaves the solid it bounds.
#pragma once

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "surface_graph.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress::detail {

constexpr int kStabSolves = 20;  // Quadric::stab's least-squares solves (its callers' `iters`)

// z = h(a, b) = q0 a^2 + q1 a b + q2 b^2 + q3 a + q4 b + q5 over the frame
// (m; u, w, n) of the points' PCA, n outward (the solid is below: z < h).
struct Quadric {
  Vec3 m, u, w, n;
  Eigen::Matrix<double, 6, 1> q;
  double residual = 0;  // RMS distance along n of the points to the fit

  // The frame from its origin and unit normal (u and w follow from n, so a
  // quadric is stored as m, n and q).
  void set_frame(const Vec3& origin, const Vec3& normal) {
    m = origin;
    n = normal;
    u = n.cross(std::abs(n.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)).normalized();
    w = n.cross(u);
  }

  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  Mat6 normal_matrix;  // the fit's normal equations (sum r r^T, sum z r), for stab
  Vec6 normal_rhs;
  double heights_squared = 0;  // sum z^2 of the fit's points

  // The design row of p in this frame, and its height along n.
  double row(const Vec3& p, Vec6& r) const {
    const Vec3 d = p - m;
    const double a = u.dot(d), b = w.dot(d);
    r << a * a, a * b, b * b, a, b, 1;
    return n.dot(d);
  }

  // Least squares by the 6x6 normal equations (a patch's heights are within
  // a few cells of its PCA plane, so squaring the condition number costs
  // nothing measurable: the same fits as a QR of the point rows to ~1e-13).
  // False with fewer than 12 points or a rank-deficient design (a curve:
  // an LDLT pivot below 1e-12 of the largest).
  bool fit(const std::vector<Vec3>& pts, const Vec3& outward);  // smooth/quadric_fit.cpp

  // RMS distance along n of the fit's points to the surface, from the
  // normal equations: sum (z - r.q)^2 = z.z - 2 q.(sum z r) + q.N q (the
  // heights are within a few cells, so the cancellation costs ~3 of 16
  // digits; the callers compare residuals at 0.02-0.1 cell).
  double rms(size_t count) const {
    const double ss = heights_squared - 2 * q.dot(normal_rhs) + q.dot(normal_matrix * q);
    return std::sqrt(std::max(ss, 0.0) / double(count));
  }

  // Refit (after fit, on the same points) so that the surface also
  // separates each stick's samples: ins[k] at least eps below it along n,
  // outs[k] at least eps above. The pressed points near a rounded crease
  // are biased (pressed in, then overshooting outwards for a few cells),
  // and the sticks are not: each violated side joins the least squares as a
  // target eps past its sample with `weight` (a squared-hinge penalty), once
  // violated kept (so the active set only grows and the loop ends), at most
  // `iters` solves. The residual is then the points' RMS distance to the
  // refit.
  void stab(const std::vector<Vec3>& pts, const std::vector<Vec3>& ins, const std::vector<Vec3>& outs, double eps,
            double weight, int iters);  // smooth/quadric_fit.cpp

  // Height of p above the surface along n: negative inside the solid.
  double height_above(const Vec3& p) const {
    const Vec3 d = p - m;
    const double a = u.dot(d), b = w.dot(d);
    return n.dot(d) - (q(0) * a * a + q(1) * a * b + q(2) * b * b + q(3) * a + q(4) * b + q(5));
  }

  // The surface point above (or below) p along n.
  Vec3 foot(const Vec3& p) const { return p - height_above(p) * n; }

  // Unit outward normal of the surface above (or below) point p.
  Vec3 normal_at(const Vec3& p) const {
    const Vec3 d = p - m;
    const double a = u.dot(d), b = w.dot(d);
    const double ha = 2 * q(0) * a + q(1) * b + q(3), hb = q(1) * a + 2 * q(2) * b + q(4);
    return (n - ha * u - hb * w).normalized();
  }

  // Where the segment from `in` (t = 0) to `out` (t = 1) leaves the solid:
  // g(t) = n . (p - m) - h(a, b) changes sign from - to +. The root nearest
  // `near` in [lo, hi]; NaN if none.
  double exit(const Vec3& in, const Vec3& out, double near, double lo, double hi) const {
    const Vec3 e = out - in, d = in - m;
    // a(t) = a0 + a1 t, b(t) = b0 + b1 t, z(t) = z0 + z1 t; g = A t^2 + B t + C.
    const double a0 = u.dot(d), a1 = u.dot(e), b0 = w.dot(d), b1 = w.dot(e), z0 = n.dot(d), z1 = n.dot(e);
    const double A = -(q(0) * a1 * a1 + q(1) * a1 * b1 + q(2) * b1 * b1);
    const double B = z1 - (2 * q(0) * a0 * a1 + q(1) * (a0 * b1 + a1 * b0) + 2 * q(2) * b0 * b1 + q(3) * a1 + q(4) * b1);
    const double C = z0 - (q(0) * a0 * a0 + q(1) * a0 * b0 + q(2) * b0 * b0 + q(3) * a0 + q(4) * b0 + q(5));
    double roots[2];
    int k = 0;
    if (std::abs(A) < 1e-12 * (std::abs(B) + std::abs(C) + 1e-300)) {
      if (B != 0) roots[k++] = -C / B;
    } else {
      const double disc = B * B - 4 * A * C;
      if (disc >= 0) {
        const double sq = std::sqrt(disc), r = -0.5 * (B + std::copysign(sq, B));
        roots[k++] = r / A;
        if (r != 0) roots[k++] = C / r;
      }
    }
    double best = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < k; ++i) {
      const double t = roots[i];
      if (!(t >= lo && t <= hi) || 2 * A * t + B <= 0) continue;  // inside to outside only
      if (std::isnan(best) || std::abs(t - near) < std::abs(best - near)) best = t;
    }
    return best;
  }
};

// fit_local_quadrics on a surface whose adjacency is built once per run
// (smooth/pipeline.cpp); `graph` is read only when there is work.
QuadricFitStats fit_local_quadrics(StickSurface& surface, const std::vector<int32_t>& region,
                                   const std::vector<uint8_t>& junction, const QuadricFitOptions& options,
                                   const std::vector<uint8_t>* only, const Adjacency& graph);

}  // namespace voxpress::detail
