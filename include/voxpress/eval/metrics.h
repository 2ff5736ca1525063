// voxpress/eval/metrics.h — fidelity of a result mesh against the truth.
//
// Reported in physical units and in voxel units (lengths measured in the
// lattice's index space, i.e. in cells; for isotropic spacing simply
// physical / spacing):
//   * stick metric (Pressing, Table 2): RMS over the result's vertices that
//     lie on sticks of the volume of |t - t_true|, t_true where the true
//     surface crosses that stick (the crossing nearest the vertex);
//   * result -> truth and truth -> result distances (RMS, mean, max), both
//     sides sampled uniformly by area (the result's vertices also count for
//     the max), and the symmetric Hausdorff distance; optionally
//     (EvalOptions::quadrature) result -> truth RMS integrated over every
//     triangle by a 7-point rule, which, unlike the samples, does not move
//     when the mesh changes elsewhere (comparing two nearly equal meshes);
//   * area-weighted mean angle between the result's face normals and the
//     true normal at the closest point (where that point lies on a crease,
//     the normal of the incident true face best aligned with the result's);
//   * volume ratio result / truth; classification violations against the
//     volume; the check_mesh verdict;
//   * two-sided Hausdorff between the true sharp edges (dihedral angle above
//     sharp_angle_deg) and the result's labelled sharp edges (Mesh::edges),
//     both sampled every 0.1 cell; with the volume, also the share of each
//     set's length within sharp_match_vox voxels of the other (recall: of
//     the true curves; precision: of the labelled ones).
// Sampling is deterministic (seeded, counter-based) and parallel; the
// numbers do not depend on the thread count.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"
#include "voxpress/eval/checks.h"
#include "voxpress/eval/truth.h"

namespace voxpress {

struct DistanceStats {
  double rms = 0, mean = 0, max = 0;
  size_t count = 0;
};

struct EvalOptions {
  size_t samples = 400000;                ///< area samples per direction
  uint64_t seed = 1;
  double sharp_angle_deg = 30;            ///< dihedral angle above which a true edge is sharp
  double sharp_match_vox = 0.5;           ///< voxels: a sharp curve point this close to the other set is matched
  const BinaryVolume* volume = nullptr;   ///< enables the stick metric, voxel units and classification
  bool self_intersections = true;         ///< check_mesh's expensive part
  bool quadrature = false;                ///< also result -> truth RMS by a 7-point rule per triangle
  Progress* progress = nullptr;
};

struct EvalReport {
  size_t vertices = 0, faces = 0;
  // Stick metric (needs the volume): vertices found on sticks and the RMS error.
  size_t stick_vertices = 0;
  std::optional<double> stick_rms_vox, stick_rms, stick_max_vox;
  // Distances in physical units and in voxel units.
  DistanceStats result_to_truth, truth_to_result, result_to_truth_vox, truth_to_result_vox;
  double hausdorff = 0;
  std::optional<double> hausdorff_vox;
  /// Result -> truth RMS by the 7-point rule (Dunavant degree 5) on every
  /// triangle, area-weighted (EvalOptions::quadrature); voxels with the volume.
  std::optional<double> result_to_truth_rule_rms, result_to_truth_rule_rms_vox;
  double normal_error_deg = 0;  ///< area-weighted mean angle
  double volume_ratio = 0;
  std::optional<uint64_t> classification_violations;
  MeshCheck mesh;
  size_t true_sharp_edges = 0;             ///< segments of the truth's sharp curves
  size_t labelled_sharp_edges = 0;         ///< the result's labelled sharp edges (Mesh::edges)
  /// Largest distance from a true sharp curve to the labelled ones, the
  /// reverse, and their maximum (two-sided Hausdorff); n/a when either set is
  /// empty. Physical units, and in voxels when the volume is known.
  std::optional<double> sharp_true_to_labelled, sharp_labelled_to_true, sharp_edge_hausdorff;
  std::optional<double> sharp_true_to_labelled_vox, sharp_labelled_to_true_vox, sharp_edge_hausdorff_vox;
  /// With the volume: the share of the true sharp curves' length within
  /// sharp_match_vox voxels of a labelled curve (recall), and of the
  /// labelled curves' length within as much of a true one (precision; 0
  /// when the truth has none and some are labelled).
  /// The Hausdorff distance is one worst point; these say how much of the
  /// feature network is found, and how much of what is labelled is real.
  std::optional<double> sharp_recall, sharp_precision;
  std::string truth;
};

EvalReport evaluate(const Mesh& result, const Truth& truth, const EvalOptions& options = {});

/// The point of the segments nearest p (p itself when there are none); the
/// sharp-edge metric's distance, also used by benchmarks and tests.
Vec3 closest_on_segments(const Vec3& p, const std::vector<std::array<Vec3, 2>>& segments);

}  // namespace voxpress
