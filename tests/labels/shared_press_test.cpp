// Pressing of shared surfaces: the pressed phantom keeps every guarantee of
// the midpoint surface (every label closed, 2-manifold, outward, free of
// self-intersection, every sample of the whole map on its side, checked in
// double and float32; interfaces shared, no gap, no overlap), moves its
// junction lines, and a label meeting one other label alone is pressed as
// the binary press of its mask; an assembly of boxes gets its flats; the
// same bytes for 1 and N threads.
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

// Distance error of the phantom's nested sphere (label 3: radius 5 about
// x = 7 in the phantom's rotated frame, label_volumes.h), RMS over a mesh.
double sphere3_rms(const Mesh& m) {
  const double c = std::cos(0.4), s = std::sin(0.4);
  const Vec3 centre = Vec3(-12.5, 40.25, 7) + Vec3(22, 24, 22.5);
  double sum = 0;
  for (const Vec3& p : m.positions) {
    const Vec3 q = p - centre;
    const double x = c * q.x() - s * q.y(), y = s * q.x() + c * q.y();
    const double e = std::sqrt((x - 7) * (x - 7) + y * y + q.z() * q.z()) - 5;
    sum += e * e;
  }
  return std::sqrt(sum / double(m.positions.size()));
}

TEST(SharedPress, PressedPhantomKeepsEveryGuarantee) {
  const ScalarVolume v = test::phantom();
  const SharedSurface mid = extract_shared_surface(v);
  SharedSurface s = mid;
  const SharedPressStats st = press_shared(s);
  EXPECT_GT(st.junction_curves, 0u);
  EXPECT_GT(st.junction_moving, 0u);
  EXPECT_GT(st.interfaces.iterations, 1);
  // The sphere's interfaces with the box and with the background continue
  // each other through their junction points: some pieces are pressed on.
  EXPECT_GT(st.continued, 0u);
  EXPECT_LT(st.continued, st.plane_curves);
  size_t moved_faces = 0;
  for (size_t i = 0; i < s.mesh.positions.size(); ++i)
    moved_faces += s.kind[i] >= 3 && s.kind[i] < 6 && (s.mesh.positions[i] - mid.mesh.positions[i]).norm() > 1e-3;
  EXPECT_GT(moved_faces, 0u) << "the junction lines were not smoothed";
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    test::expect_guarantees(label_mesh(s, L), test::whole_mask(v, double(s.labels[L])));
  }
  EXPECT_EQ(s.mesh.triangles, mid.mesh.triangles);  // pressing moves vertices only
  // The nested sphere meets label 2 alone: its surface is the binary press
  // of its mask, and it is far closer to the true sphere than the midpoints.
  const Mesh pressed3 = label_mesh(s, 3), mid3 = label_mesh(mid, 3);
  StickSurface binary = extract_sticks(test::whole_mask(v, 3));
  press(binary);
  EXPECT_NEAR(sphere3_rms(pressed3), sphere3_rms(to_mesh(binary)), 1e-9);
  EXPECT_LT(sphere3_rms(pressed3), 0.5 * sphere3_rms(mid3));
}

// The quadric fit (shared_fit.h): the nested sphere's cubes belong to it
// (the higher label), so its surface is its binary press and fit; every
// label keeps every guarantee.
TEST(SharedFit, NestedSphereGetsItsBinaryFit) {
  const ScalarVolume v = test::phantom();
  SurfaceOptions o;
  o.passes.disable(Pass::flats);
  const SharedLabels r = press_shared_labels(v, label_table(v), o);
  EXPECT_GT(r.fit.moved, 0u);
  EXPECT_EQ(r.fit.labels, 4u);
  for (uint32_t L = 1; L < r.surface.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(r.surface.labels[L]));
    test::expect_guarantees(label_mesh(r.surface, L), test::whole_mask(v, double(r.surface.labels[L])));
  }
  StickSurface binary = extract_sticks(test::whole_mask(v, 3));
  press(binary);
  const double pressed = sphere3_rms(to_mesh(binary));
  EXPECT_GT(fit_local_quadrics(binary, {}, {}).moved, 0u);
  // The same fit up to the rounding of t read back from physical positions
  // (and not the press alone: the fit moved it).
  EXPECT_NEAR(sphere3_rms(label_mesh(r.surface, 3)), sphere3_rms(to_mesh(binary)), 1e-6);
  EXPECT_GT(std::abs(sphere3_rms(to_mesh(binary)) - pressed), 1e-4);
}

