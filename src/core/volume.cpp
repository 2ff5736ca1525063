#include "voxpress/core/volume.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <unordered_map>

#include "voxpress/core/error.h"
#include "core/parallel.h"

namespace voxpress {

size_t scalar_size(ScalarType t) {
  switch (t) {
    case ScalarType::u8:
    case ScalarType::i8: return 1;
    case ScalarType::u16:
    case ScalarType::i16: return 2;
    case ScalarType::u32:
    case ScalarType::i32:
    case ScalarType::f32: return 4;
    default: return 8;
  }
}

const char* scalar_name(ScalarType t) {
  switch (t) {
    case ScalarType::u8: return "uint8";
    case ScalarType::i8: return "int8";
    case ScalarType::u16: return "uint16";
    case ScalarType::i16: return "int16";
    case ScalarType::u32: return "uint32";
    case ScalarType::i32: return "int32";
    case ScalarType::u64: return "uint64";
    case ScalarType::i64: return "int64";
    case ScalarType::f32: return "float32";
    default: return "float64";
  }
}

bool scalar_is_float(ScalarType t) { return t == ScalarType::f32 || t == ScalarType::f64; }

double ScalarVolume::value(uint64_t n) const {
  return visit([n](auto values) { return double(values[n]); });
}

uint64_t BinaryVolume::count_inside() const {
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, inside.size(), 1 << 16), uint64_t{0},
      [&](const tbb::blocked_range<size_t>& r, uint64_t acc) {
        for (size_t s = r.begin(); s < r.end(); ++s) acc += inside[s];
        return acc;
      },
      std::plus<>());
}

Selection parse_label_selection(const std::string& text) {
  Selection s;
  if (text == "all-nonzero" || text == "nonzero") {
    s.kind = Selection::Kind::nonzero;
    return s;
  }
  double v = 0;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v))
    throw UsageError("--label expects a number or 'all-nonzero', got '" + text + "'");
  s.kind = Selection::Kind::label;
  s.value = v;
  return s;
}

