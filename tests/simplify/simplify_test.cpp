// The simplifier keeps what the user was promised: every sample on its
// side, closed, 2-manifold, oriented, no self-intersection (in double, after
// float32 rounding and in the files as written), flats on their planes,
// sharp edges as edges, the error bound, the same bytes for any thread
// count.
#include <tbb/global_control.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <map>

#include "eval/mesh_query.h"
#include "labels/label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

struct Pressed {
  BinaryVolume volume;
  SurfaceResult r;
};

Pressed press(ShapeKind kind, int64_t res, int seed) {
  GenerateOptions g;
  g.res = res;
  g.rotation = parse_rotation("random:" + std::to_string(seed));
  Pressed p;
  p.volume = generate_shape(kind, g).volume;
  p.r = smooth_surface(p.volume);
  return p;
}

SimplifyStats simplify_to(Mesh& m, const BinaryVolume& v, uint64_t faces, double max_error = 0) {
  SimplifyOptions o;
  o.faces = faces;
  o.max_error = max_error;
  o.lattice = &v.lattice;
  return simplify(m, o);
}

// Rotated spheres and CAD parts (32^3) at 10 % and 2 % of their faces: every
// guarantee holds, in double and in float32; 10 % is always reached.
TEST(Simplify, EveryRotationKeepsEveryGuarantee) {
  for (ShapeKind kind : {ShapeKind::sphere, ShapeKind::cad_part})
    for (int seed : {1, 2}) {
      const Pressed p = press(kind, 32, seed);
      for (double ratio : {0.1, 0.02}) {
        SCOPED_TRACE(std::string(shape_name(kind)) + " seed " + std::to_string(seed) + " ratio " + std::to_string(ratio));
        Mesh m = p.r.mesh;
        const uint64_t target = uint64_t(ratio * double(m.face_count()));
        const SimplifyStats st = simplify_to(m, p.volume, target);
        EXPECT_EQ(st.faces_after, m.face_count());
        EXPECT_EQ(st.faces_before, p.r.mesh.face_count());
        if (ratio == 0.1) {
          EXPECT_LE(m.face_count(), target);
        }
        EXPECT_LT(m.face_count(), p.r.mesh.face_count() / 4);
        test::expect_guarantees(m, p.volume);
      }
    }
}

// Per region: its plane (fitted to its faces' corners) and the farthest
// corner from it.
std::map<int, std::pair<Vec3, Vec3>> region_planes(const Mesh& m, std::map<int, double>& worst,
                                                   std::map<int, size_t>& faces) {
  const MeshAttribute* region = m.face_attribute("region");
  std::map<int, std::vector<Vec3>> corners;
  for (size_t f = 0; f < m.face_count(); ++f)
    if (region->values[f] >= 0) {
      ++faces[int(region->values[f])];
      for (uint32_t v : m.triangles[f]) corners[int(region->values[f])].push_back(m.positions[v]);
    }
  std::map<int, std::pair<Vec3, Vec3>> planes;
  for (const auto& [r, pts] : corners) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : pts) c += p;
    c /= double(pts.size());
    Mat3 cov = Mat3::Zero();
    for (const Vec3& p : pts) cov += (p - c) * (p - c).transpose();
    const Vec3 n = Eigen::SelfAdjointEigenSolver<Mat3>(cov).eigenvectors().col(0);
    planes[r] = {n, c};
    for (const Vec3& p : pts) worst[r] = std::max(worst[r], std::abs(n.dot(p - c)));
  }
  return planes;
}

