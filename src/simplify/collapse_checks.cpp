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

// The floating-point slab test of a sweep: the tetrahedron (a, b, c, d)
// lies between the plane of (a, c, d) and b's offset from it (likewise for
// (b, c, d) and a); z beyond either slab by more than the rounding and
// `reach` is not in it.
bool in_slabs(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, double reach) {
  for (int k = 0; k < 2; ++k) {
    const Vec3& p = k == 0 ? a : b;
    const Vec3& other = k == 0 ? b : a;
    const Vec3 n = (c - p).cross(d - p);
    const double ln = n.norm(), s = n.dot(z - p), t = n.dot(other - p);
    const double e = ln * (1e-9 * ((z - p).norm() + (other - p).norm() + (c - p).norm() + (d - p).norm()) + reach);
    if (s < std::min(0.0, t) - e || s > std::max(0.0, t) + e) return false;
  }
  return true;
}

// Is z swept by the flat sweep of the triangle (a, c, d) whose corner a
// moves to b in its own plane? It covers only that plane: z counts within
// sqrt(reach2) of it (conservative).
bool swept_flat(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, double reach2) {
  if (!in_slabs(a, b, c, d, z, std::sqrt(reach2))) return false;
  return point_triangle_distance2(z, a, c, d) <= reach2 || point_triangle_distance2(z, b, c, d) <= reach2 ||
         point_triangle_distance2(z, a, b, c) <= reach2 || point_triangle_distance2(z, a, b, d) <= reach2;
}

// Where z lies against the tetrahedron (a, b, c, d) of orientation o != 0
// (exact): 0 outside, o strictly inside, 2 on its boundary.
int in_tetrahedron(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, int o) {
  if (!in_slabs(a, b, c, d, z, 0)) return 0;
  const int side = tetrahedron_side(a, b, c, d, z, o);
  return side < 0 ? 0 : side == 0 ? 2 : o;
}

// A triangle with what the clash test needs: corners, vertex ids, box
// (grown by the clearance), unit normal and its edges' outward in-plane
// unit normals.
struct ClashFace {
  Vec3 x[3];
  uint32_t id[3];
  Vec3 lo, hi, n, m[3];
  void prepare(double d) {
    lo = x[0].cwiseMin(x[1]).cwiseMin(x[2]).array() - d;
    hi = x[0].cwiseMax(x[1]).cwiseMax(x[2]).array() + d;
    n = (x[1] - x[0]).cross(x[2] - x[0]);
    const double l = n.norm();
    n = l > 0 ? Vec3(n / l) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      m[k] = (x[(k + 1) % 3] - x[k]).cross(n);  // outwards for a counter-clockwise triangle about n
      const double lm = m[k].norm();
      m[k] = lm > 0 ? Vec3(m[k] / lm) : Vec3::Zero();
    }
  }
  bool shares(uint32_t w) const { return w == id[0] || w == id[1] || w == id[2]; }
};

// Is there a plane with triangle a on one side and the corners of b that a
// does not share beyond it, each farther than 2d (d, and as much again for
// the rounding of the test)? The planes tried: a's own (either side) and
// the three through a's edges perpendicular to it (outwards), so coplanar
// neighbours on a flat are told apart too. When this holds both ways, b
// meets a only where they share and nothing else of either is within d of
// the other: triangles_clash need not run. Disjoint triangles need it one
// way only (any separating plane will do).
bool apart(const ClashFace& a, const ClashFace& b, double d) {
  int own[3], n = 0;
  for (int k = 0; k < 3; ++k)
    if (!a.shares(b.id[k])) own[n++] = k;
  if (n == 0 || a.n == Vec3::Zero()) return false;
  const auto beyond = [&](const Vec3& m, const Vec3& p, double sign) {
    for (int k = 0; k < n; ++k)
      if (sign * m.dot(b.x[own[k]] - p) <= 2 * d) return false;
    return true;
  };
  if (beyond(a.n, a.x[0], 1) || beyond(a.n, a.x[0], -1)) return true;
  for (int k = 0; k < 3; ++k)
    if (beyond(a.m[k], a.x[k], 1)) return true;
  return false;
}

}  // namespace

