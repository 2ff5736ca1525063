#include "voxpress/eval/shapes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "voxpress/core/error.h"

namespace voxpress {
namespace {

constexpr double kTorusMajor = 1.0, kTorusMinor = 0.4;
const Vec3 kBoxHalf(1.0, 0.75, 0.5);
constexpr double kCylRadius = 0.6, kCylHalf = 1.0;

// CAD part dimensions (model units).
constexpr double kPlateX = 1.0, kPlateY = 0.7, kPlateZ = 0.25, kPlateRound = 0.2;
constexpr double kChamfer = 0.15;                 // leg of the 45-degree chamfer on the +x top edge
constexpr double kBossX = 0.3, kBossY = 0.0, kBossR = 0.35, kBossTop = 0.75;
constexpr double kFillet = 0.1;                   // concave fillet at the boss base
constexpr double kHoleX = -0.5, kHoleY = 0.1, kHoleR = 0.18;

bool cad_contains(const Vec3& m) {
  const double x = m.x(), y = m.y(), z = m.z();
  // Through hole first: nothing inside it.
  if ((x - kHoleX) * (x - kHoleX) + (y - kHoleY) * (y - kHoleY) < kHoleR * kHoleR) return false;
  const double rb = std::hypot(x - kBossX, y - kBossY);
  // Boss.
  if (rb <= kBossR && z >= kPlateZ - 1e-12 && z <= kBossTop) return true;
  // Concave fillet: the ring kBossR <= r <= kBossR + f, plate top <= z <= top + f,
  // minus the torus tube centred at (kBossR + f, kPlateZ + f) of radius f.
  if (rb >= kBossR && rb <= kBossR + kFillet && z >= kPlateZ && z <= kPlateZ + kFillet) {
    const double dr = rb - (kBossR + kFillet), dz = z - (kPlateZ + kFillet);
    if (dr * dr + dz * dz >= kFillet * kFillet) return true;
  }
  // Plate: rounded rectangle in xy, |z| <= kPlateZ, chamfer x + z <= kPlateX + kPlateZ - kChamfer.
  if (std::abs(z) > kPlateZ) return false;
  if (x + z > kPlateX + kPlateZ - kChamfer) return false;
  const double ax = std::abs(x), ay = std::abs(y);
  if (ax > kPlateX || ay > kPlateY) return false;
  const double cx = kPlateX - kPlateRound, cy = kPlateY - kPlateRound;
  if (ax > cx && ay > cy) {
    const double dx = ax - cx, dy = ay - cy;
    return dx * dx + dy * dy <= kPlateRound * kPlateRound;
  }
  return true;
}

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

bool shape_contains(ShapeKind kind, const Vec3& m) {
  switch (kind) {
    case ShapeKind::sphere: return m.squaredNorm() <= 1.0;
    case ShapeKind::torus: {
      const double q = std::hypot(m.x(), m.y()) - kTorusMajor;
      return q * q + m.z() * m.z() <= kTorusMinor * kTorusMinor;
    }
    case ShapeKind::box:
      return std::abs(m.x()) <= kBoxHalf.x() && std::abs(m.y()) <= kBoxHalf.y() && std::abs(m.z()) <= kBoxHalf.z();
    case ShapeKind::cylinder: return m.x() * m.x() + m.y() * m.y() <= kCylRadius * kCylRadius && std::abs(m.z()) <= kCylHalf;
    default: return cad_contains(m);
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
      // Bounding box x in [-1, 1], y in [-0.7, 0.7], z in [-0.25, 0.75] (conservative).
      const double zc = 0.5 * (kBossTop - kPlateZ), zh = 0.5 * (kBossTop + kPlateZ);
      return kPlateX * std::abs(d.x()) + kPlateY * std::abs(d.y()) + zc * d.z() + zh * std::abs(d.z());
    }
  }
}

double shape_volume(ShapeKind kind) {
  const double pi = std::numbers::pi;
  switch (kind) {
    case ShapeKind::sphere: return 4.0 / 3.0 * pi;
    case ShapeKind::torus: return 2 * pi * pi * kTorusMajor * kTorusMinor * kTorusMinor;
    case ShapeKind::box: return 8 * kBoxHalf.prod();
    case ShapeKind::cylinder: return pi * kCylRadius * kCylRadius * 2 * kCylHalf;
    default: {
      // Plate (rounded rectangle) - chamfer + boss + fillet ring - hole; the
      // pieces do not overlap otherwise (see the dimensions above).
      const double plate = (4 * kPlateX * kPlateY - (4 - pi) * kPlateRound * kPlateRound) * 2 * kPlateZ;
      // Chamfer: at height y the plate reaches x = X(y) (rounded corners) and
      // the cut removes the triangle of area 0.5 * max(0, X - (kPlateX - kChamfer))^2
      // from the xz cross-section; integrate over y (Simpson, smooth enough).
      auto xmax = [](double y) {
        const double dy = std::abs(y) - (kPlateY - kPlateRound);
        return dy <= 0 ? kPlateX : kPlateX - kPlateRound + std::sqrt(std::max(0.0, kPlateRound * kPlateRound - dy * dy));
      };
      auto section = [&](double y) {
        const double d = std::max(0.0, xmax(y) - (kPlateX - kChamfer));
        return 0.5 * d * d;
      };
      const int n = 20000;
      const double h = 2 * kPlateY / n;
      double chamfer = section(-kPlateY) + section(kPlateY);
      for (int i = 1; i < n; ++i) chamfer += (i % 2 ? 4 : 2) * section(-kPlateY + i * h);
      chamfer *= h / 3;
      const double boss = pi * kBossR * kBossR * (kBossTop - kPlateZ);
      // Fillet ring: revolve the region between the square [0,f]^2 and the
      // quarter disc of radius f centred at (f, f), at radius r = kBossR + x.
      // Area f^2 (1 - pi/4); its centroid lies f (10 - 3 pi) / (12 - 3 pi)
      // from the boss wall (Pappus' theorem gives the volume).
      const double a = kFillet * kFillet * (1 - pi / 4);
      const double xc = kFillet * (10 - 3 * pi) / (12 - 3 * pi);
      const double fillet = 2 * pi * (kBossR + xc) * a;
      const double hole = pi * kHoleR * kHoleR * 2 * kPlateZ;
      return plate - chamfer + boss + fillet - hole;
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
  if (o.res < 8) throw UsageError("--res must be at least 8");
  if (o.margin < 0 || o.margin > o.res / 4) throw UsageError("--margin must be between 0 and res/4");
  for (int a = 0; a < 3; ++a)
    if (!(o.spacing[a] > 0) || !std::isfinite(o.spacing[a])) throw UsageError("--spacing values must be > 0");
  const Mat3& R = o.rotation;
  // Extent of the rotated shape along each world axis: support in +/- e_a.
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    const Vec3 d = R.row(a).transpose();  // (R m)_a = m . R.row(a)
    hi[a] = shape_support(kind, d);
    lo[a] = -shape_support(kind, -d);
  }
  const Vec3 extent = hi - lo;
  double cells = 0;
  for (int a = 0; a < 3; ++a) cells = std::max(cells, extent[a] / o.spacing[a]);
  const double scale = double(o.res - 1 - 2 * o.margin) / cells;  // physical units per model unit
  Lattice L;
  for (int a = 0; a < 3; ++a) {
    const double span = scale * extent[a] / o.spacing[a];
    L.dims[size_t(a)] = std::max<int64_t>(int64_t(std::ceil(span - 1e-9)) + 1 + 2 * o.margin, 2);
  }
  L.spacing = o.spacing;
  L.validate();
  if (o.max_bytes && L.size() > o.max_bytes)
    throw LimitError("", "a " + std::to_string(L.dims[0]) + "x" + std::to_string(L.dims[1]) + "x" +
                             std::to_string(L.dims[2]) + " volume exceeds the memory limit");
  GeneratedShape g;
  g.kind = kind;
  g.scale = scale;
  g.linear = scale * R;
  const Vec3 lattice_centre = 0.5 * (Vec3(double(L.dims[0] - 1), double(L.dims[1] - 1), double(L.dims[2] - 1)))
                                        .cwiseProduct(o.spacing);
  g.translation = lattice_centre - scale * 0.5 * (lo + hi);
  g.volume.lattice = L;
  g.volume.source = std::string("generated ") + shape_name(kind);
  g.volume.inside.resize(L.size());
  const Mat3 to_model = g.linear.inverse();
  ProgressCounter progress(o.progress, "sampling", uint64_t(L.dims[2]));
  tbb::parallel_for(int64_t(0), L.dims[2], [&](int64_t k) {
    for (int64_t j = 0; j < L.dims[1]; ++j)
      for (int64_t i = 0; i < L.dims[0]; ++i) {
        const Vec3 p = L.to_physical(Vec3(double(i), double(j), double(k)));
        g.volume.inside[L.linear(i, j, k)] = shape_contains(kind, to_model * (p - g.translation)) ? 1 : 0;
      }
    progress.add(1);
  });
  return g;
}

}  // namespace voxpress
