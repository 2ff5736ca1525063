// Property tests of the midpoint (stick) surface over hundreds of random,
// adversarial and generated volumes.
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <map>
#include <set>

#include "test_util.h"

namespace voxpress {
namespace {

using test::Case;

// Every vertex lies at its stick's midpoint, and the stick really is a stick.
void expect_midpoint_vertices(const BinaryVolume& v, const StickSurface& s, const std::string& name) {
  for (size_t i = 0; i < s.stick_count(); ++i) {
    const auto lo = s.lower_index(i);
    auto hi = lo;
    hi[size_t(s.axis(i))] += 1;
    ASSERT_NE(v.at(lo[0], lo[1], lo[2]), v.at(hi[0], hi[1], hi[2])) << name << ": stick " << i << " is not a stick";
    ASSERT_EQ(s.lower_inside(i), v.at(lo[0], lo[1], lo[2])) << name;
    ASSERT_EQ(s.t[i], 0.5) << name;
    Vec3 mid{double(lo[0]), double(lo[1]), double(lo[2])};
    mid[s.axis(i)] += 0.5;
    ASSERT_EQ((s.index_position(i) - mid).norm(), 0.0) << name;
  }
}

TEST(StickSurface, PropertyCorpusIsClosedManifoldOrientedAndSeparatesSamples) {
  const auto cases = test::property_volumes();
  ASSERT_GE(cases.size(), 300u);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const StickSurface s = extract_sticks(c.volume);
    EXPECT_EQ(s.stick_count(), count_sticks(c.volume));
    expect_midpoint_vertices(c.volume, s, c.name);
    const Mesh m = to_mesh(s);
    const MeshCheck r = check_mesh(m);
    ASSERT_TRUE(r.ok()) << c.name << ": " << (r.problems.empty() ? "" : r.problems[0]);
    EXPECT_TRUE(r.self_intersections_checked);
    EXPECT_GT(r.signed_volume, 0) << c.name;
    const ClassificationReport cr = check_classification(m, c.volume);
    ASSERT_EQ(cr.violations, 0u) << c.name;
    // Sticks count exactly the lattice edges whose samples differ (with padding).
    uint64_t expected = 0;
    const auto& d = c.volume.lattice.dims;
    for (int64_t k = -1; k <= d[2]; ++k)
      for (int64_t j = -1; j <= d[1]; ++j)
        for (int64_t i = -1; i <= d[0]; ++i) {
          const bool a = c.volume.at(i, j, k);
          expected += (a != c.volume.at(i + 1, j, k)) + (a != c.volume.at(i, j + 1, k)) + (a != c.volume.at(i, j, k + 1));
        }
    EXPECT_EQ(s.stick_count(), expected);
  }
}

TEST(StickSurface, EulerCharacteristicOfSphereAndTorus) {
  for (int seed = 0; seed < 6; ++seed) {
    GenerateOptions o;
    o.res = 24 + 8 * seed;
    o.rotation = parse_rotation("random:" + std::to_string(100 + seed));
    const MeshCheck sphere = check_mesh(to_mesh(extract_sticks(generate_shape(ShapeKind::sphere, o).volume)), {false});
    const MeshCheck torus = check_mesh(to_mesh(extract_sticks(generate_shape(ShapeKind::torus, o).volume)), {false});
    EXPECT_EQ(sphere.euler, 2) << "res " << o.res;
    EXPECT_EQ(sphere.components, 1u);
    EXPECT_EQ(torus.euler, 0) << "res " << o.res;
    EXPECT_EQ(torus.components, 1u);
  }
}

// The cut of the surface by every lattice plane is exactly that plane's
// marching-squares contour under the same face rule.
TEST(StickSurface, LatticePlaneCutsEqualMarchingSquares) {
  test::Rng rng(5);
  for (int rep = 0; rep < 20; ++rep) {
    const BinaryVolume v = rep % 2 ? test::random_noise(rng, {7, 6, 5}, 0.5) : test::random_blobs(rng, {9, 8, 7}, 3);
    const StickSurface s = extract_sticks(v);
    std::map<std::tuple<int64_t, int64_t, int64_t, int>, uint32_t> id;  // lower index + axis -> stick
    for (size_t i = 0; i < s.stick_count(); ++i) {
      const auto l = s.lower_index(i);
      id[{l[0], l[1], l[2], s.axis(i)}] = uint32_t(i);
    }
    for (int normal = 0; normal < 3; ++normal) {
      const int u = (normal + 1) % 3, w = (normal + 2) % 3;
      const auto& d = v.lattice.dims;
      for (int64_t c = -1; c <= d[size_t(normal)]; ++c) {
        // Mesh edges lying in plane `c`: both endpoints on sticks along u or w in that plane.
        auto in_plane = [&](uint32_t st) {
          return s.axis(st) != normal && s.lower_index(st)[size_t(normal)] == c;
        };
        std::set<std::pair<uint32_t, uint32_t>> mesh_edges, ms_edges;
        for (const Triangle& t : s.triangles)
          for (int e = 0; e < 3; ++e) {
            const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
            if (in_plane(a) && in_plane(b)) mesh_edges.insert({std::min(a, b), std::max(a, b)});
          }
        // Marching squares on the plane, squares between samples (a, b) .. (a+1, b+1).
        for (int64_t b = -1; b < d[size_t(w)] + 1; ++b)
          for (int64_t a = -1; a < d[size_t(u)] + 1; ++a) {
            auto sample = [&](int64_t da, int64_t db) {
              std::array<int64_t, 3> p{};
              p[size_t(normal)] = c;
              p[size_t(u)] = a + da;
              p[size_t(w)] = b + db;
              return v.at(p[0], p[1], p[2]);
            };
            static const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            unsigned mask = 0;
            for (int q = 0; q < 4; ++q) mask |= unsigned(sample(corner[q][0], corner[q][1])) << q;
            const SquareCase& sc = square_case(mask);
            auto edge_stick = [&](int e) {  // square edge e joins corners e and e+1
              const int* p0 = corner[e];
              const int* p1 = corner[(e + 1) % 4];
              std::array<int64_t, 3> lo{};
              lo[size_t(normal)] = c;
              lo[size_t(u)] = a + std::min(p0[0], p1[0]);
              lo[size_t(w)] = b + std::min(p0[1], p1[1]);
              const int axis = p0[0] != p1[0] ? u : w;
              return id.at({lo[0], lo[1], lo[2], axis});
            };
            for (int k = 0; k < sc.count; ++k) {
              const uint32_t x = edge_stick(sc.segments[size_t(k)][0]), y = edge_stick(sc.segments[size_t(k)][1]);
              ms_edges.insert({std::min(x, y), std::max(x, y)});
            }
          }
        ASSERT_EQ(mesh_edges, ms_edges) << "plane " << normal << "=" << c << " of volume " << rep;
      }
    }
  }
}

TEST(StickSurface, IdenticalForOneAndManyThreads) {
  test::Rng rng(77);
  std::vector<BinaryVolume> vols = {test::random_noise(rng, {40, 33, 29}, 0.5), test::random_blobs(rng, {48, 40, 36}, 5)};
  GenerateOptions o;
  o.res = 64;
  o.rotation = parse_rotation("random:5");
  vols.push_back(generate_shape(ShapeKind::cad_part, o).volume);
  for (const auto& v : vols) {
    StickSurface one, many;
    {
      tbb::task_arena arena(1);
      arena.execute([&] { one = extract_sticks(v); });
    }
    {
      tbb::task_arena arena(std::max(2, tbb::info::default_concurrency()));
      arena.execute([&] { many = extract_sticks(v); });
    }
    EXPECT_EQ(one.lower, many.lower);
    EXPECT_EQ(one.code, many.code);
    EXPECT_EQ(one.triangles, many.triangles);
  }
}

TEST(StickSurface, MirroredAndAnisotropicLatticesStayOutward) {
  test::Rng rng(9);
  BinaryVolume v = test::random_blobs(rng, {14, 12, 10}, 3);
  v.lattice.spacing = Vec3(0.7, 1.3, 2.5);
  v.lattice.origin = Vec3(-40, 12.5, 100);
  v.lattice.direction = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  v.lattice.direction.col(1) *= -1;  // left-handed index frame
  ASSERT_TRUE(v.lattice.flips_orientation());
  const Mesh m = to_mesh(extract_sticks(v));
  const MeshCheck r = check_mesh(m);
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0]);
  EXPECT_GT(r.signed_volume, 0);
  EXPECT_EQ(check_classification(m, v).violations, 0u);
  // Vertices are the physical midpoints of the sticks.
  const StickSurface s = extract_sticks(v);
  for (size_t i = 0; i < s.stick_count(); i += 7)
    EXPECT_LT((m.positions[i] - v.lattice.to_physical(s.index_position(i))).norm(), 1e-9);
}

