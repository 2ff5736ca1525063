#include "row_rays.h"

#include <algorithm>
#include <cmath>

#include "../core/predicates.h"

namespace voxpress::detail {
namespace {

// Perturbed 2D orientation of q = (qy + e, qz + e^2) against edge a -> b (yz).
int perturbed_orient(const Vec3& a, const Vec3& b, double qy, double qz) {
  const int s = orient2d(a.y(), a.z(), b.y(), b.z(), qy, qz);
  if (s != 0) return s;
  if (a.z() != b.z()) return a.z() > b.z() ? 1 : -1;  // d/d(qy) = a.z - b.z
  if (a.y() != b.y()) return b.y() > a.y() ? 1 : -1;  // d/d(qz) = b.y - a.y
  return 0;
}

// Does the closed yz-projection of triangle (a, b, c) contain (qy, qz)?
bool touches_row(const Vec3& a, const Vec3& b, const Vec3& c, int sigma, double qy, double qz) {
  const int s1 = orient2d(a.y(), a.z(), b.y(), b.z(), qy, qz);
  const int s2 = orient2d(b.y(), b.z(), c.y(), c.z(), qy, qz);
  const int s3 = orient2d(c.y(), c.z(), a.y(), a.z(), qy, qz);
  if (sigma != 0) return s1 * sigma >= 0 && s2 * sigma >= 0 && s3 * sigma >= 0;
  // Degenerate projection (a segment or a point): (qy, qz) must be collinear
  // with it and within its extent.
  if (s1 != 0 || s2 != 0 || s3 != 0) return false;
  const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
  const double zlo = std::min({a.z(), b.z(), c.z()}), zhi = std::max({a.z(), b.z(), c.z()});
  return ylo <= qy && qy <= yhi && zlo <= qz && qz <= zhi;
}

// i coordinate where the row line (j, k) meets the plane of (a, b, c); NaN if parallel.
double plane_crossing(const Vec3& a, const Vec3& b, const Vec3& c, double j, double k) {
  const Vec3 n = (b - a).cross(c - a);
  return a.x() - (n.y() * (j - a.y()) + n.z() * (k - a.z())) / n.x();
}

}  // namespace

RowRays::RowRays(std::vector<Vec3> index_vertices, const std::vector<Triangle>& triangles, std::array<int64_t, 3> lo,
                 std::array<int64_t, 3> hi, bool mirrored)
    : v_(std::move(index_vertices)), t_(triangles), lo_(lo), hi_(hi), mirrored_(mirrored) {
  rows_y_ = hi_[1] - lo_[1] + 1;
  rows_z_ = hi_[2] - lo_[2] + 1;
  start_.assign(size_t(std::max<int64_t>(rows_y_ * rows_z_, 0)) + 1, 0);
  auto for_each_hit = [&](auto&& emit) {
    for (size_t f = 0; f < t_.size(); ++f) {
      const Triangle& t = t_[f];
      const Vec3 &a = v_[t[0]], &b = v_[t[1]], &c = v_[t[2]];
      const int sigma = orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z());
      const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
      const double zlo = std::min({a.z(), b.z(), c.z()}), zhi = std::max({a.z(), b.z(), c.z()});
      if (!(yhi >= double(lo_[1]) && ylo <= double(hi_[1]) && zhi >= double(lo_[2]) && zlo <= double(hi_[2])))
        continue;
      const int64_t ja = std::max<int64_t>(lo_[1], int64_t(std::ceil(ylo)));
      const int64_t jb = std::min<int64_t>(hi_[1], int64_t(std::floor(yhi)));
      const int64_t ka = std::max<int64_t>(lo_[2], int64_t(std::ceil(zlo)));
      const int64_t kb = std::min<int64_t>(hi_[2], int64_t(std::floor(zhi)));
      for (int64_t k = ka; k <= kb; ++k)
        for (int64_t j = ja; j <= jb; ++j) {
          const double qy = double(j), qz = double(k);
          if (sigma != 0) {
            const int s1 = perturbed_orient(a, b, qy, qz), s2 = perturbed_orient(b, c, qy, qz),
                      s3 = perturbed_orient(c, a, qy, qz);
            if (s1 == sigma && s2 == sigma && s3 == sigma) {
              emit(row_of(j, k), Hit{uint32_t(f), sigma, true});
              continue;
            }
          }
          if (touches_row(a, b, c, sigma, qy, qz)) emit(row_of(j, k), Hit{uint32_t(f), sigma, false});
        }
    }
  };
  for_each_hit([&](size_t row, Hit) { ++start_[row + 1]; });
  for (size_t r = 1; r < start_.size(); ++r) start_[r] += start_[r - 1];
  hits_.resize(start_.back());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for_each_hit([&](size_t row, Hit h) { hits_[fill[row]++] = h; });
}

