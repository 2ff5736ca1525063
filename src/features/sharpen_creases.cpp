// Sharpening: thin walls, the final crease fit, vertices past their crease, curved creases.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "feature_context.h"
#include "core/parallel.h"

namespace voxpress::sharpen_impl {

// Candidates of a wall: fresh vertices between two opposite flats, and the
// pair of flats of each vertex ({-1, -1} for the others).
struct Walls {
  std::vector<std::array<int32_t, 2>> pair;
  std::vector<uint32_t> cand;
};

namespace {

constexpr uint32_t kWallFitRings = 2;
constexpr double kResolvedWall = 12;  // cells
constexpr double kFlatGap = 0.1;      // cells: a fitted flat's plane may be this far off near its rim

// The flats (up to kNear, smallest ids) that reach a fresh vertex, each
// with the ring it first arrived at.
constexpr size_t kNear = 4;
struct Reach {
  int32_t flat = -1, ring = 0;
  bool operator==(const Reach&) const = default;
};
using Near = std::array<Reach, kNear>;
void add(Near& a, Reach r) {
  for (Reach& g : a) {
    if (g.flat == r.flat) {
      g.ring = std::min(g.ring, r.ring);
      return;
    }
    if (g.flat < 0 || r.flat < g.flat) std::swap(g, r);
    if (r.flat < 0) return;
  }
}

// The flats that reach each fresh vertex over fresh vertices within
// wall_thickness + 2 rings. Jacobi rounds, so the result does not depend on
// the visiting order; each round recomputes only the fresh neighbours of
// the vertices the last round changed (an organic shape's fresh vertices
// far from any flat are never visited).
std::vector<Near> flats_near(const Sharpener& sh, std::vector<uint32_t>& fresh) {
  const auto& region = sh.seg.region;
  const auto &adj_off = sh.adj_off, &adj = sh.adj;
  std::vector<Near> near(sh.n);
  std::vector<uint32_t> changed, todo;
  for (uint32_t v = 0; v < sh.n; ++v)
    if (region[v] < 0) {
      fresh.push_back(v);
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
        if (region[adj[k]] >= 0) add(near[v], {region[adj[k]], 1});
      if (near[v][0].flat >= 0) changed.push_back(v);
    }
  std::vector<uint32_t> queued(sh.n, detail::kUnreached);
  std::vector<Near> next;
  for (uint32_t round = 0; round < uint32_t(std::ceil(detail::kWallThickness)) + 1 && !changed.empty(); ++round) {
    todo.clear();
    for (uint32_t v : changed)
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
        const uint32_t w = adj[k];
        if (region[w] < 0 && queued[w] != round) {
          queued[w] = round;
          todo.push_back(w);
        }
      }
    std::sort(todo.begin(), todo.end());
    next.resize(todo.size());
    for (size_t i = 0; i < todo.size(); ++i) {
      const uint32_t v = todo[i];
      next[i] = near[v];
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
        if (region[adj[k]] < 0)
          for (const Reach& r : near[adj[k]])
            if (r.flat >= 0) add(next[i], {r.flat, r.ring + 1});
    }
    changed.clear();
    for (size_t i = 0; i < todo.size(); ++i)
      if (next[i] != near[todo[i]]) {
        near[todo[i]] = next[i];
        changed.push_back(todo[i]);
      }
  }
  return near;
}

// The fresh vertices between the planes of two opposite flats that reach
// them, across the wall from both.
Walls wall_candidates(const Sharpener& sh, const std::vector<uint32_t>& fresh, const std::vector<Near>& near) {
  const double opposite = std::cos(170 * kPi / 180), kWallLean = std::sin(10 * kPi / 180);
  Walls W;
  W.pair.assign(sh.n, {-1, -1});
  for (uint32_t v : fresh) {
    const Near& a = near[v];
    for (size_t i = 0; i < kNear && a[i].flat >= 0 && W.pair[v][0] < 0; ++i)
      for (size_t j = i + 1; j < kNear && a[j].flat >= 0; ++j) {
        const Flat &fa = sh.seg.flats[size_t(a[i].flat)], &fb = sh.seg.flats[size_t(a[j].flat)];
        const double ha = sh.height(a[i].flat, sh.x[v]) / fa.index_normal.norm(),
                     hb = sh.height(a[j].flat, sh.x[v]) / fb.index_normal.norm(), thickness = -(ha + hb);
        const Vec3 na = fa.index_normal.normalized();
        // Between the two planes, and across the wall from both flats (a
        // rim is crossed in about as many rings as it has cells, plus the
        // rings the flats' rims stop short of the creases).
        if (!(na.dot(fb.index_normal.normalized()) <= opposite && ha < 0.5 && hb < 0.5 &&
              thickness <= detail::kWallThickness && std::max(a[i].ring, a[j].ring) <= 1.5 * thickness + 4))
          continue;
        Plane own;
        if (thickness > kResolvedWall && !(sh.ring_plane(v, own) && std::abs(own.n.normalized().dot(na)) < kWallLean))
          continue;
        W.pair[v] = {a[i].flat, a[j].flat};
        W.cand.push_back(v);
        break;
      }
  }
  return W;
}

// An outside sample between A's and B's planes (by more than `gap` cells)
// is outside because of the wall, not of a flat.
bool between(const Sharpener& sh, int32_t A, int32_t B, const Vec3& p, double gap = 0) {
  return sh.height(A, p) < -gap * sh.seg.flats[size_t(A)].index_normal.norm() &&
         sh.height(B, p) < -gap * sh.seg.flats[size_t(B)].index_normal.norm();
}

// Each candidate's wall plane: the line (in the plane of A's normal's
// frame) separating the inside samples of its rings from the outside
// samples between the flats with the widest margin; `ok` 0 where none does.
void fit_wall_planes(const Sharpener& sh, const Walls& W, std::vector<Plane>& wall, std::vector<uint8_t>& ok) {
  wall.assign(W.cand.size(), Plane{});
  ok.assign(W.cand.size(), 0);
  tbb::enumerable_thread_specific<detail::RingScratch> scratch;
  detail::parallel_for(W.cand.size(), [&](size_t k) {
    const uint32_t v = W.cand[k];
    const auto [A, B] = W.pair[v];
    const Vec3 na = sh.seg.flats[size_t(A)].index_normal.normalized();
    const Vec3 u = na.cross(std::abs(na.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)).normalized(), w = na.cross(u);
    std::vector<Eigen::Vector2d> in, out;
    double lo = 0, hi = 0;
    auto margin = [&](double a) {
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      lo = -INFINITY;
      hi = INFINITY;
      for (const auto& p : in) lo = std::max(lo, d.dot(p));
      for (const auto& p : out) hi = std::min(hi, d.dot(p));
      return hi - lo;
    };
    detail::RingScratch& rs = scratch.local();
    // (rings, gap) tried in turn; the gap only for a vertex that joined a
    // flat (a strip or leftover vertex mid-rim: otherwise a kink).
    constexpr std::pair<uint32_t, double> kAttempts[] = {
        {kWallFitRings, 0.0}, {1, 0.0}, {kWallFitRings, kFlatGap}, {1, kFlatGap}};
    for (const auto& [rings_fit, gap] : kAttempts) {
      if (gap > 0 && sh.label[v] < 0) break;
      in.clear();
      out.clear();
      detail::rings_around(v, rings_fit, sh.adj_off, sh.adj, [&](uint32_t q) { return W.pair[q] == W.pair[v]; }, rs);
      for (const auto& [q, d] : rs.out) {
        const Vec3 pi = sh.s.inside_sample(q), po = sh.s.outside_sample(q);
        in.emplace_back(u.dot(pi), w.dot(pi));
        if (between(sh, A, B, po, gap)) out.emplace_back(u.dot(po), w.dot(po));
      }
      if (in.size() < 3 || out.size() < 3) continue;
      double best = -INFINITY, best_a = 0;
      for (int i = 0; i < 180; ++i) {  // every 2 degrees, then halving steps
        const double a = 2 * kPi * i / 180, m = margin(a);
        if (m > best) best = m, best_a = a;
      }
      for (double step = kPi / 180; step > 1e-4; step /= 2)
        for (const double a : {best_a - step, best_a + step}) {
          const double m = margin(a);
          if (m > best) best = m, best_a = a;
        }
      if (!(best > 0)) continue;  // no line separates them: the rim turns here
      margin(best_a);
      wall[k] = {std::cos(best_a) * u + std::sin(best_a) * w, 0.5 * (lo + hi)};
      ok[k] = 1;
      return;
    }
  });
}

}  // namespace

