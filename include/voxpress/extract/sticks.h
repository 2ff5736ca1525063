// voxpress/extract/sticks.h — sticks and the midpoint (stick) surface.
//
// A stick is a lattice edge whose two samples differ (Pressing, Section 1).
// The surface has exactly one vertex per stick, at parameter t in (0, 1)
// from the stick's lower sample (t = 0.5 is the midpoint surface), and its
// triangles come from the derived marching-cubes cases (cube_cases.h), so it
// is closed, 2-manifold and outward-oriented for any binary volume.
//
// Index space is padded: samples beyond the lattice are outside, so the
// surface also closes around volumes that touch the border (its vertices may
// then lie half a cell outside the lattice box).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"

namespace voxpress {

struct StickSurface {
  Lattice lattice;                  ///< the source volume's lattice (unpadded)
  std::array<int64_t, 3> padded{};  ///< lattice.dims + 2 (one outside layer on each side)

  // Per stick, in canonical order: by padded sample row (k outer, j inner),
  // then x-sticks, y-sticks, z-sticks of the row, each by increasing i.
  std::vector<uint64_t> lower;  ///< padded linear index of the stick's lower sample
  std::vector<uint8_t> code;    ///< bits 0-1: axis (0, 1, 2); bit 2: lower sample is inside
  std::vector<double> t;        ///< vertex parameter along the stick, in (0, 1)

  /// Triangles as stick ids, counter-clockwise seen from outside in index space.
  std::vector<Triangle> triangles;

  size_t stick_count() const { return lower.size(); }
  int axis(size_t s) const { return code[s] & 3; }
  bool lower_inside(size_t s) const { return (code[s] >> 2) & 1; }
  /// Unpadded index of the stick's lower sample (components may be -1).
  std::array<int64_t, 3> lower_index(size_t s) const;
  /// Index-space position of the stick's vertex: lower_index + t * e_axis.
  Vec3 index_position(size_t s) const;
  /// Index-space positions of the stick's lower and upper samples.
  std::array<Vec3, 2> sample_points(size_t s) const;
  /// Index-space position of the stick's inside (outside) sample.
  Vec3 inside_sample(size_t s) const { return sample_points(s)[lower_inside(s) ? 0 : 1]; }
  Vec3 outside_sample(size_t s) const { return sample_points(s)[lower_inside(s) ? 1 : 0]; }
};

struct ExtractOptions {
  Progress* progress = nullptr;  ///< optional progress sink and cancellation
  uint64_t max_bytes = 0;        ///< refuse (LimitError) if the output would exceed this; 0 = no cap
  /// What the caller's later stages need per stick (smooth_surface: its
  /// method's measured peak), counted against max_bytes with the volume and
  /// the surface, so a run that cannot fit is refused before any work on it.
  uint64_t later_bytes_per_stick = 0;
  uint64_t held_bytes = 0;  ///< what the caller already holds, counted with the estimate against max_bytes
};

struct ExtractStats {
  uint64_t samples = 0;          ///< lattice samples visited
  uint64_t sticks = 0;
  uint64_t triangles = 0;
  double seconds_sticks = 0;     ///< classification + stick counting and filling
  double seconds_triangles = 0;  ///< cube cases and triangle filling
};

/// The stick surface of a binary volume, every t = 0.5 (the midpoint surface).
/// Deterministic: identical output for any number of threads.
/// Throws LimitError when more than 2^32 - 1 sticks would be produced or the
/// estimated output exceeds options.max_bytes.
StickSurface extract_sticks(const BinaryVolume& volume, const ExtractOptions& options = {},
                            ExtractStats* stats = nullptr);

/// Where on_own_box moved a surface from.
struct OwnBox {
  Lattice lattice;              ///< the sticks' lattice before
  std::array<int64_t, 3> lo{};  ///< the box's first sample on it
};

/// The same sticks (same order, same t) on the lattice of their own box: the
/// box of their lower samples, upper samples included, its origin at the
/// box's first sample. Physical positions are unchanged, index positions are
/// relative to the box, so a shifted, padded or cropped volume gives the
/// same index arithmetic (smooth_sticks runs every stage on it). Every
/// inside sample lies in the box (each is enclosed by sticks along every
/// axis), so the samples beyond it are outside, as the padding assumes.
/// `frame`, if given, receives what off_own_box needs to undo it.
StickSurface on_own_box(StickSurface surface, OwnBox* frame = nullptr);
/// The same sticks (same order, same t) back on the lattice on_own_box left.
StickSurface off_own_box(StickSurface surface, const OwnBox& frame);

/// Global key of a stick of a volume of `dims` samples: its lower sample
/// (p, q, r) in padded index space (unpadded + 1) and axis a, ordered as
/// extract_sticks orders sticks: ((r * (ny + 2) + q) * 3 + a) * (nx + 2) + p.
/// Names a stick across blocks (chunked.h) and across labels (shared_flats.h).
uint64_t stick_key(const std::array<int64_t, 3>& dims, const std::array<int64_t, 3>& padded_lower, int axis);

/// The classification pass alone: number of sticks (used by `voxpress info`).
uint64_t count_sticks(const BinaryVolume& volume);

/// The surface as a mesh in physical units (vertex s = stick s). Winding is
/// reversed when the lattice flips handedness, so normals stay outward.
Mesh to_mesh(const StickSurface& surface);

/// Throws InputError(volume.source, ...) for an empty volume (no inside
/// sample) or a full one (every sample inside: the surface would only be the
/// lattice's bounding box, which is almost always a wrong --label/--threshold).
void require_mixed(const BinaryVolume& volume);

}  // namespace voxpress
