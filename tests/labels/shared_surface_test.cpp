// Shared surfaces of label maps: every label's surface is closed, 2-manifold,
// outward, free of self-intersection and keeps every sample of the whole
// volume on its side; the union of the labels' surfaces has no gap and no
// overlap (each interface triangle used by exactly its two labels, in
// opposite orientations); one label against the background is the binary
// midpoint surface; the same bytes for 1 and N threads. Over the phantom,
// random and adversarial label configurations and, when ../shared is
// present, the 61-label TotalSegmentator map.
#include <tbb/global_control.h>

#include <algorithm>
#include <map>

#include "label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

using test::label_volume;
using test::set;

// Every label of the map: its mesh passes the checks against the whole volume.
void expect_every_label_closed_and_on_its_side(const ScalarVolume& v, const SharedSurface& s) {
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    const Mesh m = label_mesh(s, L);
    ASSERT_FALSE(m.triangles.empty());
    test::expect_guarantees(m, test::whole_mask(v, double(s.labels[L])));
  }
}

// No gap, no overlap: over all labels' meshes (in shared vertex ids), each
// triangle with two labels is used twice, once each way, and one facing the
// background once.
void expect_interfaces_shared(const SharedSurface& s) {
  std::map<std::array<uint32_t, 3>, int> directed;  // rotated so the smallest id is first
  auto canon = [](Triangle t) {
    while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
    return std::array<uint32_t, 3>{t[0], t[1], t[2]};
  };
  for (size_t f = 0; f < s.sides.size(); ++f) {
    ASSERT_NE(s.sides[f][0], s.sides[f][1]);
    const Triangle t = s.mesh.triangles[f];
    for (int side = 0; side < 2; ++side) {
      if (s.sides[f][size_t(side)] == 0) continue;  // the background has no mesh
      directed[canon(side == 0 ? t : Triangle{t[0], t[2], t[1]})]++;
    }
  }
  for (const auto& [t, n] : directed) EXPECT_EQ(n, 1) << "a triangle used twice the same way";
  size_t two = 0;
  for (size_t f = 0; f < s.sides.size(); ++f) two += s.sides[f][0] != 0 && s.sides[f][1] != 0;
  EXPECT_EQ(directed.size(), s.sides.size() + two);
}

void expect_all(const ScalarVolume& v) {
  const SharedSurface s = extract_shared_surface(v);
  expect_every_label_closed_and_on_its_side(v, s);
  expect_interfaces_shared(s);
}

