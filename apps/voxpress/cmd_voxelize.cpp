// voxpress voxelize MODEL --res N [--rotate random:SEED | AX,AY,AZ] [--margin M] -o OUT
#include <filesystem>

#include "common.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"

namespace voxpress::cli {
namespace {

struct VoxelizeCmd {
  std::string model, output, stats_json;
  PlacementCli place{128};
};

void run_voxelize(const VoxelizeCmd& c, const Global& g) {
  check_paths({c.model}, {{c.output, OutputKind::volume}, {c.stats_json, OutputKind::json}});

  Stopwatch clock;
  const Mesh model = read_mesh(c.model, {g.memory_limit()});
  VoxelizeOptions o;
  ProgressBar bar(!g.quiet);
  c.place.apply(o, g, bar.get());
  const Voxelized v = voxelize(model, o, c.model);
  ScalarVolume out = to_scalar(v.volume);
  out.metadata[kTruthMeshKey] = std::filesystem::absolute(c.model).lexically_normal().string();
  out.metadata[kModelToPhysicalKey] = format_transform(v.placement.linear, v.placement.translation);
  out.metadata["voxpress_rotate"] = c.place.rotate;
  write_volume(c.output, out);
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "voxelize";
    j["model"] = c.model;
    j["output"] = c.output;
    j["model_faces"] = model.triangles.size();
    j["lattice"] = lattice_json(v.volume.lattice);
    j["inside_samples"] = v.volume.count_inside();
    j["seconds"] = clock.seconds();
    j["peak_memory_bytes"] = peak_rss_bytes();
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_voxelize(CLI::App& app, Global& g) {
  auto c = std::make_shared<VoxelizeCmd>();
  auto* cmd = app.add_subcommand("voxelize", "Sample a closed mesh exactly onto a lattice (writes a volume that "
                                             "remembers its model and placement, for `voxpress eval`)");
  cmd->add_option("model", c->model, "Closed triangle mesh (.off .obj .stl .ply)")->required();
  cmd->add_option("-o,--output", c->output, "Output volume (.nrrd, .nii.gz, .mha, .tif, .h5)")->required();
  c->place.bind(*cmd, "model");
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_voxelize(*c, g);
  });
}

}  // namespace voxpress::cli