Collapser::Verdict Collapser::check(const Move& m, Probe& p) const {
  p.planar = false;
  if (!topology_ok(m.u, m.v, p)) return Verdict::topology;
  const Vec3 qi = m.q == xp[m.v] ? xi[m.v] : o.lattice ? o.lattice->to_index(m.q) : m.q;
  p.ring.clear();
  std::set_union(vf[m.u].begin(), vf[m.u].end(), vf[m.v].begin(), vf[m.v].end(), std::back_inserter(p.ring));
  if (!shape_ok(m, qi, p)) return Verdict::shape;
  if (!error_ok(m, p)) return Verdict::error;
  if (in_plane(m, qi, p)) return Verdict::ok;  // proven: no sample nor face can have come nearer
  if (!samples_ok(m, qi, p)) return Verdict::samples;
  if (!clash_free(m, qi, p)) return Verdict::clash;
  return Verdict::ok;
}

// Beyond Garland and Heckbert: a collapse inside one plane. When every
// vertex of the faces around u and v, and q, lies within kPlanar of one
// plane, and the faces are turned the same way about its normal before and
// after, the new fan covers exactly the region the old faces covered (the
// link condition makes that region a disk whose boundary, the edge's link,
// both fans share; positively turned triangles with that boundary cover
// each point of it once). No point of the surface moves farther than
// 2 kPlanar, so no sample changes side or comes nearer to the surface, and
// no face nearer to another, than it was: neither the samples' sweep nor
// the clash query is needed. kPlanar (delta / 1024) is well inside the
// factor 2 the clearance keeps spare (core/clearance.h). Most collapses of a CAD
// part's flats are such (`press --faces` on bench/compare's CAD part at
// 256^3: the stats' `in_plane`). The box of the new faces is still set
// (the round's overlap test reads it).
bool Collapser::in_plane(const Move& m, const Vec3& qi, Probe& p) const {
  if (o.junctions) return false;  // a shared surface: which label lies behind each part of the plane could change
  const double eps = delta / 1024;
  Vec3 n = Vec3::Zero(), a = Vec3::Zero();
  for (uint32_t f : p.ring) {
    if (p.is_shared(f)) continue;
    const Triangle& t = tri[f];
    n = (xi[t[1]] - xi[t[0]]).cross(xi[t[2]] - xi[t[0]]);
    a = xi[t[0]];
    break;
  }
  const double ln = n.norm();
  if (!(ln > 0)) return false;
  n /= ln;
  const auto off = [&](const Vec3& x) { return std::abs(n.dot(x - a)) > eps; };
  if (off(qi)) return false;
  for (uint32_t f : p.ring) {
    const Triangle& t = tri[f];
    if (off(xi[t[0]]) || off(xi[t[1]]) || off(xi[t[2]])) return false;
    if (!(n.dot((xi[t[1]] - xi[t[0]]).cross(xi[t[2]] - xi[t[0]])) > 0)) return false;
    if (p.is_shared(f)) continue;
    const Vec3 x0 = at_index(t[0], m, qi), x1 = at_index(t[1], m, qi), x2 = at_index(t[2], m, qi);
    if (!(n.dot((x1 - x0).cross(x2 - x0)) > 0)) return false;
  }
  p.lo = Vec3::Constant(INFINITY);
  p.hi = Vec3::Constant(-INFINITY);
  for (uint32_t f : p.ring) {
    if (p.is_shared(f)) continue;
    for (uint32_t w : tri[f]) {
      p.lo = p.lo.cwiseMin(at_index(w, m, qi));
      p.hi = p.hi.cwiseMax(at_index(w, m, qi));
    }
  }
  p.lo.array() -= delta;
  p.hi.array() += delta;
  p.planar = true;
  return true;
}

