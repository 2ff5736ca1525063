// voxpress/labels/shared_fit.h — the local quadric fit on a label map's
// shared surface (issue 54; the binary pipeline's fit_local_quadrics,
// pressing.h, between the pressing and the sharpening, as smooth_surface
// runs it).
//
// Each cube of two labels belongs to the higher-valued one (the background
// never; the label cases put the higher label inside a two-label face, so
// the shared triangles there are its binary case, checked all the same),
// the label's own stick surface (extract_sticks of its mask, every t read
// from the pressed shared surface) goes through fit_local_quadrics with the
// label's flats and junctions (find_shared_flats keeps them), and the stick
// vertices whose every shared triangle lies in its cubes take their new t.
// Vertices near junction lines stay where the shared press put them. The
// fit slides vertices along their sticks (t in [margin, 1 - margin]), so
// every triangle stays in its cube and no sample changes side; each cube
// with a moved vertex is checked exactly as press_shared checks it, and the
// moved vertices of a cube that fails go back, its neighbours rechecked.
// Deterministic: labels fitted in parallel, each vertex by one label.
#pragma once

#include <cstddef>
#include <vector>

#include "voxpress/features/passes.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_flats.h"
#include "voxpress/labels/shared_surface.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress {

struct SharedFitStats {
  size_t labels = 0;          ///< labels with cubes of their own
  size_t cubes = 0;           ///< cubes given to their owner's fit
  size_t fitted = 0;          ///< vertices whose fit was trusted
  size_t moved = 0;           ///< stick vertices that took their fitted t
  size_t cubes_put_back = 0;  ///< cubes whose moved vertices went back (exact check)
  double seconds = 0;
  PassTimes passes;           ///< Stage::fit's passes, summed over the labels (label order)
};

/// Fits `surface` (pressed by press_shared) in place; `labels` (with their
/// boxes) and `masks` as for find_shared_flats, whose result `flats` (or
/// null) excludes each label's flat and junction vertices from the fit.
/// Each label runs the feature layer's Stage::fit (its `quadric-fit` pass)
/// with `passes`, as smooth_surface does on a binary volume.
SharedFitStats fit_shared_quadrics(SharedSurface& surface, const LabelMasks& masks, const std::vector<LabelInfo>& labels,
                                   const SharedFlats* flats, const QuadricFitOptions& options = {},
                                   const PassSet& passes = {});

}  // namespace voxpress
