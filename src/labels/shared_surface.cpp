// The shared midpoint surface of a label map: every cube's label case
// (label_cases.h), vertices named by global keys so that neighbouring cubes
// meet on the same stick and face vertices, then one sort of the keys.
#include "voxpress/labels/shared_surface.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

#include "voxpress/core/error.h"
#include "voxpress/extract/cube_cases.h"
#include "voxpress/labels/label_cases.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

// Vertex kinds per padded sample: sticks along x, y, z; face centres normal
// to x, y, z; the apexes of its cube.
constexpr uint64_t kKinds = 6 + uint64_t(kMaxApexes);

struct Keys {
  uint64_t px, py;
  uint64_t key(const std::array<int64_t, 3>& p, uint64_t kind) const {
    return ((uint64_t(p[2]) * py + uint64_t(p[1])) * kKinds + kind) * px + uint64_t(p[0]);
  }
  // padded sample and kind of a key
  std::pair<std::array<int64_t, 3>, uint64_t> decode(uint64_t key) const {
    const uint64_t p = key % px, rest = key / px, kind = rest % kKinds, row = rest / kKinds;
    return {{int64_t(p), int64_t(row % py), int64_t(row / py)}, kind};
  }
};

// The distinct entries of one per-triangle array of every piece, increasing.
template <class T, size_t N>
std::vector<T> distinct(const std::vector<SharedPiece>& pieces, std::vector<std::array<T, N>> SharedPiece::*field) {
  std::vector<T> out;
  for (const SharedPiece& p : pieces)
    for (const auto& e : p.*field) out.insert(out.end(), e.begin(), e.end());
  tbb::parallel_sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

SharedPiece extract_shared_piece(const ScalarVolume& volume, const Box& read, const Box& core,
                                 const std::array<int64_t, 3>& n) {
  if (volume.components != 1) throw InputError(volume.source, "a label map has one value per sample");
  if (volume.lattice.dims != read.dims()) throw std::logic_error("extract_shared_piece: the samples are not the read box");
  // Sample labels, validated.
  std::vector<uint32_t> lab(volume.lattice.size());
  std::atomic<bool> bad{false};
  detail::parallel_ranges(lab.size(), 1 << 16, [&](detail::IndexRange r) {
    for (uint64_t i = r.begin(); i < r.end(); ++i) {
      const double x = volume.value(i);
      if (!(x >= 0 && x <= 4294967295.0 && x == std::floor(x))) bad = true;
      else lab[i] = uint32_t(x);
    }
  });
  if (bad) throw InputError(volume.source, "a label map holds whole numbers from 0 to 2^32 - 1 (found another value)");
  const auto& rd = read.dims();
  auto at = [&](int64_t i, int64_t j, int64_t k) -> uint32_t {  // unpadded, whole volume; background beyond
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return 0;
    return lab[size_t((i - read.lo[0]) + rd[0] * ((j - read.lo[1]) + rd[1] * (k - read.lo[2])))];
  };
  const Keys keys{uint64_t(n[0] + 2), uint64_t(n[1] + 2)};
  // Owned cubes by padded lower corner (p, q, r) in [0, n]: the unpadded
  // corner p - 1, clamped into the volume, lies in the core.
  std::array<int64_t, 3> first{}, last{};
  for (size_t a = 0; a < 3; ++a) {
    first[a] = core.lo[a] == 0 ? 0 : core.lo[a] + 1;
    last[a] = core.hi[a];
  }
  std::vector<SharedPiece> layers(size_t(last[2] - first[2] + 1));
  detail::parallel_ranges(size_t(last[2] + 1 - first[2]), 1, [&](detail::IndexRange rr) {
    for (int64_t r = first[2] + int64_t(rr.begin()); r < first[2] + int64_t(rr.end()); ++r) {
      SharedPiece& out = layers[size_t(r - first[2])];
      for (int64_t q = first[1]; q <= last[1]; ++q)
        for (int64_t p = first[0]; p <= last[0]; ++p) {
          std::array<uint32_t, 8> c;
          bool same = true;
          for (int k = 0; k < 8; ++k) {
            c[size_t(k)] = at(p - 1 + (k & 1), q - 1 + ((k >> 1) & 1), r - 1 + ((k >> 2) & 1));
            same = same && c[size_t(k)] == c[0];
          }
          if (same) continue;
          const uint64_t cube_id = uint64_t(p) + keys.px * (uint64_t(q) + keys.py * uint64_t(r));
          int distinct = 0;
          std::array<uint32_t, 8> value{};  // of each rank
          const LabelPattern pattern = label_pattern(c, &distinct, &value);
          const LabelCase* lc = nullptr;
          try {
            lc = &label_case(pattern);
          } catch (const std::logic_error&) {
            if (cube_id < out.underivable_cube) {
              out.underivable_cube = cube_id;
              out.underivable = "the cube at sample (" + std::to_string(p - 1) + ", " + std::to_string(q - 1) + ", " +
                                std::to_string(r - 1) + ") joins " + std::to_string(distinct) +
                                " labels in a way shared surfaces do not handle yet (issue 54)";
            }
            continue;
          }
          const std::array<int64_t, 3> cube{p, q, r};
          auto vertex_key = [&](int v) {
            if (v < 12) {
              const int a = cube_edge_axis(v), c0 = cube_edge_corner(v, 0);
              return keys.key({p + (c0 & 1), q + ((c0 >> 1) & 1), r + ((c0 >> 2) & 1)}, uint64_t(a));
            }
            if (v < kApex) {
              const int f = v - kFaceCenter, a = f / 2, side = f % 2;
              std::array<int64_t, 3> lo = cube;
              lo[size_t(a)] += side;
              return keys.key(lo, uint64_t(3 + a));
            }
            return keys.key(cube, uint64_t(6 + (v - kApex)));
          };
          for (size_t k = 0; k < lc->apexes.size(); ++k)
            out.apexes.push_back({keys.key(cube, 6 + k), lc->apexes[k]});
          for (const auto& t : lc->triangles) {
            out.cube.push_back(cube_id);
            out.keys.push_back({vertex_key(t.v[0]), vertex_key(t.v[1]), vertex_key(t.v[2])});
            out.values.push_back({value[t.in], value[t.out]});
          }
        }
    }
  });
  // The layers in order, into one piece.
  SharedPiece out;
  size_t m = 0, a = 0;
  for (const SharedPiece& l : layers) m += l.cube.size(), a += l.apexes.size();
  out.cube.reserve(m);
  out.keys.reserve(m);
  out.values.reserve(m);
  out.apexes.reserve(a);
  for (SharedPiece& l : layers) {
    out.cube.insert(out.cube.end(), l.cube.begin(), l.cube.end());
    out.keys.insert(out.keys.end(), l.keys.begin(), l.keys.end());
    out.values.insert(out.values.end(), l.values.begin(), l.values.end());
    out.apexes.insert(out.apexes.end(), l.apexes.begin(), l.apexes.end());
    if (l.underivable_cube < out.underivable_cube) {
      out.underivable_cube = l.underivable_cube;
      out.underivable = std::move(l.underivable);
    }
    l = SharedPiece{};
  }
  return out;
}

SharedSurface assemble_shared_surface(const Lattice& lattice, std::vector<SharedPiece> pieces,
                                      const std::string& source) {
  const auto& n = lattice.dims;
  const Keys keys{uint64_t(n[0] + 2), uint64_t(n[1] + 2)};
  const SharedPiece* worst = nullptr;
  for (const SharedPiece& p : pieces)
    if (p.underivable_cube != UINT64_MAX && (!worst || p.underivable_cube < worst->underivable_cube)) worst = &p;
  if (worst) throw InputError(source, worst->underivable);

  // Triangles in cube order: a cube's triangles all come from one piece,
  // consecutive, so (cube, place in the concatenation) is a total order.
  size_t m = 0;
  for (const SharedPiece& p : pieces) m += p.cube.size();
  std::vector<std::pair<uint64_t, uint64_t>> order;  // (cube, piece << 40 | index)
  bool sorted = true;
  if (pieces.size() > 1) {
    order.reserve(m);
    for (size_t p = 0; p < pieces.size(); ++p)
      for (size_t i = 0; i < pieces[p].cube.size(); ++i) order.push_back({pieces[p].cube[i], (uint64_t(p) << 40) | i});
    tbb::parallel_sort(order.begin(), order.end());
    sorted = false;
  }
  auto tri = [&](size_t i) -> std::pair<const SharedPiece*, size_t> {
    if (sorted) return {&pieces[0], i};
    const uint64_t ref = order[i].second;
    return {&pieces[size_t(ref >> 40)], size_t(ref & ((uint64_t(1) << 40) - 1))};
  };

  SharedSurface out;
  out.lattice = lattice;
  {
    std::vector<uint32_t> values = distinct(pieces, &SharedPiece::values);
    if (values.empty()) throw InputError(source, "the volume is empty: every sample is the background, 0");
    if (values[0] != 0) values.insert(values.begin(), 0u);  // beyond the lattice is background
    out.labels = std::move(values);
  }
  auto index_of = [&](uint32_t value) {
    return uint32_t(std::lower_bound(out.labels.begin(), out.labels.end(), value) - out.labels.begin());
  };

  // Vertices: the keys in increasing order.
  const std::vector<uint64_t> all = distinct(pieces, &SharedPiece::keys);
  if (all.size() >= UINT32_MAX) throw LimitError(source, "more than 2^32 - 1 vertices");
  std::vector<std::pair<uint64_t, Vec3>> apex_places;  // key, place in its cube
  for (SharedPiece& p : pieces) {
    apex_places.insert(apex_places.end(), p.apexes.begin(), p.apexes.end());
    p.apexes = {};
  }
  tbb::parallel_sort(apex_places.begin(), apex_places.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
  const Mat3 M = lattice.index_to_physical_matrix();
  out.mesh.positions.resize(all.size());
  out.kind.resize(all.size());
  out.corner.resize(all.size());
  detail::parallel_ranges(all.size(), 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const auto [s, kind] = keys.decode(all[i]);
      Vec3 x(double(s[0] - 1), double(s[1] - 1), double(s[2] - 1));
      out.kind[i] = uint8_t(std::min<uint64_t>(kind, 6));
      out.corner[i] = {s[0] - 1, s[1] - 1, s[2] - 1};
      if (kind >= 6) continue;  // an apex: placed below, from its place in the cube
      if (kind < 3) {
        x[int(kind)] += 0.5;
      } else {
        for (int a = 0; a < 3; ++a)
          if (a != int(kind - 3)) x[a] += 0.5;
      }
      out.mesh.positions[i] = lattice.origin + M * x;
    }
  });
  for (uint32_t i = 0; i < all.size(); ++i) {
    const uint8_t kind = out.kind[i];
    (kind < 3 ? out.stick_vertices : kind < 6 ? out.face_vertices : out.apex_vertices)++;
    if (kind < 6) continue;
    const Vec3 place = std::lower_bound(apex_places.begin(), apex_places.end(), all[i],
                                        [](const auto& e, uint64_t k) { return e.first < k; })
                           ->second;
    out.apexes.push_back({i, place});
    const auto& c = out.corner[i];
    out.mesh.positions[i] = lattice.origin + M * (Vec3(double(c[0]), double(c[1]), double(c[2])) + place);
  }
  // Triangles in cube order, the keys looked up.
  out.mesh.triangles.resize(m);
  out.sides.resize(m);
  const bool flip = lattice.flips_orientation();
  detail::parallel_ranges(m, 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const auto [piece, at] = tri(i);
      Triangle t;
      for (int v = 0; v < 3; ++v)
        t[size_t(v)] = uint32_t(std::lower_bound(all.begin(), all.end(), piece->keys[at][size_t(v)]) - all.begin());
      if (flip) std::swap(t[1], t[2]);
      out.mesh.triangles[i] = t;
      out.sides[i] = {index_of(piece->values[at][0]), index_of(piece->values[at][1])};
    }
  });
  return out;
}

