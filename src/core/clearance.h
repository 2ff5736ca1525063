// Clearance: the distances that keep the in/out guarantee and a valid mesh
// once the positions are rounded to float32 (private).
//
// The exact checks (orient3d, triangles_intersect) certify a mesh in
// double precision. STL and glTF store float32 positions, and most viewers
// and libraries load PLY into float32 too, so every placed vertex may move
// by up to half an ulp of its largest physical coordinate per axis. A move
// is therefore also refused when, after it, a lattice sample lies within
// `delta` of a triangle, a triangle's altitude is below `delta`, or two
// triangles come within `delta` of each other away from what they share.
// With delta = 4x the worst rounding (float32_clearance), no rounding can
// move a sample across the surface or make two triangles meet: every point
// of a triangle moves by at most the rounding of its corners.
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/lattice.h"
#include "voxpress/core/types.h"

namespace voxpress::detail {

/// Index-space cells: 4x the largest move float32 rounding of the physical
/// positions can cause for points of `lattice` within `reach` cells of its
/// box (the padding ring and sharpened vertices lie within 2 cells). 4x: the
/// two sides of a distance each move by the rounding, and a factor 2 spare.
double float32_clearance(const Lattice& lattice, double reach = 2);

/// float32_clearance for points within `reach` cells of the box of
/// `index_points` (a mesh's vertices) instead of the lattice's: the same for
/// a shifted, padded or cropped volume, and no larger for a small surface in
/// a large volume.
double float32_clearance_around(const Lattice& lattice, const std::vector<Vec3>& index_points, double reach = 2);

/// Index-space cells: the largest move float32 rounding of the physical
/// positions can cause for points of `lattice` within `reach` cells of its
/// box, judged per axis: physical coordinate r rounds by at most 2^-24 times
/// its own largest magnitude, and each index axis a receives
/// sum_r |M^-1 (a, r)| of those. A valid anisotropic lattice (spacing 0.01,
/// 1, 100) is no longer judged by its largest coordinate times its largest
/// inverse spacing (issue 73). Never more than float32_clearance / 4.
double float32_rounding(const Lattice& lattice, double reach = 2);

/// Squared distance from p to the closed triangle (a, b, c).
double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Squared distance between the closed segments [p0, p1] and [q0, q1].
double segment_distance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

/// Smallest altitude of the triangle (twice its area over its longest side).
double triangle_altitude(const Vec3& a, const Vec3& b, const Vec3& c);

/// Do two mesh triangles (vertex indices ia, ib) that do not intersect
/// beyond what they share (triangles_intersect is false) come within d of
/// each other? Disjoint: their distance; one shared vertex: the distance of
/// each one's other two corners and far edge to the other triangle; a
/// shared edge: the distance of each one's apex to the other triangle (a
/// fold shows as an apex near the other face). Rounding that moves every
/// corner by less than d / 2 leaves triangles that are not within d apart.
bool triangles_within(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3],
                      double d);

/// The checks every move keeps for float32 output: a triangle that
/// degenerates or has an altitude under d is too thin; two mesh triangles
/// that meet beyond what they share, or come within d, clash.
bool triangle_too_thin(const Vec3& a, const Vec3& b, const Vec3& c, double d);
bool triangles_clash(const Vec3 (&ta)[3], const uint32_t (&ia)[3], const Vec3 (&tb)[3], const uint32_t (&ib)[3],
                     double d);

}  // namespace voxpress::detail
