// The generated CAD-like part as an exact boundary representation.
//
// Theory of operation: the part is *defined* by this closed triangle mesh
// (model units), so its voxelization, its distances, normals, sharp edges and
// planar faces all refer to one object. Planar faces are exact; curved faces
// are tessellated finely (circles: 1024 segments, chord error <= 2.2e-6; fillet
// arc: 128 segments, <= 7.5e-6; i.e. below 0.002 voxel at 512^3).
//
//   plate    x in [-1, 1], y in [-0.7, 0.7], z in [-0.25, 0.25]; the two -x
//            vertical edges rounded (radius 0.2), the +x edges sharp
//   chamfer  45 degrees on the +x top edge: plane x + z = 1.1
//   hole     through the plate, centre (-0.5, 0.1), radius 0.18
//   boss     cylinder on top, axis (0.3, 0), radius 0.35, up to z = 0.75
//   fillet   concave, radius 0.1, between the plate top and the boss
//
// Every ring of vertices shared by two faces is computed once and reused, so
// welding identical positions closes the mesh exactly.
#include <cmath>
#include <mutex>
#include <numbers>

#include "polygon.h"
#include "voxpress/eval/shapes.h"

namespace voxpress {
namespace {

constexpr int kCircle = 1024;  // segments per full circle
constexpr int kArc = 128;      // segments along the fillet's quarter arc
constexpr double kX = 1.0, kY = 0.7, kZ = 0.25, kRound = 0.2, kChamferTopX = 0.85, kChamferZ = 0.1;
constexpr double kHoleX = -0.5, kHoleY = 0.1, kHoleR = 0.18;
constexpr double kBossX = 0.3, kBossY = 0.0, kBossR = 0.35, kBossTop = 0.75, kFillet = 0.1;

// Unit vector at angle 2 pi i / n, exact at the four axis directions.
Eigen::Vector2d unit(int i, int n) {
  i = ((i % n) + n) % n;
  if (4 * i == 0) return {1, 0};
  if (4 * i == n) return {0, 1};
  if (4 * i == 2 * n) return {-1, 0};
  if (4 * i == 3 * n) return {0, -1};
  const double a = 2 * std::numbers::pi * i / n;
  return {std::cos(a), std::sin(a)};
}

struct Builder {
  Mesh m;
  uint32_t add(const Vec3& p) {
    m.positions.push_back(p);
    return uint32_t(m.positions.size() - 1);
  }
  void tri(const Vec3& a, const Vec3& b, const Vec3& c) { m.triangles.push_back({add(a), add(b), add(c)}); }
  // Quad a b c d, counter-clockwise seen from outside.
  void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    tri(a, b, c);
    tri(a, c, d);
  }
  // Planar face at height z with an outline and holes (2D, outline CCW seen
  // from +z); facing +z when up, else -z.
  void planar(const std::vector<Vec3>& outline, const std::vector<std::vector<Vec3>>& holes, bool up) {
    auto flat = [](const std::vector<Vec3>& loop, bool reverse) {
      std::vector<detail::Point2> out;
      for (const Vec3& p : loop) out.push_back({p.x(), p.y()});
      if (reverse) std::reverse(out.begin(), out.end());
      return out;
    };
    std::vector<Vec3> all = outline;
    std::vector<std::vector<detail::Point2>> holes2;
    for (const auto& h : holes) {
      holes2.push_back(flat(h, true));  // holes clockwise
      std::vector<Vec3> rev(h.rbegin(), h.rend());
      all.insert(all.end(), rev.begin(), rev.end());
    }
    for (const auto& t : detail::triangulate_polygon(flat(outline, false), holes2)) {
      if (up)
        tri(all[t[0]], all[t[1]], all[t[2]]);
      else
        tri(all[t[0]], all[t[2]], all[t[1]]);
    }
  }
};

Mesh build() {
  Builder b;
  // ---- Shared rings (counter-clockwise seen from +z).
  auto circle = [](double cx, double cy, double r, double z) {
    std::vector<Vec3> ring;
    for (int i = 0; i < kCircle; ++i) {
      const auto u = unit(i, kCircle);
      ring.emplace_back(cx + r * u.x(), cy + r * u.y(), z);
    }
    return ring;
  };
  const auto hole_top = circle(kHoleX, kHoleY, kHoleR, kZ), hole_bottom = circle(kHoleX, kHoleY, kHoleR, -kZ);
  // Fillet arcs: alpha from 270 degrees (touching the plate at r = 0.45) to
  // 180 degrees (touching the boss at r = 0.35); tube centre (r, z) = (0.45, 0.35).
  std::vector<std::vector<Vec3>> fillet(kArc + 1);
  for (int j = 0; j <= kArc; ++j) {
    double r, z;
    if (j == 0) {
      r = kBossR + kFillet;
      z = kZ;
    } else if (j == kArc) {
      r = kBossR;
      z = kZ + kFillet;
    } else {
      const double alpha = std::numbers::pi * (1.5 - 0.5 * j / kArc);
      r = kBossR + kFillet + kFillet * std::cos(alpha);
      z = kZ + kFillet + kFillet * std::sin(alpha);
    }
    fillet[size_t(j)] = circle(kBossX, kBossY, r, z);
  }
  const auto boss_top = circle(kBossX, kBossY, kBossR, kBossTop);
  // Rounded -x corners: quarter arcs, centres (-0.8, +-0.5).
  auto corner_arc = [](double cy, int from, double z) {  // from: quarter start index (in kCircle units)
    std::vector<Vec3> arc;
    for (int i = 0; i <= kCircle / 4; ++i) {
      const auto u = unit(from + i, kCircle);
      arc.emplace_back(-kX + kRound + kRound * u.x(), cy + kRound * u.y(), z);
    }
    return arc;
  };
  const double cy = kY - kRound;
  // ---- Top and bottom outlines (CCW seen from +z).
  auto outline = [&](double z, double xmax) {
    std::vector<Vec3> o{Vec3(xmax, -kY, z), Vec3(xmax, kY, z)};
    for (const Vec3& p : corner_arc(cy, kCircle / 4, z)) o.push_back(p);       // (-0.8, 0.7) .. (-1, 0.5)
    for (const Vec3& p : corner_arc(-cy, kCircle / 2, z)) o.push_back(p);      // (-1, -0.5) .. (-0.8, -0.7)
    return o;
  };
  b.planar(outline(kZ, kChamferTopX), {hole_top, fillet[0]}, true);
  b.planar(outline(-kZ, kX), {hole_bottom}, false);
  // ---- Side walls.
  const Vec3 xa(kX, -kY, -kZ), xb(kX, kY, -kZ), xc(kX, kY, kChamferZ), xd(kX, -kY, kChamferZ);
  const Vec3 ta(kChamferTopX, -kY, kZ), tb(kChamferTopX, kY, kZ);
  b.quad(xa, xb, xc, xd);        // +x face
  b.quad(xd, xc, tb, ta);        // chamfer
  const Vec3 ya(-kX + kRound, kY, -kZ), yb(-kX + kRound, kY, kZ);
  b.quad(xb, ya, yb, tb);        // +y face: pentagon (1,-.25) (1,.1) (.85,.25) (-.8,.25) (-.8,-.25)
  b.tri(xb, tb, xc);
  const Vec3 yc(-kX + kRound, -kY, -kZ), yd(-kX + kRound, -kY, kZ);
  b.quad(xa, ta, yd, yc);        // -y face
  b.tri(xa, xd, ta);
  b.quad(Vec3(-kX, cy, -kZ), Vec3(-kX, -cy, -kZ), Vec3(-kX, -cy, kZ), Vec3(-kX, cy, kZ));  // -x face
  for (double c : {cy, -cy}) {   // rounded corners
    const int from = c > 0 ? kCircle / 4 : kCircle / 2;
    const auto lo = corner_arc(c, from, -kZ), hi = corner_arc(c, from, kZ);
    for (size_t i = 0; i + 1 < lo.size(); ++i) b.quad(lo[i], lo[i + 1], hi[i + 1], hi[i]);
  }
  // ---- Hole wall (faces the hole's axis).
  for (int i = 0; i < kCircle; ++i) {
    const int k = (i + 1) % kCircle;
    b.quad(hole_bottom[size_t(i)], hole_top[size_t(i)], hole_top[size_t(k)], hole_bottom[size_t(k)]);
  }
  // ---- Fillet, boss wall, boss top.
  for (int j = 0; j < kArc; ++j)
    for (int i = 0; i < kCircle; ++i) {
      const int k = (i + 1) % kCircle;
      const auto &lo = fillet[size_t(j)], &hi = fillet[size_t(j + 1)];
      b.quad(lo[size_t(i)], lo[size_t(k)], hi[size_t(k)], hi[size_t(i)]);
    }
  const auto& boss_bottom = fillet[kArc];
  for (int i = 0; i < kCircle; ++i) {
    const int k = (i + 1) % kCircle;
    b.quad(boss_bottom[size_t(i)], boss_bottom[size_t(k)], boss_top[size_t(k)], boss_top[size_t(i)]);
  }
  const Vec3 centre(kBossX, kBossY, kBossTop);
  for (int i = 0; i < kCircle; ++i) b.tri(centre, boss_top[size_t(i)], boss_top[size_t((i + 1) % kCircle)]);
  weld_identical_vertices(b.m);
  return b.m;
}

}  // namespace

const Mesh& cad_part_mesh() {
  static const Mesh mesh = build();
  return mesh;
}

}  // namespace voxpress
