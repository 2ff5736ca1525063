// Truth implementations: exact analytic shapes and BVH-backed meshes.
#include "voxpress/eval/truth.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <sstream>

#include "mesh_query.h"
#include "voxpress/core/error.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/io/mesh_io.h"

namespace voxpress {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTorusR = 1.0, kTorusr = 0.4;
const Vec3 kBoxHalf(1.0, 0.75, 0.5);
constexpr double kCylR = 0.6, kCylH = 1.0;

// ------------------------------------------------------------- analytic
class AnalyticTruth final : public Truth {
 public:
  AnalyticTruth(ShapeKind kind, const Mat3& linear, const Vec3& translation, double fillet)
      : kind_(kind), A_(linear), t_(translation), Ainv_(linear.inverse()), N_(linear.inverse().transpose()),
        scale_(std::cbrt(std::abs(linear.determinant()))), fillet_(kind == ShapeKind::box || kind == ShapeKind::cylinder ? fillet : 0) {}

  std::string describe() const override {
    std::string d = std::string(shape_name(kind_)) + " (analytic";
    if (fillet_ > 0) d += ", edges filleted, radius " + std::to_string(fillet_ * scale_) + " physical";
    return d + ")";
  }

  SurfacePoint closest(const Vec3& p, const Vec3* normal_hint) const override {
    const Vec3 m = Ainv_ * (p - t_);
    // Normals map with N = A^-T, so a physical hint maps back with A^T.
    const Vec3 hint = normal_hint ? Vec3(A_.transpose() * *normal_hint) : Vec3::Zero();
    Vec3 q, n;
    closest_model(m, hint, q, n);
    return {t_ + A_ * q, (N_ * n).normalized()};
  }

  bool contains(const Vec3& p) const override { return shape_contains(kind_, Ainv_ * (p - t_), fillet_); }

  double crossing(const Vec3& a, const Vec3& b, double near) const override {
    // Bisection on the exact inside test. A one-voxel stick crosses these
    // smooth surfaces at most a few times: scan 16 sub-intervals for sign
    // changes, bisect each to machine precision, keep the one nearest `near`.
    const int n = 16;
    double best = NAN;
    bool prev = contains(a);
    for (int i = 1; i <= n; ++i) {
      const double s1 = double(i) / n, s0 = double(i - 1) / n;
      const bool cur = contains(a + s1 * (b - a));
      if (cur != prev) {
        double lo = s0, hi = s1;
        const bool lo_in = prev;
        for (int it = 0; it < 50; ++it) {
          const double mid = 0.5 * (lo + hi);
          (contains(a + mid * (b - a)) == lo_in ? lo : hi) = mid;
        }
        const double s = 0.5 * (lo + hi);
        if (std::isnan(best) || std::abs(s - near) < std::abs(best - near)) best = s;
      }
      prev = cur;
    }
    return best;
  }

  SurfacePoint sample(uint64_t seed, uint64_t index) const override {
    auto u = [&](int k) { return detail::uniform(seed, 8 * index + uint64_t(k)); };
    Vec3 q, n;
    if (fillet_ > 0 && kind_ == ShapeKind::box) {
      sample_filleted_box(u, q, n);
      return {t_ + A_ * q, (N_ * n).normalized()};
    }
    switch (kind_) {
      case ShapeKind::sphere: {
        const double z = 2 * u(0) - 1, phi = 2 * kPi * u(1), r = std::sqrt(std::max(0.0, 1 - z * z));
        q = n = Vec3(r * std::cos(phi), r * std::sin(phi), z);
        break;
      }
      case ShapeKind::torus: {
        // Area element (R + r cos v): v by cosine_weighted.
        const double v = cosine_weighted(seed ^ 0x9e37u, index, 2 * kPi, kTorusR, kTorusr);
        const double w = 2 * kPi * detail::uniform(seed ^ 0x5bd1e995u, index);
        n = Vec3(std::cos(v) * std::cos(w), std::cos(v) * std::sin(w), std::sin(v));
        q = Vec3(kTorusR * std::cos(w), kTorusR * std::sin(w), 0) + kTorusr * n;
        break;
      }
      case ShapeKind::box: {
        const Vec3& h = kBoxHalf;
        const double areas[3] = {h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};
        const double total = areas[0] + areas[1] + areas[2];
        double pick = u(0) * total;
        int axis = 0;
        while (axis < 2 && pick > areas[axis]) pick -= areas[axis++];
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        q[axis] = u(1) < 0.5 ? -h[axis] : h[axis];
        q[a1] = (2 * u(2) - 1) * h[a1];
        q[a2] = (2 * u(3) - 1) * h[a2];
        n = Vec3::Zero();
        n[axis] = q[axis] > 0 ? 1 : -1;
        break;
      }
      default: sample_cylinder(seed, index, u, q, n); break;
    }
    return {t_ + A_ * q, (N_ * n).normalized()};
  }

