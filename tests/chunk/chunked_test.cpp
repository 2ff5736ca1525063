// Chunked Pressing: the stitched surface is the whole-volume surface (same
// sticks, triangles and order), keeps every guarantee, and is deterministic.
#include <tbb/global_control.h>

#include <algorithm>

#include "test_util.h"

namespace voxpress {
namespace {

using test::Rng;

SurfaceOptions plain() {
  SurfaceOptions o;
  o.passes.disable(Pass::flats);
  return o;
}

Mesh chunked(const BinaryVolume& v, int64_t chunk, int64_t halo, const SurfaceOptions& o = plain(),
             ChunkedStats* st = nullptr) {
  ChunkOptions c;
  c.chunk = chunk;
  c.halo = halo;
  return press_chunked(v.lattice, v.source, [&](const Box& b) { return crop(v, b); }, o, c, st).mesh;
}

// The whole-volume run with the chunked run's options (flats off).
Mesh whole(const BinaryVolume& v) { return smooth_surface(v, plain()).mesh; }

double max_distance(const Mesh& a, const Mesh& b) {
  double d = 0;
  for (size_t i = 0; i < a.positions.size(); ++i) d = std::max(d, (a.positions[i] - b.positions[i]).norm());
  return d;
}

TEST(Chunked, NoCubeCaseHasATriangleOnOneFace) {
  // press_block finds a triangle's cube as the minimum of its sticks' lower
  // samples: wrong if all three vertices sat on the cube's upper face.
  for (unsigned mask = 0; mask < 256; ++mask) {
    const CubeCase& c = cube_case(mask);
    for (int k = 0; k < c.count; ++k)
      for (int axis = 0; axis < 3; ++axis) {
        bool lower = false;
        for (int v = 0; v < 3; ++v) lower |= ((cube_edge_corner(c.triangles[size_t(k)][size_t(v)], 0) >> axis) & 1) == 0;
        EXPECT_TRUE(lower) << "case " << mask << " triangle " << k << " axis " << axis;
      }
  }
}

TEST(Chunked, GridCoversTheVolumeOnce) {
  const ChunkGrid g({37, 8, 20}, {.chunk = 16, .halo = 3});
  ASSERT_EQ(g.count(), 3u * 1u * 2u);
  uint64_t covered = 0;
  for (size_t b = 0; b < g.count(); ++b) {
    const Box c = g.core(b), h = g.with_halo(b);
    covered += c.size();
    for (size_t a = 0; a < 3; ++a) {
      EXPECT_LE(h.lo[a], c.lo[a]);
      EXPECT_GE(h.hi[a], c.hi[a]);
      EXPECT_EQ(h.lo[a], std::max<int64_t>(0, c.lo[a] - 3));
    }
  }
  EXPECT_EQ(covered, 37u * 8u * 20u);
  EXPECT_THROW(ChunkGrid({8, 8, 8}, {.chunk = 4, .halo = 1}), UsageError);
  EXPECT_THROW(ChunkGrid({8, 8, 8}, {.chunk = 8, .halo = -1}), UsageError);
  EXPECT_THROW(ChunkGrid({8, 8, 8}, {.chunk = 8, .halo = 257}), UsageError);
  EXPECT_EQ(ChunkGrid({16, 8, 8}, {.chunk = 8, .halo = 0}).with_halo(0).hi[0], 9);  // exact mode reads one more sample
}

TEST(Chunked, OneBlockIsTheWholeRunBitForBit) {
  GenerateOptions g;
  g.res = 40;
  g.rotation = parse_rotation("random:3");
  for (ShapeKind kind : {ShapeKind::sphere, ShapeKind::cad_part}) {
    const GeneratedShape s = generate_shape(kind, g);
    const Mesh a = whole(s.volume), b = chunked(s.volume, 64, 16);
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.positions, b.positions);
  }
}

TEST(Chunked, ExactModeIsTheWholeRunByteForByte) {
  // Halo 0: blocks only extracted, the stitched sticks smoothed at once, so
  // every stage (flats, junctions, sharp edges) sees the whole volume's
  // sticks: the same mesh, attributes included, for any block size.
  GenerateOptions g;
  g.res = 48;
  g.rotation = parse_rotation("random:3");
  Rng rng(5);
  std::vector<std::pair<std::string, BinaryVolume>> cases;
  cases.emplace_back("cad part", generate_shape(ShapeKind::cad_part, g).volume);
  cases.emplace_back("box", generate_shape(ShapeKind::box, g).volume);
  cases.emplace_back("noise", test::random_noise(rng, {21, 17, 19}, 0.5));
  cases.emplace_back("checkerboard", test::checkerboard({17, 16, 18}));
  for (const auto& [name, v] : cases) {
    const SurfaceResult a = smooth_surface(v, {});
    for (int64_t chunk : {8, 12}) {
      SCOPED_TRACE(name + " chunk " + std::to_string(chunk));
      ChunkedStats st;
      const Mesh b = chunked(v, chunk, 0, {}, &st);
      EXPECT_EQ(a.mesh.positions, b.positions);
      EXPECT_EQ(a.mesh.triangles, b.triangles);
      EXPECT_EQ(a.mesh.edges, b.edges);
      ASSERT_EQ(a.mesh.vertex_attributes.size(), b.vertex_attributes.size());
      for (size_t i = 0; i < b.vertex_attributes.size(); ++i)
        EXPECT_EQ(a.mesh.vertex_attributes[i].values, b.vertex_attributes[i].values);
      EXPECT_GT(st.blocks, 1u);
    }
  }
}

TEST(Chunked, StitchedTopologyIsTheWholeRunsAndKeepsTheGuarantees) {
  Rng rng(11);
  std::vector<std::pair<std::string, BinaryVolume>> cases;
  cases.emplace_back("noise", test::random_noise(rng, {29, 23, 19}, 0.5));
  cases.emplace_back("blobs", test::random_blobs(rng, {33, 30, 26}, 5));
  cases.emplace_back("checkerboard", test::checkerboard({17, 16, 18}));
  {  // everything inside but one sample: the blocks without it are full
    BinaryVolume v = test::make_volume(24, 20, 17);
    std::fill(v.inside.begin(), v.inside.end(), 1);
    v.inside[v.lattice.linear(12, 9, 8)] = 0;
    cases.emplace_back("full but one", v);
  }
  {  // single voxels on block borders and corners
    BinaryVolume v = test::make_volume(25, 25, 25);
    for (int64_t c : {0, 7, 8, 15, 16, 24}) v.inside[v.lattice.linear(c, c, 24 - c)] = 1;
    cases.emplace_back("voxels on borders", v);
  }
  for (const auto& [name, v] : cases) {
    SCOPED_TRACE(name);
    const Mesh a = whole(v), b = chunked(v, 16, 16);
    EXPECT_EQ(a.triangles, b.triangles);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_LT(max_distance(a, b), 1e-9);
    test::expect_guarantees(b, v);
  }
}

TEST(Chunked, HaloRoundsAreTheWholeRun) {
  // Blocks pressed apart, exchanging their sticks' t and momentum between
  // rounds of as many sweeps as the halo covers: the whole run's surface up
  // to rounding, over rotations, stopped by the tolerance in the middle of
  // a round or by the sweep cap.
  GenerateOptions g;
  g.res = 44;
  for (int seed = 1; seed <= 2; ++seed) {
    g.rotation = parse_rotation("random:" + std::to_string(seed));
    for (ShapeKind kind : {ShapeKind::sphere, ShapeKind::cad_part})
      for (double tolerance : {1e-4, 2e-3}) {
        SCOPED_TRACE(std::to_string(seed) + " " + std::to_string(int(kind)) + " " + std::to_string(tolerance));
        const GeneratedShape s = generate_shape(kind, g);
        SurfaceOptions o = plain();
        o.press.tolerance = tolerance;
        const SurfaceResult a = smooth_surface(s.volume, o);
        ChunkedStats st;
        ChunkOptions c;
        c.chunk = 22;
        c.halo = 16;
        const SurfaceResult b = press_chunked(s.volume.lattice, s.volume.source,
                                              [&](const Box& box) { return crop(s.volume, box); }, o, c, &st);
        EXPECT_EQ(st.blocks, 8u);
        EXPECT_GT(st.rounds, 1);
        EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
        EXPECT_LT(max_distance(a.mesh, b.mesh), 1e-9);
        EXPECT_EQ(a.press.iterations, b.press.iterations);
        EXPECT_NEAR(a.press.residual, b.press.residual, 1e-12);
      }
  }
}

TEST(Chunked, AHaloNarrowerThanOneSweepIsRefused) {
  GenerateOptions g;
  g.res = 40;
  const GeneratedShape s = generate_shape(ShapeKind::sphere, g);
  try {
    chunked(s.volume, 20, 4);
    FAIL() << "a halo of 4 was accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--halo 4"), std::string::npos) << e.what();
  }
}

