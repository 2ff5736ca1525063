// Flats (plane voting) and junctions: the planes found on solids whose
// planar faces are known exactly, the guarantees of the pipeline on the
// property corpus, determinism, and the stick-level invariants.
#include <array>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "test_util.h"
#include "voxpress/eval/checks.h"
#include "voxpress/eval/shapes.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/features/flats.h"
#include "voxpress/smooth/pipeline.h"

namespace voxpress {
namespace {

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / std::numbers::pi;
}

struct FlatRun {
  GeneratedShape shape;
  StickSurface surface;
  FlatSegmentation seg;
  std::vector<PlanarFace> faces;  // physical
};

// A shape at res^3 under the random rotation `seed`.
GeneratedShape rotated(ShapeKind kind, int64_t res, int seed) {
  GenerateOptions go;
  go.res = res;
  go.rotation = parse_rotation("random:" + std::to_string(seed));
  return generate_shape(kind, go);
}

FlatRun run(ShapeKind kind, GeneratedShape shape, const FlatOptions& fo = {}) {
  FlatRun r;
  r.shape = std::move(shape);
  for (const PlanarFace& f : shape_planar_faces(kind)) r.faces.push_back(transform_face(f, r.shape.linear, r.shape.translation));
  r.surface = extract_sticks(r.shape.volume);
  const SliceCurves curves = build_slice_curves(r.surface);
  press_with_flats(r.surface, curves, {}, &fo, &r.seg);
  return r;
}

FlatRun run(ShapeKind kind, int64_t res, int seed, const FlatOptions& fo = {}) {
  return run(kind, rotated(kind, res, seed), fo);
}

// Index of the true face a flat matches (normal within 1 degree, offset
// within half a cell), or -1.
int match(const Flat& f, const std::vector<PlanarFace>& faces) {
  for (size_t i = 0; i < faces.size(); ++i)
    if (angle_deg(f.normal, faces[i].normal) < 1 && std::abs(f.offset - faces[i].offset) < 0.5) return int(i);
  return -1;
}

// How many flats match each face (match()), and how many match none.
struct Matches {
  std::vector<int> per_face;
  size_t unmatched = 0;
};
Matches match_all(const std::vector<Flat>& flats, const std::vector<PlanarFace>& faces) {
  Matches m;
  m.per_face.assign(faces.size(), 0);
  for (const Flat& f : flats) {
    const int k = match(f, faces);
    if (k < 0) ++m.unmatched;
    else ++m.per_face[size_t(k)];
  }
  return m;
}

// Every guarantee of the output: closed, manifold, oriented, no sample on
// the wrong side; frozen vertices exactly on their planes.
void expect_guarantees(const StickSurface& s, const FlatSegmentation& seg, const BinaryVolume& v) {
  for (double t : s.t) ASSERT_TRUE(t >= 0.01 && t <= 0.99);
  test::expect_guarantees(to_mesh(s), v);
  ASSERT_EQ(seg.region.size(), s.stick_count());
  for (size_t i = 0; i < s.stick_count(); ++i) {
    if (seg.region[i] < 0) continue;
    const Flat& f = seg.flats[size_t(seg.region[i])];
    ASSERT_NEAR(f.index_normal.dot(s.index_position(i)), f.index_offset, 1e-9) << "frozen vertex off its plane";
  }
}

// A box's run: exactly six flats, one per face, every guarantee kept.
void expect_six_faces(const FlatRun& r) {
  ASSERT_EQ(r.seg.flats.size(), 6u);
  const Matches m = match_all(r.seg.flats, r.faces);
  ASSERT_EQ(m.unmatched, 0u) << "a flat matches no face of the box";
  for (int u : m.per_face) EXPECT_EQ(u, 1) << "each face is found once";
  expect_guarantees(r.surface, r.seg, r.shape.volume);
}

// The CAD part's run: every planar face found, no flat matching none, every
// guarantee kept.
void expect_cad_faces(const FlatRun& r) {
  const Matches m = match_all(r.seg.flats, r.faces);
  ASSERT_EQ(m.unmatched, 0u) << "spurious flat";
  for (size_t i = 0; i < r.faces.size(); ++i)
    EXPECT_GE(m.per_face[i], 1) << "planar face " << i << " (area " << r.faces[i].area << ") not found";
  expect_guarantees(r.surface, r.seg, r.shape.volume);
}

TEST(Flats, RotatedBoxesHaveExactlySixFlatsWithinOneDegree) {
  for (int seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("box 128 seed " + std::to_string(seed));
    const FlatRun r = run(ShapeKind::box, 128, seed);
    expect_six_faces(r);
  }
}

TEST(Flats, RotatedBoxesAt64AlmostAlwaysHaveExactlySixFlats) {
  // At 64^3 the first pressed estimate of a box is a pillow whose smaller
  // faces spread like tangent strips; the second detection pass (estimate
  // pressed with the first pass's flats frozen) finds them. Measured over
  // seeds 1-30 (docs/BENCHMARKS.md): all 30 rotations give exactly the six
  // faces since the stabbing refit (29 before: seed 15 has two faces 2
  // degrees off a lattice axis, see FacesNearALatticeAxisAreFound). One
  // pass: 23 of 30, 162 faces. Before the refit's rounding fix and the
  // growth's slack: 28, 177 and 1 spurious. Here (CI time) seeds 1-12;
  // the 30 are bench_flats' sweep.
  size_t exact = 0, found = 0, spurious = 0;
  for (int seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE("box 64 seed " + std::to_string(seed));
    const FlatRun r = run(ShapeKind::box, 64, seed);
    const Matches m = match_all(r.seg.flats, r.faces);
    size_t bad = m.unmatched;  // flats matching no face, or a face already taken
    for (int u : m.per_face) bad += size_t(std::max(u - 1, 0));
    exact += r.seg.flats.size() == 6 && bad == 0;
    found += size_t(std::count_if(m.per_face.begin(), m.per_face.end(), [](int u) { return u > 0; }));
    spurious += bad;
    expect_guarantees(r.surface, r.seg, r.shape.volume);
  }
  EXPECT_EQ(exact, 12u) << "rotations with exactly the six faces, of 12";
  EXPECT_EQ(found, 72u) << "faces found, of 72";
  EXPECT_EQ(spurious, 0u) << "flats matching no face or a face already taken";
}

TEST(Flats, RotatedCylinderHasTwoCapsAndACurvedWall) {
  for (int64_t res : {64, 128})
    for (int seed = 1; seed <= 2; ++seed) {
      SCOPED_TRACE("cylinder " + std::to_string(res) + " seed " + std::to_string(seed));
      const FlatRun r = run(ShapeKind::cylinder, res, seed);
      ASSERT_EQ(r.seg.flats.size(), 2u);
      EXPECT_NE(match(r.seg.flats[0], r.faces), -1);
      EXPECT_NE(match(r.seg.flats[1], r.faces), -1);
      EXPECT_NE(match(r.seg.flats[0], r.faces), match(r.seg.flats[1], r.faces));
      // The wall is curved: most of it stays fresh (its area is 2 / (2 * 0.6 / 2) = 3.3 x the caps').
      const size_t fresh = size_t(std::count(r.seg.region.begin(), r.seg.region.end(), -1));
      EXPECT_GT(double(fresh), 0.6 * double(r.surface.stick_count()));
      // The caps meet the wall at 90 degrees: junctions, all next to a frozen vertex.
      EXPECT_GT(r.seg.stats.junctions, 0u);
      expect_guarantees(r.surface, r.seg, r.shape.volume);
    }
}

TEST(Flats, CadPartPlanarFacesFoundNoneSpurious) {
  // Seed 15: the plate's two end faces lie 2 degrees off z; before near-axis
  // planes were always searched (Detector::restab), axis-aligned planes
  // through one terrace each were taken for them (6 faces, 2 spurious).
  // Seed 20: the chamfer's cores lean 3-4 degrees and were refused; they
  // stab 0.70-0.74 of their neighbourhood, and refused cores were searched
  // only from 0.9 (7 faces). Seed 1's chamfer was missed before the
  // stabbing refit, and came out as two flats 0.26 degrees apart with the
  // circle correction until the merge also tried each flat's own plane
  // (no plane stabbed both cores; each plane stabbed 98 % of the other's
  // members): each face is one flat.
  for (int seed : {1, 3, 15, 20}) {  // (CI time: bench_flats --shape cad-part sweeps 30)
    SCOPED_TRACE("cad-part 128 seed " + std::to_string(seed));
    const FlatRun r = run(ShapeKind::cad_part, 128, seed);
    expect_cad_faces(r);
    const Matches m = match_all(r.seg.flats, r.faces);
    for (size_t i = 0; i < r.faces.size(); ++i) EXPECT_LE(m.per_face[i], 1) << "planar face " << i << " split";
  }
}

TEST(Flats, CadPartAt256FoundNoneSpurious) {
  // Two rotations at 256^3, where tangent strips of the rounded corners and
  // pieces of faces once came out as spurious flats (the curved-test and
  // merge passes; their effect is measured in bench/ablation).
  for (int seed : {3}) {  // (CI time; seed 30 as well in bench_flats)
    SCOPED_TRACE("cad-part 256 seed " + std::to_string(seed));
    expect_cad_faces(run(ShapeKind::cad_part, rotated(ShapeKind::cad_part, 256, seed)));
  }
}

TEST(Flats, OrganicShapesHaveNoFlats) {
  for (ShapeKind k : {ShapeKind::sphere, ShapeKind::torus}) {
    const FlatRun r = run(k, 128, 1);
    EXPECT_TRUE(r.seg.flats.empty()) << shape_name(k);
  }
}

TEST(Flats, WithoutFlatsTheResultIsThePlainPress) {
  // No flat found: press_with_flats keeps its estimate when that was the
  // very same press, else presses again; either way the bytes of press().
  const GeneratedShape g = rotated(ShapeKind::sphere, 48, 2);
  for (int levels : {0, 3}) {
    SCOPED_TRACE("levels " + std::to_string(levels));
    PressOptions po;
    po.levels = levels;
    StickSurface a = extract_sticks(g.volume), b = a;
    const SliceCurves curves = build_slice_curves(a);
    const FlatOptions fo;
    FlatSegmentation seg;
    const FeaturePressStats st = press_with_flats(a, curves, po, &fo, &seg);
    ASSERT_TRUE(seg.flats.empty());
    const PressStats plain = press(b, curves, po);
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(st.press.iterations, plain.iterations);
    EXPECT_EQ(st.press.levels, plain.levels);
  }
}

// The Table 2 stages of the full pipeline on `s`: stick error of
// "midpoint + tiles" and the evaluation of the final surface.
struct Stages {
  FlatSegmentation seg;
  double tiles = 0;
  EvalReport final_report;
};
Stages stages(StickSurface& s, const BinaryVolume& v, const Truth& truth) {
  Stages st;
  const FlatOptions fo;
  press_with_flats(s, build_slice_curves(s), {}, &fo, &st.seg);
  StickSurface tiles = s;
  apply_flats(tiles, st.seg);
  EvalOptions eo;
  eo.volume = &v;
  eo.samples = 50000;
  st.tiles = *evaluate(to_mesh(tiles), truth, eo).stick_rms_vox;
  st.final_report = evaluate(to_mesh(s), truth, eo);
  return st;
}

TEST(Flats, FlatsMakeTheBoxMoreAccurate) {
  const GeneratedShape g = rotated(ShapeKind::box, 96, 7);
  const auto truth = shape_truth(g.kind, g.linear, g.translation);
  StickSurface plain = extract_sticks(g.volume), flats = plain;
  press_with_flats(plain, build_slice_curves(plain), {}, nullptr);
  EvalOptions eo;
  eo.volume = &g.volume;
  eo.samples = 50000;
  const double e_plain = *evaluate(to_mesh(plain), *truth, eo).stick_rms_vox;
  const Stages st = stages(flats, g.volume, *truth);
  const double e_tiles = st.tiles, e_flats = *st.final_report.stick_rms_vox;
  EXPECT_LT(e_tiles, 0.2) << "midpoint + tiles (midpoint alone: 0.29)";
  EXPECT_LT(e_flats, 0.6 * e_plain) << "flats + smoothing vs smoothing alone";
}

// Beyond the paper: the CAD part's boss stands on a concave fillet tangent
// to the plate. The plate's rim reaches onto the fillet, whose 2-ring plane
// then leans past 30 degrees; the tangent test (a quadric fitted to the
// curved side, its normal taken at the flat) must call that border smooth,
// and keep the real creases (the cylinder's rim) sharp.
TEST(Flats, FilletTangentToAFlatIsNotAJunction) {
  // The boss stands on a 6-cell fillet tangent to the plate's top: no
  // labelled sharp curve may stray onto its foot (the tangent-borders pass;
  // without it the foot is labelled 20 voxels from any true crease, as
  // bench/ablation shows). Bound over four rotations.
  for (int seed : {1, 11}) {  // (CI time: seeds 2 and 18 too in bench_flats)
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const GeneratedShape g = rotated(ShapeKind::cad_part, 128, seed);
    Mesh tm = cad_part_mesh();
    for (Vec3& p : tm.positions) p = g.translation + g.linear * p;
    const auto truth = mesh_truth(std::move(tm), "cad part");
    const Mesh m = smooth_surface(g.volume).mesh;
    EvalOptions eo;
    eo.volume = &g.volume;
    eo.samples = 20000;
    eo.self_intersections = false;
    const EvalReport r = evaluate(m, *truth, eo);
    EXPECT_EQ(r.classification_violations.value_or(1), 0u);
    EXPECT_LT(r.sharp_labelled_to_true_vox.value_or(1e300), 1.5) << "labelled curves stray from the true ones";
  }
}

// A rule's results with it on and off against the shape's truth
// (`samples` per direction; the guarantees were checked by rule_on_off).
std::array<EvalReport, 2> evaluate_on_off(const test::RuleOnOff& t, size_t samples) {
  EvalOptions eo;
  eo.volume = &t.box.shape.volume;
  eo.samples = samples;
  eo.self_intersections = false;
  return {evaluate(t.on.mesh, *t.box.truth, eo), evaluate(t.off.mesh, *t.box.truth, eo)};
}

// Issue 75's family: a box whose edges are rounded by 2.5 cells, 64^3. The
// lattice resolves that fillet: the junction chains along it allow that
// rounding and no sharp edge does (round-borders), so the flats are not
// extended onto it and the result is closer to the truth than with the
// rule off (measured 0.71 and 0.83 of it); on the sharp box (r = 0) no
// chain allows it and nothing is released.
TEST(Flats, FilletsTheLatticeResolvesAreNotFlattened) {
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    for (double r : {0.0, 2.5}) {
      const test::RuleOnOff t = test::fillet_rule_on_off(64, seed, r, Pass::round_borders);
      if (r == 0) {
        EXPECT_EQ(t.count, 0u);
        continue;
      }
      EXPECT_GT(t.count, 0u);
      const auto [on, off] = evaluate_on_off(t, 40000);
      EXPECT_LT(on.result_to_truth_vox.rms, 0.9 * off.result_to_truth_vox.rms);
    }
  }
}

