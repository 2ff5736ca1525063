// Label maps: the label table (one pass), label masks on their boxes, and
// every label pressed in one call. Theory of operation:
// include/voxpress/labels/labels.h.
#include "voxpress/labels/labels.h"


#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <span>
#include <sstream>
#include <type_traits>
#include <unordered_map>

#include "../io/io_util.h"
#include "voxpress/core/error.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

// Maps a layer's values to dense label numbers (0 = background), with a
// table for 8- and 16-bit types and a hash map with a one-entry cache (label
// maps come in runs) otherwise.
template <class T>
class LabelIndex {
 public:
  LabelIndex(const ScalarVolume& v, size_t max_labels) : source_(v.source), max_(max_labels) {
    if constexpr (std::is_integral_v<T> && sizeof(T) <= 2) table_.assign(size_t(1) << (8 * sizeof(T)), UINT32_MAX);
  }
  uint32_t operator()(T x) {
    if (x == T(0)) return 0;
    if constexpr (std::is_integral_v<T> && sizeof(T) <= 2) {
      uint32_t& id = table_[size_t(std::make_unsigned_t<T>(x))];
      if (id == UINT32_MAX) id = add(double(x));
      return id;
    } else {
      if (has_last_ && x == last_) return last_id_;
      auto it = map_.find(x);
      uint32_t id;
      if (it != map_.end()) {
        id = it->second;
      } else {
        const double d = double(x);
        if (!std::isfinite(d) || d != std::floor(d))
          throw InputError(source_, "value " + format_value(d) +
                                        " is not an integer label: this looks like a grey image (use --threshold T)");
        id = add(d);
        map_.emplace(x, id);
      }
      has_last_ = true;
      last_ = x;
      last_id_ = id;
      return id;
    }
  }
  std::vector<double> values{0.0};  ///< dense number -> value (0 = background)

 private:
  uint32_t add(double d) {
    if (values.size() > max_)
      throw InputError(source_, "more than " + std::to_string(max_) + " distinct labels");
    values.push_back(d);
    return uint32_t(values.size() - 1);
  }
  std::string source_;
  size_t max_;
  std::vector<uint32_t> table_;
  std::unordered_map<T, uint32_t> map_;
  bool has_last_ = false;
  T last_{};
  uint32_t last_id_ = 0;
};

struct LayerScan {
  std::vector<LabelInfo> labels;        // by dense number - 1
  std::vector<LabelContact> contacts;
};

// One pass over one layer of the box `read` of a volume whose dims are `n`:
// counts and boxes of the samples in `core`, and (when wanted) the contacts
// between labels along the lattice edges whose upper sample is in `core`
// (each edge of the volume once over blocks that tile it), from the current
// and previous slices of dense numbers (two slices of memory, not a volume).
template <class T>
LayerScan scan_layer(const ScalarVolume& v, std::span<const T> values, int64_t layer, size_t max_labels,
                     bool contacts, const Box& read, const Box& core, const std::array<int64_t, 3>& n) {
  const auto& d = v.lattice.dims;
  const int64_t nx = d[0], ny = d[1], nz = d[2], nc = v.components;
  LabelIndex<T> index(v, max_labels);
  std::vector<LabelInfo> info;  // by dense number - 1; samples == 0: not in the core
  std::vector<uint32_t> cur(size_t(nx * ny)), prev(size_t(nx * ny));
  std::unordered_map<uint64_t, uint64_t> pairs;
  auto touch = [&](uint32_t a, uint32_t b) {
    if (a == b) return;
    if (a > b) std::swap(a, b);
    ++pairs[(uint64_t(a) << 32) | b];
  };
  auto owned = [&](int64_t x, int a) { return x >= core.lo[size_t(a)] && x < core.hi[size_t(a)]; };
  for (int64_t k = 0; k < nz; ++k) {
    const int64_t gk = read.lo[2] + k;
    for (int64_t j = 0; j < ny; ++j) {
      const int64_t gj = read.lo[1] + j;
      const bool row_owned = owned(gk, 2) && owned(gj, 1);
      for (int64_t i = 0; i < nx; ++i) {
        const uint64_t s = v.lattice.linear(i, j, k);
        const uint32_t id = index(values[size_t(s * uint64_t(nc) + uint64_t(layer))]);
        cur[size_t(i + nx * j)] = id;
        const int64_t gi = read.lo[0] + i;
        if (!row_owned || !owned(gi, 0)) continue;
        if (id != 0) {
          if (id > info.size()) info.resize(id);
          LabelInfo& l = info[id - 1];
          const int64_t p[3] = {gi, gj, gk};
          if (l.samples == 0) {
            l.value = index.values[id];
            l.layer = layer;
            l.lo = {gi, gj, gk};
            l.hi = {gi, gj, gk};
          }
          ++l.samples;
          for (int a = 0; a < 3; ++a) {
            l.lo[size_t(a)] = std::min(l.lo[size_t(a)], p[a]);
            l.hi[size_t(a)] = std::max(l.hi[size_t(a)], p[a]);
          }
        }
        if (!contacts) continue;
        // Edges to the lower neighbours (in the read box: it holds one
        // sample below the core); the lattice's border faces the background.
        if (gi > 0) touch(cur[size_t(i - 1 + nx * j)], id);
        if (gj > 0) touch(cur[size_t(i + nx * (j - 1))], id);
        if (gk > 0) touch(prev[size_t(i + nx * j)], id);
        if (id != 0) {
          const int border = (gi == 0) + (gi == n[0] - 1) + (gj == 0) + (gj == n[1] - 1) + (gk == 0) + (gk == n[2] - 1);
          if (border) pairs[uint64_t(id)] += uint64_t(border);
        }
      }
    }
    std::swap(cur, prev);
  }
  LayerScan out;
  for (LabelInfo& l : info)
    if (l.samples) out.labels.push_back(std::move(l));
  for (const auto& [key, count] : pairs) {
    const double a = index.values[key >> 32], b = index.values[key & 0xffffffffu];
    out.contacts.push_back({std::min(a, b), std::max(a, b), count});
  }
  return out;
}

}  // namespace