  double area() const override {
    double a = 0;
    switch (kind_) {
      case ShapeKind::sphere: a = 4 * kPi; break;
      case ShapeKind::torus: a = 4 * kPi * kPi * kTorusR * kTorusr; break;
      case ShapeKind::box: {
        // Faces of the shrunk box, the edges' quarter cylinders, the corners' ball.
        const Vec3 h = kBoxHalf - Vec3::Constant(fillet_);
        const double f = fillet_;
        a = 8 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z()) + 4 * kPi * f * h.sum() + 4 * kPi * f * f;
        break;
      }
      default: {
        const CylinderParts p = cylinder_parts();
        a = p.side + 2 * p.cap + 2 * p.rim;
        break;
      }
    }
    return a * scale_ * scale_;
  }
  double volume() const override { return shape_volume(kind_, fillet_) * std::abs(A_.determinant()); }

  std::vector<std::array<Vec3, 2>> sharp_edges(double angle_deg) const override {
    std::vector<std::array<Vec3, 2>> out;
    auto add = [&](const Vec3& a, const Vec3& b) { out.push_back({t_ + A_ * a, t_ + A_ * b}); };
    if (kind_ == ShapeKind::box && fillet_ == 0 && angle_deg < 90) {  // a filleted box is C1: none
      const Vec3& h = kBoxHalf;
      for (int axis = 0; axis < 3; ++axis)
        for (int s1 : {-1, 1})
          for (int s2 : {-1, 1}) {
            Vec3 a, b;
            const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            a[axis] = -h[axis];
            b[axis] = h[axis];
            a[a1] = b[a1] = s1 * h[a1];
            a[a2] = b[a2] = s2 * h[a2];
            add(a, b);
          }
    } else if (kind_ == ShapeKind::cylinder && fillet_ == 0 && angle_deg < 90) {
      const int n = 1024;
      for (double z : {-kCylH, kCylH})
        for (int i = 0; i < n; ++i) {
          const double p0 = 2 * kPi * i / n, p1 = 2 * kPi * (i + 1) / n;
          add(Vec3(kCylR * std::cos(p0), kCylR * std::sin(p0), z), Vec3(kCylR * std::cos(p1), kCylR * std::sin(p1), z));
        }
    }
    return out;
  }

 private:
  // Picks, among candidate outward normals (the faces a crease point lies
  // on), the one best aligned with the hint, else the first.
  static Vec3 pick(const Vec3* candidates, int count, const Vec3& hint) {
    int best = 0;
    if (hint != Vec3::Zero())
      for (int i = 1; i < count; ++i)
        if (candidates[i].dot(hint) > candidates[best].dot(hint)) best = i;
    return candidates[best];
  }

