// The library's one parallel-loop entry point (src/core/parallel.h).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <vector>

#include "core/parallel.h"

namespace voxpress {
namespace {

// Every index of [0, n) is visited exactly once, in chunks of at least half
// the grain (a range splits in halves while longer than the grain), for 1
// and 4 threads and sizes around the grain.
TEST(Parallel, EveryIndexOnceInChunksOfTheGrain) {
  for (int threads : {1, 4}) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, size_t(threads));
    for (size_t n : {size_t(0), size_t(1), size_t(63), size_t(64), size_t(65), size_t(100000)}) {
      std::vector<std::atomic<int>> seen(n);
      std::atomic<size_t> short_chunks{0};
      detail::parallel_ranges(n, 64, [&](detail::IndexRange r) {
        EXPECT_LT(r.begin(), r.end());
        if (r.end() - r.begin() < std::min<size_t>(n, 32)) ++short_chunks;
        for (size_t i = r.begin(); i < r.end(); ++i) ++seen[i];
      });
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i].load(), 1) << "n " << n << " index " << i;
      EXPECT_EQ(short_chunks.load(), 0u) << "n " << n;
      std::vector<int> each(n, 0);
      detail::parallel_for(n, [&](size_t i) { each[i] += int(i % 7) + 1; });
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(each[i], int(i % 7) + 1);
    }
  }
}

// The signed form covers [lo, hi), negative bounds included, and nothing
// when hi <= lo.
TEST(Parallel, SignedRangesFromLoToHi) {
  std::vector<std::atomic<int>> seen(20);
  detail::parallel_for(int64_t(-5), int64_t(15), [&](int64_t k) { ++seen[size_t(k + 5)]; });
  for (const auto& s : seen) EXPECT_EQ(s.load(), 1);
  bool ran = false;
  detail::parallel_for(int64_t(3), int64_t(3), [&](int64_t) { ran = true; });
  detail::parallel_for(int64_t(4), int64_t(-4), [&](int64_t) { ran = true; });
  EXPECT_FALSE(ran);
}

}  // namespace
}  // namespace voxpress
