// voxpress extract IN -o OUT: the midpoint (stick) surface.
#include "common.h"

namespace voxpress::cli {
namespace {

struct ExtractCmd {
  std::string input, output, stats_json;
  InputOptions in;
  bool ascii = false, check = false;
};

void run_extract(const ExtractCmd& c, const Global& g) {
  mesh_format_from_path(c.output);  // fail on a bad extension before any work
  Stopwatch clock;
  const BinaryVolume volume = load_binary(c.input, c.in, g);
  const double t_read = clock.seconds();
  ProgressBar bar(!g.quiet);
  ExtractOptions eo;
  eo.progress = bar.get();
  eo.max_bytes = g.memory_limit();
  ExtractStats st;
  const StickSurface surface = extract_sticks(volume, eo, &st);
  const Mesh mesh = to_mesh(surface);
  const double t_extract = clock.seconds();
  const nlohmann::json checks = c.check ? check_surface(mesh, volume, bar.get(), "extracted") : nlohmann::json();
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  write_mesh(c.output, mesh, wo);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu vertices, %zu triangles\n", c.output.c_str(), mesh.vertex_count(), mesh.face_count());
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "extract";
    j["input"] = c.input;
    j["output"] = c.output;
    j["lattice"] = lattice_json(volume.lattice);
    j["counts"] = {{"samples", st.samples}, {"sticks", st.sticks}, {"vertices", mesh.vertex_count()},
                   {"triangles", mesh.face_count()}};
    j["seconds"] = {{"read", t_read},
                    {"sticks", st.seconds_sticks},
                    {"triangles", st.seconds_triangles},
                    {"extract_total", t_extract - t_read},
                    {"total", clock.seconds()}};
    j["peak_memory_bytes"] = peak_rss_bytes();
    if (c.check) j["checks"] = checks;
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_extract(CLI::App& app, Global& g) {
  auto c = std::make_shared<ExtractCmd>();
  auto* cmd = app.add_subcommand("extract", "Extract the midpoint (stick) surface of a volume");
  cmd->add_option("input", c->input, "Volume file (or folder of TIFF slices)")->required();
  cmd->add_option("-o,--output", c->output, "Output mesh (.ply .obj .stl .off .glb .gltf)")->required();
  c->in.bind(*cmd);
  cmd->add_flag("--ascii", c->ascii, "ASCII PLY instead of binary");
  cmd->add_flag("--check", c->check, "Verify the mesh (check_mesh + classification) before writing");
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_extract(*c, g);
  });
}

}  // namespace voxpress::cli
