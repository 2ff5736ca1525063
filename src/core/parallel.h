// Private: the library's parallel loops. Every loop goes through one
// non-template entry point (parallel.cpp), so TBB's scheduler templates are
// compiled once, not once per lambda; a call site compiles only its own
// loop body. Chunks are disjoint and each index is visited once, so results
// written per index do not depend on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace voxpress::detail {

// [begin, end) of one chunk; begin()/end() read like tbb::blocked_range's.
struct IndexRange {
  size_t lo, hi;
  size_t begin() const { return lo; }
  size_t end() const { return hi; }
};

// A non-owning reference to a callable taking an IndexRange (the callable
// outlives the call: parallel_ranges returns after every chunk ran).
class RangeBody {
 public:
  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, RangeBody>>>
  RangeBody(F&& f)  // NOLINT(google-explicit-constructor)
      : obj_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o, IndexRange r) { (*static_cast<std::remove_reference_t<F>*>(o))(r); }) {}
  void operator()(IndexRange r) const { call_(obj_, r); }

 private:
  void* obj_;
  void (*call_)(void*, IndexRange);
};

// Runs body over chunks of [0, n), in parallel (TBB's blocked_range and
// auto partitioner, in the current arena: a chunk is split in halves only
// while longer than `grain`, so every chunk holds at least grain / 2
// indices, or all n when n <= grain).
void parallel_ranges(size_t n, size_t grain, RangeBody body);

// body(i) for every i in [0, n), in parallel.
template <class F>
void parallel_for(size_t n, F&& body) {
  parallel_ranges(n, 1, [&](IndexRange r) {
    for (size_t i = r.lo; i < r.hi; ++i) body(i);
  });
}

// body(k) for every k in [lo, hi) (signed: lattice rows and slabs).
template <class F>
void parallel_for(int64_t lo, int64_t hi, F&& body) {
  if (hi <= lo) return;
  parallel_ranges(size_t(hi - lo), 1, [&](IndexRange r) {
    for (size_t i = r.lo; i < r.hi; ++i) body(lo + int64_t(i));
  });
}

}  // namespace voxpress::detail
