// Exact predicates: agree with exact integer arithmetic, including on
// degenerate and nearly degenerate inputs where plain doubles fail.
#include "../../src/core/predicates.h"
#include "test_util.h"

namespace voxpress {
namespace {

int sign128(__int128 v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

int orient3d_int(const std::array<int64_t, 3>& a, const std::array<int64_t, 3>& b, const std::array<int64_t, 3>& c,
                 const std::array<int64_t, 3>& d) {
  __int128 ba[3], ca[3], da[3];
  for (int k = 0; k < 3; ++k) {
    ba[k] = b[size_t(k)] - a[size_t(k)];
    ca[k] = c[size_t(k)] - a[size_t(k)];
    da[k] = d[size_t(k)] - a[size_t(k)];
  }
  const __int128 det = (ba[1] * ca[2] - ba[2] * ca[1]) * da[0] + (ba[2] * ca[0] - ba[0] * ca[2]) * da[1] +
                       (ba[0] * ca[1] - ba[1] * ca[0]) * da[2];
  return sign128(det);
}

Vec3 as_vec(const std::array<int64_t, 3>& p, double scale, double offset) {
  return Vec3(double(p[0]) * scale + offset, double(p[1]) * scale + offset, double(p[2]) * scale + offset);
}

TEST(Predicates, Orient3dMatchesIntegerArithmetic) {
  test::Rng rng(42);
  int degenerate = 0;
  for (int rep = 0; rep < 200000; ++rep) {
    std::array<std::array<int64_t, 3>, 4> p;
    const int64_t range = rep % 3 == 0 ? 4 : (rep % 3 == 1 ? (1 << 20) : (1 << 26));
    for (auto& q : p)
      for (auto& x : q) x = rng.range(-range, range);
    if (rep % 4 <= 1) {  // force coplanarity (and nudge by one unit for rep % 4 == 1): d = a + s (b - a) + t (c - a)
      const int64_t s = rng.range(-3, 3), t = rng.range(-3, 3);
      for (int k = 0; k < 3; ++k)
        p[3][size_t(k)] = p[0][size_t(k)] + s * (p[1][size_t(k)] - p[0][size_t(k)]) + t * (p[2][size_t(k)] - p[0][size_t(k)]);
      if (std::abs(p[3][0]) > (int64_t(1) << 50)) continue;
      if (rep % 4 == 1) p[3][size_t(rng.range(0, 2))] += rng.range(-1, 1);
    }
    const int expected = orient3d_int(p[0], p[1], p[2], p[3]);
    degenerate += expected == 0;
    // Power-of-two scaling keeps every value exact; the sign is invariant.
    const double scale = std::ldexp(1.0, int(rng.range(-40, 40)));
    const int got = detail::orient3d(as_vec(p[0], scale, 0), as_vec(p[1], scale, 0), as_vec(p[2], scale, 0),
                                     as_vec(p[3], scale, 0));
    ASSERT_EQ(got, expected) << "rep " << rep;
  }
  EXPECT_GT(degenerate, 10000);
}

TEST(Predicates, Orient3dNearlyDegenerateWhereDoublesFail) {
  // Large coplanar integer points nudged by one unit: the exact sign is
  // known from 128-bit integers, and plain double evaluation often gets it wrong.
  test::Rng rng(7);
  int naive_wrong = 0;
  for (int rep = 0; rep < 100000; ++rep) {
    std::array<std::array<int64_t, 3>, 4> p;
    for (int q = 0; q < 3; ++q)
      for (auto& x : p[size_t(q)]) x = rng.range(-(int64_t(1) << 24), int64_t(1) << 24);
    const int64_t s = rng.range(-5, 5), t = rng.range(-5, 5);
    for (int k = 0; k < 3; ++k)
      p[3][size_t(k)] = p[0][size_t(k)] + s * (p[1][size_t(k)] - p[0][size_t(k)]) + t * (p[2][size_t(k)] - p[0][size_t(k)]);
    if (rep % 2) p[3][size_t(rng.range(0, 2))] += rng.range(-1, 1);  // else exactly coplanar
    const int expected = orient3d_int(p[0], p[1], p[2], p[3]);
    const Vec3 a = as_vec(p[0], 1, 0), b = as_vec(p[1], 1, 0), c = as_vec(p[2], 1, 0), d = as_vec(p[3], 1, 0);
    ASSERT_EQ(detail::orient3d(a, b, c, d), expected) << "rep " << rep;
    const double naive = ((b - a).cross(c - a)).dot(d - a);
    naive_wrong += ((naive > 0) - (naive < 0)) != expected;
  }
  EXPECT_GT(naive_wrong, 0) << "the test should exercise inputs where doubles fail";
}

TEST(Predicates, Orient2dAndDegeneracy) {
  EXPECT_EQ(detail::orient2d(0, 0, 1, 0, 0, 1), 1);
  EXPECT_EQ(detail::orient2d(0, 0, 0, 1, 1, 0), -1);
  EXPECT_EQ(detail::orient2d(0.1, 0.1, 0.2, 0.2, 0.3, 0.3), detail::orient2d(1, 1, 2, 2, 3, 3));
  EXPECT_TRUE(detail::triangle_degenerate(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)));
  EXPECT_TRUE(detail::triangle_degenerate(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(2, 3, 2)));
  EXPECT_FALSE(detail::triangle_degenerate(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2.000001)));
}

TEST(Predicates, TriangleIntersectionCases) {
  const uint32_t ia[3] = {0, 1, 2};
  const Vec3 t0[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  // Disjoint indices, crossing.
  {
    const Vec3 t1[3] = {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(2, 2, 0)};
    const uint32_t ib[3] = {3, 4, 5};
    EXPECT_TRUE(detail::triangles_intersect(t0, ia, t1, ib));
  }
  // Disjoint indices, touching at a single point: still an intersection.
  {
    const Vec3 t1[3] = {Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 1, 0)};
    const uint32_t ib[3] = {3, 4, 5};
    EXPECT_TRUE(detail::triangles_intersect(t0, ia, t1, ib));
  }
  // Shared edge, fold-over (coplanar, same side): intersection.
  {
    const Vec3 t1[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.1, 0.1, 0)};
    const uint32_t ib[3] = {1, 2, 6};
    EXPECT_TRUE(detail::triangles_intersect(t0, ia, t1, ib));
  }
  // Shared edge, proper neighbour (coplanar, other side): fine.
  {
    const Vec3 t1[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
    const uint32_t ib[3] = {1, 2, 6};
    EXPECT_FALSE(detail::triangles_intersect(t0, ia, t1, ib));
  }
  // Shared vertex, fan neighbour: fine; shared vertex, piercing: intersection.
  {
    const Vec3 t1[3] = {Vec3(0, 0, 0), Vec3(0, -1, 0), Vec3(-1, 0, 0.5)};
    const uint32_t ib[3] = {0, 7, 8};
    EXPECT_FALSE(detail::triangles_intersect(t0, ia, t1, ib));
    const Vec3 t2[3] = {Vec3(0, 0, 0), Vec3(0.5, 0.3, -1), Vec3(0.3, 0.5, 1)};
    EXPECT_TRUE(detail::triangles_intersect(t0, ia, t2, ib));
  }
}

}  // namespace
}  // namespace voxpress
