// Pressing: guarantees on the whole property corpus, fidelity targets, the
// paper's Fig. 5 effect, slice-curve structure, frozen vertices, barriers.
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <set>

#include "test_util.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress {
namespace {

TEST(SliceCurves, EveryStickLiesOnOneClosedCurvePerPlaneFamily) {
  test::Rng rng(6);
  for (int rep = 0; rep < 10; ++rep) {
    const BinaryVolume v = rep % 2 ? test::random_noise(rng, {9, 8, 7}, 0.45) : test::random_blobs(rng, {12, 11, 10}, 3);
    const StickSurface s = extract_sticks(v);
    const SliceCurves c = build_slice_curves(s);
    std::vector<int> seen(3 * s.stick_count(), 0);
    for (int a = 0; a < 3; ++a)
      for (size_t k = 0; k + 1 < c.offsets[a].size(); ++k) {
        const uint32_t b = c.offsets[a][k], e = c.offsets[a][k + 1];
        ASSERT_GE(e - b, 4u) << "a closed marching-squares contour has at least 4 vertices";
        const int64_t plane = s.lower_index(c.ids[a][b])[size_t(a)];
        for (uint32_t i = b; i < e; ++i) {
          const uint32_t id = c.ids[a][i], next = c.ids[a][i + 1 < e ? i + 1 : b];
          ASSERT_NE(s.axis(id), a);
          ASSERT_EQ(s.lower_index(id)[size_t(a)], plane) << "a curve stays in its plane";
          // Consecutive vertices are mesh edge neighbours.
          bool edge = false;
          for (const Triangle& t : s.triangles)
            for (int q = 0; q < 3 && !edge; ++q)
              edge = (t[size_t(q)] == id && t[size_t((q + 1) % 3)] == next) || (t[size_t(q)] == next && t[size_t((q + 1) % 3)] == id);
          ASSERT_TRUE(edge);
          ++seen[3 * id + size_t(a)];
        }
        if (k > 0) {
          EXPECT_LE(s.lower_index(c.ids[a][c.offsets[a][k - 1]])[size_t(a)], plane) << "sorted by plane";
        }
      }
    for (size_t id = 0; id < s.stick_count(); ++id)
      for (int a = 0; a < 3; ++a) ASSERT_EQ(seen[3 * id + size_t(a)], a == s.axis(id) ? 0 : 1);
  }
}

TEST(Pressing, PropertyCorpusKeepsEveryGuarantee) {
  PressOptions o;
  o.iterations = 30;
  // Under the sanitizers one correction: the others change the arithmetic,
  // not the memory the iteration touches (CI time).
#ifdef VOXPRESS_SANITIZED
  const std::vector<double> corrections = {12.0};
#else
  const std::vector<double> corrections = {0.0, 12.0, 45.0};
#endif
  for (const test::Case& c : test::property_volumes())
    for (const double correction : corrections) {
      SCOPED_TRACE(c.name + " circle correction " + std::to_string(correction));
      o.circle_correction = correction;
      StickSurface s = extract_sticks(c.volume);
      const PressStats st = press(s, o);
      EXPECT_LE(st.iterations, o.iterations);
      for (double t : s.t) ASSERT_TRUE(t >= o.margin && t <= 1 - o.margin);
      test::expect_guarantees(to_mesh(s), c.volume);
    }
}

TEST(Pressing, QuadricFitKeepsEveryGuaranteeOnThePropertyCorpus) {
  PressOptions o;
  o.iterations = 30;
  size_t moved = 0, cases = 0;
  for (const test::Case& c : test::property_volumes()) {
    SCOPED_TRACE(c.name);
    StickSurface s = extract_sticks(c.volume);
    press(s, o);
    // Every vertex fresh, or (every other volume) every third one a junction.
    std::vector<uint8_t> junction(++cases % 2 ? 0 : s.stick_count());
    for (size_t i = 0; i < junction.size(); i += 3) junction[i] = 1;
    const std::vector<double> before = s.t;
    moved += fit_local_quadrics(s, {}, junction).moved;
    for (size_t i = 0; i < s.t.size(); ++i) {
      ASSERT_TRUE(s.t[i] >= o.margin && s.t[i] <= 1 - o.margin);
      if (!junction.empty() && junction[i]) {
        ASSERT_EQ(s.t[i], before[i]) << "a junction vertex moved";
      }
    }
    test::expect_guarantees(to_mesh(s), c.volume);
  }
  EXPECT_GT(moved, 0u);
  StickSurface s = extract_sticks(test::property_volumes().front().volume);
  EXPECT_THROW(fit_local_quadrics(s, std::vector<int32_t>(1, -1), {}), std::invalid_argument);
}

TEST(Pressing, GeneratedShapesAtRandomRotationsStayValid) {
  for (ShapeKind k : all_shapes())
    for (int seed : {11, 12}) {
      GenerateOptions g;
      g.res = 56;
      g.rotation = parse_rotation("random:" + std::to_string(seed));
      g.spacing = seed == 12 ? Vec3(1, 0.8, 1.7) : Vec3(1, 1, 1);  // anisotropic too
      const GeneratedShape shape = generate_shape(k, g);
      StickSurface s = extract_sticks(shape.volume);
      press(s);
      const Mesh m = to_mesh(s);
      EXPECT_TRUE(check_mesh(m).ok()) << shape_name(k) << " " << seed;
      EXPECT_EQ(check_classification(m, shape.volume).violations, 0u) << shape_name(k) << " " << seed;
    }
}

EvalReport evaluate_pressed(ShapeKind k, int64_t res, const PressOptions& o, const Vec3& spacing = Vec3(1, 1, 1)) {
  GenerateOptions g;
  g.res = res;
  g.rotation = parse_rotation("random:3");
  g.spacing = spacing;
  const GeneratedShape shape = generate_shape(k, g);
  StickSurface s = extract_sticks(shape.volume);
  press(s, o);
  EvalOptions e;
  e.volume = &shape.volume;
  e.samples = 100000;
  e.self_intersections = false;
  return evaluate(to_mesh(s), *shape_truth(k, shape.linear, shape.translation), e);
}

TEST(Pressing, MeetsTheFidelityTargetsOnSphereAndTorus) {
  // Issue 4: result -> truth RMS <= 0.06 voxel and normal error < 1.5 degrees
  // at 128^3 (the midpoint surface: ~0.16 and ~20 degrees).
  for (ShapeKind k : {ShapeKind::sphere, ShapeKind::torus}) {
    const EvalReport r = evaluate_pressed(k, 128, {});
    EXPECT_LE(r.result_to_truth_vox.rms, 0.06) << shape_name(k);
    EXPECT_LT(r.normal_error_deg, 1.5) << shape_name(k);
    EXPECT_EQ(*r.classification_violations, 0u);
  }
}

TEST(Pressing, QuadricFitBringsTightCurvesCloserToTheTruth) {
  // The bilaplacian presses tight curves towards the inner ends of their
  // sticks; the local quadric fit (with its stick constraints) does not.
  // A torus at 64^3 (tube radius ~5 cells) and spheres of radius 18-25
  // cells, whose gain depends on how the sphere meets the lattice: r->t
  // RMS after / before measured 0.69-0.77 on the torus over 6 rotations,
  // 0.78-0.91 on these spheres (1.01-1.05 at 47 and 61, where the press
  // alone is already close).
  double log_gain = 0;
  const std::vector<std::pair<ShapeKind, int>> cases{
      {ShapeKind::torus, 64}, {ShapeKind::sphere, 40}, {ShapeKind::sphere, 44}, {ShapeKind::sphere, 48}, {ShapeKind::sphere, 52}};
  for (const auto& [k, res] : cases) {
    GenerateOptions g;
    g.res = res;
    g.rotation = parse_rotation("random:3");
    const GeneratedShape shape = generate_shape(k, g);
    StickSurface s = extract_sticks(shape.volume);
    press(s);
    EvalOptions e;
    e.volume = &shape.volume;
    e.samples = 100000;
    e.self_intersections = false;
    const auto truth = shape_truth(k, shape.linear, shape.translation);
    const double before = evaluate(to_mesh(s), *truth, e).result_to_truth_vox.rms;
    const QuadricFitStats st = fit_local_quadrics(s, {}, {});
    EXPECT_GT(st.moved, s.stick_count() / 2) << shape_name(k);
    const EvalReport after = evaluate(to_mesh(s), *truth, e);
    const double gain = after.result_to_truth_vox.rms / before;
    EXPECT_LT(gain, k == ShapeKind::torus ? 0.85 : 0.95) << shape_name(k) << " " << res << ": " << before << " -> "
                                                         << after.result_to_truth_vox.rms;
    log_gain += std::log(gain);
    EXPECT_EQ(*after.classification_violations, 0u);
  }
  EXPECT_LT(std::exp(log_gain / double(cases.size())), 0.88);  // measured 0.84
}

TEST(Pressing, AnisotropicSpacingWorksInPhysicalSpace) {
  // A sphere sampled on 1 x 1 x 2 cells: smoothing in physical space still
  // converges to the sphere (distances in voxel units of the finer axes).
  const EvalReport r = evaluate_pressed(ShapeKind::sphere, 96, {}, Vec3(1, 1, 2));
  EXPECT_LT(r.result_to_truth.rms, 0.08);
  EXPECT_LT(r.normal_error_deg, 2.0);
  EXPECT_EQ(*r.classification_violations, 0u);
}

// A disk of radius R centred at (cx, cy) in a size x size binary image,
// its contours pressed: the mean and RMS of the vertices' radial errors
// (negative: inside the circle).
struct DiskError {
  double mean, rms;
  int levels;  // coarse-to-fine stages the press used
};
DiskError pressed_disk(int size, double R, double cx, double cy, const PressOptions& o) {
  std::vector<uint8_t> img(size_t(size * size));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) img[size_t(y * size + x)] = (x - cx) * (x - cx) + (y - cy) * (y - cy) <= R * R;
  Contours2D c = extract_contours(size, size, img);
  const int levels = press(c, o).levels;
  double sum = 0, s2 = 0;
  for (size_t v = 0; v < c.t.size(); ++v) {
    const auto p = c.position(v);
    const double e = std::hypot(p[0] - cx, p[1] - cy) - R;
    sum += e;
    s2 += e * e;
  }
  return {sum / double(c.t.size()), std::sqrt(s2 / double(c.t.size())), levels};
}

