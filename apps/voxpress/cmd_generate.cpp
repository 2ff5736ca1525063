// voxpress generate SHAPE --res N [--rotate random:SEED | AX,AY,AZ] [--spacing SX,SY,SZ] [--fillet R] -o OUT
#include "common.h"
#include "voxpress/eval/truth.h"

namespace voxpress::cli {
namespace {

struct GenerateCmd {
  std::string shape, output, stats_json;
  PlacementCli place{64};
  double fillet = 0;
};

void run_generate(const GenerateCmd& c, const Global& g) {
  check_paths({}, {{c.output, OutputKind::volume}, {c.stats_json, OutputKind::json}});

  Stopwatch clock;
  const ShapeKind kind = parse_shape(c.shape);
  GenerateOptions o;
  ProgressBar bar(!g.quiet);
  c.place.apply(o, g, bar.get());
  o.fillet = c.fillet;
  const GeneratedShape s = generate_shape(kind, o);
  ScalarVolume v = to_scalar(s.volume);
  v.metadata[kShapeKey] = shape_name(kind);
  v.metadata[kModelToPhysicalKey] = format_transform(s.linear, s.translation);
  v.metadata["voxpress_rotate"] = c.place.rotate;
  if (s.fillet > 0) {
    char radius[40];
    std::snprintf(radius, sizeof radius, "%.17g", s.fillet);
    v.metadata[kFilletKey] = radius;  // model units: `eval` knows the rounded truth
  }
  write_volume(c.output, v);
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "generate";
    j["shape"] = shape_name(kind);
    j["fillet_cells"] = c.fillet;
    j["output"] = c.output;
    j["lattice"] = lattice_json(s.volume.lattice);
    j["inside_samples"] = s.volume.count_inside();
    j["seconds"] = clock.seconds();
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_generate(CLI::App& app, Global& g) {
  auto c = std::make_shared<GenerateCmd>();
  auto* cmd = app.add_subcommand("generate", "Sample an analytic solid exactly onto a lattice (writes a volume)");
  cmd->add_option("shape", c->shape, "sphere | torus | box | cylinder | cad-part")->required();
  cmd->add_option("-o,--output", c->output, "Output volume (.nrrd, .nii.gz, .mha, .tif, .h5)")->required();
  c->place.bind(*cmd, "shape");
  cmd->add_option("--fillet", c->fillet,
                  "Box or cylinder: round its edges (and corners) with this radius in cells (of the smallest "
                  "spacing; 0 = sharp). `eval` knows the rounded truth, which has no sharp edges")
      ->capture_default_str();
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_generate(*c, g);
  });
}

}  // namespace voxpress::cli
