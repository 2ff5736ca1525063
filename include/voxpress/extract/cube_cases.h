// voxpress/extract/cube_cases.h — marching squares and marching cubes cases,
// derived at first use from one face rule (no hand-written table).
//
// The rule (docs/ARCHITECTURE.md, "The face rule"): on a square whose two
// inside corners are diagonal, the contour cuts off each inside corner
// separately — inside samples connect only along lattice edges, outside
// samples also across face diagonals. The same function decides 2D slices
// (square_case) and the six faces of every cube (cube_case), so the cut of
// the 3D surface by any lattice plane is exactly that plane's marching-squares
// contour.
//
// Cube cases are derived by walking the face segments into closed loops and
// triangulating each loop without new vertices. Among all triangulations of
// the loops of a case the derivation keeps those that (1) never draw a
// diagonal between two points of one cube face (the neighbouring cell could
// draw the same edge), (2) have no degenerate triangle and no two
// intersecting triangles with vertices at the stick midpoints; it then prefers
// the one that stays intersection-free for the most random positions of the
// vertices along their sticks (the later smoothing moves them), then the
// smallest total area.
//
// Numbering.
//   Corner c in 0..7 sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1).
//   Edge e in 0..11 runs along axis a = e / 4; the other two axes u < v take
//   the offsets (e & 1, (e >> 1) & 1). Its lower corner has offset 0 along a.
//   Square corner s in 0..3 sits at (0,0), (1,0), (1,1), (0,1) (counter-
//   clockwise); square edge s joins corners s and (s + 1) % 4.
#pragma once

#include <array>
#include <cstdint>

namespace voxpress {

/// Marching-squares case: up to two segments, each a pair of square edges,
/// oriented so that the inside corners are on the left (counter-clockwise
/// contours around inside regions).
struct SquareCase {
  uint8_t count = 0;
  std::array<std::array<uint8_t, 2>, 2> segments{};
};

/// Marching-cubes case: up to 12 triangles, each three cube edges, wound
/// counter-clockwise seen from outside (normal points from inside samples to
/// outside ones); `loops` is the number of boundary loops (surface pieces).
struct CubeCase {
  uint8_t count = 0;
  uint8_t loops = 0;
  std::array<std::array<uint8_t, 3>, 12> triangles{};
};

/// mask bit s set = square corner s inside.
const SquareCase& square_case(unsigned mask);
/// mask bit c set = cube corner c inside.
const CubeCase& cube_case(unsigned mask);

/// Axis (0, 1, 2) of cube edge e.
constexpr int cube_edge_axis(int e) { return e / 4; }
/// Lower (end = 0) or upper (end = 1) corner of cube edge e.
constexpr int cube_edge_corner(int e, int end) {
  const int a = e / 4;
  const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
  return (end << a) | ((e & 1) << u) | (((e >> 1) & 1) << v);
}

}  // namespace voxpress
