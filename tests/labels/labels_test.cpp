// Label maps: the label table against a brute-force count, every label's
// surface keeping the binary guarantee against the WHOLE volume (not only its
// box), adversarial label configurations, determinism, bad input.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <map>

#include "label_volumes.h"
#include "test_util.h"
#include "voxpress/voxpress.h"

namespace voxpress {
namespace {

using test::get;
using test::label_volume;
using test::phantom;
using test::set;
using test::whole_mask;

// Every label's surface: closed, manifold, oriented, no self-intersection,
// and every sample of the whole volume on its side (its label inside, all
// others outside), in double and float32.
void expect_every_label_guaranteed(const ScalarVolume& v, const SurfaceOptions& o = {}) {
  const LabelTable table = label_table(v);
  const std::vector<LabelSurface> surfaces = press_labels(v, table.labels, o);
  ASSERT_EQ(surfaces.size(), table.labels.size());
  for (const LabelSurface& s : surfaces) {
    SCOPED_TRACE("label " + std::to_string(s.label.value));
    test::expect_guarantees(s.result.mesh, whole_mask(v, s.label.value));
  }
}

TEST(Labels, TableMatchesABruteForceCount) {
  const ScalarVolume v = phantom();
  const LabelTable t = label_table(v);
  std::map<int, uint64_t> count;
  std::map<int, std::array<int64_t, 6>> box;
  std::map<std::pair<int, int>, uint64_t> contact;
  const auto& d = v.lattice.dims;
  auto at = [&](int64_t i, int64_t j, int64_t k) {
    return i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2] ? 0 : get(v, i, j, k);
  };
  for (int64_t k = -1; k < d[2]; ++k)
    for (int64_t j = -1; j < d[1]; ++j)
      for (int64_t i = -1; i < d[0]; ++i) {
        const int a = at(i, j, k);
        if (i >= 0 && j >= 0 && k >= 0 && a) {
          ++count[a];
          auto [it, fresh] = box.try_emplace(a, std::array<int64_t, 6>{i, j, k, i, j, k});
          auto& b = it->second;
          b = {std::min(b[0], i), std::min(b[1], j), std::min(b[2], k), std::max(b[3], i), std::max(b[4], j),
               std::max(b[5], k)};
        }
        for (const auto& n : {std::array<int64_t, 3>{i + 1, j, k}, {i, j + 1, k}, {i, j, k + 1}}) {
          if (i < 0 && n[0] < 0) continue;  // edges of the padding ring alone
          if (j < 0 && n[1] < 0) continue;
          if (k < 0 && n[2] < 0) continue;
          const int b = at(n[0], n[1], n[2]);
          if (a != b) ++contact[{std::min(a, b), std::max(a, b)}];
        }
      }
  ASSERT_EQ(t.labels.size(), count.size());
  for (const LabelInfo& l : t.labels) {
    const int a = int(l.value);
    EXPECT_EQ(l.samples, count[a]) << a;
    const auto& b = box[a];
    EXPECT_EQ(l.lo, (std::array<int64_t, 3>{b[0], b[1], b[2]})) << a;
    EXPECT_EQ(l.hi, (std::array<int64_t, 3>{b[3], b[4], b[5]})) << a;
  }
  ASSERT_EQ(t.contacts.size(), contact.size());
  for (const LabelContact& c : t.contacts)
    EXPECT_EQ(c.sticks, (contact[{int(c.a), int(c.b)}])) << c.a << "-" << c.b;
  // Three labels touch label 2 besides the background: 1, 3 and 4.
  int touching_2 = 0;
  for (const LabelContact& c : t.contacts) touching_2 += (c.a == 2 || c.b == 2) && c.a != 0;
  EXPECT_EQ(touching_2, 3);
  // A label's sticks with the background and the others are its binary sticks.
  for (const LabelInfo& l : t.labels) {
    uint64_t sticks = 0;
    for (const LabelContact& c : t.contacts) sticks += (c.a == l.value || c.b == l.value) ? c.sticks : 0;
    EXPECT_EQ(sticks, count_sticks(whole_mask(v, l.value))) << l.value;
  }
}

TEST(Labels, MaskOnTheBoxIsTheLabelEverywhere) {
  const ScalarVolume v = phantom();
  for (const LabelInfo& l : label_table(v).labels) {
    const BinaryVolume m = label_mask(v, l), whole = whole_mask(v, l.value);
    EXPECT_EQ(m.count_inside(), whole.count_inside());
    // Same physical place: the box's corner sample maps where the volume's does.
    const std::array<int64_t, 3> lo = {std::max<int64_t>(0, l.lo[0] - 1), std::max<int64_t>(0, l.lo[1] - 1),
                                       std::max<int64_t>(0, l.lo[2] - 1)};
    const Vec3 a = m.lattice.to_physical(Vec3(1, 2, 3));
    const Vec3 b = v.lattice.to_physical(Vec3(double(lo[0] + 1), double(lo[1] + 2), double(lo[2] + 3)));
    EXPECT_LT((a - b).norm(), 1e-12);
    for (int64_t k = 0; k < m.lattice.dims[2]; ++k)
      for (int64_t j = 0; j < m.lattice.dims[1]; ++j)
        for (int64_t i = 0; i < m.lattice.dims[0]; ++i)
          ASSERT_EQ(m.at(i, j, k), whole.at(lo[0] + i, lo[1] + j, lo[2] + k));
  }
}

TEST(Labels, PhantomEveryLabelKeepsItsSamplesInsideAndTheOthersOut) {
  expect_every_label_guaranteed(phantom());
}

TEST(Labels, AdversarialConfigurations) {
  {  // checkerboard of three labels: every lattice edge joins two labels
    SCOPED_TRACE("checkerboard of 3 labels");
    expect_every_label_guaranteed(test::checkerboard3({9, 8, 7}));
  }
  {  // a single voxel of label 2 inside label 1
    ScalarVolume v = label_volume({7, 7, 7});
    for (int64_t k = 1; k < 6; ++k)
      for (int64_t j = 1; j < 6; ++j)
        for (int64_t i = 1; i < 6; ++i) set(v, i, j, k, 1);
    set(v, 3, 3, 3, 2);
    SCOPED_TRACE("single voxel inside another label");
    expect_every_label_guaranteed(v);
  }
  {  // labels touching only along an edge and only at a corner
    ScalarVolume v = label_volume({8, 8, 8});
    for (int64_t k = 1; k < 4; ++k)
      for (int64_t j = 1; j < 4; ++j)
        for (int64_t i = 1; i < 4; ++i) {
          set(v, i, j, k, 1);
          set(v, i + 3, j + 3, k, 2);      // edge contact with 1
          set(v, i + 3, j + 3, k + 3, 3);  // corner contact with 1, face contact with 2
        }
    SCOPED_TRACE("edge and corner contacts");
    expect_every_label_guaranteed(v);
  }
  {  // 255 labels in a 16^3 block, random, with background
    ScalarVolume v = label_volume({16, 16, 16});
    test::Rng rng(54);
    for (int64_t k = 0; k < 16; ++k)
      for (int64_t j = 0; j < 16; ++j)
        for (int64_t i = 0; i < 16; ++i) set(v, i, j, k, int(rng.range(0, 255)));
    const LabelTable t = label_table(v);
    EXPECT_EQ(t.labels.size(), 255u);
    SCOPED_TRACE("255 random labels");
    expect_every_label_guaranteed(v);
  }
}

// A layered (4-D) .seg.nrrd: two layers whose segments overlap; each
// segment is meshed on its own layer, named, and keeps its own samples.
TEST(Labels, LayeredSegmentationEverySegmentOnItsLayer) {
  ScalarVolume v = label_volume({12, 12, 12});
  v.components = 2;
  v.bytes.assign(v.lattice.size() * 2, std::byte{0});
  for (int64_t k = 2; k < 10; ++k)
    for (int64_t j = 2; j < 10; ++j)
      for (int64_t i = 2; i < 10; ++i) {
        const uint64_t s = v.lattice.linear(i, j, k);
        v.bytes[2 * s] = std::byte(uint8_t(i < 6 ? 1 : 2));                         // layer 0: two halves
        v.bytes[2 * s + 1] = std::byte(uint8_t(std::abs(i - 6) + std::abs(j - 6) < 3 ? 1 : 0));  // layer 1 overlaps both
      }
  v.segments = {{"Segment_1", "left", 1, 0}, {"Segment_2", "right", 2, 0}, {"Segment_3", "rod", 1, 1}};
  const LabelTable t = label_table(v);
  EXPECT_TRUE(t.layered);
  ASSERT_EQ(t.labels.size(), 3u);
  EXPECT_EQ(t.labels[2].name, "rod");
  EXPECT_EQ(t.labels[2].layer, 1);
  const auto surfaces = press_labels(v, t.labels);
  for (const LabelSurface& s : surfaces) {
    SCOPED_TRACE(s.label.name);
    Selection sel;
    sel.kind = Selection::Kind::segment;
    sel.segment = s.label.name;
    test::expect_guarantees(s.result.mesh, binarize(v, sel));
  }
}

TEST(Labels, SameBytesForOneAndManyThreads) {
  const ScalarVolume v = phantom();
  const LabelTable t = label_table(v);
  std::vector<LabelSurface> one, many;
  tbb::task_arena(1).execute([&] { one = press_labels(v, t.labels); });
  tbb::task_arena(4).execute([&] { many = press_labels(v, t.labels); });
  ASSERT_EQ(one.size(), many.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].result.mesh.positions, many[i].result.mesh.positions) << i;
    EXPECT_EQ(one[i].result.mesh.triangles, many[i].result.mesh.triangles) << i;
  }
}

