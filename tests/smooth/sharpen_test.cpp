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
#include "voxpress/features/sharpen.h"

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
  r.surface = on_own_box(extract_sticks(volume));  // as smooth_sticks runs every stage
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
  for (int seed : {1, 2, 3, 29}) {  // (CI time: bench_flats sweeps seeds 1-50)
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

TEST(Sharpen, CadPartErrorDropsAndItsCreasesAreFound) {
  // Sharpened as `voxpress press` does it (the quadric fit included), the
  // CAD part is closer to the truth in position and normal, and its
  // labelled creases and the true ones lie near each other both ways. Each
  // rotation here once had a spot where a vertex beside two flats sent the
  // labels astray: seed 3, a fillet tangent to one flat met the other at a
  // crease but was judged against the tangent flat alone; seed 10, a curved
  // junction at a sample stayed curved and the chain detoured round it;
  // seed 128, a corner without a curved plane stayed at its centroid.
  for (const int seed : {3, 10, 128}) {
    SCOPED_TRACE("cad part 128 seed " + std::to_string(seed));
    const GeneratedShape g = shape(ShapeKind::cad_part, 128, seed);
    const Sharpened r = run(g.volume, {}, {}, {}, true);
    expect_valid(r.after, g.volume);
    const auto t = shape_truth(ShapeKind::cad_part, g.linear, g.translation);
    const EvalReport before = eval(r.before, *t, g.volume), after = eval(r.after, *t, g.volume);
    EXPECT_LT(after.result_to_truth_vox.rms, before.result_to_truth_vox.rms);
    EXPECT_LT(after.normal_error_deg, before.normal_error_deg);
    // How much of the crease network is found, and how much of what is
    // labelled is real (within half a voxel). One worst point (the two-sided
    // Hausdorff) is a lottery over where the lattice falls: over seeds 3, 10
    // and 128 each generated with margins 2-7 (18 samplings) it ranged
    // 0.22-18.7 voxels, recall 97.4-100 % and precision 98.0-100 %.
    ASSERT_TRUE(after.sharp_recall && after.sharp_precision);
    EXPECT_GE(*after.sharp_recall, 0.97);
    EXPECT_GE(*after.sharp_precision, 0.97);
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
  EXPECT_GE(sharpened, 5u) << "the corpus exercises the sharpening (5 cases in the sanitizers' smaller corpus)";
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

TEST(Sharpen, CurvedCreasesOnlyWhereTheyContinueAFlatsCrease) {
  // A box beside a lens (two spheres' intersection: a circular crease of
  // about 70 degrees between two curved faces, tilted off the lattice).
  // The box's flats make the layer run; the lens' crease joins no flat's
  // border, so crease-network keeps it rounded; switched off, it is labelled.
  const int64_t nx = 80, n = 40;
  BinaryVolume v = test::make_volume(nx, n, n);
  const Vec3 axis = Vec3(1, 2, 3).normalized(), centre(58, 20, 20);
  for (int64_t z = 0; z < n; ++z)
    for (int64_t y = 0; y < n; ++y)
      for (int64_t x = 0; x < nx; ++x) {
        const Vec3 p{double(x), double(y), double(z)};
        const bool box = x >= 4 && x <= 34 && y >= 6 && y <= 33 && z >= 7 && z <= 32;
        const bool lens = (p - centre - 8 * axis).norm() < 14 && (p - centre + 8 * axis).norm() < 14;
        v.inside[v.lattice.linear(x, y, z)] = box || lens;
      }
  auto lens_edges = [](const Sharpened& r) {
    size_t count = 0;
    for (const auto& e : r.after.edges) count += r.after.positions[e[0]].x() > 40 && r.after.positions[e[1]].x() > 40;
    return count;
  };
  const Sharpened on = run(v, {}, {}, {}, true);
  expect_valid(on.after, v);
  EXPECT_GT(on.after.edges.size(), 0u) << "the box keeps its edges";
  EXPECT_EQ(lens_edges(on), 0u);
  FlatOptions fo;
  SharpenOptions so;
  fo.passes.disable(Pass::crease_network);
  so.passes.disable(Pass::crease_network);
  const Sharpened off = run(v, fo, {}, so, true);
  expect_valid(off.after, v);
  EXPECT_GT(lens_edges(off), 20u) << "without the network the lens' crease is labelled";
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
  no_walls.passes.disable(Pass::walls);
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

TEST(Sharpen, FandiskGetsMoreAccurate) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const test::VoxelizedModel v = test::voxelized_shared_model("fandisk.off", 128, 1);
  const Sharpened r = run(v.volume);
  expect_valid(r.after, v.volume);
  const EvalReport before = eval(r.before, *v.truth, v.volume), after = eval(r.after, *v.truth, v.volume);
  EXPECT_LT(after.result_to_truth_vox.rms, before.result_to_truth_vox.rms);
  EXPECT_GT(r.after.edges.size(), 0u);
  // Most of the crease network is found (the crease between a thin wall
  // and a curved face was not while the wall's vertices were in the curved
  // crease fit's sides), and what is labelled is real. Over voxelizations
  // with margins 2-7 (six samplings) recall was 91.7-94.9 % and precision
  // 94.8-97.4 %; the largest gap, one point, 4.1-18.1 voxels.
  ASSERT_TRUE(after.sharp_recall && after.sharp_precision);
  EXPECT_GE(*after.sharp_recall, 0.90);
  EXPECT_GE(*after.sharp_precision, 0.94);
}

}  // namespace
}  // namespace voxpress

namespace voxpress {
namespace {

TEST(Sharpen, FilletsTheLatticeResolvesStayRound) {
  // Issue 75's family at 48^3 (bench_fillets sweeps it at 128^3): a box whose
  // edges are rounded by 1.5 cells is pressed as `voxpress press` does it.
  // Its samples allow and demand a rounding (round-chains), so next to no
  // crease is labelled and the default is as close to the truth as without
  // sharpening (before: every edge labelled, RMS above --no-sharpen's); the
  // sharp box (r = 0) at the same rotations keeps all its edges.
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    size_t sharp_labels = 0;
    for (double r : {0.0, 1.5}) {
      const test::ShapeAndTruth box = test::filleted_box(48, seed, r);
      const GeneratedShape& g = box.shape;
      const auto& truth = box.truth;
      SurfaceOptions plain;
      plain.passes.disable(Pass::sharpen);
      const SurfaceResult on = smooth_surface(g.volume, {}), off = smooth_surface(g.volume, plain);
      expect_valid(on.mesh, g.volume);
      const EvalReport a = eval(on.mesh, *truth, g.volume), b = eval(off.mesh, *truth, g.volume);
      if (r == 0) {
        sharp_labels = on.mesh.edges.size();
        ASSERT_TRUE(a.sharp_recall);
        EXPECT_GT(*a.sharp_recall, 0.99);
        EXPECT_LT(a.result_to_truth_vox.rms, 0.5 * b.result_to_truth_vox.rms);
      } else {
        EXPECT_LT(on.mesh.edges.size(), sharp_labels / 10) << "measured 26, 41 of ~900";
        EXPECT_LT(a.result_to_truth_vox.rms, 1.03 * b.result_to_truth_vox.rms);
      }
    }
  }
}

TEST(Sharpen, StripsOfResolvedFilletsStayCurved) {
  // round-strips: the narrow curved band a 3-cell fillet leaves between two
  // flats is judged as a whole; its samples allow the rounding and the
  // flats' solid does not explain its sticks, so it stays curved instead
  // of joining its flats (which flattened the fillet). A sharp box has no
  // such band.
  for (int seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    for (double r : {0.0, 3.0}) {
      const test::RuleOnOff t = test::fillet_rule_on_off(64, seed, r, Pass::round_strips);
      if (r == 0) {
        EXPECT_EQ(t.count, 0u);
        continue;
      }
      EXPECT_GT(t.count, 0u);
      const BinaryVolume& v = t.box.shape.volume;
      const double a = eval(t.on.mesh, *t.box.truth, v).result_to_truth_vox.rms;
      const double b = eval(t.off.mesh, *t.box.truth, v).result_to_truth_vox.rms;
      EXPECT_LT(a, b) << "measured 0.0582 against 0.0600, 0.0596 against 0.0641";
    }
  }
}

}  // namespace
}  // namespace voxpress