TEST(StickSurface, EmptyAndFullVolumesAreRefusedByRequireMixed) {
  BinaryVolume empty = test::make_volume(4, 4, 4);
  empty.source = "empty.nrrd";
  EXPECT_EQ(extract_sticks(empty).stick_count(), 0u);
  try {
    require_mixed(empty);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.nrrd"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos);
  }
  BinaryVolume full = empty;
  std::fill(full.inside.begin(), full.inside.end(), 1);
  EXPECT_THROW(require_mixed(full), InputError);
  // A full volume still has a valid surface (the padded box): the refusal is a policy.
  const Mesh box = to_mesh(extract_sticks(full));
  EXPECT_TRUE(check_mesh(box).ok());
}

TEST(StickSurface, LimitsAreCheckedBeforeAllocating) {
  test::Rng rng(3);
  const BinaryVolume v = test::random_noise(rng, {20, 20, 20}, 0.5);
  ExtractOptions o;
  o.max_bytes = 1000;
  EXPECT_THROW(extract_sticks(v, o), LimitError);
}

TEST(StickSurface, ProgressIsReportedAndCancellationStops) {
  struct Counting : Progress {
    int begins = 0, ends = 0;
    uint64_t last = 0;
    bool cancel = false;
    void begin(std::string_view, uint64_t) override { ++begins; }
    bool update(uint64_t done) override {
      last = std::max(last, done);
      return !cancel;
    }
    void end() override { ++ends; }
  } p;
  test::Rng rng(4);
  const BinaryVolume v = test::random_blobs(rng, {30, 30, 30}, 3);
  ExtractOptions o;
  o.progress = &p;
  extract_sticks(v, o);
  EXPECT_EQ(p.begins, 2);
  EXPECT_EQ(p.ends, 2);
  EXPECT_GT(p.last, 0u);
  p.cancel = true;
  EXPECT_THROW(extract_sticks(v, o), Cancelled);
}

}  // namespace
}  // namespace voxpress
