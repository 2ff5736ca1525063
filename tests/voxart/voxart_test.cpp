// Voxel art: .vox / .vxl readers, solid + cuberille, Lanczos fairing,
// simplification, texture atlas and the whole pipeline (Muniz et al.).
#include <tbb/global_control.h>

#include <cstring>
#include <filesystem>

#include "eval/mesh_query.h"
#include "test_util.h"
#include "voxpress/voxart/polygonize.h"

namespace voxpress {
namespace {

using test::le32;
using test::vox_chunk;
using test::vox_dict;
using test::vox_file;
using test::vox_model;

std::string palette_chunk() {
  std::string rgba;
  for (int i = 0; i < 256; ++i) rgba += std::string{char(i), char(255 - i), char(i / 2), char(255)};
  return vox_chunk("RGBA", rgba);
}

MeshCheck surface_check(const VoxartResult& r) {
  return check_mesh(r.surface(), {.self_intersections = false});
}

ColorGrid grid_from(const BinaryVolume& v, uint64_t seed) {
  ColorGrid g;
  g.dims = v.lattice.dims;
  g.voxels.assign(v.inside.size(), Rgba{0, 0, 0, 0});
  test::Rng rng(seed);
  for (size_t i = 0; i < v.inside.size(); ++i)
    if (v.inside[i]) g.voxels[i] = {uint8_t(rng.next() % 4 * 60), uint8_t(rng.next() % 3 * 100), 90, 255};
  g.name = "test";
  return g;
}

// ---- readers -------------------------------------------------------------

TEST(VoxReader, ModelAndPaletteRoundTrip) {
  test::TempDir dir;
  const std::string path = dir.path("m.vox");
  test::write_file(path, vox_file(vox_model({3, 4, 5}, {{0, 0, 0, 1}, {2, 3, 4, 7}, {1, 2, 3, 255}}) + palette_chunk()));
  const VoxelArt art = read_voxel_art(path);
  ASSERT_EQ(art.parts.size(), 1u);
  const ColorGrid& g = art.parts[0];
  EXPECT_EQ(g.count(), 3u);
  // The grid spans the voxels; palette entry i is the colour of index i + 1.
  EXPECT_EQ(g.dims, (std::array<int64_t, 3>{3, 4, 5}));
  EXPECT_EQ(g.voxels[g.index(2, 3, 4)], (Rgba{6, 249, 3, 255}));
  EXPECT_EQ(g.voxels[g.index(0, 0, 0)], (Rgba{0, 255, 0, 255}));
  EXPECT_EQ(g.voxels[g.index(1, 2, 3)], (Rgba{254, 1, 127, 255}));
}

TEST(VoxReader, DefaultPaletteWhenThereIsNoRgbaChunk) {
  const auto& p = magicavoxel_default_palette();
  EXPECT_EQ(p[1], (Rgba{255, 255, 255, 255}));
  EXPECT_EQ(p[2], (Rgba{255, 255, 204, 255}));   // 0xffccffff: blue varies fastest
  EXPECT_EQ(p[7], (Rgba{255, 204, 255, 255}));
  EXPECT_EQ(p[215], (Rgba{0, 0, 51, 255}));
  EXPECT_EQ(p[216], (Rgba{238, 0, 0, 255}));     // the cube's black is dropped
  EXPECT_EQ(p[255], (Rgba{17, 17, 17, 255}));
  test::TempDir dir;
  test::write_file(dir.path("m.vox"), vox_file(vox_model({1, 1, 1}, {{0, 0, 0, 216}})));
  EXPECT_EQ(read_voxel_art(dir.path("m.vox")).parts[0].voxels[0], p[216]);
}

TEST(VoxReader, SceneGraphPlacesRotatedAndTranslatedInstances) {
  // Model 0: a 2x1x1 bar. Node 0 (nTRN) -> 1 (nGRP) -> two nTRN (2, 4) ->
  // shapes (3, 5) of model 0: one untouched, one rotated 90 degrees about z
  // (_r: row 0 has its 1 in column 1 with sign -, row 1 in column 0) and
  // translated by (10, 0, 0).
  auto trn = [](int id, int child, const std::string& r, const std::string& t) {
    std::vector<std::pair<std::string, std::string>> frame;
    if (!r.empty()) frame.push_back({"_r", r});
    if (!t.empty()) frame.push_back({"_t", t});
    return vox_chunk("nTRN", le32(id) + vox_dict({}) + le32(child) + le32(-1) + le32(0) + le32(1) + vox_dict(frame));
  };
  auto shp = [](int id) { return vox_chunk("nSHP", le32(id) + vox_dict({}) + le32(1) + le32(0) + vox_dict({})); };
  const int rot = 1 | (0 << 2) | (1 << 4);  // row 0 -> column 1 (negative), row 1 -> column 0
  const std::string graph = trn(0, 1, "", "") + vox_chunk("nGRP", le32(1) + vox_dict({}) + le32(2) + le32(2) + le32(4)) +
                            trn(2, 3, "", "0 0 0") + shp(3) + trn(4, 5, std::to_string(rot), "10 0 0") + shp(5);
  test::TempDir dir;
  test::write_file(dir.path("s.vox"), vox_file(vox_model({2, 1, 1}, {{0, 0, 0, 1}, {1, 0, 0, 2}}) + graph));
  const VoxelArt art = read_voxel_art(dir.path("s.vox"));
  const ColorGrid& g = art.parts[0];
  EXPECT_EQ(g.count(), 4u);
  // Instance 1 at v - floor(s / 2) = (-1, 0, 0), (0, 0, 0). Instance 2: R (x, y, z) = (-y, x, z) + (10, 0, 0):
  // (-1, 0, 0) -> (10, -1, 0) and (0, 0, 0) -> (10, 0, 0).
  auto at = [&](int64_t x, int64_t y, int64_t z) {
    const Vec3 q = Vec3(double(x), double(y), double(z)) - g.offset;
    return g.filled(int64_t(q.x()), int64_t(q.y()), int64_t(q.z()));
  };
  EXPECT_TRUE(at(-1, 0, 0) && at(0, 0, 0) && at(10, -1, 0) && at(10, 0, 0));
  EXPECT_FALSE(at(9, 0, 0));
  // The rotated instance keeps its colours: index 1 at (10, -1, 0).
  const Vec3 q = Vec3(10, -1, 0) - g.offset;
  EXPECT_EQ(g.voxels[g.index(int64_t(q.x()), int64_t(q.y()), int64_t(q.z()))], magicavoxel_default_palette()[1]);
}

TEST(VoxReader, ModelsWithoutSceneGraphAreFramesAndModelPicksOne) {
  test::TempDir dir;
  test::write_file(dir.path("a.vox"),
                   vox_file(vox_chunk("PACK", le32(2)) + vox_model({2, 2, 2}, {{0, 0, 0, 1}}) +
                            vox_model({2, 2, 2}, {{0, 0, 0, 1}, {1, 1, 1, 1}})));
  EXPECT_EQ(read_voxel_art(dir.path("a.vox")).voxel_count(), 1u);
  VoxelArtReadOptions o;
  o.model = 1;
  EXPECT_EQ(read_voxel_art(dir.path("a.vox"), o).voxel_count(), 2u);
  o.model = 2;
  EXPECT_THROW(read_voxel_art(dir.path("a.vox"), o), UsageError);
}

void expect_input_error(const std::string& path, const std::string& fragment) {
  test::expect_input_error([&] { read_voxel_art(path); }, path, fragment);
}

TEST(VoxReader, MalformedFilesGiveOneLineErrors) {
  test::TempDir dir;
  auto file = [&](const std::string& name, const std::string& bytes) {
    test::write_file(dir.path(name), bytes);
    return dir.path(name);
  };
  expect_input_error(dir.path("missing.vox"), "missing.vox");
  expect_input_error(file("magic.vox", "VOXX" + le32(150)), "not a MagicaVoxel file");
  expect_input_error(file("outside.vox", vox_file(vox_model({2, 2, 2}, {{2, 0, 0, 1}}))), "outside its model");
  expect_input_error(file("nosize.vox", vox_file(vox_chunk("XYZI", le32(0)))), "XYZI chunk without its SIZE");
  expect_input_error(file("empty.vox", vox_file(vox_model({2, 2, 2}, {}))), "empty");
  expect_input_error(file("nomodel.vox", vox_file(palette_chunk())), "no model");
  expect_input_error(file("size.vox", vox_file(vox_chunk("SIZE", le32(0) + le32(5) + le32(5)))), "out of range");
  const std::string cycle = vox_chunk("nTRN", le32(0) + vox_dict({}) + le32(1) + le32(-1) + le32(0) + le32(1) + vox_dict({})) +
                            vox_chunk("nGRP", le32(1) + vox_dict({}) + le32(1) + le32(0));
  expect_input_error(file("cycle.vox", vox_file(vox_model({1, 1, 1}, {{0, 0, 0, 1}}) + cycle)), "cycle");
  expect_input_error(file("rot.vox", vox_file(vox_model({1, 1, 1}, {{0, 0, 0, 1}}) +
                                             vox_chunk("nTRN", le32(0) + vox_dict({}) + le32(1) + le32(-1) + le32(0) +
                                                                   le32(1) + vox_dict({{"_r", "5"}})) +
                                             vox_chunk("nSHP", le32(1) + vox_dict({}) + le32(1) + le32(0) + vox_dict({})))),
                     "not a signed axis permutation");
  // Every truncation of a valid file is refused (never a crash).
  const std::string good = vox_file(vox_model({3, 3, 3}, {{0, 0, 0, 1}, {1, 1, 1, 2}, {2, 2, 2, 3}}) + palette_chunk());
  for (size_t n = 0; n < good.size(); n += 7) expect_input_error(file("cut.vox", good.substr(0, n)), "cut.vox");
}


TEST(VxlReader, SectionsSpansPaletteAndPlacement) {
  test::TempDir dir;
  test::write_file(dir.path("u.vxl"), test::vxl_file());
  const VoxelArt art = read_voxel_art(dir.path("u.vxl"));
  ASSERT_EQ(art.parts.size(), 1u);
  const ColorGrid& g = art.parts[0];
  EXPECT_EQ(g.name, "Body");
  EXPECT_EQ(g.count(), 3u);
  EXPECT_EQ(g.voxels[g.index(0, 0, 0)], (Rgba{200, 0, 0, 255}));
  EXPECT_EQ(g.voxels[g.index(1, 0, 1)], (Rgba{10, 20, 30, 255}));
  EXPECT_TRUE(g.filled(1, 0, 2));
  EXPECT_FALSE(g.filled(0, 0, 1));
  // Corner (1, 1, 1) -> bounds min + (2, 1, 2) + det * translation (1, 0, 0).
  EXPECT_TRUE((g.linear * Vec3(1, 1, 1) + g.offset).isApprox(Vec3(3, 1, 2)));
  // Every truncation is refused.
  const std::string good = test::vxl_file();
  for (size_t n = 0; n < good.size(); n += 5) {
    test::write_file(dir.path("cut.vxl"), good.substr(0, n));
    expect_input_error(dir.path("cut.vxl"), "cut.vxl");
  }
}

TEST(VxlReader, HvaFrameOverridesTheTailerTransform) {
  test::TempDir dir;
  test::write_file(dir.path("u.vxl"), test::vxl_file());
  std::string hva = std::string("u") + std::string(15, '\0') + le32(2) + le32(1) + std::string("Body") + std::string(12, '\0');
  for (float t : {0.f, 8.f}) {
    const float m[12] = {1, 0, 0, t, 0, 1, 0, 0, 0, 0, 1, 0};
    for (float v : m) hva += test::f32(v);
  }
  test::write_file(dir.path("u.hva"), hva);
  VoxelArtReadOptions o;
  o.frame = 1;
  const ColorGrid g = read_voxel_art(dir.path("u.vxl"), o).parts[0];
  EXPECT_TRUE(g.offset.isApprox(Vec3(4, 0, 0)));  // det 0.5 x 8
  o.frame = 2;
  EXPECT_THROW(read_voxel_art(dir.path("u.vxl"), o), UsageError);
  test::write_file(dir.path("u.hva"), hva.substr(0, 40));
  EXPECT_THROW(
      {
        try {
          read_voxel_art(dir.path("u.vxl"));
        } catch (const InputError& e) {
          EXPECT_EQ(e.path(), dir.path("u.hva"));
          EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
          throw;
        }
      },
      InputError);
}

// ---- solid, cuberille, fairing ----------------------------------------------

TEST(Cuberille, HollowModelsBecomeSolidAndOnlyTheOuterSurfaceRemains) {
  ColorGrid g;
  g.dims = {6, 6, 6};
  g.voxels.assign(216, Rgba{0, 0, 0, 0});
  for (int64_t k = 0; k < 6; ++k)
    for (int64_t j = 0; j < 6; ++j)
      for (int64_t i = 0; i < 6; ++i)
        if (i == 0 || j == 0 || k == 0 || i == 5 || j == 5 || k == 5) g.voxels[g.index(i, j, k)] = {1, 2, 3, 255};
  const QuadMesh q = solid_cuberille(g);
  EXPECT_EQ(q.filled_cavities, 64u);
  EXPECT_EQ(q.quads.size(), 6u * 36u);
  EXPECT_EQ(q.positions.size(), 6u * 25u + 12u * 5u + 8u);  // the lattice points of a 6-cube's surface
  EXPECT_EQ(q.split_vertices, 0u);
}

Mesh quad_mesh(const QuadMesh& q) {
  Mesh m;
  m.positions = q.positions;
  for (const auto& c : q.quads) {
    m.triangles.push_back({c[0], c[1], c[2]});
    m.triangles.push_back({c[0], c[2], c[3]});
  }
  return m;
}

TEST(Cuberille, EdgeAndCornerContactsGiveClosedManifoldSurfaces) {
  // The paper's topological problems (Fig. 1): voxels touching only along an
  // edge or at a corner, alone and inside solid blocks (the complement).
  struct Config {
    std::string name;
    std::vector<std::array<int64_t, 3>> voxels;
    bool invert;
  };
  const std::vector<Config> configs = {
      {"edge pair", {{1, 1, 1}, {2, 2, 1}}, false},
      {"corner pair", {{1, 1, 1}, {2, 2, 2}}, false},
      {"edge chain", {{1, 1, 1}, {2, 2, 1}, {3, 3, 1}, {4, 4, 1}}, false},
      {"edge holes in a block", {{2, 2, 2}, {3, 3, 2}}, true},
      {"corner holes in a block", {{2, 2, 2}, {3, 3, 3}}, true},
      {"tripod", {{2, 2, 2}, {3, 3, 2}, {3, 2, 3}, {2, 3, 3}}, false},
  };
  for (const Config& c : configs) {
    SCOPED_TRACE(c.name);
    ColorGrid g;
    g.dims = {6, 6, 6};
    g.voxels.assign(216, c.invert ? Rgba{5, 5, 5, 255} : Rgba{0, 0, 0, 0});
    for (const auto& v : c.voxels) g.voxels[g.index(v[0], v[1], v[2])] = c.invert ? Rgba{0, 0, 0, 0} : Rgba{9, 9, 9, 255};
    const QuadMesh q = solid_cuberille(g);
    const MeshCheck m = check_mesh(quad_mesh(q), {.self_intersections = false});
    EXPECT_TRUE(m.closed() && m.manifold() && m.oriented()) << (m.problems.empty() ? "" : m.problems[0]);
    EXPECT_GT(m.signed_volume, 0);
    EXPECT_EQ(q.pinched_edges, 0u);
  }
}

TEST(Cuberille, PropertyCorpusGivesClosedOrientedManifoldsOfTheSolidsVolume) {
  // Every volume of the shared property corpus, coloured at random.
  size_t n = 0;
  for (const auto& c : test::property_volumes()) {
    if (c.volume.count_inside() == 0) continue;
    SCOPED_TRACE(c.name);
    const ColorGrid g = grid_from(c.volume, ++n);
    const QuadMesh q = solid_cuberille(g);
    const MeshCheck m = check_mesh(quad_mesh(q), {.self_intersections = false});
    ASSERT_TRUE(m.closed() && m.manifold() && m.oriented()) << (m.problems.empty() ? "" : m.problems[0]);
    EXPECT_EQ(q.pinched_edges, 0u);
    // The enclosed volume is the solid's voxel count.
    uint64_t solid = 0;
    for (uint8_t s : fill_solid(g)) solid += s;
    EXPECT_NEAR(m.signed_volume, double(solid), 1e-6);
    // Each quad keeps its voxel's colour.
    for (size_t i = 0; i < q.quads.size(); i += 97) {
      const Vec3 inside = q.centers[i] - 0.5 * (q.positions[q.quads[i][1]] - q.positions[q.quads[i][0]])
                                                    .cross(q.positions[q.quads[i][3]] - q.positions[q.quads[i][0]]);
      const Vec3 cell = inside.array().floor();
      EXPECT_EQ(q.colors[i], g.voxels[g.index(int64_t(cell.x()), int64_t(cell.y()), int64_t(cell.z()))]);
    }
  }
  EXPECT_GT(n, 100u);
}

TEST(LanczosFairing, FlatsStayPutCornersMoveInAndThinPartsSeparate) {
  ColorGrid g;
  g.dims = {8, 8, 8};
  g.voxels.assign(512, Rgba{1, 1, 1, 255});
  QuadMesh q = solid_cuberille(g);
  const auto before = q.positions;
  fair_lanczos(q, 1.3);
  size_t unmoved_face_interior = 0, inside = 0;
  for (size_t v = 0; v < before.size(); ++v) {
    const Vec3& p = before[v];
    int on_boundary = 0;
    for (int a = 0; a < 3; ++a) on_boundary += p[a] == 0 || p[a] == 8;
    if (on_boundary == 1) unmoved_face_interior += q.positions[v] == p;
    inside += (q.positions[v].array() >= p.cwiseMin(Vec3::Constant(4)).array() - 1e-12).all() &&
              (q.positions[v].array() <= p.cwiseMax(Vec3::Constant(4)).array() + 1e-12).all();
  }
  EXPECT_EQ(unmoved_face_interior, 6u * 49u);  // u = 0 on a flat: Eq. (9) gives no move
  EXPECT_EQ(inside, before.size());            // edges and corners move towards the centre, never out
  const Vec3 corner = q.positions[0] - before[0];
  EXPECT_GT(corner.norm(), 0.1);
  EXPECT_LT(corner.norm(), 1.0);
  // Two voxels touching along an edge: their coincident edge vertices part.
  ColorGrid e;
  e.dims = {2, 2, 1};
  e.voxels = {Rgba{1, 1, 1, 255}, Rgba{}, Rgba{}, Rgba{1, 1, 1, 255}};
  QuadMesh t = solid_cuberille(e);
  ASSERT_GT(t.split_vertices, 0u);
  fair_lanczos(t, 1.3);
  std::vector<Vec3> p = t.positions;
  std::sort(p.begin(), p.end(), [](const Vec3& a, const Vec3& b) { return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end()); });
  for (size_t i = 1; i < p.size(); ++i) EXPECT_GT((p[i] - p[i - 1]).norm(), 1e-6);
}

// ---- simplification ------------------------------------------------------

TEST(Simplify, ReachesTheTargetAndStaysClosedManifoldAndOriented) {
  test::Rng rng(3);
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE(trial);
    const ColorGrid g = grid_from(test::random_blobs(rng, {20, 18, 16}, 2 + trial % 3), uint64_t(trial));
    QuadMesh q = solid_cuberille(g);
    fair_lanczos(q);
    Mesh m = quad_mesh(q);
    const MeshCheck before = check_mesh(m, {.self_intersections = false});
    std::vector<uint32_t> keys(m.triangles.size());
    for (size_t f = 0; f < keys.size(); ++f) keys[f] = q.colors[f / 2][0];
    const uint64_t target = m.triangles.size() / (4 + uint64_t(trial % 4));
    SimplifyOptions so;
    so.faces = target;
    so.soft_keys = keys;
    simplify(m, so);
    const MeshCheck after = check_mesh(m, {.self_intersections = false});
    EXPECT_TRUE(after.closed() && after.manifold() && after.oriented()) << (after.problems.empty() ? "" : after.problems[0]);
    EXPECT_EQ(after.euler, before.euler);
    EXPECT_EQ(after.components, before.components);
    EXPECT_LE(m.triangles.size(), target + 2 * before.components * 4);
    // Volume is kept within 15 % once a blob keeps a few hundred triangles
    // (tiny ones cut down to tens of faces lose their corners' volume).
    if (target >= 300) {
      EXPECT_NEAR(after.signed_volume, before.signed_volume, 0.15 * before.signed_volume);
    }
    // Every kept vertex stays within a voxel of the faired surface.
    const Mesh faired = quad_mesh(q);  // MeshQuery keeps a reference
    const detail::MeshQuery original(faired);
    double worst = 0;
    for (const Vec3& p : m.positions) worst = std::max(worst, std::sqrt(original.closest(p).dist2));
    EXPECT_LT(worst, 1.0);
  }
}