TEST(Chunked, SameBytesForAnyThreadCountAndPieceOrder) {
  GenerateOptions g;
  g.res = 40;
  g.rotation = parse_rotation("random:5");
  const GeneratedShape s = generate_shape(ShapeKind::cad_part, g);
  Mesh one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = chunked(s.volume, 16, 10);
  }
  const Mesh many = chunked(s.volume, 16, 10);
  EXPECT_EQ(one.positions, many.positions);
  EXPECT_EQ(one.triangles, many.triangles);
  // Under a memory cap that keeps no block between rounds (each is read and
  // extracted again every round): the same bytes.
  SurfaceOptions capped = plain();
  capped.extract.max_bytes = 1;
  const Mesh again = chunked(s.volume, 16, 10, capped);
  EXPECT_EQ(again.positions, many.positions);
  EXPECT_EQ(again.triangles, many.triangles);
  // Pieces stitched in reverse order give the same surface.
  const ChunkGrid grid(s.volume.lattice.dims, {.chunk = 16, .halo = 4});
  std::vector<SurfacePiece> pieces;
  for (size_t b = 0; b < grid.count(); ++b) pieces.push_back(press_block(crop(s.volume, grid.with_halo(b)), grid, b));
  const Mesh forward = to_mesh(stitch(s.volume.lattice, pieces));
  std::reverse(pieces.begin(), pieces.end());
  const Mesh reversed = to_mesh(stitch(s.volume.lattice, pieces));
  EXPECT_EQ(reversed.positions, forward.positions);
  EXPECT_EQ(reversed.triangles, forward.triangles);
  // A tree of merges of consecutive pieces (voxpress.dask's reduction, here
  // 3 at a time) leaves one piece, the same surface.
  std::vector<SurfacePiece> level(pieces.rbegin(), pieces.rend());
  while (level.size() > 1) {
    std::vector<SurfacePiece> next;
    for (size_t i = 0; i < level.size(); i += 3)
      next.push_back(merge_pieces({level.begin() + long(i), level.begin() + long(std::min(i + 3, level.size()))},
                                  s.volume.lattice.dims));
    level = std::move(next);
  }
  ASSERT_EQ(level[0].count, grid.count());
  const Mesh merged = to_mesh(stitch(s.volume.lattice, level));
  EXPECT_EQ(merged.positions, forward.positions);
  EXPECT_EQ(merged.triangles, forward.triangles);
  EXPECT_THROW(merge_pieces({pieces[0], pieces[1]}, s.volume.lattice.dims), UsageError);  // not consecutive
  EXPECT_THROW(stitch(s.volume.lattice, {level[0], pieces[0]}), UsageError);          // a block twice
  // A missing or doubled piece would be a hole or an overlap: refused.
  pieces.push_back(pieces.front());
  EXPECT_THROW(stitch(s.volume.lattice, pieces), UsageError);
  pieces.pop_back();
  pieces.pop_back();
  EXPECT_THROW(stitch(s.volume.lattice, pieces), UsageError);
  // A triangle naming a stick no piece owns is refused.
  pieces.push_back(press_block(crop(s.volume, grid.with_halo(0)), grid, 0));
  stitch(s.volume.lattice, pieces);
  const uint64_t absent = stick_key(s.volume.lattice.dims, {1, 1, 1}, 0);  // sample (0, 0, 0) is outside the part
  for (int v = 0; v < 3; ++v) pieces.back().triangles.push_back(absent);
  EXPECT_THROW(stitch(s.volume.lattice, pieces), std::logic_error);
}