// The same beside one flat: a cylinder whose rims are rounded by 3 cells,
// 64^3 (the cap meets the curved side through the fillet). The chains
// along the rim allow that rounding against the side's plane next to the
// border and the far side's corner demands it, so the cap is not extended
// onto the fillet (measured 0.91-0.92 of the RMS with the rule off, where
// only the crease fit's own check keeps the fillet round); on the sharp
// cylinder the rim's samples forbid it and its sharp curves keep their
// recall.
TEST(Flats, FilletsBesideOneFlatAreNotFlattened) {
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    for (double r : {0.0, 3.0}) {
      const test::RuleOnOff t =
          test::rule_on_off(test::shape_and_truth(ShapeKind::cylinder, 64, seed, r), Pass::round_borders);
      const auto [on, off] = evaluate_on_off(t, 40000);
      if (r == 0) {
        ASSERT_TRUE(on.sharp_recall && off.sharp_recall);
        EXPECT_GT(*on.sharp_recall, *off.sharp_recall - 0.015);
        continue;
      }
      EXPECT_GT(t.count, 0u);
      EXPECT_LT(on.result_to_truth_vox.rms, 0.95 * off.result_to_truth_vox.rms);
    }
  }
}

// The crease fit squares a flat's border off onto the crease of its plane
// and the curved side's far surface; where a sample lies past both (a
// fillet the flat meets tangentially) the samples deny that crease and the
// vertex keeps its pressed place. On the sharp cylinder (64^3) the fit is
// the better surface; on one whose rims are rounded by 2 cells (too tight
// for round-borders to release) it costs 3-8 % here, 14-17 % before the
// samples could deny it.
TEST(Flats, CreaseFitKeepsOffFillets) {
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    for (double r : {0.0, 2.0}) {
      const test::RuleOnOff t =
          test::rule_on_off(test::shape_and_truth(ShapeKind::cylinder, 64, seed, r), Pass::crease_fit);
      const auto [a, b] = evaluate_on_off(t, 40000);
      const double on = a.result_to_truth_vox.rms, off = b.result_to_truth_vox.rms;
      EXPECT_GT(t.count, 0u);
      if (r == 0)
        EXPECT_LT(on, off);
      else
        EXPECT_LT(on, 1.1 * off);
    }
  }
}

