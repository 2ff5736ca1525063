// voxpress/simplify/simplify.h — fewer triangles, the same guarantees.
//
// Quadric-error edge collapse (Garland and Heckbert 1997) in which every
// collapse is a checked move: it is refused when a lattice sample would
// cross the surface on the way or end within the float32 clearance of it,
// when a triangle would turn over, degenerate or come within the clearance
// of another, or when the link condition fails (so a closed 2-manifold stays
// one). What the surface carries is kept: labelled edges (mesh.edges, the
// sharp creases) and the borders between faces whose face attributes differ
// (flats, label pairs) stay edges of the mesh, their vertices slide along
// them only and their corners never move; every other vertex is the
// quadric's minimiser or an input vertex. A flat therefore ends as large
// triangles inside its borders (a few dozen on a 256^3 part at 2 %: its
// vertices, clamped to their sticks, are not all on its plane). Collapses
// run in rounds of non-touching edges, cheapest first, checked in parallel
// and applied in (cost, edge) order: the same bytes for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/lattice.h"
#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"

namespace voxpress {

struct SimplifyOptions {
  /// Stop at this many triangles or fewer (0: no count target).
  uint64_t faces = 0;
  /// Physical units: no input vertex may end farther than this from the
  /// simplified surface, nor a placed vertex from the patch it replaces
  /// (0: no bound). With faces = 0, simplify as far as this allows.
  double max_error = 0;
  /// The lattice whose samples keep their side (index space = sample
  /// positions; the mesh is in its physical space). nullptr: no samples
  /// (voxel art), the other checks still hold.
  const Lattice* lattice = nullptr;
  /// Per-face keys whose borders are only penalised, not kept (voxel art's
  /// colours: the plane through the border, perpendicular to each face, is
  /// added to the quadrics). Empty: none.
  std::vector<uint32_t> soft_keys;
  /// Accept edges of three or more faces (a label map's shared surface:
  /// its junction lines), kept as feature edges like the borders.
  bool junctions = false;
  Progress* progress = nullptr;
};

struct SimplifyStats {
  uint64_t faces_before = 0, faces_after = 0, vertices_after = 0;
  uint64_t collapses = 0;
  uint64_t in_plane = 0;  ///< of those, proven inside one plane (no clash query needed)
  /// Candidate collapses refused, by the first check that failed.
  uint64_t refused_topology = 0;  ///< link condition, a tetrahedron, a feature rule
  uint64_t refused_shape = 0;     ///< a face would turn over, degenerate or be thinner than the clearance
  uint64_t refused_samples = 0;   ///< a lattice sample would cross or come within the clearance
  uint64_t refused_clash = 0;     ///< two faces would meet or come within the clearance
  uint64_t refused_error = 0;     ///< beyond max_error
  /// Physical units: the largest distance of an input vertex to the result,
  /// measured on the result (with max_error set, the bound that was kept is
  /// checked per collapse and this figure is at most max_error).
  double error = 0;
  double seconds = 0;
};

/// Simplifies a closed, oriented 2-manifold in place (physical units). Vertex
/// data of the surviving vertices (colours, attributes, texture coordinates)
/// is kept, face attributes are kept per surviving face, normals are
/// recomputed, mesh.edges keep the labelled edges that survive. Throws
/// std::invalid_argument for a mesh that is not a closed 2-manifold (or,
/// with options.junctions, one whose every edge has two faces wound
/// oppositely or three and more). `vertex_map`, when given, receives per
/// input vertex its output index or UINT32_MAX (removed).
SimplifyStats simplify(Mesh& mesh, const SimplifyOptions& options, std::vector<uint32_t>* vertex_map = nullptr);

}  // namespace voxpress
