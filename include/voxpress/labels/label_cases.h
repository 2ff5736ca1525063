// voxpress/labels/label_cases.h — marching-cubes cases for label maps
// (issue 54): one surface between every two labels, shared by both.
//
// A cube's labelling is reduced to its pattern: the rank of each corner's
// label among the cube's distinct labels in increasing value. Its case is
// derived from the faces, as the binary cases are (cube_cases.h):
//   - a face with two labels takes the binary face rule with the larger
//     label inside (cut off at a diagonal), so label N against background
//     0 is exactly the binary surface, and both cubes of a face agree;
//   - a face with three labels whose equal pair is diagonal joins that
//     pair across the face and cuts the two others off;
//   - any other face with three or four labels gets a vertex at its centre,
//     joined to each of its sticks: the point where the labels meet.
// Inside the cube, a closed loop of face segments between two labels is
// triangulated without new vertices (as the binary cases are); a junction
// (segments meeting at face centres) that runs straight from one face
// centre to another is triangulated as one patch per pair of labels around
// that junction edge; a loop or junction that cannot be triangulated so is a
// fan from a vertex inside the cube (the centroid of its vertices). Among the triangulations the derivation keeps the one that
// stays free of intersections for the most random positions of the sticks'
// vertices, then the smallest area.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/types.h"

namespace voxpress {

/// Rank of each corner's label among the cube's distinct labels, smallest
/// value first (corner numbering of cube_cases.h).
using LabelPattern = std::array<uint8_t, 8>;

/// Vertex ids of a label case: 0-11 the cube's edges (sticks), 12 + f the
/// centre of face f = 2 * axis + side, 18 + k the apex of the case's k-th
/// fan (a vertex inside the cube, at LabelCase::apexes[k]).
constexpr int kFaceCenter = 12;
constexpr int kApex = 18;
constexpr int kMaxApexes = 4;

struct LabelCase {
  struct Triangle {
    std::array<uint8_t, 3> v{};
    /// Label ranks on either side: counter-clockwise seen from `out`, so the
    /// normal points from `in` to `out` (the binary cases' inside/outside).
    uint8_t in = 0, out = 0;
  };
  std::vector<Triangle> triangles;
  std::vector<Vec3> apexes;  ///< unit-cube positions of the fans' apexes (the centroid of what each fans over)
  uint8_t labels = 0;        ///< distinct labels of the cube
};

/// The case of a pattern: derived on first use and kept (thread-safe).
/// Throws std::invalid_argument if ranks are not 0..m-1 each used.
const LabelCase& label_case(const LabelPattern& pattern);

/// The pattern of eight labels (corner order), how many distinct, and the
/// distinct values by rank (values[r] is rank r's label; the rest unset).
LabelPattern label_pattern(const std::array<uint32_t, 8>& labels, int* distinct = nullptr,
                           std::array<uint32_t, 8>* values = nullptr);

/// True when face f's centre is a vertex for these four corner ranks in the
/// face's square order (the face rule above; both cubes of a face agree).
bool face_has_center(const std::array<uint8_t, 4>& square);

/// Checks the case locally: every label's triangles (oriented outward from
/// it) use each edge inside the cube once in each direction, and around the
/// centre they form one fan. Returns an empty string or what fails.
std::string label_case_defect(const LabelCase& c);

}  // namespace voxpress
