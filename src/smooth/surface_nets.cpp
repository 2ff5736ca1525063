// Constrained Elastic Surface Nets (Gibson 1998) as the dual of the stick
// surface. Theory of operation: include/voxpress/smooth/surface_nets.h.
//
// Build: the triangles of the stick surface are grouped by cell (a triangle's
// cell is the component-wise minimum of its sticks' lower samples: no
// triangle lies in a cell face), and each cell's triangles are split into
// patches by shared sticks. A stick lies in four cells; slot k of stick s
// (along axis a, b = a + 1, c = a + 2 mod 3) is the cell at lower(s) minus
// offsets (0,0), (1,0), (1,1), (0,1) along (b, c): counter-clockwise around
// +a. Slots k and k + 1 share the face through s whose normal axis is the
// one their offsets differ in.
#include "voxpress/smooth/surface_nets.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/sentinel.h"
#include "core/timing.h"
#include "smooth/surface_graph.h"

namespace voxpress {

using detail::seconds_since;

namespace {

using detail::kNone;
constexpr int kSlotOffset[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

Vec3 index_vec(const std::array<int64_t, 3>& i) { return {double(i[0]), double(i[1]), double(i[2])}; }

struct Bounds {
  Vec3 lo, hi;
};

// The net being built: its vertices (index space, unpadded) and their
// constraint boxes; per stick slot the patch vertex of that cell and the
// face vertex on the net edge after it (kNone: none); the polygons.
struct Net {
  std::vector<Vec3> x;
  std::vector<Bounds> box;
  std::vector<uint32_t> stick_patch, face_vertex;
  std::vector<uint32_t> poly, poly_off{0};
};

Vec3 stick_midpoint(const StickSurface& surface, size_t s) {
  Vec3 m = index_vec(surface.lower_index(s));
  m[surface.axis(s)] += 0.5;
  return m;
}

// Triangles grouped by cell, each cell's split into patches (connected
// triangles: union-find over its <= 12 sticks); a patch vertex at the mean
// of its sticks' midpoints, boxed by them (Gibson: the whole cell when the
// cell has one patch).
void build_patches(const StickSurface& surface, Net& net, SurfaceNetStats& st) {
  const auto& P = surface.padded;
  auto& x = net.x;
  auto& box = net.box;
  auto& stick_patch = net.stick_patch;

  // Triangles grouped by cell.
  std::vector<std::pair<uint64_t, uint32_t>> by_cell(surface.triangles.size());
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    std::array<int64_t, 3> c{INT64_MAX, INT64_MAX, INT64_MAX};
    for (uint32_t s : surface.triangles[t]) {
      const auto L = surface.lower_index(s);
      for (int a = 0; a < 3; ++a) c[size_t(a)] = std::min(c[size_t(a)], L[size_t(a)]);
    }
    const uint64_t id = uint64_t(c[0] + 1) + uint64_t(P[0]) * (uint64_t(c[1] + 1) + uint64_t(P[1]) * uint64_t(c[2] + 1));
    by_cell[t] = {id, uint32_t(t)};
  }
  tbb::parallel_sort(by_cell.begin(), by_cell.end());

  // Patches: connected triangles of one cell (union-find over its <= 12 sticks).
  for (size_t g = 0; g < by_cell.size();) {
    size_t e = g;
    while (e < by_cell.size() && by_cell[e].first == by_cell[g].first) ++e;
    uint32_t local[12];
    int parent[12];
    int count = 0;
    auto find_local = [&](uint32_t s) {
      for (int i = 0; i < count; ++i)
        if (local[i] == s) return i;
      if (count == 12) throw std::logic_error("surface net: more than 12 sticks in a cell");
      local[count] = s;
      parent[count] = count;
      return count++;
    };
    auto root = [&](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    for (size_t k = g; k < e; ++k) {
      const Triangle& tr = surface.triangles[by_cell[k].second];
      const int a = root(find_local(tr[0])), b = root(find_local(tr[1])), c = root(find_local(tr[2]));
      parent[b] = a;
      parent[root(c)] = a;
    }
    // The cell's lower corner (unpadded), from its id.
    const uint64_t id = by_cell[g].first;
    const std::array<int64_t, 3> cell{int64_t(id % uint64_t(P[0])) - 1, int64_t(id / uint64_t(P[0]) % uint64_t(P[1])) - 1,
                                      int64_t(id / (uint64_t(P[0]) * uint64_t(P[1]))) - 1};
    int patch_of_root[12], sticks_of_patch[12] = {};
    std::fill(patch_of_root, patch_of_root + 12, -1);
    const uint32_t first = uint32_t(x.size());
    for (int i = 0; i < count; ++i) {
      const int r = root(i);
      if (patch_of_root[r] < 0) {
        patch_of_root[r] = int(x.size() - first);
        x.push_back(Vec3::Zero());
        box.push_back({Vec3::Constant(HUGE_VAL), Vec3::Constant(-HUGE_VAL)});
      }
      ++sticks_of_patch[patch_of_root[r]];
      const uint32_t p = first + uint32_t(patch_of_root[r]);
      const uint32_t s = local[i];
      const int a = surface.axis(s), b = (a + 1) % 3, c = (a + 2) % 3;
      const auto L = surface.lower_index(s);
      const int64_t ob = L[size_t(b)] - cell[size_t(b)], oc = L[size_t(c)] - cell[size_t(c)];
      int slot = -1;
      for (int k = 0; k < 4; ++k)
        if (kSlotOffset[k][0] == ob && kSlotOffset[k][1] == oc) slot = k;
      if (slot < 0) throw std::logic_error("surface net: stick outside its cell");
      stick_patch[4 * s + size_t(slot)] = p;
      const Vec3 m = stick_midpoint(surface, s);
      x[p] += m;
      box[p].lo = box[p].lo.cwiseMin(m);
      box[p].hi = box[p].hi.cwiseMax(m);
    }
    const uint32_t patches = uint32_t(x.size()) - first;
    for (uint32_t p = first; p < x.size(); ++p) {
      x[p] /= double(sticks_of_patch[p - first]);
      if (patches == 1) {  // Gibson: the whole cell
        box[p].lo = index_vec(cell);
        box[p].hi = box[p].lo + Vec3::Ones();
      }
    }
    st.split_cells += patches > 1;
    g = e;
  }
  st.patch_vertices = x.size();
  for (uint32_t p : stick_patch)
    if (p == kNone) throw std::logic_error("surface net: a stick misses one of its four cells");

}

// Net edges used by four quads: split per ambiguous-face segment. The
// segment through stick s on that face cuts off s's inside sample.
void split_ambiguous_faces(const StickSurface& surface, Net& net, SurfaceNetStats& st) {
  const size_t ns = surface.stick_count();
  auto& x = net.x;
  auto& box = net.box;
  const auto& stick_patch = net.stick_patch;
  auto& face_vertex = net.face_vertex;
  {
    struct Use {
      uint32_t u, v;
      uint32_t stick;
      uint8_t k;
    };
    std::vector<Use> uses(4 * ns);
    for (size_t s = 0; s < ns; ++s)
      for (int k = 0; k < 4; ++k) {
        const uint32_t p = stick_patch[4 * s + size_t(k)], q = stick_patch[4 * s + size_t((k + 1) % 4)];
        uses[4 * s + size_t(k)] = {std::min(p, q), std::max(p, q), uint32_t(s), uint8_t(k)};
      }
    tbb::parallel_sort(uses.begin(), uses.end(), [](const Use& a, const Use& b) {
      return std::tie(a.u, a.v, a.stick, a.k) < std::tie(b.u, b.v, b.stick, b.k);
    });
    for (size_t g = 0; g < uses.size();) {
      size_t e = g;
      while (e < uses.size() && uses[e].u == uses[g].u && uses[e].v == uses[g].v) ++e;
      if (e - g == 4) {
        // Two segments: group the four uses by the inside sample they cut off.
        std::array<int64_t, 3> corner[4];
        for (size_t i = g; i < e; ++i) {
          const uint32_t s = uses[i].stick;
          auto I = surface.lower_index(s);
          if (!surface.lower_inside(s)) ++I[size_t(surface.axis(s))];
          corner[i - g] = I;
        }
        for (size_t i = g; i < e; ++i) {
          uint32_t m = kNone;
          for (size_t j = g; j < i; ++j)
            if (corner[j - g] == corner[i - g]) m = face_vertex[4 * uses[j].stick + uses[j].k];
          if (m == kNone) {
            // The quarter of the shared face at the inside corner.
            const uint32_t s = uses[i].stick;
            const int k = uses[i].k, k1 = (k + 1) % 4;
            const int a = surface.axis(s), b = (a + 1) % 3, c = (a + 2) % 3;
            const bool across_b = kSlotOffset[k][0] != kSlotOffset[k1][0];
            const int mo = across_b ? c : b;  // the face's in-plane axis other than a
            const int off = across_b ? kSlotOffset[k][1] : kSlotOffset[k][0];
            const auto L = surface.lower_index(s);
            Vec3 centre = index_vec(L);
            centre[a] += 0.5;
            centre[mo] += 0.5 - double(off);
            const Vec3 I = index_vec(corner[i - g]);
            m = uint32_t(x.size());
            x.push_back(0.5 * (I + centre));
            box.push_back({I.cwiseMin(centre), I.cwiseMax(centre)});
            ++st.face_vertices;
          }
          face_vertex[4 * uses[i].stick + uses[i].k] = m;
        }
      } else if (e - g != 2) {
        throw std::logic_error("surface net: a net edge used by " + std::to_string(e - g) + " quads");
      }
      g = e;
    }
  }

}

// Polygons, wound outward: slots 0,1,2,3 turn counter-clockwise around +a,
// which points out of the solid when the stick's lower sample is inside.
void net_polygons(const StickSurface& surface, Net& net, SurfaceNetStats& st) {
  const size_t ns = surface.stick_count();
  const auto& stick_patch = net.stick_patch;
  const auto& face_vertex = net.face_vertex;
  auto& poly = net.poly;
  auto& poly_off = net.poly_off;
  poly.reserve(4 * ns + 2 * st.face_vertices);
  for (size_t s = 0; s < ns; ++s) {
    static constexpr int kOut[2][4] = {{0, 3, 2, 1}, {0, 1, 2, 3}};
    const int* seq = kOut[surface.lower_inside(s) ? 1 : 0];
    for (int i = 0; i < 4; ++i) {
      const int cur = seq[i], nxt = seq[(i + 1) % 4];
      const int edge = nxt == (cur + 1) % 4 ? cur : nxt;
      poly.push_back(stick_patch[4 * s + size_t(cur)]);
      const uint32_t m = face_vertex[4 * s + size_t(edge)];
      if (m != kNone) poly.push_back(m);
    }
    poly_off.push_back(uint32_t(poly.size()));
  }
  st.quads = ns;

}

// Net adjacency: with consistent winding every directed polygon edge
// occurs once, so "next in my polygons" lists each neighbour exactly once.
void net_adjacency(const Net& net, std::vector<uint32_t>& off, std::vector<uint32_t>& adj) {
  const auto& poly = net.poly;
  const auto& poly_off = net.poly_off;
  const size_t nv = net.x.size();
  off.assign(nv + 1, 0);
  adj.resize(poly.size());
  for (size_t f = 0; f + 1 < poly_off.size(); ++f)
    for (uint32_t i = poly_off[f]; i < poly_off[f + 1]; ++i) ++off[poly[i] + 1];
  for (size_t v = 0; v < nv; ++v) off[v + 1] += off[v];
  {
    std::vector<uint32_t> fill(off.begin(), off.end() - 1);
    for (size_t f = 0; f + 1 < poly_off.size(); ++f) {
      const uint32_t b = poly_off[f], e = poly_off[f + 1];
      for (uint32_t i = b; i < e; ++i) adj[fill[poly[i]]++] = poly[i + 1 == e ? b : i + 1];
    }
  }
}

// The polygons as triangles: a quad by its shorter diagonal, a polygon
// through face vertices as a fan from the first of them.
void triangulate(const Net& net, size_t patch_vertices, Mesh& mesh) {
  const auto& poly = net.poly;
  const auto& poly_off = net.poly_off;
  mesh.triangles.reserve(2 * (poly_off.size() - 1));
  for (size_t f = 0; f + 1 < poly_off.size(); ++f) {
    const uint32_t b = poly_off[f], e = poly_off[f + 1];
    if (e - b == 4) {  // a quad: the shorter diagonal
      const uint32_t q0 = poly[b], q1 = poly[b + 1], q2 = poly[b + 2], q3 = poly[b + 3];
      const auto& p = mesh.positions;
      if ((p[q0] - p[q2]).squaredNorm() <= (p[q1] - p[q3]).squaredNorm()) {
        mesh.triangles.push_back({q0, q1, q2});
        mesh.triangles.push_back({q0, q2, q3});
      } else {
        mesh.triangles.push_back({q1, q2, q3});
        mesh.triangles.push_back({q1, q3, q0});
      }
      continue;
    }
    // A polygon through face vertices: a fan from the first of them.
    uint32_t apex = b;
    while (poly[apex] < patch_vertices) ++apex;
    const uint32_t len = e - b;
    for (uint32_t i = 1; i + 1 < len; ++i)
      mesh.triangles.push_back({poly[apex], poly[b + (apex - b + i) % len], poly[b + (apex - b + i + 1) % len]});
  }
}

}  // namespace

Mesh constrained_surface_net(const StickSurface& surface, const SurfaceNetOptions& o, SurfaceNetStats* stats) {
  if (!(o.threshold > 0)) throw UsageError("the stopping threshold must be > 0");
  if (o.max_iterations < 0) throw UsageError("the iteration cap must be >= 0");
  SurfaceNetStats st;
  auto t0 = std::chrono::steady_clock::now();
  const size_t ns = surface.stick_count();
  Net net;
  net.stick_patch.assign(4 * ns, kNone);
  net.face_vertex.assign(4 * ns, kNone);
  build_patches(surface, net, st);
  split_ambiguous_faces(surface, net, st);
  net_polygons(surface, net, st);
  std::vector<uint32_t> off, adj;
  net_adjacency(net, off, adj);
  st.seconds_build = seconds_since(t0);

  // Gibson's relaxation, clamped to the boxes.
  t0 = std::chrono::steady_clock::now();
  std::vector<Vec3>& x = net.x;
  {
    ProgressCounter progress(o.progress, "surface net relaxation", uint64_t(o.max_iterations));
    const detail::Relaxation r = detail::relax(
        x, off, adj,
        [&](size_t v, const Vec3& mean) { return Vec3(mean.cwiseMax(net.box[v].lo).cwiseMin(net.box[v].hi)); },
        o.threshold, o.max_iterations, progress);
    st.iterations = r.iterations;
    st.last_max_change = r.last_max_change;
    st.converged = r.converged;
  }
  st.seconds_relax = seconds_since(t0);

  Mesh mesh;
  mesh.positions.resize(x.size());
  for (size_t v = 0; v < x.size(); ++v) mesh.positions[v] = surface.lattice.to_physical(x[v]);
  triangulate(net, st.patch_vertices, mesh);
  if (surface.lattice.flips_orientation())
    for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  st.triangles = mesh.triangles.size();
  if (stats) *stats = st;
  return mesh;
}

}  // namespace voxpress