TEST(Pressing, ArcLengthResamplingBeatsThePlainBilaplacian) {
  // The paper's Fig. 5: bilaplacian of the actual neighbours + snapping gets
  // stuck; resampling at fixed arc length converges. 3D sphere and 2D circle.
  PressOptions resampled, plain;
  plain.resample = false;
  const EvalReport a = evaluate_pressed(ShapeKind::sphere, 64, resampled);
  const EvalReport b = evaluate_pressed(ShapeKind::sphere, 64, plain);
  EXPECT_LT(a.result_to_truth.rms, 0.5 * b.result_to_truth.rms);
  EXPECT_LT(a.normal_error_deg, b.normal_error_deg);
  const double r_resampled = pressed_disk(61, 20.3, 30.2, 29.7, resampled).rms;
  const double r_plain = pressed_disk(61, 20.3, 30.2, 29.7, plain).rms;
  EXPECT_LT(r_resampled, 0.6 * r_plain);
  EXPECT_LT(r_resampled, 0.08);
}

TEST(Pressing, SameResultForOneAndManyThreads) {
  test::Rng rng(2);
  const BinaryVolume v = test::random_blobs(rng, {40, 36, 30}, 4);
  for (const double correction : {0.0, 12.0}) {
    PressOptions o;
    o.circle_correction = correction;
    StickSurface one = extract_sticks(v), many = one;
    {
      tbb::task_arena arena(1);
      arena.execute([&] { press(one, o); });
    }
    {
      tbb::task_arena arena(std::max(2, tbb::info::default_concurrency()));
      arena.execute([&] { press(many, o); });
    }
    EXPECT_EQ(one.t, many.t) << "circle correction " << correction;
  }
}

