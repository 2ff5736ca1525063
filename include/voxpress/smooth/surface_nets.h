// voxpress/smooth/surface_nets.h — Constrained Elastic Surface Nets
// (Gibson, MICCAI 1998), the volume-based baseline of Bade et al.
//
// The net is the dual of the marching-cubes surface: one vertex per surface
// patch of a mixed cell (a cell whose corners differ), one quad per stick
// joining the four patches around it, wound outward. Gibson puts one vertex
// in each mixed cell; where a cell holds several patches (samples touching
// only along an edge or at a corner) that single vertex would join sheets
// that the face rule keeps apart and make the net non-manifold, so each
// patch gets its own vertex instead. Two patches of face-adjacent cells may
// still share both segments of an ambiguous face (a thin bent tube): their
// net edge would be used by four quads. That edge is split: each segment
// gets its own vertex, kept in the quarter of the face at the inside corner
// the segment cuts off, and the polygons through it are fanned from it.
// The result is closed, 2-manifold and oriented for every binary volume.
//
// Relaxation (Gibson): every vertex moves to the mean of its net neighbours
// and is clamped to its cell (to the bounding box of its patch's edge
// midpoints in cells with several patches), Gauss-Seidel in vertex order,
// until no vertex moves more than the threshold. Quads are then split along
// their shorter diagonal. Vertices stay within a cell of the midpoint
// surface, but unlike Pressing or Bade's diamond, samples may change side.
#pragma once

#include <cstddef>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/extract/sticks.h"

namespace voxpress {

struct SurfaceNetOptions {
  double threshold = 0.002;  ///< stop when no vertex moved more than this in one iteration (cells)
  int max_iterations = 1000;
  Progress* progress = nullptr;
};

struct SurfaceNetStats {
  size_t patch_vertices = 0;  ///< net vertices in mixed cells (one per patch)
  size_t split_cells = 0;     ///< mixed cells holding more than one patch
  size_t face_vertices = 0;   ///< vertices added on shared ambiguous faces
  size_t quads = 0;           ///< one per stick
  size_t triangles = 0;
  int iterations = 0;
  double last_max_change = 0;  ///< cells
  bool converged = false;
  double seconds_build = 0, seconds_relax = 0;
};

/// The relaxed surface net of a stick surface's volume, in physical units.
/// Deterministic (serial relaxation; the build does not depend on threads).
Mesh constrained_surface_net(const StickSurface& surface, const SurfaceNetOptions& options = {},
                             SurfaceNetStats* stats = nullptr);

}  // namespace voxpress
