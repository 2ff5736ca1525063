// Pressing of a shared surface: junction lines as curves in space, then the
// labelled contours of every lattice plane with the junction points as
// barriers. Theory of operation: include/voxpress/labels/shared_press.h.
#include "voxpress/labels/shared_press.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/clearance.h"
#include "core/predicates.h"
#include "core/sentinel.h"
#include "core/timing.h"
#include "cube_check.h"
#include "own_frame.h"
#include "smooth/curve_kernel.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

using detail::Cubes;
using detail::kNone;

bool is_stick(uint8_t kind) { return kind < 3; }
bool is_face(uint8_t kind) { return kind >= 3 && kind < 6; }
// Planes closer to parallel than this (1 - cos, ~10 degrees) pin one direction only.
constexpr double kPlaneFloor = 0.015;
// Cells: planes meeting farther than this outside a junction vertex's element
// are about another edge of the parts; the vertex is left to the junction press.
constexpr double kBeyond = 0.5;

// The plane of family a (normal to axis a) a vertex lies in, or INT64_MIN.
int64_t plane_of(const SharedSurface& s, uint32_t v, int a) {
  const uint8_t k = s.kind[v];
  if ((is_stick(k) && k != a) || (is_face(k) && k - 3 == a)) return s.corner[v][size_t(a)];
  return INT64_MIN;
}

// Undirected edges (u < v) with the number of triangles on each.
struct Edge {
  uint32_t u, v, count;
};

std::vector<Edge> edges_of(const Mesh& m) {
  std::vector<uint64_t> keys(3 * m.triangles.size());
  detail::parallel_for(m.triangles.size(), [&](size_t f) {
    const Triangle& t = m.triangles[f];
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
      keys[3 * f + size_t(e)] = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<Edge> out;
  for (size_t i = 0; i < keys.size();) {
    size_t j = i;
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    out.push_back({uint32_t(keys[i] >> 32), uint32_t(keys[i]), uint32_t(j - i)});
    i = j;
  }
  return out;
}

// Adjacency in CSR form of a list of undirected edges over n vertices.
struct Graph {
  std::vector<uint32_t> offset, to, edge;  // edge: the index of the edge in the list
  Graph(size_t n, const std::vector<std::pair<uint32_t, uint32_t>>& edges) : offset(n + 1, 0) {
    for (const auto& [u, v] : edges) ++offset[u + 1], ++offset[v + 1];
    for (size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
    to.resize(offset[n]);
    edge.resize(offset[n]);
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t e = 0; e < edges.size(); ++e) {
      const auto [u, v] = edges[e];
      to[fill[u]] = v, edge[fill[u]++] = e;
      to[fill[v]] = u, edge[fill[v]++] = e;
    }
  }
  uint32_t degree(uint32_t v) const { return offset[v + 1] - offset[v]; }
};

// The chains of a graph between its `stop` vertices (each chain from a stop
// vertex to a stop vertex, possibly the same one, both ends listed), then its
// closed loops of other vertices (every other vertex has degree 2). Each edge is walked once. Chains start at stop vertices
// in increasing order, so the result does not depend on threads.
struct Chains {
  std::vector<uint32_t> ids, offsets{0};
  std::vector<uint8_t> closed;
};

Chains chains_of(const Graph& g, const std::vector<uint8_t>& stop, const std::vector<uint32_t>& members) {
  Chains c;
  std::vector<uint8_t> walked(g.to.size() / 2, 0);
  auto walk = [&](uint32_t start, uint32_t k) {  // k: position in start's adjacency
    uint32_t v = start;
    c.ids.push_back(v);
    for (;;) {
      walked[g.edge[k]] = 1;
      const uint32_t w = g.to[k];
      if (stop[w] || w == start) break;
      c.ids.push_back(w);
      // The other edge of w (w has degree 2: it is not a stop vertex).
      uint32_t next = kNone;
      for (uint32_t q = g.offset[w]; q < g.offset[w + 1]; ++q)
        if (!walked[g.edge[q]]) next = q;
      if (next == kNone) break;  // a loop closed back onto w's first edge
      v = w;
      k = next;
    }
    return g.to[k];
  };
  for (uint32_t v : members) {
    if (!stop[v]) continue;
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k) {
      if (walked[g.edge[k]]) continue;
      c.ids.push_back(walk(v, k));  // the far end (v again for a chain back to v)
      c.offsets.push_back(uint32_t(c.ids.size()));
      c.closed.push_back(0);
    }
  }
  for (uint32_t v : members) {
    if (stop[v] || g.degree(v) == 0) continue;
    bool fresh = false;
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k) fresh = fresh || !walked[g.edge[k]];
    if (!fresh) continue;
    walk(v, g.offset[v]);
    c.offsets.push_back(uint32_t(c.ids.size()));
    c.closed.push_back(1);
  }
  return c;
}