TEST(Flats, SharpEdgesEndingAtAFilletStayJunctions) {
  // The CAD part's sharp top and side edges end where a rounded vertical
  // edge begins: there the fillet cuts off samples deep inside both of the
  // sharp edge's planes, a demand no rounding of that edge explains. Such
  // short chains must stay junctions (RoundingEvidence::round_between), so
  // round-borders costs the sharp curves' recall little. Its one-flat
  // chains (the rounded vertical edges tangent to the side faces, the
  // boss's concave fillet) cost 0.6-0.9 points here (a few cells of sharp
  // curve where a tangent fillet begins); releasing the corner chains too
  // would add 1.9-2.0 points.
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const test::RuleOnOff t = test::rule_on_off(test::shape_and_truth(ShapeKind::cad_part, 64, seed), Pass::round_borders);
    const auto [a, b] = evaluate_on_off(t, 20000);
    ASSERT_TRUE(a.sharp_recall && b.sharp_recall);
    EXPECT_GT(*a.sharp_recall, *b.sharp_recall - 0.02);
  }
}

TEST(Flats, PropertyCorpusKeepsEveryGuarantee) {
  FlatOptions fo;
  fo.min_area = 4;  // small volumes: let flats happen
  PressOptions po;
  po.iterations = 30;
  for (const test::Case& c : test::property_volumes()) {
    SCOPED_TRACE(c.name);
    StickSurface s = extract_sticks(c.volume);
    FlatSegmentation seg;
    press_with_flats(s, build_slice_curves(s), po, &fo, &seg);
    expect_guarantees(s, seg, c.volume);
    for (size_t i = 0; i < s.stick_count(); ++i) {
      if (seg.barrier[i]) {
        ASSERT_GE(seg.region[i], 0) << "barriers are frozen";
      }
      if (seg.junction[i]) {
        ASSERT_LT(seg.region[i], 0) << "junctions are fresh";
      }
    }
  }
}