LabelTable label_table_part(const ScalarVolume& v, const Box& read, const Box& core, const std::array<int64_t, 3>& n,
                            size_t max_labels) {
  if (v.lattice.dims != read.dims()) throw std::logic_error("label_table_part: the samples are not the read box");
  for (size_t a = 0; a < 3; ++a)
    if (core.lo[a] < read.lo[a] || core.hi[a] > read.hi[a] || (core.lo[a] > 0 && read.lo[a] >= core.lo[a]))
      throw std::logic_error("label_table_part: the read box must hold the core and one sample below it");
  LabelTable t;
  t.layered = v.components > 1;
  for (int64_t layer = 0; layer < v.components; ++layer) {
    LayerScan scan = v.visit([&](auto values) {
      using T = typename decltype(values)::value_type;
      return scan_layer<T>(v, values, layer, max_labels, v.components == 1, read, core, n);
    });
    for (LabelInfo& l : scan.labels) t.labels.push_back(std::move(l));
    if (v.components == 1) t.contacts = std::move(scan.contacts);
  }
  return t;
}

LabelTable merge_label_tables(const std::vector<LabelTable>& parts, const ScalarVolume& header, size_t max_labels) {
  // Labels by (layer, value) and contacts by (a, b): sums, minima, maxima;
  // the result does not depend on the parts' order.
  std::map<std::pair<int64_t, double>, LabelInfo> labels;
  std::map<std::pair<double, double>, uint64_t> contacts;
  LabelTable t;
  t.layered = header.components > 1;
  for (const LabelTable& part : parts) {
    for (const LabelInfo& l : part.labels) {
      auto [it, fresh] = labels.try_emplace({l.layer, l.value}, l);
      if (fresh) continue;
      LabelInfo& m = it->second;
      m.samples += l.samples;
      for (size_t a = 0; a < 3; ++a) {
        m.lo[a] = std::min(m.lo[a], l.lo[a]);
        m.hi[a] = std::max(m.hi[a], l.hi[a]);
      }
    }
    for (const LabelContact& c : part.contacts) contacts[{c.a, c.b}] += c.sticks;
  }
  if (labels.size() > max_labels)
    throw InputError(header.source, "more than " + std::to_string(max_labels) + " distinct labels");
  for (auto& [key, l] : labels) t.labels.push_back(std::move(l));  // by layer, then value
  for (const auto& [key, count] : contacts) t.contacts.push_back({key.first, key.second, count});
  // .seg.nrrd: the segments are the labels (a value no segment names is dropped).
  if (!header.segments.empty()) {
    std::vector<LabelInfo> named;
    for (const Segment& s : header.segments) {
      for (const LabelInfo& l : t.labels)
        if (l.layer == s.layer && l.value == s.label) {
          named.push_back(l);
          named.back().name = s.name.empty() ? s.id : s.name;
        }
    }
    t.labels = std::move(named);
  }
  if (t.labels.empty()) throw InputError(header.source, "no labelled sample (every value is 0)");
  return t;
}

