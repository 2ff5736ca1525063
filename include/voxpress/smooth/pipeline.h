// voxpress/smooth/pipeline.h — one call from a binary volume to its smooth
// surface: what `voxpress press` runs (and the Python binding will).
//
//   pressing   sticks -> Pressing with flats and junctions -> sharp edges
//              (each stage optional; the default and the reference method)
//   cesn       Constrained Elastic Surface Nets from the volume
//   diamond, cell-edge, cell-size
//              Bade et al.'s relaxation of the midpoint mesh, lattice known
//   taubin, laplacian
//              unconstrained smoothing of the midpoint mesh
//
// Only pressing, diamond and cell-edge keep every sample on its side
// (keeps_classification); all methods give closed, 2-manifold, outward
// meshes. Deterministic: the same mesh for any thread count.
#pragma once

#include <optional>
#include <string>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/features/passes.h"
#include "voxpress/features/flats.h"
#include "voxpress/smooth/mesh_smoothing.h"
#include "voxpress/smooth/pressing.h"
#include "voxpress/features/sharpen.h"
#include "voxpress/smooth/surface_nets.h"
#include "voxpress/simplify/simplify.h"

namespace voxpress {

enum class Method { pressing, cesn, diamond, cell_edge, cell_size, taubin, laplacian };
/// "pressing", "cesn", "diamond", "cell-edge", "cell-size", "taubin", "laplacian".
const char* method_name(Method m);
/// Inverse of method_name; throws UsageError listing the valid names.
Method parse_method(const std::string& name);
/// True for the methods that keep every lattice sample on its side.
bool keeps_classification(Method m);

/// What a user set of a method's iteration cap, stopping tolerance and
/// Taubin / Laplacian steps; unset fields keep the method's own default.
/// Shared by smooth_surface and the mesh-only path (`voxpress smooth-mesh`).
struct MethodOverrides {
  std::optional<int> iterations;
  std::optional<double> tolerance, lambda, mu;
  void apply(PressOptions& o) const;        ///< iterations, tolerance
  void apply(SurfaceNetOptions& o) const;   ///< max_iterations, threshold
  void apply(ConstrainedOptions& o) const;  ///< max_iterations, threshold
  void apply(FairOptions& o) const;         ///< iterations, lambda, mu
};

struct SurfaceOptions {
  Method method = Method::pressing;
  // --- pressing
  PressOptions press;
  FlatOptions flat;          ///< flats and junctions (Section 3); flat.passes and sharp.passes are set from `passes`
  QuadricFitOptions fit;     ///< the local quadric fit after pressing; margin from press
  SharpenOptions sharp;      ///< sharp edges (Section 5)
  /// The feature layer's passes (voxpress/features/passes.h): disable
  /// Pass::flats for plain Pressing, Pass::sharpen to keep the chamfers.
  PassSet passes;
  bool color_regions = false;  ///< vertex colours per region
  // --- every method: when set, the iteration cap and the stopping tolerance
  // (pressing: over press.iterations / press.tolerance); lambda and mu for
  // taubin and laplacian only (UsageError otherwise)
  MethodOverrides overrides;
  // --- all
  /// Fewer triangles at the end, every sample still on its side
  /// (voxpress/simplify/simplify.h): faces and max_error; the lattice is the
  /// volume's. Both zero (the default): no simplification.
  SimplifyOptions simplify;
  ExtractOptions extract;
  Progress* progress = nullptr;  ///< overrides the stages' own progress pointers
};

struct SurfaceResult {
  Mesh mesh;                   ///< physical units, outward triangles
  ExtractStats extract;
  // pressing
  PressStats press;
  FlatSegmentation flats;      ///< empty without flats
  QuadricFitStats fit;
  SharpenStats sharpen;
  // the other methods
  SmoothStats smooth;          ///< diamond, cell-edge, cell-size, taubin, laplacian
  SurfaceNetStats net;         ///< cesn
  PassTimes pass_times;         ///< pressing: seconds and counts per pass
  SimplifyStats simplify;      ///< with options.simplify set
  double seconds_extract = 0, seconds_smooth = 0;
};

/// Throws UsageError naming the first option out of its range (NaN,
/// negative or absurd counts, angles, tolerances, margins): the one check
/// the CLI and the Python module share. smooth_surface calls it.
void validate(const SurfaceOptions& options);

/// Peak bytes per stick of `options`' stages after extraction (the memory
/// model smooth_surface checks against options.extract.max_bytes).
uint64_t bytes_per_stick(const SurfaceOptions& options);

/// Throws InputError(source, ...) when `lattice`'s coordinates are too large
/// for float32 output to keep every sample on its side at options' margin.
void require_float32_room(const Lattice& lattice, const SurfaceOptions& options, const std::string& source);

/// The pressing stages that keep one vertex per stick, in place: Pressing
/// (with flats and junctions when options.passes has them) and the local
/// quadric fit; fills r.press, r.flats, r.fit, r.pass_times. smooth_surface
/// runs it, then sharpens; the chunked run (chunk/chunked.h) stitches its
/// blocks' sticks. Every stage runs on the sticks' own box (on_own_box), so
/// t does not depend on where the volume lies; r.flats' index planes are in
/// that box's frame (sharpen them on on_own_box(surface)).
void press_stick_surface(StickSurface& surface, const SurfaceOptions& options, SurfaceResult& r);

/// The volume's smooth surface by `options.method`. Throws InputError for an
/// empty or full volume, UsageError for invalid options, LimitError when
/// options.extract.max_bytes would be exceeded.
SurfaceResult smooth_surface(const BinaryVolume& volume, const SurfaceOptions& options = {});

/// What smooth_surface does after extraction, on a volume's stick surface
/// (the whole volume's: every stage reads the sticks, never the samples).
/// press_chunked's exact mode runs it on the sticks stitched from blocks.
/// r carries what the caller measured before (extract stats and seconds).
SurfaceResult smooth_sticks(StickSurface surface, const SurfaceOptions& options, SurfaceResult r = {});

/// The last stage: r.mesh simplified by options.simplify against `lattice`'s
/// samples (nothing when neither faces nor max_error is set); fills
/// r.simplify. smooth_sticks runs it; press_chunked's halo mode too.
void simplify_result(const Lattice& lattice, const SurfaceOptions& options, SurfaceResult& r);

}  // namespace voxpress
