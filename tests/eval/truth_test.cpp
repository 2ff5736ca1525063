// Truths: exact closest points, uniform area samples, areas, sharp edges.
#include <numbers>

#include "../../src/eval/polygon.h"
#include "test_util.h"
#include "voxpress/eval/truth.h"

namespace voxpress {
namespace {

// The exact closest point of a shape 7.5 x its model placed at (3, -2, 40)
// can never be farther than the nearest of many dense surface samples, nor
// much closer; it is on the surface (inside just below, outside just above)
// with a unit normal.
void expect_exact_closest_points(const Truth& truth, test::Rng& rng) {
  std::vector<Vec3> dense;
  for (uint64_t i = 0; i < 200000; ++i) dense.push_back(truth.sample(3, i).point);
  for (int q = 0; q < 40; ++q) {
    const Vec3 p = Vec3(3, -2, 40) + 12 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    const SurfacePoint c = truth.closest(p);
    double best = INFINITY;
    for (const Vec3& d : dense) best = std::min(best, (d - p).norm());
    const double exact = (c.point - p).norm();
    EXPECT_LE(exact, best + 1e-9);
    EXPECT_GE(exact, best - 0.08);  // samples are ~0.05 apart on this 7.5x shape
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    EXPECT_TRUE(truth.contains(c.point - 1e-6 * c.normal));
    EXPECT_FALSE(truth.contains(c.point + 1e-6 * c.normal));
  }
}

TEST(Truth, AnalyticClosestPointsBeatEveryDenseSample) {
  // The exact closest point can never be farther than the nearest of many
  // dense surface samples, and never much closer than them.
  test::Rng rng(4);
  const Mat3 R = parse_rotation("random:12");
  for (ShapeKind k : {ShapeKind::sphere, ShapeKind::torus, ShapeKind::box, ShapeKind::cylinder}) {
    SCOPED_TRACE(shape_name(k));
    const auto truth = shape_truth(k, 7.5 * R, Vec3(3, -2, 40));
    expect_exact_closest_points(*truth, rng);
  }
}

TEST(Truth, SamplesAreUniformByArea) {
  const auto sphere = shape_truth(ShapeKind::sphere, 2 * Mat3::Identity(), Vec3::Zero());
  EXPECT_NEAR(sphere->area(), 16 * std::numbers::pi, 1e-9);
  EXPECT_NEAR(sphere->volume(), 32.0 / 3 * std::numbers::pi, 1e-9);
  // Uniform on a sphere: each coordinate of the normal is uniform on [-1, 1].
  int upper = 0;
  Vec3 mean = Vec3::Zero();
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const SurfacePoint s = sphere->sample(1, uint64_t(i));
    EXPECT_NEAR(s.point.norm(), 2.0, 1e-12);
    upper += s.normal.z() > 0.5;
    mean += s.normal;
  }
  EXPECT_NEAR(double(upper) / n, 0.25, 0.005);
  EXPECT_LT((mean / n).norm(), 0.01);
  // Torus: the outer half (cos v > 0) holds (R + 2r/pi) / (2R) of the area.
  const auto torus = shape_truth(ShapeKind::torus, Mat3::Identity(), Vec3::Zero());
  int outer = 0;
  for (int i = 0; i < n; ++i) {
    const SurfacePoint s = torus->sample(2, uint64_t(i));
    outer += std::hypot(s.point.x(), s.point.y()) > 1.0;
  }
  EXPECT_NEAR(double(outer) / n, (1.0 + 2 * 0.4 / std::numbers::pi) / 2, 0.005);
  EXPECT_NEAR(torus->area(), 4 * std::numbers::pi * std::numbers::pi * 0.4, 1e-9);
}

TEST(Truth, MeshTruthMatchesAnalyticOnAFineSphere) {
  // A fine icosphere-like mesh: its closest points agree with the analytic sphere.
  GenerateOptions o;
  o.res = 96;
  const GeneratedShape g = generate_shape(ShapeKind::sphere, o);
  Mesh m = to_mesh(extract_sticks(g.volume));
  for (Vec3& p : m.positions) p = g.translation + g.scale * (p - g.translation).normalized();  // project
  const auto mesh = mesh_truth(m, "projected sphere");
  const auto exact = shape_truth(ShapeKind::sphere, g.scale * Mat3::Identity(), g.translation);
  EXPECT_NEAR(mesh->area() / exact->area(), 1.0, 2e-3);
  EXPECT_NEAR(mesh->volume() / exact->volume(), 1.0, 2e-3);
  test::Rng rng(1);
  for (int q = 0; q < 200; ++q) {
    const Vec3 p = g.translation + 60 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    EXPECT_NEAR((mesh->closest(p).point - p).norm(), (exact->closest(p).point - p).norm(), 0.02);
    EXPECT_GT(mesh->closest(p).normal.dot(exact->closest(p).normal), 0.99);
  }
  // Crossing of a segment through the centre: at distance R from the centre.
  const Vec3 a = g.translation, b = g.translation + Vec3(2 * g.scale, 0, 0);
  EXPECT_NEAR(mesh->crossing(a, b, 0.5), 0.5, 1e-3);
  EXPECT_NEAR(exact->crossing(a, b, 0.5), 0.5, 1e-12);
}

TEST(Truth, SharpEdges) {
  const auto box = shape_truth(ShapeKind::box, Mat3::Identity(), Vec3::Zero());
  EXPECT_EQ(box->sharp_edges(30).size(), 12u);
  EXPECT_TRUE(shape_truth(ShapeKind::sphere, Mat3::Identity(), Vec3::Zero())->sharp_edges(30).empty());
  double cyl = 0;
  for (const auto& e : shape_truth(ShapeKind::cylinder, Mat3::Identity(), Vec3::Zero())->sharp_edges(30))
    cyl += (e[1] - e[0]).norm();
  EXPECT_NEAR(cyl, 2 * 2 * std::numbers::pi * 0.6, 1e-3);
  // The CAD part: outlines, chamfer, +x corners, hole rims and the boss rim
  // (19.941 model units); fillets and rounded corners are tangent, not sharp.
  double cad = 0;
  for (const auto& e : shape_truth(ShapeKind::cad_part, Mat3::Identity(), Vec3::Zero())->sharp_edges(30))
    cad += (e[1] - e[0]).norm();
  const double expected = (1.4 + 3.6 + 1.0 + std::numbers::pi * 0.2) + (3.3 + 1.0 + std::numbers::pi * 0.2 + 1.4) +
                          1.4 + 2 * 0.15 * std::sqrt(2.0) + 0.7 + 2 * 2 * std::numbers::pi * 0.18 +
                          2 * std::numbers::pi * 0.35;
  EXPECT_NEAR(cad, expected, 1e-3);
}

// Generated with a radius of `cells`: the same lattice as the sharp shape, a
// subset of its samples, the closed-form volume (counted within 1 %, the
// truth's exactly); a radius of `too_big` cells is refused.
GeneratedShape expect_filleted_volume(ShapeKind kind, double cells, double too_big) {
  GenerateOptions o;
  o.res = 48;
  o.rotation = parse_rotation("random:4");
  const GeneratedShape sharp = generate_shape(kind, o);
  o.fillet = cells;
  GeneratedShape round = generate_shape(kind, o);
  EXPECT_EQ(round.volume.lattice.dims, sharp.volume.lattice.dims);
  EXPECT_NEAR(round.fillet * round.scale, cells, 1e-12);
  size_t outside_sharp = 0;
  for (size_t i = 0; i < sharp.volume.inside.size(); ++i) outside_sharp += round.volume.inside[i] && !sharp.volume.inside[i];
  EXPECT_EQ(outside_sharp, 0u);
  EXPECT_LT(round.volume.count_inside(), sharp.volume.count_inside());
  const double exact = shape_volume(kind, round.fillet) * std::pow(round.scale, 3);
  EXPECT_NEAR(double(round.volume.count_inside()) / exact, 1.0, 0.01);
  EXPECT_NEAR(shape_truth(kind, round.linear, round.translation, round.fillet)->volume(), exact, 1e-9 * exact);
  o.fillet = too_big;
  EXPECT_THROW(generate_shape(kind, o), UsageError);
  return round;
}

// The filleted box (issue 75's truth-known family): its closed-form closest
// point, area sampler, area and volume agree with each other and with the
// generated volume; the rounded box has no sharp edge, the sharp one 12; the
// lattice is the sharp box's and the rounded solid lies inside it; `eval`
// finds the radius in the volume's metadata.
TEST(Truth, FilletedBoxIsExactAndHasNoSharpEdges) {
  test::Rng rng(5);
  const Mat3 R = parse_rotation("random:12");
  const double f = 0.2;  // model units (the box's half extents: 1, 0.75, 0.5)
  const auto truth = shape_truth(ShapeKind::box, 7.5 * R, Vec3(3, -2, 40), f);
  expect_exact_closest_points(*truth, rng);
  // Area: the sharp box's minus what rounding takes (Steiner), as the sampler's pieces add up.
  const double pi = std::numbers::pi, s2 = 7.5 * 7.5;
  const Vec3 h = Vec3(1, 0.75, 0.5) - Vec3::Constant(f);
  EXPECT_NEAR(truth->area(), s2 * (8 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z()) + 4 * pi * f * h.sum() + 4 * pi * f * f),
              1e-9);
  EXPECT_TRUE(truth->sharp_edges(30).empty());
  EXPECT_EQ(shape_truth(ShapeKind::box, 7.5 * R, Vec3(3, -2, 40), 0)->sharp_edges(30).size(), 12u);
  const GeneratedShape round = expect_filleted_volume(ShapeKind::box, 4, 20);
  GenerateOptions o;
  o.fillet = 1;
  EXPECT_THROW(generate_shape(ShapeKind::sphere, o), UsageError);
  // From the volume's metadata, as `eval` reads it.
  ScalarVolume v;
  v.source = "box.nrrd";
  v.metadata[kShapeKey] = "box";
  v.metadata[kModelToPhysicalKey] = format_transform(round.linear, round.translation);
  v.metadata[kFilletKey] = std::to_string(round.fillet);
  EXPECT_TRUE(resolve_truth("", &v)->sharp_edges(30).empty());
  v.metadata[kFilletKey] = "x";
  EXPECT_THROW(resolve_truth("", &v), InputError);
}