// The link condition (Dey et al.'s for 2-complexes: the links of u and v
// meet only in the link of the edge: their common neighbours are exactly
// the apexes of the edge's two faces, or of its three and more on a
// junction line, and no face of u spans two of them), no apex left with
// three neighbours, no component shrunk below a tetrahedron, no two
// feature edges merged.
bool Collapser::topology_ok(uint32_t u, uint32_t v, Probe& p) const {
  std::vector<uint32_t>& common = p.common;
  p.shared.clear();
  for (uint32_t f : vf[u])
    if (tri[f][0] == v || tri[f][1] == v || tri[f][2] == v) p.shared.push_back(f);
  if (p.shared.size() < 2) return false;
  neighbours(u, p.nu);
  neighbours(v, p.nv);
  common.clear();
  std::set_intersection(p.nu.begin(), p.nu.end(), p.nv.begin(), p.nv.end(), std::back_inserter(common));
  if (common.size() != p.shared.size() || p.nu.size() + p.nv.size() - 2 <= 4) return false;
  for (uint32_t f : p.shared) {  // the apexes are the common neighbours, once each
    const Triangle& t = tri[f];
    const uint32_t apex = t[0] != u && t[0] != v ? t[0] : t[1] != u && t[1] != v ? t[1] : t[2];
    if (!std::binary_search(common.begin(), common.end(), apex)) return false;
  }
  for (uint32_t w : common) {
    if (vf[w].size() <= 3) return false;
    const bool fu = feature.count(key(u, w)) != 0, fv = feature.count(key(v, w)) != 0;
    if (fu && fv) return false;
  }
  for (uint32_t f : vf[u]) {
    if (p.is_shared(f)) continue;
    int in_common = 0;
    for (uint32_t w : tri[f]) in_common += w != u && std::binary_search(common.begin(), common.end(), w);
    if (in_common == 2) return false;
  }
  return true;
}

