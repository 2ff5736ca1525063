// voxpress/io/mesh_io.h — reading and writing triangle meshes.
//
// Writers (format from the extension): .ply (binary little-endian by
// default, or ASCII; positions as double; normals, RGBA colours and every
// named vertex/face attribute as properties), .obj (with texture
// coordinates, and the texture as STEM.png + STEM.mtl beside it), .stl
// (binary; float32 per the format), .off, .glb / .gltf (glTF 2.0; float32
// positions, uint32 indices, optional normals, colours, texture coordinates
// and an embedded PNG texture sampled nearest; write_scene: one node per
// mesh), .vtk (legacy VTK 4.2, binary or ASCII) and .vtp (VTK XML; both with
// normals, colours and attributes as point and cell data, the coordinate
// system as 3D Slicer records it; src/io/vtk.cpp). Every write is atomic.
// Readers: .ply (ASCII and binary of either endianness, any extra properties
// kept as attributes, polygons fanned into triangles), .obj (tinyobjloader,
// double precision), .stl (binary — even when the header starts with
// "solid" — or ASCII; identical vertices welded), .off (OFF/COFF/NOFF),
// .glb / .gltf (triangle primitives' float32 positions as stored, no node
// transforms), .vtk (legacy 2.0-5.1 POLYDATA) and .vtp (XML PolyData: ascii,
// base64 or raw appended data, zlib-compressed or not). Every numeric text
// field must parse whole (no silent 0).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/lattice.h"
#include "voxpress/core/mesh.h"

namespace voxpress {

enum class MeshFormat { ply, obj, stl, off, gltf, glb, vtk, vtp };

/// Format from the extension; throws InputError for an unknown one.
MeshFormat mesh_format_from_path(const std::string& path);

struct MeshWriteOptions {
  bool ascii = false;  ///< PLY and legacy VTK: ASCII instead of binary
  /// The positions' frame (LPS, RAS), recorded where 3D Slicer reads it
  /// (VTK, VTP, PLY comment, STL header) so it places the mesh right.
  Space space = Space::unknown;
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

/// Reads a PLY, OBJ, STL, OFF, glTF / GLB, VTK or VTP mesh. Throws InputError for missing files,
/// malformed or truncated data and out-of-range indices.
Mesh read_mesh(const std::string& path, const MeshReadOptions& options = {});

}  // namespace voxpress
