// voxpress/labels/shared_sharpen.h — sharp edges on a label map's shared
// surface (issue 54, item 4: CAD assemblies; Chica et al., Section 5).
//
// A cube whose eight samples hold two labels L and X is, for L, a cube of
// L's own mask: where the shared label case there is L's binary case (the
// same triangles, compared stick by stick), L's binary sharpening may edit
// it. Each such cube is sharpened by one label, its owner: of L and X, the
// higher-valued label that has flats (the background never; the label cases
// put the higher label inside a two-label face, so its binary case is the
// shared one by construction, ambiguous faces included). For each label
// with flats, its own surface (extract_sticks of its mask, every t read
// from the pressed shared surface) goes through sharpen() with its binary
// segmentation (find_shared_flats keeps it), restricted to its cubes:
//  - a chamfer edge gets its vertex only between two editable triangles,
//    so no triangle of another cube is split (no T-junction); a crease
//    reaching a cube of three labels, or another owner's, stops there;
//  - a stick vertex moves only when every shared triangle around it is in
//    the label's cubes (all that the move changes, the sharpener sees);
//  - every move is the sharpener's checked move: no lattice sample is
//    swept (of any label: the samples are integer points), no triangle of
//    the label turns over or meets another.
// The refined triangles replace the cube's shared triangles, used by both
// labels (X's surface gets L's creases reversed). Then every changed
// triangle is checked exactly against every shared triangle near it (other
// labels' interfaces, junction cubes the sharpener saw as L's binary
// case), with the float32 clearance. The changes around a triangle that
// fails are taken back (a new vertex onto the edge it was inserted on, a
// moved stick vertex to its place) and the check runs again, until none
// fails; a label with nothing left to take back is undone whole. So the
// surface keeps every guarantee of press_shared. Deterministic: labels
// sharpened in parallel, applied in label order.
#pragma once

#include <cstddef>
#include <vector>

#include "voxpress/features/sharpen.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_flats.h"
#include "voxpress/labels/shared_surface.h"

namespace voxpress {

struct SharedSharpenStats {
  size_t labels = 0;          ///< labels sharpened (with flats and cubes of their own)
  size_t cubes = 0;           ///< cubes of two labels given to their owner's sharpening
  size_t inserted = 0;        ///< new crease vertices (edges and corners)
  size_t corners = 0;         ///< ... of which corners
  size_t moved = 0;           ///< stick vertices slid by the sharpening (onto flats, creases)
  size_t sharp_edges = 0;     ///< crease edges between sides meeting at sharp_angle or more
  size_t taken_back = 0;      ///< changes taken back where they met another surface (vertices)
  size_t labels_undone = 0;   ///< labels whose sharpening was undone whole (nothing left to take back)
  double seconds = 0;
  PassTimes passes;           ///< Stage::sharpen's passes, summed over the labels (label order)
};

/// Sharpens `surface` (pressed by press_shared with `flats`, found by
/// find_shared_flats over `labels` with `masks`) in place: new vertices
/// (kind 7, corner: the lowest corner of their cube), triangles and sides.
/// Labels without flats are left as they are.
SharedSharpenStats sharpen_shared(SharedSurface& surface, const SharedFlats& flats, const LabelMasks& masks,
                                  const std::vector<LabelInfo>& labels, const SharpenOptions& options = {});

}  // namespace voxpress
