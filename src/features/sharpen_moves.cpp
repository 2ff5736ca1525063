// Sharpening: chamfer subdivision, the exactly checked move, the feature chains.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "feature_context.h"

namespace voxpress::sharpen_impl {

void Sharpener::subdivide() {
  std::unordered_map<uint64_t, uint32_t> on_edge;
  const double floor2 = 1 - std::cos(detail::kMinAngle * kPi / 180);
  auto edge_vertex = [&](uint32_t a, uint32_t b) {
    auto [it, fresh] = on_edge.try_emplace(edge_key(a, b), kNone);
    if (!fresh) return it->second;
    ++st.chamfer_edges;
    NewVertex v;
    v.a = std::min(a, b);
    v.b = std::max(a, b);
    const Vec3 xa = x[v.a], xb = x[v.b];
    const Plane* pa = plane_of(v.a);
    const Plane* pb = plane_of(v.b);
    v.on_flats = label[v.a] >= 0 && label[v.b] >= 0;
    double u = 0.5;
    Vec3 start = xa + u * (xb - xa);
    if (pa && pb) {
      const Plane pl[2] = {*pa, *pb};
      // Start where the edge comes closest to both planes (least squares in u).
      double num = 0, den = 0;
      for (const Plane& p : pl) {
        const double g = p.n.dot(xb - xa), h = p.c - p.n.dot(xa);
        num += g * h;
        den += g * g;
      }
      if (den > 1e-12) u = std::clamp(num / den, 0.1, 0.9);
      start = xa + u * (xb - xa);
      v.u = u;
      const double angle = angle_deg(pa->n, pb->n);
      v.angle = angle;
      v.sharp = angle >= o.sharp_angle;
      if (1 - pa->n.dot(pb->n) >= floor2) {
        v.target = solve_planes(pl, 2, start, floor2);
        const bool curved = label[v.a] < 0 && label[v.b] < 0;  // a curved/curved crease
        v.moves = (v.target - start).norm() <= (curved ? std::min(kCurvedCreaseMove, detail::kMaxMove) : detail::kMaxMove);
        if (v.moves && o.passes.on(Pass::sample_wedges)) v.moves = sample_wedge(v.a, v.b, *pa, *pb, start, floor2, v.target);
        v.along = pa->n.cross(pb->n).normalized();
      }
    }
    if (!v.moves) {
      v.target = start;
      ++st.fallbacks;
    }
    return it->second = add_vertex(v, start);
  };
  // Restricted (editable): the edges of the triangles that are not editable
  // get no vertex, so no triangle outside the part is split.
  std::vector<uint64_t> blocked;
  if (editable)
    for (size_t f = 0; f < s.triangles.size(); ++f)
      if (!(*editable)[f])
        for (int e = 0; e < 3; ++e) blocked.push_back(edge_key(s.triangles[f][size_t(e)], s.triangles[f][size_t((e + 1) % 3)]));
  std::sort(blocked.begin(), blocked.end());
  for (size_t f = 0; f < s.triangles.size(); ++f) {
    const Triangle& t = s.triangles[f];
    uint32_t m[3];
    int k = 0;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
      const bool open = blocked.empty() || !std::binary_search(blocked.begin(), blocked.end(), edge_key(a, b));
      m[e] = open && chamfer(a, b) ? edge_vertex(a, b) : kNone;
      k += m[e] != kNone;
    }
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
      tris.push_back({a, b, c});
      parent.push_back(uint32_t(f));
    };
    if (k == 0) {
      emit(t[0], t[1], t[2]);
      continue;
    }
    ++st.chamfer_triangles;
    if (k == 1) {  // Fig. 8a: two triangles
      const int e = m[0] != kNone ? 0 : m[1] != kNone ? 1 : 2;
      const uint32_t pa = t[size_t(e)], pb = t[size_t((e + 1) % 3)], pc = t[size_t((e + 2) % 3)];
      emit(pa, m[e], pc);
      emit(m[e], pb, pc);
    } else if (k == 2) {  // Fig. 8b: three triangles; the apex is where the two chamfer edges meet
      const int free_edge = m[0] == kNone ? 0 : m[1] == kNone ? 1 : 2;
      const int apex = (free_edge + 2) % 3;
      const uint32_t p0 = t[size_t(apex)], p1 = t[size_t((apex + 1) % 3)], p2 = t[size_t((apex + 2) % 3)];
      const uint32_t m01 = m[apex], m20 = m[(apex + 2) % 3];
      emit(p0, m01, m20);
      if ((x[m01] - x[p2]).squaredNorm() <= (x[p1] - x[m20]).squaredNorm()) {
        emit(m01, p1, p2);
        emit(m01, p2, m20);
      } else {
        emit(m01, p1, m20);
        emit(p1, p2, m20);
      }
      feature_edges.push_back({m01, m20});
    } else {  // Fig. 8c: six triangles around a corner vertex
      NewVertex c;
      c.corner = true;
      c.from = {m[0], m[1], m[2]};
      const Vec3 start = (x[m[0]] + x[m[1]] + x[m[2]]) / 3;
      const Plane* p[3] = {plane_of(t[0]), plane_of(t[1]), plane_of(t[2])};
      c.on_flats = label[t[0]] >= 0 && label[t[1]] >= 0 && label[t[2]] >= 0;
      c.target = start;
      if (p[0] && p[1] && p[2]) {
        const Plane pl[3] = {*p[0], *p[1], *p[2]};
        c.target = solve_planes(pl, 3, start, floor2);
        c.moves = (c.target - start).norm() <= detail::kMaxMove;
        if (!c.moves) c.target = start;
      }
      // Beyond the paper: where a corner's third plane is missing (a
      // curved junction without a fit of its own, squeezed between two
      // flats), it goes onto the line of the other two; left at the
      // centroid, its three labelled edges make a spur off the crease.
      // Where all three planes meet too far away it stays: the line of
      // two flats then runs on past the end of their crease.
      if (!c.moves && (p[0] != nullptr) + (p[1] != nullptr) + (p[2] != nullptr) == 2) {
        const int i = p[0] ? 0 : 1, j = p[2] ? 2 : 1;
        if (1 - std::abs(p[i]->n.dot(p[j]->n)) >= floor2) {
          const Plane pl[2] = {*p[i], *p[j]};
          const Vec3 q = solve_planes(pl, 2, start, floor2);
          if ((q - start).norm() <= detail::kMaxMove) {
            c.target = q;
            c.moves = true;
            c.on_flats = label[t[size_t(i)]] >= 0 && label[t[size_t(j)]] >= 0;
          }
        }
      }
      if (!c.moves) ++st.fallbacks;
      c.sharp = true;
      const uint32_t w = add_vertex(c, start);
      ++st.corners;
      for (int e = 0; e < 3; ++e) {
        emit(t[size_t(e)], m[e], w);
        emit(m[e], t[size_t((e + 1) % 3)], w);
        feature_edges.push_back({w, m[e]});
      }
    }
  }
  st.inserted = nv.size() - st.corners;
}

