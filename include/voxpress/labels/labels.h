// voxpress/labels/labels.h — label maps: every label of a volume in one call.
//
// A label map holds one integer value per sample (0 = background); a 3D
// Slicer .seg.nrrd holds named segments, possibly in several overlapping
// layers. label_table() finds every label in one pass over the samples: its
// sample count, its bounding box and which labels it touches (lattice edges
// between two labels, counted like sticks). press_labels() then meshes each
// label alone on its bounding box grown by one sample (label_mask): the
// samples beyond that box are not the label, so the surface is the one the
// whole volume would give (the same sticks in the same order, only the index
// origin moves), at the cost of the label's box instead of the volume.
//
// press_labels meshes the labels independently: where two labels touch each
// places its own vertex on the shared stick and the two walls are smoothed
// separately; each surface keeps the binary guarantee for its own label, and
// the surfaces of two labels may cross each other near their common wall.
// One surface shared by all labels is extract_shared_surface + press_shared
// (shared_surface.h, shared_press.h), what `press --labels` writes by default.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "voxpress/core/volume.h"
#include "voxpress/smooth/pipeline.h"

namespace voxpress {

/// One label of a label map or one segment of a .seg.nrrd.
struct LabelInfo {
  double value = 0;          ///< the samples' value
  int64_t layer = 0;         ///< the component (layer) holding it; 0 for plain label maps
  std::string name;          ///< segment name, a --label-names entry, or empty
  uint64_t samples = 0;      ///< samples with this value in its layer
  std::array<int64_t, 3> lo{}, hi{};  ///< bounding box of those samples, inclusive
};

/// Two labels that touch: `sticks` lattice edges join a sample of each.
/// a < b; either may be 0, the background.
struct LabelContact {
  double a = 0, b = 0;
  uint64_t sticks = 0;
};

struct LabelTable {
  std::vector<LabelInfo> labels;       ///< non-zero values (or segments), by layer then value
  std::vector<LabelContact> contacts;  ///< single-layer volumes only; by (a, b)
  bool layered = false;                ///< a 4-D .seg.nrrd: layers may overlap, each label is meshed on its own layer
};

/// Every label of `volume`: the distinct non-zero values (integers; a value
/// with a fraction is an InputError: a grey image, use --threshold), or the
/// segments of a .seg.nrrd with their names. Throws InputError (naming
/// volume.source) when there is no label or more than max_labels.
LabelTable label_table(const ScalarVolume& volume, size_t max_labels = 65535);

/// Block by block (press --labels --chunk): what the box `read` of a volume
/// whose dims are `dims` contributes to its table (`samples` holds that box,
/// which holds `core` and one sample below it where there is one): counts
/// and boxes of the core's samples, contacts of the lattice edges whose
/// upper sample is in the core.
LabelTable label_table_part(const ScalarVolume& samples, const Box& read, const Box& core,
                            const std::array<int64_t, 3>& dims, size_t max_labels = 65535);

/// The table of parts that tile the volume (any order), named from the
/// header's segments: label_table(v) is this of one part holding every
/// sample. Throws InputError (naming header.source) as label_table does.
LabelTable merge_label_tables(const std::vector<LabelTable>& parts, const ScalarVolume& header,
                              size_t max_labels = 65535);

/// The values of the CLI form "1,5,7"; "all" gives none (every label).
/// Throws UsageError for anything else.
std::vector<double> parse_label_list(const std::string& text);

/// The labels with these values, in the order given, each once (every
/// label when `values` is empty). An absent value is an InputError naming
/// `source` and the labels it has.
std::vector<LabelInfo> select_labels(const LabelTable& table, const std::vector<double>& values,
                                     const std::string& source);

/// Reads a label-name table (one "VALUE NAME" per line, separated by blanks,
/// a comma or a tab; '#' starts a comment) — the form TotalSegmentator and
/// ITK-SNAP label descriptions reduce to. Throws InputError naming the file
/// and the line; the file must be a regular file (not a folder, device or
/// pipe) of at most kMaxLabelNamesBytes.
std::map<double, std::string> read_label_names(const std::string& path);
inline constexpr uint64_t kMaxLabelNamesBytes = uint64_t(16) << 20;

/// The label's samples as a binary volume on its bounding box grown by one
/// sample on each side (clipped to the lattice), with the lattice's origin
/// moved to the box's corner: physical positions are unchanged.
BinaryVolume label_mask(const ScalarVolume& volume, const LabelInfo& label);

/// Where each label's mask comes from (flats of the shared surface, --check).
using LabelMasks = std::function<BinaryVolume(const LabelInfo&)>;
/// label_mask of a volume in memory (which must outlive the result).
LabelMasks masks_in(const ScalarVolume& volume);
/// The same masks read from a file box by box: `read` returns the samples
/// of a box of `lattice` (VolumeFile::read), asked for slabs of planes, so
/// a mask costs its box's samples in bytes, not the volume's values.
using BoxRead = std::function<ScalarVolume(const Box&)>;
LabelMasks masks_read(const Lattice& lattice, const std::string& source, BoxRead read);

struct LabelSurface {
  LabelInfo label;
  SurfaceResult result;  ///< result.mesh in the volume's physical frame
};

/// Each label's smooth surface by `options` (the same as smooth_surface on
/// that label's mask alone), labels in parallel, results in the order given.
/// Deterministic for any thread count. Throws what smooth_surface throws,
/// prefixed with the label.
std::vector<LabelSurface> press_labels(const ScalarVolume& volume, const std::vector<LabelInfo>& labels,
                                       const SurfaceOptions& options = {});

}  // namespace voxpress