void Sharpener::fit_walls() {
  std::vector<uint32_t> fresh;
  const std::vector<Near> near = flats_near(*this, fresh);
  const Walls W = wall_candidates(*this, fresh, near);
  std::vector<Plane> wall;
  std::vector<uint8_t> ok;
  fit_wall_planes(*this, W, wall, ok);
  place_walls(W, wall, ok);
}

void Sharpener::place_walls(const Walls& W, const std::vector<Plane>& wall, const std::vector<uint8_t>& ok) {
  const auto& pair = W.pair;
  const auto& cand = W.cand;
  enum : uint8_t { kUnplaced, kOnFlat, kOnWall };
  std::vector<uint8_t> placed(n, kUnplaced);
  auto make_wall = [&](uint32_t v, double t, const Plane& p) {
    slide(v, t);
    label[v] = -1;
    junction[v] = 1;
    plane[v] = p;
    plane_state[v] = 1;
    placed[v] = kOnWall;
    on_wall[v] = 1;
    ++st.wall_vertices;
  };
  for (size_t k = 0; k < cand.size(); ++k) {
    const uint32_t v = cand[k];
    const auto [A, B] = pair[v];
    if (!ok[k]) continue;
    const double t = stick_crossing(v, wall[k].n, wall[k].c);  // NaN unless crossed outwards
    if (between(*this, A, B, s.outside_sample(v))) {
      if (!std::isnan(t)) make_wall(v, t, wall[k]);
      continue;
    }
    // A flat's stick. A vertex that joined a flat mid-rim (a strip or
    // leftover; left there, the rim kinks) goes where its stick first
    // leaves the solid: through the wall's plane or a flat's. Other
    // curved vertices stay: at a rounded edge neither plane bounds the
    // solid (plate_holes.STL at 256^3: moved onto a flat's plane, 0.8
    // voxel out).
    if (label[v] < 0) continue;
    int32_t first = -1;
    double tf = std::isnan(t) ? INFINITY : t;
    for (const int32_t f : {A, B}) {
      const double tc = flat_crossing(v, f);
      if (tc > -kPastSample && tc < tf) tf = tc, first = f;
    }
    if (first < 0) {
      if (!std::isnan(t)) make_wall(v, t, wall[k]);
    } else if (on_stick(tf)) {
      slide(v, tf);
      label[v] = first;
      placed[v] = kOnFlat;
    }
  }
  // A flat's vertex (frozen or joined) next to a wall vertex of that flat
  // whose stick crosses the wall's plane before its flat's: the surface
  // leaves the solid through the wall, and the flat's plane there lies
  // beyond the rim (up to 0.6 voxel out on examples/plate.obj at 64^3).
  // Decided from the walls above only, so the order does not matter.
  struct ToWall {
    uint32_t v, by;  // by: the wall vertex whose plane v takes
    double t;
  };
  std::vector<ToWall> to_wall;
  for (uint32_t v = 0; v < n; ++v) {
    const int32_t f = label[v];
    if (f < 0 || placed[v] != kUnplaced) continue;
    double t_first = flat_crossing(v, f);
    if (std::isnan(t_first)) continue;
    uint32_t by = kNone;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      const uint32_t w = adj[k];
      if (placed[w] != kOnWall || (pair[w][0] != f && pair[w][1] != f)) continue;
      const double tw = stick_crossing(v, plane[w].n, plane[w].c);
      if (tw > -kPastSample && tw < t_first) t_first = tw, by = w;
    }
    if (by != kNone) to_wall.push_back({v, by, t_first});
  }
  for (const ToWall& m : to_wall) make_wall(m.v, m.t, plane[m.by]);
  std::erase_if(leftovers, [&](uint32_t v) { return placed[v] != kUnplaced; });
}