// ---- the pipeline ----------------------------------------------------------

VoxelArt art_of(const ColorGrid& g) {
  VoxelArt a;
  a.parts.push_back(g);
  a.source = "test";
  return a;
}

TEST(Voxart, EveryFairingGivesAClosedSurfaceAndTexturedColours) {
  test::Rng rng(11);
  const ColorGrid g = grid_from(test::random_blobs(rng, {24, 20, 16}, 3), 5);
  for (VoxartFairing f : {VoxartFairing::lanczos, VoxartFairing::taubin, VoxartFairing::pressing, VoxartFairing::none}) {
    for (uint64_t faces : {uint64_t(0), uint64_t(1500)}) {
      SCOPED_TRACE(std::string(voxart_fairing_name(f)) + " faces " + std::to_string(faces));
      EXPECT_EQ(parse_voxart_fairing(voxart_fairing_name(f)), f);
      VoxartOptions o;
      o.fairing = f;
      o.target_faces = faces;
      const VoxartResult r = polygonize_voxel_art(art_of(g), o);
      const MeshCheck c = surface_check(r);
      EXPECT_TRUE(c.closed() && c.manifold() && c.oriented()) << (c.problems.empty() ? "" : c.problems[0]);
      if (faces) {
        EXPECT_LE(r.mesh.triangles.size(), faces + 8);
      }
      ASSERT_EQ(r.mesh.uvs.size(), r.mesh.positions.size());
      for (const Vec2& t : r.mesh.uvs) ASSERT_TRUE(t.x() >= 0 && t.x() <= 1 && t.y() >= 0 && t.y() <= 1);
      EXPECT_GT(r.stats.utilisation, 0.1);
      EXPECT_LE(r.stats.utilisation, 1.0);
      // Unsimplified cube-face meshes carry every voxel face's colour exactly.
      if (!faces && f != VoxartFairing::pressing) {
        EXPECT_EQ(r.stats.color_exact, 1.0);
      }
      EXPECT_GT(r.stats.color_exact, 0.9);
    }
  }
  EXPECT_THROW(parse_voxart_fairing("gauss"), UsageError);
}

