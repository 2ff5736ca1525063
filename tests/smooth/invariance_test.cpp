// Invariance: the same solid sampled on a shifted, padded or cropped lattice
// (the origin moved so that every sample keeps its physical place) gives the
// same t on every stick and the same surface (issue 74, item 2): every
// stage (flats, press, fit, sharpening) runs on the sticks' own box
// (on_own_box), and the simplifier works from the mesh's own box.
#include <array>
#include <cmath>

#include "test_util.h"

namespace voxpress {
namespace {

using test::cropped;
using test::reframed;  // padded by lo before and hi after each axis, the solid where it was

// A generated shape at 48^3, rotated by seed.
BinaryVolume shape48(ShapeKind kind, int seed) {
  GenerateOptions g;
  g.res = 48;
  g.rotation = parse_rotation("random:" + std::to_string(seed));
  return generate_shape(kind, g).volume;
}

// The pressing stages that keep one vertex per stick (`o`'s) on both volumes: the same sticks, shifted by the
// same integers, and t within 1e-9 of each other.
void expect_same_t(const BinaryVolume& a, const BinaryVolume& b, const SurfaceOptions& o) {
  StickSurface sa = extract_sticks(a), sb = extract_sticks(b);
  ASSERT_EQ(sa.stick_count(), sb.stick_count());
  ASSERT_GT(sa.stick_count(), 0u);
  SurfaceResult ra, rb;
  press_stick_surface(sa, o, ra);
  press_stick_surface(sb, o, rb);
  EXPECT_GT(ra.press.iterations, 0);
  EXPECT_EQ(ra.flats.flats.size(), rb.flats.flats.size());
  const auto la0 = sa.lower_index(0), lb0 = sb.lower_index(0);
  double worst = 0;
  size_t moved = 0;
  for (size_t i = 0; i < sa.stick_count(); ++i) {
    const auto la = sa.lower_index(i), lb = sb.lower_index(i);
    for (size_t k = 0; k < 3; ++k) ASSERT_EQ(la[k] - la0[k], lb[k] - lb0[k]) << "stick " << i;
    ASSERT_EQ(sa.axis(i), sb.axis(i));
    worst = std::max(worst, std::abs(sa.t[i] - sb.t[i]));
    moved += sa.t[i] != 0.5;
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_GT(moved, sa.stick_count() / 2);  // the stages did run
}

// The whole default pipeline (and the simplifier) on both volumes: the
// same triangles, the same labelled edges and regions, and positions equal
// within 1e-9 cell (the physical origin's rounding).
void expect_same_surface(const BinaryVolume& a, const BinaryVolume& b, const SurfaceOptions& o) {
  const SurfaceResult ra = smooth_surface(a, o), rb = smooth_surface(b, o);
  ASSERT_EQ(ra.mesh.vertex_count(), rb.mesh.vertex_count());
  EXPECT_EQ(ra.mesh.triangles, rb.mesh.triangles);
  EXPECT_EQ(ra.mesh.edges, rb.mesh.edges);
  EXPECT_EQ(ra.flats.flats.size(), rb.flats.flats.size());
  EXPECT_EQ(ra.flats.region, rb.flats.region);
  double worst = 0;  // cells
  for (size_t v = 0; v < ra.mesh.vertex_count(); ++v) {
    const Vec3 d = a.lattice.to_index(ra.mesh.positions[v]) - a.lattice.to_index(rb.mesh.positions[v]);
    worst = std::max(worst, d.cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_GT(ra.flats.flats.size() + ra.mesh.edges.size(), 0u);  // the feature layer did run
}

TEST(Invariance, DefaultPipelineOnShiftedPaddedAndCroppedVolumes) {
  for (const auto& [kind, seed] : {std::pair{ShapeKind::cad_part, 3}, std::pair{ShapeKind::box, 7}}) {
    SCOPED_TRACE(std::string(shape_name(kind)) + " seed " + std::to_string(seed));
    const BinaryVolume v = shape48(kind, seed);
    SurfaceOptions o;
    expect_same_surface(v, reframed(v, {6, 7, 8}, {5, 5, 5}), o);
    o.simplify.faces = 2000;
    expect_same_surface(v, cropped(v), o);
  }
}

TEST(Invariance, ShiftedAndPaddedRotatedSphereGivesTheSameT) {
  // The stages' t on a curved shape (the CAD part and the box: above).
  const BinaryVolume v = shape48(ShapeKind::sphere, 5);
  const BinaryVolume p = reframed(v, {6, 7, 8}, {5, 5, 5});  // shifted by (1, 2, 3) and padded by 5
  SurfaceOptions o;
  expect_same_t(v, p, o);
  expect_same_t(v, cropped(v), o);
}

TEST(Invariance, MovedOriginGivesTheSameT) {
  // The same samples with the lattice's origin moved (a NIfTI or NRRD in
  // scanner coordinates): every stage, the flats included, gives the same t.
  // The flats' junction tests once measured heights over planes whose offset
  // included the origin from points that did not.
  for (const auto& [kind, seed] : {std::pair{ShapeKind::cad_part, 3}, std::pair{ShapeKind::box, 7}}) {
    SCOPED_TRACE(std::string(shape_name(kind)) + " seed " + std::to_string(seed));
    const BinaryVolume v = shape48(kind, seed);
    BinaryVolume moved = v;
    moved.lattice.origin = Vec3(-181.25, 97.5, 1203.75);  // exact in binary: no rounding in the move itself
    SurfaceOptions o;
    expect_same_t(v, moved, o);
  }
}

TEST(Invariance, RealMaskShiftedPaddedAndCroppedGivesTheSameT) {
  // The default stages: the aorta has no flat.
  VOXPRESS_REQUIRE_SHARED_DATA();
  const BinaryVolume v = binarize(read_volume(test::shared_data() + "/medical/totalseg_aorta.nii.gz"));
  SurfaceOptions o;
  expect_same_t(v, reframed(v, {1, 2, 3}, {4, 0, 2}), o);
  expect_same_t(v, cropped(v), o);
}

}  // namespace
}  // namespace voxpress