// Stage 1: the junction lines as curves in space (PressOptions drives the
// iteration as it drives pressing: coarse-to-fine arc length, momentum,
// circle correction; Jacobi updates). x: index positions, updated in place.
PressStats press_junctions(const SharedSurface& s, const Chains& c, const std::vector<uint8_t>& moving,
                           std::vector<Vec3>& x, const PressOptions& o, int levels) {
  const auto t0 = std::chrono::steady_clock::now();
  PressStats st;
  st.levels = levels;
  st.curves = c.closed.size();
  const Mat3 M = s.lattice.index_to_physical_matrix(), Minv = M.inverse();
  const double cell = std::cbrt(s.lattice.spacing[0] * s.lattice.spacing[1] * s.lattice.spacing[2]);
  const double s2 = o.step * o.step;
  const double correction = 1 - std::cos(std::clamp(o.circle_correction, 0.0, 90.0) * std::numbers::pi / 180);
  std::vector<Vec3> disp(x.size(), Vec3::Zero()), velocity(x.size(), Vec3::Zero());
  for (uint8_t m : moving) st.fresh += m;
  if (st.fresh == 0) return st;
  // A fixed schedule (the junction lines are short; the interfaces' solve
  // after them is the one run to the tolerance): kJunctionSweeps sweeps,
  // stopped early once no vertex moves by kJunctionChange.
  constexpr int kJunctionSweeps = 100;       // what every press ran before the solver (bench_labels unchanged)
  constexpr double kJunctionChange = 1e-4;   // cells
  const int sweeps = std::min(o.iterations, kJunctionSweeps);
  for (int it = 0; it < sweeps; ++it) {
    const int stage = std::min(levels - 1, it * levels / std::max(sweeps, 1));
    const double d = o.arc_length * double(1 << (levels - 1 - stage)) * cell;
    detail::parallel_ranges(c.closed.size(), 16, [&](detail::IndexRange r) {
      detail::Scratch<Vec3> w;
      for (size_t k = r.begin(); k < r.end(); ++k) {
        const uint32_t b = c.offsets[k], n = c.offsets[k + 1] - b;
        w.resize(n);
        for (uint32_t i = 0; i < n; ++i) w.pos[i] = M * x[c.ids[b + i]];
        detail::curve_step(n, c.closed[k] != 0, d, s2, o.resample, false, correction, detail::Euclid{}, w);
        for (uint32_t i = 0; i < n; ++i)
          if (moving[c.ids[b + i]]) disp[c.ids[b + i]] = Minv * w.disp[i];
      }
    });
    const double change = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, x.size(), 1 << 12), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double acc) {
          for (size_t v = r.begin(); v < r.end(); ++v) {
            if (!moving[v]) continue;
            // Within its element: a face keeps its normal coordinate, both
            // keep the margin from the element's sides.
            Vec3 y = x[v] + disp[v] + o.momentum * velocity[v];
            for (int a = 0; a < 3; ++a) {
              const double lo = double(s.corner[v][size_t(a)]);
              y[a] = is_face(s.kind[v]) && s.kind[v] - 3 == a ? lo : std::clamp(y[a], lo + o.margin, lo + 1 - o.margin);
            }
            velocity[v] = y - x[v];
            acc = std::max(acc, velocity[v].cwiseAbs().maxCoeff());
            x[v] = y;
          }
          return acc;
        },
        [](double a, double b) { return std::max(a, b); });
    st.iterations = it + 1;
    st.residual = change;
    st.least_residual = it == 0 ? change : std::min(st.least_residual, change);
    if (change < kJunctionChange) break;
  }
  st.seconds = detail::seconds_since(t0);
  return st;
}

