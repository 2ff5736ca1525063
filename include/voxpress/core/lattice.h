// voxpress/core/lattice.h — the regular sampling grid of a volume.
//
// A Lattice maps integer sample indices (i, j, k), i fastest in memory, to
// physical positions:
//
//     p = origin + direction * diag(spacing) * (i, j, k)
//
// Units are the file's (millimetres for medical images). direction holds the
// unit direction of each index axis in its columns; it is orthonormal for
// every format we read except NIfTI sforms with shear, which are kept as-is.
// A cell is the box between 2 x 2 x 2 neighbouring samples; "voxel units"
// means lengths measured in cells (i.e. in index space).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "voxpress/core/types.h"

namespace voxpress {

/// Physical coordinate convention of a lattice's space.
enum class Space : uint8_t {
  unknown,  ///< no anatomical meaning (generated shapes, voxel art, raw)
  LPS,      ///< x = left, y = posterior, z = superior (DICOM, ITK, NRRD, MetaImage)
  RAS,      ///< x = right, y = anterior, z = superior (NIfTI, 3D Slicer's RAS)
};
const char* space_name(Space s);

/// A box of samples [lo, hi) per axis (a block of a volume).
struct Box {
  std::array<int64_t, 3> lo{}, hi{};
  uint64_t size() const { return uint64_t(hi[0] - lo[0]) * uint64_t(hi[1] - lo[1]) * uint64_t(hi[2] - lo[2]); }
  std::array<int64_t, 3> dims() const { return {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}; }
};

struct Lattice {
  std::array<int64_t, 3> dims{0, 0, 0};  ///< samples along i, j, k (each >= 1 when valid)
  Vec3 spacing{1, 1, 1};                 ///< cell size along i, j, k, physical units, > 0
  Vec3 origin{0, 0, 0};                  ///< physical position of sample (0, 0, 0)
  Mat3 direction = Mat3::Identity();     ///< columns: unit physical direction of i, j, k
  Space space = Space::unknown;

  /// Number of samples (product of dims).
  uint64_t size() const;
  /// Linear index of sample (i, j, k); i fastest. No bounds check.
  uint64_t linear(int64_t i, int64_t j, int64_t k) const {
    return uint64_t(i) + uint64_t(dims[0]) * (uint64_t(j) + uint64_t(dims[1]) * uint64_t(k));
  }
  /// The 3x3 linear part of index -> physical: direction * diag(spacing).
  Mat3 index_to_physical_matrix() const;
  /// Physical position of a (possibly fractional) index-space point.
  Vec3 to_physical(const Vec3& ijk) const;
  /// Index-space position of a physical point (inverse of to_physical).
  Vec3 to_index(const Vec3& p) const;
  /// True when index -> physical flips handedness (det < 0): a triangle wound
  /// counter-clockwise in index space is clockwise in physical space.
  bool flips_orientation() const;
  /// Throws UsageError unless dims >= 1, spacing finite and > 0, the matrix invertible.
  void validate() const;
};

/// The lattice of a box of samples of `volume`: its spacing, direction and
/// space, the box's dims, the origin at the box's first sample.
Lattice box_lattice(const Lattice& volume, const Box& box);

}  // namespace voxpress
