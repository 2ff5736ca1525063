#include "test_util.h"

namespace voxpress {
namespace {

ScalarVolume labels_u16(std::vector<uint16_t> values, std::array<int64_t, 3> dims) {
  ScalarVolume v;
  v.lattice.dims = dims;
  v.type = ScalarType::u16;
  v.bytes.resize(values.size() * 2);
  std::memcpy(v.bytes.data(), values.data(), v.bytes.size());
  v.source = "labels.nrrd";
  return v;
}

TEST(Lattice, IndexPhysicalRoundTripWithAnisotropyAndRotation) {
  Lattice l;
  l.dims = {10, 20, 30};
  l.spacing = Vec3(0.5, 1.5, 3);
  l.origin = Vec3(-10, 4, 7);
  l.direction = Eigen::AngleAxisd(0.7, Vec3(1, -1, 2).normalized()).toRotationMatrix();
  l.validate();
  const Vec3 ijk(3.25, 7.5, 11);
  const Vec3 p = l.to_physical(ijk);
  EXPECT_LT((l.to_index(p) - ijk).norm(), 1e-12);
  EXPECT_NEAR((l.to_physical(Vec3(1, 0, 0)) - l.origin).norm(), 0.5, 1e-12);
  EXPECT_NEAR((l.to_physical(Vec3(0, 0, 1)) - l.origin).norm(), 3.0, 1e-12);
  EXPECT_FALSE(l.flips_orientation());
  l.direction.col(2) *= -1;
  EXPECT_TRUE(l.flips_orientation());
  l.spacing.x() = 0;
  EXPECT_THROW(l.validate(), UsageError);
}

TEST(Volume, BinarizeByLabelNonzeroAndThreshold) {
  const ScalarVolume v = labels_u16({0, 1, 2, 2, 0, 7, 1, 0}, {2, 2, 2});
  Selection s;
  s.kind = Selection::Kind::label;
  s.value = 2;
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{0, 0, 1, 1, 0, 0, 0, 0}));
  EXPECT_EQ(binarize(v, parse_label_selection("all-nonzero")).inside, (std::vector<uint8_t>{0, 1, 1, 1, 0, 1, 1, 0}));
  s.kind = Selection::Kind::threshold;
  s.value = 2;
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{0, 0, 1, 1, 0, 1, 0, 0}));
  // A label that does not exist names the file.
  s.kind = Selection::Kind::label;
  s.value = 5;
  try {
    binarize(v, s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("labels.nrrd"), std::string::npos);
  }
}

TEST(Volume, AutomaticSelectionAcceptsMasksAndAsksForAChoiceOtherwise) {
  // A mask whose foreground is 257 (as in BallBinary30x30x30.nrrd).
  EXPECT_EQ(binarize(labels_u16({0, 257, 257, 0, 0, 0, 0, 257}, {2, 2, 2})).count_inside(), 3u);
  try {
    binarize(labels_u16({0, 1, 2, 3, 0, 0, 0, 0}, {2, 2, 2}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3 labels"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--label"), std::string::npos);
  }
  ScalarVolume grey;
  grey.lattice.dims = {2, 1, 1};
  grey.type = ScalarType::f32;
  const float vals[2] = {0.25f, 1.5f};
  grey.bytes.resize(8);
  std::memcpy(grey.bytes.data(), vals, 8);
  EXPECT_THROW(binarize(grey), InputError);
  EXPECT_THROW(parse_label_selection("abc"), UsageError);
}

TEST(Volume, SegmentsSelectTheirLayerAndLabel) {
  // Two layers (components fastest): layer 0 holds segment A (label 1), layer 1 holds B (label 1) and C (label 2).
  ScalarVolume v;
  v.lattice.dims = {3, 1, 1};
  v.type = ScalarType::u8;
  v.components = 2;
  const uint8_t data[6] = {1, 0, 0, 1, 1, 2};
  v.bytes.resize(6);
  std::memcpy(v.bytes.data(), data, 6);
  v.segments = {{"Segment_1", "A", 1, 0}, {"Segment_2", "B", 1, 1}, {"Segment_3", "C", 2, 1}};
  Selection s;
  s.kind = Selection::Kind::segment;
  s.segment = "A";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{1, 0, 1}));
  s.segment = "B";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{0, 1, 0}));
  s.segment = "Segment_3";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{0, 0, 1}));
  s.segment = "nope";
  EXPECT_THROW(binarize(v, s), InputError);
  EXPECT_THROW(binarize(v), InputError);  // several segments: must choose
}

TEST(Volume, HistogramCountsLabelsAndGivesUpOnGreyImages) {
  const auto h = value_histogram(labels_u16({0, 1, 2, 2, 0, 7, 1, 0}, {2, 2, 2}));
  ASSERT_TRUE(h);
  EXPECT_EQ(*h, (std::vector<std::pair<double, uint64_t>>{{0, 3}, {1, 2}, {2, 2}, {7, 1}}));
  std::vector<uint16_t> many(5000);
  for (size_t i = 0; i < many.size(); ++i) many[i] = uint16_t(i);
  EXPECT_FALSE(value_histogram(labels_u16(many, {5000, 1, 1}), 100));
}

}  // namespace
}  // namespace voxpress
