// voxpress/chunk/chunked.h — block by block: volumes larger than memory
// (`press --chunk`) and larger than one machine (voxpress.dask).
//
// The volume is cut into blocks of `chunk` samples per side. A block is read
// with max(halo, 1) more samples on every side (clipped at the volume) and
// keeps only what it owns:
//   - a stick, when its lower sample, clamped into the volume, lies in the
//     block's core (a stick from the outside layer below the volume belongs
//     to the block holding sample 0);
//   - a cube's triangles, when the cube's lower corner, clamped the same way,
//     lies in the core.
// Every owned stick and cube lies at least one sample inside the block's
// read box, so the block sees its true samples: the stitched surface has
// exactly the sticks, triangles and order of the whole-volume run (stick s
// = whole-run stick s). Pieces name sticks by global keys, so stitching is a
// sort and a lookup: no welding, no duplicate, no crack.
//
// Two modes. Exact (halo 0): blocks are only extracted, and smoothing runs
// once on the stitched sticks, which is all smooth_surface's stages read:
// the whole-volume result byte for byte (flats and sharp edges included),
// with the volume never in memory.
// Halo (>= 1): the blocks are pressed apart too, for surfaces larger than
// one process (Dask workers), in rounds. Pressing's reach is global (its
// coarse-to-fine stages move information hundreds of cells), but one
// sweep reaches only a few cells: a sweep moves a vertex from the
// positions within twice its arc length d (times the stage's scale) plus
// two curve segments along its curves. A round runs as many sweeps of the
// whole run's schedule as the halo covers (press_rounds), so the block's
// own sticks see only true neighbours, then the blocks exchange the t and
// momentum of their sticks (PressState) and the next round starts from
// them: the whole run's sweeps exactly, up to rounding (positions are taken
// relative to each block's own box). Each block is read and extracted once
// (BlockRounds: a Dask worker keeps it between the block's rounds; in
// process, blocks are kept while they fit in half the memory cap, the rest
// read again every round). A last step (BlockRounds::finish) runs the
// quadric fit on the final t, whose reach (a dozen rings) the halo must
// also cover. Flats are off in that mode (a plane across blocks would need
// one vote over all of them); levels come from the whole volume's extent,
// so blocks press with the whole run's stages.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/smooth/pipeline.h"

namespace voxpress {

struct ChunkOptions {
  int64_t chunk = 256;  ///< block side, samples (>= 8)
  /// 0 (exact): blocks are read with one sample around them and only
  /// extracted; their sticks, stitched, are the whole volume's, and the rest
  /// of smooth_surface runs on them (any method, flats and sharp edges too):
  /// the whole-volume result byte for byte, in memory bounded by the surface
  /// and one block, not by the volume.
  /// >= 1: each block is also pressed apart, reading this many samples
  /// beyond it, in exchange rounds (voxpress.dask's workers): Pressing only,
  /// flats off; the whole run's surface up to rounding. The wider the halo,
  /// the fewer the rounds (press_rounds; too narrow for one sweep of the
  /// coarsest stage: refused).
  int64_t halo = 0;
};

/// The blocks of a volume, x fastest then y then z.
struct ChunkGrid {
  std::array<int64_t, 3> dims{};  ///< the volume's samples per axis
  int64_t chunk = 256, halo = 0;
  ChunkGrid(const std::array<int64_t, 3>& dims, const ChunkOptions& o);
  size_t count() const { return size_t(n_[0] * n_[1] * n_[2]); }
  Box core(size_t b) const;       ///< the samples block b owns
  Box with_halo(size_t b) const;  ///< core grown by max(halo, 1), clipped to the volume
  /// The block whose core holds `sample` clamped into the volume (a stick's owner: its lower sample's).
  size_t block_of(const std::array<int64_t, 3>& sample) const;

