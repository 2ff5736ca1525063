// voxpress eval RESULT [--truth SHAPE|MESH] [--volume VOL] [--json FILE]
#include <cstdio>

#include "common.h"
#include "voxpress/core/memory_budget.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"

namespace voxpress::cli {
namespace {

struct EvalCmd {
  std::string result, truth, volume, json;
  InputOptions in;
  size_t samples = 400000;
  uint64_t seed = 1;
  double sharp_match = 0.5;
  bool no_self_intersections = false;
  bool quadrature = false;
};

nlohmann::json stats_json(const DistanceStats& s) {
  return {{"rms", s.rms}, {"mean", s.mean}, {"max", s.max}, {"samples", s.count}};
}

void run_eval(const EvalCmd& c, const Global& g) {
  check_paths({c.result, c.truth, c.volume}, {{c.json, OutputKind::json}});

  Stopwatch clock;
  const Mesh result = read_mesh(c.result, {g.memory_limit()});
  std::optional<ScalarVolume> raw;
  std::optional<BinaryVolume> vol;
  if (!c.volume.empty()) {
    raw = load_volume(c.volume, c.in, g);
    vol = binarize(*raw, c.in.selection());
  }
  // The result's measuring and the volume with its mask (memory_budget.h);
  // a truth mesh is charged when it is read.
  const uint64_t need = result.triangles.size() * kEvalBytesPerResultFace + (raw ? raw->bytes.size() + vol->inside.size() : 0);
  charge_memory(c.result, need, g.memory_limit(),
                "measuring its " + std::to_string(result.triangles.size()) + " faces (" +
                    std::to_string(kEvalBytesPerResultFace) + " bytes each, with the volume)");
  const auto truth = resolve_truth(c.truth, raw ? &*raw : nullptr);
  EvalOptions o;
  o.samples = c.samples;
  o.seed = c.seed;
  o.sharp_match_vox = c.sharp_match;
  o.volume = vol ? &*vol : nullptr;
  o.self_intersections = !c.no_self_intersections;
  o.quadrature = c.quadrature;
  ProgressBar bar(!g.quiet);
  o.progress = bar.get();
  const EvalReport r = evaluate(result, *truth, o);

  auto fmt = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4f", v);
    return std::string(b);
  };
  const bool vox = vol.has_value();
  std::printf("result      %s: %zu vertices, %zu faces\n", c.result.c_str(), r.vertices, r.faces);
  std::printf("truth       %s\n", r.truth.c_str());
  std::printf("%-34s %12s %12s\n", "", vox ? "voxels" : "", "physical");
  auto row = [&](const char* name, std::optional<double> v_vox, double v_phys) {
    std::printf("%-34s %12s %12s\n", name, v_vox ? fmt(*v_vox).c_str() : (vox ? "n/a" : ""), fmt(v_phys).c_str());
  };
  if (vox) {
    if (r.stick_rms_vox)
      std::printf("%-34s %12s %12s   (%zu of %zu vertices on sticks)\n", "stick error RMS (Pressing Table 2)",
                  fmt(*r.stick_rms_vox).c_str(), fmt(*r.stick_rms).c_str(), r.stick_vertices, r.vertices);
    else
      std::printf("%-34s %12s %12s   (no vertex lies on a stick)\n", "stick error RMS (Pressing Table 2)", "n/a", "n/a");
  }
  auto v = [&](const DistanceStats& s, double DistanceStats::*f) { return vox ? std::optional<double>(s.*f) : std::nullopt; };
  row("result -> truth RMS", v(r.result_to_truth_vox, &DistanceStats::rms), r.result_to_truth.rms);
  if (r.result_to_truth_rule_rms)
    row("result -> truth RMS (7-point rule)", r.result_to_truth_rule_rms_vox, *r.result_to_truth_rule_rms);
  row("result -> truth mean", v(r.result_to_truth_vox, &DistanceStats::mean), r.result_to_truth.mean);
  row("result -> truth max", v(r.result_to_truth_vox, &DistanceStats::max), r.result_to_truth.max);
  row("truth -> result RMS", v(r.truth_to_result_vox, &DistanceStats::rms), r.truth_to_result.rms);
  row("truth -> result mean", v(r.truth_to_result_vox, &DistanceStats::mean), r.truth_to_result.mean);
  row("truth -> result max", v(r.truth_to_result_vox, &DistanceStats::max), r.truth_to_result.max);
  row("Hausdorff (symmetric)", r.hausdorff_vox, r.hausdorff);
  std::printf("%-34s %12s degrees\n", "normal error (area-weighted mean)", fmt(r.normal_error_deg).c_str());
  std::printf("%-34s %12s\n", "volume ratio result / truth", fmt(r.volume_ratio).c_str());
  if (r.classification_violations)
    std::printf("%-34s %12lu\n", "classification violations", (unsigned long)*r.classification_violations);
  std::printf("%-34s %12s\n", "mesh check", r.mesh.ok() ? "OK" : r.mesh.problems[0].c_str());
  if (r.sharp_edge_hausdorff) {
    row("sharp edges true -> labelled max", r.sharp_true_to_labelled_vox, *r.sharp_true_to_labelled);
    row("sharp edges labelled -> true max", r.sharp_labelled_to_true_vox, *r.sharp_labelled_to_true);
    row("sharp edges Hausdorff", r.sharp_edge_hausdorff_vox, *r.sharp_edge_hausdorff);
  } else {
    std::printf("%-34s %12s   (%zu true sharp-edge segments, %zu labelled)\n", "sharp edges Hausdorff", "n/a",
                r.true_sharp_edges, r.labelled_sharp_edges);
  }
  if (r.sharp_recall)
    std::printf("%-34s %11.1f %%  (of the true sharp curves' length, within %g voxel of a labelled one)\n",
                "sharp edges recall", 100 * *r.sharp_recall, o.sharp_match_vox);
  if (r.sharp_precision)
    std::printf("%-34s %11.1f %%  (of the labelled curves' length, within %g voxel of a true one)\n",
                "sharp edges precision", 100 * *r.sharp_precision, o.sharp_match_vox);

