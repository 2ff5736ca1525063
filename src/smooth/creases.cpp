// Beyond the paper: the fresh vertices next to a sharp flat border placed by
// the curved side's own surface, extrapolated up to the flat. Theory of
// operation: include/voxpress/smooth/flats.h (fit_creases).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "surface_graph.h"
#include "voxpress/smooth/flats.h"

namespace voxpress {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Where the stick from `in` (t = 0) to `out` (t = 1) leaves the solid
// bounded by the quadric height field h(a, b) over the frame (m; u, w, n),
// n outward: g(t) = n . (p - m) - h(a, b) changes sign from - to +. The
// root nearest `near` in [lo, hi]; NaN if none.
double quadric_exit(const Eigen::Matrix<double, 6, 1>& q, const Vec3& m, const Vec3& u, const Vec3& w, const Vec3& n,
                    const Vec3& in, const Vec3& out, double near, double lo, double hi) {
  const Vec3 e = out - in, d = in - m;
  // a(t) = a0 + a1 t, b(t) = b0 + b1 t, z(t) = z0 + z1 t.
  const double a0 = u.dot(d), a1 = u.dot(e), b0 = w.dot(d), b1 = w.dot(e), z0 = n.dot(d), z1 = n.dot(e);
  // h = q0 a^2 + q1 a b + q2 b^2 + q3 a + q4 b + q5
  const double A = -(q(0) * a1 * a1 + q(1) * a1 * b1 + q(2) * b1 * b1);
  const double B = z1 - (2 * q(0) * a0 * a1 + q(1) * (a0 * b1 + a1 * b0) + 2 * q(2) * b0 * b1 + q(3) * a1 + q(4) * b1);
  const double C = z0 - (q(0) * a0 * a0 + q(1) * a0 * b0 + q(2) * b0 * b0 + q(3) * a0 + q(4) * b0 + q(5));
  double roots[2];
  int k = 0;
  if (std::abs(A) < 1e-12 * (std::abs(B) + std::abs(C) + 1e-300)) {
    if (B != 0) roots[k++] = -C / B;
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      const double sq = std::sqrt(disc), r = -0.5 * (B + std::copysign(sq, B));
      roots[k++] = r / A;
      if (r != 0) roots[k++] = C / r;
    }
  }
  double best = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < k; ++i) {
    const double t = roots[i];
    if (!(t >= lo && t <= hi) || 2 * A * t + B <= 0) continue;  // inside to outside only
    if (std::isnan(best) || std::abs(t - near) < std::abs(best - near)) best = t;
  }
  return best;
}

}  // namespace

