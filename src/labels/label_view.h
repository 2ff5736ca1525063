// A label's own binary view of the shared surface (private to src/labels):
// where a cube holds two labels and the shared triangles there are the
// binary case of its owner's mask, the owner's binary stages (the quadric
// fit, the sharpening) may edit it on the owner's own stick surface, and
// their results map back stick for stick (shared_fit.h, shared_sharpen.h).
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "shared_sticks.h"
#include "voxpress/core/volume.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_surface.h"

namespace voxpress::detail {

using Cube = std::array<int64_t, 3>;

Cube floor_of(const Vec3& p);
/// Index-space centre of a shared vertex's element (stick, face or cube).
Vec3 element_centre(const SharedSurface& s, uint32_t v);

/// Per label index of `s`: the position in `labels` of the label of that
/// value, or SIZE_MAX (the background and labels not listed).
std::vector<size_t> listed_labels(const SharedSurface& s, const std::vector<LabelInfo>& labels);

/// The shared triangles grouped by the cube they lie in, and who owns each
/// cube: a cube of two labels, all its vertices on sticks, belongs to the
/// higher-valued of its labels that `takes_part` (per label index; the
/// background never owns): label_cases put the higher label inside a
/// two-label face, so the shared case is its binary case.
struct Ownership {
  std::vector<std::pair<Cube, uint32_t>> tris;  ///< (cube, shared triangle), sorted
  std::vector<size_t> offsets{0};               ///< group g: tris[offsets[g], offsets[g + 1])
  std::vector<uint32_t> owner;                  ///< per group: a label index, or UINT32_MAX
  std::vector<std::vector<uint32_t>> mine;      ///< per label index: the groups it owns
  std::vector<uint32_t> degree;                 ///< per shared vertex: its triangles
};
Ownership ownership(const SharedSurface& s, const std::vector<uint8_t>& takes_part);

/// Label L's own stick surface (extract_sticks of its mask, whose sample
/// (0, 0, 0) is the shared lattice's `lo`), every t read from the shared
/// surface, and which of it L may edit.
struct LabelView {
  uint32_t label = 0;               ///< index into SharedSurface::labels
  std::array<int64_t, 3> lo{};
  StickSurface surf;
  std::vector<uint32_t> idx;        ///< per stick: the shared vertex
  std::vector<Cube> cube;           ///< per triangle: its cube (shared lattice)
  std::vector<uint8_t> editable;    ///< per triangle: in a cube L owns whose shared triangles are L's own
  std::vector<uint32_t> shared_of;  ///< per editable triangle: the same shared triangle
  std::vector<uint8_t> fixed;       ///< per stick: has a shared triangle that is not editable
  size_t cubes = 0;                 ///< cubes L may edit
  /// Index-space position of stick k on the shared lattice.
  Vec3 shared_position(size_t k) const {
    return surf.index_position(k) + Vec3(double(lo[0]), double(lo[1]), double(lo[2]));
  }
};
LabelView label_view(const SharedSurface& s, const Ownership& own, const SharedSticks& sticks,
                     const BinaryVolume& mask, const std::array<int64_t, 3>& lo, uint32_t L);

}  // namespace voxpress::detail
