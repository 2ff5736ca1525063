// The voxelizer: exact against its model, deterministic, strict about input.
#include "test_util.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"

namespace voxpress {
namespace {

Mesh in_physical(const Mesh& model, const Placement& p) {
  Mesh m = model;
  for (Vec3& x : m.positions) x = p.translation + p.linear * x;
  return m;
}

void expect_exact_voxelization(const Mesh& model, const std::string& name, int64_t res, const std::string& rotate) {
  SCOPED_TRACE(name + " " + rotate);
  VoxelizeOptions o;
  o.res = res;
  o.rotation = parse_rotation(rotate);
  const Voxelized v = voxelize(model, o, name);
  EXPECT_EQ(*std::max_element(v.volume.lattice.dims.begin(), v.volume.lattice.dims.end()), res);
  ASSERT_GT(v.volume.count_inside(), 0u);
  // Every sample is on the side of the original model the volume says.
  EXPECT_EQ(check_classification(in_physical(model, v.placement), v.volume).violations, 0u);
  // The midpoint surface of the voxelization is valid and separates the samples too.
  const Mesh mid = to_mesh(extract_sticks(v.volume));
  EXPECT_TRUE(check_mesh(mid, {false}).ok());
  EXPECT_EQ(check_classification(mid, v.volume).violations, 0u);
  // Same bytes twice.
  EXPECT_EQ(voxelize(model, o, name).volume.inside, v.volume.inside);
}

TEST(Voxelize, ExactAgainstTheModelAtRandomRotations) {
  for (const char* rot : {"random:1", "random:2", "random:3", "17,-40,123"}) {
    expect_exact_voxelization(cad_part_mesh(), "cad part", 64, rot);
    GenerateOptions o;
    o.res = 30;
    o.rotation = parse_rotation(rot);
    const Mesh blobby = to_mesh(extract_sticks(generate_shape(ShapeKind::torus, o).volume));
    expect_exact_voxelization(blobby, "torus midpoint mesh", 57, rot);
  }
}

TEST(Voxelize, MatchesTheAnalyticCadPartGeneration) {
  // generate cad-part is the voxelization of its B-rep: same lattice, same bytes.
  GenerateOptions g;
  g.res = 72;
  g.rotation = parse_rotation("random:5");
  VoxelizeOptions v;
  v.res = 72;
  v.rotation = g.rotation;
  EXPECT_EQ(generate_shape(ShapeKind::cad_part, g).volume.inside, voxelize(cad_part_mesh(), v).volume.inside);
}

TEST(Voxelize, SharedMeshes) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  for (const char* f : {"fandisk.off", "bunny.off", "plate_holes.STL", "fixed_top.ply", "thingi10k-65004.stl"})
    expect_exact_voxelization(read_mesh(test::shared_data() + "/meshes/" + f), f, 64, "random:9");
}

TEST(Voxelize, RefusesOpenAndNonManifoldMeshes) {
  Mesh open = cad_part_mesh();
  open.triangles.pop_back();
  try {
    voxelize(open, {}, "open.stl");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("open.stl"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("3 boundary edges"), std::string::npos) << e.what();
  }
  Mesh flipped = cad_part_mesh();
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_THROW(voxelize(flipped, {}, "x"), InputError);
  EXPECT_THROW(voxelize(Mesh{}, {}, "empty"), InputError);
  VoxelizeOptions bad;
  bad.res = 4;
  EXPECT_THROW(voxelize(cad_part_mesh(), bad), UsageError);
}

TEST(Voxelize, InwardOrientedMeshesWorkToo) {
  Mesh inward = cad_part_mesh();
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  VoxelizeOptions o;
  o.res = 40;
  EXPECT_EQ(voxelize(inward, o).volume.inside, voxelize(cad_part_mesh(), o).volume.inside);
}

TEST(Voxelize, PointContainment) {
  EXPECT_TRUE(mesh_contains(cad_part_mesh(), Vec3(0, -0.5, 0)));
  EXPECT_FALSE(mesh_contains(cad_part_mesh(), Vec3(0, -0.5, 0.3)));
  EXPECT_TRUE(mesh_contains(cad_part_mesh(), Vec3(1, 0, 0)));  // on the +x face: boundary counts as inside
}

}  // namespace
}  // namespace voxpress