// The detection tries cells ahead in parallel (find_flats): the result
// must be the serial loop's, on a part that accepts flats among rejections
// and on a cylinder whose wall rejects many tangent strips.
TEST(Flats, SameResultForOneAndManyThreads) {
  for (const auto& [kind, res, seed] : {std::tuple{ShapeKind::cad_part, 72, 3}, std::tuple{ShapeKind::cylinder, 96, 2}}) {
    SCOPED_TRACE(int(kind));
    const GeneratedShape g = rotated(kind, res, seed);
    StickSurface one = extract_sticks(g.volume), many = one;
    const SliceCurves curves = build_slice_curves(one);
    const FlatOptions fo;
    FlatSegmentation s1, s2;
    {
      tbb::task_arena arena(1);
      arena.execute([&] { press_with_flats(one, curves, {}, &fo, &s1); });
    }
    {
      tbb::task_arena arena(4);  // a look-ahead of up to 16 cells, whatever the cores
      arena.execute([&] { press_with_flats(many, curves, {}, &fo, &s2); });
    }
    EXPECT_EQ(one.t, many.t);
    EXPECT_EQ(s1.region, s2.region);
    EXPECT_EQ(s1.junction, s2.junction);
    EXPECT_EQ(s1.stats.tried, s2.stats.tried);
    for (size_t p = 0; p < size_t(Pass::count); ++p) EXPECT_EQ(s1.stats.passes.count[p], s2.stats.passes.count[p]) << p;
    EXPECT_GT(s1.flats.size(), 0u);
    EXPECT_GT(s1.stats.tried, s1.flats.size()) << "no rejected cell: the look-ahead is not exercised";
  }
}