uint32_t Sharpener::add_vertex(const NewVertex& v, const Vec3& at) {
  nv.push_back(v);
  x.push_back(at);
  return uint32_t(n + nv.size() - 1);
}

void Sharpener::final_crease_fit() {
  const detail::CreaseFit c{.rings = detail::kFinalCreaseRings,
                            .fit_rings = detail::kFinalCreaseFitRings,
                            .residual = detail::kFinalCreaseResidual,
                            .margin = o.margin,
                            .max_move = detail::kFinalCreaseMaxMove};
  for (const auto& [v, t] : detail::crease_targets(s, seg.flats, label, junction, x, adj_off, adj, c)) {
    slide(v, t);
    ++st.final_crease_vertices;
  }
}

int Sharpener::crease_kind_near(uint32_t v, int32_t f, std::vector<uint32_t>& ring) const {
  size_t below = 0, above = 0;
  ring.assign(1, v);
  detail::grow_rings(ring, 2, adj_off, adj);
  for (uint32_t w : ring)
    if (label[w] < 0 && !junction[w]) (height(f, x[w]) < 0 ? below : above) += 1;
  return below > 0 && below >= 3 * above ? 1 : above > 0 && above >= 3 * below ? -1 : 0;
}

void Sharpener::past_creases() {
  struct Move {
    uint32_t v;
    int32_t label;  // the flat it joins, or -1 (it leaves its flat)
    double t;       // where on its stick it goes (NaN: it stays where it is)
  };
  std::vector<Move> moves;
  std::vector<uint32_t> ring;
  for (uint32_t v = 0; v < n; ++v) {
    if (label[v] < 0 && junction[v]) {  // a curved junction: past the crease on the flat?
      double best;
      const int32_t f = nearest_neighbour_flat(v, best);
      if (f < 0) continue;
      const double tf = flat_crossing(v, f);
      const bool crossed = on_stick(tf);
      if (!crossed && best > kPastSample) continue;
      Plane side;  // uncached (plane_of's cache would keep curved_creases from setting it)
      if (!tangent_plane(v, side)) continue;
      const int kind = crease_kind_near(v, f, ring);
      if (crossed) {
        const double tc = leaves_at(v, side);
        if ((kind > 0 && tf < tc) || (kind < 0 && tf > tc)) moves.push_back({v, f, tf});
      } else {
        const double hc = side.n.dot(x[v]) - side.c;  // on the flat's plane already: where is the side's?
        if ((kind > 0 && hc < -kPastSample) || (kind < 0 && hc > kPastSample)) moves.push_back({v, f, NAN});
      }
    } else if (const int32_t f = label[v]; f >= 0) {  // a member: past the crease on the curved face?
      uint32_t w = kNone;  // its nearest curved junction neighbour
      double d2 = INFINITY;
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
        if (const uint32_t q = adj[k]; label[q] < 0 && junction[q] && (x[q] - x[v]).squaredNorm() < d2)
          d2 = (x[q] - x[v]).squaredNorm(), w = q;
      if (w == kNone) continue;
      Plane side;
      if (!tangent_plane(w, side) || angle_deg(side.n, seg.flats[size_t(f)].index_normal) < o.sharp_angle) continue;
      const int kind = crease_kind_near(v, f, ring);
      const double tf = flat_crossing(v, f), tc = stick_crossing(v, side.n, side.c);
      if (!on_stick(tc) || !std::isfinite(tf)) continue;
      if ((kind > 0 && tc < tf - kLeaveMargin) || (kind < 0 && tc > tf + kLeaveMargin)) moves.push_back({v, -1, tc});
    }
  }
  for (const Move& m : moves) {
    if (std::isfinite(m.t)) slide(m.v, m.t);
    label[m.v] = m.label;
    if (m.label >= 0) {
      ++st.past_crease;
    } else {
      junction[m.v] = 1;
      ++st.left_flat;
    }
  }
  for (const Move& m : moves)
    if (m.label >= 0)
      for (uint32_t k = adj_off[m.v]; k < adj_off[m.v + 1]; ++k)
        if (label[adj[k]] < 0) junction[adj[k]] = 1;
}

