// voxpress/labels/shared_press.h — Pressing of a label map's shared surface
// (issue 54; Chica et al., Section 4, extended to several labels).
//
// Two stages, one direction:
//  1. Junction lines. Edges of the shared surface where three or more
//     interfaces meet (three or more triangles on one edge) form the
//     junction lines; they are smoothed as 1-D curves in space with the same
//     bilaplacian on arc length, each face-centre vertex kept inside its
//     face square, each apex inside its cube. Points where a line branches
//     or ends, and vertices around which four or more labels meet, stay fixed.
//     With flats (CAD assemblies), a junction vertex whose neighbours' flats
//     pin every free coordinate of its element (two parts' faces meeting at
//     an edge) is placed where those planes meet and stays there.
//  2. Interfaces. On each lattice plane the surface's cut is a network of
//     labelled contours: curves of stick vertices between junction points
//     (the face-centre vertices of the plane's faces). Every curve is
//     pressed as in the binary case, the junction points as fixed barriers
//     (PressOptions::free_ends applies to the pieces between them); two
//     pieces that continue each other through a junction point (a sphere's
//     interfaces with a box and with the background) are pressed there as
//     one curve, each with the other as context, the point left out. Each
//     stick vertex slides along its stick and averages its two planes'
//     proposals.
// Every vertex stays in its element (stick, face, cube), away from the
// lattice samples by the margin, and every triangle lies in one cube: a
// cube's corner is an extreme point of the cube, so no triangle of the cube
// can contain it while its vertices move. So no sample changes side: each
// sample stays inside its own label's closed surface and outside every other.
// Then the result is checked cube by cube with exact predicates (triangles
// of different cubes meet only in the shared faces' contour segments): the
// vertices of a cube whose triangles intersect or degenerate are pinned at
// their midpoints and both stages run again around them; a cube that still
// fails is put back at its midpoints (where every label case is free of
// intersection), rechecking the cubes that share its vertices. So the
// pressed surface is free of self-intersection by construction.
#pragma once

#include <cstddef>
#include <optional>

#include "voxpress/labels/shared_fit.h"
#include "voxpress/labels/shared_flats.h"
#include "voxpress/labels/shared_sharpen.h"
#include "voxpress/labels/shared_surface.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress {

struct SharedPressStats {
  size_t junction_curves = 0;    ///< junction lines (open between fixed points, or closed)
  size_t junction_moving = 0;    ///< their vertices that move
  size_t junction_fixed = 0;     ///< junction vertices kept in place (branch and end points, 4+ labels)
  size_t junction_on_flats = 0;  ///< junction vertices placed where their neighbours' flats meet
  size_t plane_curves = 0;       ///< pieces of labelled contours and closed contours on the planes
  size_t continued = 0;          ///< pieces pressed on through a junction point into the piece continuing them
  size_t cubes_pinned = 0;       ///< cubes that failed the exact check and were pressed again pinned
  size_t cubes_reset = 0;        ///< cubes put back at their midpoints after that
  size_t flat_vertices = 0;      ///< stick vertices frozen on a flat
  PressStats junctions, interfaces;
  double seconds = 0;
};

/// Presses the shared surface in place (mesh positions). `options` drives
/// both stages (iterations, step, arc length, margin, levels, momentum,
/// circle correction, free ends). With `flats` (find_shared_flats of this
/// surface), their vertices are frozen on their planes and those at sharp
/// borders cut the slice curves. Deterministic for any thread count.
SharedPressStats press_shared(SharedSurface& surface, const PressOptions& options = {},
                              const SharedFlats* flats = nullptr);

/// What `press --labels` and Python's press_labels() do by default: the
/// shared surface of `volume` (whose labels and boxes `table` lists),
/// each label's flats when options.passes has them, pressed by
/// options.press (with options.overrides), fitted (options.fit,
/// Pass::quadric_fit; shared_fit.h), then sharpened where labels have flats
/// (options.sharp, Pass::sharpen; shared_sharpen.h): smooth_surface's
/// stages, on the shared surface. Throws InputError when float32
/// output could not keep every sample on its side (require_float32_room).
struct SharedLabels {
  SharedSurface surface;
  std::optional<SharedFlats> flats;  ///< empty with --no-flats
  SharedPressStats press;
  SharedFitStats fit;          ///< when options.passes has Pass::quadric_fit
  SharedSharpenStats sharpen;  ///< labels with flats, when options.passes has Pass::sharpen
  SimplifyStats simplify;      ///< with options.simplify (faces: the shared surface's triangles)
  double seconds_extract = 0;
  /// The feature layer's passes as each label ran them (its detection, fit
  /// and sharpening), summed over the labels: the binary pipeline's table.
  PassTimes passes;
};
SharedLabels press_shared_labels(const ScalarVolume& volume, const LabelTable& table, const SurfaceOptions& options);
/// The same on a shared surface already extracted from `source` (press --labels --chunk
/// assembles it from blocks), each label's mask for its flats from `masks`.
SharedLabels press_shared_labels(SharedSurface surface, const LabelMasks& masks, const LabelTable& table,
                                 const SurfaceOptions& options, const std::string& source);

}  // namespace voxpress