  // The filleted box (the shrunk box h plus a ball of radius f), uniform by
  // area: a face of the shrunk box, an edge's quarter cylinder or a corner's
  // ball eighth, by their areas. A uniform direction of the whole ball
  // (cylinder) lands in the corner (edge) of its signs.
  template <class U>
  void sample_filleted_box(const U& u, Vec3& q, Vec3& n) const {
    const Vec3 h = kBoxHalf - Vec3::Constant(fillet_);
    const double f = fillet_;
    double piece[7];
    for (int a = 0; a < 3; ++a) {
      piece[a] = 8 * h[(a + 1) % 3] * h[(a + 2) % 3];  // the two faces normal to axis a
      piece[3 + a] = 4 * kPi * f * h[a];                // the four edges along axis a
    }
    piece[6] = 4 * kPi * f * f;
    double total = 0;
    for (double p : piece) total += p;
    double pick = u(0) * total;
    int k = 0;
    while (k < 6 && pick > piece[k]) pick -= piece[k++];
    auto sgn = [](double x) { return x >= 0 ? 1.0 : -1.0; };
    if (k < 3) {  // a face
      const int a1 = (k + 1) % 3, a2 = (k + 2) % 3;
      n = Vec3::Zero();
      n[k] = u(1) < 0.5 ? -1 : 1;
      q = h[k] * n + f * n;
      q[a1] = (2 * u(2) - 1) * h[a1];
      q[a2] = (2 * u(3) - 1) * h[a2];
    } else if (k < 6) {  // an edge along axis a
      const int a = k - 3, a1 = (a + 1) % 3, a2 = (a + 2) % 3;
      const double phi = 2 * kPi * u(1);
      n = Vec3::Zero();
      n[a1] = std::cos(phi);
      n[a2] = std::sin(phi);
      Vec3 c = Vec3::Zero();
      c[a] = (2 * u(2) - 1) * h[a];
      c[a1] = sgn(n[a1]) * h[a1];
      c[a2] = sgn(n[a2]) * h[a2];
      q = c + f * n;
    } else {  // a corner
      const double z = 2 * u(1) - 1, phi = 2 * kPi * u(2), r = std::sqrt(std::max(0.0, 1 - z * z));
      n = Vec3(r * std::cos(phi), r * std::sin(phi), z);
      q = Vec3(sgn(n.x()) * h.x(), sgn(n.y()) * h.y(), sgn(n.z()) * h.z()) + f * n;
    }
  }

  // An angle in [0, span) with density R + r cos(angle): rejection sampling
  // from a sub-stream of this index (the torus: acceptance 1/1.4; 64 tries
  // never all fail in practice, and the last one is taken if they do).
  static double cosine_weighted(uint64_t stream, uint64_t index, double span, double R, double r) {
    double a = 0;
    for (uint64_t k = 0; k < 64; ++k) {
      a = span * detail::uniform(stream, 128 * index + 2 * k);
      if (detail::uniform(stream, 128 * index + 2 * k + 1) * (R + r) <= R + r * std::cos(a)) break;
    }
    return a;
  }

  // The (filleted) cylinder's areas, model units: its side, one cap's disc
  // and one rim's outer quarter torus (Pappus) of the shrunk cylinder r, h
  // (a sharp cylinder: no rim).
  struct CylinderParts {
    double side, cap, rim;
  };
  CylinderParts cylinder_parts() const {
    const double f = fillet_, r = kCylR - f, h = kCylH - f;
    return {2 * kPi * kCylR * 2 * h, kPi * r * r, 2 * kPi * f * (kPi / 2 * r + f)};
  }

  // The cylinder, sharp or filleted (the shrunk cylinder r, h plus a ball
  // of radius f), uniform by area: the side, a cap's disc or a rim's outer
  // quarter torus (none when sharp), by their areas. On a rim, theta (0:
  // outwards, pi/2: up) has density (r + f cos theta): cosine_weighted.
  template <class U>
  void sample_cylinder(uint64_t seed, uint64_t index, const U& u, Vec3& q, Vec3& n) const {
    const double f = fillet_, r = kCylR - f, h = kCylH - f;
    const auto [side, cap, rim] = cylinder_parts();
    const double phi = 2 * kPi * u(1);
    const Vec3 dir(std::cos(phi), std::sin(phi), 0);
    const double up = u(3) < 0.5 ? -1 : 1;
    double pick = u(0) * (side + 2 * cap + 2 * rim);
    if (pick < side) {
      n = dir;
      q = Vec3(kCylR * dir.x(), kCylR * dir.y(), (2 * u(2) - 1) * h);
    } else if ((pick -= side) < 2 * cap) {
      const double rho = r * std::sqrt(u(2));
      q = Vec3(rho * dir.x(), rho * dir.y(), up * kCylH);
      n = Vec3(0, 0, up);
    } else {
      const double th = cosine_weighted(seed ^ 0x7f4a7c15u, index, kPi / 2, r, f);
      n = Vec3(std::cos(th) * dir.x(), std::cos(th) * dir.y(), up * std::sin(th));
      q = Vec3(r * dir.x(), r * dir.y(), up * h) + f * n;
    }
  }