// The filleted cylinder (the family's one-flat case: a cap meets a curved
// side through the fillet): its closest point and sampler agree; its area
// is Steiner's derivative S + 2 M f + 4 pi f^2 of the shrunk cylinder's
// volume polynomial (the code sums side, caps and Pappus' rims); the
// generated volume counts the closed-form volume; no sharp edge.
TEST(Truth, FilletedCylinderIsExactAndHasNoSharpEdges) {
  test::Rng rng(6);
  const Mat3 R = parse_rotation("random:13");
  const double f = 0.25, pi = std::numbers::pi;  // the cylinder: radius 0.6, half height 1
  const auto truth = shape_truth(ShapeKind::cylinder, 7.5 * R, Vec3(3, -2, 40), f);
  expect_exact_closest_points(*truth, rng);
  const double r = 0.6 - f, h = 1.0 - f;
  const double S = 4 * pi * r * h + 2 * pi * r * r, M = 2 * pi * h + pi * pi * r;
  EXPECT_NEAR(truth->area(), 7.5 * 7.5 * (S + 2 * M * f + 4 * pi * f * f), 1e-9);
  EXPECT_TRUE(truth->sharp_edges(30).empty());
  EXPECT_FALSE(shape_truth(ShapeKind::cylinder, 7.5 * R, Vec3(3, -2, 40), 0)->sharp_edges(30).empty());
  // Uniform by area: the share of normals within 30 degrees of the axis is
  // that of the caps and the rims' bands theta in [60, 90] degrees.
  const Vec3 axis = (R * Vec3::UnitZ()).normalized();
  const int n = 200000;
  int near_axis = 0;
  for (int i = 0; i < n; ++i) near_axis += std::abs(truth->sample(2, uint64_t(i)).normal.dot(axis)) > std::cos(pi / 6);
  // A rim's band theta in [60, 90] degrees: the integral of 2 pi (r + f cos theta) f, times two rims.
  const double band = 2 * 2 * pi * f * (r * (pi / 6) + f * (1 - std::sin(pi / 3)));
  const double share = (2 * pi * r * r + band) / (S + 2 * M * f + 4 * pi * f * f);
  EXPECT_NEAR(double(near_axis) / n, share, 0.005);
  expect_filleted_volume(ShapeKind::cylinder, 3, 30);
}