// Beyond the paper: where a surface continues smoothly through a junction
// line (a sphere pressed into a box: its interfaces with the box and with
// the background are one sphere), the two pieces of a plane's contour that
// continue each other through a junction point are pressed as one curve
// there, each with the other as context, instead of each ending at the
// point. Pieces pair when they turn by less than this at the point,
// measured on the midpoint surface over chords of kTangentCells cells:
constexpr double kContinueDegrees = 35;  // organ-like junctions (~120 degrees each) never pair
constexpr double kTangentCells = 3;      // the staircase's noise (half a cell) turns a chord by < 10 degrees

// Per open chain end (2 k + e, e = 0 its first vertex, 1 its last): the
// chain end continuing it through its junction point, or -1. Greedy by
// increasing turning angle, each end paired once; deterministic.
std::vector<int64_t> continuations(const SharedSurface& s, const Chains& c, const Graph& jg,
                                   const std::vector<Vec3>& x0, const Mat3& M) {
  const size_t n = c.closed.size();
  std::vector<int64_t> partner(2 * n, -1);
  const double cell = std::cbrt(s.lattice.spacing.prod());
  std::vector<std::pair<uint32_t, uint32_t>> ends;  // (junction vertex, chain end)
  for (size_t k = 0; k < n; ++k) {
    if (c.closed[k] || c.offsets[k + 1] - c.offsets[k] < 3) continue;
    for (uint32_t e = 0; e < 2; ++e) {
      const uint32_t v = c.ids[e == 0 ? c.offsets[k] : c.offsets[k + 1] - 1];
      if (jg.degree(v) > 0 && !is_stick(s.kind[v])) ends.push_back({v, uint32_t(2 * k + e)});
    }
  }
  std::sort(ends.begin(), ends.end());
  // Unit direction from the junction point into the chain, over a chord.
  auto direction = [&](uint32_t end) {
    const size_t k = end / 2;
    const uint32_t b = c.offsets[k], e = c.offsets[k + 1], m = e - b;
    const Vec3 p = M * x0[c.ids[end % 2 == 0 ? b : e - 1]];
    Vec3 q = p;
    for (uint32_t i = 1; i < m; ++i) {
      q = M * x0[c.ids[end % 2 == 0 ? b + i : e - 1 - i]];
      if ((q - p).norm() >= kTangentCells * cell) break;
    }
    return Vec3((q - p).normalized());
  };
  const double limit = std::cos(kContinueDegrees * std::numbers::pi / 180);
  for (size_t i = 0; i < ends.size();) {
    size_t j = i;
    while (j < ends.size() && ends[j].first == ends[i].first) ++j;
    if (j - i >= 3) {
      std::vector<Vec3> dir;
      for (size_t k = i; k < j; ++k) dir.push_back(direction(ends[k].second));
      std::vector<std::tuple<double, size_t, size_t>> pairs;  // (-cos of the turn, a, b)
      for (size_t a = 0; a < dir.size(); ++a)
        for (size_t b = a + 1; b < dir.size(); ++b)
          if (ends[i + a].second / 2 != ends[i + b].second / 2 && -dir[a].dot(dir[b]) >= limit)
            pairs.push_back({dir[a].dot(dir[b]), a, b});
      std::sort(pairs.begin(), pairs.end());
      for (const auto& [cosine, a, b] : pairs) {
        const uint32_t ea = ends[i + a].second, eb = ends[i + b].second;
        if (partner[ea] >= 0 || partner[eb] >= 0) continue;
        partner[ea] = eb;
        partner[eb] = ea;
      }
    }
    i = j;
  }
  return partner;
}


