// voxpress/labels/shared_flats.h — flats of a label map's shared surface
// (issue 54, item 4: CAD assemblies, parts cut by the field of view).
//
// Each label's own surface (its mask on its box, label_mask) goes through the
// binary detection (press_with_flats: estimate, plane voting, junctions;
// Chica et al., Section 3). A label's sticks are exactly the shared
// surface's stick vertices of that label's interfaces, so each flat maps
// stick for stick onto the shared surface: a vertex found on a flat is frozen
// where the plane crosses its stick (t in [margin, 1 - margin]: inside its
// element, as press_shared requires), and a frozen vertex at a sharp border
// cuts the slice curves there. An interface between two labels is seen by
// both; where both freeze a vertex the label of lower value decides its t
// (the two planes are the same face seen from either side, within their fit).
// Sharpening: shared_sharpen.h.
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/progress.h"
#include "voxpress/core/volume.h"
#include "voxpress/features/flats.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_surface.h"

namespace voxpress {

struct SharedFlats {
  std::vector<double> t;           ///< per shared vertex: t on its flat's plane, NaN when not frozen
  std::vector<uint8_t> barrier;    ///< per shared vertex: a frozen vertex where slice curves are cut
  std::vector<int32_t> region;     ///< per shared vertex: index in `flats`, or -1
  std::vector<Flat> flats;         ///< every label's flats, by label then the label's own order
  std::vector<uint32_t> flat_label;  ///< per flat: the value of the label it was found on
  /// Per label (in the order given): its own binary segmentation, on the
  /// sticks of its mask's surface (extract_sticks of masks(label)); empty
  /// for a label without flats. The sharpening starts from it (shared_sharpen.h).
  std::vector<FlatSegmentation> segmentations;
  size_t frozen = 0;               ///< vertices frozen
  double seconds = 0;
  /// Flats found on the label of this value.
  size_t flats_of(double value) const;
};

/// The flats of every label of `labels` (label_table(volume).labels: their
/// boxes) mapped onto the shared vertices of `surface`, each label's mask
/// from `masks` (masks_in(volume), or masks_read of a file). Labels in
/// parallel; deterministic for any thread count.
SharedFlats find_shared_flats(const LabelMasks& masks, const SharedSurface& surface,
                              const std::vector<LabelInfo>& labels, const PressOptions& press,
                              const FlatOptions& flats, Progress* progress = nullptr);

}  // namespace voxpress
