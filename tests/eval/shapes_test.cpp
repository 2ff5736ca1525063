#include "test_util.h"

namespace voxpress {
namespace {

TEST(Shapes, SampledVolumeMatchesAnalyticVolume) {
  for (ShapeKind k : all_shapes())
    for (int seed : {1, 2}) {
      GenerateOptions o;
      o.res = 96;
      o.rotation = parse_rotation("random:" + std::to_string(seed));
      const GeneratedShape g = generate_shape(k, o);
      const double sampled = double(g.volume.count_inside());
      const double exact = shape_volume(k) * g.scale * g.scale * g.scale;
      EXPECT_NEAR(sampled / exact, 1.0, 0.01) << shape_name(k);
      // N samples along the physically longest side.
      EXPECT_EQ(*std::max_element(g.volume.lattice.dims.begin(), g.volume.lattice.dims.end()), 96);
    }
}

TEST(Shapes, MarginKeepsTheShapeOffTheBorder) {
  for (ShapeKind k : all_shapes()) {
    GenerateOptions o;
    o.res = 40;
    o.rotation = parse_rotation("random:9");
    const BinaryVolume v = generate_shape(k, o).volume;
    const auto& d = v.lattice.dims;
    for (int64_t kk = 0; kk < d[2]; ++kk)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i)
          if (i < 2 || j < 2 || kk < 2 || i >= d[0] - 2 || j >= d[1] - 2 || kk >= d[2] - 2) {
            ASSERT_FALSE(v.at(i, j, kk)) << shape_name(k);
          }
  }
}

TEST(Shapes, AnisotropicSpacingSamplesPhysicalSpace) {
  GenerateOptions iso, aniso;
  iso.res = aniso.res = 64;
  aniso.spacing = Vec3(1, 1, 2.5);
  const GeneratedShape a = generate_shape(ShapeKind::sphere, iso), b = generate_shape(ShapeKind::sphere, aniso);
  EXPECT_LT(b.volume.lattice.dims[2], a.volume.lattice.dims[2]);
  const double va = double(a.volume.count_inside()) / std::pow(a.scale, 3);
  const double vb = double(b.volume.count_inside()) * 2.5 / std::pow(b.scale, 3);
  EXPECT_NEAR(vb / va, 1.0, 0.03);
}

TEST(Shapes, RotationsAreDeterministicAndUniformish) {
  EXPECT_EQ(parse_rotation("random:5"), parse_rotation("random:5"));
  EXPECT_NE(parse_rotation("random:5"), parse_rotation("random:6"));
  const Mat3 r = parse_rotation("90,0,0");
  EXPECT_LT((r * Vec3::UnitY() - Vec3::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(parse_rotation("random:77").determinant(), 1.0, 1e-12);
  // The mean of R e_z over many seeds is near zero for a uniform distribution.
  Vec3 mean = Vec3::Zero();
  for (int s = 0; s < 2000; ++s) mean += parse_rotation("random:" + std::to_string(s)) * Vec3::UnitZ();
  EXPECT_LT((mean / 2000).norm(), 0.05);
  EXPECT_THROW(parse_rotation("random:x"), UsageError);
  EXPECT_THROW(parse_rotation("1,2"), UsageError);
  EXPECT_THROW(parse_shape("teapot"), UsageError);
}

TEST(Shapes, CadPartMeshIsAValidSolidMatchingItsClosedFormVolume) {
  const Mesh& m = cad_part_mesh();
  const MeshCheck r = check_mesh(m);
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0]);
  EXPECT_EQ(r.euler, 0);  // genus 1: the through hole
  EXPECT_NEAR(r.signed_volume, shape_volume(ShapeKind::cad_part), 2e-5);
}

TEST(Shapes, CadPartHasTheAdvertisedFeatures) {
  // Through hole: a vertical line through its axis is empty; boss and plate are solid.
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(-0.5, 0.1, 0)));
  EXPECT_TRUE(shape_contains(ShapeKind::cad_part, Vec3(-0.5, 0.4, 0)));
  EXPECT_TRUE(shape_contains(ShapeKind::cad_part, Vec3(0.3, 0, 0.7)));
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(0.3, 0, 0.8)));
  // Chamfer along the whole +x top edge; rounded -x vertical corners, sharp +x ones.
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(0.99, 0, 0.24)));
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(0.99, 0.69, 0.24)));
  EXPECT_TRUE(shape_contains(ShapeKind::cad_part, Vec3(0.99, 0, -0.24)));
  EXPECT_TRUE(shape_contains(ShapeKind::cad_part, Vec3(0.99, 0.69, 0)));
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(-0.99, 0.69, 0)));
  // Concave fillet at the boss base.
  EXPECT_TRUE(shape_contains(ShapeKind::cad_part, Vec3(0.3 + 0.36, 0, 0.26)));
  EXPECT_FALSE(shape_contains(ShapeKind::cad_part, Vec3(0.3 + 0.44, 0, 0.34)));
}

}  // namespace
}  // namespace voxpress
