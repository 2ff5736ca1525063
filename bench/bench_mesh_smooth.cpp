// bench_mesh_smooth: Bade et al.'s sphere experiment (Fig. 7: a binary
// sphere of diameter 60, stopping threshold 0.002) for the mesh-level
// constraints, CESN, Taubin and Laplacian, then every method's time on the
// 256^3 organic volume. Prints Markdown tables (docs/BENCHMARKS.md).
//   build/bench/bench_mesh_smooth [--runs N] [--no-organic]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>

#include "organic.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

struct Result {
  Mesh mesh;
  int iterations = 0;
  bool converged = false;
  double seconds = 0;  // median over runs
};

// The methods, from the volume's stick surface. Mesh-level constraints
// start from the midpoint mesh with its lattice *recovered* (timed), as a
// user with only the exported mesh would run them.
Result run(const std::string& method, const StickSurface& s, const Mesh& mc, int runs) {
  std::vector<double> times;
  Result r;
  for (int k = 0; k < runs; ++k) {
    const double t0 = now();
    if (method == "cesn") {
      SurfaceNetStats st;
      r.mesh = constrained_surface_net(s, {}, &st);
      r.iterations = st.iterations;
      r.converged = st.converged;
    } else if (method == "taubin" || method == "laplacian") {
      r.mesh = mc;
      const SmoothStats st = fair(r.mesh, fair_defaults(method == "taubin" ? FairOptions::Kind::taubin
                                                                           : FairOptions::Kind::laplacian));
      r.iterations = st.iterations;
    } else if (method == "pressing") {
      StickSurface p = s;
      const PressStats st = press(p);
      r.mesh = to_mesh(p);
      r.iterations = st.iterations;
      r.converged = st.iterations < PressOptions{}.iterations;
    } else {
      LatticeMesh lm = recover_lattice(mc, "midpoint mesh");
      ConstrainedOptions o;
      o.constraint = parse_constraint(method);
      const SmoothStats st = constrained_smooth(lm, o);
      r.mesh = std::move(lm.mesh);
      r.iterations = st.iterations;
      r.converged = st.converged;
    }
    times.push_back(now() - t0);
  }
  std::sort(times.begin(), times.end());
  r.seconds = times[times.size() / 2];
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bade et al. sphere experiment and mesh-smoothing timings"};
  int runs = 5;
  bool organic = true;
  app.add_option("--runs", runs, "Timed runs per method on the sphere (median reported)")->capture_default_str();
  app.add_flag("!--no-organic", organic, "Skip the 256^3 organic volume");
  CLI11_PARSE(app, argc, argv);

  const std::vector<std::string> methods = {"cell-size", "cell-edge", "diamond", "cesn", "taubin", "laplacian", "pressing"};
  GenerateOptions g;
  g.res = 65;  // diameter res - 1 - 2 margin = 60 cells
  const GeneratedShape sphere = generate_shape(ShapeKind::sphere, g);
  const StickSurface s = extract_sticks(sphere.volume);
  const Mesh mc = to_mesh(s);
  const auto analytic = shape_truth(ShapeKind::sphere, sphere.linear, sphere.translation);
  const auto midpoint = mesh_truth(mc, "midpoint surface");
  const double diagonal = std::sqrt(3.0);
  std::printf("Sphere of diameter 60 cells: midpoint mesh %zu vertices, %zu triangles; threshold 0.002 cells; "
              "median of %d runs.\n\n",
              mc.vertex_count(), mc.face_count(), runs);
  std::printf("| method | iterations | time | V (%%) | maxD (cell diag.) | viol. | r→t RMS | normal err. |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  {
    EvalOptions eo;
    eo.volume = &sphere.volume;
    eo.self_intersections = false;
    const EvalReport e = evaluate(mc, *analytic, eo);
    std::printf("| midpoint (MC) | – | – | 100.0 | 0 | %llu | %.4f | %.2f° |\n",
                (unsigned long long)*e.classification_violations, e.result_to_truth_vox.rms, e.normal_error_deg);
  }
  const double v0 = signed_volume(mc);
  for (const std::string& m : methods) {
    const Result r = run(m, s, mc, runs);
    EvalOptions eo;
    eo.volume = &sphere.volume;
    eo.self_intersections = false;
    const EvalReport e = evaluate(r.mesh, *analytic, eo);
    const EvalReport d = evaluate(r.mesh, *midpoint, {});
    std::printf("| %s | %d%s | %.1f ms | %.1f | %.2f | %llu | %.4f | %.2f° |\n", m.c_str(), r.iterations,
                r.converged || m == "taubin" || m == "laplacian" ? "" : " (cap)", 1e3 * r.seconds,
                100 * signed_volume(r.mesh) / v0, d.hausdorff / diagonal,
                (unsigned long long)*e.classification_violations, e.result_to_truth_vox.rms, e.normal_error_deg);
  }
  if (!organic) return 0;

  const BinaryVolume& vol = bench::organic();
  double t0 = now();
  const StickSurface os = extract_sticks(vol);
  const double t_extract = now() - t0;
  const Mesh omc = to_mesh(os);
  std::printf("\n%s: %zu sticks, extraction %.2f s. One run each, all cores.\n\n", vol.source.c_str(),
              os.stick_count(), t_extract);
  std::printf("| method | iterations | time | viol. |\n|---|---:|---:|---:|\n");
  for (const std::string& m : methods) {
    const Result r = run(m, os, omc, 1);
    const uint64_t viol = check_classification(r.mesh, vol).violations;
    std::printf("| %s | %d%s | %.2f s | %llu |\n", m.c_str(), r.iterations,
                r.converged || m == "taubin" || m == "laplacian" ? "" : " (cap)", r.seconds, (unsigned long long)viol);
  }
  return 0;
}