SharedSurface extract_shared_surface(const ScalarVolume& volume) {
  if (volume.components != 1) throw InputError(volume.source, "a label map has one value per sample");
  volume.lattice.validate();
  const Box all{{0, 0, 0}, volume.lattice.dims};
  std::vector<SharedPiece> one;
  one.push_back(extract_shared_piece(volume, all, all, volume.lattice.dims));
  return assemble_shared_surface(volume.lattice, std::move(one), volume.source);
}

Mesh label_mesh(const SharedSurface& s, uint32_t label) {
  Mesh m;
  std::vector<uint32_t> id(s.mesh.positions.size(), UINT32_MAX);
  std::vector<uint8_t> used(s.mesh.positions.size(), 0);
  for (size_t f = 0; f < s.sides.size(); ++f)
    if (s.sides[f][0] == label || s.sides[f][1] == label)
      for (uint32_t v : s.mesh.triangles[f]) used[v] = 1;
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) {
      id[v] = uint32_t(m.positions.size());
      m.positions.push_back(s.mesh.positions[v]);
    }
  for (size_t f = 0; f < s.sides.size(); ++f) {
    if (s.sides[f][0] != label && s.sides[f][1] != label) continue;
    const Triangle& t = s.mesh.triangles[f];
    Triangle u{id[t[0]], id[t[1]], id[t[2]]};
    if (s.sides[f][1] == label) std::swap(u[1], u[2]);  // it is this triangle's out side: outward is the other way
    m.triangles.push_back(u);
  }
  return m;
}

Mesh interfaces_mesh(const SharedSurface& s) {
  Mesh m = s.mesh;
  MeshAttribute in{"label_in", ScalarType::u32, {}}, out{"label_out", ScalarType::u32, {}};
  in.values.reserve(s.sides.size());
  out.values.reserve(s.sides.size());
  for (const auto& sd : s.sides) {
    in.values.push_back(double(s.labels[sd[0]]));
    out.values.push_back(double(s.labels[sd[1]]));
  }
  m.face_attributes = {std::move(in), std::move(out)};
  return m;
}

}  // namespace voxpress
