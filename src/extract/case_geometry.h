// The geometry of cube-case derivations (private): the cube's faces, where
// a case's vertices lie, and the search over triangulations of a loop that
// both the binary cases (cube_cases.cpp) and the label cases
// (labels/label_cases.cpp) use. Vertex ids: 0-11 cube edges (sticks),
// 12 + f the centre of face f (2 * axis + side), 18 the cube's centre.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "voxpress/core/types.h"
#include "voxpress/extract/cube_cases.h"

namespace voxpress::detail {

struct Face {
  int axis, side;
  int corner[4];  // cube corners in square order (counter-clockwise seen from +axis)
  int edge[4];    // cube edges in square-edge order
};
/// The six faces, index 2 * axis + side.
std::array<Face, 6> make_faces();

/// Bit set of the faces vertex v lies on (none for the centre).
unsigned vertex_faces(int v);
/// Position of cube edge e's vertex at parameter t, in the unit cube.
Vec3 edge_point(int e, double t);
/// A deterministic stream of 64-bit values (the robustness samples' positions).
uint64_t splitmix(uint64_t& s);

using Tri = std::array<uint8_t, 3>;
/// No degenerate triangle and no two triangles intersecting beyond their
/// shared vertices, for the positions pos[vertex id].
bool valid_geometry(const std::vector<Tri>& tris, std::span<const Vec3> pos);
/// valid_geometry of base + added when base is known valid: only the pairs
/// that involve an added triangle are tested.
bool valid_with(const std::vector<Tri>& base, const std::vector<Tri>& added, std::span<const Vec3> pos);
/// Every triangulation of polygon `loop` (vertex order kept, so every
/// triangle inherits the loop's orientation) that draws no diagonal inside a
/// cube face (the neighbouring cell could draw the same edge).
void triangulations(const std::vector<int>& loop, std::vector<std::vector<Tri>>& out);
double total_area(const std::vector<Tri>& tris, std::span<const Vec3> pos);

}  // namespace voxpress::detail
