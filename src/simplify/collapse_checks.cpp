// The checks that make every collapse a safe move (beyond Garland and
// Heckbert: their collapse keeps neither the samples' sides nor the mesh
// free of self-intersections). Cheapest first: topology, the faces' shape,
// the error, the samples, then the other faces nearby.
#include <algorithm>
#include <cmath>

#include "core/clearance.h"
#include "core/predicates.h"
#include "simplify/collapser.h"

namespace voxpress::detail {

namespace {

// A surviving face may turn by at most ~78 degrees in one collapse (the
// bound voxel art's simplifier used; a larger turn is a fold in the making).
constexpr double kMinNormalDot = 0.2;

// Is z swept by the triangle (a, c, d) while its corner a moves straight to
// b, i.e. in the closed tetrahedron (a, b, c, d)? A flat sweep covers only
// its plane: z counts within sqrt(reach2) of it (conservative).
bool swept(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, double reach2) {
  // First in floating point: the tetrahedron lies between the plane of
  // (a, c, d) and b's offset from it (likewise for (b, c, d) and a); z
  // beyond either slab by more than the rounding and the reach is not swept.
  const double reach = std::sqrt(reach2);
  for (int k = 0; k < 2; ++k) {
    const Vec3& p = k == 0 ? a : b;
    const Vec3& other = k == 0 ? b : a;
    const Vec3 n = (c - p).cross(d - p);
    const double ln = n.norm(), s = n.dot(z - p), t = n.dot(other - p);
    const double e = ln * (1e-9 * ((z - p).norm() + (other - p).norm() + (c - p).norm() + (d - p).norm()) + reach);
    if (s < std::min(0.0, t) - e || s > std::max(0.0, t) + e) return false;
  }
  const int o = orient3d(a, b, c, d);
  if (o != 0)
    return orient3d(z, b, c, d) * o >= 0 && orient3d(a, z, c, d) * o >= 0 && orient3d(a, b, z, d) * o >= 0 &&
           orient3d(a, b, c, z) * o >= 0;
  return point_triangle_distance2(z, a, c, d) <= reach2 || point_triangle_distance2(z, b, c, d) <= reach2 ||
         point_triangle_distance2(z, a, b, c) <= reach2 || point_triangle_distance2(z, a, b, d) <= reach2;
}

// Do the corners of b that a does not share lie on one side of a's plane,
// each farther than d from it? Then b meets a only where they share, and
// no part of b is within d of a beyond that: the exact test can be skipped
// when this holds both ways (2d: a margin for the rounding of the test).
bool beside(const Vec3 (&a)[3], const Vec3& na, const uint32_t (&ia)[3], const Vec3 (&b)[3], const uint32_t (&ib)[3],
            double d) {
  int side = 0;
  for (int k = 0; k < 3; ++k) {
    if (ib[k] == ia[0] || ib[k] == ia[1] || ib[k] == ia[2]) continue;
    const double h = na.dot(b[k] - a[0]);
    const int s = h > 2 * d ? 1 : h < -2 * d ? -1 : 0;
    if (s == 0 || (side != 0 && s != side)) return false;
    side = s;
  }
  return true;
}

Vec3 unit_normal(const Vec3 (&t)[3]) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double l = n.norm();
  return l > 0 ? Vec3(n / l) : Vec3::Zero();
}

void sorted_neighbours(const std::vector<std::vector<uint32_t>>& vf, const std::vector<Triangle>& tri, uint32_t v,
                       std::vector<uint32_t>& out) {
  out.clear();
  for (uint32_t f : vf[v])
    for (uint32_t w : tri[f])
      if (w != v) out.push_back(w);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace

bool Collapser::try_move(const Move& m) {
  if (!topology_ok(m.u, m.v)) {
    ++st.refused_topology;
    return false;
  }
  const Vec3 qi = m.q == xp[m.v] ? xi[m.v] : o.lattice ? o.lattice->to_index(m.q) : m.q;
  ring.clear();
  std::set_union(vf[m.u].begin(), vf[m.u].end(), vf[m.v].begin(), vf[m.v].end(), std::back_inserter(ring));
  if (!shape_ok(m, qi)) {
    ++st.refused_shape;
    return false;
  }
  if (!error_ok(m)) {
    ++st.refused_error;
    return false;
  }
  if (!samples_ok(m, qi)) {
    ++st.refused_samples;
    return false;
  }
  if (!clash_free(m, qi)) {
    ++st.refused_clash;
    return false;
  }
  return true;
}

// The link condition (the common neighbours of u and v are exactly the
// apexes of their two faces), no apex left with three neighbours, no
// component shrunk below a tetrahedron, no two feature edges merged.
bool Collapser::topology_ok(uint32_t u, uint32_t v) {
  shared.clear();
  for (uint32_t f : vf[u])
    if (tri[f][0] == v || tri[f][1] == v || tri[f][2] == v) shared.push_back(f);
  if (shared.size() != 2) return false;
  sorted_neighbours(vf, tri, u, nu);
  sorted_neighbours(vf, tri, v, nv_);
  common.clear();
  std::set_intersection(nu.begin(), nu.end(), nv_.begin(), nv_.end(), std::back_inserter(common));
  if (common.size() != 2 || nu.size() + nv_.size() - 2 <= 4) return false;
  for (uint32_t w : common) {
    if (vf[w].size() <= 3) return false;
    const bool fu = feature.count(key(u, w)) != 0, fv = feature.count(key(v, w)) != 0;
    if (fu && fv) return false;
  }
  return true;
}

bool Collapser::shape_ok(const Move& m, const Vec3& qi) {
  for (uint32_t f : ring) {
    if (f == shared[0] || f == shared[1]) continue;
    const Triangle& t = tri[f];
    const Vec3 n0 = (xp[t[1]] - xp[t[0]]).cross(xp[t[2]] - xp[t[0]]);
    const Vec3 a = at_phys(t[0], m), b = at_phys(t[1], m), c = at_phys(t[2], m);
    const Vec3 n1 = (b - a).cross(c - a);
    if (!(n1.dot(n0) > kMinNormalDot * n1.norm() * n0.norm())) return false;
    if (triangle_too_thin(at_index(t[0], m, qi), at_index(t[1], m, qi), at_index(t[2], m, qi), delta)) return false;
  }
  return true;
}

// Every input vertex gone from the patch (attached to its faces, or u, or
// v leaving its input position) goes to its nearest new face; the move's
// error is the largest of those distances and of q's to the old patch.
bool Collapser::error_ok(const Move& m) {
  assign.clear();
  move_error = 0;
  if (!(o.max_error > 0)) return true;  // no bound: the error is measured once, at the end
  auto nearest = [&](const Vec3& p, uint32_t& best) {
    double d2 = INFINITY;
    for (uint32_t f : ring) {
      if (f == shared[0] || f == shared[1]) continue;
      const Triangle& t = tri[f];
      const double e = point_triangle_distance2(p, at_phys(t[0], m), at_phys(t[1], m), at_phys(t[2], m));
      if (e < d2) {
        d2 = e;
        best = f;
      }
    }
    return d2;
  };
  auto place = [&](uint32_t p) {
    uint32_t f = 0;
    move_error = std::max(move_error, std::sqrt(nearest(input[p], f)));
    assign.emplace_back(p, f);
  };
  for (uint32_t f : ring)
    for (uint32_t p : attached[f]) place(p);
  if (!moved[m.u]) place(m.u);
  if (!moved[m.v] && m.q != xp[m.v]) place(m.v);
  if (m.q != xp[m.v] && m.q != xp[m.u]) {
    double d2 = INFINITY;
    for (uint32_t f : ring) {
      const Triangle& t = tri[f];
      d2 = std::min(d2, point_triangle_distance2(m.q, xp[t[0]], xp[t[1]], xp[t[2]]));
    }
    move_error = std::max(move_error, std::sqrt(d2));
  }
  return !(o.max_error > 0) || move_error <= o.max_error;
}

// No sample swept on the way (u to q, then v to q) nor within the
// clearance of a final face. Only samples that exist are checked: the
// lattice and its ring of virtual outside samples.
bool Collapser::samples_ok(const Move& m, const Vec3& qi) const {
  if (!o.lattice) return true;
  const double d2 = delta * delta;
  auto any = [&](std::initializer_list<Vec3> pts, auto&& hit) {
    Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
    for (const Vec3& p : pts) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    lo = (lo.array() - delta).ceil().max(sample_lo.array());
    hi = (hi.array() + delta).floor().min(sample_hi.array());
    for (double z = lo.z(); z <= hi.z(); ++z)
      for (double y = lo.y(); y <= hi.y(); ++y)
        for (double x = lo.x(); x <= hi.x(); ++x)
          if (hit(Vec3(x, y, z))) return true;
    return false;
  };
  const uint32_t movers[2] = {m.u, m.v};
  for (int k = 0; k < 2; ++k) {
    const uint32_t w = movers[k];
    const Vec3 a = xi[w];
    if (a == qi) continue;
    for (uint32_t f : vf[w]) {
      const Triangle& t = tri[f];
      const int i = t[0] == w ? 0 : t[1] == w ? 1 : 2;
      // During the second move, u already sits at q.
      const auto corner = [&](uint32_t x) { return k == 1 && x == m.u ? qi : xi[x]; };
      const Vec3 c = corner(t[size_t((i + 1) % 3)]), d = corner(t[size_t((i + 2) % 3)]);
      if (c == qi || d == qi) continue;  // the face shrinks onto its own edge: it sweeps only itself
      if (any({a, qi, c, d}, [&](const Vec3& z) { return swept(a, qi, c, d, z, d2); })) return false;
    }
  }
  for (uint32_t f : ring) {
    if (f == shared[0] || f == shared[1]) continue;
    const Triangle& t = tri[f];
    const Vec3 a = at_index(t[0], m, qi), b = at_index(t[1], m, qi), c = at_index(t[2], m, qi);
    const Vec3 n = (b - a).cross(c - a).normalized();  // shape_ok: not degenerate
    const auto near = [&](const Vec3& z) {
      const double h = n.dot(z - a);
      return h * h <= 4 * d2 && point_triangle_distance2(z, a, b, c) <= d2;  // off its plane by 2 delta: not near
    };
    if (any({a, b, c}, near)) return false;
  }
  return true;
}

// The new faces neither meet nor come within the clearance of each other or
// of any other face.
bool Collapser::clash_free(const Move& m, const Vec3& qi) const {
  struct Face {
    Vec3 x[3];
    uint32_t id[3];
    Vec3 lo, hi, n;
  };
  Face nf[64];
  int n = 0;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (uint32_t f : ring) {
    if (f == shared[0] || f == shared[1]) continue;
    if (n == 64) return false;  // a vertex of over 60 faces: not worth the check
    Face& g = nf[n++];
    for (int c = 0; c < 3; ++c) {
      const uint32_t w = tri[f][size_t(c)];
      g.x[c] = at_index(w, m, qi);
      g.id[c] = w == m.u ? m.v : w;
    }
    g.n = unit_normal(g.x);
    g.lo = g.x[0].cwiseMin(g.x[1]).cwiseMin(g.x[2]).array() - delta;
    g.hi = g.x[0].cwiseMax(g.x[1]).cwiseMax(g.x[2]).array() + delta;
    lo = lo.cwiseMin(g.lo);
    hi = hi.cwiseMax(g.hi);
  }
  const auto overlap = [](const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
    return !((alo.array() > bhi.array()).any() || (blo.array() > ahi.array()).any());
  };
  const auto clash = [&](const Face& a, const Vec3 (&bx)[3], const uint32_t (&bi)[3], const Vec3& bn) {
    if (beside(a.x, a.n, a.id, bx, bi, delta) && beside(bx, bn, bi, a.x, a.id, delta)) return false;
    return triangles_clash(a.x, a.id, bx, bi, delta);
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (overlap(nf[i].lo, nf[i].hi, nf[j].lo, nf[j].hi) && clash(nf[i], nf[j].x, nf[j].id, nf[j].n)) return false;
  bool clashed = false;
  grid.query(lo, hi, [&](uint32_t g) {
    if (clashed || std::binary_search(ring.begin(), ring.end(), g)) return;
    const Triangle& t = tri[g];
    const Vec3 gx[3] = {xi[t[0]], xi[t[1]], xi[t[2]]};
    const uint32_t gi[3] = {t[0], t[1], t[2]};
    const Vec3 glo = gx[0].cwiseMin(gx[1]).cwiseMin(gx[2]), ghi = gx[0].cwiseMax(gx[1]).cwiseMax(gx[2]);
    Vec3 gn = Vec3::Zero();
    for (int i = 0; i < n && !clashed; ++i) {
      if (!overlap(nf[i].lo, nf[i].hi, glo, ghi)) continue;
      if (gn == Vec3::Zero()) gn = unit_normal(gx);
      clashed = clash(nf[i], gx, gi, gn);
    }
  });
  return !clashed;
}

}  // namespace voxpress::detail