TEST(Voxart, VertexColoursWithoutTextureAndYUp) {
  ColorGrid g;
  g.dims = {3, 3, 5};
  g.voxels.assign(45, Rgba{40, 50, 60, 255});
  VoxartOptions o;
  o.texture = false;
  const VoxartResult r = polygonize_voxel_art(art_of(g), o);
  EXPECT_TRUE(r.mesh.uvs.empty() && r.mesh.texture.empty());
  ASSERT_EQ(r.mesh.colors.size(), r.mesh.positions.size());
  for (const Rgba& c : r.mesh.colors) EXPECT_EQ(c, (Rgba{40, 50, 60, 255}));
  EXPECT_EQ(r.stats.color_exact, 1.0);
  const auto box = bounding_box(r.mesh);
  EXPECT_GT(box[1].y() - box[0].y(), box[1].x() - box[0].x() + 1);  // the tall z axis is now y
}

TEST(Voxart, SameOutputForOneAndManyThreads) {
  test::Rng rng(5);
  const ColorGrid g = grid_from(test::random_blobs(rng, {22, 22, 22}, 3), 9);
  VoxartOptions o;
  o.target_faces = 2000;
  auto run = [&](int threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, size_t(threads));
    return polygonize_voxel_art(art_of(g), o).mesh;
  };
  const Mesh a = run(1), b = run(4);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.uvs, b.uvs);
  EXPECT_EQ(a.texture.rgba, b.texture.rgba);
}

