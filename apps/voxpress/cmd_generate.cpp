// voxpress generate SHAPE --res N [--rotate random:SEED | AX,AY,AZ] [--spacing SX,SY,SZ] -o OUT
#include "common.h"
#include "voxpress/eval/truth.h"

namespace voxpress::cli {
namespace {

struct GenerateCmd {
  std::string shape, output, rotate = "none", spacing = "1,1,1", stats_json;
  int64_t res = 64, margin = 2;
};

void run_generate(const GenerateCmd& c, const Global& g) {
  Stopwatch clock;
  const ShapeKind kind = parse_shape(c.shape);
  GenerateOptions o;
  o.res = c.res;
  o.margin = c.margin;
  o.rotation = parse_rotation(c.rotate);
  o.spacing = parse_vec3(c.spacing, "--spacing");
  o.max_bytes = g.memory_limit();
  ProgressBar bar(!g.quiet);
  o.progress = bar.get();
  const GeneratedShape s = generate_shape(kind, o);
  ScalarVolume v = to_scalar(s.volume);
  v.metadata[kShapeKey] = shape_name(kind);
  v.metadata[kModelToPhysicalKey] = format_transform(s.linear, s.translation);
  v.metadata["voxpress_rotate"] = c.rotate;
  write_volume(c.output, v);
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "generate";
    j["shape"] = shape_name(kind);
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
  cmd->add_option("-o,--output", c->output, "Output volume (.nrrd, .nii.gz, .mha, .tif)")->required();
  cmd->add_option("--res", c->res, "Samples along the physically longest side")->capture_default_str();
  cmd->add_option("--rotate", c->rotate, "random:SEED, AX,AY,AZ in degrees, or none")->capture_default_str();
  cmd->add_option("--spacing", c->spacing, "Cell size SX,SY,SZ (anisotropic lattices)")->capture_default_str();
  cmd->add_option("--margin", c->margin, "Outside samples around the shape")->capture_default_str();
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_generate(*c, g);
  });
}

}  // namespace voxpress::cli
