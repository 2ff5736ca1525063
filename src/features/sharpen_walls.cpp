// Sharpening: thin walls (the walls pass). Theory of operation: sharpener.h
// and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "core/parallel.h"
#include "feature_context.h"

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

// fit_walls' last step: each fitted wall's vertices onto its plane, flat
// vertices whose stick leaves through it too.
void place_walls(Sharpener& sh, const Walls& W, const std::vector<Plane>& wall, const std::vector<uint8_t>& ok) {
  const size_t n = sh.n;
  const StickSurface& s = sh.s;
  const auto& adj_off = sh.adj_off;
  const auto& adj = sh.adj;
  auto& label = sh.label;
  auto& plane = sh.plane;
  const auto& pair = W.pair;
  const auto& cand = W.cand;
  enum : uint8_t { kUnplaced, kOnFlat, kOnWall };
  std::vector<uint8_t> placed(n, kUnplaced);
  auto make_wall = [&](uint32_t v, double t, const Plane& p) {
    sh.slide(v, t);
    label[v] = -1;
    sh.junction[v] = 1;
    plane[v] = p;
    sh.plane_state[v] = 1;
    placed[v] = kOnWall;
    sh.on_wall[v] = 1;
    ++sh.st.wall_vertices;
  };
  for (size_t k = 0; k < cand.size(); ++k) {
    const uint32_t v = cand[k];
    const auto [A, B] = pair[v];
    if (!ok[k]) continue;
    const double t = sh.stick_crossing(v, wall[k].n, wall[k].c);  // NaN unless crossed outwards
    if (between(sh, A, B, s.outside_sample(v))) {
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
      const double tc = sh.flat_crossing(v, f);
      if (tc > -Sharpener::kPastSample && tc < tf) tf = tc, first = f;
    }
    if (first < 0) {
      if (!std::isnan(t)) make_wall(v, t, wall[k]);
    } else if (Sharpener::on_stick(tf)) {
      sh.slide(v, tf);
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
    double t_first = sh.flat_crossing(v, f);
    if (std::isnan(t_first)) continue;
    uint32_t by = kNone;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      const uint32_t w = adj[k];
      if (placed[w] != kOnWall || (pair[w][0] != f && pair[w][1] != f)) continue;
      const double tw = sh.stick_crossing(v, plane[w].n, plane[w].c);
      if (tw > -Sharpener::kPastSample && tw < t_first) t_first = tw, by = w;
    }
    if (by != kNone) to_wall.push_back({v, by, t_first});
  }
  for (const ToWall& m : to_wall) make_wall(m.v, m.t, plane[m.by]);
  std::erase_if(sh.leftovers, [&](uint32_t v) { return placed[v] != kUnplaced; });
}

// Beyond the paper: thin walls. A plate a few cells thick has its rim
// between two nearly opposite flats; the rim's fresh vertices are all
// junctions with too few fresh neighbours for a plane of their own, so they
// joined the flats (join_leftovers), and the chamfer between two parallel
// planes has no line: one crease was labelled along the middle of the rim,
// a cell from both true edges (1002_tray_bottom at 256^3: none of its
// sharp length within half a voxel of a label). A fresh vertex reached,
// over fresh vertices, from members of two flats A, B whose normals are at
// least 170 degrees apart (a plate's faces; 150 also took fandisk's curved
// faces between its two nearly opposite sides), and lying between their
// planes at most `wall_thickness` cells apart, is on such a wall; beyond
// 12 cells the samples resolve the wall's own surface, and its 2-ring
// plane must be within 10 degrees of perpendicular to the flats (on
// fandisk's curved faces it is not: without this test a bound of 24 took
// them, r->t 0.0732 -> 0.0762 at 128^3). Its
// plane: the widest separator of the inside samples of the sticks of the
// wall vertices within 2 rings (over wall vertices) from those sticks'
// outside samples that lie between A's and B's planes (outside because of
// the wall, not of a flat): a maximum-margin line in the plane
// perpendicular to A's normal, searched over its angle, c in the middle of
// the margin (the centre of the feasible set, like the flats' centring).
// Where no line separates them (the rim turns: the tray's corners, small
// holes) the 1-ring's samples are used. The pressed rim is no guide:
// squeezed between the flats, its vertices sit up to a cell inside. The
// vertex then slides along its stick onto that plane when its own outside
// sample is between A and B, and becomes a curved junction whose plane is
// the wall's, so the chamfers on both sides cut along wall ∩ A and wall ∩
// B. Fixed 2- or 3-ring fits were measured worse than 1 ring (their
// infeasible fits left vertices out); 3 rings first, then 2 and 1, is no
// better than 2 then 1 (measured with `build/bench/bench_ablation --cases
// plate_holes.STL,thingi10k-65004.stl --passes walls`). Rim vertices on a flat's
// stick (its outside sample above a face) that joined a flat, and the
// flats' own vertices next to the wall, go where their stick first leaves
// the solid, through the wall or the flat; left on a flat mid-rim, they
// kinked it.
void fit_walls(Sharpener& sh) {
  std::vector<uint32_t> fresh;
  const std::vector<Near> near = flats_near(sh, fresh);
  const Walls W = wall_candidates(sh, fresh, near);
  std::vector<Plane> wall;
  std::vector<uint8_t> ok;
  fit_wall_planes(sh, W, wall, ok);
  place_walls(sh, W, wall, ok);
}

}  // namespace

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t walls_step(FeatureContext& c) {
  sharpen_impl::fit_walls(*c.sharpen);
  return c.sharpen->st.wall_vertices;
}

}  // namespace voxpress::detail
