// voxpress/eval/shapes.h — analytic solids sampled exactly onto a lattice.
//
// Each shape is an exact point-membership test in its own model frame (a few
// units across). generate_shape() rotates it, scales it so that its
// bounding box spans `res` samples along its physically longest side, and
// samples the inside test at every lattice sample: the volume is the exact
// binary discretisation, so the truth is known for evaluation. The
// model -> physical transform is returned (and stored by `voxpress generate`
// in the NRRD header) so the truth can be placed in the lattice frame.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"

namespace voxpress {

enum class ShapeKind { sphere, torus, box, cylinder, cad_part };

/// "sphere", "torus", "box", "cylinder", "cad-part".
const char* shape_name(ShapeKind kind);
/// Inverse of shape_name; throws UsageError listing the valid names.
ShapeKind parse_shape(std::string_view name);
std::vector<ShapeKind> all_shapes();

/// Exact inside test in model coordinates (points on the boundary count as inside).
///   sphere   radius 1
///   torus    major radius 1, minor radius 0.4, axis z
///   box      half extents 1 x 0.75 x 0.5
///   cylinder radius 0.6, flat caps at z = +-1
///   cad-part a 2 x 1.4 x 0.5 plate with its two -x vertical edges rounded
///            (radius 0.2) and a 45-degree chamfer on its +x top edge, a
///            cylindrical boss (radius 0.35) with a concave fillet (radius
///            0.1) at its base, and a through hole (radius 0.18); defined by
///            its exact boundary mesh, cad_part_mesh() (the test is O(#faces))
/// `fillet` (model units, box and cylinder): the edges (and the box's
/// corners) rounded with that radius, the Minkowski sum of the shape shrunk
/// by it and a ball (0: the sharp shape; below its smallest half extent).
bool shape_contains(ShapeKind kind, const Vec3& m, double fillet = 0);
/// The CAD part's exact boundary representation in model units: a closed,
/// manifold, outward triangle mesh (~0.3 M triangles; built once, ~0.1 s).
/// It *defines* the part: shape_contains and generate_shape use it.
const Mesh& cad_part_mesh();

/// A planar face of a solid's boundary: the plane normal . x = offset
/// (normal unit, outward) and the face's area.
struct PlanarFace {
  Vec3 normal{0, 0, 1};
  double offset = 0;
  double area = 0;
};
/// The planar faces of a closed triangle mesh: edge-connected sets of
/// triangles on one plane (normals within `angle_deg`, offsets within
/// `distance`), largest first. Finely tessellated curved faces come out as
/// many tiny "faces": filter by area.
std::vector<PlanarFace> planar_faces(const Mesh& mesh, double angle_deg = 1e-4, double distance = 1e-9);
/// The planar faces of a shape in model units (box: 6, cylinder: its 2
/// caps, cad-part: those of its mesh larger than 1e-3, sphere/torus: none).
std::vector<PlanarFace> shape_planar_faces(ShapeKind kind, double fillet = 0);
/// A plane under physical = translation + linear * model (linear a similarity).
PlanarFace transform_face(const PlanarFace& f, const Mat3& linear, const Vec3& translation);
/// Support function: max over the shape of m . d (d need not be unit).
double shape_support(ShapeKind kind, const Vec3& d);
/// Volume of the solid in model units^3 (closed form; one 1-D integral for
/// the CAD part's chamfer across its rounded corners). Used by tests.
double shape_volume(ShapeKind kind, double fillet = 0);

/// Parses "random:SEED", "AX,AY,AZ" (degrees, applied about x then y then z)
/// or "none". Random rotations are uniform over SO(3) and reproducible across
/// platforms (own integer RNG, no std:: distributions).
Mat3 parse_rotation(const std::string& spec);

struct GenerateOptions {
  int64_t res = 64;             ///< samples along the physically longest side, >= 8
  Vec3 spacing{1, 1, 1};        ///< physical cell size along i, j, k
  Mat3 rotation = Mat3::Identity();
  int64_t margin = 2;           ///< outside samples around the shape's bounding box
  /// Box only: its edges and corners rounded with this radius in cells (the
  /// smallest spacing). The lattice is the sharp box's, so every radius of
  /// one rotation samples the same lattice and r = 0 is the box itself.
  double fillet = 0;
  uint64_t max_bytes = 0;       ///< LimitError if the volume would exceed this (0 = no cap)
  Progress* progress = nullptr;
};

struct GeneratedShape {
  BinaryVolume volume;
  ShapeKind kind = ShapeKind::sphere;
  /// physical = translation + linear * model (linear = scale * rotation).
  Mat3 linear = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  double scale = 1;  ///< physical units per model unit
  double fillet = 0;  ///< the box's or cylinder's fillet radius in model units (GenerateOptions::fillet / scale)
};

GeneratedShape generate_shape(ShapeKind kind, const GenerateOptions& options);

/// Metadata keys under which `voxpress generate` stores the shape and its
/// model -> physical transform (12 numbers: row-major 3x3, then translation).
inline constexpr const char* kShapeKey = "voxpress_shape";
inline constexpr const char* kModelToPhysicalKey = "voxpress_model_to_physical";
/// The box's or cylinder's fillet radius in model units (absent: 0, sharp).
inline constexpr const char* kFilletKey = "voxpress_fillet";

}  // namespace voxpress