// Flat faces end no farther from their flat's plane than the input's did
// (flat vertices sit on the plane as far as their sticks allow), far fewer
// of them; labelled sharp edges stay edges of two faces; the region
// attribute survives per face.
TEST(Simplify, FlatsStayOnTheirPlanesAndSharpEdgesStayEdges) {
  const Pressed p = press(ShapeKind::cad_part, 48, 4);
  const Mesh& in = p.r.mesh;
  ASSERT_GT(in.edges.size(), 0u);
  ASSERT_NE(in.face_attribute("region"), nullptr);
  std::map<int, double> worst_in, worst_out;
  std::map<int, size_t> faces_in, faces_out;
  const auto planes = region_planes(in, worst_in, faces_in);
  ASSERT_GE(planes.size(), 4u);
  Mesh m = in;
  simplify_to(m, p.volume, in.face_count() / 20);
  test::expect_guarantees(m, p.volume);
  const MeshAttribute* region = m.face_attribute("region");
  ASSERT_NE(region, nullptr);
  ASSERT_EQ(region->values.size(), m.face_count());
  for (size_t f = 0; f < m.face_count(); ++f) {
    const int r = int(region->values[f]);
    if (r < 0) continue;
    ++faces_out[r];
    const auto& [n, c] = planes.at(r);
    for (uint32_t v : m.triangles[f]) EXPECT_LE(std::abs(n.dot(m.positions[v] - c)), worst_in[r] + 1e-9) << "flat " << r;
  }
  for (const auto& [r, n] : faces_in) EXPECT_LT(faces_out[r] * 10, n) << "flat " << r << " collapses to far fewer triangles";
  // Every labelled edge is an edge of two faces.
  ASSERT_GT(m.edges.size(), 0u);
  std::map<std::pair<uint32_t, uint32_t>, int> faces_of;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[size_t(k)], b = t[size_t((k + 1) % 3)];
      ++faces_of[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& e : m.edges) EXPECT_EQ((faces_of[{std::min(e[0], e[1]), std::max(e[0], e[1])}]), 2);
}

// A cube of side k cells, each face a k x k grid of squares split in two,
// its twelve edges labelled sharp; rotated, so no plane is axis-aligned.
Mesh gridded_cube(int k, const Mat3& R) {
  Mesh m;
  std::map<std::array<int, 3>, uint32_t> id;
  const auto vertex = [&](std::array<int, 3> p) {
    auto [it, fresh] = id.try_emplace(p, uint32_t(m.positions.size()));
    if (fresh) m.positions.push_back(R * Vec3(p[0], p[1], p[2]));
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j) {
          std::array<uint32_t, 4> q;
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> p{};
            p[size_t(axis)] = side * k;
            p[size_t(u)] = i + (c == 1 || c == 2);
            p[size_t(v)] = j + (c >= 2);
            q[size_t(c)] = vertex(p);
          }
          // (u, v, axis) is right-handed: counter-clockwise about +axis.
          if (side == 1) m.triangles.push_back({q[0], q[1], q[2]}), m.triangles.push_back({q[0], q[2], q[3]});
          else m.triangles.push_back({q[0], q[2], q[1]}), m.triangles.push_back({q[0], q[3], q[2]});
        }
    }
  for (const auto& [p, a] : id)  // the edges: two coordinates at 0 or k, neighbours along the third
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const bool on_edge = (p[size_t(u)] % k == 0) && (p[size_t(v)] % k == 0);
      if (!on_edge || p[size_t(axis)] == k) continue;
      std::array<int, 3> q = p;
      ++q[size_t(axis)];
      m.edges.push_back({a, id.at(q)});
    }
  return m;
}

TEST(Simplify, CollapsesInsideAPlaneChangeNoPointOfTheSurface) {
  // A gridded cube, rotated: every collapse that keeps its faces and edges
  // changes no point of the solid. Most lie inside one face's plane, where
  // the clash query is proven unnecessary (Collapser::in_plane); the result
  // is a closed, oriented 2-manifold without self-intersections, of the
  // same volume to rounding.
  const Mat3 R = (Eigen::AngleAxisd(0.3, Vec3::UnitX()) * Eigen::AngleAxisd(0.5, Vec3::UnitY())).toRotationMatrix();
  Mesh m = gridded_cube(8, R);
  ASSERT_TRUE(check_mesh(m).ok());
  const double before = signed_volume(m);
  ASSERT_NEAR(before, 512, 1e-9);
  SimplifyOptions o;
  o.faces = 12;
  const SimplifyStats st = simplify(m, o);
  EXPECT_TRUE(check_mesh(m).ok());
  EXPECT_LE(m.face_count(), 24u);  // measured 16: 12 and a few at the pinned corners
  EXPECT_GT(st.in_plane * 2, st.collapses);
  EXPECT_LT(st.in_plane, st.collapses);  // the edges' collapses are not inside one plane
  EXPECT_NEAR(signed_volume(m), before, 1e-9 * before);
}

