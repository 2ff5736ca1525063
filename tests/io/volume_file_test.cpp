// VolumeFile: boxes read from disk equal the same boxes of the whole volume,
// for every layout that streams and for the ones read whole; bad boxes and
// truncated payloads are refused.
#include <fstream>

#include "test_util.h"

namespace voxpress {
namespace {

ScalarVolume random_volume(ScalarType type, std::array<int64_t, 3> dims, int64_t components, uint64_t seed) {
  return test::random_scalar_volume(type, dims, seed, components, 1000);
}

// The box of a whole volume, sample by sample (the reference VolumeFile::read is held to).
std::vector<std::byte> box_of(const ScalarVolume& v, const Box& b) {
  const size_t value = scalar_size(v.type) * size_t(v.components);
  std::vector<std::byte> out;
  for (int64_t k = b.lo[2]; k < b.hi[2]; ++k)
    for (int64_t j = b.lo[1]; j < b.hi[1]; ++j)
      for (int64_t i = b.lo[0]; i < b.hi[0]; ++i) {
        const std::byte* p = v.bytes.data() + v.lattice.linear(i, j, k) * value;
        out.insert(out.end(), p, p + value);
      }
  return out;
}

void expect_boxes_match(const std::string& path, const ScalarVolume& whole, bool streams) {
  const VolumeFile f(path);
  EXPECT_EQ(f.streams(), streams) << path;
  EXPECT_TRUE(f.header().bytes.empty());
  EXPECT_EQ(f.header().lattice.dims, whole.lattice.dims);
  EXPECT_EQ(f.header().components, whole.components);
  test::Rng rng(7);
  const auto& d = whole.lattice.dims;
  std::vector<Box> boxes = {Box{{0, 0, 0}, d}, Box{{0, 0, 0}, {1, 1, 1}}, Box{{d[0] - 1, d[1] - 1, d[2] - 1}, d},
                            Box{{0, 2, 3}, {d[0], d[1] - 1, d[2]}}};  // whole rows
  for (int n = 0; n < 12; ++n) {
    Box b;
    for (size_t a = 0; a < 3; ++a) {
      b.lo[a] = rng.range(0, d[a] - 1);
      b.hi[a] = rng.range(b.lo[a] + 1, d[a]);
    }
    boxes.push_back(b);
  }
  for (const Box& b : boxes) {
    const ScalarVolume got = f.read(b);
    EXPECT_EQ(got.lattice.dims, b.dims());
    EXPECT_LT((got.lattice.origin - whole.lattice.to_physical(Vec3(double(b.lo[0]), double(b.lo[1]), double(b.lo[2])))).norm(), 1e-9);
    EXPECT_TRUE(got.bytes == box_of(whole, b)) << path << " box " << b.lo[0] << "," << b.lo[1] << "," << b.lo[2];
  }
}

TEST(VolumeFile, RawNrrdStreamsAndGzipIsReadWholeWithTheSameBoxes) {
  test::TempDir dir;
  for (ScalarType t : {ScalarType::u8, ScalarType::i16, ScalarType::f32}) {
    const ScalarVolume v = random_volume(t, {37, 23, 19}, 1, uint64_t(t) + 1);
    test::write_raw_volume(dir.path("raw.nrrd"), v);
    expect_boxes_match(dir.path("raw.nrrd"), v, true);
    write_volume(dir.path("gz.nrrd"), v);
    expect_boxes_match(dir.path("gz.nrrd"), v, false);
    write_volume(dir.path("v.nii"), v);
    expect_boxes_match(dir.path("v.nii"), read_volume(dir.path("v.nii")), false);
  }
}

TEST(VolumeFile, LayeredBigEndianDetachedListAndRawFilesStream) {
  test::TempDir dir;
  // A 4-D layered file: components fastest.
  const ScalarVolume layers = random_volume(ScalarType::u8, {11, 9, 7}, 3, 3);
  test::write_raw_volume(dir.path("layers.seg.nrrd"), layers);
  expect_boxes_match(dir.path("layers.seg.nrrd"), layers, true);

  // Big-endian uint16 over a detached LIST of one file per plane.
  ScalarVolume v = random_volume(ScalarType::u16, {13, 8, 5}, 1, 4);
  v.lattice.direction = Mat3::Identity();  // as the header below says
  const size_t plane = size_t(13 * 8) * 2;
  {
    std::ofstream h(dir.path("list.nhdr"));
    h << "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 13 8 5\nencoding: raw\nendian: big\n"
         "space directions: (0.7,0,0) (0,1.25,0) (0,0,2.5)\nspace origin: (-12.5,3.25,100)\ndata file: LIST\n";
    for (int k = 0; k < 5; ++k) {
      h << "plane" << k << ".raw\n";
      std::string bytes(reinterpret_cast<const char*>(v.bytes.data()) + size_t(k) * plane, plane);
      for (size_t i = 0; i + 1 < bytes.size(); i += 2) std::swap(bytes[i], bytes[i + 1]);
      std::ofstream(dir.path("plane" + std::to_string(k) + ".raw"), std::ios::binary) << bytes;
    }
  }
  expect_boxes_match(dir.path("list.nhdr"), v, true);

  // Headerless raw with a header to skip.
  {
    std::ofstream f(dir.path("v.raw"), std::ios::binary);
    f << "HEADER";
    f.write(reinterpret_cast<const char*>(v.bytes.data()), std::streamsize(v.bytes.size()));
  }
  ReadOptions ro;
  ro.raw = RawLayout{{13, 8, 5}, ScalarType::u16, {1, 1, 1}, {0, 0, 0}, false, 6};
  const VolumeFile f(dir.path("v.raw"), ro);
  EXPECT_TRUE(f.streams());
  EXPECT_TRUE(f.read(Box{{2, 1, 1}, {9, 7, 4}}).bytes == box_of(v, Box{{2, 1, 1}, {9, 7, 4}}));
}

TEST(VolumeFile, BadBoxesAndTruncatedPayloadsAreRefused) {
  test::TempDir dir;
  const ScalarVolume v = random_volume(ScalarType::u8, {10, 10, 10}, 1, 5);
  test::write_raw_volume(dir.path("v.nrrd"), v);
  const VolumeFile f(dir.path("v.nrrd"));
  EXPECT_THROW(f.read(Box{{0, 0, 0}, {11, 10, 10}}), UsageError);
  EXPECT_THROW(f.read(Box{{-1, 0, 0}, {5, 5, 5}}), UsageError);
  EXPECT_THROW(f.read(Box{{3, 3, 3}, {3, 5, 5}}), UsageError);
  // Truncated: refused at open, naming the file, before any box is read.
  const std::string bytes = test::read_file(dir.path("v.nrrd"));
  std::ofstream(dir.path("cut.nrrd"), std::ios::binary) << bytes.substr(0, bytes.size() - 10);
  try {
    VolumeFile cut(dir.path("cut.nrrd"));
    ADD_FAILURE() << "a truncated file was opened";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.nrrd"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  EXPECT_THROW(VolumeFile(dir.path("absent.nrrd")), InputError);
}

TEST(VolumeFile, ValueSummariesOfBlocksMergeIntoTheWholeVolumes) {
  // What press --chunk resolves an automatic selection from.
  const ScalarVolume v = random_volume(ScalarType::u8, {20, 20, 20}, 1, 6);
  test::TempDir dir;
  test::write_raw_volume(dir.path("v.nrrd"), v);
  const VolumeFile f(dir.path("v.nrrd"));
  ValueSummary merged;
  for (int64_t k = 0; k < 20; k += 7) merged.merge(summarize_values(f.read(Box{{0, 0, k}, {20, 20, std::min<int64_t>(20, k + 7)}})));
  const ValueSummary whole = summarize_values(v);
  EXPECT_EQ(merged.lo, whole.lo);
  EXPECT_EQ(merged.hi, whole.hi);
  EXPECT_EQ(merged.more, whole.more);
  EXPECT_EQ(merged.nonzero, whole.nonzero);
  EXPECT_TRUE(whole.more);  // 1000 values of uint8: more than kMaxDistinct
}

}  // namespace
}  // namespace voxpress
