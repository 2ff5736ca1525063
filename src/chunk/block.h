// Private to the chunked run: one block's sticks, named by global keys, and
// which of them (and of their triangles) the block owns (the rules:
// include/voxpress/chunk/chunked.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "voxpress/chunk/chunked.h"

namespace voxpress::detail {

/// A block's sticks as extracted from its samples (grid.with_halo(b)):
/// each stick's global key and whether the block owns it. Empty when the
/// block has no sticks of the whole surface.
struct BlockSticks {
  StickSurface s;
  std::vector<uint64_t> key;
  std::vector<uint8_t> owned;
  std::array<int64_t, 3> offset{};  ///< the read box's corner in the volume
};
BlockSticks block_sticks(const BinaryVolume& samples, const ChunkGrid& grid, size_t b, const ExtractOptions& eo);

/// The block's piece: its owned sticks (key, code, t) and, with
/// `triangles`, its owned triangles.
SurfacePiece owned_piece(const BlockSticks& bs, const ChunkGrid& grid, size_t b, bool triangles);

}  // namespace voxpress::detail
