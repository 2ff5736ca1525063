// Mesh validity and in/out classification checks.
//
// check_mesh, cheap to expensive:
//   1. indices in range; degenerate faces (repeated index, exactly collinear);
//   2. half-edge table sorted by undirected edge: boundary (1 face),
//      non-manifold (> 2) and misoriented (2 faces, same direction) edges;
//   3. vertex fans: corners of the two faces of each manifold edge are joined
//      (union-find); a vertex whose corners form more than one set has several
//      fans (a pinch); a vertex with no corner is unreferenced;
//   4. face components, Euler characteristic, volume, area;
//   5. self-intersections: BVH over face boxes, exact triangle-pair tests that
//      ignore what adjacent faces legitimately share (predicates.h).
//
// check_classification: the mesh is mapped to index space; each lattice row
// (j, k) is a ray along +i, symbolically perturbed to (j + e, k + e^2) so it
// never hits a vertex or edge exactly. A triangle crossed by the ray adds +1
// to the winding number of the samples after it when it faces -i (entering),
// -1 otherwise. Which samples lie after the crossing is decided exactly with
// orient3d against the triangle's plane; a sample on the plane and inside the
// triangle lies on the surface and is a violation.
#include "voxpress/eval/checks.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numeric>
#include <set>

#include "../core/bvh.h"
#include "../core/predicates.h"

namespace voxpress {
namespace {

class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), size_t(0)); }
  size_t find(size_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(size_t a, size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<size_t> parent_;
};

struct HalfEdge {
  uint64_t key;     // (min vertex << 32) | max vertex
  uint32_t face;
  uint8_t corner;   // the edge runs from corner to corner + 1 of face
  bool forward;     // min -> max
  bool operator<(const HalfEdge& o) const {
    return key != o.key ? key < o.key : (face != o.face ? face < o.face : corner < o.corner);
  }
};

std::string edge_name(uint64_t key) {
  return std::to_string(key >> 32) + "-" + std::to_string(key & 0xffffffffu);
}

void add_problem(MeshCheck& r, size_t count, const std::string& what, const std::vector<std::string>& examples) {
  if (count == 0) return;
  std::string s = std::to_string(count) + " " + what;
  if (!examples.empty()) {
    s += " (e.g. ";
    for (size_t i = 0; i < examples.size(); ++i) s += (i ? ", " : "") + examples[i];
    s += ")";
  }
  r.problems.push_back(s);
}

}  // namespace

