// Label cases: every pattern of three labels derives a case in which each
// label's triangles close up inside the cube (every inner edge used once
// each way, one fan around each apex); with four to eight labels the
// derivation either gives such a case or refuses (logic_error), never a
// defective one; two labels are the binary case.
#include <cstdlib>
#include <set>

#include "test_util.h"
#include "voxpress/labels/label_cases.h"

namespace voxpress {
namespace {

// Every surjective pattern of m labels over 8 corners (m^8 candidates).
std::vector<LabelPattern> all_patterns(int m) {
  std::vector<LabelPattern> out;
  int total = 1;
  for (int i = 0; i < 8; ++i) total *= m;
  for (int n = 0; n < total; ++n) {
    LabelPattern p{};
    int x = n;
    unsigned used = 0;
    for (int c = 0; c < 8; ++c, x /= m) {
      p[size_t(c)] = uint8_t(x % m);
      used |= 1u << p[size_t(c)];
    }
    if (used == (1u << m) - 1) out.push_back(p);
  }
  return out;
}

TEST(LabelCases, TwoLabelsAreTheBinaryCaseWithTheLargerLabelInside) {
  for (unsigned mask = 1; mask < 255; ++mask) {
    LabelPattern p{};
    for (int c = 0; c < 8; ++c) p[size_t(c)] = uint8_t((mask >> c) & 1);
    const LabelCase& lc = label_case(p);
    const CubeCase& cc = cube_case(mask);
    ASSERT_EQ(lc.triangles.size(), size_t(cc.count));
    for (size_t i = 0; i < lc.triangles.size(); ++i) {
      EXPECT_EQ(lc.triangles[i].v, cc.triangles[i]);
      EXPECT_EQ(lc.triangles[i].in, 1);
      EXPECT_EQ(lc.triangles[i].out, 0);
    }
  }
}

TEST(LabelCases, EveryThreeLabelPatternClosesUpPerLabel) {
  const bool all = std::getenv("VOXPRESS_ALL_LABEL_PATTERNS") != nullptr;
  size_t n = 0;
  for (const LabelPattern& p : all_patterns(3)) {
    // Every third pattern (CI time); VOXPRESS_ALL_LABEL_PATTERNS=1 derives
    // all 5796 (all pass: docs/ARCHITECTURE.md, Label maps).
    if (!all && n++ % 3) continue;
    if (all) ++n;
    const LabelCase& lc = label_case(p);
    EXPECT_EQ(label_case_defect(lc), "") << int(p[0]) << int(p[1]) << int(p[2]) << int(p[3]) << int(p[4]) << int(p[5])
                                          << int(p[6]) << int(p[7]);
    EXPECT_LE(lc.apexes.size(), size_t(kMaxApexes));
  }
  EXPECT_GT(n, 0u);
}

TEST(LabelCases, PatternsOfFourToEightLabelsCloseUpOrAreRefused) {
  test::Rng rng(54);
  size_t derived = 0;
  for (int n = 0; n < 300; ++n) {
    const int m = int(rng.range(4, 8));
    std::array<uint32_t, 8> labels{};
    for (auto& l : labels) l = uint32_t(rng.range(0, m - 1)) * 7;
    int distinct = 0;
    const LabelPattern p = label_pattern(labels, &distinct);
    try {
      const LabelCase& lc = label_case(p);
      EXPECT_EQ(lc.labels, distinct);
      EXPECT_EQ(label_case_defect(lc), "");
      ++derived;
    } catch (const std::logic_error&) {  // not derivable yet (issue 54): refused, never wrong
    }
  }
  EXPECT_GT(derived, 0u);
}

TEST(LabelCases, PatternsRankLabelsByValue) {
  int d = 0;
  EXPECT_EQ(label_pattern({9, 0, 0, 4, 4, 4, 9, 0}, &d), (LabelPattern{2, 0, 0, 1, 1, 1, 2, 0}));
  EXPECT_EQ(d, 3);
  EXPECT_THROW(label_case(LabelPattern{0, 2, 2, 2, 2, 2, 2, 2}), std::invalid_argument);
  EXPECT_TRUE(face_has_center({0, 0, 1, 2}));
  EXPECT_FALSE(face_has_center({0, 1, 0, 2}));
  EXPECT_TRUE(face_has_center({0, 1, 2, 3}));
  EXPECT_FALSE(face_has_center({0, 1, 1, 0}));
}

}  // namespace
}  // namespace voxpress
