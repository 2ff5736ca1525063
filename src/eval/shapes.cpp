#include "voxpress/eval/shapes.h"


#include <algorithm>
#include <map>
#include <numbers>
#include <cmath>
#include <sstream>

#include "voxpress/core/error.h"
#include "voxpress/eval/voxelize.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

constexpr double kTorusMajor = 1.0, kTorusMinor = 0.4;
const Vec3 kBoxHalf(1.0, 0.75, 0.5);
constexpr double kCylRadius = 0.6, kCylHalf = 1.0;

uint64_t splitmix(uint64_t& s) {
  uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double uniform01(uint64_t& s) { return double(splitmix(s) >> 11) * 0x1.0p-53; }

}  // namespace

const char* shape_name(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::sphere: return "sphere";
    case ShapeKind::torus: return "torus";
    case ShapeKind::box: return "box";
    case ShapeKind::cylinder: return "cylinder";
    default: return "cad-part";
  }
}

std::vector<ShapeKind> all_shapes() {
  return {ShapeKind::sphere, ShapeKind::torus, ShapeKind::box, ShapeKind::cylinder, ShapeKind::cad_part};
}

ShapeKind parse_shape(std::string_view name) {
  for (ShapeKind k : all_shapes())
    if (name == shape_name(k)) return k;
  if (name == "cad" || name == "part") return ShapeKind::cad_part;
  throw UsageError("unknown shape '" + std::string(name) + "' (choose sphere, torus, box, cylinder or cad-part)");
}

bool shape_contains(ShapeKind kind, const Vec3& m, double fillet) {
  if (kind == ShapeKind::box && fillet > 0) {
    // The Minkowski sum of the shrunk box and a ball: within `fillet` of it.
    const Vec3 inner = kBoxHalf - Vec3::Constant(fillet);
    return (m.cwiseAbs() - inner).cwiseMax(0.0).squaredNorm() <= fillet * fillet;
  }
  if (kind == ShapeKind::cylinder && fillet > 0) {
    // The same for the shrunk cylinder: its rims become quarter tori.
    const double dr = std::max(0.0, std::hypot(m.x(), m.y()) - (kCylRadius - fillet));
    const double dz = std::max(0.0, std::abs(m.z()) - (kCylHalf - fillet));
    return dr * dr + dz * dz <= fillet * fillet;
  }
  switch (kind) {
    case ShapeKind::sphere: return m.squaredNorm() <= 1.0;
    case ShapeKind::torus: {
      const double q = std::hypot(m.x(), m.y()) - kTorusMajor;
      return q * q + m.z() * m.z() <= kTorusMinor * kTorusMinor;
    }
    case ShapeKind::box:
      return std::abs(m.x()) <= kBoxHalf.x() && std::abs(m.y()) <= kBoxHalf.y() && std::abs(m.z()) <= kBoxHalf.z();
    case ShapeKind::cylinder: return m.x() * m.x() + m.y() * m.y() <= kCylRadius * kCylRadius && std::abs(m.z()) <= kCylHalf;
    default: return mesh_contains(cad_part_mesh(), m);
  }
}

double shape_support(ShapeKind kind, const Vec3& d) {
  const double dxy = std::hypot(d.x(), d.y());
  switch (kind) {
    case ShapeKind::sphere: return d.norm();
    case ShapeKind::torus: return kTorusMajor * dxy + kTorusMinor * d.norm();
    case ShapeKind::box: return kBoxHalf.cwiseProduct(d.cwiseAbs()).sum();
    case ShapeKind::cylinder: return kCylRadius * dxy + kCylHalf * std::abs(d.z());
    default: {
      double best = -INFINITY;  // exact for the polyhedral B-rep
      for (const Vec3& p : cad_part_mesh().positions) best = std::max(best, p.dot(d));
      return best;
    }
  }
}

