// Pressing throughput: vertex-iterations per second on a 256^3 organic
// shape (a gyroid clipped by a ball, about 1 M vertices), 1 and 2 threads,
// 100 iterations with the default (accelerated) schedule and with the
// paper's plain iteration.
//   build/bench/bench_press
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>

#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

const BinaryVolume& organic() {
  static const BinaryVolume v = [] {
    BinaryVolume b;
    const int64_t n = 256;
    b.lattice.dims = {n, n, n};
    b.inside.resize(size_t(n * n * n));
    const double w = 2 * M_PI / 46.0;  // gyroid period: 46 voxels
    for (int64_t k = 0; k < n; ++k)
      for (int64_t j = 0; j < n; ++j)
        for (int64_t i = 0; i < n; ++i) {
          const double x = double(i) - 127.5, y = double(j) - 127.3, z = double(k) - 127.1;
          const double g = std::sin(w * x) * std::cos(w * y) + std::sin(w * y) * std::cos(w * z) +
                           std::sin(w * z) * std::cos(w * x);
          b.inside[b.lattice.linear(i, j, k)] = x * x + y * y + z * z < 120.0 * 120.0 && g > 0.2;
        }
    return b;
  }();
  return v;
}

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
