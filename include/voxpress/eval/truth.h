// voxpress/eval/truth.h — the true solid a volume was sampled from.
//
// A Truth answers, in the physical frame of the volume: the closest surface
// point and the outward normal there, inside/outside, where a segment
// crosses the surface, uniform-by-area surface samples, area, volume and the
// sharp feature curves. Analytic shapes (sphere, torus, box, cylinder) answer
// exactly from closed forms; meshes (voxelized models, the CAD part's B-rep)
// through a BVH. All queries are const and thread-safe.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"
#include "voxpress/eval/shapes.h"

namespace voxpress {

struct SurfacePoint {
  Vec3 point;
  Vec3 normal;  ///< unit, outward
};

class Truth {
 public:
  virtual ~Truth() = default;
  /// e.g. "sphere (analytic)", "fandisk.off (mesh, 14454 faces)".
  virtual std::string describe() const = 0;
  /// Closest surface point and the outward normal there. Where the closest
  /// point lies on several faces (an edge or a corner of the truth), the
  /// normal is that of the incident face best aligned with `normal_hint`
  /// when given (the metrics pass the result's own face normal), else any.
  virtual SurfacePoint closest(const Vec3& p, const Vec3* normal_hint = nullptr) const = 0;
  /// Inside or on the surface.
  virtual bool contains(const Vec3& p) const = 0;
  /// Parameter s in [0, 1] of a crossing of the segment a + s (b - a) with
  /// the surface, the one nearest to `near`; NaN when there is none.
  virtual double crossing(const Vec3& a, const Vec3& b, double near) const = 0;
  /// Point number `index` of a deterministic uniform-by-area sequence.
  virtual SurfacePoint sample(uint64_t seed, uint64_t index) const = 0;
  virtual double area() const = 0;
  virtual double volume() const = 0;
  /// Sharp feature curves as segments: mesh edges whose dihedral angle
  /// exceeds `angle_deg` (analytic shapes: their creases, finely sampled).
  virtual std::vector<std::array<Vec3, 2>> sharp_edges(double angle_deg) const = 0;
};

/// An analytic shape placed by physical = translation + linear * model
/// (linear a similarity, as generate_shape produces). The CAD part is a mesh
/// truth. `fillet`: the box's or cylinder's fillet radius in model units
/// (GeneratedShape::fillet); a filleted shape has no sharp edges (C1).
std::unique_ptr<Truth> shape_truth(ShapeKind kind, const Mat3& linear, const Vec3& translation, double fillet = 0);

/// A closed mesh in the physical frame, taken by value. `name` is used by describe().
std::unique_ptr<Truth> mesh_truth(Mesh physical_mesh, const std::string& name);

/// Resolves a truth for evaluation. `spec` is a shape name, a mesh file, or
/// empty; `volume` (may be null) is the volume the result was extracted
/// from: its metadata (written by `voxpress generate` / `voxpress voxelize`)
/// supplies the model -> physical transform, and the truth itself when spec
/// is empty. Throws UsageError / InputError explaining what is missing.
std::unique_ptr<Truth> resolve_truth(const std::string& spec, const ScalarVolume* volume);

/// Metadata keys written by `voxpress voxelize` (see also kShapeKey and
/// kModelToPhysicalKey in shapes.h).
inline constexpr const char* kTruthMeshKey = "voxpress_truth_mesh";

/// 12 numbers (row-major 3x3, then translation) <-> transform.
std::string format_transform(const Mat3& linear, const Vec3& translation);
bool parse_transform(const std::string& text, Mat3& linear, Vec3& translation);

}  // namespace voxpress
