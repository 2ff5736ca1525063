// voxpress/chunk/chunked_labels.h — a label map block by block
// (`press --labels --chunk`; issue 56, item 4).
//
// One pass over the blocks of chunked.h's grid (each read once, with one
// sample around it): each block gives its part of the label table (counts,
// boxes and contacts of the samples it owns) and its piece of the shared
// surface (the triangles of the cubes it owns, vertices named by global
// keys). The parts merge into the whole volume's table and the pieces
// assemble into the whole volume's midpoint shared surface: the same bytes
// as label_table and extract_shared_surface of the volume in memory, so
// pressing it (press_shared_labels) gives the in-memory result byte for
// byte. Each label's flats then read that label's box from the file
// (masks_read), one label per thread at a time. Memory: one block's samples
// per thread, the surface, and while flats run the boxes of the labels in
// hand (--no-flats drops those).
#pragma once

#include "voxpress/chunk/chunked.h"
#include "voxpress/core/progress.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_surface.h"

namespace voxpress {

struct ChunkedLabels {
  LabelTable table;       ///< label_table of the whole volume
  SharedSurface surface;  ///< extract_shared_surface of the whole volume
  size_t blocks = 0;
  double seconds_blocks = 0, seconds_assemble = 0;
};

/// The table and midpoint shared surface of the label map `header`
/// describes (one component), its samples read box by box by `read`.
/// chunks.halo must be 0 (the shared surface is pressed whole). Errors are
/// those of the in-memory calls, the lowest block's first.
ChunkedLabels extract_labels_chunked(const ScalarVolume& header, const BoxRead& read, const ChunkOptions& chunks,
                                     Progress* progress = nullptr);

}  // namespace voxpress
