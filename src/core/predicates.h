// Exact geometric predicates on doubles (private).
//
// Theory of operation: each predicate first evaluates its determinant in
// floating point together with Shewchuk's a-priori error bound ("Adaptive
// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates",
// 1997, the orient2dfast / orient3dfast bounds). When the bound cannot
// certify the sign — nearly or exactly degenerate input, which midpoint
// surfaces are full of — the determinant is recomputed exactly with
// floating-point expansions (sums of non-overlapping doubles built with the
// error-free two_sum / two_product; same paper, Sections 2.4-2.7). Results
// are exact for all finite inputs short of overflow, and nothing allocates.
#pragma once

#include "voxpress/core/types.h"

namespace voxpress::detail {

/// Sign of ((b - a) x (c - a)) . (d - a): +1 when d lies on the side the
/// right-hand normal of triangle (a, b, c) points to, 0 when coplanar.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Sign of (b - a) x (c - a) in 2D: +1 when a, b, c turn counter-clockwise.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);

/// orient2d of the projections of a, b, c that drop coordinate `drop` (0, 1 or 2);
/// the remaining axes keep their cyclic order ((1,2), (2,0), (0,1)).
int orient2d_drop(const Vec3& a, const Vec3& b, const Vec3& c, int drop);

/// z against the tetrahedron (a, b, c, d) of orientation o = orient3d(a, b,
/// c, d) != 0: -1 outside, 0 on its boundary, +1 strictly inside.
int tetrahedron_side(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& z, int o);

/// True when the triangle's three corners are collinear (or coincide).
bool triangle_degenerate(const Vec3& a, const Vec3& b, const Vec3& c);

/// Closed segment [p, q] against closed triangle (a, b, c) (non-degenerate).
bool segment_intersects_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);

/// Do two non-degenerate triangles of a mesh intersect anywhere other than in
/// the vertices / edge they share by index? ia, ib hold the vertex indices.
bool triangles_intersect(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3]);

}  // namespace voxpress::detail
