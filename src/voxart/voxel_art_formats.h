// The voxel-art readers behind read_voxel_art (private).
#pragma once

#include <string>

#include "voxpress/voxart/voxel_art.h"

namespace voxpress::detail {
VoxelArt read_vox(const std::string& path, const VoxelArtReadOptions& options);
VoxelArt read_vxl(const std::string& path, const VoxelArtReadOptions& options);
}  // namespace voxpress::detail
