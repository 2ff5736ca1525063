// voxpress extract IN -o OUT: the midpoint (stick) surface; with --labels,
// every label of a label map in one surface whose interfaces are shared
// (labels/shared_surface.h), the two labels of each triangle as face
// attributes.
#include "common.h"

namespace voxpress::cli {
namespace {

struct ExtractCmd {
  std::string input, output, stats_json;
  InputOptions in;
  bool ascii = false, check = false, labels = false;
  SimplifyOptions simplify;  ///< --faces, --max-error
};

// --labels: the shared surface; --check checks every label's closed surface.
void run_extract_labels(const ExtractCmd& c, const Global& g) {
  Stopwatch clock;
  ProgressBar bar(!g.quiet);
  const ScalarVolume volume = load_volume(c.input, c.in, g);
  const double t_read = clock.seconds();
  SharedSurface s = extract_shared_surface(volume);
  const double t_extract = clock.seconds() - t_read;
  const bool simplifying = c.simplify.faces || c.simplify.max_error;
  SimplifyStats simplified;
  if (simplifying) {
    SimplifyOptions so = c.simplify;
    so.progress = bar.get();
    simplified = simplify_shared(s, so);
  }
  nlohmann::json checks = nlohmann::json::array();
  if (c.check)
    for (uint32_t L = 1; L < s.labels.size(); ++L) {
      Selection sel;
      sel.kind = Selection::Kind::label;
      sel.value = double(s.labels[L]);
      nlohmann::json j = check_surface(label_mesh(s, L), binarize(volume, sel), bar.get(),
                                       "label " + std::to_string(s.labels[L]));
      j["label"] = s.labels[L];
      checks.push_back(j);
    }
  const Mesh mesh = interfaces_mesh(s);
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  wo.space = volume.lattice.space;
  write_mesh(c.output, mesh, wo);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu labels, %zu vertices (%llu on face centres, %llu inside cubes), %zu triangles\n",
                 c.output.c_str(), s.labels.size() - 1, mesh.vertex_count(), (unsigned long long)s.face_vertices,
                 (unsigned long long)s.apex_vertices, mesh.face_count());
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "extract --labels";
    j["input"] = c.input;
    j["output"] = c.output;
    j["labels"] = s.labels.size() - 1;
    j["vertices"] = {{"sticks", s.stick_vertices}, {"face_centres", s.face_vertices}, {"apexes", s.apex_vertices}};
    j["triangles"] = mesh.face_count();
    j["seconds"] = {{"read", t_read}, {"extract", t_extract}, {"total", clock.seconds()}};
    if (simplifying) j["simplify"] = simplify_stats_json(simplified, c.simplify);
    j["peak_memory_bytes"] = peak_rss_bytes();
    if (c.check) j["checks"] = checks;
    write_json(c.stats_json, j);
  }
}

void run_extract(const ExtractCmd& c, const Global& g) {
  check_paths({c.input}, {{c.output, OutputKind::mesh}, {c.stats_json, OutputKind::json}});

  mesh_format_from_path(c.output);  // fail on a bad extension before any work
  const bool simplifying = c.simplify.faces || c.simplify.max_error;
  if (c.labels) return run_extract_labels(c, g);
  Stopwatch clock;
  ProgressBar bar(!g.quiet);
  const VolumeSurface vs = load_surface(c.input, c.in, g, bar.get());
  Mesh mesh = to_mesh(vs.surface);
  const double t_extract = clock.seconds();
  SimplifyStats simplified;
  if (simplifying) {
    SimplifyOptions so = c.simplify;
    so.lattice = &vs.volume.lattice;
    so.progress = bar.get();
    simplified = simplify(mesh, so);
  }
  const nlohmann::json checks = c.check ? check_surface(mesh, vs.volume, bar.get(), "extracted") : nlohmann::json();
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  wo.space = vs.volume.lattice.space;
  write_mesh(c.output, mesh, wo);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu vertices, %zu triangles\n", c.output.c_str(), mesh.vertex_count(), mesh.face_count());
  if (!c.stats_json.empty()) {
    nlohmann::json j = surface_stats_json("extract", c.input, c.output, vs.volume.lattice, vs.stats, mesh);
    j["seconds"] = {{"read", vs.seconds_read},
                    {"sticks", vs.stats.seconds_sticks},
                    {"triangles", vs.stats.seconds_triangles},
                    {"extract_total", t_extract - vs.seconds_read},
                    {"total", clock.seconds()}};
    if (simplifying) j["simplify"] = simplify_stats_json(simplified, c.simplify);
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
  cmd->add_flag("--labels", c->labels,
                "Every label of a label map in one surface, each interface shared by its two labels "
                "(face attributes label_in, label_out; PLY keeps them)");
  bind_simplify(*cmd, c->simplify);
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_extract(*c, g);
  });
}

}  // namespace voxpress::cli
