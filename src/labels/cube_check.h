// The exact check of a shared surface cube by cube (private to src/labels):
// while every vertex stays in its element (stick, face square, cube), every
// triangle stays in its cube, and triangles of different cubes meet only in
// the segments of a shared face's contour, which both cubes use. So a
// surface whose every cube passes is free of self-intersection; the checks
// also keep the float32 clearance (core/clearance.h).
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/mesh.h"

namespace voxpress::detail {

/// The triangles of each cube (every triangle lies in one cube: its
/// midpoint centroid is strictly inside it, as no triangle has its three
/// vertices on one face), as groups of a CSR list, and for each vertex the
/// groups it has triangles in.
struct Cubes {
  std::vector<uint32_t> tris, offsets{0};
  std::vector<uint32_t> vertex_offsets, vertex_groups;
};

/// The cubes of `m`'s triangles, `x0` the vertices' element centres (index
/// space); the groups of the vertices `only` flags (null: all).
Cubes cubes_of(const Mesh& m, const std::vector<Vec3>& x0, const std::vector<uint8_t>* only = nullptr);

/// The groups among `groups` (increasing) whose triangles, at index-space
/// positions `x`, degenerate, have an altitude under delta (cells), or meet
/// or come within delta of each other beyond what they share (exact).
std::vector<uint32_t> failing_cubes(const Mesh& m, const Cubes& c, const std::vector<uint32_t>& groups,
                                    const std::vector<Vec3>& x, double delta);

/// Puts the vertices of each failing group back at `back` (once each:
/// `reset` marks them), rechecks the groups that share them, until none
/// fails; a group whose vertices are all back already is left as it is.
/// Returns how many groups were put back.
size_t put_back(const Mesh& m, const Cubes& c, std::vector<uint32_t> bad, std::vector<Vec3>& x,
                const std::vector<Vec3>& back, std::vector<uint8_t>& reset, double delta);

}  // namespace voxpress::detail
