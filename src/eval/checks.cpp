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
// check_classification: the mesh is mapped to index space and every lattice
// row is classified exactly by RowRays (row_rays.h); a sample lying exactly on
// the surface is a violation.
#include "voxpress/eval/checks.h"

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
#include "row_rays.h"
#include "core/parallel.h"

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

namespace {

// 1. Indices: false (the check stops) on an out-of-range index or a
// non-finite coordinate.
bool check_indices(const Mesh& mesh, const MeshCheckOptions& options, MeshCheck& r) {
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
  const size_t cap = options.max_examples;
  std::vector<std::string> ex;
  for (size_t f = 0; f < T.size(); ++f)
    if (T[f][0] >= P.size() || T[f][1] >= P.size() || T[f][2] >= P.size()) {
      if (r.invalid_indices++ < cap) ex.push_back("face " + std::to_string(f));
    }
  add_problem(r, r.invalid_indices, "faces with out-of-range vertex indices", ex);
  if (r.invalid_indices) return false;
  for (const Vec3& p : P)
    if (!p.allFinite()) {
      r.problems.push_back("non-finite vertex coordinates");
      return false;
    }
  return true;
}

// Degenerate faces (repeated or collinear corners), flagged.
std::vector<uint8_t> check_degenerate(const Mesh& mesh, const MeshCheckOptions& options, MeshCheck& r) {
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
  const size_t cap = options.max_examples;
  std::vector<uint8_t> degenerate(T.size(), 0);
  std::vector<std::string> ex;
  for (size_t f = 0; f < T.size(); ++f) {
    const Triangle& t = T[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || detail::triangle_degenerate(P[t[0]], P[t[1]], P[t[2]])) {
      degenerate[f] = 1;
      if (r.degenerate_faces++ < cap) ex.push_back("face " + std::to_string(f));
    }
  }
  add_problem(r, r.degenerate_faces, "degenerate faces (repeated or collinear corners)", ex);
  return degenerate;
}

// 2. Edges: boundary, non-manifold and misoriented; faces joined across
// edges (components) and corners across manifold edges (vertex fans).
void check_edges(const Mesh& mesh, const MeshCheckOptions& options, MeshCheck& r, UnionFind& corners,
                 UnionFind& faces) {
  const auto& T = mesh.triangles;
  const size_t cap = options.max_examples;
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

// 3. Vertex fans: pinched and unreferenced vertices.
void check_fans(const Mesh& mesh, const MeshCheckOptions& options, MeshCheck& r, UnionFind& corners) {
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
  const size_t cap = options.max_examples;
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

// 4. Global measures: components, area, Euler characteristic, volume.
void global_measures(const Mesh& mesh, MeshCheck& r, UnionFind& faces) {
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
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

// 5. Self-intersections (degenerate faces left out).
void check_self_intersections(const Mesh& mesh, const MeshCheckOptions& options, const std::vector<uint8_t>& degenerate,
                              MeshCheck& r) {
  const auto& P = mesh.positions;
  const auto& T = mesh.triangles;
  const size_t cap = options.max_examples;
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

}  // namespace

MeshCheck check_mesh(const Mesh& mesh, const MeshCheckOptions& options) {
  MeshCheck r;
  r.vertices = mesh.positions.size();
  r.faces = mesh.triangles.size();
  if (!check_indices(mesh, options, r)) return r;
  const std::vector<uint8_t> degenerate = check_degenerate(mesh, options, r);
  UnionFind corners(3 * mesh.triangles.size());
  UnionFind faces(mesh.triangles.size());
  check_edges(mesh, options, r, corners, faces);
  check_fans(mesh, options, r, corners);
  global_measures(mesh, r, faces);
  if (options.self_intersections && !mesh.triangles.empty()) check_self_intersections(mesh, options, degenerate, r);
  return r;
}

// ---------------------------------------------------------------------------
namespace {

// Planes of samples a streamed check holds at once (a few tens of MB at 1024^2).
constexpr uint64_t kSlabSamples = uint64_t(32) << 20;

// The rows of planes [k0, k1) (padded indices allowed) against rays; `slab`
// holds the volume's planes from slab_k0 (samples beyond it are outside).
void classify_planes(const detail::RowRays& rays, const ClassificationOptions& options, const std::array<int64_t, 3>& lo,
                     const std::array<int64_t, 3>& hi, int64_t k0, int64_t k1, const BinaryVolume& slab,
                     int64_t slab_k0, ProgressCounter& progress, std::atomic<uint64_t>* tally, std::mutex& m,
                     std::vector<std::array<int64_t, 3>>& examples) {
  detail::parallel_for(k0, k1, [&](int64_t k) {
    std::vector<int> winding;
    std::vector<uint8_t> odd;
    std::vector<int64_t> on_surface;
    uint64_t local[3] = {0, 0, 0};
    std::vector<std::array<int64_t, 3>> local_ex;
    for (int64_t j = lo[1]; j <= hi[1]; ++j) {
      rays.classify(j, k, winding, odd, on_surface);
      auto next_on = on_surface.begin();
      for (int64_t i = lo[0]; i <= hi[0]; ++i) {
        int kind = -1;  // 0: inside found outside, 1: outside found inside, 2: on the surface
        if (next_on != on_surface.end() && *next_on == i) {
          ++next_on;
          kind = 2;
        } else {
          const size_t x = size_t(i - lo[0]);
          const bool inside = options.rule == ClassificationOptions::Rule::winding ? winding[x] > 0 : odd[x] != 0;
          const bool expected = slab.at(i, j, k - slab_k0);
          if (inside != expected) kind = expected ? 0 : 1;
        }
        if (kind >= 0) {
          ++local[kind];
          if (local_ex.size() < options.max_examples) local_ex.push_back({i, j, k});
        }
      }
    }
    for (int c = 0; c < 3; ++c) tally[c] += local[c];
    if (!local_ex.empty()) {
      std::lock_guard lock(m);
      examples.insert(examples.end(), local_ex.begin(), local_ex.end());
    }
    progress.add(1);
  });
}

// Both forms: `slab_of(k0, k1)` returns the volume's planes [k0, k1) (k0 is
// where the returned volume starts) for the in-volume planes.
ClassificationReport classify(const Mesh& mesh, const Lattice& L, const ClassificationOptions& options, int64_t slab,
                              const std::function<const BinaryVolume&(int64_t k0, int64_t k1)>& slab_of) {
  ClassificationReport rep;
  const int64_t pad = options.include_padding ? 1 : 0;
  const std::array<int64_t, 3> lo{-pad, -pad, -pad};
  const std::array<int64_t, 3> hi{L.dims[0] - 1 + pad, L.dims[1] - 1 + pad, L.dims[2] - 1 + pad};
  const Mat3 inv = L.index_to_physical_matrix().inverse();
  std::vector<Vec3> V(mesh.positions.size());
  for (size_t v = 0; v < V.size(); ++v) V[v] = inv * (mesh.positions[v] - L.origin);
  const detail::RowRays rays(std::move(V), mesh.triangles, lo, hi, L.flips_orientation());

  std::atomic<uint64_t> tally[3] = {0, 0, 0};  // inside found outside, outside found inside, on the surface
  std::mutex m;
  std::vector<std::array<int64_t, 3>> examples;
  ProgressCounter progress(options.progress, "classification", uint64_t(hi[2] - lo[2] + 1));
  const BinaryVolume none;  // the padding planes: every sample outside
  if (pad) classify_planes(rays, options, lo, hi, -1, 0, none, 0, progress, tally, m, examples);
  for (int64_t k0 = 0; k0 < L.dims[2]; k0 += slab) {
    const int64_t k1 = std::min(L.dims[2], k0 + slab);
    classify_planes(rays, options, lo, hi, k0, k1, slab_of(k0, k1), k0, progress, tally, m, examples);
  }
  if (pad) classify_planes(rays, options, lo, hi, L.dims[2], L.dims[2] + 1, none, 0, progress, tally, m, examples);
  rep.samples = uint64_t(hi[0] - lo[0] + 1) * uint64_t(hi[1] - lo[1] + 1) * uint64_t(hi[2] - lo[2] + 1);
  rep.inside_found_outside = tally[0];
  rep.outside_found_inside = tally[1];
  rep.on_surface = tally[2];
  rep.violations = rep.inside_found_outside + rep.outside_found_inside + rep.on_surface;
  std::sort(examples.begin(), examples.end(), [](const auto& x, const auto& y) {
    return std::tie(x[2], x[1], x[0]) < std::tie(y[2], y[1], y[0]);
  });
  if (examples.size() > options.max_examples) examples.resize(options.max_examples);
  rep.examples = examples;
  return rep;
}

}  // namespace

ClassificationReport check_classification(const Mesh& mesh, const BinaryVolume& volume,
                                          const ClassificationOptions& options) {
  // One slab: the whole volume, read in place.
  const int64_t nz = std::max<int64_t>(volume.lattice.dims[2], 1);
  return classify(mesh, volume.lattice, options, nz, [&](int64_t, int64_t) -> const BinaryVolume& { return volume; });
}

ClassificationReport check_classification(const Mesh& mesh, const Lattice& lattice, const PlaneReader& read,
                                          const ClassificationOptions& options, int64_t slab) {
  const uint64_t plane = std::max<uint64_t>(uint64_t(lattice.dims[0]) * uint64_t(lattice.dims[1]), 1);
  if (slab <= 0) slab = int64_t(std::max<uint64_t>(kSlabSamples / plane, 1));
  BinaryVolume current;
  return classify(mesh, lattice, options, slab, [&](int64_t k0, int64_t k1) -> const BinaryVolume& {
    current = read(k0, k1);
    if (current.lattice.dims != std::array<int64_t, 3>{lattice.dims[0], lattice.dims[1], k1 - k0} ||
        current.inside.size() != current.lattice.size())
      throw std::logic_error("check_classification: the plane reader returned the wrong planes");
    return current;
  });
}

}  // namespace voxpress