double shape_volume(ShapeKind kind, double fillet) {
  const double pi = std::numbers::pi;
  if (kind == ShapeKind::box && fillet > 0) {
    // Steiner's formula for the shrunk box h plus a ball of radius f: volume,
    // + area f, + the edges' quarter cylinders, + the corners' ball.
    const Vec3 h = kBoxHalf - Vec3::Constant(fillet);
    const double f = fillet;
    return 8 * h.prod() + 8 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z()) * f + 2 * pi * h.sum() * f * f +
           4.0 / 3.0 * pi * f * f * f;
  }
  if (kind == ShapeKind::cylinder && fillet > 0) {
    // Steiner's formula for the shrunk cylinder (radius r, half height h):
    // V + S f + M f^2 + 4/3 pi f^3, M = 2 pi h + pi^2 r its integrated mean curvature.
    const double r = kCylRadius - fillet, h = kCylHalf - fillet, f = fillet;
    return 2 * pi * r * r * h + (4 * pi * r * h + 2 * pi * r * r) * f + (2 * pi * h + pi * pi * r) * f * f +
           4.0 / 3.0 * pi * f * f * f;
  }
  switch (kind) {
    case ShapeKind::sphere: return 4.0 / 3.0 * pi;
    case ShapeKind::torus: return 2 * pi * pi * kTorusMajor * kTorusMinor * kTorusMinor;
    case ShapeKind::box: return 8 * kBoxHalf.prod();
    case ShapeKind::cylinder: return pi * kCylRadius * kCylRadius * 2 * kCylHalf;
    default: {
      // Plate (rectangle with the two -x corners rounded) - chamfer prism +
      // boss + fillet ring - hole; the pieces do not overlap otherwise.
      const double plate = (2 * 2 * 0.7 - 2 * (1 - pi / 4) * 0.2 * 0.2) * 0.5;
      const double chamfer = 0.5 * 0.15 * 0.15 * 1.4;
      const double boss = pi * 0.35 * 0.35 * 0.5;
      // Fillet ring: revolve the region between the square [0,f]^2 and the
      // quarter disc of radius f centred at (f, f) about the boss axis, at
      // r = 0.35 + x. Area f^2 (1 - pi/4); its centroid lies
      // f (10 - 3 pi) / (12 - 3 pi) from the boss wall (Pappus' theorem).
      const double f = 0.1;
      const double a = f * f * (1 - pi / 4);
      const double xc = f * (10 - 3 * pi) / (12 - 3 * pi);
      const double ring = 2 * pi * (0.35 + xc) * a;
      const double hole = pi * 0.18 * 0.18 * 0.5;
      return plate - chamfer + boss + ring - hole;
    }
  }
}

Mat3 parse_rotation(const std::string& spec) {
  if (spec.empty() || spec == "none") return Mat3::Identity();
  if (spec.rfind("random:", 0) == 0) {
    uint64_t seed = 0;
    try {
      size_t used = 0;
      seed = std::stoull(spec.substr(7), &used);
      if (used != spec.size() - 7) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw UsageError("--rotate random:SEED needs an integer seed, got '" + spec + "'");
    }
    uint64_t s = seed * 0x9e3779b97f4a7c15ull + 0x1234567ull;
    // Shoemake's uniform random unit quaternion.
    const double u1 = uniform01(s), u2 = uniform01(s), u3 = uniform01(s);
    const double pi = std::numbers::pi;
    const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(2 * pi * u3), std::sqrt(1 - u1) * std::sin(2 * pi * u2),
                               std::sqrt(1 - u1) * std::cos(2 * pi * u2), std::sqrt(u1) * std::sin(2 * pi * u3));
    return q.normalized().toRotationMatrix();
  }
  std::array<double, 3> deg{};
  std::stringstream in(spec);
  std::string part;
  int n = 0;
  while (std::getline(in, part, ',')) {
    try {
      size_t used = 0;
      if (n >= 3) throw std::invalid_argument("too many");
      deg[size_t(n)] = std::stod(part, &used);
      if (used != part.size() || !std::isfinite(deg[size_t(n)])) throw std::invalid_argument("junk");
    } catch (const std::exception&) {
      throw UsageError("--rotate expects random:SEED or AX,AY,AZ in degrees, got '" + spec + "'");
    }
    ++n;
  }
  if (n != 3) throw UsageError("--rotate expects random:SEED or AX,AY,AZ in degrees, got '" + spec + "'");
  const double r = std::numbers::pi / 180;
  return (Eigen::AngleAxisd(deg[2] * r, Vec3::UnitZ()) * Eigen::AngleAxisd(deg[1] * r, Vec3::UnitY()) *
          Eigen::AngleAxisd(deg[0] * r, Vec3::UnitX()))
      .toRotationMatrix();
}

GeneratedShape generate_shape(ShapeKind kind, const GenerateOptions& o) {
  const Mat3& R = o.rotation;
  if (!(o.fillet >= 0) || !std::isfinite(o.fillet)) throw UsageError("--fillet must be a finite radius >= 0");
  if (o.fillet > 0 && kind != ShapeKind::box && kind != ShapeKind::cylinder)
    throw UsageError("--fillet rounds the edges of 'box' or 'cylinder' only");
  // Extent of the rotated shape along each world axis: support in +/- e_a.
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    const Vec3 d = R.row(a).transpose();  // (R m)_a = m . R.row(a)
    hi[a] = shape_support(kind, d);
    lo[a] = -shape_support(kind, -d);
  }
  const Placement place = place_on_lattice(lo, hi, R, o.res, o.spacing, o.margin, o.max_bytes);
  GeneratedShape g;
  g.kind = kind;
  g.scale = place.scale;
  g.linear = place.linear;
  g.translation = place.translation;
  const Lattice& L = place.lattice;
  // The radius in cells of the smallest spacing, in model units; the
  // lattice is the sharp shape's (the rounded one lies inside it).
  g.fillet = o.fillet * L.spacing.minCoeff() / g.scale;
  const double smallest = kind == ShapeKind::cylinder ? std::min(kCylRadius, kCylHalf) : kBoxHalf.minCoeff();
  if (g.fillet >= smallest)
    throw UsageError("--fillet " + std::to_string(o.fillet) + " cells is not below the " + shape_name(kind) +
                     "'s smallest half extent (" + std::to_string(smallest * g.scale / L.spacing.minCoeff()) + " cells)");
  if (kind == ShapeKind::cad_part) {
    // The part is its mesh: classify every sample exactly against it.
    Mesh physical;
    for (const Vec3& p : cad_part_mesh().positions) physical.positions.push_back(g.translation + g.linear * p);
    physical.triangles = cad_part_mesh().triangles;
    g.volume = voxelize_on(physical, L, o.progress);
  } else {
    g.volume.lattice = L;
    g.volume.inside.resize(L.size());
    const Mat3 to_model = g.linear.inverse();
    ProgressCounter progress(o.progress, "sampling", uint64_t(L.dims[2]));
    detail::parallel_for(int64_t(0), L.dims[2], [&](int64_t k) {
      for (int64_t j = 0; j < L.dims[1]; ++j)
        for (int64_t i = 0; i < L.dims[0]; ++i) {
          const Vec3 p = L.to_physical(Vec3(double(i), double(j), double(k)));
          g.volume.inside[L.linear(i, j, k)] = shape_contains(kind, to_model * (p - g.translation), g.fillet) ? 1 : 0;
        }
      progress.add(1);
    });
  }
  g.volume.source = std::string("generated ") + shape_name(kind) + (g.fillet > 0 ? " (filleted)" : "");
  return g;
}