void Sharpener::index() {
  const size_t nvert = x.size();
  fan_off.assign(nvert + 1, 0);
  for (const Triangle& t : tris)
    for (uint32_t v : t) ++fan_off[v + 1];
  for (size_t v = 0; v < nvert; ++v) fan_off[v + 1] += fan_off[v];
  fan.resize(fan_off[nvert]);
  std::vector<uint32_t> fill(fan_off.begin(), fan_off.end() - 1);
  for (uint32_t f = 0; f < tris.size(); ++f)
    for (uint32_t v : tris[f]) fan[fill[v]++] = f;
  std::unordered_map<uint64_t, uint8_t> near;
  for (size_t f = 0; f < tris.size(); ++f) {
    bool touches_new = false;
    for (uint32_t v : tris[f]) touches_new |= v >= n;
    if (!touches_new) continue;
    const auto b = grid_cell(x[tris[f][0]], kNearBlock);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) near[bucket_key({b[0] + dx, b[1] + dy, b[2] + dz})] = 1;
  }
  anchor.resize(tris.size());
  anchor_reach = 0;
  for (uint32_t f = 0; f < tris.size(); ++f) {
    anchor[f] = x[tris[f][0]].cast<float>();
    const Vec3 a = anchor[f].cast<double>();
    if (!near.count(bucket_key(grid_cell(a, kNearBlock)))) continue;
    buckets[bucket_key(grid_cell(a, kBucket))].push_back(f);
    for (uint32_t v : tris[f]) anchor_reach = std::max(anchor_reach, (x[v] - a).cwiseAbs().maxCoeff());
  }
}