// Every label of the pressed surface keeps every guarantee (double and
// float32), and pressing moved the surface.
void expect_pressed(const ScalarVolume& v) {
  const SharedSurface mid = extract_shared_surface(v);
  SharedSurface s = mid;
  press_shared(s);
  EXPECT_NE(s.mesh.positions, mid.mesh.positions);
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    test::expect_guarantees(label_mesh(s, L), test::whole_mask(v, double(s.labels[L])));
  }
}

TEST(SharedPress, AdversarialLabelConfigurationsKeepEveryGuarantee) {
  {
    SCOPED_TRACE("checkerboards");
    expect_pressed(test::checkerboard3({9, 8, 7}));
    expect_pressed(test::checkerboard3({10, 9, 8}, 2, 0));
  }
  {  // a single voxel of 2 inside 1; labels touching along an edge and at a corner only
    ScalarVolume v = test::label_volume({10, 10, 10});
    for (int64_t k = 1; k < 5; ++k)
      for (int64_t j = 1; j < 5; ++j)
        for (int64_t i = 1; i < 5; ++i) test::set(v, i, j, k, 1);
    test::set(v, 2, 2, 2, 2);
    test::set(v, 6, 6, 6, 3);
    test::set(v, 7, 7, 6, 4);
    test::set(v, 7, 7, 7, 5);
    SCOPED_TRACE("voxel inside, edge and corner contacts");
    expect_pressed(v);
  }
  for (int seed = 0; seed < 3; ++seed) {  // three labels at random: junctions everywhere
    ScalarVolume v = test::label_volume({12, 11, 10}, {1, 1.3, 0.8});
    test::Rng r3{uint64_t(seed)};
    for (auto& b : v.bytes) b = std::byte(uint8_t(r3.range(0, 2)));
    SCOPED_TRACE("noise " + std::to_string(seed));
    expect_pressed(v);
  }
}

// The 61-label TotalSegmentator map as press --labels makes it: every label
// closed, 2-manifold, oriented, free of self-intersection, 0 violations, in
// double and float32.
TEST(SharedPress, SixtyOneLabelMap) {
  const std::string path = test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "../shared is absent: " << path;
  const ScalarVolume v = read_volume(path);
  // What press --labels does: press, flats, quadric fit, sharpening.
  const SharedLabels r = press_shared_labels(v, label_table(v), SurfaceOptions{});
  const SharedSurface& s = r.surface;
  EXPECT_GT(r.press.junction_moving, 0u);
  EXPECT_GT(r.fit.moved, 0u);
  EXPECT_GT(r.sharpen.inserted, 0u) << "the field of view's cut is sharpened";
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    test::expect_guarantees(label_mesh(s, L), test::whole_mask(v, double(s.labels[L])));
  }
}