TEST(Pressing, CircleCorrectionKeepsTightCurvesRound) {
  // The bilaplacian moves a circle of radius R inwards by about
  // s^2 d^4 / (4 R^3) per iteration, so tight curves end pressed against the
  // inner ends of their sticks; with the circle correction (the default)
  // circles are fixed points. A disk of radius 9.3 pixels (mean signed
  // radial error) and a sphere at 32^3 (radius ~13 cells; result -> truth).
  PressOptions paper, corrected;
  paper.circle_correction = 0;
  const DiskError p = pressed_disk(27, 9.3, 13.2, 12.7, paper), c = pressed_disk(27, 9.3, 13.2, 12.7, corrected);
  EXPECT_LT(p.mean, 0) << "the paper's bilaplacian presses the circle inwards";
  EXPECT_LT(std::abs(c.mean), 0.5 * std::abs(p.mean)) << p.mean << " -> " << c.mean;
  EXPECT_LT(c.rms, p.rms);
  const EvalReport a = evaluate_pressed(ShapeKind::sphere, 32, paper);
  const EvalReport b = evaluate_pressed(ShapeKind::sphere, 32, corrected);
  EXPECT_LT(b.result_to_truth_vox.rms, 0.8 * a.result_to_truth_vox.rms)
      << a.result_to_truth_vox.rms << " -> " << b.result_to_truth_vox.rms;
  EXPECT_EQ(*b.classification_violations, 0u);
}

