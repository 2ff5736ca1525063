// What the user gets is what is checked: the default press written in every
// mesh format and read back keeps every guarantee in that format's precision
// (STL and glTF store float32; PLY, OBJ, OFF, VTK and VTP the exact doubles).
#include "test_util.h"

namespace voxpress {
namespace {

void expect_every_format_keeps_the_guarantee(const BinaryVolume& volume, const std::string& name) {
  const SurfaceResult r = smooth_surface(volume);
  ASSERT_GT(r.sharpen.inserted, 0u) << "the case exercises the sharpening";
  test::TempDir dir;
  for (const char* ext : {".ply", ".obj", ".off", ".stl", ".glb", ".gltf", ".vtk", ".vtp"}) {
    SCOPED_TRACE(name + ext);
    const std::string path = dir.path("out" + std::string(ext));
    write_mesh(path, r.mesh);
    const Mesh back = read_mesh(path);
    ASSERT_EQ(back.face_count(), r.mesh.face_count());
    ASSERT_EQ(back.vertex_count(), r.mesh.vertex_count()) << "no two vertices round to one position";
    const MeshCheck mc = check_mesh(back);
    EXPECT_TRUE(mc.ok()) << (mc.problems.empty() ? "" : mc.problems[0]);
    EXPECT_EQ(check_classification(back, volume).violations, 0u);
  }
}

// Fandisk at 128^3, rotation 1: before the clearance its STL had 3 samples
// on the wrong side and 304 intersecting face pairs (the PLY none).
TEST(Written, RotatedRealMeshKeepsTheGuaranteeInEveryFormat) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const test::VoxelizedModel m = test::voxelized_shared_model("fandisk.off", 128, 1);
  expect_every_format_keeps_the_guarantee(m.volume, "fandisk 128");
}

// A generated part, anisotropic and far from the origin (larger
// coordinates: a larger float32 rounding to keep clear of).
TEST(Written, AnisotropicPartFarFromTheOriginKeepsTheGuaranteeInEveryFormat) {
  expect_every_format_keeps_the_guarantee(test::far_anisotropic_part(72), "cad part 72");
}

}  // namespace
}  // namespace voxpress
