// Solid, cuberille quads and Lanczos fairing (Muniz et al., Sections 4.2-4.3).

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/sentinel.h"
#include "voxpress/core/error.h"
#include "voxpress/voxart/polygonize.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

using detail::kNone;

uint32_t find(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

}  // namespace

std::vector<uint8_t> fill_solid(const ColorGrid& grid) {
  // Section 4.2: a buffer two voxels larger per axis, flood filled from its
  // corner through empty voxels (iteratively); whatever the fill does not
  // reach is solid.
  const int64_t P[3] = {grid.dims[0] + 2, grid.dims[1] + 2, grid.dims[2] + 2};
  const int64_t sy = P[0], sz = P[0] * P[1];
  std::vector<uint8_t> outside(uint64_t(P[0]) * uint64_t(P[1]) * uint64_t(P[2]), 0);
  std::vector<int64_t> stack{0};
  outside[0] = 1;
  const int64_t step[6] = {-1, 1, -sy, sy, -sz, sz};
  while (!stack.empty()) {
    const int64_t c = stack.back();
    stack.pop_back();
    const int64_t q0[3] = {c % sy, (c % sz) / sy, c / sz};
    for (int d = 0; d < 6; ++d) {
      int64_t q[3] = {q0[0], q0[1], q0[2]};
      q[d / 2] += d % 2 ? 1 : -1;
      if (q[d / 2] < 0 || q[d / 2] >= P[d / 2]) continue;
      const int64_t n = c + step[d];
      if (outside[size_t(n)] || grid.filled(q[0] - 1, q[1] - 1, q[2] - 1)) continue;
      outside[size_t(n)] = 1;
      stack.push_back(n);
    }
  }
  std::vector<uint8_t> solid(grid.voxels.size());
  for (int64_t k = 0; k < grid.dims[2]; ++k)
    for (int64_t j = 0; j < grid.dims[1]; ++j)
      for (int64_t i = 0; i < grid.dims[0]; ++i)
        solid[grid.index(i, j, k)] = !outside[size_t((i + 1) + (j + 1) * sy + (k + 1) * sz)];
  return solid;
}

namespace {

// The cuberille of a solid (Section 4.2): the quads between its voxels and
// the outside, over a grid padded by one voxel per side.
class Cuberille {
 public:
  Cuberille(const ColorGrid& grid, const std::vector<uint8_t>& filled)
      : grid_(grid), P{grid.dims[0] + 2, grid.dims[1] + 2, grid.dims[2] + 2}, sy(P[0]), sz(P[0] * P[1]),
        outside_(uint64_t(P[0]) * uint64_t(P[1]) * uint64_t(P[2]), 1), slot_(outside_.size(), kNone) {
    for (int64_t k = 0; k < grid.dims[2]; ++k)
      for (int64_t j = 0; j < grid.dims[1]; ++j)
        for (int64_t i = 0; i < grid.dims[0]; ++i) outside_[size_t(padded(i + 1, j + 1, k + 1))] = !filled[grid.index(i, j, k)];
  }

  // Faces: (cell, direction d = 2 * axis + (positive ? 1 : 0)).
  struct Face {
    int64_t cell;
    int dir;
  };
  std::vector<Face> faces;

  // Every face between a solid voxel and the outside; returns the enclosed
  // cavity voxels (filled, never touching the outside).
  uint64_t find_faces() {
    uint64_t cavities = 0;
    for (int64_t k = 1; k + 1 < P[2]; ++k)
      for (int64_t j = 1; j + 1 < P[1]; ++j)
        for (int64_t i = 1; i + 1 < P[0]; ++i) {
          const int64_t c = padded(i, j, k);
          if (outside_[size_t(c)]) continue;
          if (!grid_.filled(i - 1, j - 1, k - 1)) {
            ++cavities;
            continue;  // an enclosed cavity voxel never touches the outside
          }
          for (int d = 0; d < 6; ++d) {
            if (!outside_[size_t(c + step[d])]) continue;
            if (slot_[size_t(c)] == kNone) {
              slot_[size_t(c)] = uint32_t(slot_faces_.size() / 6);
              slot_faces_.resize(slot_faces_.size() + 6, kNone);
            }
            slot_faces_[6 * slot_[size_t(c)] + size_t(d)] = uint32_t(faces.size());
            faces.push_back({c, d});
          }
        }
    return cavities;
  }

  // The padded coordinates of a cell.
  std::array<int64_t, 3> coords(int64_t cell) const { return {cell % sy, (cell % sz) / sy, cell / sz}; }