std::vector<PlanarFace> planar_faces(const Mesh& mesh, double angle_deg, double distance) {
  const size_t nf = mesh.face_count();
  std::vector<Vec3> normal(nf);
  std::vector<double> area(nf);
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    const Vec3 c = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    area[f] = c.norm() / 2;
    normal[f] = area[f] > 0 ? Vec3(c.normalized()) : Vec3::Zero();
  }
  // Faces across each edge (a closed manifold mesh has two per edge).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> edges;
  for (size_t f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e) {
      uint32_t a = mesh.triangles[f][size_t(e)], b = mesh.triangles[f][size_t((e + 1) % 3)];
      if (a > b) std::swap(a, b);
      edges[{a, b}].push_back(uint32_t(f));
    }
  const double cos_tol = std::cos(angle_deg * std::numbers::pi / 180);
  std::vector<int> group(nf, -1);
  std::vector<PlanarFace> out;
  for (size_t f0 = 0; f0 < nf; ++f0) {
    if (group[f0] >= 0 || area[f0] == 0) continue;
    const Vec3 n = normal[f0];
    const double c = n.dot(mesh.positions[mesh.triangles[f0][0]]);
    const int id = int(out.size());
    PlanarFace pf{n, c, 0};
    std::vector<uint32_t> stack{uint32_t(f0)};
    group[f0] = id;
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      pf.area += area[f];
      for (int e = 0; e < 3; ++e) {
        uint32_t a = mesh.triangles[f][size_t(e)], b = mesh.triangles[f][size_t((e + 1) % 3)];
        if (a > b) std::swap(a, b);
        for (uint32_t g : edges[{a, b}]) {
          if (group[g] >= 0 || area[g] == 0 || normal[g].dot(n) < cos_tol) continue;
          bool on = true;
          for (uint32_t v : mesh.triangles[g]) on &= std::abs(n.dot(mesh.positions[v]) - c) <= distance;
          if (!on) continue;
          group[g] = id;
          stack.push_back(g);
        }
      }
    }
    out.push_back(pf);
  }
  std::stable_sort(out.begin(), out.end(), [](const PlanarFace& a, const PlanarFace& b) { return a.area > b.area; });
  return out;
}

std::vector<PlanarFace> shape_planar_faces(ShapeKind kind, double fillet) {
  std::vector<PlanarFace> out;
  switch (kind) {
    case ShapeKind::box: {
      const Vec3 h = kBoxHalf, inner = kBoxHalf - Vec3::Constant(fillet);  // a filleted face is its inner rectangle
      for (int a = 0; a < 3; ++a)
        for (double s : {1.0, -1.0}) {
          Vec3 n = Vec3::Zero();
          n[a] = s;
          out.push_back({n, h[a], 4 * inner[(a + 1) % 3] * inner[(a + 2) % 3]});
        }
      break;
    }
    case ShapeKind::cylinder:  // a filleted cap is its inner disc
      for (double s : {1.0, -1.0})
        out.push_back({Vec3(0, 0, s), kCylHalf, std::numbers::pi * (kCylRadius - fillet) * (kCylRadius - fillet)});
      break;
    case ShapeKind::cad_part:
      for (const PlanarFace& f : planar_faces(cad_part_mesh()))
        if (f.area > 1e-3) out.push_back(f);
      break;
    default: break;
  }
  return out;
}

PlanarFace transform_face(const PlanarFace& f, const Mat3& linear, const Vec3& translation) {
  const double scale = std::cbrt(std::abs(linear.determinant()));
  const Vec3 n = (linear.inverse().transpose() * f.normal).normalized();
  return {n, scale * f.offset + n.dot(translation), scale * scale * f.area};
}

}  // namespace voxpress
