// voxpress/eval/checks.h — the invariant checkers every method and test reuses.
//
// check_mesh: closed, 2-manifold, consistently and outwardly oriented, no
// degenerate faces, no self-intersections. check_classification: every
// lattice sample strictly on its own side of the mesh (the in/out guarantee).
// Both are exact (filtered floating point with an exact fallback), run cheap
// checks before expensive ones, and report; they never throw on a bad mesh.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"

namespace voxpress {

struct MeshCheckOptions {
  bool self_intersections = true;  ///< the expensive part (BVH + exact triangle tests)
  size_t max_examples = 8;         ///< problems listed per kind
};

struct MeshCheck {
  size_t vertices = 0, faces = 0, edges = 0;
  size_t invalid_indices = 0;        ///< faces referencing a missing vertex (other checks skipped)
  size_t degenerate_faces = 0;       ///< repeated vertex or collinear corners (exact)
  size_t boundary_edges = 0;         ///< edges with one face
  size_t nonmanifold_edges = 0;      ///< edges with more than two faces
  size_t misoriented_edges = 0;      ///< two faces traversing the edge in the same direction
  size_t nonmanifold_vertices = 0;   ///< faces around the vertex form more than one fan
  size_t unreferenced_vertices = 0;
  size_t self_intersections = 0;     ///< intersecting face pairs (beyond shared vertices/edges)
  bool self_intersections_checked = false;
  size_t components = 0;             ///< edge-connected face components
  int64_t euler = 0;                 ///< V - E + F over referenced vertices
  double signed_volume = 0;
  double area = 0;
  std::vector<std::string> problems; ///< human-readable; empty means the mesh is valid

  bool closed() const { return boundary_edges == 0 && invalid_indices == 0; }
  bool manifold() const { return nonmanifold_edges == 0 && nonmanifold_vertices == 0; }
  bool oriented() const { return misoriented_edges == 0; }
  bool ok() const { return problems.empty(); }
};

/// Checks a mesh. Problems are: invalid indices, degenerate faces, boundary,
/// non-manifold or misoriented edges, non-manifold or unreferenced vertices,
/// self-intersections, and a negative enclosed volume (inward orientation) of
/// a closed, oriented mesh.
MeshCheck check_mesh(const Mesh& mesh, const MeshCheckOptions& options = {});

struct ClassificationOptions {
  /// winding: a sample is inside when the mesh's winding number around it is
  /// positive (an inverted mesh fails); parity: when a ray from it crosses the
  /// mesh an odd number of times (orientation-blind, for other tools' meshes).
  enum class Rule { winding, parity } rule = Rule::winding;
  /// Also check the ring of virtual outside samples one index beyond the
  /// lattice on every side (a surface must not swallow them either).
  bool include_padding = true;
  size_t max_examples = 8;
  Progress* progress = nullptr;
};

struct ClassificationReport {
  uint64_t samples = 0;            ///< samples checked
  uint64_t violations = 0;         ///< = inside_outside + outside_inside + on_surface
  uint64_t inside_found_outside = 0;
  uint64_t outside_found_inside = 0;
  uint64_t on_surface = 0;         ///< samples lying exactly on the mesh
  std::vector<std::array<int64_t, 3>> examples;  ///< sample indices of the first violations
};

/// Classifies every lattice sample against a closed mesh given in the
/// volume's physical space and compares with the volume. Exact: rays run
/// along lattice rows, symbolically perturbed off vertices and edges.
ClassificationReport check_classification(const Mesh& mesh, const BinaryVolume& volume,
                                          const ClassificationOptions& options = {});

/// Planes [k0, k1) of a volume as a BinaryVolume of dims (nx, ny, k1 - k0).
using PlaneReader = std::function<BinaryVolume(int64_t k0, int64_t k1)>;

/// The same check on a volume too large to hold: `lattice` is the whole
/// volume's, its planes are read `slab` at a time (0: as many as make ~32 M
/// samples). Same report, sample for sample, as the in-memory check.
ClassificationReport check_classification(const Mesh& mesh, const Lattice& lattice, const PlaneReader& read,
                                          const ClassificationOptions& options = {}, int64_t slab = 0);

}  // namespace voxpress