void Sharpener::curved_creases() {
  detail::CurvedCreaseFit c;
  c.sharp_angle = o.sharp_angle;
  c.margin = o.margin;
  c.network = o.passes.on(Pass::crease_network);
  // A thin wall's vertices are junctions on their wall's fitted plane, a
  // face of their own: they stay, but are the wall's side of a crease
  // with a curved face (without its vertices the 2-means sees one side
  // only, and a wall's steep crease with a curved face goes unlabelled).
  std::vector<uint8_t> role(n);
  for (size_t v = 0; v < n; ++v)
    role[v] = !junction[v] ? detail::kCreaseFree : on_wall[v] ? detail::kCreaseSide : detail::kCreaseSkip;
  std::vector<Vec3> normal;
  const auto found =
      detail::curved_crease_targets(s, label, role, x, adj_off, adj, c, &normal, &st.passes.count[size_t(Pass::crease_network)]);
  for (const auto& f : found) {
    slide(f.v, f.t);
    if (plane_state[f.v] != 0) continue;
    crease_side[f.v] = 1;
    plane[f.v] = f.chosen;
    plane_state[f.v] = 1;
  }
  st.curved_crease_vertices = found.size();
  for (const auto& f : found) {
    const uint32_t v = f.v;
    if (crease_side[v] != 1) continue;
    const Vec3 mine = physical_normal(f.chosen.n), theirs = physical_normal(f.other.n);
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      const uint32_t w = adj[k];
      if (label[w] >= 0 || junction[w] || plane_state[w] != 0) continue;
      if (normal[w].dot(theirs) > normal[w].dot(mine)) {
        crease_side[w] = 2;
        plane[w] = f.other;
        plane_state[w] = 1;
      }
    }
  }
}

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t walls_step(FeatureContext& c) {
  c.sharpen->fit_walls();
  return c.sharpen->st.wall_vertices;
}

size_t final_crease_step(FeatureContext& c) {
  c.sharpen->final_crease_fit();
  return c.sharpen->st.final_crease_vertices;
}

size_t past_crease_step(FeatureContext& c) {
  c.sharpen->past_creases();
  return c.sharpen->st.past_crease + c.sharpen->st.left_flat;
}

size_t final_curved_creases_step(FeatureContext& c) {
  c.sharpen->curved_creases();
  return c.sharpen->st.curved_crease_vertices;
}

}  // namespace voxpress::detail
