// voxpress/core/mesh.h — the triangle mesh every pipeline returns.
//
// Layout: positions is #V by 3 doubles (physical units); triangles is #F by 3
// uint32 vertex indices, counter-clockwise when seen from outside the solid
// (right-hand normal points out). Optional per-vertex and per-face data lives
// beside them; an empty vector means "absent", otherwise it has #V (or #F)
// entries. No half-edge structure appears here: algorithms that need
// adjacency build it privately.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/types.h"
#include "voxpress/core/volume.h"

namespace voxpress {

/// A named scalar per vertex or per face. values are stored as double and
/// written with `type` (PLY property type; other formats ignore it).
struct MeshAttribute {
  std::string name;
  ScalarType type = ScalarType::f32;
  std::vector<double> values;
};

/// An 8-bit RGBA image, rows from the top, 4 bytes per texel.
struct Texture {
  int64_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  ///< width * height * 4
  bool empty() const { return width == 0 || height == 0; }
};

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  std::vector<Vec3> normals;                         ///< optional, per vertex, unit length
  std::vector<std::array<uint8_t, 4>> colors;        ///< optional, per vertex, RGBA
  std::vector<MeshAttribute> vertex_attributes;      ///< optional, each with #V values
  std::vector<MeshAttribute> face_attributes;        ///< optional, each with #F values
  /// Optional labelled edges: the sharp feature curves, as vertex pairs
  /// (PLY "edge" elements, OBJ "l" records).
  std::vector<std::array<uint32_t, 2>> edges;
  /// Optional per-vertex texture coordinates in [0, 1], glTF convention:
  /// (0, 0) is the top-left corner of `texture`, v grows downwards.
  std::vector<Vec2> uvs;
  /// Optional diffuse texture sampled through `uvs` (written by the glTF and
  /// OBJ writers: embedded PNG / PNG + MTL beside the OBJ). Texels are meant
  /// to be looked up with nearest filtering.
  Texture texture;

  size_t vertex_count() const { return positions.size(); }
  size_t face_count() const { return triangles.size(); }
  /// Attribute by name, or nullptr.
  const MeshAttribute* vertex_attribute(const std::string& name) const;
  const MeshAttribute* face_attribute(const std::string& name) const;
  /// Throws InputError(source, ...) if an index (face or edge) is out of range or an
  /// attribute has the wrong length.
  void validate(const std::string& source = {}) const;
};

/// For each vertex, the index of its position among the distinct ones (bit-
/// identical positions, -0 = +0, numbered by first occurrence); `kept`
/// receives the first vertex of each.
std::vector<uint32_t> identical_positions(const Mesh& mesh, std::vector<uint32_t>* kept = nullptr);

/// Merges vertices with bit-identical positions (STL stores every triangle's
/// corners separately; a textured mesh splits its vertices at chart seams)
/// and drops triangles that become degenerate (two equal indices). Vertex
/// attributes (and texture coordinates) of the first occurrence are kept;
/// edges are renumbered. Returns the number of vertices removed.
size_t weld_identical_vertices(Mesh& mesh);

/// Per-vertex unit normals: area-weighted mean of the adjacent face normals.
std::vector<Vec3> vertex_normals(const Mesh& mesh);

/// Signed volume enclosed (positive for a closed outward-oriented mesh).
double signed_volume(const Mesh& mesh);

/// Axis-aligned bounding box {min, max}; both zero for an empty mesh.
std::array<Vec3, 2> bounding_box(const Mesh& mesh);

}  // namespace voxpress