  // The filleted cylinder's exact closest point, as the box's: from outside
  // the shrunk cylinder along the direction from its nearest point; from
  // inside it straight to the nearer of the side and the cap.
  void closest_filleted_cylinder(const Vec3& m, Vec3& q, Vec3& n) const {
    const double f = fillet_, r = kCylR - f, h = kCylH - f;
    const double rho = std::hypot(m.x(), m.y());
    const Vec3 dir = rho > 0 ? Vec3(m.x() / rho, m.y() / rho, 0) : Vec3::UnitX();
    // Exactly m where m is inside (rho * dir would round off it).
    const Vec3 c = rho <= r ? Vec3(m.x(), m.y(), std::clamp(m.z(), -h, h)) : Vec3(r * dir.x(), r * dir.y(), std::clamp(m.z(), -h, h));
    const Vec3 d = m - c;
    if (d.squaredNorm() > 0) {
      n = d.normalized();
      q = c + f * n;
      return;
    }
    if (r - rho <= h - std::abs(m.z())) {
      n = dir;
      q = Vec3(kCylR * dir.x(), kCylR * dir.y(), m.z());
    } else {
      n = Vec3(0, 0, m.z() >= 0 ? 1 : -1);
      q = Vec3(m.x(), m.y(), n.z() * kCylH);
    }
  }

  // The filleted box's exact closest point: from outside the shrunk box h,
  // along the direction from its nearest point c (distance |m - c| - f);
  // from inside it, straight to the nearest face (its flat part covers the
  // projection). The surface is C1, so the normal is unique.
  void closest_filleted_box(const Vec3& m, Vec3& q, Vec3& n) const {
    const Vec3 h = kBoxHalf - Vec3::Constant(fillet_);
    const Vec3 c = m.cwiseMax(-h).cwiseMin(h);
    const Vec3 d = m - c;
    if (d.squaredNorm() > 0) {
      n = d.normalized();
    } else {
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (h[a] - std::abs(m[a]) < h[axis] - std::abs(m[axis])) axis = a;
      n = Vec3::Zero();
      n[axis] = m[axis] >= 0 ? 1 : -1;
      Vec3 cc = m;
      cc[axis] = n[axis] * h[axis];
      q = cc + fillet_ * n;
      return;
    }
    q = c + fillet_ * n;
  }

