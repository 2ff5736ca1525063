// voxpress/render/render.h — pictures without a GPU.
//
// A compact software rasterizer for README pictures, previews and tests:
// orthographic camera, z-buffer, flat shading (so facets show), supersampled
// antialiasing, and the colours the pipelines attach to a mesh: the texture
// (voxel art), vertex colours, or one colour per region (flat id; curved
// surface grey). Sharp feature curves (Mesh::edges) are drawn as dark lines.
// Deterministic: the same bytes on every run and thread count (serial).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"

namespace voxpress {

enum class View { iso, x, y, z };
/// "iso", "x", "y", "z"; throws UsageError otherwise.
View parse_view(const std::string& name);

enum class Coloring {
  automatic,  ///< texture if present, else vertex colours, else the base colour
  regions,    ///< the face (else vertex) attribute "region" (flat id >= 0; curved = grey), else the face attribute "label_in" (a label map's interfaces); as automatic without one
  plain,      ///< the base colour only
};

struct RenderOptions {
  int width = 800, height = 600;
  View view = View::iso;
  Coloring coloring = Coloring::automatic;
  bool features = true;  ///< draw Mesh::edges
  bool wireframe = false;  ///< draw every triangle's edges (thin, grey)
  int supersample = 3;   ///< samples per pixel along each axis
  std::array<uint8_t, 3> base{190, 198, 215};
  std::array<uint8_t, 3> background{255, 255, 255};
  /// Points to frame instead of the mesh's own vertices (pictures of several
  /// meshes drawn to one scale: all their vertices).
  std::vector<Vec3> frame;
};

/// Renders the mesh (physical units) filling the picture; returns RGBA rows
/// from the top. Throws UsageError for sizes outside 16..8192.
Texture render_mesh(const Mesh& mesh, const RenderOptions& options = {});

/// Pictures side by side (same height expected; shorter ones are padded),
/// separated by `gap` pixels of the first picture's corner colour.
Texture side_by_side(const std::vector<Texture>& pictures, int gap = 8);

/// The boundary faces of the inside voxels (each sample drawn as the cube of
/// its cell), in physical units, outward: the "input voxels" of previews.
/// Corners are shared; not guaranteed manifold (display only). LimitError
/// naming the volume when `held_bytes` (what the caller holds besides the
/// volume), the volume and the faces would exceed `max_bytes` (0: no cap;
/// memory_budget.h).
Mesh voxel_faces(const BinaryVolume& volume, uint64_t max_bytes = 0, uint64_t held_bytes = 0);

/// A colour for region id `region` (>= 0), distinct for neighbouring ids.
std::array<uint8_t, 3> region_color(int64_t region);

}  // namespace voxpress