  if (!c.json.empty()) {
    nlohmann::json j;
    j["result"] = c.result;
    j["truth"] = r.truth;
    j["vertices"] = r.vertices;
    j["faces"] = r.faces;
    j["samples_per_direction"] = c.samples;
    j["physical"] = {{"result_to_truth", stats_json(r.result_to_truth)},
                     {"truth_to_result", stats_json(r.truth_to_result)},
                     {"hausdorff", r.hausdorff}};
    if (r.stick_rms) j["physical"]["stick_rms"] = *r.stick_rms;
    if (r.result_to_truth_rule_rms) j["physical"]["result_to_truth_rule_rms"] = *r.result_to_truth_rule_rms;
    if (vox) {
      j["voxels"] = {{"result_to_truth", stats_json(r.result_to_truth_vox)},
                     {"truth_to_result", stats_json(r.truth_to_result_vox)},
                     {"hausdorff", *r.hausdorff_vox}};
      if (r.stick_rms_vox) {
        j["voxels"]["stick_rms"] = *r.stick_rms_vox;
        j["voxels"]["stick_max"] = *r.stick_max_vox;
      }
      if (r.result_to_truth_rule_rms_vox) j["voxels"]["result_to_truth_rule_rms"] = *r.result_to_truth_rule_rms_vox;
      j["stick_vertices"] = r.stick_vertices;
      j["classification_violations"] = *r.classification_violations;
    }
    j["normal_error_deg"] = r.normal_error_deg;
    j["volume_ratio"] = r.volume_ratio;
    j["mesh_ok"] = r.mesh.ok();
    j["mesh_problems"] = r.mesh.problems;
    j["true_sharp_edge_segments"] = r.true_sharp_edges;
    j["labelled_sharp_edges"] = r.labelled_sharp_edges;
    auto opt = [](const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); };
    j["sharp_edges"] = {{"physical", {{"true_to_labelled", opt(r.sharp_true_to_labelled)},
                                      {"labelled_to_true", opt(r.sharp_labelled_to_true)},
                                      {"hausdorff", opt(r.sharp_edge_hausdorff)}}},
                        {"voxels", {{"true_to_labelled", opt(r.sharp_true_to_labelled_vox)},
                                    {"labelled_to_true", opt(r.sharp_labelled_to_true_vox)},
                                    {"hausdorff", opt(r.sharp_edge_hausdorff_vox)},
                                    {"recall", opt(r.sharp_recall)},
                                    {"precision", opt(r.sharp_precision)},
                                    {"match", o.sharp_match_vox}}}};
    j["seconds"] = clock.seconds();
    write_json(c.json, j);
  }
}

}  // namespace

void register_eval(CLI::App& app, Global& g) {
  auto c = std::make_shared<EvalCmd>();
  auto* cmd = app.add_subcommand("eval", "Measure a result mesh against the true solid (stick error, distances both "
                                         "ways, Hausdorff, normals, volume, guarantees)");
  cmd->add_option("result", c->result, "Result mesh (.ply .obj .stl .off)")->required();
  cmd->add_option("--truth", c->truth, "sphere|torus|box|cylinder|cad-part, or a mesh file; default: what --volume "
                                       "records (voxpress generate / voxelize)");
  cmd->add_option("--volume", c->volume, "The volume the result came from: placement of the truth, stick metric, "
                                         "voxel units, classification");
  c->in.bind(*cmd);
  cmd->add_option("--json", c->json, "Also write the report as JSON");
  cmd->add_option("--samples", c->samples, "Area samples per direction")
      ->check(CLI::Range(size_t(1), size_t(100000000)))
      ->capture_default_str();
  cmd->add_option("--seed", c->seed, "Sampling seed")->capture_default_str();
  cmd->add_option("--sharp-match", c->sharp_match,
                  "Voxels: a sharp curve point this close to the other set counts as found (recall, precision)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_flag("--no-self-intersections", c->no_self_intersections, "Skip the self-intersection test");
  cmd->add_flag("--quadrature", c->quadrature,
                "Also result -> truth RMS by a 7-point rule on every triangle: unlike the samples, it moves only "
                "where two meshes differ (for comparing nearly equal results)");
  cmd->callback([c, &g] {
    g.apply();
    run_eval(*c, g);
  });
}

}  // namespace voxpress::cli