  // Exact closest point q on the model surface and outward normal n.
  void closest_model(const Vec3& m, const Vec3& hint, Vec3& q, Vec3& n) const {
    if (fillet_ > 0) return kind_ == ShapeKind::box ? closest_filleted_box(m, q, n) : closest_filleted_cylinder(m, q, n);
    switch (kind_) {
      case ShapeKind::sphere: {
        const double r = m.norm();
        n = r > 0 ? Vec3(m / r) : Vec3::UnitX();
        q = n;
        return;
      }
      case ShapeKind::torus: {
        const double rho = std::hypot(m.x(), m.y());
        const Vec3 dir = rho > 0 ? Vec3(m.x() / rho, m.y() / rho, 0) : Vec3::UnitX();
        const Vec3 c = kTorusR * dir, d = m - c;
        const double len = d.norm();
        n = len > 0 ? Vec3(d / len) : dir;
        q = c + kTorusr * n;
        return;
      }
      case ShapeKind::box: {
        const Vec3& h = kBoxHalf;
        Vec3 cand[3];
        int count = 0;
        if ((m.cwiseAbs().array() > h.array()).any()) {
          // Outside: clamp; the faces q lies on are candidates, the one with
          // the largest excess first.
          q = m.cwiseMax(-h).cwiseMin(h);
          int order[3] = {0, 1, 2};
          std::sort(order, order + 3, [&](int a, int b) { return std::abs(m[a]) - h[a] > std::abs(m[b]) - h[b]; });
          for (int a : order)
            if (std::abs(q[a]) == h[a]) cand[count++] = (q[a] > 0 ? 1.0 : -1.0) * Vec3::Unit(a);
        } else {
          // Inside: the nearest face(s).
          double best = INFINITY;
          for (int a = 0; a < 3; ++a) best = std::min(best, h[a] - std::abs(m[a]));
          int axis = -1;
          for (int a = 0; a < 3; ++a)
            if (h[a] - std::abs(m[a]) == best) {
              cand[count++] = (m[a] >= 0 ? 1.0 : -1.0) * Vec3::Unit(a);
              if (axis < 0) axis = a;
            }
          q = m;
          q[axis] = m[axis] >= 0 ? h[axis] : -h[axis];
        }
        n = pick(cand, count, hint);
        return;
      }
      default: {  // capped cylinder
        const double rho = std::hypot(m.x(), m.y());
        const Vec3 dir = rho > 0 ? Vec3(m.x() / rho, m.y() / rho, 0) : Vec3::UnitX();
        const Vec3 cap = Vec3(0, 0, m.z() >= 0 ? 1 : -1);
        const double to_side = kCylR - rho, to_cap = kCylH - std::abs(m.z());
        if (to_side >= 0 && to_cap >= 0) {  // inside: the nearer of side and cap
          if (to_side <= to_cap) {
            q = Vec3(kCylR * dir.x(), kCylR * dir.y(), m.z());
          } else {
            q = Vec3(m.x(), m.y(), m.z() >= 0 ? kCylH : -kCylH);
          }
          const Vec3 cand[2] = {to_side <= to_cap ? dir : cap, to_side <= to_cap ? cap : dir};
          n = pick(cand, to_side == to_cap ? 2 : 1, hint);
          return;
        }
        const double r = std::min(rho, kCylR);
        q = Vec3(r * dir.x(), r * dir.y(), std::clamp(m.z(), -kCylH, kCylH));
        const bool on_side = r == kCylR, on_cap = std::abs(q.z()) == kCylH;
        const bool side_first = -to_side >= -to_cap;  // larger excess first
        Vec3 cand[2];
        int count = 0;
        if (on_side && on_cap) {
          cand[count++] = side_first ? dir : cap;
          cand[count++] = side_first ? cap : dir;
        } else {
          cand[count++] = on_side ? dir : cap;
        }
        n = pick(cand, count, hint);
        return;
      }
    }
  }

  ShapeKind kind_;
  Mat3 A_;
  Vec3 t_;
  Mat3 Ainv_, N_;
  double scale_;
  double fillet_;  // the box's or cylinder's fillet radius (model units), 0 otherwise
};

// ------------------------------------------------------------- mesh
class MeshTruth final : public Truth {
 public:
  MeshTruth(Mesh mesh, std::string name) : mesh_(std::move(mesh)), name_(std::move(name)), query_(mesh_) {
    volume_ = signed_volume(mesh_);
  }
  std::string describe() const override {
    return name_ + " (mesh, " + std::to_string(mesh_.triangles.size()) + " faces)";
  }
  SurfacePoint closest(const Vec3& p, const Vec3* normal_hint) const override {
    const auto hit = query_.closest(p, normal_hint ? *normal_hint : Vec3::Zero());
    return {hit.point, query_.normal(hit.face)};
  }
  bool contains(const Vec3& p) const override { return mesh_contains(mesh_, p); }
  double crossing(const Vec3& a, const Vec3& b, double near) const override {
    thread_local std::vector<double> hits;
    query_.segment_hits(a, b, hits);
    double best = NAN;
    for (double s : hits)
      if (std::isnan(best) || std::abs(s - near) < std::abs(best - near)) best = s;
    return best;
  }
  SurfacePoint sample(uint64_t seed, uint64_t index) const override {
    const auto hit = query_.sample(seed, index);
    return {hit.point, query_.normal(hit.face)};
  }
  double area() const override { return query_.area(); }
  double volume() const override { return std::abs(volume_); }
  std::vector<std::array<Vec3, 2>> sharp_edges(double angle_deg) const override {
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> faces;
    for (uint32_t f = 0; f < mesh_.triangles.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = mesh_.triangles[f][size_t(k)], v = mesh_.triangles[f][size_t((k + 1) % 3)];
        faces[{std::min(u, v), std::max(u, v)}].push_back(f);
      }
    const double cos_limit = std::cos(angle_deg * kPi / 180);
    std::vector<std::array<Vec3, 2>> out;
    for (const auto& [e, fs] : faces)
      if (fs.size() == 2 && query_.normal(fs[0]).dot(query_.normal(fs[1])) < cos_limit)
        out.push_back({mesh_.positions[e.first], mesh_.positions[e.second]});
    return out;
  }

