// The truth-known family for the sharp-edge decision (issue 75): a box whose
// edges and corners are rounded with radius r cells (`voxpress generate box
// --fillet R`; r = 0 is the sharp box), or a cylinder whose rims are
// (`--shape cylinder`: a flat cap meets a curved side through the fillet),
// over several rotations, pressed by
// the default, `--no-sharpen` and `--no-flats`, each measured against its
// exact truth by the same evaluate() as `voxpress eval` and bench/compare.
// A fillet of radius r > 0 has no sharp edge, so every labelled edge there is
// a false one (precision 0); at r = 0 the box's 12 edges (the cylinder's
// two rims) are the truth.
//   build/bench/bench_fillets                                  # the table in docs/BENCHMARKS.md
//   build/bench/bench_fillets --shape cylinder
//   build/bench/bench_fillets --radii 0,1,3 --seeds 1,2 --res 96
// Per radius and variant, means over the seeds: result -> truth RMS and
// Hausdorff (voxels), mean normal error (degrees), sharp-edge recall /
// precision (within half a voxel; "-" where undefined: recall without true
// edges, precision without labelled ones) and labelled sharp edges. The last
// column is the default's RMS over the best of the three (the issue's
// target: at most 1.03). Every run is checked (closed, manifold, oriented,
// no self-intersection, 0 violations) and a failure is printed.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

struct Variant {
  const char* name;
  std::vector<Pass> off;
};
const Variant kVariants[] = {{"default", {}}, {"--no-sharpen", {Pass::sharpen}}, {"--no-flats", {Pass::flats}}};
constexpr size_t kVariantCount = std::size(kVariants);

struct Figures {
  double rms = 0, normal = 0, hausdorff = 0, recall = 0, precision = 0, labelled = 0;
  int runs = 0, recall_runs = 0, precision_runs = 0;
  std::vector<std::string> failures;
};

std::vector<double> split(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  for (std::string w; std::getline(in, w, ',');)
    if (!w.empty()) out.push_back(std::stod(w));
  return out;
}

std::string mean_or_dash(double sum, int n, double scale, int digits) {
  if (n == 0) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, scale * sum / n);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The filleted family: the sharp-edge decision against the exact truth"};
  std::string radii_arg = "0,0.5,1,1.5,2,3,4", seeds_arg = "1,2,3,4,5", shape_arg = "box";
  int64_t res = 128;
  size_t samples = 100000;
  app.add_option("--radii", radii_arg, "Fillet radii in cells")->capture_default_str();
  app.add_option("--seeds", seeds_arg, "Rotations (random:N)")->capture_default_str();
  app.add_option("--res", res, "Resolution")->capture_default_str();
  app.add_option("--shape", shape_arg, "box or cylinder")->capture_default_str();
  app.add_option("--samples", samples, "Area samples per direction")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const std::vector<double> radii = split(radii_arg), seeds = split(seeds_arg);
  const ShapeKind kind = parse_shape(shape_arg);

  std::vector<std::array<Figures, kVariantCount>> figures(radii.size());
  for (size_t ri = 0; ri < radii.size(); ++ri)
    for (double seed : seeds) {
      GenerateOptions go;
      go.res = res;
      go.rotation = parse_rotation("random:" + std::to_string(int(seed)));
      go.fillet = radii[ri];
      const GeneratedShape g = generate_shape(kind, go);
      const auto truth = shape_truth(kind, g.linear, g.translation, g.fillet);
      for (size_t vi = 0; vi < kVariantCount; ++vi) {
        SurfaceOptions so;
        for (Pass p : kVariants[vi].off) so.passes.disable(p);
        const SurfaceResult r = smooth_surface(g.volume, so);
        EvalOptions eo;
        eo.volume = &g.volume;
        eo.samples = samples;
        const EvalReport e = evaluate(r.mesh, *truth, eo);
        Figures& f = figures[ri][vi];
        ++f.runs;
        f.rms += e.result_to_truth_vox.rms;
        f.normal += e.normal_error_deg;
        f.hausdorff += e.hausdorff_vox.value_or(0);
        f.labelled += double(e.labelled_sharp_edges);
        if (e.sharp_recall) f.recall += *e.sharp_recall, ++f.recall_runs;
        if (e.sharp_precision) f.precision += *e.sharp_precision, ++f.precision_runs;
        const uint64_t violations = e.classification_violations.value_or(0);
        if (!e.mesh.ok() || violations)
          f.failures.push_back("r " + std::to_string(radii[ri]) + " seed " + std::to_string(int(seed)) + ": " +
                               (e.mesh.ok() ? std::to_string(violations) + " violations" : e.mesh.problems[0]));
        std::fprintf(stderr, "r %.1f seed %d %-13s r->t %.4f normal %.2f H %.3f labelled %zu\n", radii[ri],
                     int(seed), kVariants[vi].name, e.result_to_truth_vox.rms, e.normal_error_deg,
                     e.hausdorff_vox.value_or(0), e.labelled_sharp_edges);
      }
    }

  std::printf("%s, res %ld, rotations random:%s; means over the rotations: r->t RMS (vox) / normal error (deg) / "
              "Hausdorff (vox) / sharp recall / precision (%%, within 0.5 vox) / labelled sharp edges\n\n",
              shape_name(kind), long(res), seeds_arg.c_str());
  std::printf("| r (cells) |");
  for (const Variant& v : kVariants) std::printf(" %s |", v.name);
  std::printf(" default / best RMS |\n|---:|");
  for (size_t i = 0; i < kVariantCount; ++i) std::printf("---|");
  std::printf("---:|\n");
  for (size_t ri = 0; ri < radii.size(); ++ri) {
    std::printf("| %g |", radii[ri]);
    double best = INFINITY;
    for (size_t vi = 0; vi < kVariantCount; ++vi) best = std::min(best, figures[ri][vi].rms / figures[ri][vi].runs);
    for (size_t vi = 0; vi < kVariantCount; ++vi) {
      const Figures& f = figures[ri][vi];
      const double rms = f.rms / f.runs;
      std::printf(" %s%.4f%s / %.2f° / %.2f / %s / %s / %.0f |", rms == best ? "**" : "", rms, rms == best ? "**" : "",
                  f.normal / f.runs, f.hausdorff / f.runs, mean_or_dash(f.recall, f.recall_runs, 100, 1).c_str(),
                  mean_or_dash(f.precision, f.precision_runs, 100, 1).c_str(), f.labelled / f.runs);
    }
    std::printf(" %.3f |\n", figures[ri][0].rms / figures[ri][0].runs / best);
  }
  bool ok = true;
  for (size_t ri = 0; ri < radii.size(); ++ri)
    for (size_t vi = 0; vi < kVariantCount; ++vi)
      for (const auto& msg : figures[ri][vi].failures)
        std::printf("CHECK FAILED (%s): %s\n", kVariants[vi].name, msg.c_str()), ok = false;
  return ok ? 0 : 1;
}