void Sharpener::widen(uint32_t v) {
  for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k)
    anchor_reach = std::max(anchor_reach, (x[v] - anchor[fan[k]].cast<double>()).cwiseAbs().maxCoeff());
}

bool Sharpener::allowed(uint32_t v, const Vec3& q) const {
  const Vec3 p = x[v];
  auto at = [&](uint32_t w) -> const Vec3& { return w == v ? q : x[w]; };
  Vec3 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
  for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k) {
    const Triangle& t = tris[fan[k]];
    const int i = t[0] == v ? 0 : t[1] == v ? 1 : 2;
    const Vec3& a = x[t[size_t((i + 1) % 3)]];
    const Vec3& b = x[t[size_t((i + 2) % 3)]];
    const Vec3 nn = (a - q).cross(b - q);
    if (!(nn.squaredNorm() > 1e-20) || nn.dot((a - p).cross(b - p)) <= 0) return false;  // turned over
    if (detail::triangle_too_thin(q, a, b, delta)) return false;
    lo = lo.cwiseMin(a).cwiseMin(b);
    hi = hi.cwiseMax(a).cwiseMax(b);
    // No lattice sample in the swept tetrahedron (p, q, a, b), nor within
    // the clearance of the moved triangle (q, a, b).
    const Vec3 tl = p.cwiseMin(q).cwiseMin(a).cwiseMin(b).array() - delta,
               th = p.cwiseMax(q).cwiseMax(a).cwiseMax(b).array() + delta;
    for (double zz = std::ceil(tl.z()); zz <= th.z(); ++zz)
      for (double yy = std::ceil(tl.y()); yy <= th.y(); ++yy)
        for (double xx = std::ceil(tl.x()); xx <= th.x(); ++xx) {
          const Vec3 z(xx, yy, zz);
          if (in_closed_tet(p, q, a, b, z) || detail::point_triangle_distance2(z, q, a, b) <= delta * delta)
            return false;
        }
  }
  lo.array() -= delta;
  hi.array() += delta;
  // The fan does not fold onto itself, and no refined triangle nearby meets
  // it or comes within the clearance (boxes farther apart are).
  auto too_close = [&](const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3]) {
    const Vec3 alo = ta[0].cwiseMin(ta[1]).cwiseMin(ta[2]), ahi = ta[0].cwiseMax(ta[1]).cwiseMax(ta[2]);
    const Vec3 blo = tb[0].cwiseMin(tb[1]).cwiseMin(tb[2]), bhi = tb[0].cwiseMax(tb[1]).cwiseMax(tb[2]);
    if ((alo.array() > bhi.array() + delta).any() || (blo.array() > ahi.array() + delta).any()) return false;
    return detail::triangles_clash(ta, ia, tb, ib, delta);
  };
  for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k)
    for (uint32_t k2 = k + 1; k2 < fan_off[v + 1]; ++k2) {
      const Triangle& t = tris[fan[k]];
      const Triangle& u = tris[fan[k2]];
      const Vec3 fb[3] = {at(t[0]), at(t[1]), at(t[2])};
      const Vec3 ub[3] = {at(u[0]), at(u[1]), at(u[2])};
      const uint32_t fi[3] = {t[0], t[1], t[2]}, ui[3] = {u[0], u[1], u[2]};
      if (too_close(fb, fi, ub, ui)) return false;
    }
  // A triangle meeting the box [lo, hi] has its anchor within anchor_reach
  // of it (plus a hair for the rounding of the differences).
  const Vec3 pad = Vec3::Constant(anchor_reach + 1e-6);
  const auto b0 = grid_cell(lo - pad, kBucket), b1 = grid_cell(hi + pad, kBucket);
  for (int64_t bz = b0[2]; bz <= b1[2]; ++bz)
    for (int64_t by = b0[1]; by <= b1[1]; ++by)
      for (int64_t bx = b0[0]; bx <= b1[0]; ++bx) {
        const auto it = buckets.find(bucket_key({bx, by, bz}));
        if (it == buckets.end()) continue;
        for (uint32_t g : it->second) {
          const Triangle& tg = tris[g];
          if (tg[0] == v || tg[1] == v || tg[2] == v) continue;
          const Vec3 gb[3] = {x[tg[0]], x[tg[1]], x[tg[2]]};
          const Vec3 glo = gb[0].cwiseMin(gb[1]).cwiseMin(gb[2]), ghi = gb[0].cwiseMax(gb[1]).cwiseMax(gb[2]);
          if ((glo.array() > hi.array()).any() || (ghi.array() < lo.array()).any()) continue;
          if (detail::triangle_degenerate(gb[0], gb[1], gb[2])) continue;
          const uint32_t gi[3] = {tg[0], tg[1], tg[2]};
          for (uint32_t k = fan_off[v]; k < fan_off[v + 1]; ++k) {
            const Triangle& t = tris[fan[k]];
            const Vec3 fb[3] = {at(t[0]), at(t[1]), at(t[2])};
            const uint32_t fi[3] = {t[0], t[1], t[2]};
            if (too_close(fb, fi, gb, gi)) return false;
          }
        }
      }
  return true;
}

