// Sharp edge recovery: accuracy against exactly known solids (box, CAD-like
// part, fandisk when ../shared is present), the recovered creases, the
// guarantees on the property corpus, the subdivision bookkeeping, the
// segmented output and determinism.
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "test_util.h"
#include "voxpress/eval/checks.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/smooth/sharpen.h"

namespace voxpress {
namespace {

struct Sharpened {
  StickSurface surface;
  FlatSegmentation seg;
  Mesh before, after;  // pressed with flats, then sharpened
  SharpenStats stats;
};

// Pressed with flats, then (with `fit`, as smooth_surface and `voxpress
// press` do) the local quadric fit, then sharpened.
Sharpened run(const BinaryVolume& volume, const FlatOptions& fo = {}, const PressOptions& po = {},
              const SharpenOptions& so = {}, bool fit = false) {
  Sharpened r;
  r.surface = extract_sticks(volume);
  press_with_flats(r.surface, build_slice_curves(r.surface), po, &fo, &r.seg);
  if (fit) {
    QuadricFitOptions qo;
    qo.margin = po.margin;
    fit_local_quadrics(r.surface, r.seg.region, r.seg.junction, qo);
  }
  r.before = to_mesh(r.surface);
  SharpenResult sr = sharpen(r.surface, r.seg, so);
  r.after = std::move(sr.mesh);
  r.stats = sr.stats;
  return r;
}

GeneratedShape shape(ShapeKind kind, int64_t res, int seed) {
  GenerateOptions go;
  go.res = res;
  go.rotation = parse_rotation("random:" + std::to_string(seed));
  return generate_shape(kind, go);
}

void expect_valid(const Mesh& m, const BinaryVolume& v) { test::expect_guarantees(m, v); }

EvalReport eval(const Mesh& m, const Truth& truth, const BinaryVolume& v) {
  EvalOptions eo;
  eo.volume = &v;
  eo.samples = 60000;
  eo.self_intersections = false;
  return evaluate(m, truth, eo);
}

Vec3 face_normal(const Mesh& m, size_t f) {
  const Triangle& t = m.triangles[f];
  return (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).normalized();
}

// Original vertices left curved (region -1) in the sharpened mesh.
size_t curved_vertices(const Sharpened& r) {
  const auto* region = r.after.vertex_attribute("region");
  return size_t(std::count_if(region->values.begin(), region->values.begin() + ptrdiff_t(r.surface.stick_count()),
                              [](double v) { return v < 0; }));
}

TEST(Sharpen, RotatedBoxesGetTheirEdgesBack) {
  // Seeds 8 and 21 need the snapping's tolerance of samples a hair outside
  // a face (solid_crossing), 29 the flats' crease refit (0.33 / 0.18 / 0.41
  // before), 39 and 48 the snapping's wider look for a corner's third flat
  // (0.93 / 4.6 before).
  for (int seed : {1, 2, 3, 8, 21, 29, 39, 48}) {
    SCOPED_TRACE("box 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::box, 128, seed);
    const auto truth = shape_truth(ShapeKind::box, g.linear, g.translation);
    const Sharpened r = run(g.volume);
    ASSERT_EQ(r.seg.flats.size(), 6u);
    expect_valid(r.after, g.volume);
    const EvalReport before = eval(r.before, *truth, g.volume), after = eval(r.after, *truth, g.volume);
    EXPECT_LT(after.result_to_truth_vox.rms, 0.6 * before.result_to_truth_vox.rms);
    EXPECT_LT(after.normal_error_deg, before.normal_error_deg);
    EXPECT_GE(r.stats.corners, 8u) << "at least one corner vertex per box corner";
    ASSERT_TRUE(after.sharp_edge_hausdorff_vox.has_value());
    // The target: true and labelled edges within 0.15 voxel both
    // ways (48 of seeds 1-50 meet it, the worst of those 0.13, docs/BENCHMARKS.md).
    EXPECT_LT(*after.sharp_edge_hausdorff_vox, 0.15);
    // Every original vertex ends on a flat: no bevel is left curved.
    ASSERT_NE(r.after.vertex_attribute("region"), nullptr);
    EXPECT_EQ(curved_vertices(r), 0u);
    // Dihedral angles across the labelled edges: the box's 90 degrees.
    std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> faces;
    for (size_t f = 0; f < r.after.face_count(); ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = r.after.triangles[f][size_t(k)], b = r.after.triangles[f][size_t((k + 1) % 3)];
        faces[{std::min(a, b), std::max(a, b)}].push_back(f);
      }
    size_t within = 0;
    for (const auto& e : r.after.edges) {
      const auto& fs = faces.at({std::min(e[0], e[1]), std::max(e[0], e[1])});
      ASSERT_EQ(fs.size(), 2u);
      const double angle =
          std::acos(std::clamp(face_normal(r.after, fs[0]).dot(face_normal(r.after, fs[1])), -1.0, 1.0)) * 180 /
          std::numbers::pi;
      within += std::abs(angle - 90) <= 5;
    }
    EXPECT_GE(double(within), 0.95 * double(r.after.edges.size()));
  }
}

using Segments = std::vector<std::array<Vec3, 2>>;

Segments labelled_edges(const Mesh& m) {
  Segments e;
  for (const auto& ed : m.edges) e.push_back({m.positions[ed[0]], m.positions[ed[1]]});
  return e;
}

// Distances from points every quarter cell along `from` to the nearest
// segment of `to` (infinite when `to` is empty; one infinite distance when
// `from` is), sorted.
std::vector<double> sampled_distances(const Segments& from, const Segments& to) {
  std::vector<double> d;
  for (const auto& sg : from) {
    const int k = std::max(1, int(std::ceil((sg[1] - sg[0]).norm() / 0.25)));
    for (int i = 0; i <= k; ++i) {
      const Vec3 p = sg[0] + (sg[1] - sg[0]) * (double(i) / k);
      d.push_back(to.empty() ? INFINITY : (closest_on_segments(p, to) - p).norm());
    }
  }
  if (d.empty()) d.push_back(INFINITY);
  std::sort(d.begin(), d.end());
  return d;
}

// True sharp curves to the labelled edges of m, and back.
std::vector<double> crease_distances(const Segments& truth, const Mesh& m) { return sampled_distances(truth, labelled_edges(m)); }
std::vector<double> labelled_distances(const Segments& truth, const Mesh& m) { return sampled_distances(labelled_edges(m), truth); }

double fraction_within(const std::vector<double>& sorted, double r) {
  return double(std::upper_bound(sorted.begin(), sorted.end(), r) - sorted.begin()) / double(sorted.size());
}

TEST(Sharpen, CadPartErrorDropsAndItsCreasesAreFound) {
  // Sharpened as `voxpress press` does it (the quadric fit included), the
  // CAD part is closer to the truth in position and normal,
  // and its labelled creases and the true ones lie near each other both
  // ways. Each rotation here had a spot where a vertex beside two flats
  // sent the labels astray (two-sided Hausdorff, voxels, measured before ->
  // after): seed 3, a fillet tangent to one flat met the other at a crease
  // but was judged against the tangent flat alone, and the crease had a gap
  // (0.72 -> 0.34); seed 10, a curved junction at a sample, whose stick lies
  // wholly below the curved side's plane, stayed curved and the chain
  // detoured round it (0.85 -> 0.62, the rest another corner); seed 128, a
  // corner without a curved plane stayed at its centroid, a spur off the
  // crease of two flats (0.67 -> 0.42).
  for (const auto& [seed, most] : std::map<int, double>{{3, 0.5}, {10, 0.75}, {128, 0.55}}) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cad_part, 128, seed);
    const Sharpened r = run(g.volume, {}, {}, {}, true);
    expect_valid(r.after, g.volume);
    const auto t = shape_truth(ShapeKind::cad_part, g.linear, g.translation);
    const EvalReport before = eval(r.before, *t, g.volume), after = eval(r.after, *t, g.volume);
    EXPECT_LT(after.result_to_truth_vox.rms, before.result_to_truth_vox.rms);
    EXPECT_LT(after.normal_error_deg, before.normal_error_deg);
    const auto sharp = t->sharp_edges(30);
    const double h = std::max(crease_distances(sharp, r.after).back(), labelled_distances(sharp, r.after).back());
    EXPECT_LT(h, most) << "measured 0.34, 0.62, 0.42";
  }
}

FlatOptions paper_junctions() {
  FlatOptions fo;
  fo.junction_ring_off_plane = 0;
  return fo;
}

// The flats with their whole rims (FlatOptions::rim_tangent_angle off): the
// tests of steps measured before the rim left the tangent fillets, whose
// figures it moves, compare their two arms on these.
FlatOptions full_rims(FlatOptions fo = {}) {
  fo.rim_tangent_angle = 0;
  return fo;
}

TEST(Sharpen, ThinStripsAndTangentPlanesPlaceTheCreases) {
  // The CAD part at 128^3 (voxel = unit spacing, so distances are in
  // voxels). Where the flats' rims stop a few vertices short of a crease
  // (the chamfer's 45-degree creases), the paper's rule labels nothing
  // there; thin strips join them to a flat. The hole's and the boss's
  // creases are curved / flat, where the curved side's 2-ring plane is a
  // secant that puts the crease ~0.15 voxel inside; tangent planes fix it.
  SharpenOptions paper, strips;
  paper.strip_rings = 0;
  paper.curved_fit_rings = 0;
  strips.curved_fit_rings = 0;
  // Two-sided Hausdorff distance between the true and labelled creases, per
  // rotation: strips trade a stray label on one seed for whole creases
  // recovered on others (measured when strips came in, seeds 1-4: 1.8 / 2.5 / 5.9 / 1.9 ->
  // 1.7 / 8.0 / 1.6 / 1.3; before the flats' stabbing refit found seed 1's
  // chamfer, 7.4 -> 7.0 there). Since the planes are centred in their
  // feasible sets the paper's rule loses less (1.8 / 1.7 / 3.0 / 1.9 ->
  // 1.2 / 1.0 / 1.5 / 1.3; uncentred 1.8 / 2.5 / 5.9 / 1.9 -> 1.2 / 1.1 / 1.6 / 1.3).
  int better = 0;
  double gain = 0;
  for (int seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cad_part, 128, seed);
    const auto truth = shape_truth(ShapeKind::cad_part, g.linear, g.translation)->sharp_edges(30);
    const Sharpened a = run(g.volume, full_rims(), {}, paper), b = run(g.volume, full_rims(), {}, strips);
    expect_valid(b.after, g.volume);
    const auto da = crease_distances(truth, a.after), db = crease_distances(truth, b.after);
    const double h_paper = std::max(da.back(), labelled_distances(truth, a.after).back());
    const double h_strips = std::max(db.back(), labelled_distances(truth, b.after).back());
    better += h_strips < h_paper;
    gain = std::max(gain, h_paper - h_strips);
    if (seed < 2 || seed > 3) continue;
    // Tangent planes: more of the creases within 0.15 voxel of a label.
    const Sharpened c = run(g.volume, full_rims());
    expect_valid(c.after, g.volume);
    EXPECT_GT(fraction_within(crease_distances(truth, c.after), 0.15), fraction_within(db, 0.15) + 0.03);
    EXPECT_GT(c.stats.tangent_planes, 100u);
  }
  EXPECT_GE(better, 3) << "rotations where strips bring the labels closer, of 4";
  EXPECT_GT(gain, 1.0) << "a stretch of crease recovered somewhere (voxels)";
}

