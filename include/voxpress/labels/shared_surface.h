// voxpress/labels/shared_surface.h — one surface for every label of a label
// map, each interface shared by the two labels it separates (issue 54).
//
// Vertices: one per stick (a lattice edge whose two samples have different
// labels; samples beyond the lattice are background 0), one at the centre
// of each face where three or four labels meet around a point, and the
// apexes of the label cases that need one (label_cases.h). Every triangle
// separates two labels and is stored once, wound counter-clockwise seen
// from its `out` label (its normal points from `in` to `out`); each label's
// closed surface is its triangles, those of which it is `out` reversed. A
// label against the background alone gives exactly the binary midpoint
// surface (extract_sticks, t = 0.5). This is the midpoint surface: every
// vertex at its stick's midpoint, its face's or its case's centre;
// press_shared (shared_press.h) smooths it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"
#include "voxpress/simplify/simplify.h"

namespace voxpress {

struct SharedSurface {
  Lattice lattice;
  std::vector<uint32_t> labels;  ///< label values by index; index 0 is the background, 0
  Mesh mesh;                     ///< physical positions; every interface triangle once
  std::vector<std::array<uint32_t, 2>> sides;  ///< per triangle: (in, out) label indices
  /// Per vertex, what it lies on: kind 0-2 a stick along that axis, 3-5 a
  /// face normal to axis kind - 3, 6 an apex inside a cube, 7 a crease
  /// vertex the sharpening inserted (shared_sharpen.h); `corner` the
  /// (unpadded, may be -1) index of the stick's lower sample or of the
  /// face's or the cube's lowest corner.
  std::vector<uint8_t> kind;
  std::vector<std::array<int64_t, 3>> corner;
  /// The apex vertices (kind 6) and their exact places in their cubes
  /// (0..1 from `corner`), by vertex: the shared press starts from them,
  /// so that its arithmetic does not depend on where the lattice is.
  std::vector<std::pair<uint32_t, Vec3>> apexes;
  uint64_t stick_vertices = 0, face_vertices = 0, apex_vertices = 0;
};

/// The shared midpoint surface of a label map (integer values 0..2^32-1,
/// one component). Deterministic for any thread count. Throws InputError
/// (naming volume.source) for fractional or negative values, a volume with
/// a single value, or a cube whose labelling has no derived case yet (some
/// cubes of four or more labels; the error names the lowest such cube).
/// The same as assemble_shared_surface of one piece holding every cube.
SharedSurface extract_shared_surface(const ScalarVolume& volume);

/// What the cubes of one block of a label map contribute (press --labels
/// --chunk): their triangles, vertices named by global keys (padded sample
/// and kind, so neighbouring blocks name a shared vertex alike), in cube
/// order.
struct SharedPiece {
  std::vector<uint64_t> cube;                   ///< per triangle: padded linear index of its cube
  std::vector<std::array<uint64_t, 3>> keys;    ///< per triangle: its vertices' keys
  std::vector<std::array<uint32_t, 2>> values;  ///< per triangle: (in, out) label values
  std::vector<std::pair<uint64_t, Vec3>> apexes;  ///< key and place in its cube (0..1) of each apex
  std::string underivable;  ///< the lowest cube without a derived case (empty: none)
  uint64_t underivable_cube = UINT64_MAX;
};

/// The piece of the cubes whose lower corner, clamped into the volume,
/// lies in `core` (samples of the whole volume, whose dims are `dims`):
/// `samples` holds the box `read` (core grown by one sample, clipped).
/// Throws InputError for samples that are not labels.
SharedPiece extract_shared_piece(const ScalarVolume& samples, const Box& read, const Box& core,
                                 const std::array<int64_t, 3>& dims);

/// The shared surface of pieces that together cover every cube once, in
/// any order: the same bytes as extract_shared_surface of the whole volume.
/// `source` names the volume in errors.
SharedSurface assemble_shared_surface(const Lattice& lattice, std::vector<SharedPiece> pieces,
                                      const std::string& source);

/// The closed, outward surface of label index `label` (its triangles, the
/// ones it is `out` of reversed), vertices renumbered in order of the
/// shared mesh. Vertex positions are bit-identical to the shared mesh's.
Mesh label_mesh(const SharedSurface& surface, uint32_t label);

/// Simplifies the shared surface once (simplify() on its lattice, junction
/// lines and label-pair borders kept as edges): both labels of an interface
/// keep the same triangles, each label's surface stays closed and 2-manifold
/// and every sample stays on its side. Per-vertex kind and corner follow the
/// surviving vertices (a simplified surface is no longer pressed further).
SimplifyStats simplify_shared(SharedSurface& surface, const SimplifyOptions& options);

/// The whole shared surface, each interface once, with face attributes
/// label_in and label_out (the label values on either side; PLY keeps them).
Mesh interfaces_mesh(const SharedSurface& surface);

}  // namespace voxpress
