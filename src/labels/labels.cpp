// Label maps: the label table (one pass), label masks on their boxes, and
// every label pressed in one call. Theory of operation:
// include/voxpress/labels/labels.h.
#include "voxpress/labels/labels.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <span>
#include <sstream>
#include <type_traits>
#include <unordered_map>

#include "voxpress/core/error.h"

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

// One pass over one layer: counts and boxes, and (when wanted) the contacts
// between labels along lattice edges, from the current and previous slices
// of dense numbers (two slices of memory, not a volume).
template <class T>
LayerScan scan_layer(const ScalarVolume& v, std::span<const T> values, int64_t layer, size_t max_labels,
                     bool contacts) {
  const auto& d = v.lattice.dims;
  const int64_t nx = d[0], ny = d[1], nz = d[2], nc = v.components;
  LabelIndex<T> index(v, max_labels);
  std::vector<LabelInfo> info;
  std::vector<uint32_t> cur(size_t(nx * ny)), prev(size_t(nx * ny));
  std::unordered_map<uint64_t, uint64_t> pairs;
  auto touch = [&](uint32_t a, uint32_t b) {
    if (a == b) return;
    if (a > b) std::swap(a, b);
    ++pairs[(uint64_t(a) << 32) | b];
  };
  for (int64_t k = 0; k < nz; ++k) {
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        const uint64_t s = v.lattice.linear(i, j, k);
        const uint32_t id = index(values[size_t(s * uint64_t(nc) + uint64_t(layer))]);
        cur[size_t(i + nx * j)] = id;
        if (id != 0) {
          if (id > info.size()) {
            info.resize(id);
            LabelInfo& l = info[id - 1];
            l.value = index.values[id];
            l.layer = layer;
            l.lo = {i, j, k};
            l.hi = {i, j, k};
          }
          LabelInfo& l = info[id - 1];
          ++l.samples;
          const int64_t p[3] = {i, j, k};
          for (int a = 0; a < 3; ++a) {
            l.lo[size_t(a)] = std::min(l.lo[size_t(a)], p[a]);
            l.hi[size_t(a)] = std::max(l.hi[size_t(a)], p[a]);
          }
        }
        if (!contacts) continue;
        // Edges to the lower neighbours; the lattice's border faces the background.
        if (i > 0) touch(cur[size_t(i - 1 + nx * j)], id);
        if (j > 0) touch(cur[size_t(i + nx * (j - 1))], id);
        if (k > 0) touch(prev[size_t(i + nx * j)], id);
        if (id != 0) {
          const int border = (i == 0) + (i == nx - 1) + (j == 0) + (j == ny - 1) + (k == 0) + (k == nz - 1);
          if (border) pairs[uint64_t(id)] += uint64_t(border);
        }
      }
    std::swap(cur, prev);
  }
  LayerScan out;
  out.labels = std::move(info);
  for (const auto& [key, n] : pairs) {
    const double a = index.values[key >> 32], b = index.values[key & 0xffffffffu];
    out.contacts.push_back({std::min(a, b), std::max(a, b), n});
  }
  std::sort(out.contacts.begin(), out.contacts.end(),
            [](const LabelContact& x, const LabelContact& y) { return std::tie(x.a, x.b) < std::tie(y.a, y.b); });
  return out;
}

}  // namespace

LabelTable label_table(const ScalarVolume& v, size_t max_labels) {
  LabelTable t;
  t.layered = v.components > 1;
  for (int64_t layer = 0; layer < v.components; ++layer) {
    LayerScan scan = v.visit([&](auto values) {
      using T = typename decltype(values)::value_type;
      return scan_layer<T>(v, values, layer, max_labels, v.components == 1);
    });
    for (LabelInfo& l : scan.labels) t.labels.push_back(std::move(l));
    if (v.components == 1) t.contacts = std::move(scan.contacts);
  }
  std::sort(t.labels.begin(), t.labels.end(), [](const LabelInfo& a, const LabelInfo& b) {
    return std::tie(a.layer, a.value) < std::tie(b.layer, b.value);
  });
  // .seg.nrrd: the segments are the labels (a value no segment names is dropped).
  if (!v.segments.empty()) {
    std::vector<LabelInfo> named;
    for (const Segment& s : v.segments) {
      for (const LabelInfo& l : t.labels)
        if (l.layer == s.layer && l.value == s.label) {
          named.push_back(l);
          named.back().name = s.name.empty() ? s.id : s.name;
        }
    }
    t.labels = std::move(named);
  }
  if (t.labels.empty()) throw InputError(v.source, "no labelled sample (every value is 0)");
  return t;
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
      throw InputError(source, "no sample has label " + format_value(value) + " (labels: " + have + ")");
    }
  }
  return out;
}

std::map<double, std::string> read_label_names(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the label-name table");
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

BinaryVolume label_mask(const ScalarVolume& v, const LabelInfo& label) {
  std::array<int64_t, 3> lo{}, hi{};
  for (size_t a = 0; a < 3; ++a) {
    lo[a] = std::max<int64_t>(0, label.lo[a] - 1);
    hi[a] = std::min<int64_t>(v.lattice.dims[a] - 1, label.hi[a] + 1);
  }
  BinaryVolume b;
  b.source = v.source;
  b.lattice = v.lattice;
  b.lattice.dims = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
  b.lattice.origin = v.lattice.to_physical(Vec3(double(lo[0]), double(lo[1]), double(lo[2])));
  b.inside.assign(b.lattice.size(), 0);
  const uint64_t nc = uint64_t(v.components), layer = uint64_t(label.layer);
  v.visit([&](auto values) {
    using T = typename decltype(values)::value_type;
    const T want = T(label.value);
    const auto& d = b.lattice.dims;
    tbb::parallel_for(int64_t(0), d[2], [&](int64_t k) {
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i) {
          const uint64_t s = v.lattice.linear(lo[0] + i, lo[1] + j, lo[2] + k);
          b.inside[b.lattice.linear(i, j, k)] = values[size_t(s * nc + layer)] == want;
        }
    });
  });
  return b;
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
  tbb::parallel_for(size_t(0), labels.size(), [&](size_t i) {
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