std::string format_value(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

namespace {

template <class Pred>
BinaryVolume select(const ScalarVolume& v, int64_t component, Pred pred) {
  BinaryVolume b;
  b.lattice = v.lattice;
  b.source = v.source;
  const uint64_t n = v.lattice.size();
  b.inside.resize(n);
  const int64_t stride = v.components;
  v.visit([&](auto values) {
    detail::parallel_ranges(n, 1 << 16, [&](detail::IndexRange r) {
      for (uint64_t s = r.begin(); s < r.end(); ++s)
        b.inside[s] = pred(double(values[s * uint64_t(stride) + uint64_t(component)])) ? 1 : 0;
    });
  });
  return b;
}

template <class Pred>
BinaryVolume select_any_component(const ScalarVolume& v, Pred pred) {
  BinaryVolume b = select(v, 0, pred);
  for (int64_t c = 1; c < v.components; ++c) {
    BinaryVolume other = select(v, c, pred);
    for (size_t s = 0; s < b.inside.size(); ++s) b.inside[s] |= other.inside[s];
  }
  return b;
}

}  // namespace

void ValueSummary::add(double x) {
  lo = std::min(lo, x);
  hi = std::max(hi, x);
  if (x != std::floor(x)) fractional = true;
  if (x == 0 || more) return;
  auto it = std::lower_bound(nonzero.begin(), nonzero.end(), x);
  if (it != nonzero.end() && *it == x) return;
  if (nonzero.size() == kMaxDistinct) {
    more = true;
    nonzero.clear();  // which values were seen first depends on the order of blocks: keep none
    return;
  }
  nonzero.insert(it, x);
}

void ValueSummary::merge(const ValueSummary& o) {
  lo = std::min(lo, o.lo);
  hi = std::max(hi, o.hi);
  fractional |= o.fractional;
  for (double x : o.nonzero) add(x);
  if (o.more) {
    more = true;
    nonzero.clear();
  }
}

ValueSummary summarize_values(const ScalarVolume& v) {
  return v.visit([&](auto values) {
    ValueSummary s;
    bool first = true;
    double last = 0;
    for (const auto value : values) {
      const double x = double(value);
      if (!first && (x == last)) continue;  // runs of one value: the common case of masks and label maps
      first = false;
      last = x;
      s.add(x);
    }
    return s;
  });
}

Selection resolve_selection(const ScalarVolume& v, const Selection& sel, const ValueSummary& values) {
  using K = Selection::Kind;
  if (sel.kind != K::automatic) return sel;
  // Automatic: a mask with a single non-zero value is unambiguous.
  if (v.segments.size() == 1) {
    Selection s;
    s.kind = K::segment;
    s.segment = v.segments[0].id.empty() ? v.segments[0].name : v.segments[0].id;
    return s;
  }
  if (v.segments.size() > 1) {
    std::string names;
    for (const Segment& s : v.segments) names += (names.empty() ? "" : ", ") + s.name;
    throw InputError(v.source, "segmentation with " + std::to_string(v.segments.size()) + " segments (" + names +
                                   "); choose one with --segment NAME or --label N");
  }
  if (values.fractional)
    throw InputError(v.source, std::string("grey-level volume (") + scalar_name(v.type) + ", values " +
                                   format_value(values.lo) + " .. " + format_value(values.hi) +
                                   "); choose an iso-level with --threshold T");
  if (values.more)
    throw InputError(v.source, "volume with many distinct values; choose --label N, --label all-nonzero or --threshold T");
  if (values.nonzero.size() > 1) {
    std::string labels;
    for (size_t i = 0; i < values.nonzero.size() && i < 8; ++i) labels += (i ? ", " : "") + format_value(values.nonzero[i]);
    if (values.nonzero.size() > 8) labels += ", ...";
    throw InputError(v.source, "label map with " + std::to_string(values.nonzero.size()) + " labels (" + labels +
                                   "); choose one with --label N or --label all-nonzero");
  }
  Selection s;
  s.kind = K::nonzero;
  return s;
}

BinaryVolume select_samples(const ScalarVolume& v, const Selection& sel) {
  using K = Selection::Kind;
  switch (sel.kind) {
    case K::label: {
      const double label = sel.value;
      if (!std::isfinite(label)) throw UsageError("the label must be a finite number, not " + format_value(label));
      return select_any_component(v, [label](double x) { return x == label; });
    }
    case K::nonzero: return select_any_component(v, [](double x) { return x != 0; });
    case K::threshold: {
      const double t = sel.value;
      if (!std::isfinite(t)) throw UsageError("the threshold must be a finite number, not " + format_value(t));
      return select_any_component(v, [t](double x) { return x >= t; });
    }
    case K::segment: {
      // An ID names one segment; a name two segments share is ambiguous (one
      // was picked silently, issue 73).
      const Segment* chosen = nullptr;
      for (const Segment& s : v.segments)
        if (s.id == sel.segment) chosen = &s;
      if (!chosen) {
        for (const Segment& s : v.segments)
          if (s.name == sel.segment) {
            if (chosen)
              throw InputError(v.source, "segment name '" + sel.segment + "' is shared by segments " + chosen->id +
                                             " and " + s.id + "; choose one by its ID with --segment ID");
            chosen = &s;
          }
      }
      for (const Segment& s : v.segments) {
        if (&s == chosen) {
          if (s.layer < 0 || s.layer >= v.components)
            throw InputError(v.source, "segment '" + sel.segment + "' names layer " + std::to_string(s.layer) +
                                           " but the file has " + std::to_string(v.components));
          const double label = s.label;
          return select(v, s.layer, [label](double x) { return x == label; });
        }
      }
      std::string names;
      for (const Segment& s : v.segments) names += (names.empty() ? "" : ", ") + s.name;
      throw InputError(v.source, "no segment named '" + sel.segment + "'" +
                                     (names.empty() ? " (the file has no segments)" : " (segments: " + names + ")"));
    }
    case K::automatic: break;
  }
  throw UsageError("select_samples: resolve an automatic selection first (resolve_selection)");
}

BinaryVolume binarize(const ScalarVolume& v, const Selection& sel) {
  const Selection s = sel.kind == Selection::Kind::automatic ? resolve_selection(v, sel, summarize_values(v)) : sel;
  BinaryVolume b = select_samples(v, s);
  if (s.kind == Selection::Kind::label && b.count_inside() == 0)
    throw InputError(v.source, "no sample has label " + format_value(s.value) + " (see `voxpress info`)");
  return b;
}

std::optional<std::vector<std::pair<double, uint64_t>>> value_histogram(const ScalarVolume& v, size_t max_distinct) {
  using Result = std::optional<std::vector<std::pair<double, uint64_t>>>;
  return v.visit([&](auto values) -> Result {
    using T = typename decltype(values)::value_type;
    std::vector<std::pair<double, uint64_t>> out;
    if constexpr (sizeof(T) <= 2 && std::is_integral_v<T>) {
      // Dense counting for 8- and 16-bit types.
      constexpr int64_t lo = std::numeric_limits<T>::min();
      constexpr size_t range = size_t(1) << (8 * sizeof(T));
      std::vector<uint64_t> counts(range, 0);
      for (T x : values) ++counts[size_t(int64_t(x) - lo)];
      for (size_t i = 0; i < range; ++i)
        if (counts[i]) out.emplace_back(double(int64_t(i) + lo), counts[i]);
      if (out.size() > max_distinct) return std::nullopt;
    } else {
      std::unordered_map<T, uint64_t> counts;
      for (T x : values) {
        auto [it, fresh] = counts.try_emplace(x, 0);
        ++it->second;
        if (fresh && counts.size() > max_distinct) return std::nullopt;
      }
      for (auto& [x, n] : counts) out.emplace_back(double(x), n);
      std::sort(out.begin(), out.end());
    }
    return out;
  });
}

ScalarVolume to_scalar(const BinaryVolume& b) {
  ScalarVolume v;
  v.lattice = b.lattice;
  v.type = ScalarType::u8;
  v.bytes.resize(b.inside.size());
  std::memcpy(v.bytes.data(), b.inside.data(), b.inside.size());
  v.source = b.source;
  return v;
}

}  // namespace voxpress
