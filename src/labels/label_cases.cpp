// The label cases' table (theory: include/voxpress/labels/label_cases.h);
// each case is derived on first use (label_derive.cpp).
#include "voxpress/labels/label_cases.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "labels/label_derive.h"

namespace voxpress {

using detail::distinct_count;

bool face_has_center(const std::array<uint8_t, 4>& q) {
  const int k = distinct_count(q.data(), 4);
  if (k == 4) return true;
  if (k < 3) return false;
  return !(q[0] == q[2] || q[1] == q[3]);
}

LabelPattern label_pattern(const std::array<uint32_t, 8>& labels, int* distinct, std::array<uint32_t, 8>* values) {
  std::array<uint32_t, 8> sorted = labels;
  std::sort(sorted.begin(), sorted.end());
  const auto end = std::unique(sorted.begin(), sorted.end());
  LabelPattern p{};
  for (size_t c = 0; c < 8; ++c) p[c] = uint8_t(std::lower_bound(sorted.begin(), end, labels[c]) - sorted.begin());
  if (distinct) *distinct = int(end - sorted.begin());
  if (values) *values = sorted;
  return p;
}

const LabelCase& label_case(const LabelPattern& pattern) {
  const int m = distinct_count(pattern.data(), 8);
  for (uint8_t x : pattern)
    if (x >= m) throw std::invalid_argument("label_case: ranks must be 0..m-1, each used");
  static std::mutex mutex;
  static std::map<LabelPattern, LabelCase> cache;
  {
    std::lock_guard lock(mutex);
    const auto it = cache.find(pattern);
    if (it != cache.end()) return it->second;
  }
  LabelCase c = detail::derive_label_case(pattern);  // outside the lock: derivations of different patterns run in parallel
  std::lock_guard lock(mutex);
  return cache.emplace(pattern, std::move(c)).first->second;  // std::map: references stay valid
}

std::string label_case_defect(const LabelCase& c) { return detail::label_case_defect(c, true); }

}  // namespace voxpress
