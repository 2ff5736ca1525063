// voxpress/voxart/voxel_art.h — coloured voxel models (voxel art) and their readers.
//
// MagicaVoxel .vox (chunks SIZE / XYZI / RGBA, the default palette when RGBA
// is absent, PACK, and the scene graph nTRN / nGRP / nSHP / LAYR) and
// Westwood Tiberian Sun / Red Alert 2 .vxl (sections, span data, embedded
// palette; the .hva beside it gives each section's transform). Both formats
// are Z-up; the parts keep the file's frame.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/types.h"
#include "voxpress/core/memory_budget.h"

namespace voxpress {

using Rgba = std::array<uint8_t, 4>;

/// One voxel model: a dense grid of colours, x fastest. alpha 0 = empty;
/// every painted voxel has alpha 255 (palette alpha is not opacity in these
/// formats). Voxel (i, j, k) is the cube [i, i+1] x [j, j+1] x [k, k+1] in
/// grid coordinates.
struct ColorGrid {
  std::array<int64_t, 3> dims{0, 0, 0};
  std::vector<Rgba> voxels;
  std::string name;
  /// Affine map from grid coordinates to the model's frame: x -> linear * x + offset.
  Mat3 linear = Mat3::Identity();
  Vec3 offset = Vec3::Zero();

  uint64_t index(int64_t i, int64_t j, int64_t k) const {
    return uint64_t(i) + uint64_t(dims[0]) * (uint64_t(j) + uint64_t(dims[1]) * uint64_t(k));
  }
  bool filled(int64_t i, int64_t j, int64_t k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2] && voxels[index(i, j, k)][3] != 0;
  }
  uint64_t count() const;
};

/// A voxel-art file: one part for .vox (every shape instance of the scene
/// graph painted into one grid, later instances over earlier ones: the
/// rotations are axis permutations and the translations whole voxels), one
/// part per section for .vxl.
struct VoxelArt {
  std::vector<ColorGrid> parts;
  std::string source;
  std::string format;  ///< "vox" or "vxl"
  std::vector<std::string> notes;  ///< what was chosen (frame, model, palette), for the CLI to report
  uint64_t voxel_count() const;
};


struct VoxelArtReadOptions {
  uint64_t max_bytes = 0;  ///< memory cap; 0 = default_memory_limit()
  /// .vox: convert only model K, untransformed (default: the scene graph, or
  /// model 0 when the file has several models but no scene graph, as
  /// animation frames are stored).
  int64_t model = -1;
  /// .vxl: which .hva animation frame places the sections (default 0).
  int64_t frame = 0;
};

/// Reads .vox or .vxl (by extension). Throws InputError naming the file for
/// missing, malformed, truncated or empty models; LimitError above the cap.
VoxelArt read_voxel_art(const std::string& path, const VoxelArtReadOptions& options = {});

/// MagicaVoxel's default palette (index 0 unused), used when a .vox has no RGBA chunk.
const std::array<Rgba, 256>& magicavoxel_default_palette();

}  // namespace voxpress