void RowRays::classify(int64_t j, int64_t k, std::vector<int>& winding, std::vector<uint8_t>& odd,
                       std::vector<int64_t>& on_surface) const {
  const int64_t i0 = lo_[0], i1 = hi_[0];
  const size_t n = size_t(i1 - i0 + 1);
  winding.assign(n + 1, 0);
  odd.assign(n + 1, 0);
  on_surface.clear();
  const size_t row = row_of(j, k);
  const double dj = double(j), dk = double(k);
  for (uint32_t h = start_[row]; h < start_[row + 1]; ++h) {
    const Triangle& t = t_[hits_[h].tri];
    const Vec3 &a = v_[t[0]], &b = v_[t[1]], &c = v_[t[2]];
    const int sigma = hits_[h].sigma;
    if (!hits_[h].crossing) {
      // Touching only: report the samples lying exactly on the triangle.
      double lo = std::min({a.x(), b.x(), c.x()}), hi = std::max({a.x(), b.x(), c.x()});
      if (sigma != 0) {  // a single point of the row line lies on the plane
        const double xc = plane_crossing(a, b, c, dj, dk);
        if (std::isfinite(xc)) lo = hi = xc;
      }
      const int64_t from = std::max<int64_t>(i0, int64_t(std::floor(lo)) - 1);
      const int64_t to = std::min<int64_t>(i1, int64_t(std::ceil(hi)) + 1);
      for (int64_t i = from; i <= to; ++i) {
        const Vec3 p{double(i), dj, dk};
        if (segment_intersects_triangle(p, p, a, b, c)) on_surface.push_back(i);
      }
      continue;
    }
    // s(i) < 0: sample i before the crossing; > 0 after; 0 on the triangle.
    auto s = [&](int64_t i) { return orient3d(a, b, c, Vec3{double(i), dj, dk}) * sigma; };
    double xc = plane_crossing(a, b, c, dj, dk);
    if (!std::isfinite(xc)) xc = 0.5 * double(i0 + i1);
    int64_t before = std::clamp<int64_t>(int64_t(std::floor(xc)), i0 - 1, i1);
    while (before + 1 <= i1 && s(before + 1) < 0) ++before;
    while (before >= i0 && s(before) >= 0) --before;
    if (before + 1 <= i1 && s(before + 1) == 0) on_surface.push_back(before + 1);
    // Entering the solid (outward normal towards -i) raises the winding number.
    const int delta = (sigma < 0) != mirrored_ ? 1 : -1;
    winding[size_t(before + 1 - i0)] += delta;
    odd[size_t(before + 1 - i0)] ^= 1;
  }
  // Prefix sums turn the changes into per-sample values.
  for (size_t i = 1; i < n; ++i) {
    winding[i] += winding[i - 1];
    odd[i] ^= odd[i - 1];
  }
  winding.resize(n);
  odd.resize(n);
  std::sort(on_surface.begin(), on_surface.end());
  on_surface.erase(std::unique(on_surface.begin(), on_surface.end()), on_surface.end());
}

}  // namespace voxpress::detail