TEST(Voxart, WritesObjWithMtlAndPngAndGlbWithTheTexture) {
  ColorGrid g;
  g.dims = {2, 2, 2};
  g.voxels.assign(8, Rgba{200, 10, 10, 255});
  g.voxels[7] = {10, 200, 10, 255};
  const VoxartResult r = polygonize_voxel_art(art_of(g));
  test::TempDir dir;
  write_mesh(dir.path("m.obj"), r.mesh);
  EXPECT_TRUE(std::filesystem::exists(dir.path("m.mtl")) && std::filesystem::exists(dir.path("m.png")));
  const std::string obj = test::read_file(dir.path("m.obj"));
  EXPECT_NE(obj.find("mtllib m.mtl"), std::string::npos);
  EXPECT_NE(obj.find("\nvt "), std::string::npos);
  EXPECT_NE(test::read_file(dir.path("m.mtl")).find("map_Kd m.png"), std::string::npos);
  const Mesh back = read_mesh(dir.path("m.obj"));
  EXPECT_EQ(back.triangles.size(), r.mesh.triangles.size());
  write_mesh(dir.path("m.glb"), r.mesh);
  const std::string glb = test::read_file(dir.path("m.glb"));
  EXPECT_NE(glb.find("TEXCOORD_0"), std::string::npos);
  EXPECT_NE(glb.find("image/png"), std::string::npos);
  EXPECT_NE(glb.find("\x89PNG"), std::string::npos);
}

