// One table-driven ablation of the feature layer: every pass of
// voxpress/features/passes.h switched off alone, on CAD, freeform and
// organic cases over several rotations, against the default press. It
// replaces the per-rule tests that compared one rule on and off on a seed or
// two (their claims are figures, and figures belong here, not in ctest).
//   build/bench/bench_ablation                       # the table in docs/BENCHMARKS.md
//   build/bench/bench_ablation --seeds 1,2,3 --res 128 --passes past-crease,snap
//   build/bench/bench_ablation --cases cad-part,fandisk
//   build/bench/bench_ablation --decision   # issue 75's table: default against
//       --no-sharpen and --no-flats per case, with sharp recall and precision
// Columns per case: result -> truth RMS (voxels), mean normal error
// (degrees), sharp-edge Hausdorff (voxels, true <-> labelled, where the
// truth has sharp edges) and labelled sharp edges, each the mean over the
// seeds; every run is also checked (closed, manifold, oriented, no
// self-intersection, 0 violations) and a failure is printed.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

// The rows: the default, then each pass of the feature layer off alone
// (voxpress/features/passes.h: `flats` off is the whole layer, `sharpen`
// off keeps the chamfers).
struct Rule {
  std::string name, what;
  std::optional<Pass> off;
};

std::vector<Rule> rules() {
  std::vector<Rule> r = {{"default", "every pass on", std::nullopt}};
  for (const PassInfo& p : feature_passes()) r.push_back({p.name, std::string(p.section) + ": " + p.what, p.pass});
  return r;
}

struct Case {
  std::string name;
  BinaryVolume volume;
  std::unique_ptr<Truth> truth;
};

Case make_case(const std::string& name, int64_t res, int seed, const std::string& data) {
  Case c;
  c.name = name;
  const Mat3 rotation = parse_rotation("random:" + std::to_string(seed));
  for (ShapeKind k : {ShapeKind::box, ShapeKind::cylinder, ShapeKind::cad_part, ShapeKind::sphere, ShapeKind::torus})
    if (name == shape_name(k)) {
      GenerateOptions go;
      go.res = res;
      go.rotation = rotation;
      GeneratedShape g = generate_shape(k, go);
      c.truth = shape_truth(k, g.linear, g.translation);
      c.volume = std::move(g.volume);
      return c;
    }
  const std::string file = data + "/meshes/" + name;
  if (!std::filesystem::exists(file)) throw InputError(file, "no such model (is ../shared/data there?)");
  const Mesh model = read_mesh(file);
  VoxelizeOptions vo;
  vo.res = res;
  vo.rotation = rotation;
  Voxelized v = voxelize(model, vo, file);
  Mesh phys = model;
  for (Vec3& p : phys.positions) p = v.placement.translation + v.placement.linear * p;
  c.truth = mesh_truth(std::move(phys), name);
  c.volume = std::move(v.volume);
  return c;
}

struct Figures {
  double rms = 0, normal = 0, sharp_h = 0, labelled = 0, recall = 0, precision = 0;
  int sharp_runs = 0, recall_runs = 0, precision_runs = 0, runs = 0;
  std::vector<std::string> failures;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string w; std::getline(in, w, ',');)
    if (!w.empty()) out.push_back(w);
  return out;
}

using Table = std::vector<std::vector<Figures>>;  // [rule][case]

