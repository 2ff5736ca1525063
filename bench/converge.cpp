// Pressing's solver: how close each sweep budget comes to the fixed point
// (the residual of the map at d, and the distance of t to the longest
// run's), in how many seconds, and how far the result is from the truth.
//   build/bench/bench_converge                          # the table in docs/BENCHMARKS.md
//   build/bench/bench_converge --shape cad-part --res 256 --seeds 1 [--flats]
//   build/bench/bench_converge --volume mask.nrrd
// Each row runs the default schedule with --iterations N and tolerance 0;
// the reference is the last (largest) N; "max |dt|" is the largest
// difference of t to it, a fraction of the stick (= cells along it).
// --flats runs press_with_flats (estimates, detection, crease rounds) instead
// of the plain press; "r->t RMS" is the stick surface's distance to the
// truth (voxels) after the press (no quadric fit, no sharpening).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

struct Run {
  std::vector<double> t;
  PressStats st;
  double seconds = 0;
};

Run solve(const StickSurface& base, const SliceCurves& curves, int sweeps, bool flats, double momentum) {
  StickSurface s = base;
  PressOptions po;
  po.tolerance = 0;
  po.iterations = sweeps;
  po.momentum = momentum;
  const auto t0 = std::chrono::steady_clock::now();
  Run r;
  if (flats) {
    FlatOptions fo;
    r.st = press_with_flats(s, curves, po, &fo, nullptr).press;
  } else {
    r.st = press(s, curves, po);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.t = std::move(s.t);
  return r;
}

double rms_to_truth(StickSurface s, const std::vector<double>& t, const Truth* truth, const BinaryVolume& v) {
  if (!truth) return NAN;
  s.t = t;
  EvalOptions eo;
  eo.volume = &v;
  eo.samples = 100000;
  eo.self_intersections = false;
  return evaluate(to_mesh(s), *truth, eo).result_to_truth_vox.rms;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Pressing's solver: tolerance against distance to the fixed point");
  std::vector<std::string> shapes{"sphere", "torus", "cad-part"};
  std::string volume_path;
  int res = 128, seeds = 1;
  bool flats = false;
  std::vector<int> budgets{100, 200, 400, 1000, 4000};
  std::vector<double> momenta{PressOptions{}.momentum};
  app.add_option("--shape", shapes, "Generated shapes");
  app.add_option("--volume", volume_path, "A volume file instead (no truth)");
  app.add_option("--res", res, "Samples along the longest side");
  app.add_option("--seeds", seeds, "Random rotations 1..N");
  app.add_option("--iterations", budgets, "Sweep budgets of the rows (the last is the reference)");
  app.add_flag("--flats", flats, "press_with_flats instead of the plain press");
  app.add_option("--momentum", momenta, "Heavy-ball momenta of the rows (the reference uses the first)");
  CLI11_PARSE(app, argc, argv);
  std::printf("| case | momentum | sweeps | residual | seconds | max abs dt to ref | RMS dt | r->t RMS |\n"
              "|---|---:|---:|---:|---:|---:|---:|---:|\n");
  auto one = [&](const std::string& name, const BinaryVolume& v, const Truth* truth) {
    const StickSurface base = extract_sticks(v);
    const SliceCurves curves = build_slice_curves(base);
    std::vector<Run> runs;
    std::vector<double> used;
    for (double m : momenta)
      for (size_t k = 0; k + 1 < budgets.size(); ++k) {
        runs.push_back(solve(base, curves, budgets[k], flats, m));
        used.push_back(m);
      }
    runs.push_back(solve(base, curves, budgets.back(), flats, momenta.front()));
    used.push_back(momenta.front());
    const Run& ref = runs.back();
    size_t at = 0;
    auto row = [&](const Run& r) {
      double mx = 0, ss = 0;
      for (size_t i = 0; i < r.t.size(); ++i) {
        const double d = std::abs(r.t[i] - ref.t[i]);
        mx = std::max(mx, d);
        ss += d * d;
      }
      std::printf("| %s | %.2f | %d | %.1e | %.3f | %.1e | %.1e | %.4f |\n", name.c_str(), used[at++], r.st.iterations,
                  r.st.residual, r.seconds, mx, std::sqrt(ss / double(r.t.size())), rms_to_truth(base, r.t, truth, v));
    };
    for (const Run& r : runs) row(r);
    std::fflush(stdout);
  };
  if (!volume_path.empty()) {
    one(volume_path, binarize(read_volume(volume_path)), nullptr);
    return 0;
  }
  for (const std::string& shape : shapes)
    for (int seed = 1; seed <= seeds; ++seed) {
      GenerateOptions g;
      g.res = res;
      g.rotation = parse_rotation("random:" + std::to_string(seed));
      const ShapeKind kind = parse_shape(shape);
      const GeneratedShape gs = generate_shape(kind, g);
      const auto truth = shape_truth(kind, gs.linear, gs.translation);
      one(shape + " " + std::to_string(res) + " r" + std::to_string(seed), gs.volume, truth.get());
    }
  return 0;
}
