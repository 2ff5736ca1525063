// Private: the derivation of one label case (label_derive.cpp; theory:
// include/voxpress/labels/label_cases.h). label_case() caches its results.
#pragma once

#include <cstdint>
#include <string>

#include "voxpress/labels/label_cases.h"

namespace voxpress::detail {

/// The case of a pattern of ranks 0..m-1 (no triangles below two labels; the
/// binary case, the larger label inside, for two).
LabelCase derive_label_case(const LabelPattern& ranks);
/// How many distinct ranks r[0..n) holds (each below 8).
int distinct_count(const uint8_t* r, int n);
/// complete = false: only edges used twice the same way (a partial case).
std::string label_case_defect(const LabelCase& c, bool complete);

}  // namespace voxpress::detail