TEST(Truth, ResolveFromVolumeMetadata) {
  ScalarVolume v;
  v.source = "vol.nrrd";
  EXPECT_THROW(resolve_truth("", &v), UsageError);
  EXPECT_THROW(resolve_truth("sphere", &v), UsageError);  // placement unknown
  v.metadata[kShapeKey] = "torus";
  v.metadata[kModelToPhysicalKey] = format_transform(3 * Mat3::Identity(), Vec3(1, 2, 3));
  const auto t = resolve_truth("", &v);
  EXPECT_NE(t->describe().find("torus"), std::string::npos);
  EXPECT_NEAR(t->closest(Vec3(1, 2, 3) + Vec3(3 * 1.4 + 1, 0, 0)).point.x(), 1 + 3 * 1.4, 1e-12);
  Mat3 L;
  Vec3 T;
  EXPECT_TRUE(parse_transform(format_transform(parse_rotation("random:3"), Vec3(1, 2, 3)), L, T));
  EXPECT_LT((L - parse_rotation("random:3")).norm(), 1e-15);
  EXPECT_FALSE(parse_transform("1 2 3", L, T));
  v.metadata[kModelToPhysicalKey] = "garbage";
  EXPECT_THROW(resolve_truth("", &v), InputError);
}

TEST(Polygon, EarClippingWithHolesCoversTheExactArea) {
  // A square with two square holes, and a circle-with-circle-holes like the CAD top face.
  auto area_of = [](const std::vector<detail::Point2>& pts, const std::vector<std::array<uint32_t, 3>>& tris) {
    double a = 0;
    for (const auto& t : tris) {
      const auto &p = pts[t[0]], &q = pts[t[1]], &r = pts[t[2]];
      const double s = (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
      EXPECT_GT(s, 0) << "triangles must be counter-clockwise and non-degenerate";
      a += 0.5 * s;
    }
    return a;
  };
  std::vector<detail::Point2> outer{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  std::vector<std::vector<detail::Point2>> holes{{{2, 2}, {2, 4}, {4, 4}, {4, 2}}, {{6, 6}, {6, 8}, {8, 8}, {8, 6}}};
  std::vector<detail::Point2> all = outer;
  for (const auto& h : holes) all.insert(all.end(), h.begin(), h.end());
  const auto tris = detail::triangulate_polygon(outer, holes);
  EXPECT_EQ(tris.size(), 4 + 4 + 4 + 2 * 2 - 2u);  // n + 2h - 2 triangles
  EXPECT_NEAR(area_of(all, tris), 100 - 8, 1e-12);
  // Circles.
  std::vector<detail::Point2> ring, h1, h2;
  const int n = 256;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    ring.push_back({5 * std::cos(a), 5 * std::sin(a)});
    h1.push_back({-2 + std::cos(-a), std::sin(-a)});
    h2.push_back({2 + 1.5 * std::cos(-a), 0.5 + 1.5 * std::sin(-a)});
  }
  std::vector<detail::Point2> all2 = ring;
  all2.insert(all2.end(), h1.begin(), h1.end());
  all2.insert(all2.end(), h2.begin(), h2.end());
  const double polygon_area = 0.5 * n * std::sin(2 * std::numbers::pi / n) * (25 - 1 - 2.25);
  EXPECT_NEAR(area_of(all2, detail::triangulate_polygon(ring, {h1, h2})), polygon_area, 1e-9);
}

}  // namespace
}  // namespace voxpress
