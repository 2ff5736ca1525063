// The simplifier: state, the order of the collapses, and the output
// (Garland and Heckbert 1997 for the quadrics and the order; the checks are
// in collapse_checks.cpp).
#include "simplify/collapser.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <chrono>
#include <cmath>
#include <queue>
#include <stdexcept>

#include "core/clearance.h"
#include "core/timing.h"
#include "eval/mesh_query.h"
#include "core/parallel.h"

namespace voxpress::detail {

namespace {

// Edge lengths: the quadric's minimiser is used only within this many of
// the edge's midpoint (farther means the quadric is nearly singular along
// the move; the endpoints are then the candidates).
constexpr double kOptimumReach = 2;
// The face grid's cell in mean face extents: fewer, fuller cells (the
// query is bound by cache misses per cell; build/bench/bench_simplify).
constexpr double kGridCell = 2;
// A round checks at most kRound moves in parallel, looking at most kLook
// times as many heap entries for them: rounds of a few hundred keep the
// cost order nearly serial and the threads busy (build/bench/bench_simplify).
constexpr uint64_t kRound = 256;
constexpr size_t kLook = 4;
// How far a refused collapse's q is lifted off the surface, in cells: a
// quarter of the band between the samples (build/bench/bench_simplify
// --shape sphere: the floor of the face count).
constexpr double kLift = 0.25;

}  // namespace

Collapser::Collapser(Mesh& m, const SimplifyOptions& opt)
    : mesh(m), o(opt), tri(m.triangles) {}

void Collapser::build() {
  const size_t nv = mesh.positions.size(), nf = tri.size();
  xp = mesh.positions;
  input = mesh.positions;
  xi.resize(nv);
  double reach = 0;
  for (size_t v = 0; v < nv; ++v) {
    xi[v] = o.lattice ? o.lattice->to_index(xp[v]) : xp[v];
    reach = std::max(reach, xp[v].cwiseAbs().maxCoeff());
  }
  if (o.lattice) {
    // Everything relative to the mesh's own box, not the lattice's extent,
    // so that a shifted, padded or cropped volume simplifies alike (issue
    // 74, item 2): the clearance covers the rounding of the coordinates
    // the mesh has (and 2 cells around), and every lattice point is a
    // sample (beyond the volume, outside ones), keyed from the box's corner.
    Vec3 lo = nv ? xi[0] : Vec3::Zero();
    for (const Vec3& x : xi) lo = lo.cwiseMin(x);
    key_base = lo.array().floor() - double(kKeyRoom);
    delta = float32_clearance_around(*o.lattice, xi);
  } else {
    delta = 4 * std::ldexp(std::max(reach, 1.0), -24);  // float32 rounding of the largest coordinate, 4x as in clearance.h
  }
  vf.assign(nv, {});
  for (uint32_t f = 0; f < nf; ++f)
    for (uint32_t v : tri[f]) vf[v].push_back(f);
  face_alive.assign(nf, 1);
  vertex_alive.assign(nv, 1);
  moved.assign(nv, 0);
  stamp.assign(nv, 0);
  attached.assign(nf, {});
  alive_faces = nf;

  // Edges from sorted half-edges: each must have two faces in opposite
  // directions (a closed, oriented 2-manifold) or, with junctions, three
  // or more (a junction line of a shared surface: a feature edge).
  struct Half {
    uint64_t key;
    uint32_t face;
    bool forward;
  };
  std::vector<Half> he;
  he.reserve(3 * nf);
  for (uint32_t f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = tri[f][size_t(c)], b = tri[f][size_t((c + 1) % 3)];
      he.push_back({key(a, b), f, a < b});
    }
  std::sort(he.begin(), he.end(), [](const Half& x, const Half& y) { return std::tie(x.key, x.face) < std::tie(y.key, y.face); });
  std::vector<uint64_t> edges;
  for (size_t i = 0, j = 0; i < he.size(); i = j) {
    while (j < he.size() && he[j].key == he[i].key) ++j;
    const size_t k = j - i;
    if (k < 2 || (k == 2 && he[i].forward == he[i + 1].forward) || (k > 2 && !o.junctions))
      throw std::invalid_argument(o.junctions ? "simplify: the surface has an open or misoriented edge"
                                              : "simplify: the mesh is not a closed, oriented 2-manifold");
    edges.push_back(he[i].key);
    bool hard = k > 2;
    for (const MeshAttribute& at : mesh.face_attributes)
      for (size_t h = i + 1; h < j; ++h) hard |= at.values[he[h].face] != at.values[he[i].face];
    if (hard) feature[he[i].key] |= kBorder;
  }
  he = {};
  if (o.junctions) {  // the face classes: one per distinct tuple of face attributes
    std::map<std::vector<double>, uint32_t> classes;
    std::vector<double> tuple(mesh.face_attributes.size());
    face_class.resize(nf);
    for (uint32_t f = 0; f < nf; ++f) {
      for (size_t k = 0; k < tuple.size(); ++k) tuple[k] = mesh.face_attributes[k].values[f];
      face_class[f] = classes.try_emplace(tuple, uint32_t(classes.size())).first->second;
    }
  }
  for (const auto& e : mesh.edges) {
    const auto it = std::lower_bound(edges.begin(), edges.end(), key(e[0], e[1]));
    if (it != edges.end() && *it == key(e[0], e[1])) feature[*it] |= kSharp;
  }

  // Quadrics: each face's plane, weighted by its area; soft borders add
  // their perpendicular planes, weighted by the squared border length.
  Q.assign(nv, ErrorQuadric{});
  for (uint32_t f = 0; f < nf; ++f) {
    const Triangle& t = tri[f];
    const Vec3 n = (xp[t[1]] - xp[t[0]]).cross(xp[t[2]] - xp[t[0]]);
    const double a2 = n.norm();
    if (!(a2 > 0)) continue;
    const ErrorQuadric q = ErrorQuadric::plane(n / a2, n.dot(xp[t[0]]) / a2, a2 / 2);
    for (uint32_t v : t) Q[v] += q;
  }
  if (!o.soft_keys.empty())
    for (uint64_t k : edges) {
      const uint32_t a = uint32_t(k >> 32), b = uint32_t(k);
      uint32_t fs[2], n = 0;
      for (uint32_t f : vf[a])
        if ((tri[f][0] == b || tri[f][1] == b || tri[f][2] == b) && n < 2) fs[n++] = f;
      if (n != 2 || o.soft_keys[fs[0]] == o.soft_keys[fs[1]]) continue;
      const Vec3 e = xp[b] - xp[a];
      for (uint32_t h : fs) {
        const Triangle& t = tri[h];
        Vec3 m = e.cross((xp[t[1]] - xp[t[0]]).cross(xp[t[2]] - xp[t[0]]));
        if (!(m.norm() > 0)) continue;
        m.normalize();
        const ErrorQuadric q = ErrorQuadric::plane(m, m.dot(xp[a]), e.squaredNorm());
        Q[a] += q;
        Q[b] += q;
      }
    }
  fdeg.assign(nv, 0);
  for (const auto& [k, flags] : feature) {
    const uint32_t a = uint32_t(k >> 32), b = uint32_t(k);
    fdeg[a] = uint8_t(std::min(254, fdeg[a] + 1));
    fdeg[b] = uint8_t(std::min(254, fdeg[b] + 1));
  }
  // A vertex off every feature whose faces are not one disc (as many faces
  // as neighbours) is a pinch: it stays.
  for (uint32_t v = 0; v < nv; ++v) {
    if (fdeg[v] != 0) continue;
    neighbours(v, around);
    if (around.size() != vf[v].size()) fdeg[v] = kPinned;
  }
  rebuild_grid();
}

void Collapser::rebuild_grid() {
  double extent = 0;
  for (uint32_t f = 0; f < tri.size(); ++f) {
    if (!face_alive[f]) continue;
    Vec3 lo, hi;
    box_of(f, lo, hi);
    extent += (hi - lo).maxCoeff();
  }
  grid.reset(std::max(kGridCell * extent / double(std::max<uint64_t>(alive_faces, 1)), 1e-3), tri.size());
  for (uint32_t f = 0; f < tri.size(); ++f) {
    if (!face_alive[f]) continue;
    Vec3 lo, hi;
    box_of(f, lo, hi);
    grid.insert(f, lo, hi);
  }
  grid_faces = alive_faces;
}

// A vertex with no feature edge moves freely; one on exactly two (inside a
// chain) slides along them; any other (a chain's end, a junction) stays.
bool Collapser::removable(uint32_t u, uint32_t v) const {
  if (fdeg[u] == 0) return true;
  if (fdeg[u] != 2) return false;
  const auto it = feature.find(key(u, v));
  return it != feature.end();
}

int Collapser::moves(uint32_t a, uint32_t b, Move* out) const {
  ErrorQuadric q = Q[a];
  q += Q[b];
  const double len2 = (xp[a] - xp[b]).squaredNorm();
  int n = 0;
  if (removable(a, b)) out[n++] = {q(xp[b]), len2, a, b, xp[b]};
  if (removable(b, a)) out[n++] = {q(xp[a]), len2, b, a, xp[a]};
  if (fdeg[a] == 0 && fdeg[b] == 0) {
    const Vec3 mid = (xp[a] + xp[b]) / 2;
    Vec3 x;
    if (q.minimise(x) && (x - mid).squaredNorm() <= kOptimumReach * kOptimumReach * len2 && x != xp[a] && x != xp[b])
      out[n++] = {q(x), len2, std::max(a, b), std::min(a, b), x};
  }
  // Cheapest first; equal costs keep the order above (deterministic).
  std::stable_sort(out, out + n, [](const Move& x, const Move& y) { return x.cost < y.cost; });
  return n;
}

// Sample-aware placement (beyond Garland and Heckbert): q moved by kLift
// cells along the patch's normal, outwards then inwards (cheaper first).
// Only for a collapse of two free vertices that a sample refused: large
// triangles over a curved patch cut into it by their sag, and the band
// between the inside and the outside samples leaves room to lift them.
int Collapser::lift(const Move& m, Move* out) const {
  if (!o.lattice || fdeg[m.u] != 0 || fdeg[m.v] != 0) return 0;
  Vec3 n = Vec3::Zero();
  for (uint32_t w : {m.u, m.v})
    for (uint32_t f : vf[w]) {
      const Triangle& t = tri[f];
      n += (xp[t[1]] - xp[t[0]]).cross(xp[t[2]] - xp[t[0]]);
    }
  if (!(n.norm() > 0)) return 0;
  n.normalize();
  const double h = kLift * o.lattice->spacing.minCoeff();
  ErrorQuadric q = Q[m.u];
  q += Q[m.v];
  const double len2 = (xp[m.u] - xp[m.v]).squaredNorm();
  out[0] = {0, len2, m.u, m.v, m.q + h * n};
  out[1] = {0, len2, m.u, m.v, m.q - h * n};
  out[0].cost = q(out[0].q);
  out[1].cost = q(out[1].q);
  if (out[1].cost < out[0].cost) std::swap(out[0], out[1]);
  return 2;
}

bool Collapser::entry_of(uint32_t a, uint32_t b, Entry& out) const {
  Move mv[3];
  if (moves(a, b, mv) == 0) return false;
  const uint32_t lo = std::min(a, b), hi = std::max(a, b);
  out = {mv[0].cost, mv[0].len2, lo, hi, stamp[lo], stamp[hi]};
  return true;
}

void Collapser::neighbours(uint32_t v, std::vector<uint32_t>& out) const {
  out.clear();
  for (uint32_t f : vf[v])
    for (uint32_t w : tri[f])
      if (w != v) out.push_back(w);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

void Collapser::recount(uint32_t v) {
  if (fdeg[v] == kPinned) return;
  neighbours(v, around);
  int n = 0;
  for (uint32_t w : around) n += feature.count(key(v, w)) != 0;
  fdeg[v] = uint8_t(std::min(254, n));
}

void Collapser::box_of(uint32_t f, Vec3& lo, Vec3& hi) const {
  const Triangle& t = tri[f];
  lo = xi[t[0]].cwiseMin(xi[t[1]]).cwiseMin(xi[t[2]]);
  hi = xi[t[0]].cwiseMax(xi[t[1]]).cwiseMax(xi[t[2]]);
}

void Collapser::apply(const Move& m, const Probe& p) {
  const uint32_t u = m.u, v = m.v;
  for (uint32_t f : p.shared) {
    face_alive[f] = 0;
    grid.erase(f);
    attached[f].clear();
    for (uint32_t w : tri[f])
      if (w != u && w != v) vf[w].erase(std::find(vf[w].begin(), vf[w].end(), f));
  }
  std::vector<uint32_t>& keep = keep_;
  keep.clear();
  for (uint32_t f : vf[v])
    if (face_alive[f]) keep.push_back(f);
  std::vector<uint32_t>& from_u = from_u_;
  from_u.clear();
  for (uint32_t f : vf[u]) {
    if (!face_alive[f]) continue;
    for (uint32_t& w : tri[f])
      if (w == u) w = v;
    keep.push_back(f);
    from_u.push_back(f);
  }
  std::sort(keep.begin(), keep.end());
  vf[v].assign(keep.begin(), keep.end());
  vf[u].clear();
  vertex_alive[u] = 0;
  alive_faces -= p.shared.size();
  // Feature edges of u become v's (flags joined); u-v itself disappears.
  std::vector<std::pair<uint32_t, uint8_t>>& carried = carried_;
  carried.clear();
  for (uint32_t w : p.nu) {
    const auto it = feature.find(key(u, w));
    if (it == feature.end()) continue;
    if (w != v) carried.emplace_back(w, it->second);
    feature.erase(it);
  }
  for (const auto& [w, flags] : carried) feature[key(v, w)] |= flags;
  const bool v_moved = m.q != xp[v];
  if (v_moved) {
    moved[v] = 1;
    xp[v] = m.q;
    xi[v] = o.lattice ? o.lattice->to_index(m.q) : m.q;
  }
  moved[u] = 1;
  Q[v] += Q[u];
  ++stamp[u];
  ++stamp[v];
  for (uint32_t f : vf[v]) attached[f].clear();  // re-assigned below, from the checked assignment
  for (const auto& [x, f] : p.assign) attached[f].push_back(x);
  // The faces whose corners moved: u's, and v's too when v moved.
  for (uint32_t f : v_moved ? vf[v] : from_u) {
    Vec3 lo, hi;
    box_of(f, lo, hi);
    grid.move(f, lo, hi);
  }
  // Feature degrees change only where u's feature edges moved to v.
  if (!carried.empty() || fdeg[u] != 0) {
    recount(v);
    for (const auto& [w, flags] : carried) recount(w);
  }
  ++st.collapses;
}

// Takes the round's moves off the heap, cheapest first: at most `want`
// (kRound) edges whose closed neighbourhoods (both ends and their
// neighbours) meet no earlier one's; an edge that meets one goes back on
// the heap for a later round, a stale one (an end removed or changed since
// it was pushed) is dropped. Returns how many were taken.
size_t Collapser::select(Heap& heap, uint64_t want) {
  want = std::clamp<uint64_t>(want, 1, kRound);
  ++round_id_;
  if (round_.size() < want) round_.resize(want);
  std::vector<Entry> later;
  size_t n = 0;
  for (size_t looked = 0; n < want && looked < kLook * want && !heap.empty();) {
    const Entry e = heap.top();
    heap.pop();
    if (stale(e)) continue;
    ++looked;
    if (claim_[e.a] == round_id_ || claim_[e.b] == round_id_) {
      later.push_back(e);
      continue;
    }
    // The closed neighbourhoods of a and b: every corner of their faces.
    bool free = true;
    for (uint32_t v : {e.a, e.b})
      for (uint32_t f : vf[v])
        for (uint32_t w : tri[f]) free = free && claim_[w] != round_id_;
    if (!free) {
      later.push_back(e);
      continue;
    }
    for (uint32_t v : {e.a, e.b})
      for (uint32_t f : vf[v])
        for (uint32_t w : tri[f]) claim_[w] = round_id_;
    Candidate& c = round_[n++];
    c.a = e.a;
    c.b = e.b;
  }
  for (const Entry& e : later) heap.push(e);
  return n;
}

void Collapser::count(Verdict v) {
  switch (v) {
    case Verdict::ok: break;
    case Verdict::topology: ++st.refused_topology; break;
    case Verdict::shape: ++st.refused_shape; break;
    case Verdict::error: ++st.refused_error; break;
    case Verdict::samples: ++st.refused_samples; break;
    case Verdict::clash: ++st.refused_clash; break;
  }
}

SimplifyStats Collapser::run(std::vector<uint32_t>* vertex_map) {
  const auto t0 = std::chrono::steady_clock::now();
  st.faces_before = tri.size();
  const bool bounded = o.max_error > 0;
  if (o.faces == 0 && !bounded) {  // nothing asked
    st.faces_after = tri.size();
    st.vertices_after = mesh.positions.size();
    if (vertex_map) {
      vertex_map->resize(mesh.positions.size());
      for (uint32_t v = 0; v < vertex_map->size(); ++v) (*vertex_map)[v] = v;
    }
    return st;
  }
  build();
  // Every edge's cheapest move, costed in parallel, in face order.
  std::vector<Entry> first(3 * tri.size());
  std::vector<uint8_t> has(first.size(), 0);
  detail::parallel_ranges(tri.size(), 1024, [&](detail::IndexRange r) {
    for (size_t f = r.begin(); f < r.end(); ++f)
      for (size_t c = 0; c < 3; ++c) {
        const uint32_t a = tri[f][c], b = tri[f][(c + 1) % 3];
        has[3 * f + c] = a < b && entry_of(a, b, first[3 * f + c]);
      }
  });
  size_t edges = 0;
  for (size_t i = 0; i < first.size(); ++i)
    if (has[i]) first[edges++] = first[i];
  first.resize(edges);
  has = {};
  Heap heap(std::move(first));
  const uint64_t target = o.faces;
  ProgressCounter progress(o.progress, "simplify", target < st.faces_before ? (st.faces_before - target) / 2 : 0);
  claim_.assign(xp.size(), 0);
  // Rounds: the cheapest edges whose neighbourhoods do not touch are
  // checked in parallel against the state before the round, then applied
  // in cost order. Two such moves change disjoint faces and vertices, so
  // each one's checks still hold after the others, except that their new
  // faces could come near each other: a move whose new faces' box meets
  // one applied earlier in the round is checked again first. The rounds
  // depend on the costs only, so the result is the same for any number of
  // threads.
  std::vector<std::pair<Vec3, Vec3>> applied;
  std::vector<uint32_t> kept;
  std::vector<std::vector<Entry>> fresh;
  while (alive_faces > target && !heap.empty()) {
    const size_t n = select(heap, (alive_faces - target + 1) / 2);
    detail::parallel_ranges(n, 1, [&](detail::IndexRange r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        Candidate& c = round_[i];
        c.n = moves(c.a, c.b, c.mv);  // reads the state before the round, as the checks do
        c.accepted = -1;
        const auto try_from = [&](int first_move) {  // the first of mv[first_move..n) to pass
          for (int k = first_move; k < c.n && c.accepted < 0; ++k)
            if ((c.verdict[k] = check(c.mv[k], c.probe)) == Verdict::ok) c.accepted = k;
        };
        try_from(0);
        // Refused for a sample: the same collapse with q lifted off the
        // surface, either way (the chords of a curved patch cut into it).
        if (c.accepted < 0 && c.n > 0 && std::find(c.verdict, c.verdict + c.n, Verdict::samples) != c.verdict + c.n) {
          const int base = c.n;
          c.n += lift(c.mv[0], c.mv + base);
          try_from(base);
        }
      }
    });
    applied.clear();
    for (size_t i = 0; i < n && alive_faces > target; ++i) {
      Candidate& c = round_[i];
      const int tried = c.accepted < 0 ? c.n : c.accepted + 1;  // the refused moves, then the kept one
      for (int k = 0; k < tried; ++k) count(c.verdict[k]);
      if (c.accepted < 0) continue;
      const Move& m = c.mv[c.accepted];
      const auto meets = [&](const std::pair<Vec3, Vec3>& b) {
        return !((c.probe.lo.array() > b.second.array()).any() || (b.first.array() > c.probe.hi.array()).any());
      };
      if (std::any_of(applied.begin(), applied.end(), meets)) {
        const Verdict again = check(m, c.probe);
        if (again != Verdict::ok) {
          count(again);
          continue;
        }
      }
      apply(m, c.probe);
      st.in_plane += c.probe.planar;
      applied.emplace_back(c.probe.lo, c.probe.hi);
      kept.push_back(m.v);
    }
    // The kept vertices' edges, costed in parallel (a kept vertex's
    // neighbours are in its own move's neighbourhood, which no other move
    // of the round touched) and pushed in order.
    fresh.resize(kept.size());
    detail::parallel_ranges(kept.size(), 8, [&](detail::IndexRange r) {
      std::vector<uint32_t> nb;
      for (size_t i = r.begin(); i < r.end(); ++i) {
        const uint32_t v = kept[i];
        fresh[i].clear();
        neighbours(v, nb);
        Entry e;
        for (uint32_t w : nb)
          if (entry_of(v, w, e)) fresh[i].push_back(e);
      }
    });
    for (const auto& entries : fresh)
      for (const Entry& e : entries) heap.push(e);
    // Over two entries per live edge (3/2 per face): the stale ones go. The
    // next pop is the same either way (a stale entry is never taken).
    if (heap.size() > 3 * alive_faces) heap.prune([&](const Entry& e) { return stale(e); });
    progress.add(kept.size());
    kept.clear();
    if (2 * alive_faces < grid_faces) rebuild_grid();
  }
  compact(vertex_map);
  // The error: the farthest input vertex from the result (order-free max).
  if (st.collapses > 0) {
    const MeshQuery query(mesh);
    st.error = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, input.size(), 4096), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double e) {
          for (size_t v = r.begin(); v < r.end(); ++v)
            if (moved[v]) e = std::max(e, query.closest(input[v]).dist2);
          return e;
        },
        [](double x, double y) { return std::max(x, y); });
    st.error = std::sqrt(st.error);
  }
  st.faces_after = tri.size();
  st.vertices_after = mesh.positions.size();
  st.seconds = seconds_since(t0);
  return st;
}

