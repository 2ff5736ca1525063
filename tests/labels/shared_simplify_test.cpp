// A label map's shared surface simplified once (issue 76, item 3): every
// label stays closed, 2-manifold, outward and free of self-intersection
// with every sample of the map on its side (double and float32), the
// labels of an interface keep the same triangles, the junction lines stay.
#include <filesystem>
#include <map>

#include "label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

size_t junction_edges(const Mesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> faces;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++faces[{std::min(t[size_t(k)], t[size_t((k + 1) % 3)]), std::max(t[size_t(k)], t[size_t((k + 1) % 3)])}];
  size_t n = 0;
  for (const auto& [e, count] : faces) n += count >= 3;
  return n;
}

void expect_simplified_labels_keep_every_guarantee(const ScalarVolume& v, double ratio) {
  SurfaceOptions plain;
  const SharedLabels full = press_shared_labels(v, label_table(v), plain);
  SurfaceOptions o;
  o.simplify.faces = uint64_t(ratio * double(full.surface.mesh.face_count()));
  const SharedLabels r = press_shared_labels(v, label_table(v), o);
  const SharedSurface& s = r.surface;
  EXPECT_EQ(r.simplify.faces_before, full.surface.mesh.face_count());
  EXPECT_EQ(r.simplify.faces_after, s.mesh.face_count());
  EXPECT_LE(s.mesh.face_count(), o.simplify.faces);
  EXPECT_EQ(s.sides.size(), s.mesh.face_count());
  EXPECT_EQ(s.kind.size(), s.mesh.vertex_count());
  EXPECT_GT(junction_edges(s.mesh), 0u) << "junction lines kept";
  size_t label_faces = 0;
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    const Mesh m = label_mesh(s, L);
    label_faces += m.face_count();
    test::expect_guarantees(m, test::whole_mask(v, double(s.labels[L])));
  }
  // Each interface triangle bounds two labels (one of them may be the
  // background, which has no mesh): shared, neither doubled nor dropped.
  size_t with_background = 0;
  for (const auto& sd : s.sides) with_background += sd[0] == 0 || sd[1] == 0;
  EXPECT_EQ(label_faces, 2 * s.mesh.face_count() - with_background);
}

TEST(SharedSimplify, PhantomKeepsEveryGuarantee) {
  expect_simplified_labels_keep_every_guarantee(test::phantom(), 0.25);
}

TEST(SharedSimplify, AssemblyOfBoxesKeepsEveryGuarantee) {
  expect_simplified_labels_keep_every_guarantee(test::assembly(2).volume, 0.05);
}

// The 61-label TotalSegmentator map to about 50,000 interface triangles:
// every label keeps every guarantee. A sample swept by an interface
// triangle of one label pair and back by one of another pair changes label
// though its winding sum is zero: before the sums were taken per pair, 2
// samples of label 5 ended on the wrong side here.
TEST(SharedSimplify, SixtyOneLabelMapKeepsEveryGuarantee) {
  const std::string path = test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "../shared is absent: " << path;
  expect_simplified_labels_keep_every_guarantee(read_volume(path), 0.12);
}

}  // namespace
}  // namespace voxpress
