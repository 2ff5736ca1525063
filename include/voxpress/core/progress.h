// voxpress/core/progress.h — progress reporting and cancellation, injected.
//
// Long stages take an optional Progress*. They call begin() once, then
// update() from any thread (at most once per slab or slice, so the call is
// cheap), then end(). update() returning false asks the stage to stop: it
// throws Cancelled at the next poll. A null pointer means "no reporting".
#pragma once

#include <atomic>
#include <cstdint>
#include <string_view>

#include "voxpress/core/error.h"

namespace voxpress {

class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

class Progress {
 public:
  virtual ~Progress() = default;
  /// A stage starts; total is the number of work units it will report.
  virtual void begin(std::string_view stage, uint64_t total) = 0;
  /// done units of the current stage are finished (thread-safe, monotone).
  /// Return false to cancel.
  virtual bool update(uint64_t done) = 0;
  virtual void end() = 0;
};

/// Thread-safe helper a stage uses to count finished units.
class ProgressCounter {
 public:
  ProgressCounter(Progress* p, std::string_view stage, uint64_t total) : p_(p) {
    if (p_) p_->begin(stage, total);
  }
  ~ProgressCounter() {
    if (p_) p_->end();
  }
  ProgressCounter(const ProgressCounter&) = delete;
  ProgressCounter& operator=(const ProgressCounter&) = delete;
  /// Adds n finished units; throws Cancelled if the sink asked to stop.
  void add(uint64_t n) {
    if (!p_) return;
    const uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (!p_->update(done)) throw Cancelled();
  }

 private:
  Progress* p_;
  std::atomic<uint64_t> done_{0};
};

}  // namespace voxpress