size_t fit_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o, std::vector<uint8_t>* zone) {
  const size_t n = s.stick_count();
  if (zone) zone->assign(n, 0);
  if (seg.flats.empty() || o.crease_rings < 0) return 0;
  std::vector<uint32_t> off, adj;
  detail::vertex_adjacency(n, s.triangles, off, adj);
  std::vector<Vec3> x(n), in(n), out(n);
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    x[v] = s.index_position(v);
    const auto l = s.lower_index(v);
    const Vec3 a = Vec3(double(l[0]), double(l[1]), double(l[2]));
    Vec3 b = a;
    b[s.axis(v)] += 1;
    in[v] = s.lower_inside(v) ? a : b;
    out[v] = s.lower_inside(v) ? b : a;
  });
  // Ring distance of each fresh vertex from the junctions (over fresh
  // vertices), and the flat of the junction it was reached from.
  constexpr uint32_t kFar = UINT32_MAX;
  std::vector<uint32_t> dist(n, kFar);
  std::vector<int32_t> flat(n, -1);
  std::vector<uint32_t> front;
  for (size_t v = 0; v < n; ++v) {
    if (seg.region[v] >= 0 || !seg.junction[v]) continue;
    for (uint32_t k = off[v]; k < off[v + 1] && flat[v] < 0; ++k) flat[v] = seg.region[adj[k]];
    if (flat[v] < 0) continue;
    dist[v] = 0;
    front.push_back(uint32_t(v));
  }
  const uint32_t R = uint32_t(o.crease_rings), F = uint32_t(o.crease_fit_rings);
  for (uint32_t d = 0; d < R + F && !front.empty(); ++d) {
    std::vector<uint32_t> next;
    for (uint32_t v : front)
      for (uint32_t k = off[v]; k < off[v + 1]; ++k) {
        const uint32_t w = adj[k];
        if (seg.region[w] >= 0 || dist[w] != kFar) continue;
        dist[w] = d + 1;
        flat[w] = flat[v];
        next.push_back(w);
      }
    front.swap(next);
  }
  std::vector<uint32_t> members;
  for (size_t v = 0; v < n; ++v)
    if (dist[v] <= R) members.push_back(uint32_t(v));
  std::vector<double> t_new(members.size(), std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> ring, seen(n, 0);
    std::vector<Vec3> pts;
    uint32_t stamp = 0;
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const uint32_t v = members[i];
      // Anchors: fresh vertices beyond the zone, within R + F rings of v.
      ++stamp;
      ring.assign(1, v);
      seen[v] = stamp;
      std::vector<uint32_t> level(1, v), nl;
      for (uint32_t d = 0; d < R + F; ++d) {
        nl.clear();
        for (uint32_t a : level)
          for (uint32_t k = off[a]; k < off[a + 1]; ++k) {
            const uint32_t w = adj[k];
            if (seg.region[w] >= 0 || seen[w] == stamp) continue;
            seen[w] = stamp;
            ring.push_back(w);
            nl.push_back(w);
          }
        level.swap(nl);
      }
      pts.clear();
      Vec3 outward = Vec3::Zero();
      for (uint32_t w : ring)
        if (dist[w] > R) {
          pts.push_back(x[w]);
          outward += out[w] - in[w];
        }
      if (pts.size() < 12) continue;
      const detail::Pca p = detail::pca(pts);
      Vec3 nn = p.normal.dot(outward) < 0 ? Vec3(-p.normal) : p.normal, u, w;
      u = nn.cross(std::abs(nn.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)).normalized();
      w = nn.cross(u);
      Eigen::MatrixXd A(pts.size(), 6);
      Eigen::VectorXd z(pts.size());
      for (size_t k = 0; k < pts.size(); ++k) {
        const Vec3 d = pts[k] - p.mean;
        const double a = u.dot(d), b = w.dot(d);
        A.row(Eigen::Index(k)) << a * a, a * b, b * b, a, b, 1;
        z(Eigen::Index(k)) = nn.dot(d);
      }
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
      if (qr.rank() < 6) continue;
      const Eigen::Matrix<double, 6, 1> q = qr.solve(z);
      const double res = std::sqrt((A * q - z).squaredNorm() / double(pts.size()));
      if (res > o.crease_residual) continue;
      const double tv = (x[v] - in[v]).dot(out[v] - in[v]);
      const double tc = quadric_exit(q, p.mean, u, w, nn, in[v], out[v], tv, -1, 2);
      if (std::isnan(tc)) continue;
      // The flat's plane (index space) and the rule between the two sides.
      const Flat& f = seg.flats[size_t(flat[v])];
      const double fi = f.index_normal.dot(in[v]) - f.index_offset, fo = f.index_normal.dot(out[v]) - f.index_offset;
      const double tf = fi >= 0 ? -kInf : fo <= 0 ? kInf : -fi / (fo - fi);
      const bool convex = f.index_normal.dot(p.mean) < f.index_offset;
      const double t = convex ? std::min(tc, tf) : std::max(tc, tf);
      t_new[i] = std::clamp(t, o.margin, 1 - o.margin);
    }
  });
  size_t moved = 0;
  for (size_t i = 0; i < members.size(); ++i) {
    if (std::isnan(t_new[i])) continue;
    const uint32_t v = members[i];
    s.t[v] = s.lower_inside(v) ? t_new[i] : 1 - t_new[i];
    if (zone) (*zone)[v] = 1;
    ++moved;
  }
  return moved;
}

}  // namespace voxpress