 private:
  std::array<int64_t, 3> n_{};  // blocks per axis
};

/// The whole volume's inside count and the bounding box of its inside
/// samples (the pre-pass that sets levels and refuses empty or full volumes).
struct VolumeSummary {
  uint64_t inside = 0, samples = 0;
  Box bounds{{INT64_MAX, INT64_MAX, INT64_MAX}, {INT64_MIN, INT64_MIN, INT64_MIN}};
  void add(const BinaryVolume& block, const Box& where);  ///< where: block's box in the volume
  void merge(const VolumeSummary& other);
};

/// What one block contributes, named by global keys (see stick_key).
struct SurfacePiece {
  std::vector<uint64_t> sticks;     ///< keys of the owned sticks, increasing
  std::vector<uint8_t> code;        ///< StickSurface::code of each
  std::vector<double> t;            ///< pressed t of each
  std::vector<uint64_t> triangles;  ///< owned triangles: 3 stick keys each, in whole-run order
  std::vector<double> velocity;     ///< a round's piece: the momentum of each owned stick
  /// A round's piece: per sweep of the round, the residual over the owned
  /// sticks (NaN before the last stage); BlockRounds::finish's: one, at the final t.
  std::vector<double> residuals;
  PressStats press;                 ///< the block's Pressing (iterations == 0: nothing to press)
  uint64_t block = 0, blocks = 0;   ///< which block of how many (stitch wants each exactly once)
  uint64_t count = 1;               ///< merged pieces: the blocks [block, block + count)
};


/// Block b's piece of the surface, extracted: `samples` holds
/// grid.with_halo(b) (its lattice's dims must match); its sticks keep the
/// extraction's t (the exact mode).
SurfacePiece press_block(const BinaryVolume& samples, const ChunkGrid& grid, size_t b);

/// Sweeps [first, last) of the whole run's schedule (PressOptions::iterations).
struct PressRound {
  int first = 0, last = 0;
  bool measured = false;  ///< holds sweeps of the last stage (whose residuals may stop the run)
};
/// The halo mode's rounds for `options` (as chunk_surface_options returns
/// them: levels set): each as many sweeps as keep every owned stick beyond
/// the reach of its block's artificial border. UsageError when the halo is
/// narrower than the reach of one sweep of the coarsest stage (the message
/// names the smallest halo).
std::vector<PressRound> press_rounds(const Lattice& lattice, const SurfaceOptions& options, int64_t halo);

/// Where a round starts: the last round's pieces (each block's at most
/// once: all of them, or those of the blocks around the one reading them),
/// viewed where they are. A block finds each of its sticks in its owner's
/// piece (a round's piece holds its owned sticks by increasing key).
struct PressState {
  struct Piece {
    uint64_t block = 0;
    std::span<const uint64_t> sticks;
    std::span<const double> t, velocity;  ///< velocity may be empty (at rest)
  };
  std::vector<Piece> pieces;
};
/// Views of the pieces (which must outlive the state).
PressState press_state(const std::vector<SurfacePiece>& pieces);

/// Block b in the halo mode: its sticks extracted from `samples` (its read
/// box) once, placed on their own box with the layout the sweeps run on,
/// so that every round and the last step reuse them (a Dask worker keeps
/// one between a block's rounds). Each call starts from a state and changes
/// nothing it holds: any round in any order gives what a fresh extraction
/// would.
class BlockRounds {
 public:
  BlockRounds(const BinaryVolume& samples, const ChunkGrid& grid, size_t b, const SurfaceOptions& options);
  ~BlockRounds();
  BlockRounds(BlockRounds&&) noexcept;
  /// The round's sweeps: the block's sticks (owned or in its halo) start
  /// from `state` (those it lacks, and every stick when it is empty: the
  /// extraction's t, at rest); the piece holds the owned sticks' t,
  /// momentum and residuals (no triangles).
  SurfacePiece round(const PressRound& round, const PressState& state) const;
  /// The last step: the sticks at `state`'s t (after the last round), the
  /// residual there (`residuals`, one value, when `measure`), then the
  /// quadric fit; the piece holds the owned sticks and triangles, for stitch.
  SurfacePiece finish(const PressState& state, bool measure) const;
  /// Memory held (what a Dask worker reports for it).
  uint64_t bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One piece of consecutive pieces (each piece's blocks follow the one
/// before): sticks and triangles merged in whole-run order (k-way), so a
/// tree of merges (voxpress.dask) leaves stitch sorted pieces. UsageError if
/// the blocks are not consecutive blocks of one grid.
SurfacePiece merge_pieces(const std::vector<SurfacePiece>& pieces, const std::array<int64_t, 3>& dims);

/// Joins the blocks' pieces into the whole volume's stick surface (any piece
/// order; deterministic). Throws UsageError unless the pieces are each block
/// of one grid exactly once, std::logic_error if a triangle names a stick no
/// piece owns (pieces pressed with different halos or volumes).
StickSurface stitch(const Lattice& lattice, const std::vector<SurfacePiece>& pieces);

struct ChunkedStats {
  size_t blocks = 0, pressed = 0;  ///< blocks, and those with sticks to press
  int levels = 0, max_iterations = 0;
  int rounds = 0;                  ///< the halo mode's exchange rounds
  uint64_t sticks = 0, triangles = 0, inside = 0;
  double seconds_summary = 0, seconds_blocks = 0, seconds_stitch = 0;
};

/// Reads the samples of a box of the volume as a BinaryVolume of that box's
/// size (its lattice's origin need not be set). Called from several threads.
using BlockReader = std::function<BinaryVolume(const Box&)>;

/// The chunked run: summary pass, blocks (in parallel, each read once with
/// its halo), stitch, and in the exact mode (halo 0) smooth_sticks on the
/// stitched sticks. `lattice` is the whole volume's; `source` names it in
/// errors. Refuses empty and full volumes like smooth_surface.
SurfaceResult press_chunked(const Lattice& lattice, const std::string& source, const BlockReader& read,
                            const SurfaceOptions& options, const ChunkOptions& chunks, ChunkedStats* stats = nullptr);

/// The samples of `box` of an in-memory volume.
BinaryVolume crop(const BinaryVolume& volume, const Box& box);

/// SurfaceOptions as the chunked run uses them: flats off, levels set from
/// the whole volume's extent (summary.bounds), progress off.
SurfaceOptions chunk_surface_options(const SurfaceOptions& options, const VolumeSummary& summary);

}  // namespace voxpress