// Beyond the paper (CAD assemblies): a junction vertex next to stick
// vertices on flats lies where those flats' planes meet — a line where two
// parts' faces meet at an edge. Where the planes pin every free coordinate
// of its element (a stick's t; a face's two in-plane coordinates; an apex's
// three), it goes to their least-squares point in the element, kept inside
// by the margin, and stays there as a fixed point of both stages. Planes
// that leave a direction free (one face plane across a face vertex: its
// place along the line is the junction press's to find) place nothing.
// Returns per vertex: 1 when it has such a place (`target`).
std::vector<uint8_t> flat_places(const SharedSurface& s, const SharedFlats& flats, const std::vector<Edge>& edges,
                                 const std::vector<uint32_t>& members, const std::vector<Vec3>& x0, double margin,
                                 std::vector<Vec3>& target) {
  const size_t n = s.mesh.positions.size();
  std::vector<std::pair<uint32_t, uint32_t>> all;
  for (const Edge& e : edges) all.push_back({e.u, e.v});
  const Graph g(n, all);
  const Mat3 Mt = s.lattice.index_to_physical_matrix().transpose();
  std::vector<uint8_t> placed(n, 0);
  target.assign(n, Vec3::Zero());
  detail::parallel_for(members.size(), [&](size_t i) {
    const uint32_t v = members[i];
    std::vector<int32_t> regions;
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k)
      if (const int32_t r = flats.region[g.to[k]]; r >= 0 && is_stick(s.kind[g.to[k]])) regions.push_back(r);
    std::sort(regions.begin(), regions.end());
    regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
    if (regions.empty()) return;
    // The element's free coordinates (mask), the planes restricted to them.
    const uint8_t kind = s.kind[v];
    Vec3 free = Vec3::Zero();
    for (int a = 0; a < 3; ++a)
      free[a] = kind == 6 || (is_stick(kind) && kind == a) || (is_face(kind) && kind - 3 != a) ? 1 : 0;
    Mat3 A = Mat3::Zero();
    Vec3 r = Vec3::Zero();
    for (int32_t f : regions) {  // the plane in index space: (M^T n) . x = offset - n . origin
      const Flat& F = flats.flats[size_t(f)];
      const Vec3 nn = Mt * F.normal;
      const double len = nn.norm(), c = (F.offset - F.normal.dot(s.lattice.origin)) / len;
      const Vec3 u = nn / len, uf = u.cwiseProduct(free);
      A += uf * uf.transpose();
      r += uf * (c - u.dot(x0[v]));
    }
    Eigen::SelfAdjointEigenSolver<Mat3> es(A);
    Vec3 y = x0[v];
    int pinned = 0;
    for (int k = 0; k < 3; ++k)
      if (es.eigenvalues()[k] > kPlaneFloor) {
        y += es.eigenvectors().col(k) * (es.eigenvectors().col(k).dot(r) / es.eigenvalues()[k]);
        ++pinned;
      }
    if (pinned < free.sum()) return;
    for (int a = 0; a < 3; ++a) {
      const double lo = double(s.corner[v][size_t(a)]);
      if (free[a] == 0) continue;
      if (y[a] < lo - kBeyond || y[a] > lo + 1 + kBeyond) return;  // the planes meet elsewhere
      y[a] = std::clamp(y[a], lo + margin, lo + 1 - margin);
    }
    target[v] = y;
    placed[v] = 1;
  });
  return placed;
}

// Press levels for the extent of the surface's cells.
int shared_press_levels(const SharedSurface& s, const PressOptions& o) {
  const size_t n = s.mesh.positions.size();
  int64_t extent = 0;
  for (int a = 0; a < 3; ++a) {
    int64_t lo = INT64_MAX, hi = INT64_MIN;
    for (const auto& c : s.corner) lo = std::min(lo, c[size_t(a)]), hi = std::max(hi, c[size_t(a)]);
    if (n > 0) extent = std::max(extent, hi + 2 - lo);
  }
  return press_levels_for_extent(o.levels, extent);
}

// Labels around each junction vertex, up to four: their count.
std::vector<uint8_t> labels_around(const SharedSurface& s, const Graph& jg) {
  const size_t n = s.mesh.positions.size();
  std::vector<std::array<uint32_t, 4>> around(n);
  std::vector<uint8_t> count(n, 0);
  for (size_t f = 0; f < s.sides.size(); ++f)
    for (uint32_t v : s.mesh.triangles[f])
      for (uint32_t L : s.sides[f]) {
        if (jg.degree(v) == 0 || count[v] == 4) continue;
        if (std::find(around[v].begin(), around[v].begin() + count[v], L) == around[v].begin() + count[v])
          around[v][count[v]++] = L;
      }
  return count;
}