LabelTable label_table(const ScalarVolume& v, size_t max_labels) {
  const Box all{{0, 0, 0}, v.lattice.dims};
  return merge_label_tables({label_table_part(v, all, all, v.lattice.dims, max_labels)}, v, max_labels);
}

std::vector<double> parse_label_list(const std::string& text) {
  if (text == "all") return {};
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(value))
      throw UsageError("--labels takes 'all' or values like 1,5,7, not '" + text + "'");
    values.push_back(value);
  }
  if (values.empty()) throw UsageError("--labels selects no label");
  return values;
}

std::vector<LabelInfo> select_labels(const LabelTable& table, const std::vector<double>& values,
                                     const std::string& source) {
  if (values.empty()) return table.labels;
  std::vector<LabelInfo> out;
  for (const double value : values) {
    bool found = false;
    for (const LabelInfo& l : table.labels)
      if (l.value == value) {
        found = true;
        const bool twice = std::any_of(out.begin(), out.end(), [&](const LabelInfo& o) {
          return o.value == l.value && o.layer == l.layer;
        });
        if (!twice) out.push_back(l);  // "5,5" is label 5 once
      }
    if (!found) {
      std::string have;
      for (size_t i = 0; i < table.labels.size() && i < 20; ++i)
        have += (i ? ", " : "") + format_value(table.labels[i].value);
      if (table.labels.size() > 20) have += ", ...";
      // 0 is never a label (issue 73: "no sample has label 0" on a map full of zeros).
      throw InputError(source, (value == 0 ? std::string("0 is the background, not a label")
                                           : "no sample has label " + format_value(value)) +
                                   " (labels: " + have + ")");
    }
  }
  return out;
}

std::map<double, std::string> read_label_names(const std::string& path) {
  // A regular file of bounded size: a device (/dev/zero), a pipe or a folder
  // would otherwise be read without end or silently give no names (issue 73).
  const uint64_t size = detail::file_size(path);
  if (size > kMaxLabelNamesBytes)
    throw InputError(path, "the label-name table has " + std::to_string(size) + " bytes, more than the " +
                               std::to_string(kMaxLabelNamesBytes >> 20) + " MiB a table of names can need");
  const std::vector<std::byte> bytes = detail::read_range(path, 0, size);
  std::istringstream in(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  std::map<double, std::string> names;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    for (char& ch : line)
      if (ch == ',' || ch == '\t' || ch == '\r') ch = ' ';
    std::istringstream fields(line);
    std::string value_text, name;
    if (!(fields >> value_text)) continue;
    std::getline(fields >> std::ws, name);
    while (!name.empty() && name.back() == ' ') name.pop_back();
    char* end = nullptr;
    const double value = std::strtod(value_text.c_str(), &end);
    if (end != value_text.c_str() + value_text.size() || !std::isfinite(value) || name.empty())
      throw InputError(path, "line " + std::to_string(n) + ": expected 'VALUE NAME', got '" + line + "'");
    names[value] = name;
  }
  return names;
}

namespace {

// The label's box grown by one sample (inclusive), not clipped to the
// lattice: beyond it the mask is background, as everywhere outside a
// volume. So a label's mask, and every stage run on it, is the same for a
// cropped, shifted or padded map (issue 74, item 2).
std::pair<std::array<int64_t, 3>, std::array<int64_t, 3>> mask_box(const LabelInfo& label) {
  std::array<int64_t, 3> lo{}, hi{};
  for (size_t a = 0; a < 3; ++a) {
    lo[a] = label.lo[a] - 1;
    hi[a] = label.hi[a] + 1;
  }
  return {lo, hi};
}

// The part of [lo, hi] (inclusive) inside the lattice, as a half-open Box.
Box within(const Lattice& lattice, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
  Box b;
  for (size_t a = 0; a < 3; ++a) {
    b.lo[a] = std::max<int64_t>(0, lo[a]);
    b.hi[a] = std::min<int64_t>(lattice.dims[a], hi[a] + 1);
  }
  return b;
}

// An empty mask of the box [lo, hi] (mask_box), its lattice's origin at the box's corner.
BinaryVolume empty_mask(const Lattice& lattice, const std::string& source, const std::array<int64_t, 3>& lo,
                        const std::array<int64_t, 3>& hi) {
  BinaryVolume b;
  b.source = source;
  b.lattice = lattice;
  b.lattice.dims = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
  b.lattice.origin = lattice.to_physical(Vec3(double(lo[0]), double(lo[1]), double(lo[2])));
  b.inside.assign(b.lattice.size(), 0);
  return b;
}

// The samples of `box` of v that hold the label, into mask m at its sample
// `at` (box's first sample there).
void mask_into(const ScalarVolume& v, const Box& box, const LabelInfo& label, BinaryVolume& m,
               const std::array<int64_t, 3>& at) {
  const uint64_t nc = uint64_t(v.components), layer = uint64_t(label.layer);
  const auto d = box.dims();
  v.visit([&](auto values) {
    using T = typename decltype(values)::value_type;
    const T want = T(label.value);
    detail::parallel_for(int64_t(0), d[2], [&](int64_t k) {
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i) {
          const uint64_t s = v.lattice.linear(box.lo[0] + i, box.lo[1] + j, box.lo[2] + k);
          m.inside[m.lattice.linear(at[0] + i, at[1] + j, at[2] + k)] = values[size_t(s * nc + layer)] == want;
        }
    });
  });
}

