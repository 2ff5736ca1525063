// A label map block by block: the merged table and the assembled shared
// surface are the in-memory ones exactly, for any block size (including
// blocks that cut through three- and four-label junctions and 255 labels),
// thread count and reader; bad inputs are refused as in memory.
#include <tbb/global_control.h>

#include <cstring>

#include "../labels/label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

using test::label_volume;
using test::set;

// The samples of `box` of an in-memory volume, placed where the box lies.
ScalarVolume crop_scalar(const ScalarVolume& v, const Box& box) {
  ScalarVolume out = v;
  out.lattice = box_lattice(v.lattice, box);
  const size_t e = scalar_size(v.type) * size_t(v.components), nx = size_t(box.hi[0] - box.lo[0]);
  out.bytes.resize(box.size() * e);
  std::byte* dst = out.bytes.data();
  for (int64_t k = box.lo[2]; k < box.hi[2]; ++k)
    for (int64_t j = box.lo[1]; j < box.hi[1]; ++j, dst += nx * e)
      std::memcpy(dst, v.bytes.data() + v.lattice.linear(box.lo[0], j, k) * e, nx * e);
  return out;
}

ChunkedLabels chunked(const ScalarVolume& v, int64_t chunk) {
  ChunkOptions c;
  c.chunk = chunk;
  return extract_labels_chunked(v, [&](const Box& b) { return crop_scalar(v, b); }, c);
}

void expect_same(const ChunkedLabels& c, const ScalarVolume& v, const std::string& what) {
  SCOPED_TRACE(what);
  const LabelTable t = label_table(v);
  ASSERT_EQ(c.table.labels.size(), t.labels.size());
  for (size_t i = 0; i < t.labels.size(); ++i) {
    EXPECT_EQ(c.table.labels[i].value, t.labels[i].value);
    EXPECT_EQ(c.table.labels[i].samples, t.labels[i].samples);
    EXPECT_EQ(c.table.labels[i].lo, t.labels[i].lo);
    EXPECT_EQ(c.table.labels[i].hi, t.labels[i].hi);
  }
  ASSERT_EQ(c.table.contacts.size(), t.contacts.size());
  for (size_t i = 0; i < t.contacts.size(); ++i) {
    EXPECT_EQ(c.table.contacts[i].a, t.contacts[i].a);
    EXPECT_EQ(c.table.contacts[i].b, t.contacts[i].b);
    EXPECT_EQ(c.table.contacts[i].sticks, t.contacts[i].sticks);
  }
  const SharedSurface s = extract_shared_surface(v);
  EXPECT_EQ(c.surface.labels, s.labels);
  EXPECT_EQ(c.surface.mesh.triangles, s.mesh.triangles);
  EXPECT_EQ(c.surface.sides, s.sides);
  EXPECT_EQ(c.surface.kind, s.kind);
  EXPECT_EQ(c.surface.corner, s.corner);
  ASSERT_EQ(c.surface.mesh.positions.size(), s.mesh.positions.size());
  EXPECT_EQ(0, std::memcmp(c.surface.mesh.positions.data(), s.mesh.positions.data(),
                           s.mesh.positions.size() * sizeof(Vec3)));  // bit for bit
  EXPECT_GT(s.mesh.triangles.size(), 0u);
}

TEST(ChunkedLabels, BlocksGiveTheInMemoryTableAndSurfaceExactly) {
  const ScalarVolume phantom = test::phantom();  // rotated, anisotropic; 3- and 4-label junctions
  for (int64_t chunk : {8, 9, 13, 30, 64}) expect_same(chunked(phantom, chunk), phantom, "phantom, chunk " + std::to_string(chunk));
  const ScalarVolume board = test::checkerboard3({17, 11, 10});  // every cube three labels
  for (int64_t chunk : {8, 10}) expect_same(chunked(board, chunk), board, "checkerboard, chunk " + std::to_string(chunk));
  // 255 labels in 16^3 (every cube of many labels), cut into eight blocks.
  ScalarVolume many = label_volume({16, 16, 16});
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 16; ++j)
      for (int64_t i = 0; i < 16; ++i) set(many, i, j, k, 1 + int(((i / 2) + 8 * (j / 2) + 64 * (k / 4)) % 255));
  expect_same(chunked(many, 8), many, "255 labels");
  // A label only in the outermost layer of a block, and one voxel of 2 in 1.
  ScalarVolume edge = label_volume({20, 12, 12});
  for (int64_t k = 2; k < 10; ++k)
    for (int64_t j = 2; j < 10; ++j)
      for (int64_t i = 2; i < 18; ++i) set(edge, i, j, k, i == 8 ? 3 : 1);
  set(edge, 12, 5, 5, 2);
  expect_same(chunked(edge, 8), edge, "thin layers at block borders");
}

TEST(ChunkedLabels, SameBytesForAnyThreadCount) {
  const ScalarVolume phantom = test::phantom();
  ChunkedLabels one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = chunked(phantom, 8);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = chunked(phantom, 8);
  }
  EXPECT_EQ(one.surface.mesh.triangles, two.surface.mesh.triangles);
  EXPECT_EQ(one.surface.sides, two.surface.sides);
  EXPECT_EQ(0, std::memcmp(one.surface.mesh.positions.data(), two.surface.mesh.positions.data(),
                           one.surface.mesh.positions.size() * sizeof(Vec3)));
}

TEST(ChunkedLabels, BadVolumesAreRefusedAsInMemory) {
  test::expect_input_error([&] { chunked(label_volume({20, 20, 20}), 8); }, "test-labels", "no labelled sample");
  ScalarVolume grey = label_volume({20, 10, 10});
  grey.type = ScalarType::f32;
  grey.bytes.assign(grey.lattice.size() * 4, std::byte{0});
  const float x = 2.5f;
  std::memcpy(grey.bytes.data() + 4 * grey.lattice.linear(15, 5, 5), &x, 4);
  test::expect_input_error([&] { chunked(grey, 8); }, "test-labels", "not an integer label");
  ScalarVolume layered = label_volume({10, 10, 10});
  layered.components = 2;
  layered.bytes.assign(layered.lattice.size() * 2, std::byte{1});
  test::expect_input_error([&] { chunked(layered, 8); }, "test-labels", "layered");
  ChunkOptions halo;
  halo.chunk = 8;
  halo.halo = 2;
  const ScalarVolume p = test::phantom();
  EXPECT_THROW(extract_labels_chunked(p, [&](const Box& b) { return crop_scalar(p, b); }, halo), UsageError);
}

}  // namespace
}  // namespace voxpress