TEST(Flats, JunctionAngleOptionControlsJunctions) {
  const FlatRun r = run(ShapeKind::cylinder, 64, 1);
  StickSurface s = extract_sticks(r.shape.volume);
  const SliceCurves curves = build_slice_curves(s);
  FlatOptions fo;
  fo.junction_angle = 180;  // no angle is sharp: only vertices squeezed between flats remain junctions
  FlatSegmentation seg;
  press_with_flats(s, curves, {}, &fo, &seg);
  EXPECT_GT(r.seg.stats.junctions, 0u);
  EXPECT_LT(seg.stats.junctions * 10, r.seg.stats.junctions);
  EXPECT_EQ(seg.flats.size(), 2u);
}

TEST(Flats, RegionAttributesAndColours) {
  const FlatRun r = run(ShapeKind::box, 48, 2);
  Mesh m = to_mesh(r.surface);
  add_region_attributes(m, r.seg, true);
  const MeshAttribute* region = m.vertex_attribute("region");
  const MeshAttribute* junction = m.vertex_attribute("junction");
  ASSERT_TRUE(region && junction);
  ASSERT_EQ(m.colors.size(), m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    ASSERT_EQ(region->values[v], double(r.seg.region[v]));
    if (r.seg.region[v] >= 0 && r.seg.region[v] != r.seg.region[0]) {
      EXPECT_TRUE(r.seg.region[0] < 0 || m.colors[v] != m.colors[0]) << "different flats, different colours";
    }
  }
}

