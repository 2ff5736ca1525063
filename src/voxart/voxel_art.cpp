// read_voxel_art: dispatch by extension; ColorGrid / VoxelArt helpers.
#include "voxpress/voxart/voxel_art.h"

#include "../io/io_util.h"
#include "voxel_art_formats.h"

namespace voxpress {

uint64_t ColorGrid::count() const {
  uint64_t n = 0;
  for (const Rgba& v : voxels) n += v[3] != 0;
  return n;
}

uint64_t VoxelArt::voxel_count() const {
  uint64_t n = 0;
  for (const ColorGrid& g : parts) n += g.count();
  return n;
}

VoxelArt read_voxel_art(const std::string& path, const VoxelArtReadOptions& options) {
  const std::string ext = detail::extension_of(path);
  if (ext == ".vox") return detail::read_vox(path, options);
  if (ext == ".vxl") return detail::read_vxl(path, options);
  throw InputError(path, "unknown voxel-art format '" + ext + "' (expected .vox or .vxl)");
}

}  // namespace voxpress