TEST(SharedSurface, PhantomLabelsAreClosedAndShareTheirInterfaces) {
  const ScalarVolume v = test::phantom();
  const SharedSurface s = extract_shared_surface(v);
  EXPECT_EQ(s.labels, (std::vector<uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_GT(s.face_vertices, 0u);  // three labels meet around face centres
  expect_every_label_closed_and_on_its_side(v, s);
  expect_interfaces_shared(s);
  // The interface between the nested spheres (2 and 3) is one set of triangles.
  size_t between = 0;
  for (const auto& sd : s.sides) between += (sd[0] == 2 && sd[1] == 3) || (sd[0] == 3 && sd[1] == 2);
  EXPECT_EQ(between, label_mesh(s, 3).triangles.size());  // sphere 3 touches only sphere 2
}

TEST(SharedSurface, OneLabelIsTheBinaryMidpointSurface) {
  GenerateOptions g;
  g.res = 32;
  g.rotation = parse_rotation("random:4");
  const GeneratedShape shape = generate_shape(ShapeKind::cad_part, g);
  ScalarVolume v;
  v.lattice = shape.volume.lattice;
  v.type = ScalarType::u16;
  v.bytes.resize(v.lattice.size() * 2);
  for (uint64_t i = 0; i < v.lattice.size(); ++i) {
    const uint16_t x = shape.volume.inside[i] ? 7 : 0;
    std::memcpy(v.bytes.data() + 2 * i, &x, 2);
  }
  const SharedSurface s = extract_shared_surface(v);
  const Mesh binary = to_mesh(extract_sticks(shape.volume));
  const Mesh shared = label_mesh(s, 1);
  ASSERT_EQ(shared.positions.size(), binary.positions.size());
  ASSERT_EQ(shared.triangles.size(), binary.triangles.size());
  EXPECT_EQ(s.face_vertices + s.apex_vertices, 0u);
  // Same triangles as position triples (the vertex numbering differs).
  auto triples = [](const Mesh& m) {
    std::vector<std::array<double, 9>> out;
    for (const Triangle& t : m.triangles) {
      std::array<Vec3, 3> p = {m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
      auto less = [](const Vec3& a, const Vec3& b) { return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3); };
      while (less(p[1], p[0]) || less(p[2], p[0])) p = {p[1], p[2], p[0]};
      out.push_back({p[0].x(), p[0].y(), p[0].z(), p[1].x(), p[1].y(), p[1].z(), p[2].x(), p[2].y(), p[2].z()});
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_TRUE(triples(shared) == triples(binary));
}

TEST(SharedSurface, AdversarialLabelConfigurations) {
  {  // checkerboard of three labels, and of three labels over a background
    SCOPED_TRACE("checkerboard");
    expect_all(test::checkerboard3({9, 8, 7}));
    expect_all(test::checkerboard3({9, 8, 7}, 2, 0));
  }
  {  // a single voxel of 2 inside 1; labels touching along an edge and at a corner only
    ScalarVolume v = label_volume({10, 10, 10});
    for (int64_t k = 1; k < 5; ++k)
      for (int64_t j = 1; j < 5; ++j)
        for (int64_t i = 1; i < 5; ++i) set(v, i, j, k, 1);
    set(v, 2, 2, 2, 2);
    set(v, 6, 6, 6, 3);
    set(v, 7, 7, 6, 4);  // 3 and 4 share an edge (a lattice line), 3 and 5 a corner
    set(v, 7, 7, 7, 5);
    SCOPED_TRACE("voxel inside, edge and corner contacts");
    expect_all(v);
  }
  {  // 255 labels in a 16^3 block (values spread out), and random three-label noise
    ScalarVolume v = label_volume({16, 16, 16});
    test::Rng rng(255);
    for (auto& b : v.bytes) b = std::byte(uint8_t(rng.range(0, 255)));
    SCOPED_TRACE("255 labels");
    try {  // in double precision only here (255 labels; the float32 pass runs on the others)
      const SharedSurface s = extract_shared_surface(v);
      for (uint32_t L = 1; L < s.labels.size(); ++L) {
        const Mesh m = label_mesh(s, L);
        const MeshCheck mc = check_mesh(m);
        EXPECT_TRUE(mc.ok()) << "label " << s.labels[L] << ": " << (mc.problems.empty() ? "" : mc.problems[0]);
        EXPECT_EQ(check_classification(m, test::whole_mask(v, double(s.labels[L]))).violations, 0u);
      }
      expect_interfaces_shared(s);
    } catch (const InputError& e) {  // a cube of many labels with no derived case: refused, named
      EXPECT_NE(std::string(e.what()).find("issue 54"), std::string::npos) << e.what();
    }
    for (int seed = 0; seed < 3; ++seed) {
      test::Rng r3{uint64_t(seed)};
      for (auto& b : v.bytes) b = std::byte(uint8_t(r3.range(0, 2)));
      SCOPED_TRACE("noise " + std::to_string(seed));
      expect_all(v);
    }
  }
}

TEST(SharedSurface, SameBytesForAnyThreadCountAndBadInputIsRefused) {
  const ScalarVolume v = test::phantom();
  SharedSurface one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = extract_shared_surface(v);
  }
  const SharedSurface many = extract_shared_surface(v);
  EXPECT_EQ(one.mesh.positions, many.mesh.positions);
  EXPECT_EQ(one.mesh.triangles, many.mesh.triangles);
  EXPECT_EQ(one.sides, many.sides);
  test::expect_input_error([&] { extract_shared_surface(label_volume({4, 4, 4})); }, "test-labels", "empty");
  ScalarVolume f = label_volume({4, 4, 4});
  f.type = ScalarType::f32;
  f.bytes.assign(64 * 4, std::byte{0});
  const float half = 0.5f;
  std::memcpy(f.bytes.data(), &half, 4);
  test::expect_input_error([&] { extract_shared_surface(f); }, "test-labels", "whole numbers");
}

// extract --labels: the file as written and read back (PLY, float32
// positions) holds every label's closed surface, selected by its face
// attributes; a grey volume is refused with nothing written.
TEST(SharedSurface, ExtractLabelsWritesEveryLabelsSurfaceInOneFile) {
  test::TempDir tmp;
  const ScalarVolume v = test::phantom();
  write_volume(tmp.path("phantom.nrrd"), v);
  std::string out;
  ASSERT_EQ(test::run_cli("-q extract " + tmp.path("phantom.nrrd") + " --labels --check -o " + tmp.path("all.ply"), &out), 0)
      << out;
  const Mesh m = read_mesh(tmp.path("all.ply"));
  ASSERT_EQ(m.face_attributes.size(), 2u);
  EXPECT_EQ(m.face_attributes[0].name, "label_in");
  EXPECT_EQ(m.face_attributes[1].name, "label_out");
  for (int label = 1; label <= 4; ++label) {
    SCOPED_TRACE("label " + std::to_string(label));
    Mesh one;
    std::vector<uint32_t> id(m.positions.size(), UINT32_MAX);
    for (size_t f = 0; f < m.triangles.size(); ++f) {
      Triangle t = m.triangles[f];
      if (m.face_attributes[1].values[f] == label) std::swap(t[1], t[2]);
      else if (m.face_attributes[0].values[f] != label) continue;
      for (uint32_t& x : t) {
        if (id[x] == UINT32_MAX) {
          id[x] = uint32_t(one.positions.size());
          one.positions.push_back(m.positions[x]);
        }
        x = id[x];
      }
      one.triangles.push_back(t);
    }
    const MeshCheck mc = check_mesh(one);
    EXPECT_TRUE(mc.ok()) << (mc.problems.empty() ? "" : mc.problems[0]);
    EXPECT_EQ(check_classification(one, test::whole_mask(v, label)).violations, 0u);
  }
  ScalarVolume grey = test::random_scalar_volume(ScalarType::f32, {8, 8, 8}, 3);
  const float half = 0.5f;
  std::memcpy(grey.bytes.data(), &half, 4);
  write_volume(tmp.path("grey.nrrd"), grey);
  EXPECT_EQ(test::run_cli("-q extract " + tmp.path("grey.nrrd") + " --labels -o " + tmp.path("grey.ply"), &out), 1);
  EXPECT_NE(out.find("grey.nrrd"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.path("grey.ply")));
}

TEST(SharedSurface, SixtyOneLabelMap) {
  const std::string path = test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "../shared is absent: " << path;
  const ScalarVolume v = read_volume(path);
  const SharedSurface s = extract_shared_surface(v);
  EXPECT_EQ(s.labels.size(), 62u);
  expect_interfaces_shared(s);
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    const Mesh m = label_mesh(s, L);
    const MeshCheck mc = check_mesh(m);
    EXPECT_TRUE(mc.ok()) << (mc.problems.empty() ? "" : mc.problems[0]);
    EXPECT_EQ(check_classification(m, test::whole_mask(v, double(s.labels[L]))).violations, 0u);
  }
}

}  // namespace
}  // namespace voxpress