bool Collapser::shape_ok(const Move& m, const Vec3& qi, const Probe& p) const {
  for (uint32_t f : p.ring) {
    if (p.is_shared(f)) continue;
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
bool Collapser::error_ok(const Move& m, Probe& pr) const {
  pr.assign.clear();
  if (!(o.max_error > 0)) return true;  // no bound: the error is measured once, at the end
  double move_error = 0;
  auto nearest = [&](const Vec3& p, uint32_t& best) {
    double d2 = INFINITY;
    for (uint32_t f : pr.ring) {
      if (pr.is_shared(f)) continue;
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
    pr.assign.emplace_back(p, f);
  };
  for (uint32_t f : pr.ring)
    for (uint32_t p : attached[f]) place(p);
  if (!moved[m.u]) place(m.u);
  if (!moved[m.v] && m.q != xp[m.v]) place(m.v);
  if (m.q != xp[m.v] && m.q != xp[m.u]) {
    double d2 = INFINITY;
    for (uint32_t f : pr.ring) {
      const Triangle& t = tri[f];
      d2 = std::min(d2, point_triangle_distance2(m.q, xp[t[0]], xp[t[1]], xp[t[2]]));
    }
    move_error = std::max(move_error, std::sqrt(d2));
  }
  return move_error <= o.max_error;
}

// No sample swept on the way (u to q, then v to q) nor within the
// clearance of a final face. Every lattice point is a sample (beyond the
// volume, an outside one), so where the volume ends does not matter.
bool Collapser::samples_ok(const Move& m, const Vec3& qi, Probe& p) const {
  if (!o.lattice) return true;
  const double d2 = delta * delta;
  constexpr double kKeySpan = double((int64_t(1) << 21) - 1);
  auto any = [&](std::initializer_list<Vec3> pts, auto&& hit) {
    Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
    for (const Vec3& x : pts) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    lo = (lo.array() - delta).ceil();
    hi = (hi.array() + delta).floor();
    if (((lo - key_base).array() < 0).any() || ((hi - key_base).array() >= kKeySpan).any())
      return true;  // past the keys' range: refused
    for (double z = lo.z(); z <= hi.z(); ++z)
      for (double y = lo.y(); y <= hi.y(); ++y)
        for (double x = lo.x(); x <= hi.x(); ++x)
          if (hit(Vec3(x, y, z))) return true;
    return false;
  };
  // A sample changes side iff the surface passes over it a net nonzero
  // number of times: a triangle with one moving corner sweeps its
  // tetrahedron once, with the sign of its orientation, so the sum over the
  // two moves' tetrahedra of the signed memberships is the change of the
  // sample's winding number (a sample swept forwards and back keeps its
  // side). On a shared surface the sum is taken per label pair (face
  // class): a sweep by an (a, b) face undone by a (b, c) face moves the
  // sample from label a to c (the 61-label map lost 1-2 samples per run to
  // that before). A sample on a tetrahedron's boundary, or near a flat
  // sweep, counts as changed (conservative).
  std::vector<std::tuple<uint64_t, uint32_t, int>>& hits = p.hits;
  hits.clear();
  const auto key = [&](const Vec3& z) {
    const Vec3 k = z - key_base;
    return (uint64_t(k.x()) << 42) | (uint64_t(k.y()) << 21) | uint64_t(k.z());
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
      const int sense = orient3d(a, qi, c, d);
      bool changed = false;
      if (sense == 0) {
        changed = any({a, qi, c, d}, [&](const Vec3& z) { return swept_flat(a, qi, c, d, z, d2); });
      } else {
        changed = any({a, qi, c, d}, [&](const Vec3& z) {
          const int in = in_tetrahedron(a, qi, c, d, z, sense);
          if (in == 2) return true;
          if (in != 0) hits.emplace_back(key(z), face_class.empty() ? 0 : face_class[f], in);
          return false;
        });
      }
      if (changed) return false;
    }
  }
  std::sort(hits.begin(), hits.end());
  const auto same = [](const auto& x, const auto& y) { return std::get<0>(x) == std::get<0>(y) && std::get<1>(x) == std::get<1>(y); };
  for (size_t i = 0, j = 0; i < hits.size(); i = j) {
    int net = 0;
    for (j = i; j < hits.size() && same(hits[j], hits[i]); ++j) net += std::get<2>(hits[j]);
    if (net != 0) return false;
  }
  for (uint32_t f : p.ring) {
    if (p.is_shared(f)) continue;
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
bool Collapser::clash_free(const Move& m, const Vec3& qi, Probe& p) const {
  ClashFace nf[64];
  int n = 0;
  Vec3& lo = p.lo;
  Vec3& hi = p.hi;
  lo = Vec3::Constant(INFINITY);
  hi = Vec3::Constant(-INFINITY);
  for (uint32_t f : p.ring) {
    if (p.is_shared(f)) continue;
    if (n == 64) return false;  // a vertex of over 60 faces: not worth the check
    ClashFace& g = nf[n++];
    for (int c = 0; c < 3; ++c) {
      const uint32_t w = tri[f][size_t(c)];
      g.x[c] = at_index(w, m, qi);
      g.id[c] = w == m.u ? m.v : w;
    }
    g.prepare(delta);
    lo = lo.cwiseMin(g.lo);
    hi = hi.cwiseMax(g.hi);
  }
  const auto overlap = [](const ClashFace& a, const Vec3& blo, const Vec3& bhi) {
    return !((a.lo.array() > bhi.array()).any() || (blo.array() > a.hi.array()).any());
  };
  const auto clash = [&](const ClashFace& a, const ClashFace& b) {
    // Disjoint triangles need one separating plane; sharing a vertex, both.
    const bool disjoint = !a.shares(b.id[0]) && !a.shares(b.id[1]) && !a.shares(b.id[2]);
    const bool ab = apart(a, b, delta);
    if (ab && disjoint) return false;
    if ((ab || disjoint) && apart(b, a, delta)) return false;
    return triangles_clash(a.x, a.id, b.x, b.id, delta);
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (overlap(nf[i], nf[j].lo, nf[j].hi) && clash(nf[i], nf[j])) return false;
  bool clashed = false;
  grid.query(lo, hi, [&](uint32_t g) {
    if (clashed || std::binary_search(p.ring.begin(), p.ring.end(), g)) return;
    const Triangle& t = tri[g];
    ClashFace c;
    for (int k = 0; k < 3; ++k) {
      c.x[k] = xi[t[size_t(k)]];
      c.id[k] = t[size_t(k)];
    }
    const Vec3 glo = c.x[0].cwiseMin(c.x[1]).cwiseMin(c.x[2]), ghi = c.x[0].cwiseMax(c.x[1]).cwiseMax(c.x[2]);
    bool ready = false;
    for (int i = 0; i < n && !clashed; ++i) {
      if (!overlap(nf[i], glo, ghi)) continue;
      if (!ready) c.prepare(0), ready = true;
      clashed = clash(nf[i], c);
    }
  });
  return !clashed;
}

}  // namespace voxpress::detail