void Collapser::compact(std::vector<uint32_t>* vertex_map) {
  const size_t nv = xp.size(), nf = tri.size();
  std::vector<uint32_t> remap(nv, UINT32_MAX);
  uint32_t next = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (vertex_alive[v]) remap[v] = next++;
  auto keep_vertices = [&](auto& values) {
    if (values.empty()) return;
    size_t k = 0;
    for (size_t v = 0; v < nv; ++v)
      if (vertex_alive[v]) values[k++] = values[v];
    values.resize(k);
  };
  mesh.positions = xp;
  keep_vertices(mesh.positions);
  keep_vertices(mesh.colors);
  keep_vertices(mesh.uvs);
  for (MeshAttribute& a : mesh.vertex_attributes) keep_vertices(a.values);
  size_t k = 0;
  for (size_t f = 0; f < nf; ++f) {
    if (!face_alive[f]) continue;
    Triangle t = tri[f];
    for (uint32_t& w : t) w = remap[w];
    tri[k] = t;
    for (MeshAttribute& a : mesh.face_attributes) a.values[k] = a.values[f];
    ++k;
  }
  tri.resize(k);
  for (MeshAttribute& a : mesh.face_attributes) a.values.resize(k);
  mesh.edges.clear();
  for (const auto& [e, flags] : feature)
    if (flags & kSharp) mesh.edges.push_back({remap[uint32_t(e >> 32)], remap[uint32_t(e)]});
  std::sort(mesh.edges.begin(), mesh.edges.end());
  if (!mesh.normals.empty()) mesh.normals = vertex_normals(mesh);
  if (vertex_map) *vertex_map = std::move(remap);
}

}  // namespace voxpress::detail

namespace voxpress {

SimplifyStats simplify(Mesh& mesh, const SimplifyOptions& options, std::vector<uint32_t>* vertex_map) {
  if (!options.soft_keys.empty() && options.soft_keys.size() != mesh.triangles.size())
    throw std::invalid_argument("simplify: soft_keys must have one key per face");
  if (!(options.max_error >= 0) || !std::isfinite(options.max_error))
    throw std::invalid_argument("simplify: max_error must be finite and non-negative");
  mesh.validate();
  detail::Collapser c(mesh, options);
  return c.run(vertex_map);
}

}  // namespace voxpress
