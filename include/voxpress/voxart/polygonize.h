// voxpress/voxart/polygonize.h — voxel art to a textured, faired, simplified
// mesh (Muniz, Montenegro and Clua, "Fast polygonization and texture map
// extraction from volumetric objects ...": ../shared/papers/
// voxel-art-polygonization-muniz-et-al.md).
//
// Steps, each public for tests and benchmarks:
//   1. solid_cuberille (Section 4.2): flood fill from outside through a padded
//      buffer (hollow models become solid), then one quad per face between a
//      solid voxel and the outside, carrying the voxel's colour. Voxels that
//      touch only along an edge or at a corner (the paper's topological
//      problems, Fig. 1) get split vertices so the quad mesh is a closed
//      2-manifold: around an edge with two diagonal solid voxels the surface
//      wraps each empty voxel separately (solids 18-connected, the outside
//      6-connected), and a corner shared by several such fans gets one vertex
//      per fan.
//   2. fair_lanczos (Section 4.3, Eq. 8-10): one pass of the modified Lanczos
//      kernel over the quad neighbourhoods, in voxel units.
//   3. attribute smoothing (Section 4.4): vertex normals = mean of the
//      distinct adjacent face normals, vertex colours = mean of the adjacent
//      quads' colours.
//   4. optional simplification (voxpress/simplify/simplify.h, colour
//      borders penalised, not kept), done before the atlas so the texture is
//      rendered for the final triangles.
//   5. texture atlas (Section 4.5): charts grown from the most axis-aligned
//      faces while the normal stays within 60 degrees of the seed's, projected
//      on the seed's plane, packed, and rendered from the voxel colours with
//      nearest texels and dilated padding.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/voxart/voxel_art.h"

namespace voxpress {

/// The cube-face mesh of one part, in the part's grid coordinates.
struct QuadMesh {
  std::vector<Vec3> positions;
  std::vector<std::array<uint32_t, 4>> quads;  ///< counter-clockwise seen from outside
  std::vector<Rgba> colors;                    ///< per quad: its voxel's colour
  std::vector<Vec3> centers;                   ///< per quad: centre of the voxel face (unfaired)
  uint64_t split_vertices = 0;  ///< lattice corners that got more than one vertex (non-manifold configurations)
  uint64_t filled_cavities = 0; ///< empty voxels enclosed by the model, made solid
  uint64_t separated_edges = 0; ///< edge-touching voxel pairs kept apart (see solid_cuberille)
  uint64_t pinched_edges = 0;   ///< edges still doubled either way (solid_cuberille then fills a voxel)
};

/// The solid of Section 4.2: painted voxels plus the empty voxels the outside
/// cannot reach (1 = solid), over the grid, x fastest.
std::vector<uint8_t> fill_solid(const ColorGrid& grid);

/// Step 1. Throws InputError(grid.name, ...) when the grid holds no voxel.
QuadMesh solid_cuberille(const ColorGrid& grid);

/// Step 2: one pass of Eq. (8)-(10) with constant lambda (the paper: 1.3).
void fair_lanczos(QuadMesh& mesh, double lambda = 1.3);

enum class VoxartFairing { lanczos, taubin, pressing, none };
VoxartFairing parse_voxart_fairing(const std::string& name);  ///< throws UsageError
const char* voxart_fairing_name(VoxartFairing f);

enum class AtlasPacker { best, paper, shelf };
AtlasPacker parse_atlas_packer(const std::string& name);  ///< throws UsageError

struct VoxartOptions {
  VoxartFairing fairing = VoxartFairing::lanczos;
  double lambda = 1.3;          ///< Lanczos constant (Eq. 8)
  int taubin_iterations = 10;   ///< the paper's comparison
  uint64_t target_faces = 0;    ///< simplify to at most this many triangles; 0 = keep all
  bool texture = true;          ///< false: per-vertex colours instead of an atlas
  double chart_angle = 60;      ///< degrees: theta_min of Section 4.5
  int texels_per_voxel = 0;     ///< 0 = automatic (4, fewer when the texture would exceed max_texture)
  int64_t max_texture = 8192;   ///< largest texture side
  int padding = 2;              ///< texels of dilated border around each chart
  AtlasPacker packer = AtlasPacker::best;
  bool y_up = true;             ///< rotate the Z-up voxel frame to glTF's Y-up
  uint64_t max_bytes = 0;       ///< memory cap for the grids, quads and atlas (memory_budget.h); 0 = none
};

struct VoxartStats {
  uint64_t voxels = 0, quads = 0, split_vertices = 0, filled_cavities = 0, separated_edges = 0;
  uint64_t vertices = 0, triangles = 0;  ///< final mesh
  uint64_t charts = 0;
  int64_t texture_width = 0, texture_height = 0;
  int texels_per_voxel = 0;
  double utilisation = 0;                ///< chart texels / texture texels, chosen packer
  double utilisation_paper = 0, utilisation_shelf = 0;
  std::string packer;
  double color_exact = 0;                ///< fraction of voxel faces whose centre samples their voxel's colour
  double seconds_extract = 0, seconds_fair = 0, seconds_attributes = 0, seconds_simplify = 0, seconds_atlas = 0,
         seconds_total = 0;
};

struct VoxartResult {
  Mesh mesh;  ///< positions, normals, triangles; uvs + texture (or colours without texture)
  /// Per vertex of `mesh`: its vertex on the surface before the atlas split
  /// it along chart seams. Faces renumbered through this are the closed,
  /// 2-manifold, consistently oriented surface (see surface()).
  std::vector<uint32_t> surface_vertex;
  VoxartStats stats;
  /// The mesh with chart seams joined again (positions and triangles only).
  Mesh surface() const;
};

/// The whole pipeline over every part of `art`.
VoxartResult polygonize_voxel_art(const VoxelArt& art, const VoxartOptions& options = {});

}  // namespace voxpress