// CSR curves for the iteration: an open chain J1 .. J2 as a cycle whose
// closing segment J2 -> J1 joins two barriers (no vertex between them);
// a chain continued through a junction point by another (partner) as an
// open polyline with that piece as context beyond the point.
void add_plane_curves(const Chains& pc, const std::vector<int64_t>& partner, const PressOptions& o, detail::Family& f,
                      std::vector<uint32_t>& ids, std::vector<uint32_t>& offsets, SharedPressStats& st) {
  for (size_t k = 0; k < pc.closed.size(); ++k) {
    uint32_t b = pc.offsets[k], e = pc.offsets[k + 1];
    const int64_t before = pc.closed[k] ? -1 : partner[2 * k], after = pc.closed[k] ? -1 : partner[2 * k + 1];
    if (before < 0 && after < 0) {
      if (!pc.closed[k] && pc.ids[e - 1] == pc.ids[b]) --e;
      ids.insert(ids.end(), pc.ids.begin() + b, pc.ids.begin() + e);
      offsets.push_back(uint32_t(ids.size()));
      f.spans.push_back({});
      continue;
    }
    // The partner chain's vertices from its end at the junction point
    // (excluded) away from it.
    auto away = [&](int64_t end) {
      const size_t q = size_t(end / 2);
      const uint32_t qb = pc.offsets[q], qe = pc.offsets[q + 1];
      std::vector<uint32_t> out(pc.ids.begin() + qb, pc.ids.begin() + qe);
      if (end % 2 == 1) std::reverse(out.begin(), out.end());
      out.erase(out.begin());
      return out;
    };
    const size_t start = ids.size();
    const bool loose = o.free_ends && e - b - 1 >= detail::kFreePiece;
    if (before >= 0) {
      std::vector<uint32_t> c = away(before);
      ids.insert(ids.end(), c.rbegin(), c.rend());
    }
    // The junction point itself is left out where the curve goes on
    // through it: its place (stage 1, inside its face square) would bend
    // the continued curve towards it.
    const uint32_t first = before >= 0 || loose ? b + 1 : b, last = after >= 0 || loose ? e - 1 : e;
    detail::Family::Span sp;
    sp.open = 1;
    sp.free = loose;
    sp.lo = uint32_t(ids.size() - start) + (first == b ? 1 : 0);
    ids.insert(ids.end(), pc.ids.begin() + first, pc.ids.begin() + last);
    sp.hi = uint32_t(ids.size() - start) - (last == e ? 1 : 0);
    if (after >= 0) {
      std::vector<uint32_t> c = away(after);
      ids.insert(ids.end(), c.begin(), c.end());
    }
    offsets.push_back(uint32_t(ids.size()));
    f.spans.push_back(sp);
    ++st.continued;
  }
}

// The labelled contours of the lattice planes normal to axis a, cut at the
// barriers, as iteration family f over ids and offsets (CSR).
void plane_family(const SharedSurface& s, int a, const std::vector<Edge>& edges, const std::vector<uint8_t>& barrier,
                  const Graph& jg, const std::vector<Vec3>& x0, const Mat3& M, const PressOptions& o, detail::Family& f,
                  std::vector<uint32_t>& ids, std::vector<uint32_t>& offsets, SharedPressStats& st) {
  const size_t n = s.mesh.positions.size();
  const int u = (a + 1) % 3, w = (a + 2) % 3;
  std::vector<std::pair<uint32_t, uint32_t>> in_plane;
  for (const Edge& e : edges) {
    const int64_t p = plane_of(s, e.u, a);
    if (p != INT64_MIN && p == plane_of(s, e.v, a)) in_plane.push_back({e.u, e.v});
  }
  const Graph g(n, in_plane);
  std::vector<uint32_t> mem;
  for (uint32_t v = 0; v < n; ++v) {
    if (plane_of(s, v, a) == INT64_MIN) continue;
    if (is_stick(s.kind[v]) && g.degree(v) != 2)
      throw std::logic_error("press_shared: a stick vertex without two neighbours in a plane");
    mem.push_back(v);
  }
  const Chains pc = chains_of(g, barrier, mem);
  const std::vector<int64_t> partner = continuations(s, pc, jg, x0, M);
  add_plane_curves(pc, partner, o, f, ids, offsets, st);
  offsets.insert(offsets.begin(), 0u);
  st.plane_curves += pc.closed.size();
  f.ids = &ids;
  f.offsets = &offsets;
  f.g = {M.col(u).squaredNorm(), M.col(u).dot(M.col(w)), M.col(w).squaredNorm()};
  f.cell = std::sqrt(s.lattice.spacing[u] * s.lattice.spacing[w]);
  const size_t m = ids.size();
  f.base.resize(m);
  f.mov.resize(m);
  f.dst.resize(m);
  for (size_t k = 0; k < m; ++k) {
    const uint32_t v = ids[k];
    const uint8_t kind = s.kind[v];
    f.mov[k] = uint8_t(is_stick(kind) && kind != u ? 1 : 0);
    f.dst[k] = 2 * v + uint32_t(is_stick(kind) ? SliceCurves::slot(a, kind) : 0);
    if (is_stick(kind)) f.base[k] = Vec2(double(s.corner[v][size_t(u)]), double(s.corner[v][size_t(w)]));
  }
}

}  // namespace

