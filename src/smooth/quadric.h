// Private helper of the flats' tangent test, the crease fit and sharpen's
// curved-side planes: a quadric height field fitted to surface points by
// least squares, its surface point and normal over a point, and where a
// stick leaves the solid it bounds.
#pragma once

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <vector>

#include "surface_graph.h"

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

  // False with fewer than 12 points or a rank-deficient design (a curve).
  bool fit(const std::vector<Vec3>& pts, const Vec3& outward) {
    if (pts.size() < 12) return false;
    const Pca p = pca(pts);
    set_frame(p.mean, p.normal.dot(outward) < 0 ? Vec3(-p.normal) : p.normal);
    Eigen::MatrixXd A(pts.size(), 6);
    Eigen::VectorXd z(pts.size());
    for (size_t k = 0; k < pts.size(); ++k) {
      const Vec3 d = pts[k] - m;
      const double a = u.dot(d), b = w.dot(d);
      A.row(Eigen::Index(k)) << a * a, a * b, b * b, a, b, 1;
      z(Eigen::Index(k)) = n.dot(d);
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < 6) return false;
    q = qr.solve(z);
    residual = std::sqrt((A * q - z).squaredNorm() / double(pts.size()));
    return true;
  }

  // Refit (after fit) so that the surface also separates each stick's
  // samples: ins[k] at least eps below it along n, outs[k] at least eps
  // above. The pressed points near a rounded crease are biased (pressed
  // in, then overshooting outwards for a few cells), and the sticks are
  // not: each violated side joins the least squares as a target eps past
  // its sample with `weight` (a squared-hinge penalty), once violated kept
  // (so the active set only grows and the loop ends), at most `iters`
  // solves. The residual is then the points' RMS distance to the refit.
  void stab(const std::vector<Vec3>& pts, const std::vector<Vec3>& ins, const std::vector<Vec3>& outs, double eps,
            double weight, int iters) {
    auto row = [&](const Vec3& p, Eigen::Matrix<double, 6, 1>& r) {
      const Vec3 d = p - m;
      const double a = u.dot(d), b = w.dot(d);
      r << a * a, a * b, b * b, a, b, 1;
      return n.dot(d);
    };
    Eigen::Matrix<double, 6, 6> N0 = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> r0 = Eigen::Matrix<double, 6, 1>::Zero(), r;
    for (const Vec3& p : pts) {
      const double z = row(p, r);
      N0 += r * r.transpose();
      r0 += z * r;
    }
    // Each sample's design row and height, once (2k: inside, 2k + 1: outside).
    std::vector<Eigen::Matrix<double, 6, 1>> rs(2 * ins.size());
    std::vector<double> zs(2 * ins.size());
    for (size_t k = 0; k < ins.size(); ++k) {
      zs[2 * k] = row(ins[k], rs[2 * k]);
      zs[2 * k + 1] = row(outs[k], rs[2 * k + 1]);
    }
    std::vector<uint8_t> active(2 * ins.size(), 0);
    for (int it = 0; it < iters; ++it) {
      bool changed = false;
      for (size_t k = 0; k < ins.size(); ++k) {
        if (!active[2 * k] && zs[2 * k] - rs[2 * k].dot(q) > -eps) active[2 * k] = 1, changed = true;
        if (!active[2 * k + 1] && zs[2 * k + 1] - rs[2 * k + 1].dot(q) < eps) active[2 * k + 1] = 1, changed = true;
      }
      if (!changed) break;
      Eigen::Matrix<double, 6, 6> N = N0;
      Eigen::Matrix<double, 6, 1> rhs = r0;
      for (size_t k = 0; k < 2 * ins.size(); ++k) {
        if (!active[k]) continue;
        const double z = zs[k] + (k % 2 ? -eps : eps);
        N += weight * rs[k] * rs[k].transpose();
        rhs += weight * z * rs[k];
      }
      q = N.ldlt().solve(rhs);
    }
    double ss = 0;
    for (const Vec3& p : pts) {
      const double z = row(p, r);
      ss += (z - r.dot(q)) * (z - r.dot(q));
    }
    residual = std::sqrt(ss / double(pts.size()));
  }

  // The surface point above (or below) p along n.
  Vec3 foot(const Vec3& p) const {
    const Vec3 d = p - m;
    const double a = u.dot(d), b = w.dot(d);
    const double h = q(0) * a * a + q(1) * a * b + q(2) * b * b + q(3) * a + q(4) * b + q(5);
    return p + (h - n.dot(d)) * n;
  }

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

}  // namespace voxpress::detail