constexpr uint64_t kSlabSamples = uint64_t(1) << 24;  // a box is read this many samples at a time (16 Mi)

}  // namespace

BinaryVolume label_mask(const ScalarVolume& v, const LabelInfo& label) {
  const auto [lo, hi] = mask_box(label);
  BinaryVolume b = empty_mask(v.lattice, v.source, lo, hi);
  const Box in = within(v.lattice, lo, hi);
  mask_into(v, in, label, b, {in.lo[0] - lo[0], in.lo[1] - lo[1], in.lo[2] - lo[2]});
  return b;
}

LabelMasks masks_in(const ScalarVolume& volume) {
  return [&volume](const LabelInfo& label) { return label_mask(volume, label); };
}

LabelMasks masks_read(const Lattice& lattice, const std::string& source, BoxRead read) {
  return [lattice, source, read = std::move(read)](const LabelInfo& label) {
    const auto [lo, hi] = mask_box(label);
    BinaryVolume b = empty_mask(lattice, source, lo, hi);
    const Box in = within(lattice, lo, hi);
    const auto d = in.dims();
    const int64_t planes = std::max<int64_t>(1, int64_t(kSlabSamples / uint64_t(d[0] * d[1])));
    for (int64_t k0 = in.lo[2]; k0 < in.hi[2]; k0 += planes) {
      const int64_t k1 = std::min(in.hi[2], k0 + planes);
      const ScalarVolume slab = read(Box{{in.lo[0], in.lo[1], k0}, {in.hi[0], in.hi[1], k1}});
      if (slab.lattice.dims != std::array<int64_t, 3>{d[0], d[1], k1 - k0})
        throw std::logic_error("masks_read: the reader returned the wrong box");
      mask_into(slab, Box{{0, 0, 0}, slab.lattice.dims}, label, b, {in.lo[0] - lo[0], in.lo[1] - lo[1], k0 - lo[2]});
    }
    return b;
  };
}

std::vector<LabelSurface> press_labels(const ScalarVolume& v, const std::vector<LabelInfo>& labels,
                                       const SurfaceOptions& options) {
  validate(options);
  std::vector<LabelSurface> out(labels.size());
  Progress* progress = options.progress;
  if (progress) progress->begin("labels", labels.size());
  std::atomic<uint64_t> done{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  size_t failed_at = labels.size();
  SurfaceOptions per = options;
  per.progress = nullptr;  // one bar for the labels, not one per label
  // Labels in parallel (each smooth_surface is itself parallel and gives the
  // same bytes for any thread count, so the results do not depend on the
  // schedule); the first failure in label order is the one reported.
  detail::parallel_for(labels.size(), [&](size_t i) {
    try {
      out[i].label = labels[i];
      out[i].result = smooth_surface(label_mask(v, labels[i]), per);
    } catch (const Error& e) {
      std::lock_guard lock(failure_mutex);
      if (i < failed_at) {
        failed_at = i;
        const std::string what = "label " + format_value(labels[i].value) +
                                 (labels[i].name.empty() ? "" : " (" + labels[i].name + ")") + ": ";
        if (const auto* le = dynamic_cast<const LimitError*>(&e))
          failure = std::make_exception_ptr(LimitError(le->path(), what + le->problem()));
        else if (const auto* ie = dynamic_cast<const InputError*>(&e))
          failure = std::make_exception_ptr(InputError(ie->path(), what + ie->problem()));
        else if (dynamic_cast<const UsageError*>(&e))
          failure = std::make_exception_ptr(UsageError(what + e.what()));
        else
          failure = std::current_exception();
      }
    }
    if (progress) progress->update(++done);
  });
  if (progress) progress->end();
  if (failure) std::rethrow_exception(failure);
  return out;
}

}  // namespace voxpress