void print_ablation(int64_t res, const std::string& seeds, const std::vector<std::string>& cases,
                    const std::vector<const Rule*>& chosen, const Table& figures) {
  std::printf("res %ld, seeds %s; per case: r->t RMS (vox) / normal error (deg) / sharp H (vox) / labelled sharp "
              "edges, means over the seeds; [x%%]: r->t RMS change against the default\n\n| pass off | what it does |",
              long(res), seeds.c_str());
  for (const auto& c : cases) std::printf(" %s |", c.c_str());
  std::printf("\n|---|---|");
  for (size_t i = 0; i < cases.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (size_t ri = 0; ri < chosen.size(); ++ri) {
    std::printf("| %s | %s |", chosen[ri]->name.c_str(), chosen[ri]->what.c_str());
    for (size_t ci = 0; ci < cases.size(); ++ci) {
      const Figures& f = figures[ri][ci];
      const Figures& d = figures[0][ci];
      const double rms = f.rms / f.runs;
      std::printf(" %.4f", rms);
      if (ri > 0) std::printf(" [%+.0f%%]", 100 * (rms / (d.rms / d.runs) - 1));
      std::printf(" / %.2f / ", f.normal / f.runs);
      if (f.sharp_runs) {
        std::printf("%.2f", f.sharp_h / f.sharp_runs);
      } else {
        std::printf("-");
      }
      std::printf(" / %.0f |", f.labelled / f.runs);
    }
    std::printf("\n");
  }
}

// Issue 75's decision table: rows are cases; the default's RMS against the
// best of --no-sharpen (rule `sharpen` off) and --no-flats (`flats` off),
// and the default's sharp recall / precision and labelled edges.
void print_decision(int64_t res, const std::string& seeds, const std::vector<std::string>& cases, const Table& figures) {
  std::printf("res %ld, seeds %s; r->t RMS (vox), means over the seeds; default / best: the default over the better of "
              "--no-sharpen and --no-flats (issue 75: <= 1.03); recall / precision: of the true sharp curves (dihedral "
              "> 30 deg) within 0.5 vox, means over the seeds\n\n",
              long(res), seeds.c_str());
  std::printf("| case | default | --no-sharpen | --no-flats | default / best | sharp recall / precision | labelled |\n");
  std::printf("|---|---:|---:|---:|---:|---|---:|\n");
  const auto mean = [](double sum, int n) { return n ? sum / n : 0.0; };
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const Figures &d = figures[0][ci], &nf = figures[1][ci], &ns = figures[2][ci];
    const double a = d.rms / d.runs, b = ns.rms / ns.runs, c = nf.rms / nf.runs;
    std::printf("| %s | %.4f | %.4f | %.4f | %.3f | ", cases[ci].c_str(), a, b, c, a / std::min(b, c));
    if (d.recall_runs) {
      std::printf("%.1f / ", 100 * mean(d.recall, d.recall_runs));
    } else {
      std::printf("- / ");
    }
    if (d.precision_runs) {
      std::printf("%.1f %%", 100 * mean(d.precision, d.precision_runs));
    } else {
      std::printf("-");
    }
    std::printf(" | %.0f |\n", d.labelled / d.runs);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Ablation of the feature layer: each rule off alone, against the default"};
  std::string cases_arg = "cad-part,cylinder,box,fandisk.off,bunny.off", seeds_arg = "1,2,3", rules_arg,
              data = "../shared/data";
  int64_t res = 128;
  app.add_option("--cases", cases_arg, "Generated shapes and ../shared/data/meshes models")->capture_default_str();
  app.add_option("--seeds", seeds_arg, "Rotations (random:N)")->capture_default_str();
  app.add_option("--res", res, "Resolution")->capture_default_str();
  app.add_option("--passes", rules_arg, "Only these passes (default and flats always run)");
  app.add_option("--data", data, "The shared data folder")->capture_default_str();
  bool decision = false;
  app.add_flag("--decision", decision,
               "Issue 75's table: the default against --no-sharpen and --no-flats, one row per case");
  CLI11_PARSE(app, argc, argv);
  if (decision) rules_arg = "sharpen";
  std::vector<int> seeds;
  for (const auto& s : split(seeds_arg)) seeds.push_back(std::stoi(s));
  const auto only = split(rules_arg);
  const std::vector<Rule> all = rules();
  std::vector<const Rule*> chosen;
  for (const Rule& r : all)
    if (only.empty() || r.name == "default" || r.name == "flats" ||
        std::find(only.begin(), only.end(), r.name) != only.end())
      chosen.push_back(&r);
  const auto cases = split(cases_arg);
  // figures[rule][case]
  std::vector<std::vector<Figures>> figures(chosen.size(), std::vector<Figures>(cases.size()));
  for (size_t ci = 0; ci < cases.size(); ++ci)
    for (int seed : seeds) {
      const Case c = make_case(cases[ci], res, seed, data);
      for (size_t ri = 0; ri < chosen.size(); ++ri) {
        SurfaceOptions so;
        if (chosen[ri]->off) so.passes.disable(*chosen[ri]->off);
        const SurfaceResult r = smooth_surface(c.volume, so);
        EvalOptions eo;
        eo.volume = &c.volume;
        eo.samples = 100000;
        const EvalReport e = evaluate(r.mesh, *c.truth, eo);
        Figures& f = figures[ri][ci];
        ++f.runs;
        f.rms += e.result_to_truth_vox.rms;
        f.normal += e.normal_error_deg;
        f.labelled += double(e.labelled_sharp_edges);
        if (e.sharp_edge_hausdorff_vox) f.sharp_h += *e.sharp_edge_hausdorff_vox, ++f.sharp_runs;
        if (e.sharp_recall) f.recall += *e.sharp_recall, ++f.recall_runs;
        if (e.sharp_precision) f.precision += *e.sharp_precision, ++f.precision_runs;
        const MeshCheck mc = check_mesh(r.mesh);
        const uint64_t violations = e.classification_violations.value_or(0);
        if (!mc.ok() || violations)
          f.failures.push_back(cases[ci] + " seed " + std::to_string(seed) + ": " +
                               (mc.ok() ? std::to_string(violations) + " violations" : mc.problems[0]));
        std::fprintf(stderr, "%s seed %d %s: r->t %.4f\n", cases[ci].c_str(), seed, chosen[ri]->name.c_str(),
                     e.result_to_truth_vox.rms);
      }
    }
  if (decision) {
    print_decision(res, seeds_arg, cases, figures);
  } else {
    print_ablation(res, seeds_arg, cases, chosen, figures);
  }
  bool ok = true;
  for (size_t ri = 0; ri < chosen.size(); ++ri)
    for (const auto& fs : figures[ri])
      for (const auto& msg : fs.failures) std::printf("CHECK FAILED (%s): %s\n", chosen[ri]->name.c_str(), msg.c_str()), ok = false;
  return ok ? 0 : 1;
}