TEST(Chunked, ClassificationBySlabsReportsWhatTheWholeVolumeCheckDoes) {
  // press --chunk --check classifies slabs of planes: every slab size gives
  // the in-memory report, violations included (a pushed-in vertex here).
  Rng rng(3);
  const BinaryVolume v = test::random_blobs(rng, {26, 21, 23}, 4);
  Mesh m = whole(v);
  for (size_t i = 0; i < m.positions.size(); i += 97) m.positions[i] += Vec3(0.9, -0.8, 0.7);
  const ClassificationReport ref = check_classification(m, v);
  ASSERT_GT(ref.violations, 0u);
  const PlaneReader planes = [&](int64_t k0, int64_t k1) {
    return crop(v, Box{{0, 0, k0}, {v.lattice.dims[0], v.lattice.dims[1], k1}});
  };
  for (int64_t slab : {1, 4, 7, 23, 0}) {
    const ClassificationReport r = check_classification(m, v.lattice, planes, {}, slab);
    EXPECT_EQ(r.samples, ref.samples);
    EXPECT_EQ(r.inside_found_outside, ref.inside_found_outside);
    EXPECT_EQ(r.outside_found_inside, ref.outside_found_inside);
    EXPECT_EQ(r.on_surface, ref.on_surface);
    EXPECT_EQ(r.examples, ref.examples);
  }
}

TEST(Chunked, EmptyAndFullVolumesAreRefused) {
  BinaryVolume v = test::make_volume(20, 20, 20);
  EXPECT_THROW(chunked(v, 8, 2), InputError);
  std::fill(v.inside.begin(), v.inside.end(), 1);
  EXPECT_THROW(chunked(v, 8, 2), InputError);
  SurfaceOptions cesn;
  cesn.method = Method::cesn;
  v.inside[0] = 0;
  EXPECT_THROW(chunked(v, 8, 2, cesn), UsageError);
}

}  // namespace
}  // namespace voxpress
