// Texture atlas of a triangle mesh (private; Muniz et al., Section 4.5).
//
// Charts: faces in order of decreasing axis alignment (largest |normal
// component| first) seed a chart that grows over edges while a face's normal
// stays within `angle` of the seed's; the chart is projected on the plane
// normal to the seed's normal (axis-aligned seeds get the axis plane, so
// voxel faces land on whole texels). Each chart is rasterized in fixed point
// with the top-left rule, so a texel belongs to one face; a chart whose
// projection overlaps itself is grown again with half the angle (down to
// single faces). Charts get `padding` texels on every side, filled by
// dilating their colours. Packers: the paper's (repeatedly merge the two
// narrowest stacked or the two shortest side by side, whichever wastes less
// of its enclosing square, then square and centre) and a shelf packer (rows by decreasing height);
// AtlasPacker::best keeps the smaller texture.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/voxart/polygonize.h"

namespace voxpress::detail {

struct AtlasOptions {
  double angle_degrees = 60;
  double texels_per_unit = 4;  ///< texels per unit of the mesh's coordinates
  int padding = 2;
  AtlasPacker packer = AtlasPacker::best;
  int64_t max_side = int64_t(1) << 62;  ///< wider: only the size is returned, no texture made
  uint64_t max_bytes = 0, held_bytes = 0;  ///< the memory cap (0: none) and what the caller holds
  std::string source;                      ///< named by a refusal
};

struct AtlasResult {
  Mesh mesh;  ///< the input with vertices split per chart, uvs and texture set
  std::vector<uint32_t> source_vertex;  ///< per output vertex: the input vertex
  uint64_t charts = 0, covered_texels = 0;
  double utilisation_paper = 0, utilisation_shelf = 0;
  std::string packer;
};

/// `color(face, point)` gives the colour of the surface at a point of a face
/// (called from several threads for different charts; must be thread-safe).
AtlasResult build_atlas(const Mesh& mesh, const AtlasOptions& options,
                        const std::function<Rgba(uint32_t face, const Vec3& point)>& color);

/// Texture coordinates -> texel (nearest), clamped.
Rgba sample_texture(const Texture& t, const Vec2& uv);

}  // namespace voxpress::detail
