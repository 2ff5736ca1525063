// smooth_surface: every method from one call, each with what it promises.
#include <tbb/global_control.h>

#include <cmath>
#include <functional>

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
  o.passes.disable(Pass::sharpen);
  const SurfaceResult chamfered = smooth_surface(box.volume, o);
  EXPECT_TRUE(chamfered.mesh.edges.empty());
  EXPECT_EQ(chamfered.mesh.vertex_count(), chamfered.extract.sticks);
  // The quadric fit after pressing moves only curved vertices (a box's
  // chamfers here), and not at all when off.
  EXPECT_GT(chamfered.fit.moved, 0u);
  EXPECT_LE(chamfered.fit.moved, chamfered.fit.fitted);
  EXPECT_LE(chamfered.fit.fitted, chamfered.extract.sticks - chamfered.flats.frozen_count());
  o.fit.rings = 0;
  EXPECT_EQ(smooth_surface(box.volume, o).fit.fitted, 0u);
  o.passes.disable(Pass::flats);
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
  // Out-of-range options are the library's one usage error (the CLI and
  // Python share it).
  for (auto bad : std::vector<std::function<void(SurfaceOptions&)>>{
           [](SurfaceOptions& s) { s.press.iterations = -1; },
           [](SurfaceOptions& s) { s.press.tolerance = std::nan(""); },
           [](SurfaceOptions& s) { s.flat.junction_angle = -5; },
           [](SurfaceOptions& s) { s.sharp.sharp_angle = 400; },
           [](SurfaceOptions& s) { s.press.margin = 0; },
           [](SurfaceOptions& s) { s.overrides.iterations = -3; }}) {
    SurfaceOptions s;
    bad(s);
    EXPECT_THROW(validate(s), UsageError);
    EXPECT_THROW(smooth_surface(ball, s), UsageError);
  }
  EXPECT_NO_THROW(validate(SurfaceOptions{}));
  // A lattice whose float32 rounding would reach the pressing clearance.
  BinaryVolume far = ball;
  far.lattice.origin = Vec3(1e5, 0, 0);
  far.lattice.spacing = Vec3(0.5, 0.5, 0.5);
  EXPECT_THROW(smooth_surface(far), InputError);
}

// Deterministic (issue 11): the same bytes for 1 and 4 threads on a spread
// of the property-test volumes, for the reference method with every stage
// and for two of the others.
TEST(Pipeline, SameMeshForOneAndManyThreadsOnThePropertyVolumes) {
  const auto cases = test::property_volumes();
  int compared = 0;
  for (size_t i = 0; i < cases.size(); i += 5) {
    const test::Case& c = cases[i];
    for (Method m : {Method::pressing, Method::cesn, Method::diamond}) {
      SCOPED_TRACE(c.name + " " + method_name(m));
      auto run = [&](int threads) -> std::optional<Mesh> {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
        SurfaceOptions o;
        o.method = m;
        try {
          return smooth_surface(c.volume, o).mesh;
        } catch (const InputError&) {
          return std::nullopt;  // empty or full volume: refused the same way each time
        }
      };
      const auto one = run(1), many = run(4);
      ASSERT_EQ(one.has_value(), many.has_value());
      if (!one) continue;
      EXPECT_EQ(one->triangles, many->triangles);
      EXPECT_EQ(one->positions, many->positions);
      ++compared;
    }
  }
  EXPECT_GT(compared, 50);
}

TEST(Passes, TableIsInRunningOrderAndNamesRoundTrip) {
  const auto& passes = feature_passes();
  ASSERT_EQ(passes.size(), size_t(Pass::count));
  for (size_t i = 0; i < passes.size(); ++i) {
    EXPECT_EQ(size_t(passes[i].pass), i) << passes[i].name;
    EXPECT_EQ(parse_pass(passes[i].name), passes[i].pass);
    EXPECT_STRNE(passes[i].section, "");
    if (i > 0) {
      EXPECT_GE(passes[i].stage, passes[i - 1].stage) << passes[i].name;  // stages in pipeline order
    }
    if (passes[i].needs != Pass::count) {
      EXPECT_LT(size_t(passes[i].needs), i) << passes[i].name;
    }
  }
  EXPECT_THROW(parse_pass("no-such-pass"), UsageError);
  PassSet s;
  s.disable("walls");
  s.disable(Pass::flats);
  EXPECT_FALSE(s.on(Pass::walls));
  EXPECT_TRUE(s.on(Pass::snap));
  EXPECT_EQ(s.disabled(), (std::vector<std::string>{"flats", "walls"}));
}

TEST(Passes, TheDriverRunsEachStageInTableOrder) {
  // A rotated CAD part has flats, junctions (crease rounds) and creases:
  // every stage runs. Switched-off passes leave the trace, and a pass whose
  // `needs` is off does too.
  GenerateOptions g;
  g.res = 40;
  g.rotation = parse_rotation("random:3");
  const GeneratedShape part = generate_shape(ShapeKind::cad_part, g);
  for (const char* off : {"", "snap", "curved-creases", "junctions", "moves"}) {
    SCOPED_TRACE(off);
    SurfaceOptions o;
    if (*off) o.passes.disable(off);
    const SurfaceResult r = smooth_surface(part.volume, o);
    const std::vector<Pass>& trace = r.pass_times.trace;
    test::expect_trace_follows_table(trace, o.passes);
    for (Stage st : {Stage::detect, Stage::crease_round, Stage::fit, Stage::sharpen}) {
      if (st == Stage::crease_round && !o.passes.on(Pass::junctions)) continue;  // no junction, no crease round
      EXPECT_TRUE(std::any_of(trace.begin(), trace.end(), [&](Pass p) { return feature_passes()[size_t(p)].stage == st; }))
          << "stage " << int(st) << " never ran";
    }
    if (*off) {
      const Pass p = parse_pass(off);
      EXPECT_EQ(std::count(trace.begin(), trace.end(), p), 0);
      if (p == Pass::curved_creases) {
        EXPECT_EQ(std::count(trace.begin(), trace.end(), Pass::final_curved_creases), 0);
      }
    }
  }
}

TEST(Passes, EachPassOffKeepsTheGuarantees) {
  // Every pass switched off alone on a rotated CAD part (flats, fillets,
  // creases): the result still keeps every sample on its side and is a
  // closed, oriented 2-manifold; the pass's own count drops to 0.
  GenerateOptions g;
  g.res = 40;
  g.rotation = parse_rotation("random:3");
  const GeneratedShape part = generate_shape(ShapeKind::cad_part, g);
  for (const PassInfo& p : feature_passes()) {
    SCOPED_TRACE(p.name);
    SurfaceOptions o;
    o.passes.disable(p.pass);
    const SurfaceResult r = smooth_surface(part.volume, o);
    EXPECT_EQ(r.pass_times.count[size_t(p.pass)], 0u);
    EXPECT_TRUE(check_mesh(r.mesh).ok());
    EXPECT_EQ(check_classification(r.mesh, part.volume).violations, 0u);
  }
}

}  // namespace
}  // namespace voxpress