TEST(Pressing, LevelsGrowWithTheExtent) {
  // PressOptions::levels = 0: 2 coarse-to-fine stages below 192 cells, one
  // more each time the extent doubles. The slow modes of the bilaplacian
  // are as long as the solid, so a larger solid needs a coarser first
  // stage: on a disk of radius 120 pixels the third stage brings the
  // contour closer to the circle than two stages in the same 100 iterations.
  PressOptions automatic, two;
  two.levels = 2;
  EXPECT_EQ(pressed_disk(61, 20.3, 30.2, 29.7, automatic).levels, 2);
  const DiskError a = pressed_disk(260, 120.3, 130.2, 129.7, automatic), b = pressed_disk(260, 120.3, 130.2, 129.7, two);
  EXPECT_EQ(a.levels, 3);
  EXPECT_EQ(b.levels, 2);
  EXPECT_LT(a.rms, 0.8 * b.rms) << b.rms << " -> " << a.rms;
}

TEST(Pressing, FrozenVerticesNeverMoveAndBarriersCutCurves) {
  test::Rng rng(3);
  const BinaryVolume v = test::random_blobs(rng, {30, 28, 26}, 3);
  StickSurface s = extract_sticks(v);
  std::vector<uint8_t> frozen(s.stick_count(), 0), barrier(s.stick_count(), 0);
  for (size_t i = 0; i < s.t.size(); ++i) {
    if (rng.uniform() < 0.2) {
      frozen[i] = 1;
      s.t[i] = 0.2 + 0.6 * rng.uniform();
      if (rng.uniform() < 0.3) barrier[i] = 1;
    }
  }
  const std::vector<double> before = s.t;
  const SliceCurves c = build_slice_curves(s);
  const PressStats st = press(s, c, {}, frozen, barrier);
  EXPECT_EQ(st.frozen, size_t(std::count(frozen.begin(), frozen.end(), 1)));
  size_t moved = 0;
  for (size_t i = 0; i < s.t.size(); ++i) {
    if (frozen[i])
      ASSERT_EQ(s.t[i], before[i]);
    else
      moved += s.t[i] != before[i];
  }
  EXPECT_GT(moved, s.t.size() / 2);
  const Mesh m = to_mesh(s);
  EXPECT_TRUE(check_mesh(m).ok());
  EXPECT_EQ(check_classification(m, v).violations, 0u);
  std::vector<uint8_t> not_frozen_barrier(s.stick_count(), 0);
  not_frozen_barrier[0] = 1;
  EXPECT_THROW(press(s, c, {}, {}, not_frozen_barrier), std::invalid_argument);
}

TEST(Pressing, StopsAtTheToleranceAndReportsIterations) {
  GenerateOptions g;
  g.res = 40;
  StickSurface s = extract_sticks(generate_shape(ShapeKind::sphere, g).volume);
  PressOptions o;
  o.iterations = 1000;
  o.tolerance = 1e-3;
  const PressStats st = press(s, o);
  EXPECT_LT(st.iterations, 1000);
  EXPECT_LE(st.residual, 1e-3);
  EXPECT_GT(st.curves, 0u);
  EXPECT_EQ(st.fresh, s.stick_count());
}

TEST(Contours2D, MatchTheSquareRuleAndStayClosed) {
  // Two pixels touching at a corner make two separate contours (the face rule).
  Contours2D c = extract_contours(2, 2, {1, 0, 0, 1});
  EXPECT_EQ(c.offsets.size() - 1, 2u);
  EXPECT_EQ(c.t.size(), 8u);
  // A pressed ring keeps its vertices inside their sticks.
  std::vector<uint8_t> img(30 * 20);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 30; ++x) {
      const double r = std::hypot(x - 14.5, y - 9.7);
      img[size_t(y * 30 + x)] = r < 8.3 && r > 3.1;
    }
  c = extract_contours(30, 20, img);
  EXPECT_EQ(c.offsets.size() - 1, 2u);  // outer and inner boundary
  press(c);
  for (double t : c.t) EXPECT_TRUE(t > 0 && t < 1);
}

}  // namespace
}  // namespace voxpress