// What is written is the closed solid in every format: the textured mesh
// splits its vertices at chart seams (glTF needs that), so PLY and OFF (no
// texture) weld them back, OBJ writes welded positions with a vt per
// corner, and the glTF reader welds identical positions as STL's does. Each
// file read back is closed, manifold, oriented and free of self-intersections.
TEST(Voxart, EveryWrittenFormatIsTheClosedSolid) {
  ColorGrid g;
  g.dims = {3, 2, 2};
  g.voxels.assign(12, Rgba{200, 10, 10, 255});
  g.voxels[7] = {10, 200, 10, 255};
  g.voxels[2] = {10, 10, 200, 255};
  const VoxartResult r = polygonize_voxel_art(art_of(g));
  ASSERT_FALSE(r.mesh.uvs.empty());
  Mesh split = r.mesh;
  EXPECT_GT(weld_identical_vertices(split), 0u) << "the textured mesh has seams";
  EXPECT_FALSE(check_mesh(r.mesh).closed()) << "as split, it is not the solid";
  test::TempDir dir;
  for (const std::string ext : {".ply", ".off", ".obj", ".stl", ".glb", ".gltf", ".vtk", ".vtp"}) {
    SCOPED_TRACE(ext);
    write_mesh(dir.path("m" + ext), r.mesh);
    const Mesh back = read_mesh(dir.path("m" + ext));
    const MeshCheck c = check_mesh(back);
    EXPECT_TRUE(c.ok()) << (c.problems.empty() ? "" : c.problems[0]);
    EXPECT_EQ(back.positions.size(), split.positions.size());
    EXPECT_EQ(back.triangles.size(), r.mesh.triangles.size());
  }
  // The OBJ keeps every corner's texture coordinate.
  const std::string obj = test::read_file(dir.path("m.obj"));
  size_t vt = 0;
  for (size_t p = obj.find("\nvt "); p != std::string::npos; p = obj.find("\nvt ", p + 1)) ++vt;
  EXPECT_EQ(vt, r.mesh.uvs.size());
}

