// check_mesh and check_classification find what they claim to find.
#include "../../src/core/bvh.h"
#include "test_util.h"

namespace voxpress {
namespace {

Mesh cube_mesh(double lo = 0, double hi = 1) {
  Mesh m;
  for (int c = 0; c < 8; ++c) m.positions.emplace_back(c & 1 ? hi : lo, c & 2 ? hi : lo, c & 4 ? hi : lo);
  // Outward-facing quads split into triangles.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    m.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  return m;
}

TEST(CheckMesh, CubeIsValid) {
  const MeshCheck r = check_mesh(cube_mesh());
  EXPECT_TRUE(r.ok()) << r.problems.size();
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.components, 1u);
  EXPECT_NEAR(r.signed_volume, 1.0, 1e-12);
  EXPECT_NEAR(r.area, 6.0, 1e-12);
}

TEST(CheckMesh, DetectsEachKindOfDefect) {
  {
    Mesh m = cube_mesh();
    m.triangles.pop_back();
    const MeshCheck r = check_mesh(m);
    EXPECT_EQ(r.boundary_edges, 3u);
    EXPECT_FALSE(r.closed());
    EXPECT_FALSE(r.ok());
  }
  {
    Mesh m = cube_mesh();
    std::swap(m.triangles[0][1], m.triangles[0][2]);
    const MeshCheck r = check_mesh(m);
    EXPECT_EQ(r.misoriented_edges, 3u);
    EXPECT_FALSE(r.oriented());
  }
  {
    Mesh m = cube_mesh();
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    const MeshCheck r = check_mesh(m);
    EXPECT_TRUE(r.oriented());
    EXPECT_LT(r.signed_volume, 0);
    EXPECT_FALSE(r.ok()) << "inward orientation must be reported";
  }
  {
    Mesh m = cube_mesh();
    m.triangles.push_back({0, 1, 1});
    EXPECT_EQ(check_mesh(m).degenerate_faces, 1u);
    m.triangles.back() = {0, 1, 2};
    m.positions[2] = Vec3(2, 0, 0);  // collinear with 0 and 1
    EXPECT_GE(check_mesh(m).degenerate_faces, 1u);
  }
  {
    // Two cubes sharing one vertex: a pinched (non-manifold) vertex.
    Mesh a = cube_mesh(0, 1), b = cube_mesh(1, 2);
    const uint32_t base = uint32_t(a.positions.size());
    for (auto p : b.positions) a.positions.push_back(p);
    for (auto t : b.triangles) a.triangles.push_back({t[0] == 0 ? 7 : t[0] + base, t[1] == 0 ? 7 : t[1] + base,
                                                      t[2] == 0 ? 7 : t[2] + base});
    const MeshCheck r = check_mesh(a);
    EXPECT_EQ(r.nonmanifold_vertices, 1u);
    EXPECT_EQ(r.unreferenced_vertices, 1u);
  }
  {
    // Three faces on one edge.
    Mesh m = cube_mesh();
    m.positions.emplace_back(0.5, 0.5, 0.5);
    m.triangles.push_back({0, 1, 8});
    EXPECT_GE(check_mesh(m).nonmanifold_edges, 1u);
  }
  {
    // Two overlapping cubes intersect; a cube inside another does not.
    Mesh m = cube_mesh(0, 1), n = cube_mesh(0.5, 1.5), inner = cube_mesh(0.25, 0.75);
    auto merge = [](Mesh x, const Mesh& y) {
      const uint32_t base = uint32_t(x.positions.size());
      for (auto p : y.positions) x.positions.push_back(p);
      for (auto t : y.triangles) x.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
      return x;
    };
    EXPECT_GT(check_mesh(merge(m, n)).self_intersections, 0u);
    EXPECT_EQ(check_mesh(merge(m, inner)).self_intersections, 0u);
    EXPECT_EQ(check_mesh(merge(m, inner), {false}).self_intersections_checked, false);
  }
  {
    Mesh m = cube_mesh();
    m.triangles.push_back({0, 1, 99});
    const MeshCheck r = check_mesh(m);
    EXPECT_EQ(r.invalid_indices, 1u);
    EXPECT_FALSE(r.ok());
  }
}

TEST(Bvh, OverlappingPairsMatchBruteForce) {
  test::Rng rng(11);
  std::vector<detail::Aabb> boxes(500);
  for (auto& b : boxes) {
    const Vec3 c(rng.uniform() * 10, rng.uniform() * 10, rng.uniform() * 10);
    const Vec3 h(rng.uniform(), rng.uniform(), rng.uniform());
    b.grow(c - h);
    b.grow(c + h);
  }
  std::set<std::pair<uint32_t, uint32_t>> brute, found;
  for (uint32_t i = 0; i < boxes.size(); ++i)
    for (uint32_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j])) brute.insert({i, j});
  std::mutex m;
  detail::Bvh(boxes).for_each_overlapping_pair([&](uint32_t a, uint32_t b) {
    std::lock_guard lock(m);
    EXPECT_TRUE(found.insert({std::min(a, b), std::max(a, b)}).second) << "pair reported twice";
  });
  EXPECT_EQ(found, brute);
}

TEST(CheckClassification, DetectsMisplacedAndInvertedSurfaces) {
  test::Rng rng(8);
  const BinaryVolume v = test::random_blobs(rng, {16, 14, 12}, 3);
  Mesh m = to_mesh(extract_sticks(v));
  ASSERT_EQ(check_classification(m, v).violations, 0u);
  // Shifted by 0.6 voxel: samples change side.
  Mesh shifted = m;
  for (auto& p : shifted.positions) p.x() += 0.6;
  const auto r = check_classification(shifted, v);
  EXPECT_GT(r.violations, 0u);
  EXPECT_GT(r.inside_found_outside + r.outside_found_inside, 0u);
  EXPECT_FALSE(r.examples.empty());
  // Inverted orientation: every inside sample is found outside by the winding rule...
  Mesh inverted = m;
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  EXPECT_EQ(check_classification(inverted, v).inside_found_outside, v.count_inside());
  // ... and nothing by the orientation-blind parity rule.
  ClassificationOptions parity;
  parity.rule = ClassificationOptions::Rule::parity;
  EXPECT_EQ(check_classification(inverted, v, parity).violations, 0u);
  // A vertex exactly on a sample is a violation (on the surface).
  Mesh touching = m;
  const Vec3 sample = v.lattice.to_physical(Vec3(0, 0, 0));
  touching.positions[0] = sample;
  EXPECT_GT(check_classification(touching, v).violations, 0u);
}

TEST(CheckClassification, HonoursPhysicalLattices) {
  test::Rng rng(10);
  BinaryVolume v = test::random_blobs(rng, {12, 10, 9}, 3);
  v.lattice.spacing = Vec3(0.3, 0.9, 2.0);
  v.lattice.origin = Vec3(5, -3, 12);
  v.lattice.direction = Eigen::AngleAxisd(1.1, Vec3(0.2, 1, 0.4).normalized()).toRotationMatrix();
  const Mesh m = to_mesh(extract_sticks(v));
  EXPECT_EQ(check_classification(m, v).violations, 0u);
  // The same mesh against the identity lattice is wrong.
  BinaryVolume plain = v;
  plain.lattice = Lattice{};
  plain.lattice.dims = v.lattice.dims;
  EXPECT_GT(check_classification(m, plain).violations, 0u);
}

}  // namespace
}  // namespace voxpress