// Issue 54, item 4: the shared surface of a CAD assembly gets its flats.
// Over rotations: each box's faces are found (its own six, the shared face
// seen from both sides), every label keeps every guarantee, and each label
// is closer to its true box than the shared press without flats.
TEST(SharedPress, AssemblyOfBoxesGetsItsFlats) {
  for (int seed : {1, 2, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const test::Assembly a = test::assembly(seed);
    const SharedSurface mid = extract_shared_surface(a.volume);
    SharedSurface plain = mid, flat = mid;
    press_shared(plain);
    const SharedFlats f = find_shared_flats(masks_in(a.volume), flat, label_table(a.volume).labels, PressOptions{}, FlatOptions{});
    for (uint32_t value : {1u, 2u})
      EXPECT_GE(f.flats_of(value), 5u) << "label " << value;
    const SharedPressStats st = press_shared(flat, PressOptions{}, &f);
    EXPECT_GT(st.flat_vertices, mid.stick_vertices / 2) << "most of a box is flat";
    for (uint32_t L = 1; L < flat.labels.size(); ++L) {
      SCOPED_TRACE("label " + std::to_string(flat.labels[L]));
      const Mesh m = label_mesh(flat, L), p = label_mesh(plain, L);
      test::expect_guarantees(m, test::whole_mask(a.volume, double(flat.labels[L])));
      auto rms = [&](const Mesh& mesh) {
        double sum = 0;
        for (const Vec3& x : mesh.positions) sum += std::pow(a.distance(int(flat.labels[L]), x), 2);
        return std::sqrt(sum / double(mesh.positions.size()));
      };
      EXPECT_LT(rms(m), 0.8 * rms(p));  // measured 0.16-0.68 over these seeds
    }
  }
}

TEST(SharedLabels, EachLabelRunsThePassTable) {
  // The shared surface's stages run the binary pipeline's pass table per
  // label through its driver: each label's detection, fit and sharpening
  // appear in the trace, and switching a pass off is honoured.
  const test::Assembly a = test::assembly(1);
  const LabelTable table = label_table(a.volume);
  const SharedLabels on = press_shared_labels(a.volume, table, SurfaceOptions{});
  const auto times = [](const SharedLabels& r, Pass p) {
    return size_t(std::count(r.passes.trace.begin(), r.passes.trace.end(), p));
  };
  EXPECT_GT(on.fit.labels, 0u);
  EXPECT_EQ(times(on, Pass::quadric_fit), on.fit.labels);
  EXPECT_GT(on.passes.count[size_t(Pass::quadric_fit)], 0u);
  EXPECT_GE(times(on, Pass::flats), 2u) << "both boxes' detection";
  EXPECT_EQ(times(on, Pass::moves), on.sharpen.labels);
  // The same sequence as a binary run: each stage's steps in table order,
  // the stages in pipeline order (every label's detection, then every
  // label's fit, then every label's sharpening).
  test::expect_trace_follows_table(on.passes.trace, SurfaceOptions{}.passes);
  SurfaceOptions off;
  off.passes.disable(Pass::quadric_fit);
  const SharedLabels r = press_shared_labels(a.volume, table, off);
  EXPECT_EQ(times(r, Pass::quadric_fit), 0u);
  EXPECT_EQ(r.fit.moved, 0u);
  test::expect_trace_follows_table(r.passes.trace, off.passes);
  for (uint32_t L = 1; L < r.surface.labels.size(); ++L)
    test::expect_guarantees(label_mesh(r.surface, L), test::whole_mask(a.volume, double(r.surface.labels[L])));
}

TEST(SharedPress, SameBytesForOneAndManyThreads) {
  const ScalarVolume v = test::checkerboard3({9, 8, 7}, 2, 0);
  SharedSurface one = extract_shared_surface(v), many = one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    press_shared(one);
  }
  press_shared(many);
  EXPECT_EQ(one.mesh.positions, many.mesh.positions);
  // With flats (found per label in parallel).
  const ScalarVolume boxes = test::assembly(4).volume;
  SharedSurface a = extract_shared_surface(boxes), b = a;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    const SharedFlats f = find_shared_flats(masks_in(boxes), a, label_table(boxes).labels, PressOptions{}, FlatOptions{});
    press_shared(a, PressOptions{}, &f);
  }
  const SharedFlats f = find_shared_flats(masks_in(boxes), b, label_table(boxes).labels, PressOptions{}, FlatOptions{});
  EXPECT_GT(f.frozen, 0u);
  press_shared(b, PressOptions{}, &f);
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  for (uint32_t L = 1; L < one.labels.size(); ++L)
    test::expect_guarantees(label_mesh(one, L), test::whole_mask(v, double(one.labels[L])));
}


// Issue 74, item 2, for label maps: the map padded (by 1, 2, 3 samples
// before and 5 after, the origin moved back) and cropped to the box of its
// labelled samples gives the same shared surface as press --labels makes it
// (flats, press, fit, sharpening): the same triangles, their labels, and
// positions within 1e-9 cell. Three and four labels meet in the phantom
// (apexes), the assembly has flats and sharp edges.
using test::cropped;
using test::reframed;

void expect_same_surface_when_reframed(const ScalarVolume& v) {
  const SharedLabels ref = press_shared_labels(v, label_table(v), SurfaceOptions{});
  EXPECT_GT(ref.surface.apex_vertices + ref.sharpen.inserted, 0u) << "apexes or creases to move";
  const double cell = std::cbrt(v.lattice.spacing.prod());
  for (const ScalarVolume& w : {reframed(v, {1, 2, 3}, {5, 5, 5}), cropped(v)}) {
    const SharedLabels r = press_shared_labels(w, label_table(w), SurfaceOptions{});
    ASSERT_EQ(r.surface.mesh.triangles, ref.surface.mesh.triangles);
    EXPECT_EQ(r.surface.sides, ref.surface.sides);
    ASSERT_EQ(r.surface.mesh.positions.size(), ref.surface.mesh.positions.size());
    double worst = 0;
    for (size_t i = 0; i < r.surface.mesh.positions.size(); ++i)
      worst = std::max(worst, (r.surface.mesh.positions[i] - ref.surface.mesh.positions[i]).norm() / cell);
    EXPECT_LT(worst, 1e-9);
  }
}

TEST(SharedPress, ShiftedPaddedAndCroppedPhantomGivesTheSameSurface) {
  expect_same_surface_when_reframed(test::phantom());
}

TEST(SharedPress, ShiftedPaddedAndCroppedAssemblyGivesTheSameSurface) {
  expect_same_surface_when_reframed(test::assembly(2).volume);
}

}  // namespace
}  // namespace voxpress