 private:
  Mesh mesh_;
  std::string name_;
  detail::MeshQuery query_;
  double volume_ = 0;
};

Mesh transformed(const Mesh& m, const Mat3& linear, const Vec3& translation) {
  Mesh out;
  out.triangles = m.triangles;
  out.positions.reserve(m.positions.size());
  for (const Vec3& p : m.positions) out.positions.push_back(translation + linear * p);
  if (linear.determinant() < 0)
    for (auto& t : out.triangles) std::swap(t[1], t[2]);
  return out;
}

}  // namespace

std::unique_ptr<Truth> shape_truth(ShapeKind kind, const Mat3& linear, const Vec3& translation, double fillet) {
  if (kind == ShapeKind::cad_part)
    return mesh_truth(transformed(cad_part_mesh(), linear, translation), shape_name(kind));
  return std::make_unique<AnalyticTruth>(kind, linear, translation, fillet);
}

std::unique_ptr<Truth> mesh_truth(Mesh physical_mesh, const std::string& name) {
  return std::make_unique<MeshTruth>(std::move(physical_mesh), name);
}

std::string format_transform(const Mat3& linear, const Vec3& translation) {
  std::ostringstream t;
  t.precision(17);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) t << linear(r, c) << ' ';
  t << translation.x() << ' ' << translation.y() << ' ' << translation.z();
  return t.str();
}

bool parse_transform(const std::string& text, Mat3& linear, Vec3& translation) {
  std::istringstream in(text);
  double v[12];
  for (double& x : v)
    if (!(in >> x) || !std::isfinite(x)) return false;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) linear(r, c) = v[3 * r + c];
  translation = Vec3(v[9], v[10], v[11]);
  return std::abs(linear.determinant()) > 0;
}

std::unique_ptr<Truth> resolve_truth(const std::string& spec, const ScalarVolume* volume) {
  Mat3 linear = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  bool have_transform = false;
  std::string meta_shape, meta_mesh;
  double fillet = 0;
  if (volume) {
    auto get = [&](const char* key) {
      auto it = volume->metadata.find(key);
      return it == volume->metadata.end() ? std::string() : it->second;
    };
    meta_shape = get(kShapeKey);
    meta_mesh = get(kTruthMeshKey);
    const std::string tr = get(kModelToPhysicalKey);
    if (!tr.empty()) {
      if (!parse_transform(tr, linear, translation))
        throw InputError(volume->source, std::string("malformed ") + kModelToPhysicalKey + " metadata");
      have_transform = true;
    }
    const std::string fl = get(kFilletKey);
    if (!fl.empty()) {
      char* end = nullptr;
      fillet = std::strtod(fl.c_str(), &end);
      if (end == fl.c_str() || *end != '\0' || !(fillet >= 0) || !std::isfinite(fillet))
        throw InputError(volume->source, std::string("malformed ") + kFilletKey + " metadata");
    }
  }
  std::string what = spec.empty() ? (!meta_shape.empty() ? meta_shape : meta_mesh) : spec;
  if (what.empty())
    throw UsageError("no truth: give --truth SHAPE|MESH, or a --volume written by `voxpress generate` or "
                     "`voxpress voxelize`");
  for (ShapeKind k : all_shapes())
    if (what == shape_name(k)) {
      if (!have_transform)
        throw UsageError(std::string("the ") + shape_name(k) +
                         " truth needs its placement: give the --volume written by `voxpress generate`");
      return shape_truth(k, linear, translation, fillet);
    }
  // A mesh file: the stored transform applies when the volume was voxelized from a model.
  Mesh model = read_mesh(what);
  require_solid(model, what);  // inside and outside, volume ratio: an open mesh has neither (issue 73)
  const std::string name = std::filesystem::path(what).filename().string();
  return mesh_truth(have_transform ? transformed(model, linear, translation) : std::move(model), name);
}

}  // namespace voxpress