// What the user gets: the simplified part written in each format and read
// back, on an anisotropic lattice far from the origin (a larger float32
// rounding to keep clear of).
TEST(Simplify, WrittenFilesKeepTheGuarantee) {
  const BinaryVolume part = test::far_anisotropic_part(40);
  SurfaceOptions so;
  so.simplify.faces = 1500;
  const SurfaceResult r = smooth_surface(part, so);
  EXPECT_LE(r.mesh.face_count(), 1500u);
  EXPECT_EQ(r.simplify.faces_after, r.mesh.face_count());
  test::TempDir dir;
  for (const char* ext : {".ply", ".stl", ".glb", ".obj"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir.path(std::string("s") + ext);
    write_mesh(path, r.mesh);
    const Mesh back = read_mesh(path);
    ASSERT_EQ(back.face_count(), r.mesh.face_count());
    test::expect_guarantees(back, part);
  }
}

// max_error bounds the distance of every input vertex to the result
// (measured here independently), with or without a face target.
TEST(Simplify, MaxErrorBoundsEveryInputVertexDistance) {
  const Pressed p = press(ShapeKind::sphere, 32, 5);
  for (double bound : {0.05, 0.3}) {
    SCOPED_TRACE(bound);
    Mesh m = p.r.mesh;
    const SimplifyStats st = simplify_to(m, p.volume, 0, bound);
    EXPECT_LT(m.face_count(), p.r.mesh.face_count() / 2);
    EXPECT_GT(st.refused_error, 0u);
    EXPECT_LE(st.error, bound);
    const detail::MeshQuery q(m);
    double worst = 0;
    for (const Vec3& x : p.r.mesh.positions) worst = std::max(worst, std::sqrt(q.closest(x).dist2));
    EXPECT_LE(worst, bound + 1e-12);
    EXPECT_NEAR(worst, st.error, 1e-12);
    test::expect_guarantees(m, p.volume);
  }
}

TEST(Simplify, SameBytesForAnyThreadCount) {
  // The rounds' moves are checked in parallel: 1, 2 and 4 threads.
  const Pressed p = press(ShapeKind::cad_part, 32, 6);
  Mesh one = p.r.mesh;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    simplify_to(one, p.volume, 1500);
  }
  for (size_t threads : {2, 4}) {
    Mesh m = p.r.mesh;
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
      simplify_to(m, p.volume, 1500);
    }
    EXPECT_EQ(one.positions, m.positions) << threads << " threads";
    EXPECT_EQ(one.triangles, m.triangles) << threads << " threads";
    EXPECT_EQ(one.edges, m.edges) << threads << " threads";
  }
}

// Junction lines (edges of three and more faces): a label map's shared
// midpoint surface, simplified with junctions allowed, keeps every label
// closed and every sample on its side; without the option it is refused.
TEST(Simplify, JunctionLinesOfASharedSurface) {
  const ScalarVolume v = test::phantom();
  SharedSurface s = extract_shared_surface(v);
  SimplifyOptions o;
  o.faces = s.mesh.face_count() / 5;
  Mesh m = s.mesh;
  o.lattice = &s.lattice;
  EXPECT_THROW(simplify(m, o), std::invalid_argument);
  const SimplifyStats st = simplify_shared(s, o);
  EXPECT_LE(st.faces_after, o.faces);
  for (uint32_t L = 1; L < s.labels.size(); ++L) {
    SCOPED_TRACE("label " + std::to_string(s.labels[L]));
    test::expect_guarantees(label_mesh(s, L), test::whole_mask(v, double(s.labels[L])));
  }
}

TEST(Simplify, RefusesWhatIsNotAClosedManifoldAndNoTargetIsANoOp) {
  const Pressed p = press(ShapeKind::sphere, 24, 1);
  Mesh m = p.r.mesh;
  const SimplifyStats none = simplify_to(m, p.volume, 0);
  EXPECT_EQ(none.collapses, 0u);
  EXPECT_EQ(m.triangles, p.r.mesh.triangles);
  m.face_attributes.clear();
  m.triangles.pop_back();  // a hole
  EXPECT_THROW(simplify_to(m, p.volume, 100), std::invalid_argument);
  SimplifyOptions bad;
  bad.max_error = -1;
  EXPECT_THROW(simplify(m, bad), std::invalid_argument);
}

}  // namespace
}  // namespace voxpress
