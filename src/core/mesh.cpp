#include "voxpress/core/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "voxpress/core/error.h"

namespace voxpress {

const MeshAttribute* Mesh::vertex_attribute(const std::string& name) const {
  for (const auto& a : vertex_attributes)
    if (a.name == name) return &a;
  return nullptr;
}

const MeshAttribute* Mesh::face_attribute(const std::string& name) const {
  for (const auto& a : face_attributes)
    if (a.name == name) return &a;
  return nullptr;
}

void Mesh::validate(const std::string& source) const {
  const size_t nv = positions.size();
  for (size_t f = 0; f < triangles.size(); ++f)
    for (uint32_t v : triangles[f])
      if (v >= nv)
        throw InputError(source, "face " + std::to_string(f) + " uses vertex " + std::to_string(v) + " but there are " +
                                     std::to_string(nv) + " vertices");
  for (size_t e = 0; e < edges.size(); ++e)
    if (edges[e][0] >= nv || edges[e][1] >= nv)
      throw InputError(source, "edge " + std::to_string(e) + " uses a vertex beyond the " + std::to_string(nv) + " vertices");
  if (!normals.empty() && normals.size() != nv) throw InputError(source, "normal count differs from vertex count");
  if (!colors.empty() && colors.size() != nv) throw InputError(source, "color count differs from vertex count");
  if (!uvs.empty() && uvs.size() != nv) throw InputError(source, "texture coordinate count differs from vertex count");
  if (!texture.empty() && (texture.width < 0 || texture.height < 0 ||
                           texture.rgba.size() != uint64_t(texture.width) * uint64_t(texture.height) * 4))
    throw InputError(source, "texture size differs from width x height x 4");
  for (const auto& a : vertex_attributes)
    if (a.values.size() != nv) throw InputError(source, "vertex attribute '" + a.name + "' has the wrong length");
  for (const auto& a : face_attributes)
    if (a.values.size() != triangles.size())
      throw InputError(source, "face attribute '" + a.name + "' has the wrong length");
  for (size_t v = 0; v < nv; ++v)
    if (!positions[v].allFinite()) throw InputError(source, "vertex " + std::to_string(v) + " is not finite");
}

namespace {
struct BitHash {
  size_t operator()(const Vec3& p) const {
    uint64_t h = 1469598103934665603ull;
    for (int a = 0; a < 3; ++a) {
      uint64_t bits;
      std::memcpy(&bits, &p[a], 8);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    return size_t(h);
  }
};
struct BitEqual {
  bool operator()(const Vec3& a, const Vec3& b) const { return std::memcmp(a.data(), b.data(), 24) == 0; }
};
}  // namespace

std::vector<uint32_t> identical_positions(const Mesh& mesh, std::vector<uint32_t>* kept_out) {
  std::unordered_map<Vec3, uint32_t, BitHash, BitEqual> first;
  first.reserve(mesh.positions.size());
  std::vector<uint32_t> remap(mesh.positions.size());
  std::vector<uint32_t> kept;
  kept.reserve(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    // -0.0 and +0.0 are the same point.
    Vec3 p = mesh.positions[v];
    for (int a = 0; a < 3; ++a)
      if (p[a] == 0) p[a] = 0;
    auto [it, fresh] = first.try_emplace(p, uint32_t(kept.size()));
    if (fresh) kept.push_back(uint32_t(v));
    remap[v] = it->second;
  }
  if (kept_out) *kept_out = std::move(kept);
  return remap;
}

size_t weld_identical_vertices(Mesh& mesh) {
  std::vector<uint32_t> kept;
  const std::vector<uint32_t> remap = identical_positions(mesh, &kept);
  const size_t removed = mesh.positions.size() - kept.size();
  if (removed == 0) return 0;
  auto compact = [&](auto& vec) {
    if (vec.empty()) return;
    std::remove_reference_t<decltype(vec)> out;
    out.reserve(kept.size());
    for (uint32_t v : kept) out.push_back(vec[v]);
    vec.swap(out);
  };
  compact(mesh.positions);
  compact(mesh.normals);
  compact(mesh.colors);
  compact(mesh.uvs);
  for (auto& e : mesh.edges) e = {remap[e[0]], remap[e[1]]};
  for (auto& a : mesh.vertex_attributes) compact(a.values);
  std::vector<Triangle> tris;
  tris.reserve(mesh.triangles.size());
  std::vector<size_t> kept_faces;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    Triangle t{remap[mesh.triangles[f][0]], remap[mesh.triangles[f][1]], remap[mesh.triangles[f][2]]};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    tris.push_back(t);
    kept_faces.push_back(f);
  }
  if (tris.size() != mesh.triangles.size())
    for (auto& a : mesh.face_attributes) {
      std::vector<double> vals;
      vals.reserve(kept_faces.size());
      for (size_t f : kept_faces) vals.push_back(a.values[f]);
      a.values.swap(vals);
    }
  mesh.triangles.swap(tris);
  std::vector<std::array<uint32_t, 2>> edges;
  for (const auto& e : mesh.edges)
    if (remap[e[0]] != remap[e[1]]) edges.push_back({remap[e[0]], remap[e[1]]});
  mesh.edges.swap(edges);
  return removed;
}

std::vector<Vec3> vertex_normals(const Mesh& mesh) {
  std::vector<Vec3> n(mesh.positions.size(), Vec3::Zero());
  for (const Triangle& t : mesh.triangles) {
    const Vec3 fn = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (uint32_t v : t) n[v] += fn;
  }
  for (Vec3& v : n) {
    const double len = v.norm();
    if (len > 0) v /= len;
  }
  return n;
}

double signed_volume(const Mesh& mesh) {
  // Sum of signed tetrahedra against the bounding-box centre (better
  // conditioned than against the origin for meshes far from it).
  const auto box = bounding_box(mesh);
  const Vec3 c = 0.5 * (box[0] + box[1]);
  double v = 0;
  for (const Triangle& t : mesh.triangles)
    v += (mesh.positions[t[0]] - c).dot((mesh.positions[t[1]] - c).cross(mesh.positions[t[2]] - c));
  return v / 6.0;
}

std::array<Vec3, 2> bounding_box(const Mesh& mesh) {
  if (mesh.positions.empty()) return {Vec3::Zero(), Vec3::Zero()};
  Vec3 lo = mesh.positions[0], hi = lo;
  for (const Vec3& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {lo, hi};
}

}  // namespace voxpress