MeshCheck check_mesh(const Mesh& mesh, const MeshCheckOptions& options) {
  MeshCheck r;
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
  r.vertices = P.size();
  r.faces = T.size();
  const size_t cap = options.max_examples;

  // 1. Indices and degeneracy.
  {
    std::vector<std::string> ex;
    for (size_t f = 0; f < T.size(); ++f)
      if (T[f][0] >= P.size() || T[f][1] >= P.size() || T[f][2] >= P.size()) {
        if (r.invalid_indices++ < cap) ex.push_back("face " + std::to_string(f));
      }
    add_problem(r, r.invalid_indices, "faces with out-of-range vertex indices", ex);
    if (r.invalid_indices) return r;
    for (const Vec3& p : P)
      if (!p.allFinite()) {
        r.problems.push_back("non-finite vertex coordinates");
        return r;
      }
  }
  std::vector<uint8_t> degenerate(T.size(), 0);
  {
    std::vector<std::string> ex;
    for (size_t f = 0; f < T.size(); ++f) {
      const Triangle& t = T[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || detail::triangle_degenerate(P[t[0]], P[t[1]], P[t[2]])) {
        degenerate[f] = 1;
        if (r.degenerate_faces++ < cap) ex.push_back("face " + std::to_string(f));
      }
    }
    add_problem(r, r.degenerate_faces, "degenerate faces (repeated or collinear corners)", ex);
  }

  // 2. Edges.
  std::vector<HalfEdge> he;
  he.reserve(3 * T.size());
  for (size_t f = 0; f < T.size(); ++f) {
    const Triangle& t = T[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = t[k], v = t[(k + 1) % 3];
      he.push_back({(uint64_t(std::min(u, v)) << 32) | std::max(u, v), uint32_t(f), uint8_t(k), u < v});
    }
  }
  tbb::parallel_sort(he.begin(), he.end());
  UnionFind corners(3 * T.size());
  UnionFind faces(T.size());
  {
    std::vector<std::string> exb, exn, exm;
    for (size_t i = 0; i < he.size();) {
      size_t j = i;
      while (j < he.size() && he[j].key == he[i].key) ++j;
      const size_t n = j - i;
      ++r.edges;
      for (size_t k = i + 1; k < j; ++k) faces.unite(he[i].face, he[k].face);
      if (n == 1) {
        if (r.boundary_edges++ < cap) exb.push_back(edge_name(he[i].key));
      } else if (n > 2) {
        if (r.nonmanifold_edges++ < cap) exn.push_back(edge_name(he[i].key) + " (" + std::to_string(n) + " faces)");
      } else {
        if (he[i].forward == he[i + 1].forward) {
          if (r.misoriented_edges++ < cap) exm.push_back(edge_name(he[i].key));
        }
        // Join the corners of both end vertices across the edge.
        for (uint32_t vtx : {uint32_t(he[i].key >> 32), uint32_t(he[i].key & 0xffffffffu)}) {
          auto corner_of = [&](const HalfEdge& h) {
            const Triangle& t = T[h.face];
            for (int c = 0; c < 3; ++c)
              if (t[c] == vtx) return 3 * size_t(h.face) + size_t(c);
            return size_t(0);
          };
          corners.unite(corner_of(he[i]), corner_of(he[i + 1]));
        }
      }
      i = j;
    }
    add_problem(r, r.boundary_edges, "boundary edges (the mesh is not closed)", exb);
    add_problem(r, r.nonmanifold_edges, "non-manifold edges", exn);
    add_problem(r, r.misoriented_edges, "edges whose two faces have inconsistent orientation", exm);
  }

  // 3. Vertex fans.
  {
    std::vector<int64_t> first_root(P.size(), -1);
    std::vector<uint8_t> pinched(P.size(), 0);
    for (size_t f = 0; f < T.size(); ++f) {
      const Triangle& t = T[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
      for (int c = 0; c < 3; ++c) {
        const int64_t root = int64_t(corners.find(3 * f + size_t(c)));
        int64_t& fr = first_root[t[c]];
        if (fr < 0)
          fr = root;
        else if (fr != root)
          pinched[t[c]] = 1;
      }
    }
    std::vector<std::string> exv, exu;
    for (size_t v = 0; v < P.size(); ++v) {
      if (first_root[v] < 0) {
        if (r.unreferenced_vertices++ < cap) exu.push_back("vertex " + std::to_string(v));
      } else if (pinched[v]) {
        if (r.nonmanifold_vertices++ < cap) exv.push_back("vertex " + std::to_string(v));
      }
    }
    add_problem(r, r.nonmanifold_vertices, "non-manifold vertices (more than one fan of faces)", exv);
    add_problem(r, r.unreferenced_vertices, "unreferenced vertices", exu);
  }

  // 4. Global measures.
  {
    size_t referenced = r.vertices - r.unreferenced_vertices;
    size_t nf = 0;
    for (size_t f = 0; f < T.size(); ++f) {
      const Triangle& t = T[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
      ++nf;
      if (faces.find(f) == f) ++r.components;
      r.area += 0.5 * (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]).norm();
    }
    r.euler = int64_t(referenced) - int64_t(r.edges) + int64_t(nf);
    r.signed_volume = signed_volume(mesh);
    if (r.closed() && r.manifold() && r.oriented() && r.faces > 0 && r.signed_volume < 0)
      r.problems.push_back("inward orientation: the enclosed volume is negative (" + std::to_string(r.signed_volume) +
                           ")");
  }

  // 5. Self-intersections.
  if (options.self_intersections && !T.empty()) {
    std::vector<detail::Aabb> boxes(T.size());
    std::vector<uint32_t> ids;
    for (size_t f = 0; f < T.size(); ++f) {
      if (degenerate[f]) continue;
      detail::Aabb b;
      for (uint32_t v : T[f]) b.grow(P[v]);
      boxes[ids.size()] = b;
      ids.push_back(uint32_t(f));
    }
    boxes.resize(ids.size());
    const detail::Bvh bvh(boxes);
    std::atomic<size_t> count{0};
    std::mutex m;
    std::set<std::pair<uint32_t, uint32_t>> examples;  // the smallest pairs, deterministic
    bvh.for_each_overlapping_pair([&](uint32_t a, uint32_t b) {
      const uint32_t fa = ids[a], fb = ids[b];
      const Triangle& ta = T[fa];
      const Triangle& tb = T[fb];
      const Vec3 pa[3] = {P[ta[0]], P[ta[1]], P[ta[2]]};
      const Vec3 pb[3] = {P[tb[0]], P[tb[1]], P[tb[2]]};
      const uint32_t ia[3] = {ta[0], ta[1], ta[2]};
      const uint32_t ib[3] = {tb[0], tb[1], tb[2]};
      if (!detail::triangles_intersect(pa, ia, pb, ib)) return;
      count.fetch_add(1, std::memory_order_relaxed);
      std::lock_guard lock(m);
      examples.insert({std::min(fa, fb), std::max(fa, fb)});
      if (examples.size() > cap) examples.erase(std::prev(examples.end()));
    });
    r.self_intersections = count.load();
    r.self_intersections_checked = true;
    std::vector<std::string> ex;
    for (auto [a, b] : examples) ex.push_back("faces " + std::to_string(a) + " and " + std::to_string(b));
    add_problem(r, r.self_intersections, "intersecting face pairs", ex);
  }
  return r;
}

// ---------------------------------------------------------------------------
namespace {

struct Crossing {
  int64_t before;  // last sample index strictly before the crossing (may be -2)
  int delta;       // winding change for samples after it
};

// Perturbed 2D orientation of q = (qy + e, qz + e^2) against edge a -> b (yz).
int perturbed_orient(const Vec3& a, const Vec3& b, double qy, double qz) {
  const int s = detail::orient2d(a.y(), a.z(), b.y(), b.z(), qy, qz);
  if (s != 0) return s;
  if (a.z() != b.z()) return a.z() > b.z() ? 1 : -1;  // d/d(qy) = a.z - b.z
  if (a.y() != b.y()) return b.y() > a.y() ? 1 : -1;  // d/d(qz) = b.y - a.y
  return 0;
}

// Does the closed yz-projection of triangle (a, b, c) contain (qy, qz)?
bool touches_row(const Vec3& a, const Vec3& b, const Vec3& c, int sigma, double qy, double qz) {
  const int s1 = detail::orient2d(a.y(), a.z(), b.y(), b.z(), qy, qz);
  const int s2 = detail::orient2d(b.y(), b.z(), c.y(), c.z(), qy, qz);
  const int s3 = detail::orient2d(c.y(), c.z(), a.y(), a.z(), qy, qz);
  if (sigma != 0) return s1 * sigma >= 0 && s2 * sigma >= 0 && s3 * sigma >= 0;
  // Degenerate projection (a segment or a point): (qy, qz) must be collinear
  // with it and within its extent.
  if (s1 != 0 || s2 != 0 || s3 != 0) return false;
  const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
  const double zlo = std::min({a.z(), b.z(), c.z()}), zhi = std::max({a.z(), b.z(), c.z()});
  return ylo <= qy && qy <= yhi && zlo <= qz && qz <= zhi;
}

}  // namespace

ClassificationReport check_classification(const Mesh& mesh, const BinaryVolume& volume,
                                          const ClassificationOptions& options) {
  ClassificationReport rep;
  const Lattice& L = volume.lattice;
  const int64_t nx = L.dims[0], ny = L.dims[1], nz = L.dims[2];
  const int64_t pad = options.include_padding ? 1 : 0;
  const int64_t i0 = -pad, i1 = nx - 1 + pad;  // sample range along each row
  const int64_t j0 = -pad, j1 = ny - 1 + pad, k0 = -pad, k1 = nz - 1 + pad;
  const int64_t rows_y = j1 - j0 + 1, rows_z = k1 - k0 + 1;

  // Mesh in index space.
  const bool mirrored = L.flips_orientation();
  const Mat3 inv = L.index_to_physical_matrix().inverse();
  std::vector<Vec3> V(mesh.positions.size());
  for (size_t v = 0; v < V.size(); ++v) V[v] = inv * (mesh.positions[v] - L.origin);

  // Bin (triangle, row) hits: count, prefix-sum, fill.
  struct Hit {
    uint32_t tri;
    int sigma;      // sign of the yz-projected area (= sign of the normal's x); 0: parallel to the rays
    bool crossing;  // the perturbed ray crosses it (else it only touches the row line)
  };
  auto row_of = [&](int64_t j, int64_t k) { return size_t((k - k0) * rows_y + (j - j0)); };
  std::vector<uint32_t> start(size_t(rows_y * rows_z) + 1, 0);
  auto for_each_hit = [&](auto&& emit) {
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      const Triangle& t = mesh.triangles[f];
      const Vec3 &a = V[t[0]], &b = V[t[1]], &c = V[t[2]];
      const int sigma = detail::orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z());
      const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
      const double zlo = std::min({a.z(), b.z(), c.z()}), zhi = std::max({a.z(), b.z(), c.z()});
      const int64_t ja = std::max<int64_t>(j0, int64_t(std::ceil(ylo))), jb = std::min<int64_t>(j1, int64_t(std::floor(yhi)));
      const int64_t ka = std::max<int64_t>(k0, int64_t(std::ceil(zlo))), kb = std::min<int64_t>(k1, int64_t(std::floor(zhi)));
      for (int64_t k = ka; k <= kb; ++k)
        for (int64_t j = ja; j <= jb; ++j) {
          const double qy = double(j), qz = double(k);
          if (sigma != 0) {
            const int s1 = perturbed_orient(a, b, qy, qz), s2 = perturbed_orient(b, c, qy, qz),
                      s3 = perturbed_orient(c, a, qy, qz);
            if (s1 == sigma && s2 == sigma && s3 == sigma) {
              emit(row_of(j, k), Hit{uint32_t(f), sigma, true});
              continue;
            }
          }
          // Not crossed by the perturbed ray, but the row line itself may
          // touch the closed triangle: samples there could lie on it.
          if (touches_row(a, b, c, sigma, qy, qz)) emit(row_of(j, k), Hit{uint32_t(f), sigma, false});
        }
    }
  };
  for_each_hit([&](size_t row, Hit) { ++start[row + 1]; });
  for (size_t r = 1; r < start.size(); ++r) start[r] += start[r - 1];
  std::vector<Hit> hits(start.back());
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for_each_hit([&](size_t row, Hit h) { hits[fill[row]++] = h; });
  }

  std::atomic<uint64_t> in_out{0}, out_in{0}, on{0};
  std::mutex m;
  std::vector<std::array<int64_t, 3>> examples;
  ProgressCounter progress(options.progress, "classification", uint64_t(rows_z));
  tbb::parallel_for(k0, k1 + 1, [&](int64_t k) {
    std::vector<Crossing> cross;
    std::vector<int> winding(size_t(i1 - i0 + 2));
    std::vector<int> parity(size_t(i1 - i0 + 2));
    uint64_t local[3] = {0, 0, 0};
    std::vector<std::array<int64_t, 3>> local_ex;
    for (int64_t j = j0; j <= j1; ++j) {
      const size_t row = row_of(j, k);
      cross.clear();
      std::vector<int64_t> on_samples;
      for (uint32_t h = start[row]; h < start[row + 1]; ++h) {
        const Triangle& t = mesh.triangles[hits[h].tri];
        const Vec3 &a = V[t[0]], &b = V[t[1]], &c = V[t[2]];
        const int sigma = hits[h].sigma;
        if (!hits[h].crossing) {
          // Touching only: report the samples lying exactly on the triangle.
          auto lies_on = [&](int64_t i) {
            const Vec3 p{double(i), double(j), double(k)};
            return detail::segment_intersects_triangle(p, p, a, b, c);
          };
          double lo = std::min({a.x(), b.x(), c.x()}), hi = std::max({a.x(), b.x(), c.x()});
          if (sigma != 0) {  // a single point of the row line is on the plane
            const Vec3 n = (b - a).cross(c - a);
            const double xc = a.x() - (n.y() * (double(j) - a.y()) + n.z() * (double(k) - a.z())) / n.x();
            if (std::isfinite(xc)) lo = hi = xc;
          }
          const int64_t from = std::max<int64_t>(i0, int64_t(std::floor(lo)) - 1);
          const int64_t to = std::min<int64_t>(i1, int64_t(std::ceil(hi)) + 1);
          for (int64_t i = from; i <= to; ++i)
            if (lies_on(i)) on_samples.push_back(i);
          continue;
        }
        // s(i) < 0: sample i before the crossing; > 0 after; 0 on the triangle.
        auto s = [&](int64_t i) { return detail::orient3d(a, b, c, Vec3(double(i), double(j), double(k))) * sigma; };
        const Vec3 n = (b - a).cross(c - a);
        double xc = a.x() - (n.y() * (double(j) - a.y()) + n.z() * (double(k) - a.z())) / n.x();
        if (!std::isfinite(xc)) xc = 0.5 * double(i0 + i1);
        int64_t before = std::clamp<int64_t>(int64_t(std::floor(xc)), i0 - 1, i1);
        while (before + 1 <= i1 && s(before + 1) < 0) ++before;
        while (before >= i0 && s(before) >= 0) --before;
        if (before + 1 <= i1 && s(before + 1) == 0) on_samples.push_back(before + 1);
        // Entering the solid (outward normal towards -i) raises the winding
        // number; mapping to index space mirrors orientation when the lattice does.
        cross.push_back({before, (sigma < 0) != mirrored ? 1 : -1});
      }
      std::fill(winding.begin(), winding.end(), 0);
      std::fill(parity.begin(), parity.end(), 0);
      for (const Crossing& c : cross) {
        winding[size_t(c.before + 1 - i0)] += c.delta;
        parity[size_t(c.before + 1 - i0)] ^= 1;
      }
      std::sort(on_samples.begin(), on_samples.end());
      on_samples.erase(std::unique(on_samples.begin(), on_samples.end()), on_samples.end());
      auto next_on = on_samples.begin();
      int w = 0, par = 0;
      for (int64_t i = i0; i <= i1; ++i) {
        w += winding[size_t(i - i0)];
        par ^= parity[size_t(i - i0)];
        int kind = -1;  // 0: inside found outside, 1: outside found inside, 2: on the surface
        if (next_on != on_samples.end() && *next_on == i) {
          ++next_on;
          kind = 2;
        } else {
          const bool inside = options.rule == ClassificationOptions::Rule::winding ? w > 0 : par != 0;
          const bool expected = volume.at(i, j, k);
          if (inside != expected) kind = expected ? 0 : 1;
        }
        if (kind >= 0) {
          ++local[kind];
          if (local_ex.size() < options.max_examples) local_ex.push_back({i, j, k});
        }
      }
    }
    in_out += local[0];
    out_in += local[1];
    on += local[2];
    if (!local_ex.empty()) {
      std::lock_guard lock(m);
      examples.insert(examples.end(), local_ex.begin(), local_ex.end());
    }
    progress.add(1);
  });
  rep.samples = uint64_t(i1 - i0 + 1) * uint64_t(rows_y) * uint64_t(rows_z);
  rep.inside_found_outside = in_out;
  rep.outside_found_inside = out_in;
  rep.on_surface = on;
  rep.violations = rep.inside_found_outside + rep.outside_found_inside + rep.on_surface;
  std::sort(examples.begin(), examples.end(), [](const auto& x, const auto& y) {
    return std::tie(x[2], x[1], x[0]) < std::tie(y[2], y[1], y[0]);
  });
  if (examples.size() > options.max_examples) examples.resize(options.max_examples);
  rep.examples = examples;
  return rep;
}

}  // namespace voxpress
