// voxpress press IN -o OUT: the midpoint surface smoothed by Pressing.
#include <cstdio>

#include "common.h"

namespace voxpress::cli {
namespace {

struct PressCmd {
  std::string input, output, stats_json;
  InputOptions in;
  PressCli smooth;
  bool ascii = false, check = false;
};

void run_press(const PressCmd& c, const Global& g) {
  mesh_format_from_path(c.output);  // a bad extension fails before any work
  const PressOptions po = c.smooth.resolve();
  Stopwatch clock;
  const BinaryVolume volume = load_binary(c.input, c.in, g);
  const double t_read = clock.seconds();
  ProgressBar bar(!g.quiet);
  ExtractOptions eo;
  eo.progress = bar.get();
  eo.max_bytes = g.memory_limit();
  ExtractStats es;
  StickSurface surface = extract_sticks(volume, eo, &es);
  const double t_extract = clock.seconds();
  PressOptions o = po;
  o.progress = bar.get();
  const PressStats ps = press(surface, o);
  const Mesh mesh = to_mesh(surface);
  const nlohmann::json checks = c.check ? check_surface(mesh, volume, bar.get(), "pressed") : nlohmann::json();
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  write_mesh(c.output, mesh, wo);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu vertices, %zu triangles, %d iterations (last max change %.2g)\n", c.output.c_str(),
                 mesh.vertex_count(), mesh.face_count(), ps.iterations, ps.last_max_change);
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "press";
    j["method"] = "pressing";
    j["input"] = c.input;
    j["output"] = c.output;
    j["lattice"] = lattice_json(volume.lattice);
    j["counts"] = {{"samples", es.samples}, {"sticks", es.sticks}, {"vertices", mesh.vertex_count()},
                   {"triangles", mesh.face_count()}};
    j["pressing"] = press_stats_json(ps, po);
    j["seconds"] = {{"read", t_read}, {"extract", t_extract - t_read}, {"press", ps.seconds}, {"total", clock.seconds()}};
    j["peak_memory_bytes"] = peak_rss_bytes();
    if (c.check) j["checks"] = checks;
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_press(CLI::App& app, Global& g) {
  auto c = std::make_shared<PressCmd>();
  auto* cmd = app.add_subcommand("press", "Smooth surface of a volume: Pressing (vertices slide along their sticks, "
                                          "so no sample changes side)");
  cmd->add_option("input", c->input, "Volume file (or folder of TIFF slices)")->required();
  cmd->add_option("-o,--output", c->output, "Output mesh (.ply .obj .stl .off .glb .gltf)")->required();
  c->in.bind(*cmd);
  c->smooth.bind(*cmd);
  cmd->add_flag("--ascii", c->ascii, "ASCII PLY instead of binary");
  cmd->add_flag("--check", c->check, "Verify the mesh (check_mesh + classification) before writing");
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_press(*c, g);
  });
}

}  // namespace voxpress::cli