TEST(Sharpen, RimPocketsLeaveTheCurvedCreasesInPlace) {
  // A flat's rim along a curved face is ragged; the curved vertices in its
  // pockets are thin (within strip_rings of the flat) but not a strip
  // between flats. Joined to the flat without moving, off its plane, they
  // made the crease vertices next to them turn triangles over, so those
  // moves were cut back 0.3-0.5 voxel off the rim. Rotated cylinders at
  // 128^3 (rims: flat caps on a curved wall): more of the true rims within
  // 0.15 voxel of a label (measured, seeds 1 / 2: 0.73 / 0.70 of the rims
  // without, 0.91 / 0.84 with), and more of the labels within 0.15 of a rim.
  // Measured without the vertices past the crease (SharpenOptions::
  // past_crease), which came later and also moves rim vertices: with it,
  // seed 2's rims are within 0.15 voxel of a label on 0.997 without pockets
  // and 0.986 with, but over CAD part 128 seeds 1-8 and 128 and cylinder 128
  // seeds 1-6 and 128 the pockets still take the shares within 0.15 voxel
  // from 95.4 / 94.7 % to 98.1 / 98.0 % (CAD part, recall / precision) and
  // from 90.0 / 88.5 % to 98.6 / 99.0 % (cylinders).
  SharpenOptions old, pockets;
  old.rim_pockets = false;
  old.past_crease = pockets.past_crease = false;
  for (int seed = 1; seed <= 2; ++seed) {
    SCOPED_TRACE("cylinder 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cylinder, 128, seed);
    const auto truth = shape_truth(ShapeKind::cylinder, g.linear, g.translation)->sharp_edges(30);
    const Sharpened a = run(g.volume, {}, {}, old), b = run(g.volume, {}, {}, pockets);
    expect_valid(b.after, g.volume);
    const double fa = fraction_within(crease_distances(truth, a.after), 0.15);
    const double fb = fraction_within(crease_distances(truth, b.after), 0.15);
    EXPECT_GT(fb, fa + 0.08);
    EXPECT_GT(fraction_within(labelled_distances(truth, b.after), 0.15),
              fraction_within(labelled_distances(truth, a.after), 0.15));
  }
}

// A shape at res^3 rotated by random:seed.
struct Case {
  ShapeKind kind;
  int seed;
  int res = 128;
};

// Section 3's junction test as the paper has it (FlatOptions::
// junction_ring_off_plane off): the steps below that were measured with it
// are tested with it, since the stopped-rim test now does part of their
// work on their seeds.
// The case pressed with flats once and sharpened twice: with `off` (one
// step turned off) and with the defaults.
struct OffOn {
  GeneratedShape g;
  SharpenResult off, on;
};
OffOn sharpen_off_on(const Case& c, const SharpenOptions& off, const SharpenOptions& on = {}, const FlatOptions& fo = {}) {
  OffOn r{shape(c.kind, c.res, c.seed), {}, {}};
  StickSurface s = extract_sticks(r.g.volume);
  FlatSegmentation seg;
  press_with_flats(s, build_slice_curves(s), {}, &fo, &seg);
  r.off = sharpen(s, seg, off);
  r.on = sharpen(s, seg, on);
  return r;
}

TEST(Sharpen, RightAngleCreaseMovesAreRetried) {
  // A new vertex whose move onto a flat/curved crease was blocked (mostly by
  // a fan triangle it would turn over) was cut back and left short of the
  // crease. Retried like the moves onto flats' planes, those onto creases
  // whose planes are within SharpenOptions::retry_right_angle of
  // perpendicular get there once their neighbours have moved: the labelled
  // curves come closer to the true ones, and no guarantee is lost.
  SharpenOptions off;
  off.retry_right_angle = -1;
  for (const Case c : {Case{ShapeKind::cad_part, 13}, Case{ShapeKind::cylinder, 2}}) {
    SCOPED_TRACE(std::string(shape_name(c.kind)) + " 128 seed " + std::to_string(c.seed));
    const auto [g, a, b] = sharpen_off_on(c, off);
    expect_valid(b.mesh, g.volume);
    const auto sharp = shape_truth(c.kind, g.linear, g.translation)->sharp_edges(30);
    const auto ca = crease_distances(sharp, a.mesh), cb = crease_distances(sharp, b.mesh);
    const double ha = std::max(ca.back(), labelled_distances(sharp, a.mesh).back());
    const double hb = std::max(cb.back(), labelled_distances(sharp, b.mesh).back());
    EXPECT_LT(hb, 0.6 * ha) << "measured 0.79 -> 0.29, 0.89 -> 0.16 voxel";
    EXPECT_GE(fraction_within(cb, 0.15), fraction_within(ca, 0.15));
  }
}

TEST(Sharpen, FinalCreaseFitPlacesTheRoundedCreases) {
  // Snapping, the leftovers and the rim pockets move the flats' rims after
  // press_with_flats placed the curved vertices next to its junctions; where
  // a rim had stopped short of a crease, the curved side stayed pressed in.
  // Fitting again once the labels are final puts more of the true
  // flat/curved creases within 0.15 voxel of a label, and the result closer
  // to the truth. Since the pieces next to the rims have free ends
  // (PressOptions::free_ends) the curved side is pressed in less and the
  // gain is smaller (share within 0.15 voxel, cylinder 128 seeds 1 / 4, CAD
  // part 128 seed 4: 0.982 / 0.977 / 0.919 -> 0.985 / 0.995 / 0.932;
  // result -> truth 0.0660 -> 0.0653 summed), so it is tested over the three.
  // With the circle correction (PressOptions::circle_correction) the curved
  // side is hardly pressed in at all: the share goes 2.878 -> 2.914 summed
  // and result -> truth 0.0621 -> 0.0623, so the fit must not cost the
  // surface more than 1 %.
  SharpenOptions off;
  off.final_crease_rings = 0;
  double within_off = 0, within_on = 0, rms_off = 0, rms_on = 0;
  for (const Case c : {Case{ShapeKind::cylinder, 1}, Case{ShapeKind::cylinder, 4}, Case{ShapeKind::cad_part, 4}}) {
    SCOPED_TRACE(std::string(shape_name(c.kind)) + " 128 seed " + std::to_string(c.seed));
    const auto [g, a, b] = sharpen_off_on(c, off, {}, full_rims());
    const auto truth = shape_truth(c.kind, g.linear, g.translation);
    EXPECT_EQ(a.stats.final_crease_vertices, 0u);
    EXPECT_GT(b.stats.final_crease_vertices, 100u);
    expect_valid(b.mesh, g.volume);
    const auto sharp = truth->sharp_edges(30);
    within_off += fraction_within(crease_distances(sharp, a.mesh), 0.15);
    within_on += fraction_within(crease_distances(sharp, b.mesh), 0.15);
    rms_off += eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms;
    rms_on += eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms;
  }
  EXPECT_GT(within_on, within_off + 0.015) << "measured +0.036 summed";
  EXPECT_LT(rms_on, 1.01 * rms_off);
}

TEST(Sharpen, VerticesPastTheCreaseChangeSides) {
  // Where a flat face passes through a sample next to a curved face, a
  // curved junction vertex on a stick from that sample can lie past the
  // crease, on the flat; the crease vertices inserted on its edges were cut
  // back around it, and the labelled chain detoured up to a voxel off the
  // true crease. Joining such vertices to the flat takes half or more of
  // the labelled points more than half a voxel from a true crease there,
  // and the worst one closer (CAD part 128 seeds 13 / 15 / 128, cylinder 128
  // seed 2; points every quarter voxel along the labelled curves). On seed 13
  // the vertices' sticks do not cross the flat's plane: they join because
  // they lie on it (without that branch seed 13 ends with more such points
  // than with the step off, and fails here). Flat members past the crease,
  // on the curved face, leave their flat; with both, the result is closer
  // to the truth on three of the four and summed (seed 128 +0.4 % since the
  // chamfer planes are checked against their samples; 0.0249 -> 0.0241
  // before). Both run without the right-angle retry, as they were measured:
  // with it, seed 15 has no labelled point more than half a voxel off
  // either way (the retried moves reach the crease around the vertex too).
  SharpenOptions off, on;
  off.retry_right_angle = on.retry_right_angle = -1;
  off.past_crease = false;
  double rms_off = 0, rms_on = 0;
  for (const Case c : {Case{ShapeKind::cad_part, 13}, Case{ShapeKind::cad_part, 15}, Case{ShapeKind::cad_part, 128},
                       Case{ShapeKind::cylinder, 2}}) {
    SCOPED_TRACE(std::string(shape_name(c.kind)) + " 128 seed " + std::to_string(c.seed));
    const auto [g, a, b] = sharpen_off_on(c, off, on);
    const auto truth = shape_truth(c.kind, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    EXPECT_EQ(a.stats.past_crease + a.stats.left_flat, 0u);
    EXPECT_GT(b.stats.past_crease, 0u);
    EXPECT_GT(b.stats.left_flat, 0u);
    expect_valid(b.mesh, g.volume);
    const auto la = labelled_distances(sharp, a.mesh), lb = labelled_distances(sharp, b.mesh);
    const double far_off = 1 - fraction_within(la, 0.5), far_on = 1 - fraction_within(lb, 0.5);
    EXPECT_LT(far_on, 0.75 * far_off) << "measured 104 -> 23, 17 -> 0, 39 -> 16, 37 -> 10 points (of 15 k, 9 k, 10 k, 3 k)";
    EXPECT_LT(lb.back(), la.back()) << "measured 1.71 -> 0.79, 1.06 -> 0.42, 0.93 -> 0.86, 1.15 -> 0.89";
    const double ra = eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms;
    const double rb = eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms;
    EXPECT_LT(rb, 1.01 * ra) << "measured 0.0284 -> 0.0282, 0.0298 -> 0.0294, 0.0245 -> 0.0246, 0.0207 -> 0.0196";
    rms_off += ra;
    rms_on += rb;
  }
  EXPECT_LT(rms_on, 0.99 * rms_off) << "measured 0.1033 -> 0.1018 summed";
}

TEST(Sharpen, JoinedJunctionsPassTheBorderOn) {
  // A curved junction that joins a flat (snapping, the leftovers) moves the
  // flat's border onto its curved neighbours. Unless they become junctions,
  // their edges to it are no chamfer edges and the labelled curve has a gap
  // there (CAD part 128 seed 1: two cells of the boss's rim, the true crease
  // a voxel from any label). The on-plane bands are off in both runs: on
  // seed 2 they give the border the same junctions (0.44 voxel either way).
  SharpenOptions off, on;
  on.on_plane_bands = off.on_plane_bands = false;
  off.inherit_junctions = false;
  for (const int seed : {1, 2, 8}) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const auto [g, a, b] = sharpen_off_on({ShapeKind::cad_part, seed}, off, on, paper_junctions());
    const auto truth = shape_truth(ShapeKind::cad_part, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    EXPECT_EQ(a.stats.inherited_junctions, 0u);
    EXPECT_GT(b.stats.inherited_junctions, 0u);
    expect_valid(b.mesh, g.volume);
    const auto ca = crease_distances(sharp, a.mesh), cb = crease_distances(sharp, b.mesh);
    EXPECT_LT(cb.back(), 0.75 * ca.back()) << "measured 0.96 -> 0.55, 0.67 -> 0.44, 0.72 -> 0.41 voxel";
    EXPECT_GE(fraction_within(cb, 0.15), fraction_within(ca, 0.15)) << "measured 94.1 -> 94.3, 92.5 -> 93.8, 90.8 -> 90.8 %";
  }
}

TEST(Sharpen, OnPlaneBandsJoinTheirFlat) {
  // Where a flat's rim stops a cell or two short of a sharp flat/curved
  // crease, the curved vertices in between lie on the flat's plane but are
  // no junctions, so the labelled chain ran along the rim, inside the true
  // crease (CAD part 128 seeds 3, 4 and 13). Joining them to the flat puts
  // the chain on the crease: the true crease's farthest point from any
  // label comes closer, the two-sided distance drops, and the result is no
  // farther from the truth.
  SharpenOptions off;
  off.on_plane_bands = false;
  double rms_off = 0, rms_on = 0;
  for (const int seed : {3, 4, 13}) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const auto [g, a, b] = sharpen_off_on({ShapeKind::cad_part, seed}, off, {}, full_rims(paper_junctions()));
    const auto truth = shape_truth(ShapeKind::cad_part, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    EXPECT_EQ(a.stats.band_joins + a.stats.band_junctions, 0u);
    EXPECT_GT(b.stats.band_joins, 0u);
    expect_valid(b.mesh, g.volume);
    const auto ca = crease_distances(sharp, a.mesh), cb = crease_distances(sharp, b.mesh);
    EXPECT_LT(cb.back(), 0.85 * ca.back()) << "measured 1.05 -> 0.69, 1.29 -> 0.31, 1.77 -> 1.34 voxel";
    EXPECT_LT(std::max(cb.back(), labelled_distances(sharp, b.mesh).back()),
              std::max(ca.back(), labelled_distances(sharp, a.mesh).back()));
    rms_off += eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms;
    rms_on += eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms;
  }
  EXPECT_LT(rms_on, 1.005 * rms_off) << "measured 0.0788 -> 0.0784 summed";
}

TEST(Sharpen, ChamferPlanesAgreeWithTheirSamples) {
  // A curved side's plane can lean too far where the estimate rounded the
  // crease, so the two planes' line lies cells outside the solid and the
  // new vertex ends there with no sample crossed. Where the planes' solid
  // takes in an outside sample (convex) or leaves out an inside one
  // (concave), the curved plane moves onto it or the vertex stays. On the
  // CAD part at 64^3, whose curved faces are a few cells across, the
  // result comes closer to the truth on every rotation; a box's exact
  // planes explain their samples, so nothing changes there.
  SharpenOptions off;
  off.sample_wedges = false;
  double rms_off = 0, rms_on = 0;
  for (const int seed : {1, 3, 5}) {
    SCOPED_TRACE("cad part 64 seed " + std::to_string(seed));
    const auto [g, a, b] = sharpen_off_on({ShapeKind::cad_part, seed, 64}, off);
    const auto truth = shape_truth(ShapeKind::cad_part, g.linear, g.translation);
    EXPECT_EQ(a.stats.wedge_checks, 0u);
    EXPECT_GT(b.stats.wedge_checks, 20u);
    EXPECT_GT(b.stats.wedge_shifts, 0u);
    EXPECT_LE(b.stats.wedge_shifts, b.stats.wedge_checks);
    expect_valid(b.mesh, g.volume);
    const double ra = eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms;
    const double rb = eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms;
    EXPECT_LT(rb, 0.99 * ra) << "measured 0.0719 -> 0.0662, 0.0793 -> 0.0776, 0.0863 -> 0.0803";
    rms_off += ra;
    rms_on += rb;
  }
  EXPECT_LT(rms_on, 0.96 * rms_off) << "measured 0.2375 -> 0.2241 summed";
  for (const int seed : {1, 2}) {
    SCOPED_TRACE("box 128 seed " + std::to_string(seed));
    const auto [g, a, b] = sharpen_off_on({ShapeKind::box, seed}, off);
    EXPECT_EQ(b.stats.wedge_checks, 0u);
    EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  }
}

TEST(Sharpen, OnPlaneBandsReachTwoRingDeepNotches) {
  // A flat's rim can stop two rings short of the crease, so the band
  // vertex next to the rim has no curved junction among its neighbours,
  // only two rings away (the cylinder's cap, CAD part seed 22's boss top).
  // Looking two rings out takes those bands too: the farthest true crease
  // point comes closer, the labels stay as close, and the surface no
  // farther from the truth.
  SharpenOptions one;
  one.band_reach = 1;
  for (const Case c : {Case{ShapeKind::cylinder, 3}, Case{ShapeKind::cad_part, 22}}) {
    SCOPED_TRACE(std::string(shape_name(c.kind)) + " 128 seed " + std::to_string(c.seed));
    const auto [g, a, b] = sharpen_off_on(c, one, {}, full_rims(paper_junctions()));
    const auto truth = shape_truth(c.kind, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    EXPECT_GT(b.stats.band_joins, a.stats.band_joins);
    expect_valid(b.mesh, g.volume);
    const auto ca = crease_distances(sharp, a.mesh), cb = crease_distances(sharp, b.mesh);
    const double la = labelled_distances(sharp, a.mesh).back(), lb = labelled_distances(sharp, b.mesh).back();
    EXPECT_LT(cb.back(), 0.6 * ca.back()) << "measured 2.57 -> 1.15, 2.08 -> 1.13 voxel";
    // The labels gained lie a little farther out (labelled -> true 1.54 ->
    // 1.73, 1.05 -> 1.37), but the two-sided distance drops.
    EXPECT_LT(std::max(cb.back(), lb), 0.8 * std::max(ca.back(), la)) << "measured 2.57 -> 1.73, 2.08 -> 1.37 voxel";
    EXPECT_LE(eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms, 1.001 * eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms)
        << "measured 0.02482 -> 0.02480, 0.03146 -> 0.03113";
  }
}

TEST(Sharpen, JunctionTestLeavesTheStoppedRimOut) {
  // Where a flat's rim stops a cell or two short of a crease, the fresh
  // vertices in between lie on the flat's plane; Section 3's 2-ring plane
  // through them leaned halfway between the two sides, under the junction
  // angle, so no junction marked the crease and the flat never reached it.
  // Leaving them out of the plane (FlatOptions::junction_ring_off_plane)
  // brings the true creases' farthest points closer to a label, and the
  // surface closer to the truth. On CAD part seed 128 (0.75 -> 0.61 when
  // measured) both arms' farthest points now lie at the corner where the
  // top, a side and the side's tangent rounded corner meet, 0.75 voxel off
  // either way, which this step does not reach: there only the share within
  // 0.15 voxel and the distance to the truth are compared.
  for (const Case c : {Case{ShapeKind::cylinder, 5}, Case{ShapeKind::cad_part, 13}, Case{ShapeKind::cad_part, 128}}) {
    SCOPED_TRACE(std::string(shape_name(c.kind)) + " 128 seed " + std::to_string(c.seed));
    const GeneratedShape g = shape(c.kind, 128, c.seed);
    const auto truth = shape_truth(c.kind, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    const Sharpened a = run(g.volume, full_rims(paper_junctions())), b = run(g.volume, full_rims());
    expect_valid(b.after, g.volume);
    const auto ca = crease_distances(sharp, a.after), cb = crease_distances(sharp, b.after);
    const double ra = eval(a.after, *truth, g.volume).result_to_truth_vox.rms;
    const double rb = eval(b.after, *truth, g.volume).result_to_truth_vox.rms;
    if (c.seed != 128) {
      EXPECT_LT(cb.back(), 0.85 * ca.back()) << "measured 1.11 -> 0.09, 1.34 -> 0.69 voxel";
      EXPECT_LT(std::max(cb.back(), labelled_distances(sharp, b.after).back()),
                0.95 * std::max(ca.back(), labelled_distances(sharp, a.after).back()))
          << "measured 1.11 -> 0.09, 1.34 -> 0.79 voxel";
    }
    // Seed 128: equal (93.5 %) since sharpening keeps the float32 clearance.
    if (c.seed != 128) {
      EXPECT_GT(fraction_within(cb, 0.15), fraction_within(ca, 0.15)) << "measured 97.5 -> 100, 94.6 -> 95.8 %";
    } else {
      EXPECT_GE(fraction_within(cb, 0.15), fraction_within(ca, 0.15));
    }
    EXPECT_LT(rb, ra) << "measured 0.0191 -> 0.0178, 0.0283 -> 0.0274, 0.0246 -> 0.0240";
  }
}

TEST(Sharpen, JoinedVerticesTakeTheNearestPlane) {
  // A curved vertex that joins a flat (snapping, the leftovers, the strips,
  // the vertices past a crease) ends up on or next to the plane of the flat
  // it joins: no flat with a member within 3 rings has a plane nearer to
  // it. Taking the first ring that reached any flat, a strip vertex of the
  // CAD part's bottom rim (128 seed 5) joined the bottom 1.04 cells below
  // its plane while 0.15 from the side face's, and the crease chain
  // detoured 0.94 voxel around it.
  for (const int seed : {5, 7, 15}) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cad_part, 128, seed);
    const Sharpened r = run(g.volume);
    expect_valid(r.after, g.volume);
    const size_t n = r.surface.stick_count();
    const auto& region = r.after.vertex_attribute("region")->values;
    std::vector<std::vector<uint32_t>> adj(n);
    for (const Triangle& t : r.before.triangles)
      for (int k = 0; k < 3; ++k) adj[t[size_t(k)]].push_back(t[size_t((k + 1) % 3)]);
    size_t joined = 0, farther = 0;
    for (uint32_t v = 0; v < n; ++v) {
      if (r.seg.region[v] >= 0 || region[v] < 0) continue;
      ++joined;
      std::vector<uint32_t> ring{v};
      for (int k = 0; k < 3; ++k)
        for (size_t i = 0, end = ring.size(); i < end; ++i)
          for (uint32_t q : adj[ring[i]])
            if (std::find(ring.begin(), ring.end(), q) == ring.end()) ring.push_back(q);
      const Vec3& p = r.after.positions[v];
      const auto dist = [&](int f) { return std::abs(r.seg.flats[size_t(f)].normal.dot(p) - r.seg.flats[size_t(f)].offset); };
      double nearest = INFINITY;
      for (uint32_t q : ring)
        if (region[q] >= 0) nearest = std::min(nearest, dist(int(region[q])));
      farther += dist(int(region[v])) > nearest + 0.05;
    }
    EXPECT_GT(joined, 100u);
    EXPECT_EQ(farther, 0u) << "of " << joined << " joined vertices";
  }
}

TEST(Sharpen, FreeEndsKeepTheCurvedSideOffTheFlatsCorner) {
  // Beyond the paper (Section 4, Fig. 7): the curve pieces between barriers
  // have free ends, so the curved side of a sharp rim follows its own shape
  // up to the rim instead of being pulled towards the flat's corner, and the
  // crease fit extrapolates a side that is not pressed in. Per rotation it
  // can go either way; over nine rotations of the cylinder at 64^3 the
  // result is closer to the truth and more of the rims are within 0.15
  // voxel of a label.
  double r_fixed = 0, r_free = 0, w_fixed = 0, w_free = 0;
  const std::vector<int> seeds{1, 2, 3, 4, 5, 6, 7, 8, 64};
  for (const int seed : seeds) {
    SCOPED_TRACE("cylinder 64 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cylinder, 64, seed);
    const auto truth = shape_truth(ShapeKind::cylinder, g.linear, g.translation);
    const auto sharp = truth->sharp_edges(30);
    StickSurface pinned = extract_sticks(g.volume), loose = pinned;
    const SliceCurves curves = build_slice_curves(pinned);
    const FlatOptions fo = paper_junctions();
    PressOptions po;
    po.free_ends = false;
    FlatSegmentation seg_fixed, seg_free;
    press_with_flats(pinned, curves, po, &fo, &seg_fixed);
    po.free_ends = true;
    press_with_flats(loose, curves, po, &fo, &seg_free);
    // The estimates keep fixed ends: the same flats either way.
    ASSERT_EQ(seg_free.region, seg_fixed.region);
    const SharpenResult a = sharpen(pinned, seg_fixed), b = sharpen(loose, seg_free);
    expect_valid(b.mesh, g.volume);
    const double ra = eval(a.mesh, *truth, g.volume).result_to_truth_vox.rms;
    const double rb = eval(b.mesh, *truth, g.volume).result_to_truth_vox.rms;
    const double wa = fraction_within(crease_distances(sharp, a.mesh), 0.15);
    const double wb = fraction_within(crease_distances(sharp, b.mesh), 0.15);
    r_fixed += ra, r_free += rb, w_fixed += wa, w_free += wb;
  }
  // Measured (means over the nine): result -> truth 0.0281 -> 0.0254,
  // share of the rims within 0.15 voxel 0.937 -> 0.956 (before the circle
  // correction, PressOptions::circle_correction, which keeps the curved
  // side from being pressed in either way: 0.0317 -> 0.0295, 0.905 -> 0.939).
  EXPECT_LT(r_free, 0.95 * r_fixed);
  EXPECT_GT(w_free, w_fixed + 0.012 * double(seeds.size()));
}

TEST(Sharpen, SnappingTakesBevelsNotCurvedFaces) {
  SharpenOptions off;
  off.snap_rings = 0;
  {
    // Box 128 seed 8: the flats stop ~5 cells short of two corners; the
    // curved patches there are explained by the flats' solid and snap onto
    // it, so the corners come back (two-sided crease Hausdorff measured 2.08
    // -> 0.33 voxel).
    const GeneratedShape g = shape(ShapeKind::box, 128, 8);
    const auto truth = shape_truth(ShapeKind::box, g.linear, g.translation);
    const Sharpened a = run(g.volume, {}, {}, off), b = run(g.volume);
    expect_valid(b.after, g.volume);
    EXPECT_GT(curved_vertices(a), 100u);
    EXPECT_EQ(curved_vertices(b), 0u);
    EXPECT_GT(b.stats.snapped, 1000u);
    const EvalReport ea = eval(a.after, *truth, g.volume), eb = eval(b.after, *truth, g.volume);
    EXPECT_LT(*eb.sharp_edge_hausdorff_vox, 0.5 * *ea.sharp_edge_hausdorff_vox);
  }
  for (int seed = 1; seed <= 2; ++seed) {
    // A capped cylinder's side is a curved face: its sticks lie outside the
    // caps' solid, so none of it snaps (the curved vertices are those
    // without snapping).
    SCOPED_TRACE("cylinder 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cylinder, 128, seed);
    const Sharpened a = run(g.volume, {}, {}, off), b = run(g.volume);
    expect_valid(b.after, g.volume);
    EXPECT_GT(curved_vertices(b), 30000u);
    EXPECT_EQ(curved_vertices(b), curved_vertices(a));
  }
}

TEST(Sharpen, SubdivisionFollowsFigure8) {
  const GeneratedShape g = shape(ShapeKind::box, 48, 4);
  const Sharpened r = run(g.volume);
  // Each chamfer triangle becomes 2, 3 or 6; the others are kept.
  const size_t orig = r.surface.triangles.size();
  EXPECT_GT(r.after.face_count(), orig);
  EXPECT_LE(r.after.face_count(), orig + 5 * r.stats.chamfer_triangles);
  EXPECT_GE(r.after.face_count(), orig + r.stats.chamfer_triangles);
  EXPECT_EQ(r.after.vertex_count(), r.surface.stick_count() + r.stats.inserted + r.stats.corners);
  EXPECT_EQ(r.stats.inserted, r.stats.chamfer_edges);
  // Euler characteristic unchanged (a sphere).
  const MeshCheck mc = check_mesh(r.after);
  EXPECT_EQ(mc.euler, 2);
  // Faces of a flat lie on its plane.
  const MeshAttribute* region = r.after.face_attribute("region");
  ASSERT_NE(region, nullptr);
  size_t on_plane = 0, flat_faces = 0;
  for (size_t f = 0; f < r.after.face_count(); ++f) {
    const int32_t id = int32_t(region->values[f]);
    if (id < 0) continue;
    ++flat_faces;
    const Flat& fl = r.seg.flats[size_t(id)];
    bool all = true;
    for (uint32_t v : r.after.triangles[f]) all &= std::abs(fl.normal.dot(r.after.positions[v]) - fl.offset) < 1e-6;
    on_plane += all;
  }
  EXPECT_GT(flat_faces, r.after.face_count() / 2);
  // (not all: a leftover vertex whose projection would cross a sample stays short of the plane)
  EXPECT_GE(double(on_plane), 0.9 * double(flat_faces));
}

TEST(Sharpen, PropertyCorpusKeepsEveryGuarantee) {
  FlatOptions fo;
  fo.min_area = 4;  // small volumes: let flats, junctions and chamfers happen
  fo.min_width = 1;
  PressOptions po;
  po.iterations = 30;
  size_t sharpened = 0;
  for (const test::Case& c : test::property_volumes()) {
    SCOPED_TRACE(c.name);
    const Sharpened r = run(c.volume, fo, po);
    expect_valid(r.after, c.volume);
    sharpened += r.stats.inserted > 0;
    for (const auto& e : r.after.edges) ASSERT_TRUE(e[0] < r.after.vertex_count() && e[1] < r.after.vertex_count());
  }
  EXPECT_GT(sharpened, 5u) << "the corpus exercises the sharpening";
}

TEST(Sharpen, AdversarialRotatedBoxUnionsKeepEveryGuarantee) {
  // Unions of small rotated boxes: many flats, concave creases, corners of
  // three or more faces and thin slabs, at low resolution.
  test::Rng rng(17);
  for (int k = 0; k < 12; ++k) {
    SCOPED_TRACE("union " + std::to_string(k));
    const int64_t n = 28;
    BinaryVolume v = test::make_volume(n, n, n);
    for (int b = 0; b < 3; ++b) {
      const GeneratedShape g = shape(ShapeKind::box, 12 + int64_t(rng.range(0, 8)), int(rng.range(1, 1000)));
      const auto& d = g.volume.lattice.dims;
      const int64_t ox = rng.range(0, n - d[0]), oy = rng.range(0, n - d[1]), oz = rng.range(0, n - d[2]);
      for (int64_t z = 0; z < d[2]; ++z)
        for (int64_t y = 0; y < d[1]; ++y)
          for (int64_t x = 0; x < d[0]; ++x)
            if (g.volume.at(x, y, z) && ox + x < n && oy + y < n && oz + z < n)
              v.inside[v.lattice.linear(ox + x, oy + y, oz + z)] = 1;
    }
    FlatOptions fo;
    fo.min_area = 10;
    const Sharpened r = run(v, fo);
    expect_valid(r.after, v);
  }
}

TEST(Sharpen, SameResultForOneAndManyThreads) {
  const GeneratedShape g = shape(ShapeKind::cad_part, 72, 3);
  Sharpened a, b;
  {
    tbb::task_arena arena(1);
    arena.execute([&] { a = run(g.volume); });
  }
  {
    tbb::task_arena arena(std::max(2, tbb::info::default_concurrency()));
    arena.execute([&] { b = run(g.volume); });
  }
  EXPECT_GT(a.stats.snapped, 0u) << "the parallel part (snap_to_flats) runs";
  EXPECT_EQ(a.stats.snapped, b.stats.snapped);
  EXPECT_EQ(a.after.positions, b.after.positions);
  EXPECT_EQ(a.after.triangles, b.after.triangles);
  EXPECT_EQ(a.after.edges, b.after.edges);
}

TEST(Sharpen, WithoutFlatsItIsThePressedMesh) {
  const GeneratedShape g = shape(ShapeKind::sphere, 40, 1);
  StickSurface s = extract_sticks(g.volume);
  FlatSegmentation none;
  press_with_flats(s, build_slice_curves(s), {}, nullptr, &none);
  const SharpenResult r = sharpen(s, none);
  const Mesh m = to_mesh(s);
  EXPECT_EQ(r.mesh.positions, m.positions);
  EXPECT_EQ(r.mesh.triangles, m.triangles);
  EXPECT_TRUE(r.mesh.edges.empty());
  EXPECT_EQ(r.stats.inserted, 0u);
}

TEST(Sharpen, SharpAngleOptionControlsTheLabels) {
  const GeneratedShape g = shape(ShapeKind::box, 128, 1);
  SharpenOptions strict;
  strict.sharp_angle = 120;  // the box's creases are 90 degrees: none is labelled
  const Sharpened a = run(g.volume), b = run(g.volume, {}, {}, strict);
  EXPECT_GT(a.after.edges.size(), 0u);
  EXPECT_TRUE(b.after.edges.empty());
  EXPECT_EQ(a.after.positions, b.after.positions) << "labels only: the geometry is the same";
}

// A closed box [0, a] x [0, b] x [0, c], faces outwards.
Mesh box_mesh(double a, double b, double c) {
  Mesh m;
  for (int k = 0; k < 8; ++k) m.positions.emplace_back(k & 1 ? a : 0, k & 2 ? b : 0, k & 4 ? c : 0);
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

TEST(Sharpen, ThinPlatesGetBothEdgesOfTheirRim) {
  // A plate a few cells thick: its rim lies between two opposite flats, and
  // the chamfer between two parallel planes has no line, so without the
  // walls one crease runs along the middle of the rim, a cell or more from
  // both true edges (fit_walls). The truth is the plate's mesh.
  SharpenOptions no_walls;
  no_walls.wall_thickness = 0;
  for (double cells : {2.5, 4.0})
    for (int seed : {1, 2, 3}) {
      SCOPED_TRACE("thickness " + std::to_string(cells) + " seed " + std::to_string(seed));
      const test::VoxelizedModel v = test::voxelized_model(box_mesh(1, 0.7, cells / 60), "plate", 64, seed);
      ASSERT_EQ(check_mesh(v.physical).problems.size(), 0u);
      const Sharpened with = run(v.volume), without = run(v.volume, {}, {}, no_walls);
      expect_valid(with.after, v.volume);
      EXPECT_GT(with.stats.wall_vertices, 0u);
      EXPECT_EQ(without.stats.wall_vertices, 0u);
      const EvalReport a = eval(with.after, *v.truth, v.volume), b = eval(without.after, *v.truth, v.volume);
      // Measured (with / without): recall 0.95-0.97 / 0.00-0.09, precision
      // 0.975-0.994 / 0.00-0.15, result -> truth 0.024-0.035 / 0.086-0.095.
      // Before the rim's flat vertices took the wall's plane where their
      // stick crosses it first, precision was 0.91-0.97 and result -> truth
      // 0.028-0.040: the rim kinked where a flat's plane ran past it.
      EXPECT_GT(a.sharp_recall.value_or(0), 0.85);
      EXPECT_GT(a.sharp_precision.value_or(0), 0.95);
      EXPECT_LT(b.sharp_recall.value_or(0), 0.3);
      EXPECT_LT(a.result_to_truth_vox.rms, 0.45 * b.result_to_truth_vox.rms);
      if (seed == 1) {  // the walls are fitted in parallel: same result on one thread
        Sharpened one;
        tbb::task_arena arena(1);
        arena.execute([&] { one = run(v.volume); });
        EXPECT_EQ(one.stats.wall_vertices, with.stats.wall_vertices);
        EXPECT_EQ(one.after.positions, with.after.positions);
        EXPECT_EQ(one.after.edges, with.after.edges);
      }
    }
}

TEST(Sharpen, CrossingThinPlatesKeepEveryGuarantee) {
  // Two or three rotated plates 1-4 cells thick through one another: rims
  // next to other plates' faces, walls one sample thick, T and X joints.
  test::Rng rng(23);
  size_t walls = 0;
  for (int k = 0; k < 10; ++k) {
    SCOPED_TRACE("plates " + std::to_string(k));
    const int64_t n = 44;
    BinaryVolume v = test::make_volume(n, n, n);
    const int plates = 2 + int(rng.range(0, 1));
    for (int p = 0; p < plates; ++p) {
      const Mat3 R = parse_rotation("random:" + std::to_string(rng.range(1, 100000)));
      const Vec3 c = Vec3::Constant(n / 2.0) + Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 8;
      const Vec3 half(10 + 6 * rng.uniform(), 8 + 6 * rng.uniform(), 0.5 + 1.5 * rng.uniform());
      for (int64_t z = 0; z < n; ++z)
        for (int64_t y = 0; y < n; ++y)
          for (int64_t x = 0; x < n; ++x) {
            const Vec3 q = R * (Vec3(double(x), double(y), double(z)) - c);
            if (std::abs(q.x()) <= half.x() && std::abs(q.y()) <= half.y() && std::abs(q.z()) <= half.z())
              v.inside[v.lattice.linear(x, y, z)] = 1;
          }
    }
    const Sharpened r = run(v);
    expect_valid(r.after, v);
    walls += r.stats.wall_vertices;
  }
  EXPECT_GT(walls, 0u);
}

// A solid of revolution about z from a profile of (radius, z) points,
// first and last on the axis (closed by two fans), `segments` around.
Mesh revolved(const std::vector<std::array<double, 2>>& profile, int segments) {
  Mesh m;
  const uint32_t rows = uint32_t(profile.size()) - 2;  // rings between the two poles
  m.positions.emplace_back(0, 0, profile.front()[1]);
  for (uint32_t i = 1; i <= rows; ++i)
    for (int k = 0; k < segments; ++k) {
      const double a = 2 * std::numbers::pi * k / segments;
      m.positions.emplace_back(profile[i][0] * std::cos(a), profile[i][0] * std::sin(a), profile[i][1]);
    }
  m.positions.emplace_back(0, 0, profile.back()[1]);
  const uint32_t S = uint32_t(segments), top = uint32_t(m.positions.size() - 1);
  auto at = [&](uint32_t i, uint32_t k) { return 1 + (i - 1) * S + k % S; };
  for (uint32_t k = 0; k < S; ++k) {
    m.triangles.push_back({0, at(1, k + 1), at(1, k)});
    for (uint32_t i = 1; i < rows; ++i) {
      m.triangles.push_back({at(i, k), at(i, k + 1), at(i + 1, k + 1)});
      m.triangles.push_back({at(i, k), at(i + 1, k + 1), at(i + 1, k)});
    }
    m.triangles.push_back({top, at(rows, k), at(rows, k + 1)});
  }
  return m;
}

TEST(Sharpen, CurvedCreasesArePlacedAndLabelled) {
  // Two cylinders and two cones between flat caps: a concave and two
  // convex creases between curved faces (45 degrees), which no flat border
  // reaches (fit_curved_creases at press time, curved_creases in sharpen).
  // Against the same pipeline without them: more accurate, the creases
  // labelled, the guarantees kept, the same flats, one thread = many.
  std::vector<std::array<double, 2>> profile{{0, -0.6}, {0.35, -0.6}};
  auto line = [&](double r, double z) {  // subdivided, so the truth's faces stay small along z
    const auto [r0, z0] = profile.back();
    for (int i = 1; i <= 8; ++i) profile.push_back({r0 + (r - r0) * i / 8, z0 + (z - z0) * i / 8});
  };
  line(0.35, -0.25);  // cylinder
  line(0.6, 0.0);     // cone out: concave crease at its foot
  line(0.6, 0.2);     // cylinder: convex crease
  line(0.25, 0.55);   // cone in: convex crease
  profile.push_back({0, 0.55});
  const Mesh model = revolved(profile, 384);
  ASSERT_TRUE(check_mesh(model).ok());
  FlatOptions fo_off;
  fo_off.curved_creases = false;
  SharpenOptions so_off;
  so_off.curved_creases = false;
  for (int seed : {1, 2, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const test::VoxelizedModel v = test::voxelized_model(model, "revolved", 96, seed);
    const Sharpened on = run(v.volume), off = run(v.volume, fo_off, {}, so_off);
    expect_valid(on.after, v.volume);
    EXPECT_GT(on.seg.stats.curved_crease_vertices, 0u);
    EXPECT_GT(on.stats.curved_crease_vertices, 0u);
    EXPECT_EQ(off.seg.stats.curved_crease_vertices + off.stats.curved_crease_vertices, 0u);
    EXPECT_EQ(on.seg.flats.size(), off.seg.flats.size());
    const EvalReport a = eval(on.after, *v.truth, v.volume), b = eval(off.after, *v.truth, v.volume);
    // Measured with / without (seeds 1-3): result -> truth 0.059-0.063 /
    // 0.068-0.077, recall within 0.5 voxel 0.61-0.72 / 0.21-0.26 (the caps'
    // flat borders only), precision 0.96-0.99 / 0.97-0.99.
    EXPECT_LT(a.result_to_truth_vox.rms, 0.92 * b.result_to_truth_vox.rms);
    EXPECT_GT(a.sharp_recall.value_or(0), b.sharp_recall.value_or(0) + 0.25);
    EXPECT_GT(a.sharp_precision.value_or(0), 0.9);
    if (seed == 1) {  // the fits run in parallel: same result on one thread
      Sharpened one;
      tbb::task_arena arena(1);
      arena.execute([&] { one = run(v.volume); });
      EXPECT_EQ(one.after.positions, on.after.positions);
      EXPECT_EQ(one.after.edges, on.after.edges);
    }
  }
}

TEST(Sharpen, FandiskGetsMoreAccurate) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const test::VoxelizedModel v = test::voxelized_shared_model("fandisk.off", 128, 1);
  const Sharpened r = run(v.volume);
  expect_valid(r.after, v.volume);
  const EvalReport before = eval(r.before, *v.truth, v.volume), after = eval(r.after, *v.truth, v.volume);
  EXPECT_LT(after.result_to_truth_vox.rms, before.result_to_truth_vox.rms);
  EXPECT_GT(r.after.edges.size(), 0u);
  // The crease between a thin wall and a curved face is labelled: with the
  // wall's vertices left out of the curved crease fit's sides it was not,
  // and the true sharp curves were 8.9 voxels from a label there (5.9 now,
  // at a 30-33 degree crease elsewhere).
  ASSERT_TRUE(after.sharp_true_to_labelled_vox.has_value());
  EXPECT_LT(*after.sharp_true_to_labelled_vox, 7.0);
}

}  // namespace
}  // namespace voxpress
