// A uniform grid of triangles for the simplifier's clash queries (private).
//
// A triangle is listed in every cell its box meets; a query visits the
// cells its box meets and reports each triangle once. Triangles grow as the
// mesh is simplified (a flat ends as two triangles across the part), so the
// simplifier rebuilds the grid with the mean triangle extent as its cell
// whenever the face count has halved: a triangle stays in a handful of
// cells and a query's box in a few dozen. The cells are found through an
// open-addressing table (a node-based map's pointer chasing was most of the
// query's time: perf on build/bench/bench_simplify).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "voxpress/core/types.h"

namespace voxpress::detail {

class FaceGrid {
 public:
  /// Cells of side `cell` (index space); `faces` is the largest face id + 1.
  void reset(double cell, size_t faces) {
    side_ = cell;
    keys_.assign(1024, kEmpty);
    slot_.assign(1024, 0);
    lists_.clear();
    range_.assign(faces, {});
  }
  double side() const { return side_; }

  void insert(uint32_t f, const Vec3& lo, const Vec3& hi) {
    Range& r = range_[f];
    for (int k = 0; k < 3; ++k) {
      r.lo[k] = cell(lo[k]);
      r.hi[k] = cell(hi[k]);
    }
    r.used = true;
    visit_cells(r, [&](const std::array<int32_t, 3>&, uint64_t key) { lists_[find_or_add(key)].push_back(f); });
  }

  void erase(uint32_t f) {
    Range& r = range_[f];
    if (!r.used) return;
    visit_cells(r, [&](const std::array<int32_t, 3>&, uint64_t key) {
      std::vector<uint32_t>& v = lists_[find(key)];
      *std::find(v.begin(), v.end(), f) = v.back();
      v.pop_back();
    });
    r.used = false;
  }

  /// Re-lists f for its new box (nothing to do when it meets the same cells).
  void move(uint32_t f, const Vec3& lo, const Vec3& hi) {
    Range r;
    for (int k = 0; k < 3; ++k) {
      r.lo[k] = cell(lo[k]);
      r.hi[k] = cell(hi[k]);
    }
    const Range& old = range_[f];
    if (old.used && old.lo == r.lo && old.hi == r.hi) return;
    erase(f);
    insert(f, lo, hi);
  }

  /// visit(f) once for every triangle listed in a cell [lo, hi] meets. A
  /// triangle is reported from the first cell (lowest x, y, z) where its
  /// cells and the query's meet, so the query writes nothing: queries may
  /// run in parallel.
  template <class F>
  void query(const Vec3& lo, const Vec3& hi, F&& visit) const {
    Range r;
    for (int k = 0; k < 3; ++k) {
      r.lo[k] = cell(lo[k]);
      r.hi[k] = cell(hi[k]);
    }
    visit_cells(r, [&](const std::array<int32_t, 3>& c, uint64_t key) {
      const uint32_t i = find(key);
      if (i == kNone) return;
      for (uint32_t f : lists_[i]) {
        const Range& fr = range_[f];
        if (c[0] == std::max(r.lo[0], fr.lo[0]) && c[1] == std::max(r.lo[1], fr.lo[1]) &&
            c[2] == std::max(r.lo[2], fr.lo[2]))
          visit(f);
      }
    });
  }

 private:
  struct Range {
    std::array<int32_t, 3> lo{}, hi{};
    bool used = false;
  };
  static constexpr int64_t kBias = int64_t(1) << 20;  // 21 bits per axis

  static constexpr uint64_t kEmpty = ~uint64_t(0);
  static constexpr uint32_t kNone = ~uint32_t(0);
  size_t home(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> 20) & (keys_.size() - 1); }
  // The list of a cell, or kNone (linear probing; cells are never removed,
  // an emptied cell keeps its empty list).
  uint32_t find(uint64_t key) const {
    for (size_t i = home(key);; i = (i + 1) & (keys_.size() - 1)) {
      if (keys_[i] == key) return slot_[i];
      if (keys_[i] == kEmpty) return kNone;
    }
  }
  uint32_t find_or_add(uint64_t key) {
    if (2 * (lists_.size() + 1) > keys_.size()) {  // keep the table at most half full
      std::vector<uint64_t> keys(2 * keys_.size(), kEmpty);
      std::vector<uint32_t> slot(keys.size());
      keys.swap(keys_);
      slot.swap(slot_);
      for (size_t j = 0; j < keys.size(); ++j)
        if (keys[j] != kEmpty) {
          size_t i = home(keys[j]);
          while (keys_[i] != kEmpty) i = (i + 1) & (keys_.size() - 1);
          keys_[i] = keys[j];
          slot_[i] = slot[j];
        }
    }
    size_t i = home(key);
    for (; keys_[i] != kEmpty; i = (i + 1) & (keys_.size() - 1))
      if (keys_[i] == key) return slot_[i];
    keys_[i] = key;
    slot_[i] = uint32_t(lists_.size());
    lists_.emplace_back();
    return slot_[i];
  }
  int32_t cell(double x) const { return int32_t(std::floor(x / side_)); }
  template <class F>
  static void visit_cells(const Range& r, F&& f) {
    const uint64_t m = (uint64_t(1) << 21) - 1;
    for (int32_t z = r.lo[2]; z <= r.hi[2]; ++z)
      for (int32_t y = r.lo[1]; y <= r.hi[1]; ++y)
        for (int32_t x = r.lo[0]; x <= r.hi[0]; ++x)
          f(std::array<int32_t, 3>{x, y, z}, ((uint64_t(int64_t(x) + kBias) & m) << 42) |
                                                 ((uint64_t(int64_t(y) + kBias) & m) << 21) |
                                                 (uint64_t(int64_t(z) + kBias) & m));
  }

  double side_ = 1;
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> slot_;
  std::vector<std::vector<uint32_t>> lists_;
  std::vector<Range> range_;
};

}  // namespace voxpress::detail