SharedPressStats press_shared(SharedSurface& s, const PressOptions& o, const SharedFlats* flats) {
  const auto t0 = std::chrono::steady_clock::now();
  SharedPressStats st;
  const size_t n = s.mesh.positions.size();
  if (s.kind.size() != n || s.corner.size() != n) throw std::invalid_argument("press_shared: vertex kinds missing");
  for (uint8_t k : s.kind)
    if (k > 6) throw std::invalid_argument("press_shared: a sharpened surface (its midpoint places are gone)");
  if (s.apexes.size() != s.apex_vertices) throw std::invalid_argument("press_shared: apex places missing");
  if (flats && (flats->t.size() != n || flats->region.size() != n || flats->barrier.size() != n))
    throw std::invalid_argument("press_shared: flats of another surface");
  // The press runs on the surface's own box (issue 74, item 2: the same t
  // for any shift, pad or crop of the map): corners relative to its lowest
  // one, the origin moved there, and the midpoint places exact in that
  // frame (no rounding of the physical positions back to index space).
  const detail::OwnFrame frame(s);
  std::vector<Vec3> x0(n);
  std::vector<double> t0s(n, 0);
  detail::parallel_for(n, [&](size_t v) {
    const uint8_t k = s.kind[v];
    x0[v] = Vec3(double(s.corner[v][0]), double(s.corner[v][1]), double(s.corner[v][2]));
    for (int a = 0; a < 3; ++a)
      if ((is_stick(k) && k == a) || (is_face(k) && k - 3 != a)) x0[v][a] += 0.5;
    if (is_stick(k)) t0s[v] = 0.5;
  });
  for (const auto& [v, place] : s.apexes) x0[v] += place;
  const int levels = shared_press_levels(s, o);
  const std::vector<Edge> edges = edges_of(s.mesh);

  // Junction lines: edges with three or more triangles.
  std::vector<std::pair<uint32_t, uint32_t>> junction;
  for (const Edge& e : edges)
    if (e.count >= 3) junction.push_back({e.u, e.v});
  const Graph jg(n, junction);
  const std::vector<uint8_t> count = labels_around(s, jg);
  std::vector<uint32_t> members;
  for (uint32_t v = 0; v < n; ++v)
    if (jg.degree(v) > 0) members.push_back(v);

  // The labelled contours of every plane, cut at the junction points.
  // Stick vertices on a flat keep its plane (junction lines excepted: they
  // stay at their midpoints); those at a sharp border are barriers too.
  std::vector<uint8_t> on_flat(n, 0), barrier(n, 0);
  for (uint32_t v = 0; v < n; ++v) {
    on_flat[v] = flats && flats->region[v] >= 0 && is_stick(s.kind[v]) && jg.degree(v) == 0;
    st.flat_vertices += on_flat[v];
    barrier[v] = !is_stick(s.kind[v]) || jg.degree(v) > 0 || (on_flat[v] && flats->barrier[v]);
  }
  std::vector<detail::Family> families(3);
  std::vector<uint32_t> ids[3], offsets[3];
  const Mat3 M = s.lattice.index_to_physical_matrix();
  for (int a = 0; a < 3; ++a)
    plane_family(s, a, edges, barrier, jg, x0, M, o, families[size_t(a)], ids[a], offsets[a], st);

  const Cubes cubes = detail::cubes_of(s.mesh, x0);
  const double delta = detail::float32_clearance_around(s.lattice, x0);
  std::vector<uint32_t> all(cubes.offsets.size() - 1);
  for (uint32_t g = 0; g < all.size(); ++g) all[g] = g;
  std::vector<Vec3> place;
  const std::vector<uint8_t> placed =
      flats ? flat_places(s, *flats, edges, members, x0, o.margin, place) : std::vector<uint8_t>(n, 0);
  // One pressing of both stages; `pinned` vertices keep their midpoint place.
  std::vector<Vec3> x;
  std::vector<uint8_t> pinned(n, 0);
  auto run = [&] {
    x = x0;
    std::vector<double> t = t0s;
    std::vector<uint8_t> moving(n, 0), stop(n, 0);
    st.junction_moving = st.junction_fixed = st.junction_on_flats = 0;
    for (uint32_t v : members) {
      if (placed[v] && !pinned[v]) {
        x[v] = place[v];
        if (is_stick(s.kind[v])) t[v] = place[v][s.kind[v]] - double(s.corner[v][s.kind[v]]);
        ++st.junction_on_flats;
      }
      moving[v] = jg.degree(v) == 2 && !is_stick(s.kind[v]) && count[v] < 4 && !pinned[v] && !placed[v];
      stop[v] = !moving[v];
      (moving[v] ? st.junction_moving : st.junction_fixed)++;
    }
    const Chains jc = chains_of(jg, stop, members);
    st.junction_curves = jc.closed.size();
    st.junctions = press_junctions(s, jc, moving, x, o, levels);
    for (int a = 0; a < 3; ++a) {  // junction points at their pressed places (t = 0)
      const int u = (a + 1) % 3, w = (a + 2) % 3;
      detail::Family& f = families[size_t(a)];
      for (size_t k = 0; k < ids[a].size(); ++k)
        if (!is_stick(s.kind[ids[a][k]])) f.base[k] = Vec2(x[ids[a][k]][u], x[ids[a][k]][w]);
    }
    std::vector<uint8_t> frozen(barrier);
    for (uint32_t v = 0; v < n; ++v) {
      frozen[v] |= pinned[v] | on_flat[v];
      if (on_flat[v] && !pinned[v]) t[v] = flats->t[v];
    }
    st.interfaces = detail::iterate(t, families, 2, frozen, barrier, o, levels);
    detail::parallel_for(n, [&](size_t v) {
      if (!is_stick(s.kind[v]) || jg.degree(v) > 0) return;  // junction sticks stay where stage 1 put them
      Vec3 y(double(s.corner[v][0]), double(s.corner[v][1]), double(s.corner[v][2]));
      y[s.kind[v]] += t[v];
      x[v] = y;
    });
  };
  // The checked result: press, check every cube exactly; pin the vertices
  // of the cubes that fail and press again, so the pressing works around
  // them; then put the vertices of any cube that still fails back at their
  // midpoints, and recheck the cubes that share them, until none fails.
  // A cube whose vertices are all at their midpoints passes (the label
  // cases are intersection-free there, and clear of each other by far more
  // than float32 rounding), so this ends, every cube valid in float32.
  auto pin = [&](const std::vector<uint32_t>& bad) {
    for (uint32_t g : bad)
      for (uint32_t k = cubes.offsets[g]; k < cubes.offsets[g + 1]; ++k)
        for (uint32_t v : s.mesh.triangles[cubes.tris[k]]) pinned[v] = 1;
  };
  run();
  std::vector<uint32_t> bad = detail::failing_cubes(s.mesh, cubes, all, x, delta);
  if (!bad.empty()) {
    st.cubes_pinned = bad.size();
    pin(bad);
    run();
    bad = detail::failing_cubes(s.mesh, cubes, all, x, delta);
  }
  std::vector<uint8_t> reset(n, 0);
  st.cubes_reset = detail::put_back(s.mesh, cubes, std::move(bad), x, x0, reset, delta);
  detail::parallel_for(n, [&](size_t v) {
    if (x[v] != x0[v]) s.mesh.positions[v] = s.lattice.to_physical(x[v]);  // the others keep their bits
  });
  s.mesh.normals.clear();
  st.seconds = detail::seconds_since(t0);
  return st;
}

}  // namespace voxpress
