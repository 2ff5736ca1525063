// The clearance distances (core/clearance.h) against dense sampling, and the
// float32 margin against real rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/clearance.h"
#include "test_util.h"

namespace voxpress {
namespace {

Vec3 random_point(test::Rng& rng, double scale) {
  return Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
}

// Squared distance from p to the triangle by sampling its barycentric grid
// (an upper bound within h of the true distance).
double sampled_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int steps) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= steps; ++i)
    for (int j = 0; i + j <= steps; ++j) {
      const double u = double(i) / steps, v = double(j) / steps;
      best = std::min(best, (p - (a + u * (b - a) + v * (c - a))).squaredNorm());
    }
  return best;
}

TEST(Clearance, PointTriangleDistanceMatchesSampling) {
  test::Rng rng(5);
  for (int k = 0; k < 300; ++k) {
    const Vec3 a = random_point(rng, 2), b = random_point(rng, 2), c = random_point(rng, 2), p = random_point(rng, 3);
    const double exact = std::sqrt(detail::point_triangle_distance2(p, a, b, c));
    const double sampled = std::sqrt(sampled_distance2(p, a, b, c, 200));
    ASSERT_LE(exact, sampled + 1e-12);
    ASSERT_GE(exact, sampled - 0.03);  // the grid's spacing bounds the sampling error
  }
  // A degenerate triangle (three collinear points) is its segment.
  EXPECT_NEAR(detail::point_triangle_distance2(Vec3(0.5, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)), 1, 1e-12);
}

TEST(Clearance, SegmentDistanceMatchesSampling) {
  test::Rng rng(6);
  for (int k = 0; k < 300; ++k) {
    const Vec3 p0 = random_point(rng, 2), p1 = random_point(rng, 2), q0 = random_point(rng, 2), q1 = random_point(rng, 2);
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 400; ++i)
      for (int j = 0; j <= 400; j += 1) {
        if ((i + j) % 4) continue;
        sampled = std::min(sampled, ((p0 + (p1 - p0) * (i / 400.0)) - (q0 + (q1 - q0) * (j / 400.0))).norm());
      }
    const double exact = std::sqrt(detail::segment_distance2(p0, p1, q0, q1));
    ASSERT_LE(exact, sampled + 1e-12);
    ASSERT_GE(exact, sampled - 0.02);
  }
  // Parallel and point-like segments.
  EXPECT_NEAR(detail::segment_distance2(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 2, 0), Vec3(3, 2, 0)), 4, 1e-12);
  EXPECT_NEAR(detail::segment_distance2(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0)), 1, 1e-12);
}

TEST(Clearance, TrianglePairsWithinByWhatTheyShare) {
  const uint32_t ia[3] = {0, 1, 2};
  const Vec3 ta[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  // Disjoint, 0.1 above: within 0.11, not within 0.09.
  const uint32_t ib[3] = {3, 4, 5};
  const Vec3 tb[3] = {Vec3(0.2, 0.2, 0.1), Vec3(0.6, 0.2, 0.1), Vec3(0.2, 0.6, 0.1)};
  EXPECT_TRUE(detail::triangles_within(ta, ia, tb, ib, 0.11));
  EXPECT_FALSE(detail::triangles_within(ta, ia, tb, ib, 0.09));
  // A shared edge folded nearly flat onto the first: the apex 1e-3 above it.
  const uint32_t ic[3] = {1, 0, 6};
  const Vec3 fold[3] = {Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(0.3, 0.3, 1e-3)};
  EXPECT_TRUE(detail::triangles_within(ta, ia, fold, ic, 2e-3));
  EXPECT_FALSE(detail::triangles_within(ta, ia, fold, ic, 5e-4));
  // The same edge opened flat (the apex on the other side): apart.
  const Vec3 open[3] = {Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(0.3, -0.3, 0)};
  EXPECT_FALSE(detail::triangles_within(ta, ia, open, ic, 0.1));
  // One shared vertex, the other's far edge passing 1e-3 over the first.
  const uint32_t id[3] = {0, 7, 8};
  const Vec3 fan[3] = {Vec3(0, 0, 0), Vec3(0.5, 0.4, 1e-3), Vec3(0.4, 0.5, 1e-3)};
  EXPECT_TRUE(detail::triangles_within(ta, ia, fan, id, 2e-3));
  EXPECT_FALSE(detail::triangles_within(ta, ia, fan, id, 1e-4));
}

TEST(Clearance, Float32MarginCoversTheRounding) {
  Lattice l;
  l.dims = {300, 200, 100};
  l.spacing = Vec3(0.4, 0.8, 2.5);
  l.origin = Vec3(-1234.5, 876.25, 4321);
  l.direction = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const double delta = detail::float32_clearance(l);
  test::Rng rng(8);
  double worst = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 ijk(rng.uniform() * 301 - 1, rng.uniform() * 201 - 1, rng.uniform() * 101 - 1);
    const Vec3 p = l.to_physical(ijk);
    worst = std::max(worst, (l.to_index(p.cast<float>().cast<double>()) - ijk).norm());
  }
  EXPECT_GT(worst, 0);
  EXPECT_LE(4 * worst, delta * 1.0001) << "the margin is at least 4x any rounding seen";
  EXPECT_LT(delta, 0.01) << "and far below the pressing margin of 0.01 cell";
}

// Per axis (issue 73): an anisotropic lattice's rounding is bounded on each
// axis by its own coordinates, never above the whole-lattice bound, and
// still at least every rounding seen.
TEST(Clearance, Float32RoundingPerAxisCoversTheRounding) {
  test::Rng rng(9);
  for (int t = 0; t < 4; ++t) {
    Lattice l;
    l.dims = {16, 16, 16};
    l.spacing = Vec3(0.01, 1, 100);
    if (t >= 2) l.origin = Vec3(3, -40, 2000 * t);
    if (t % 2) l.direction = Eigen::AngleAxisd(0.3 * t, Vec3(1, -2, 3).normalized()).toRotationMatrix();
    const double rounding = detail::float32_rounding(l);
    EXPECT_LE(rounding, detail::float32_clearance(l) / 4 * 1.0000001);
    double worst = 0;
    for (int k = 0; k < 20000; ++k) {
      const Vec3 ijk(rng.uniform() * 17 - 1, rng.uniform() * 17 - 1, rng.uniform() * 17 - 1);
      worst = std::max(worst, (l.to_index(l.to_physical(ijk).cast<float>().cast<double>()) - ijk).norm());
    }
    EXPECT_GT(worst, 0);
    EXPECT_LE(worst, rounding) << t;
    if (t == 0) {
      EXPECT_LT(4 * rounding, 0.01) << "room enough for the pressing margin";
      EXPECT_GT(detail::float32_clearance(l), 0.01) << "which the whole-lattice bound refused";
    }
  }
}

}  // namespace
}  // namespace voxpress
