// A hierarchy of uniform grids of triangles for the simplifier's clash
// queries (private).
//
// Level l has cells of side `cell` * 4^l; a triangle is listed at the
// finest level where its box spans at most two cells per axis (so in at
// most 8 cells), and a query visits the cells its box meets on every
// level that holds a triangle, reporting each triangle once. A flat
// simplifies to a few triangles across the part: on one grid such a
// triangle was listed in hundreds of cells, and moving it rewrote them all
// (the grid's moves were 0.22 s of the 0.75 s serial apply on the 256^3 CAD
// part, `press --faces 9000`; 0.13 s after). The simplifier rebuilds the grid with the mean triangle
// extent as its finest cell whenever the face count has halved. The cells
// are found through open-addressing tables (a node-based map's pointer
// chasing was most of the query's time: perf on build/bench/bench_simplify).
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
  /// Finest cells of side `cell` (index space); `faces` is the largest face id + 1.
  void reset(double cell, size_t faces) {
    side_ = cell;
    for (Level& l : levels_) {
      l.keys.assign(64, kEmpty);
      l.slot.assign(64, 0);
      l.lists.clear();
      l.faces = 0;
    }
    range_.assign(faces, {});
  }

  void insert(uint32_t f, const Vec3& lo, const Vec3& hi) { list(f, range_of(lo, hi, level_of(lo, hi))); }

  void erase(uint32_t f) {
    Range& r = range_[f];
    if (!r.used) return;
    Level& l = levels_[r.level];
    visit_cells(r, [&](const std::array<int32_t, 3>&, uint64_t key) {
      std::vector<uint32_t>& v = l.lists[find(l, key)];
      *std::find(v.begin(), v.end(), f) = v.back();
      v.pop_back();
    });
    --l.faces;
    r.used = false;
  }

  /// Re-lists f for its new box (nothing to do when it meets the same cells).
  void move(uint32_t f, const Vec3& lo, const Vec3& hi) {
    const Range r = range_of(lo, hi, level_of(lo, hi));
    const Range& old = range_[f];
    if (old.used && old.level == r.level && old.lo == r.lo && old.hi == r.hi) return;
    erase(f);
    list(f, r);
  }

  /// visit(f) once for every triangle listed in a cell [lo, hi] meets. A
  /// triangle is reported from the first cell (lowest x, y, z) of its level
  /// where its cells and the query's meet, so the query writes nothing:
  /// queries may run in parallel.
  template <class F>
  void query(const Vec3& lo, const Vec3& hi, F&& visit) const {
    for (uint8_t k = 0; k < kLevels; ++k) {
      const Level& l = levels_[k];
      if (l.faces == 0) continue;
      const Range r = range_of(lo, hi, k);
      visit_cells(r, [&](const std::array<int32_t, 3>& c, uint64_t key) {
        const uint32_t i = find(l, key);
        if (i == kNone) return;
        for (uint32_t f : l.lists[i]) {
          const Range& fr = range_[f];
          if (c[0] == std::max(r.lo[0], fr.lo[0]) && c[1] == std::max(r.lo[1], fr.lo[1]) &&
              c[2] == std::max(r.lo[2], fr.lo[2]))
            visit(f);
        }
      });
    }
  }

 private:
  static constexpr uint8_t kLevels = 8;  // the coarsest cell: 4^7 = 16384 finest cells
  struct Range {
    std::array<int32_t, 3> lo{}, hi{};
    uint8_t level = 0;
    bool used = false;
  };
  struct Level {
    std::vector<uint64_t> keys;
    std::vector<uint32_t> slot;
    std::vector<std::vector<uint32_t>> lists;
    size_t faces = 0;  // triangles listed at this level
  };
  static constexpr int64_t kBias = int64_t(1) << 20;  // 21 bits per axis

  static constexpr uint64_t kEmpty = ~uint64_t(0);
  static constexpr uint32_t kNone = ~uint32_t(0);
  // Lists f in the cells of r (its level's).
  void list(uint32_t f, const Range& r) {
    range_[f] = r;
    range_[f].used = true;
    Level& l = levels_[r.level];
    ++l.faces;
    visit_cells(r, [&](const std::array<int32_t, 3>&, uint64_t key) { l.lists[find_or_add(l, key)].push_back(f); });
  }
  double side(uint8_t level) const { return side_ * double(uint64_t(1) << (2 * level)); }
  // The finest level whose cell is at least the box's longest side (so the
  // box spans at most two cells per axis).
  uint8_t level_of(const Vec3& lo, const Vec3& hi) const {
    const double e = (hi - lo).maxCoeff();
    uint8_t k = 0;
    while (k + 1 < kLevels && side(k) < e) ++k;
    return k;
  }
  Range range_of(const Vec3& lo, const Vec3& hi, uint8_t level) const {
    Range r;
    r.level = level;
    const double s = side(level);
    for (int k = 0; k < 3; ++k) {
      r.lo[k] = int32_t(std::floor(lo[k] / s));
      r.hi[k] = int32_t(std::floor(hi[k] / s));
    }
    return r;
  }
  static size_t home(const Level& l, uint64_t key) {
    return size_t((key * 0x9E3779B97F4A7C15ull) >> 20) & (l.keys.size() - 1);
  }
  // The list of a cell, or kNone (linear probing; cells are never removed,
  // an emptied cell keeps its empty list).
  static uint32_t find(const Level& l, uint64_t key) {
    for (size_t i = home(l, key);; i = (i + 1) & (l.keys.size() - 1)) {
      if (l.keys[i] == key) return l.slot[i];
      if (l.keys[i] == kEmpty) return kNone;
    }
  }
  static uint32_t find_or_add(Level& l, uint64_t key) {
    if (2 * (l.lists.size() + 1) > l.keys.size()) {  // keep the table at most half full
      std::vector<uint64_t> keys(2 * l.keys.size(), kEmpty);
      std::vector<uint32_t> slot(keys.size());
      keys.swap(l.keys);
      slot.swap(l.slot);
      for (size_t j = 0; j < keys.size(); ++j)
        if (keys[j] != kEmpty) {
          size_t i = home(l, keys[j]);
          while (l.keys[i] != kEmpty) i = (i + 1) & (l.keys.size() - 1);
          l.keys[i] = keys[j];
          l.slot[i] = slot[j];
        }
    }
    size_t i = home(l, key);
    for (; l.keys[i] != kEmpty; i = (i + 1) & (l.keys.size() - 1))
      if (l.keys[i] == key) return l.slot[i];
    l.keys[i] = key;
    l.slot[i] = uint32_t(l.lists.size());
    l.lists.emplace_back();
    return l.slot[i];
  }
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
  std::array<Level, kLevels> levels_;
  std::vector<Range> range_;
};

}  // namespace voxpress::detail