bool Sharpener::move(uint32_t v, const Vec3& q, bool partial) {
  const Vec3 p = x[v];
  if (q == p) return true;
  if (v < n && fixed && (*fixed)[v]) return false;
  if (allowed(v, q)) {
    x[v] = q;
    widen(v);
    return true;
  }
  if (!partial) return false;
  ++st.cut_back;
  double lo = 0, hi = 1;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = (lo + hi) / 2;
    (allowed(v, p + mid * (q - p)) ? lo : hi) = mid;
  }
  if (lo > 0) {
    x[v] = p + lo * (q - p);
    widen(v);
  }
  return false;
}

void Sharpener::build_chains() {
  const size_t m = nv.size();
  chain_nb.assign(m, {kNone, kNone});
  chain_degree.assign(m, 0);
  for (const auto& e : feature_edges)
    for (int k = 0; k < 2; ++k) {
      const uint32_t a = e[size_t(k)] - uint32_t(n), b = e[size_t(1 - k)];
      if (chain_degree[a] < 2) chain_nb[a][chain_degree[a]] = b;
      ++chain_degree[a];
    }
}

void Sharpener::smooth_chains() {
  const size_t m = nv.size();
  std::vector<Vec3> L(m), step(m);
  for (int it = 0; it < detail::kChainIterations; ++it) {
    for (uint32_t i = 0; i < m; ++i)
      L[i] = inner(i) ? Vec3((x[chain_nb[i][0]] + x[chain_nb[i][1]]) / 2 - x[n + i]) : Vec3::Zero();
    for (uint32_t i = 0; i < m; ++i) {
      step[i].setZero();
      if (!inner(i)) continue;
      const NewVertex& v = nv[i];
      const int32_t ra = label[v.a], rb = label[v.b];
      if (ra >= 0 && rb >= 0) continue;  // on the exact line of two flats
      // -L^2 = L(v) - mean of the neighbours' L; 1/4 damps a zigzag in one step.
      Vec3 d = 0.25 * (L[i] - (L[chain_nb[i][0] - n] + L[chain_nb[i][1] - n]) / 2);
      const Vec3 tangent = (x[chain_nb[i][1]] - x[chain_nb[i][0]]).normalized();
      d -= d.dot(tangent) * tangent;
      if (ra >= 0 || rb >= 0) {
        const Vec3& fn = seg.flats[size_t(ra >= 0 ? ra : rb)].index_normal;
        d -= d.dot(fn) * fn;
      }
      step[i] = d;
    }
    for (uint32_t i = 0; i < m; ++i)
      if (step[i].squaredNorm() > 0) move(uint32_t(n + i), x[n + i] + step[i]);
  }
}

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t sharpen_step(FeatureContext& c) {
  sharpen_impl::Sharpener& sh = *c.sharpen;
  sh.subdivide();
  if (!sh.nv.empty()) sh.build_chains();
  return sh.st.inserted;
}

}  // namespace voxpress::detail
