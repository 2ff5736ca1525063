// Triangulation of simple polygons with holes by ear clipping (private).
//
// Theory of operation (after D. Eberly, "Triangulation by Ear Clipping"):
// each hole is joined to the outer boundary by a bridge — from the hole's
// rightmost vertex M along +x to the first boundary edge hit, then to the
// visible vertex P that edge offers (or the reflex vertex inside the
// triangle M, I, P closest in angle to the ray) — which turns the region
// into one weakly simple polygon (M and P appear twice). Ears are then
// clipped: a convex vertex whose triangle contains no reflex vertex (other
// than copies of its own corners). All orientation tests are exact.
// O(n * r) for n vertices and r reflex vertices; meant for the few thousand
// vertices of a truth face, not for large inputs.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace voxpress::detail {

struct Point2 {
  double x, y;
};

/// outer: counter-clockwise; holes: clockwise, strictly inside outer and
/// disjoint. Returns counter-clockwise triangles indexing the concatenation
/// outer, holes[0], holes[1], ... Throws std::logic_error if clipping stalls
/// (self-intersecting input).
std::vector<std::array<uint32_t, 3>> triangulate_polygon(const std::vector<Point2>& outer,
                                                         const std::vector<std::vector<Point2>>& holes);

}  // namespace voxpress::detail
