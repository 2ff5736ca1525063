#include "predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace voxpress::detail {
namespace {

constexpr double kEps = 1.1102230246251565e-16;  // 2^-53
constexpr double kO3dBound = (7.0 + 56.0 * kEps) * kEps;
constexpr double kCcwBound = (3.0 + 16.0 * kEps) * kEps;

// ---- Exact expansion arithmetic (Shewchuk 1997, Sections 2.4-2.7).
// An expansion is a sum of non-overlapping doubles stored in increasing
// magnitude; its sign is the sign of its last (largest) component. two_sum
// and two_product (via fused multiply-add) are error-free transformations,
// so every quantity below is exact. Requires IEEE round-to-nearest-even.

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

class Expansion {
 public:
  static constexpr int kCap = 256;
  Expansion() {}  // components left uninitialised on purpose: only [0, n_) is live
  Expansion(const Expansion& o) : n_(o.n_) { std::copy(o.c_, o.c_ + o.n_, c_); }
  Expansion& operator=(const Expansion& o) {
    n_ = o.n_;
    std::copy(o.c_, o.c_ + o.n_, c_);
    return *this;
  }
  explicit Expansion(double a) {
    if (a != 0) c_[n_++] = a;
  }
  static Expansion diff(double a, double b) {  // exact a - b
    Expansion e;
    double x, y;
    two_sum(a, -b, x, y);
    if (y != 0) e.c_[e.n_++] = y;
    if (x != 0) e.c_[e.n_++] = x;
    return e;
  }
  int sign() const { return n_ == 0 ? 0 : (c_[n_ - 1] > 0 ? 1 : -1); }

  // h = e + f (fast_expansion_sum_zeroelim).
  friend Expansion operator+(const Expansion& e, const Expansion& f) {
    if (e.n_ == 0) return f;
    if (f.n_ == 0) return e;
    Expansion h;
    int ei = 0, fi = 0;
    auto take = [&]() {
      if (fi >= f.n_ || (ei < e.n_ && std::abs(e.c_[ei]) < std::abs(f.c_[fi]))) return e.c_[ei++];
      return f.c_[fi++];
    };
    double q = take();
    while (ei < e.n_ || fi < f.n_) {
      double x, y;
      two_sum(q, take(), x, y);
      q = x;
      if (y != 0) h.push(y);
    }
    if (q != 0 || h.n_ == 0) h.push(q);
    if (h.n_ == 1 && h.c_[0] == 0) h.n_ = 0;
    return h;
  }
  friend Expansion operator-(const Expansion& e, const Expansion& f) { return e + f.negated(); }

  // h = e * b (scale_expansion_zeroelim).
  Expansion scaled(double b) const {
    Expansion h;
    if (n_ == 0 || b == 0) return h;
    double q, hh;
    two_product(c_[0], b, q, hh);
    if (hh != 0) h.push(hh);
    for (int i = 1; i < n_; ++i) {
      double p1, p0, sum, err;
      two_product(c_[i], b, p1, p0);
      two_sum(q, p0, sum, err);
      if (err != 0) h.push(err);
      two_sum(p1, sum, q, err);
      if (err != 0) h.push(err);
    }
    if (q != 0 || h.n_ == 0) h.push(q);
    if (h.n_ == 1 && h.c_[0] == 0) h.n_ = 0;
    return h;
  }
  friend Expansion operator*(const Expansion& e, const Expansion& f) {
    Expansion h;
    for (int i = 0; i < f.n_; ++i) h = h + e.scaled(f.c_[i]);
    return h;
  }

