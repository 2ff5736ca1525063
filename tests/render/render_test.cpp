// The software renderer and the voxel-face mesh of previews.
#include "test_util.h"
#include "voxpress/render/render.h"

namespace voxpress {
namespace {

// Pixels differing from the background, and their bounding rectangle.
struct Ink {
  int64_t count = 0, x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};
Ink ink(const Texture& t) {
  Ink k;
  for (int64_t y = 0; y < t.height; ++y)
    for (int64_t x = 0; x < t.width; ++x) {
      const uint8_t* p = &t.rgba[size_t(y * t.width + x) * 4];
      if (p[0] == 255 && p[1] == 255 && p[2] == 255) continue;
      ++k.count, k.x0 = std::min(k.x0, x), k.y0 = std::min(k.y0, y), k.x1 = std::max(k.x1, x), k.y1 = std::max(k.y1, y);
    }
  return k;
}

BinaryVolume box_volume(std::array<int64_t, 3> dims, std::array<int64_t, 3> lo, std::array<int64_t, 3> hi) {
  BinaryVolume v = test::make_volume(dims[0], dims[1], dims[2]);
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) v.inside[v.lattice.linear(i, j, k)] = 1;
  return v;
}

TEST(VoxelFaces, ClosedOutwardAndEnclosingEveryInsideCell) {
  BinaryVolume v = box_volume({8, 7, 6}, {1, 2, 1}, {5, 4, 3});
  v.lattice.spacing = Vec3(0.5, 1.0, 2.0);
  for (bool mirror : {false, true}) {
    SCOPED_TRACE(mirror ? "mirrored lattice" : "plain lattice");
    if (mirror) v.lattice.direction = Vec3(-1, 1, 1).asDiagonal();
    const Mesh m = voxel_faces(v);
    const MeshCheck c = check_mesh(m, {.self_intersections = false});
    EXPECT_TRUE(c.closed() && c.manifold() && c.oriented());
    EXPECT_NEAR(signed_volume(m), 5 * 3 * 3 * 0.5 * 1.0 * 2.0, 1e-9);  // positive: outward
    EXPECT_EQ(m.triangles.size(), size_t(2 * 2 * (5 * 3 + 3 * 3 + 5 * 3)));
  }
  // Random volumes: every face separates an inside cell from an outside one,
  // so the enclosed volume is the inside count (non-manifold corners allowed).
  test::Rng rng(3);
  for (int r = 0; r < 20; ++r) {
    const BinaryVolume n = test::random_noise(rng, {9, 8, 7}, 0.4);
    EXPECT_NEAR(signed_volume(voxel_faces(n)), double(n.count_inside()), 1e-9);
  }
}

TEST(Render, SilhouetteOfABoxAlongZIsItsRectangle) {
  const BinaryVolume v = box_volume({40, 40, 10}, {5, 10, 2}, {34, 24, 7});  // 30 x 15 cells
  const Mesh m = voxel_faces(v);
  RenderOptions o;
  o.width = 400, o.height = 300, o.view = View::z, o.supersample = 1;
  const Texture t = render_mesh(m, o);
  ASSERT_EQ(t.rgba.size(), size_t(400 * 300 * 4));
  const Ink k = ink(t);
  const double w = double(k.x1 - k.x0 + 1), h = double(k.y1 - k.y0 + 1);
  EXPECT_NEAR(w / h, 2.0, 0.03);                     // 30 : 15 cells
  EXPECT_NEAR(w, 0.92 * 400, 2.0);                  // fills 92 % of the width
  EXPECT_NEAR(double(k.count), w * h, 0.01 * w * h);  // a full rectangle
  // The same bytes every time.
  EXPECT_EQ(render_mesh(m, o).rgba, t.rgba);
}

TEST(Render, ColoursRegionsTexturesAndFeatures) {
  GenerateOptions g;
  g.res = 32;
  g.rotation = parse_rotation("random:2");
  const BinaryVolume v = generate_shape(ShapeKind::box, g).volume;
  const Mesh pressed = smooth_surface(v).mesh;
  ASSERT_NE(pressed.vertex_attribute("region"), nullptr);
  RenderOptions o;
  o.width = o.height = 200;
  o.coloring = Coloring::plain;
  o.features = false;
  const Texture plain = render_mesh(pressed, o);
  o.coloring = Coloring::regions;
  const Texture regions = render_mesh(pressed, o);
  EXPECT_NE(plain.rgba, regions.rgba);
  EXPECT_EQ(ink(plain).count, ink(regions).count);  // same silhouette
  if (!pressed.edges.empty()) {
    o.features = true;
    EXPECT_NE(render_mesh(pressed, o).rgba, regions.rgba);
  }
  // A textured square facing +z: its picture is the texture's colour (shaded).
  Mesh quad;
  quad.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  quad.uvs = {Vec2(0, 1), Vec2(1, 1), Vec2(1, 0), Vec2(0, 0)};
  quad.texture.width = quad.texture.height = 2;
  quad.texture.rgba = {250, 0, 0, 255, 250, 0, 0, 255, 0, 0, 250, 255, 0, 0, 250, 255};  // top red, bottom blue
  RenderOptions q;
  q.view = View::z, q.width = q.height = 100, q.supersample = 1;
  const Texture t = render_mesh(quad, q);
  const uint8_t* top = &t.rgba[size_t(25 * 100 + 50) * 4];
  const uint8_t* bottom = &t.rgba[size_t(75 * 100 + 50) * 4];
  EXPECT_GT(top[0], 150);
  EXPECT_LT(top[2], 30);
  EXPECT_GT(bottom[2], 150);
  EXPECT_LT(bottom[0], 30);
  // A label map's interfaces colour by label_in: two labels, two colours.
  Mesh labelled = quad;
  labelled.uvs.clear();
  labelled.texture = {};
  labelled.face_attributes = {{"label_in", ScalarType::u32, {3, 3}}, {"label_out", ScalarType::u32, {0, 0}}};
  q.coloring = Coloring::regions;
  const Texture three = render_mesh(labelled, q);
  labelled.face_attributes[0].values = {3, 8};
  const Texture two = render_mesh(labelled, q);
  EXPECT_EQ(three.rgba[size_t(30 * 100 + 80) * 4], two.rgba[size_t(30 * 100 + 80) * 4]) << "the face of label 3";
  EXPECT_NE(std::vector<uint8_t>(three.rgba.begin() + (70 * 100 + 20) * 4, three.rgba.begin() + (70 * 100 + 20) * 4 + 3),
            std::vector<uint8_t>(two.rgba.begin() + (70 * 100 + 20) * 4, two.rgba.begin() + (70 * 100 + 20) * 4 + 3))
      << "the face of label 8";
  RenderOptions tiny;
  tiny.width = 8;
  EXPECT_THROW(render_mesh(quad, tiny), UsageError);
  EXPECT_THROW(parse_view("top"), UsageError);
}

// --wireframe draws the triangles' edges: a box's voxel faces seen along z
// show one grey line per row and column of cells, nothing outside it.
TEST(Render, WireframeDrawsTheTrianglesEdges) {
  const Mesh m = voxel_faces(box_volume({12, 12, 12}, {2, 2, 2}, {9, 9, 9}));
  RenderOptions o;
  o.view = View::z;
  o.width = o.height = 200;
  const Texture plain = render_mesh(m, o);
  o.wireframe = true;
  const Texture wire = render_mesh(m, o);
  const Ink a = ink(plain), b = ink(wire);
  EXPECT_NEAR(double(a.x0), double(b.x0), 2);  // the outline's strokes may add a pixel
  EXPECT_NEAR(double(a.x1), double(b.x1), 2);
  EXPECT_NEAR(double(a.y1), double(b.y1), 2);
  // Stroke-dark pixels along a row through the box (the face is far
  // lighter): one run per edge line crossed.
  const int64_t y = 100;
  int darker = 0, runs = 0;
  bool in_run = false;
  for (int64_t x = 0; x < 200; ++x) {
    const size_t p = size_t(y * 200 + x) * 4;
    const bool dark = wire.rgba[p] < 120 && plain.rgba[p] > 150;
    darker += dark;
    runs += dark && !in_run;
    in_run = dark;
  }
  EXPECT_GT(darker, 0);
  EXPECT_GE(runs, 8);  // 8 cells across (the edges between cells and the two sides; diagonals add more)
}

TEST(Render, RegionColoursAreDistinctForNeighbouringIds) {
  for (int64_t r = 0; r < 40; ++r) {
    const auto a = region_color(r), b = region_color(r + 1);
    const int d = std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
    EXPECT_GT(d, 40) << r;
  }
}

}  // namespace
}  // namespace voxpress