TEST(Labels, BadInputIsRefusedNamingTheFile) {
  ScalarVolume empty = label_volume({4, 4, 4});
  EXPECT_THROW(label_table(empty), InputError);
  ScalarVolume grey;
  grey.lattice.dims = {3, 3, 3};
  grey.type = ScalarType::f32;
  grey.bytes.resize(27 * 4);
  float* f = reinterpret_cast<float*>(grey.bytes.data());
  for (int i = 0; i < 27; ++i) f[i] = 0.25f * float(i);
  grey.source = "grey.nrrd";
  try {
    label_table(grey);
    ADD_FAILURE() << "a grey image is not a label map";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), "grey.nrrd");
    EXPECT_NE(std::string(e.what()).find("--threshold"), std::string::npos);
  }
  const ScalarVolume v = phantom();
  const LabelTable t = label_table(v);
  EXPECT_THROW(select_labels(t, parse_label_list("2,9"), v.source), InputError);
  EXPECT_THROW(parse_label_list("2,x"), UsageError);
  EXPECT_THROW(parse_label_list(""), UsageError);
  EXPECT_TRUE(parse_label_list("all").empty());
  EXPECT_EQ(select_labels(t, parse_label_list("all"), v.source).size(), t.labels.size());
  EXPECT_EQ(select_labels(t, parse_label_list("4,2,4"), v.source).size(), 2u);
  EXPECT_THROW(label_table(v, 2), InputError);  // more labels than allowed
  test::TempDir tmp;
  test::write_file(tmp.path("names.txt"), "# value name\n1 box\n2,sphere\n3\tinner sphere\n");
  const auto names = read_label_names(tmp.path("names.txt"));
  EXPECT_EQ(names.at(1), "box");
  EXPECT_EQ(names.at(2), "sphere");
  EXPECT_EQ(names.at(3), "inner sphere");
  test::write_file(tmp.path("bad.txt"), "1 box\nliver\n");
  try {
    read_label_names(tmp.path("bad.txt"));
    ADD_FAILURE() << "a line without a value was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos);
    EXPECT_EQ(e.path(), tmp.path("bad.txt"));
  }
  EXPECT_THROW(read_label_names(tmp.path("missing.txt")), InputError);
}

TEST(Labels, SharedLabelMapEveryOrganInOneCall) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const ScalarVolume v = read_volume(test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz");
  const LabelTable t = label_table(v);
  EXPECT_EQ(t.labels.size(), 61u);
  const std::vector<LabelSurface> surfaces = press_labels(v, t.labels);
  for (const LabelSurface& s : surfaces) {
    SCOPED_TRACE("label " + std::to_string(s.label.value));
    const MeshCheck mc = check_mesh(s.result.mesh);
    EXPECT_TRUE(mc.ok()) << (mc.problems.empty() ? "" : mc.problems[0]);
    EXPECT_EQ(check_classification(s.result.mesh, whole_mask(v, s.label.value)).violations, 0u);
  }
}

}  // namespace
}  // namespace voxpress