TEST(Flats, FandiskPlanarFacesFoundAndStagesBeatTheMidpoint) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const test::VoxelizedModel v = test::voxelized_shared_model("fandisk.off", 128, 1);
  StickSurface s = extract_sticks(v.volume);
  const Stages st = stages(s, v.volume, *v.truth);
  const FlatSegmentation& seg = st.seg;
  const double e_tiles = st.tiles;
  const EvalReport& final_report = st.final_report;
  // Every planar face of 500 cells or more (seven at this rotation) has a
  // flat within 1 degree and half a cell. Its two narrow 600-cell side faces
  // have few voters (their estimate is bent by the rounded edges on both
  // sides): they are only tried because a cell needs just a share of
  // min_area voters to seed a cluster (flats.cpp, kSeedShare).
  ASSERT_EQ(v.volume.lattice.spacing, Vec3(1, 1, 1)) << "match compares offsets in cells";
  std::vector<PlanarFace> faces;
  for (const PlanarFace& f : planar_faces(v.physical, 0.5, 0.02))
    if (f.area >= 500) faces.push_back(f);
  EXPECT_GE(faces.size(), 7u);
  const Matches m = match_all(seg.flats, faces);
  for (size_t i = 0; i < faces.size(); ++i)
    EXPECT_GE(m.per_face[i], 1) << "planar face of " << faces[i].area << " cells, normal " << faces[i].normal.transpose();
  EXPECT_LT(e_tiles, 0.25);
  EXPECT_LT(*final_report.stick_rms_vox, e_tiles);
  EXPECT_EQ(final_report.classification_violations.value_or(1), 0u);
  EXPECT_TRUE(final_report.mesh.ok());
}

}  // namespace
}  // namespace voxpress
