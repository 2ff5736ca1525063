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

/// The block's piece: its owned sticks (key, code, t: `t` if given, in
/// stick order, else the sticks' own) and, with `triangles`, its owned
/// triangles.
SurfacePiece owned_piece(const BlockSticks& bs, const ChunkGrid& grid, size_t b, bool triangles,
                         const std::vector<double>* t = nullptr);

/// A stick key's parts (stick_key: padded x fastest, then the axis, y, z).
struct KeyCodec {
  uint64_t px, py;
  explicit KeyCodec(const std::array<int64_t, 3>& dims) : px(uint64_t(dims[0] + 2)), py(uint64_t(dims[1] + 2)) {}
  /// Padded (p, q, r) of the stick's lower sample, and its axis.
  std::array<uint64_t, 4> decode(uint64_t key) const {
    const uint64_t p = key % px, rest = key / px, a = rest % 3, row = rest / 3;
    return {p, row % py, row / py, a};
  }
  /// The stick's lower sample in the volume (unpadded; components may be -1).
  std::array<int64_t, 3> lower(uint64_t key) const {
    const auto d = decode(key);
    return {int64_t(d[0]) - 1, int64_t(d[1]) - 1, int64_t(d[2]) - 1};
  }
};

}  // namespace voxpress::detail