  // Corner q of a face: lattice point (padded coordinates), counter-clockwise
  // seen from outside.
  std::array<int64_t, 3> corner(const Face& f, int q) const {
    const int a = f.dir / 2, u = (a + 1) % 3, v = (a + 2) % 3;
    static const int ccw[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, cw[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
    const int(*order)[2] = f.dir % 2 ? ccw : cw;
    std::array<int64_t, 3> p = coords(f.cell);
    p[size_t(a)] += f.dir % 2;
    p[size_t(u)] += order[q][0];
    p[size_t(v)] += order[q][1];
    return p;
  }

  // The key of the lattice edge p0 p1.
  int64_t lattice_edge(const std::array<int64_t, 3>& p0, const std::array<int64_t, 3>& p1) const {
    int axis = 0;
    while (p0[size_t(axis)] == p1[size_t(axis)]) ++axis;
    const auto& lo = p0[size_t(axis)] < p1[size_t(axis)] ? p0 : p1;
    return ((lo[2] * (P[1] + 1) + lo[1]) * (P[0] + 1) + lo[0]) * 3 + axis;
  }

  // Corners joined across each edge (classes in `parent`, 4 per face).
  // Going around the edge from a face, the next face is the one bounding
  // the same outside voxel: concave (the voxel diagonal to ours across the
  // edge is solid), flat (the voxel beside ours is), or convex (our own
  // next face). Where two solid voxels meet only along the edge, that joins
  // them (18-connected solids) unless the edge is in `separate` (sorted),
  // where each voxel keeps its own faces (6-connected).
  void join_corners(const std::vector<int64_t>& separate, std::vector<uint32_t>& parent) const {
    const auto solid = [&](int64_t c) { return !outside_[size_t(c)]; };
    for (uint32_t x = 0; x < parent.size(); ++x) parent[x] = x;
    for (uint32_t fi = 0; fi < faces.size(); ++fi) {
      const Face& f = faces[fi];
      std::array<std::array<int64_t, 3>, 4> cs;
      for (int q = 0; q < 4; ++q) cs[size_t(q)] = corner(f, q);
      for (int q = 0; q < 4; ++q) {
        const auto &p0 = cs[size_t(q)], &p1 = cs[size_t((q + 1) % 4)];
        // Tangent across the edge: the in-face axis along which the edge
        // sits at the far (or near) side of the face.
        int tdir = -1;
        for (int b = 0; b < 3; ++b) {
          if (b == f.dir / 2 || p0[size_t(b)] != p1[size_t(b)]) continue;
          const int64_t base = coords(f.cell)[size_t(b)];
          tdir = 2 * b + (p0[size_t(b)] > base ? 1 : 0);
        }
        const int64_t n = step[f.dir], t = step[tdir];
        Face g;
        const bool diagonal = solid(f.cell + n + t) && !solid(f.cell + t);
        if (diagonal && std::binary_search(separate.begin(), separate.end(), lattice_edge(p0, p1)))
          g = {f.cell, tdir};
        else if (solid(f.cell + n + t))
          g = {f.cell + n + t, tdir ^ 1};
        else if (solid(f.cell + t))
          g = {f.cell + t, f.dir};
        else
          g = {f.cell, tdir};
        const uint32_t gi = face_id(g.cell, g.dir);
        for (int r = 0; r < 4; ++r) {
          const auto pr = corner(g, r);
          for (int e = 0; e < 2; ++e)
            if (pr == (e ? p1 : p0)) {
              const uint32_t x = find(parent, 4 * fi + uint32_t((q + e) % 4)), y = find(parent, 4 * gi + uint32_t(r));
              if (x != y) parent[std::max(x, y)] = std::min(x, y);
            }
        }
      }
    }
  }

 private:
  int64_t padded(int64_t i, int64_t j, int64_t k) const { return i + j * sy + k * sz; }
  uint32_t face_id(int64_t cell, int dir) const { return slot_faces_[6 * slot_[size_t(cell)] + size_t(dir)]; }

  const ColorGrid& grid_;
  const int64_t P[3];
  const int64_t sy, sz;
  const int64_t step[6] = {-1, 1, -sy, sy, -sz, sz};
  std::vector<uint8_t> outside_;
  std::vector<uint32_t> slot_;  // boundary cell -> index into slot_faces_ / 6
  std::vector<uint32_t> slot_faces_;
};

}  // namespace

QuadMesh solid_cuberille(const ColorGrid& grid) {
  Cuberille cb(grid, fill_solid(grid));
  QuadMesh out;
  out.filled_cavities = cb.find_faces();
  const auto& faces = cb.faces;
  if (faces.empty()) throw InputError(grid.name, "the part holds no voxel");
  if (faces.size() > (size_t(1) << 29)) throw LimitError(grid.name, "too many voxel faces for one mesh");
  // An edge whose two sheets end on the same vertices at both ends (four
  // faces on one vertex pair) is marked separate and the pairing redone;
  // edges that stay doubled either way are reported to the caller.
  std::vector<int64_t> separate;  // sorted lattice edge keys
  std::vector<uint32_t> parent(4 * faces.size()), id(parent.size());
  std::vector<std::array<uint32_t, 3>> edge_use;  // (min vertex, max vertex, face) per quad edge
  for (int round = 0;; ++round) {
    cb.join_corners(separate, parent);
    uint32_t count = 0;
    std::fill(id.begin(), id.end(), kNone);
    for (uint32_t x = 0; x < parent.size(); ++x) {
      const uint32_t root = find(parent, x);
      if (id[root] == kNone) id[root] = count++;
      id[x] = id[root];
    }
    edge_use.clear();
    for (uint32_t fi = 0; fi < faces.size(); ++fi)
      for (uint32_t q = 0; q < 4; ++q) {
        const uint32_t a = id[4 * fi + q], b = id[4 * fi + (q + 1) % 4];
        edge_use.push_back({std::min(a, b), std::max(a, b), fi * 4 + q});
      }
    std::sort(edge_use.begin(), edge_use.end());
    std::vector<int64_t> doubled;
    for (size_t i = 0, j; i < edge_use.size(); i = j) {
      for (j = i; j < edge_use.size() && edge_use[j][0] == edge_use[i][0] && edge_use[j][1] == edge_use[i][1]; ++j) {
      }
      if (j - i > 2) {
        const uint32_t fi = edge_use[i][2] / 4, q = edge_use[i][2] % 4;
        doubled.push_back(cb.lattice_edge(cb.corner(faces[fi], int(q)), cb.corner(faces[fi], int((q + 1) % 4))));
      }
    }
    if (doubled.empty()) break;
    std::sort(doubled.begin(), doubled.end());
    doubled.erase(std::unique(doubled.begin(), doubled.end()), doubled.end());
    std::vector<int64_t> merged;
    std::set_union(separate.begin(), separate.end(), doubled.begin(), doubled.end(), std::back_inserter(merged));
    if (merged.size() == separate.size() || round > 8) {
      out.pinched_edges = doubled.size();
      break;
    }
    separate.swap(merged);
  }
  out.separated_edges = separate.size();
  out.quads.resize(faces.size());
  out.colors.resize(faces.size());
  out.centers.resize(faces.size());
  std::vector<std::array<int64_t, 3>> lattice;
  for (uint32_t fi = 0; fi < faces.size(); ++fi) {
    const Cuberille::Face& f = faces[fi];
    Vec3 centre = Vec3::Zero();
    for (int q = 0; q < 4; ++q) {
      const uint32_t v = id[4 * fi + uint32_t(q)];
      const auto p = cb.corner(f, q);
      const Vec3 x(double(p[0] - 1), double(p[1] - 1), double(p[2] - 1));
      if (v == out.positions.size()) {
        out.positions.push_back(x);
        lattice.push_back(p);
      }
      out.quads[fi][size_t(q)] = v;
      centre += x;
    }
    out.centers[fi] = centre / 4;
    const auto [i, j, k] = cb.coords(f.cell);
    out.colors[fi] = grid.voxels[grid.index(i - 1, j - 1, k - 1)];
  }
  std::sort(lattice.begin(), lattice.end());
  out.split_vertices = uint64_t(lattice.end() - std::unique(lattice.begin(), lattice.end()));
  return out;
}

void fair_lanczos(QuadMesh& mesh, double lambda) {
  // Section 4.3. Neighbours: every other vertex of the quads around a vertex
  // (edge and diagonal ones). Eq. (8) with unit weights per neighbour
  // direction (the paper's recommendation: a fixed distance, so that edges
  // of length 1 and sqrt(2) weigh alike), then Eq. (9)-(10) per coordinate.
  const size_t nv = mesh.positions.size();
  std::vector<uint32_t> start(nv + 1, 0);
  for (const auto& q : mesh.quads)
    for (uint32_t v : q) start[v + 1] += 3;
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> nb(start[nv]), fill(start.begin(), start.end() - 1);
  for (const auto& q : mesh.quads)
    for (int c = 0; c < 4; ++c)
      for (int o = 1; o < 4; ++o) nb[fill[q[size_t(c)]]++] = q[size_t((c + o) % 4)];
  const std::vector<Vec3> old = mesh.positions;
  auto kernel = [](double u) {  // Eq. (9)
    if (u == 0) return 0.0;
    const double pu = std::numbers::pi * u;
    const double l = 1 - 3 * std::sin(pu) * std::sin(pu / 3) / (pu * pu);
    return u > 0 ? l : -l;
  };
  detail::parallel_ranges(nv, 4096, [&](detail::IndexRange r) {
    std::vector<uint32_t> local;
    for (size_t v = r.begin(); v != r.end(); ++v) {
      local.assign(nb.begin() + start[v], nb.begin() + start[v + 1]);
      std::sort(local.begin(), local.end());
      local.erase(std::unique(local.begin(), local.end()), local.end());
      Vec3 sum = Vec3::Zero();
      for (uint32_t w : local) {
        const Vec3 d = old[w] - old[v];
        const double len = d.norm();
        if (len > 0) sum += d / len;
      }
      if (local.empty()) continue;
      const Vec3 u = lambda / double(local.size()) * sum;  // Eq. (8)
      mesh.positions[v] = old[v] + Vec3(kernel(u.x()), kernel(u.y()), kernel(u.z()));  // Eq. (10)
    }
  });
}

}  // namespace voxpress
