// voxpress/io/mesh_io.h — reading and writing triangle meshes.
//
// Writers (format from the extension): .ply (binary little-endian by
// default, or ASCII; positions as double; normals, RGBA colours and every
// named vertex/face attribute as properties), .obj (with texture
// coordinates, and the texture as STEM.png + STEM.mtl beside it), .stl
// (binary; float32 per the format), .off, .glb / .gltf (glTF 2.0; float32
// positions, uint32 indices, optional normals, colours, texture coordinates
// and an embedded PNG texture sampled nearest; write_scene: one node per
// mesh). Every write is atomic.
// Readers: .ply (ASCII and binary of either endianness, any extra properties
// kept as attributes, polygons fanned into triangles), .obj (tinyobjloader,
// double precision), .stl (binary — even when the header starts with
// "solid" — or ASCII; identical vertices welded), .off (OFF/COFF/NOFF),
// .glb / .gltf (triangle primitives' float32 positions as stored, no node
// transforms). Every numeric text field must parse whole (no silent 0).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"

namespace voxpress {

enum class MeshFormat { ply, obj, stl, off, gltf, glb };

/// Format from the extension; throws InputError for an unknown one.
MeshFormat mesh_format_from_path(const std::string& path);

struct MeshWriteOptions {
  bool ascii = false;  ///< PLY only: ASCII instead of binary little-endian
};

void write_mesh(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options = {});

/// One mesh of a glTF scene: a node named `name`, its material's base colour
/// `color` (linear RGBA in [0, 1]).
struct SceneMesh {
  std::string name;
  const Mesh* mesh = nullptr;
  std::array<double, 4> color{0.8, 0.8, 0.8, 1.0};
};

/// A .glb / .gltf holding one node per mesh (a label map's organs, each
/// toggled and coloured on its own in a viewer). Atomic, like write_mesh;
/// throws UsageError for another extension, an empty list or an empty mesh.
void write_scene(const std::string& path, const std::vector<SceneMesh>& meshes);

struct MeshReadOptions {
  uint64_t max_bytes = 0;  ///< memory cap; 0 = default_memory_limit()
};

/// Reads a PLY, OBJ, STL, OFF or glTF / GLB mesh. Throws InputError for missing files,
/// malformed or truncated data and out-of-range indices.
Mesh read_mesh(const std::string& path, const MeshReadOptions& options = {});

}  // namespace voxpress