 private:
  Expansion negated() const {
    Expansion h = *this;
    for (int i = 0; i < n_; ++i) h.c_[i] = -h.c_[i];
    return h;
  }
  void push(double v) {
    if (n_ >= kCap) throw std::logic_error("expansion capacity exceeded");
    c_[n_++] = v;
  }
  double c_[kCap];
  int n_ = 0;
};

int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // ((b - a) x (c - a)) . (d - a), every difference and product exact.
  const Expansion bax = Expansion::diff(b.x(), a.x()), bay = Expansion::diff(b.y(), a.y()),
                  baz = Expansion::diff(b.z(), a.z());
  const Expansion cax = Expansion::diff(c.x(), a.x()), cay = Expansion::diff(c.y(), a.y()),
                  caz = Expansion::diff(c.z(), a.z());
  const Expansion dax = Expansion::diff(d.x(), a.x()), day = Expansion::diff(d.y(), a.y()),
                  daz = Expansion::diff(d.z(), a.z());
  const Expansion det =
      (bay * caz - baz * cay) * dax + (baz * cax - bax * caz) * day + (bax * cay - bay * cax) * daz;
  return det.sign();
}

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  const Expansion det = Expansion::diff(bx, ax) * Expansion::diff(cy, ay) - Expansion::diff(by, ay) * Expansion::diff(cx, ax);
  return det.sign();
}

}  // namespace

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Shewchuk's orient3d computes det[a-d; b-d; c-d], which is the negation of ours.
  const double adx = a.x() - d.x(), bdx = b.x() - d.x(), cdx = c.x() - d.x();
  const double ady = a.y() - d.y(), bdy = b.y() - d.y(), cdy = c.y() - d.y();
  const double adz = a.z() - d.z(), bdz = b.z() - d.z(), cdz = c.z() - d.z();
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                           (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                           (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  const double bound = kO3dBound * permanent;
  if (std::isfinite(det) && std::isfinite(bound) && permanent > 1e-280) {
    if (det > bound) return -1;
    if (-det > bound) return 1;
  }
  return orient3d_exact(a, b, c, d);
}

int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double detleft = (ax - cx) * (by - cy);
  const double detright = (ay - cy) * (bx - cx);
  const double det = detleft - detright;
  const double bound = kCcwBound * (std::abs(detleft) + std::abs(detright));
  if (std::isfinite(det) && std::isfinite(bound) && bound > 1e-280) {
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

int orient2d_drop(const Vec3& a, const Vec3& b, const Vec3& c, int drop) {
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  return orient2d(a[u], a[v], b[u], b[v], c[u], c[v]);
}

int tetrahedron_side(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, int o) {
  bool boundary = false;
  for (int k = 0; k < 4; ++k) {
    const int s = orient3d(k == 0 ? z : a, k == 1 ? z : b, k == 2 ? z : c, k == 3 ? z : d);
    if (s == -o) return -1;
    boundary |= s == 0;
  }
  return boundary ? 0 : 1;
}

bool triangle_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
  return orient2d_drop(a, b, c, 0) == 0 && orient2d_drop(a, b, c, 1) == 0 && orient2d_drop(a, b, c, 2) == 0;
}

namespace {

// A projection in which triangle (a, b, c) is not degenerate.
int good_drop(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return std::abs(n[i]) > std::abs(n[j]); });
  for (int d : order)
    if (orient2d_drop(a, b, c, d) != 0) return d;
  return -1;
}

struct P2 {
  double x, y;
};
P2 project(const Vec3& p, int drop) { return {p[(drop + 1) % 3], p[(drop + 2) % 3]}; }
int o2(const P2& a, const P2& b, const P2& c) { return orient2d(a.x, a.y, b.x, b.y, c.x, c.y); }

bool on_segment_2d(const P2& a, const P2& b, const P2& p) {
  // p collinear with a, b: is it within the closed segment?
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool segments_intersect_2d(const P2& p, const P2& q, const P2& a, const P2& b) {
  const int d1 = o2(a, b, p), d2 = o2(a, b, q), d3 = o2(p, q, a), d4 = o2(p, q, b);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  if (d1 == 0 && on_segment_2d(a, b, p)) return true;
  if (d2 == 0 && on_segment_2d(a, b, q)) return true;
  if (d3 == 0 && on_segment_2d(p, q, a)) return true;
  if (d4 == 0 && on_segment_2d(p, q, b)) return true;
  return false;
}

bool point_in_triangle_2d(const P2& p, const P2& a, const P2& b, const P2& c) {
  const int s = o2(a, b, c);
  const int s1 = o2(a, b, p), s2 = o2(b, c, p), s3 = o2(c, a, p);
  return s1 * s >= 0 && s2 * s >= 0 && s3 * s >= 0;
}

}  // namespace

