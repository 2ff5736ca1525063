// voxpress/core/volume.h — scalar (label / grey) and binary volumes over a Lattice.
//
// Readers return a ScalarVolume: the file's voxel type kept as-is (no
// widening, so a 512^3 uint8 label map stays 128 MiB), x fastest, native
// byte order. binarize() turns it into the BinaryVolume every method works on.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "voxpress/core/lattice.h"

namespace voxpress {

enum class ScalarType : uint8_t { u8, i8, u16, i16, u32, i32, u64, i64, f32, f64 };

/// Bytes per value of a ScalarType.
size_t scalar_size(ScalarType t);
/// Short name ("uint8", "int16", "float32", ...).
const char* scalar_name(ScalarType t);
/// True for f32 and f64.
bool scalar_is_float(ScalarType t);

/// A named segment of a 3D Slicer .seg.nrrd (Segment<N>_* keys).
struct Segment {
  std::string id;      ///< SegmentN_ID
  std::string name;    ///< SegmentN_Name
  double label = 1;    ///< SegmentN_LabelValue: the voxel value of this segment
  int64_t layer = 0;   ///< SegmentN_Layer: which layer (component) holds it
};

/// A volume as stored in a file: one scalar type, `components` values per
/// sample (1, or the number of layers of a 4-D .seg.nrrd; components vary
/// fastest), samples x fastest.
struct ScalarVolume {
  Lattice lattice;
  ScalarType type = ScalarType::u8;
  int64_t components = 1;
  std::vector<std::byte> bytes;  ///< size = lattice.size() * components * scalar_size(type)
  std::vector<Segment> segments; ///< from .seg.nrrd metadata; empty otherwise
  std::map<std::string, std::string> metadata;  ///< free key/value pairs kept from the header
  std::string source;            ///< file path, used in error messages

  uint64_t value_count() const { return lattice.size() * uint64_t(components); }
  /// Value number n (sample * components + component) converted to double.
  double value(uint64_t n) const;
  /// Calls f(std::span<const T>) with the typed values.
  template <class F>
  decltype(auto) visit(F&& f) const;
};

/// A binary volume: inside[s] is 1 for inside samples, 0 for outside, x fastest.
/// Samples beyond the lattice are outside by definition (the surface closes
/// around volumes that touch the border).
struct BinaryVolume {
  Lattice lattice;
  std::vector<uint8_t> inside;
  std::string source;

  bool at(int64_t i, int64_t j, int64_t k) const {
    if (i < 0 || j < 0 || k < 0 || i >= lattice.dims[0] || j >= lattice.dims[1] || k >= lattice.dims[2])
      return false;
    return inside[lattice.linear(i, j, k)] != 0;
  }
  uint64_t count_inside() const;
};

/// Which samples of a ScalarVolume are inside.
struct Selection {
  enum class Kind {
    automatic,  ///< binary masks (one non-zero value): that value; anything else is an error asking for a choice
    label,      ///< value == label (all layers of a .seg.nrrd)
    nonzero,    ///< value != 0 (--label all-nonzero)
    threshold,  ///< value >= threshold (grey volumes)
    segment,    ///< a .seg.nrrd segment by name or ID: its layer's value == its label
  };
  Kind kind = Kind::automatic;
  double value = 0;      ///< label value or threshold
  std::string segment;   ///< segment name or ID for Kind::segment
};

/// A sample value as messages and file names print it (default stream
/// precision: 5, 2.5, 1e+20).
std::string format_value(double v);

/// Parses the CLI forms "N", "all-nonzero" (label) and "T" (threshold).
Selection parse_label_selection(const std::string& text);

/// What automatic selection needs of a volume's values: their range, whether
/// one is fractional, and its distinct non-zero values (up to kMaxDistinct;
/// past that `more`, and none kept). Blocks of a volume summarise apart and
/// merge into the whole volume's summary.
struct ValueSummary {
  static constexpr size_t kMaxDistinct = 64;  // past this a volume is "many distinct values", not a label map
  double lo = INFINITY, hi = -INFINITY;
  bool fractional = false, more = false;
  std::vector<double> nonzero;  ///< increasing
  void add(double x);
  void merge(const ValueSummary& other);
};
ValueSummary summarize_values(const ScalarVolume& volume);

/// The concrete selection an automatic one stands for on a volume with these
/// values (its one segment, or its one non-zero value); a non-automatic
/// selection unchanged. Throws InputError (naming volume.source) when the
/// choice is ambiguous: a grey volume, a label map, several segments.
Selection resolve_selection(const ScalarVolume& volume, const Selection& selection, const ValueSummary& values);

/// The samples a resolved selection picks (none is not an error: blocks of a
/// volume may hold none). Throws UsageError for an automatic selection.
BinaryVolume select_samples(const ScalarVolume& volume, const Selection& selection);

/// Turns a scalar volume into a binary one. Throws InputError (naming
/// volume.source) when the selection does not apply: no such label, an
/// automatic selection on a multi-label or grey volume, an unknown segment.
BinaryVolume binarize(const ScalarVolume& volume, const Selection& selection = {});

/// Distinct values and their sample counts (all components), sorted by value.
/// Returns nullopt when there are more than max_distinct values (a grey image).
std::optional<std::vector<std::pair<double, uint64_t>>> value_histogram(const ScalarVolume& volume,
                                                                      size_t max_distinct = 4096);

/// Builds a ScalarVolume of type uint8 from a binary one (for writing).
ScalarVolume to_scalar(const BinaryVolume& volume);

// ---------------------------------------------------------------------------
template <class F>
decltype(auto) ScalarVolume::visit(F&& f) const {
  const auto n = value_count();
  auto span_of = [&](auto tag) {
    using T = decltype(tag);
    return std::span<const T>(reinterpret_cast<const T*>(bytes.data()), n);
  };
  switch (type) {
    case ScalarType::u8: return f(span_of(uint8_t{}));
    case ScalarType::i8: return f(span_of(int8_t{}));
    case ScalarType::u16: return f(span_of(uint16_t{}));
    case ScalarType::i16: return f(span_of(int16_t{}));
    case ScalarType::u32: return f(span_of(uint32_t{}));
    case ScalarType::i32: return f(span_of(int32_t{}));
    case ScalarType::u64: return f(span_of(uint64_t{}));
    case ScalarType::i64: return f(span_of(int64_t{}));
    case ScalarType::f32: return f(span_of(float{}));
    default: return f(span_of(double{}));
  }
}

}  // namespace voxpress
