// smooth_surface: every method from one call, each with what it promises.
#include "test_util.h"

namespace voxpress {
namespace {

TEST(Pipeline, EveryMethodGivesAClosedSurfaceAndTheGuaranteedOnesKeepEverySample) {
  GenerateOptions g;
  g.res = 40;
  g.rotation = parse_rotation("random:6");
  const GeneratedShape part = generate_shape(ShapeKind::cad_part, g);
  for (Method m : {Method::pressing, Method::cesn, Method::diamond, Method::cell_edge, Method::cell_size, Method::taubin,
                   Method::laplacian}) {
    SCOPED_TRACE(method_name(m));
    EXPECT_EQ(parse_method(method_name(m)), m);
    SurfaceOptions o;
    o.method = m;
    const SurfaceResult r = smooth_surface(part.volume, o);
    EXPECT_EQ(r.extract.sticks, extract_sticks(part.volume).stick_count());
    const MeshCheck c = check_mesh(r.mesh, {.self_intersections = false});
    EXPECT_TRUE(c.closed() && c.manifold() && c.oriented());
    const uint64_t violations = check_classification(r.mesh, part.volume).violations;
    if (keeps_classification(m)) {
      EXPECT_EQ(violations, 0u);
    } else {
      EXPECT_GT(violations, 0u);  // the baselines do move samples to the wrong side here
    }
  }
}

TEST(Pipeline, PressingStagesAndOverridesAreHonoured) {
  GenerateOptions g;
  g.res = 48;
  g.rotation = parse_rotation("random:2");
  const GeneratedShape box = generate_shape(ShapeKind::box, g);
  SurfaceOptions o;
  const SurfaceResult full = smooth_surface(box.volume, o);
  EXPECT_GT(full.flats.flats.size(), 0u);
  EXPECT_GT(full.mesh.edges.size(), 0u);  // sharp edges inserted
  o.sharpen = false;
  const SurfaceResult chamfered = smooth_surface(box.volume, o);
  EXPECT_TRUE(chamfered.mesh.edges.empty());
  EXPECT_EQ(chamfered.mesh.vertex_count(), chamfered.extract.sticks);
  o.flats = false;
  o.overrides.iterations = 3;
  const SurfaceResult plain = smooth_surface(box.volume, o);
  EXPECT_TRUE(plain.flats.flats.empty());
  EXPECT_EQ(plain.press.iterations, 3);
}

TEST(Pipeline, RefusesBadOptionsAndEmptyVolumes) {
  SurfaceOptions o;
  o.method = Method::diamond;
  o.overrides.lambda = 0.3;
  const BinaryVolume ball = generate_shape(ShapeKind::sphere, GenerateOptions{}).volume;
  EXPECT_THROW(smooth_surface(ball, o), UsageError);
  EXPECT_THROW(parse_method("smooth"), UsageError);
  EXPECT_THROW(smooth_surface(test::make_volume(4, 4, 4)), InputError);
}

}  // namespace
}  // namespace voxpress