bool segment_intersects_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Cheap rejection on bounding boxes.
  for (int k = 0; k < 3; ++k) {
    const double smin = std::min(p[k], q[k]), smax = std::max(p[k], q[k]);
    const double tmin = std::min({a[k], b[k], c[k]}), tmax = std::max({a[k], b[k], c[k]});
    if (smax < tmin || smin > tmax) return false;
  }
  const int sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
  if (sp == sq && sp != 0) return false;
  if (sp == 0 && sq == 0) {
    const int drop = good_drop(a, b, c);
    const P2 P = project(p, drop), Q = project(q, drop), A = project(a, drop), B = project(b, drop),
             C = project(c, drop);
    if (point_in_triangle_2d(P, A, B, C) || point_in_triangle_2d(Q, A, B, C)) return true;
    return segments_intersect_2d(P, Q, A, B) || segments_intersect_2d(P, Q, B, C) || segments_intersect_2d(P, Q, C, A);
  }
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

bool triangles_intersect(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3]) {
  int shared = 0;
  int sa[3] = {-1, -1, -1};  // for each corner of a: matching corner of b
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (ia[i] == ib[j]) {
        sa[i] = j;
        ++shared;
      }
  if (shared == 3) return true;  // duplicate face
  if (shared == 2) {
    int a_free = 0;
    while (sa[a_free] >= 0) ++a_free;
    int b_free = 0;
    while (b_free == sa[0] || b_free == sa[1] || b_free == sa[2]) ++b_free;
    const Vec3& u = ta[(a_free + 1) % 3];
    const Vec3& v = ta[(a_free + 2) % 3];
    if (orient3d(u, v, ta[a_free], tb[b_free]) != 0) return false;
    const int drop = good_drop(u, v, ta[a_free]);
    return orient2d_drop(u, v, ta[a_free], drop) * orient2d_drop(u, v, tb[b_free], drop) > 0;
  }
  if (shared == 1) {
    int a_shared = 0;
    while (sa[a_shared] < 0) ++a_shared;
    const int b_shared = sa[a_shared];
    const Vec3& a1 = ta[(a_shared + 1) % 3];
    const Vec3& a2 = ta[(a_shared + 2) % 3];
    const Vec3& b1 = tb[(b_shared + 1) % 3];
    const Vec3& b2 = tb[(b_shared + 2) % 3];
    return segment_intersects_triangle(a1, a2, tb[0], tb[1], tb[2]) ||
           segment_intersects_triangle(b1, b2, ta[0], ta[1], ta[2]);
  }
  // Disjoint vertex sets: reject when the bounding boxes are apart or one
  // triangle lies strictly on one side of the other's plane (Moller's
  // early-out), else test every edge.
  for (int k = 0; k < 3; ++k)
    if (std::max({ta[0][k], ta[1][k], ta[2][k]}) < std::min({tb[0][k], tb[1][k], tb[2][k]}) ||
        std::max({tb[0][k], tb[1][k], tb[2][k]}) < std::min({ta[0][k], ta[1][k], ta[2][k]}))
      return false;
  auto one_side = [](const Vec3(&t)[3], const Vec3(&o)[3]) {
    const int s0 = orient3d(t[0], t[1], t[2], o[0]);
    const int s1 = orient3d(t[0], t[1], t[2], o[1]);
    const int s2 = orient3d(t[0], t[1], t[2], o[2]);
    return s0 == s1 && s1 == s2 && s0 != 0;
  };
  if (one_side(ta, tb) || one_side(tb, ta)) return false;
  for (int i = 0; i < 3; ++i) {
    if (segment_intersects_triangle(ta[i], ta[(i + 1) % 3], tb[0], tb[1], tb[2])) return true;
    if (segment_intersects_triangle(tb[i], tb[(i + 1) % 3], ta[0], ta[1], ta[2])) return true;
  }
  return false;
}

}  // namespace voxpress::detail
