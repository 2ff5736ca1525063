// The derived marching squares / cubes cases obey the face rule and are
// intersection-free, also when vertices move along their sticks.
#include <set>

#include "../../src/core/predicates.h"
#include "test_util.h"

namespace voxpress {
namespace {

Vec3 corner_pos(int c) { return Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1); }
Vec3 edge_pos(int e, double t) {
  Vec3 p = corner_pos(cube_edge_corner(e, 0));
  p[cube_edge_axis(e)] = t;
  return p;
}

TEST(SquareCases, FaceRuleSeparatesDiagonalInsideCorners) {
  EXPECT_EQ(square_case(0).count, 0);
  EXPECT_EQ(square_case(15).count, 0);
  for (unsigned m : {5u, 10u}) {
    const SquareCase& sc = square_case(m);
    ASSERT_EQ(sc.count, 2);
    // Each segment cuts off exactly one inside corner: it joins the two edges of that corner.
    for (int k = 0; k < 2; ++k) {
      const int a = sc.segments[size_t(k)][0], b = sc.segments[size_t(k)][1];
      const int shared = (a == (b + 1) % 4) ? a : b;  // the corner between edges b and a
      EXPECT_TRUE((m >> shared) & 1) << "segment must surround an inside corner";
    }
  }
  // Orientation: inside on the left of every segment.
  static const double mid[4][2] = {{0.5, 0}, {1, 0.5}, {0.5, 1}, {0, 0.5}};
  static const double cor[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (unsigned m = 1; m < 15; ++m) {
    const SquareCase& sc = square_case(m);
    EXPECT_GE(sc.count, 1);
    for (int k = 0; k < sc.count; ++k) {
      const auto* p = mid[sc.segments[size_t(k)][0]];
      const auto* q = mid[sc.segments[size_t(k)][1]];
      for (int c = 0; c < 4; ++c) {
        const double side = (q[0] - p[0]) * (cor[c][1] - p[1]) - (q[1] - p[1]) * (cor[c][0] - p[0]);
        // Corners adjacent to the segment's edges are on the side matching their state.
        const bool adjacent = c == sc.segments[size_t(k)][0] || c == (sc.segments[size_t(k)][0] + 1) % 4;
        if (adjacent) {
          EXPECT_EQ(side > 0, bool((m >> c) & 1)) << "mask " << m;
        }
      }
    }
  }
}

TEST(CubeCases, EveryCaseIsAClosedOrientedIntersectionFreeSurface) {
  test::Rng rng(1);
  for (unsigned mask = 0; mask < 256; ++mask) {
    const CubeCase& cc = cube_case(mask);
    // Exactly the sticks of the case are used, each by at least one triangle.
    std::set<int> used, sticks;
    for (int e = 0; e < 12; ++e)
      if (((mask >> cube_edge_corner(e, 0)) & 1) != ((mask >> cube_edge_corner(e, 1)) & 1)) sticks.insert(e);
    for (int k = 0; k < cc.count; ++k)
      for (int c = 0; c < 3; ++c) used.insert(cc.triangles[size_t(k)][size_t(c)]);
    EXPECT_EQ(used, sticks) << "case " << mask;
    // Triangles point from inside corners to outside ones: each normal has a
    // positive component along (outside centroid - inside centroid) locally.
    for (int k = 0; k < cc.count; ++k) {
      const auto& t = cc.triangles[size_t(k)];
      const Vec3 a = edge_pos(t[0], 0.5), b = edge_pos(t[1], 0.5), c = edge_pos(t[2], 0.5);
      const Vec3 n = (b - a).cross(c - a);
      ASSERT_GT(n.norm(), 0) << "degenerate triangle in case " << mask;
      for (int e : {int(t[0]), int(t[1]), int(t[2])}) {
        const int c0 = cube_edge_corner(e, 0), c1 = cube_edge_corner(e, 1);
        const Vec3 in = ((mask >> c0) & 1) ? corner_pos(c0) : corner_pos(c1);
        const Vec3 out = ((mask >> c0) & 1) ? corner_pos(c1) : corner_pos(c0);
        EXPECT_GT(n.dot(out - in), 0) << "case " << mask << ": triangle faces the inside";
      }
    }
    // Open edges of the cell's triangles lie on cube faces and pair up
    // (every interior edge is shared by exactly two triangles, opposite directions).
    std::map<std::pair<int, int>, int> directed;
    for (int k = 0; k < cc.count; ++k)
      for (int c = 0; c < 3; ++c) ++directed[{cc.triangles[size_t(k)][size_t(c)], cc.triangles[size_t(k)][size_t((c + 1) % 3)]}];
    for (auto& [e, n] : directed) {
      EXPECT_EQ(n, 1) << "case " << mask;
      const bool interior = directed.count({e.second, e.first}) > 0;
      if (!interior) {
        // A boundary edge of the cell's surface must lie on a cube face.
        const Vec3 p = edge_pos(e.first, 0.5), q = edge_pos(e.second, 0.5);
        bool on_face = false;
        for (int a = 0; a < 3; ++a)
          on_face |= p[a] == q[a] && (p[a] == 0 || p[a] == 1);
        EXPECT_TRUE(on_face) << "case " << mask;
      } else {
        // An interior edge never lies in a cube face (a neighbour could draw it too).
        const Vec3 p = edge_pos(e.first, 0.5), q = edge_pos(e.second, 0.5);
        for (int a = 0; a < 3; ++a) EXPECT_FALSE(p[a] == q[a] && (p[a] == 0 || p[a] == 1)) << "case " << mask;
      }
    }
    // No two triangles intersect, at the midpoints and for random positions along the sticks.
    for (int rep = 0; rep < 200; ++rep) {
      std::array<Vec3, 12> pos;
      for (int e = 0; e < 12; ++e) pos[size_t(e)] = edge_pos(e, rep == 0 ? 0.5 : 0.001 + 0.998 * rng.uniform());
      for (int i = 0; i < cc.count; ++i)
        for (int j = i + 1; j < cc.count; ++j) {
          const auto& ti = cc.triangles[size_t(i)];
          const auto& tj = cc.triangles[size_t(j)];
          const Vec3 a[3] = {pos[ti[0]], pos[ti[1]], pos[ti[2]]};
          const Vec3 b[3] = {pos[tj[0]], pos[tj[1]], pos[tj[2]]};
          const uint32_t ia[3] = {ti[0], ti[1], ti[2]}, ib[3] = {tj[0], tj[1], tj[2]};
          ASSERT_FALSE(detail::triangles_intersect(a, ia, b, ib)) << "case " << mask << " sample " << rep;
        }
    }
  }
}

TEST(CubeCases, FaceRuleConnectivitySignature) {
  // Inside and outside play symmetric roles only up to the face rule; the
  // number of surface pieces can differ (6- vs 18-connectivity). Check the
  // rule's signature cases: two diagonal inside corners give two pieces,
  // two diagonal outside corners give one.
  const unsigned face_diag_in = (1u << 0) | (1u << 3);      // corners 0 and 3 of face z = 0
  EXPECT_EQ(cube_case(face_diag_in).loops, 2);
  EXPECT_EQ(cube_case(255u ^ face_diag_in).loops, 1);
  const unsigned body_diag_in = (1u << 0) | (1u << 7);
  EXPECT_EQ(cube_case(body_diag_in).loops, 2);
  EXPECT_EQ(cube_case(255u ^ body_diag_in).loops, 2);
}

}  // namespace
}  // namespace voxpress
