#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace voxpress::detail {

void parallel_ranges(size_t n, size_t grain, RangeBody body) {
  if (n == 0) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain == 0 ? 1 : grain),
                    [&](const tbb::blocked_range<size_t>& r) { body(IndexRange{r.begin(), r.end()}); });
}

}  // namespace voxpress::detail
