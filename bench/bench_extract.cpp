// Throughput of the classification/stick pass and of the full midpoint
// extraction on generated volumes, 1 and N threads. Prints voxels/s and the
// process's peak resident memory; bench/run runs each case in a separate
// process so that the peak belongs to that case alone.
//
//   build/bench/bench_extract --benchmark_filter='Extract/512/2'
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <map>
#include <memory>

#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

// One generated volume per resolution, built on first use (outside timing).
const BinaryVolume& volume(int64_t res) {
  static std::map<int64_t, BinaryVolume> cache;
  auto it = cache.find(res);
  if (it == cache.end()) {
    GenerateOptions o;
    o.res = res;
    o.rotation = parse_rotation("random:1");
    // The torus: a smooth organic-like surface filling most of the box.
    it = cache.emplace(res, generate_shape(ShapeKind::torus, o).volume).first;
  }
  return it->second;
}

double peak_rss_mib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;
}

void set_counters(benchmark::State& state, const BinaryVolume& v, uint64_t sticks, uint64_t triangles) {
  state.counters["voxels/s"] =
      benchmark::Counter(double(v.lattice.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["sticks"] = double(sticks);
  state.counters["triangles"] = double(triangles);
  state.counters["peak_MiB"] = peak_rss_mib();
}

void Sticks(benchmark::State& state) {
  const BinaryVolume& v = volume(state.range(0));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(1)));
  uint64_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = count_sticks(v));
  set_counters(state, v, n, 0);
}

void Extract(benchmark::State& state) {
  const BinaryVolume& v = volume(state.range(0));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(1)));
  uint64_t sticks = 0, triangles = 0;
  for (auto _ : state) {
    const Mesh m = to_mesh(extract_sticks(v));
    sticks = m.positions.size();
    triangles = m.triangles.size();
    benchmark::DoNotOptimize(m.positions.data());
  }
  set_counters(state, v, sticks, triangles);
}

BENCHMARK(Sticks)->ArgsProduct({{256, 512}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Extract)->ArgsProduct({{256, 512}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
