// One table-driven ablation of the feature layer: every rule beyond the
// paper switched off alone (and the whole layer off), on CAD, freeform and
// organic cases over several rotations, against the default press. It
// replaces the per-rule tests that compared one rule on and off on a seed or
// two (their claims are figures, and figures belong here, not in ctest).
//   build/bench/bench_ablation                       # the table in docs/BENCHMARKS.md
//   build/bench/bench_ablation --seeds 1,2,3 --res 128 --rules past_crease,snap
//   build/bench/bench_ablation --cases cad-part,fandisk
// Columns per case: result -> truth RMS (voxels), mean normal error
// (degrees), sharp-edge Hausdorff (voxels, true <-> labelled, where the
// truth has sharp edges) and labelled sharp edges, each the mean over the
// seeds; every run is also checked (closed, manifold, oriented, no
// self-intersection, 0 violations) and a failure is printed.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

struct Rule {
  const char* name;
  const char* what;
  std::function<void(SurfaceOptions&)> off;
};

// Every public switch of a rule beyond the paper, and the layers as a whole.
const std::vector<Rule>& rules() {
  static const std::vector<Rule> r = {
      {"default", "every rule on", [](SurfaceOptions&) {}},
      {"no-flats", "the whole feature layer off (--no-flats)", [](SurfaceOptions& o) { o.flats = false; }},
      {"no-sharpen", "flats, no sharpening (--no-sharpen)", [](SurfaceOptions& o) { o.sharpen = false; }},
      {"stab_refit", "flats: core planes refit by stabbed sticks", [](SurfaceOptions& o) { o.flat.stab_refit = false; }},
      {"crease_refit", "flats: planes refit along their creases", [](SurfaceOptions& o) { o.flat.crease_refit = false; }},
      {"center_planes", "flats: centred planes", [](SurfaceOptions& o) { o.flat.center_planes = false; }},
      {"crease_rounds", "flats: curved side placed by its quadric", [](SurfaceOptions& o) { o.flat.crease_rounds = 0; }},
      {"rim_tangent", "flats: the rim leaves tangent fillets", [](SurfaceOptions& o) { o.flat.rim_tangent_angle = 0; }},
      {"ring_off_plane", "flats: junction test without the stopped rim",
       [](SurfaceOptions& o) { o.flat.junction_ring_off_plane = 0; }},
      {"curved_creases", "creases between curved faces",
       [](SurfaceOptions& o) { o.flat.curved_creases = o.sharp.curved_creases = false; }},
      {"free_ends", "pressing: open curve pieces at barriers", [](SurfaceOptions& o) { o.press.free_ends = false; }},
      {"snap", "sharpen: bands snapped onto the flats", [](SurfaceOptions& o) { o.sharp.snap_rings = 0; }},
      {"strips", "sharpen: thin strips join a flat", [](SurfaceOptions& o) { o.sharp.strip_rings = 0; }},
      {"rim_pockets", "sharpen: rim pockets stay curved", [](SurfaceOptions& o) { o.sharp.rim_pockets = false; }},
      {"tangent_plane", "sharpen: curved side's quadric tangent plane",
       [](SurfaceOptions& o) { o.sharp.curved_fit_rings = 0; }},
      {"walls", "sharpen: thin walls get their own plane", [](SurfaceOptions& o) { o.sharp.wall_thickness = 0; }},
      {"final_crease", "sharpen: final crease fit", [](SurfaceOptions& o) { o.sharp.final_crease_rings = 0; }},
      {"past_crease", "sharpen: vertices past the crease change sides",
       [](SurfaceOptions& o) { o.sharp.past_crease = false; }},
      {"inherit_junctions", "sharpen: joined junctions pass the border on",
       [](SurfaceOptions& o) { o.sharp.inherit_junctions = false; }},
      {"on_plane_bands", "sharpen: on-plane bands join their flat",
       [](SurfaceOptions& o) { o.sharp.on_plane_bands = false; }},
      {"sample_wedges", "sharpen: chamfer planes agree with their samples",
       [](SurfaceOptions& o) { o.sharp.sample_wedges = false; }},
      {"retry_right_angle", "sharpen: right-angle crease moves retried",
       [](SurfaceOptions& o) { o.sharp.retry_right_angle = -1; }},
  };
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
  double rms = 0, normal = 0, sharp_h = 0, labelled = 0;
  int sharp_runs = 0, runs = 0;
  std::vector<std::string> failures;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string w; std::getline(in, w, ',');)
    if (!w.empty()) out.push_back(w);
  return out;
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
  app.add_option("--rules", rules_arg, "Only these rules (default and no-flats always run)");
  app.add_option("--data", data, "The shared data folder")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::vector<int> seeds;
  for (const auto& s : split(seeds_arg)) seeds.push_back(std::stoi(s));
  const auto only = split(rules_arg);
  std::vector<const Rule*> chosen;
  for (const Rule& r : rules())
    if (only.empty() || std::string(r.name) == "default" || std::string(r.name) == "no-flats" ||
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
        chosen[ri]->off(so);
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
        const MeshCheck mc = check_mesh(r.mesh);
        const uint64_t violations = e.classification_violations.value_or(0);
        if (!mc.ok() || violations)
          f.failures.push_back(cases[ci] + " seed " + std::to_string(seed) + ": " +
                               (mc.ok() ? std::to_string(violations) + " violations" : mc.problems[0]));
        std::fprintf(stderr, "%s seed %d %s: r->t %.4f\n", cases[ci].c_str(), seed, chosen[ri]->name,
                     e.result_to_truth_vox.rms);
      }
    }
  std::printf("res %ld, seeds %s; per case: r->t RMS (vox) / normal error (deg) / sharp H (vox) / labelled sharp "
              "edges, means over the seeds; [x%%]: r->t RMS change against the default\n\n| rule | off |",
              long(res), seeds_arg.c_str());
  for (const auto& c : cases) std::printf(" %s |", c.c_str());
  std::printf("\n|---|---|");
  for (size_t i = 0; i < cases.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (size_t ri = 0; ri < chosen.size(); ++ri) {
    std::printf("| %s | %s |", chosen[ri]->name, chosen[ri]->what);
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
  bool ok = true;
  for (size_t ri = 0; ri < chosen.size(); ++ri)
    for (const auto& fs : figures[ri])
      for (const auto& msg : fs.failures) std::printf("CHECK FAILED (%s): %s\n", chosen[ri]->name, msg.c_str()), ok = false;
  return ok ? 0 : 1;
}
