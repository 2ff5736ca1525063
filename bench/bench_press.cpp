// Pressing throughput: vertex-iterations per second on a 256^3 organic
// shape (a gyroid clipped by a ball, about 1 M vertices), 1 and 2 threads,
// 100 iterations with the default (accelerated) schedule and with the
// paper's plain iteration.
//   build/bench/bench_press
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "organic.h"
#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

using bench::organic;

void Press(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  const StickSurface base = extract_sticks(organic());
  const SliceCurves curves = build_slice_curves(base);
  PressOptions o;
  o.iterations = 100;
  o.tolerance = 0;
  if (state.range(1) == 0) {  // the paper's plain iteration
    o.levels = 1;
    o.momentum = 0;
  }
  PressStats st;
  for (auto _ : state) {
    state.PauseTiming();
    StickSurface s = base;
    state.ResumeTiming();
    st = press(s, curves, o);
  }
  state.counters["vertices"] = double(base.stick_count());
  state.counters["vertex_it/s"] =
      benchmark::Counter(double(base.stick_count()) * st.iterations * double(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(state.range(1) ? "accelerated (default)" : "paper's plain iteration");
}

void Curves(benchmark::State& state) {
  const StickSurface base = extract_sticks(organic());
  for (auto _ : state) benchmark::DoNotOptimize(build_slice_curves(base).ids[0].data());
  state.counters["vertices"] = double(base.stick_count());
}

BENCHMARK(Press)->ArgsProduct({{1, 2}, {1, 0}})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(Curves)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