TEST(Voxart, SharedVoxelArtLoadsAndConverts) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  size_t files = 0;
  for (const char* sub : {"/vox", "/vxl"}) {
    std::vector<std::string> paths;
    for (const auto& e : std::filesystem::directory_iterator(test::shared_data() + sub)) {
      const std::string ext = e.path().extension().string();
      if (ext == ".vox" || ext == ".vxl") paths.push_back(e.path().string());
    }
    std::sort(paths.begin(), paths.end());
    for (const std::string& p : paths) {
      SCOPED_TRACE(p);
      const VoxelArt art = read_voxel_art(p);
      EXPECT_GT(art.voxel_count(), 0u);
      const VoxartResult r = polygonize_voxel_art(art);
      const MeshCheck c = surface_check(r);
      EXPECT_TRUE(c.closed() && c.manifold() && c.oriented()) << (c.problems.empty() ? "" : c.problems[0]);
      EXPECT_EQ(r.stats.color_exact, 1.0);
      ++files;
    }
  }
  EXPECT_EQ(files, 14u);  // 10 .vox and 4 .vxl
}

TEST(Voxart, SharedFilesHaveTheDocumentedContents) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const std::string d = test::shared_data();
  // Counts from ../shared/data/README.md.
  EXPECT_EQ(read_voxel_art(d + "/vox/chr_knight.vox").voxel_count(), 398u);
  EXPECT_EQ(read_voxel_art(d + "/vox/menger.vox").voxel_count(), 160000u);
  EXPECT_EQ(read_voxel_art(d + "/vox/monu1.vox").voxel_count(), 156942u);
  EXPECT_EQ(read_voxel_art(d + "/vxl/cc.vxl").voxel_count(), 33005u);
  EXPECT_EQ(read_voxel_art(d + "/vxl/simple.vxl").voxel_count(), 9u);
  const VoxelArt legs = read_voxel_art(d + "/vxl/legs.vxl");
  EXPECT_EQ(legs.parts.size(), 18u);
  EXPECT_EQ(legs.voxel_count(), 6u * (1516 + 1632 + 3642));
  EXPECT_EQ(read_voxel_art(d + "/vxl/hmec.vxl").parts.size(), 13u);
  // The hollow dragon becomes solid.
  const QuadMesh q = solid_cuberille(read_voxel_art(d + "/vox/dragon.vox").parts[0]);
  EXPECT_EQ(q.filled_cavities, 91952u);
}

}  // namespace
}  // namespace voxpress
