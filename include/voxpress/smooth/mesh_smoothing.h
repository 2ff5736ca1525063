// voxpress/smooth/mesh_smoothing.h — smoothing a staircase mesh without its
// volume (Bade, Konrad and Preim, "Reducing artifacts in surface meshes
// extracted from binary volumes"), and the unconstrained baselines.
//
// A marching-cubes mesh of a binary volume has every vertex at the midpoint
// of a lattice edge (a stick). recover_lattice() reads the lattice back from
// the mesh alone (Section 3): cell size per axis from the triangle edge
// extents, the sample phase from the lowest vertex, and each vertex's edge
// (axis and lower sample). constrained_smooth() then relaxes the mesh
// (Section 4), every vertex moved to the mean of its neighbours and clipped:
//   cell-size  to the box of +-1/2 cell around its start (4.1; no guarantee:
//              samples may change side),
//   cell-edge  to its own lattice edge (4.3),
//   diamond    to the octahedron |dx|/hx + |dy|/hy + |dz|/hz <= 1/2 around
//              its start (4.4; its tips are the edge's two samples).
// cell-edge and diamond keep every lattice sample on its side: relative to a
// corner S of a cell, every point strictly inside the diamond of any of the
// cell's 12 edges lies strictly on one side of the plane through S normal to
// the cell diagonal away from S (its L1 distance to the edge midpoint is
// below 1/2, and the midpoints are at least 1/2 beyond that plane), so a
// triangle of that cell never contains S; the regions are convex, so no
// sample is crossed while vertices move either (docs/ARCHITECTURE.md).
// Both are tested against the volume; cell-size has no such guarantee.
//
// fair() is Laplacian or Taubin lambda/mu smoothing of any mesh, no constraint.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/lattice.h"
#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/extract/sticks.h"

namespace voxpress {

/// A marching-cubes mesh tied to its lattice: vertex v lies on the lattice
/// edge from sample lower[v] to lower[v] + e_axis[v].
struct LatticeMesh {
  Lattice lattice;                            ///< dims cover every edge's samples
  Mesh mesh;                                  ///< physical positions, outward triangles
  std::vector<std::array<int64_t, 3>> lower;  ///< per vertex: lower sample index of its edge
  std::vector<uint8_t> axis;                  ///< per vertex: the edge's axis (0, 1, 2)
  size_t welded = 0;                          ///< duplicate vertices merged on input (STL)
  double misfit = 0;                          ///< largest input offset from the ideal midpoint, cells
  /// Index-space position of vertex v's edge midpoint.
  Vec3 midpoint(size_t v) const;
};

struct RecoverOptions {
  /// How far (fraction of a cell) an extent or a coordinate may be from its
  /// ideal value: float32 files (STL) carry ~1e-7 relative rounding.
  double tolerance = 0.01;
};

/// Recovers the lattice of a marching-cubes mesh given in physical units
/// (Bade Section 3: 3.2 cell size, 3.3 cell centre, 3.4 cell edge). The mesh
/// is welded first (STL stores every corner separately) and its vertices are
/// snapped to their ideal edge midpoints. The lattice is axis-aligned
/// (direction = identity); its origin is the lowest sample of any edge.
/// Throws InputError(source, ...) naming the test that failed: no triangles,
/// an axis without a cell size, triangle edge extents other than 0, h/2, h
/// (rotated, remeshed, decimated or smoothed meshes), a vertex that is not at
/// an edge midpoint, or two vertices on one edge.
LatticeMesh recover_lattice(Mesh mesh, const std::string& source, const RecoverOptions& options = {});

/// The midpoint surface of a stick surface with its known lattice (any
/// spacing and direction; no recovery needed).
LatticeMesh lattice_mesh(const StickSurface& surface);

enum class MeshConstraint { cell_size, cell_edge, diamond };
const char* constraint_name(MeshConstraint c);
/// "cell-size", "cell-edge", "diamond"; throws UsageError otherwise.
MeshConstraint parse_constraint(const std::string& name);

struct ConstrainedOptions {
  MeshConstraint constraint = MeshConstraint::diamond;
  double threshold = 0.002;  ///< stop when no vertex moved more than this in one iteration (cells)
  int max_iterations = 1000;
  /// Kept away from the region's sample tips, as a fraction of the edge
  /// (cell-edge: t in [margin, 1 - margin]; diamond: L1 radius (1 - 2 margin) / 2).
  double margin = 0.01;
  Progress* progress = nullptr;
};

struct SmoothStats {
  int iterations = 0;
  double last_max_change = 0;  ///< cells (constrained) or physical units (fair)
  bool converged = false;      ///< stopped by the threshold, not by the cap
  double seconds = 0;
};

/// Relaxes mesh.mesh.positions in place (Section 4). Each iteration visits
/// the vertices in order and moves each to the mean of its neighbours'
/// current positions, clipped to its region (Gauss-Seidel, as the paper's
/// loop; serial, so the result does not depend on the thread count).
/// Vertex normals, now stale, are dropped; other attributes are kept.
SmoothStats constrained_smooth(LatticeMesh& mesh, const ConstrainedOptions& options = {});

struct FairOptions {
  enum class Kind { laplacian, taubin } kind = Kind::taubin;
  /// Taubin: one iteration = a lambda step then a mu step (Bade Fig. 2:
  /// lambda 0.7143, mu -0.7692, 110 iterations). Laplacian: lambda steps.
  double lambda = 0.7143, mu = -0.7692;
  int iterations = 110;
  Progress* progress = nullptr;
};
/// Defaults per kind: Taubin as Bade Fig. 2; Laplacian lambda 0.5, 20 iterations.
FairOptions fair_defaults(FairOptions::Kind kind);

/// Unconstrained umbrella smoothing of any mesh, in place (simultaneous
/// updates, parallel, deterministic). Stale vertex normals are dropped.
SmoothStats fair(Mesh& mesh, const FairOptions& options = fair_defaults(FairOptions::Kind::taubin));

}  // namespace voxpress
