// Exact inside/outside classification of lattice samples against a triangle
// mesh, one ray per lattice row (private; used by check_classification and
// the voxelizer).
//
// Theory of operation: the mesh is given in index space. Each row (j, k) is a
// ray along +i, symbolically perturbed to (j + e, k + e^2) so that it never
// meets a vertex or an edge ambiguously (midpoint vertices lie exactly on
// rows). A triangle whose yz-projection contains the perturbed point is
// crossed; its crossing raises the winding number of every later sample by
// one when the triangle faces -i (entering the solid), lowers it otherwise.
// Which samples lie after a crossing is decided exactly with orient3d against
// the triangle's plane. Triangles whose closed projection merely touches the
// row line are kept too, to report samples that lie exactly on the surface.
// Triangles are binned to rows once (count, prefix-sum, fill); rows are then
// independent, so callers run them in parallel.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "voxpress/core/types.h"

namespace voxpress::detail {

class RowRays {
 public:
  /// lo/hi: inclusive sample index ranges along i, j, k (they may extend
  /// beyond a lattice, e.g. to a ring of padding samples). mirrored: the
  /// index frame has the opposite handedness of the mesh's frame (winding
  /// numbers change sign).
  RowRays(std::vector<Vec3> index_vertices, const std::vector<Triangle>& triangles, std::array<int64_t, 3> lo,
          std::array<int64_t, 3> hi, bool mirrored);

  /// Row (j, k): winding[i - lo_i] = winding number of sample i (0 outside,
  /// +1 inside an outward-oriented closed mesh); odd[i - lo_i] = parity of the
  /// crossings before it; on_surface = sorted samples lying exactly on the mesh.
  void classify(int64_t j, int64_t k, std::vector<int>& winding, std::vector<uint8_t>& odd,
                std::vector<int64_t>& on_surface) const;

  const std::array<int64_t, 3>& lo() const { return lo_; }
  const std::array<int64_t, 3>& hi() const { return hi_; }
  int64_t row_length() const { return hi_[0] - lo_[0] + 1; }

 private:
  struct Hit {
    uint32_t tri;
    int sigma;      // sign of the yz-projected area (= sign of the normal's i component); 0: parallel to rays
    bool crossing;  // crossed by the perturbed ray (else it only touches the row line)
  };
  size_t row_of(int64_t j, int64_t k) const { return size_t((k - lo_[2]) * rows_y_ + (j - lo_[1])); }

  std::vector<Vec3> v_;
  const std::vector<Triangle>& t_;
  std::array<int64_t, 3> lo_, hi_;
  int64_t rows_y_, rows_z_;
  bool mirrored_;
  std::vector<uint32_t> start_;
  std::vector<Hit> hits_;
};

}  // namespace voxpress::detail
