// voxpress smooth-mesh IN -o OUT: smooth a staircase (marching-cubes) mesh
// without its volume (Bade et al.), or with Taubin / Laplacian.
#include <cstdio>

#include "common.h"

namespace voxpress::cli {
namespace {

struct SmoothMeshCmd {
  std::string input, output, stats_json;
  std::string method = "constrained", constraint = "diamond";
  MethodOverrides overrides;
  SimplifyOptions simplify;  ///< --faces, --max-error
  bool ascii = false;
  CLI::Option* constraint_option = nullptr;
};

void run_smooth_mesh(const SmoothMeshCmd& c, const Global& g) {
  check_paths({c.input}, {{c.output, OutputKind::mesh}, {c.stats_json, OutputKind::json}});

  mesh_format_from_path(c.output);  // a bad extension fails before any work
  const std::optional<FairOptions::Kind> kind = fair_kind(c.method);
  if (!kind && c.method != "constrained")
    throw UsageError("--method must be constrained, taubin or laplacian (got '" + c.method + "')");
  const MeshConstraint constraint = parse_constraint(c.constraint);
  if (kind && c.constraint_option->count()) throw UsageError("--constraint applies to --method constrained only");
  if (!kind && (c.overrides.lambda || c.overrides.mu)) throw UsageError("--lambda and --mu apply to taubin and laplacian only");
  Stopwatch clock;
  ProgressBar bar(!g.quiet);
  MeshReadOptions ro;
  ro.max_bytes = g.memory_limit();
  Mesh mesh = read_mesh(c.input, ro);
  const double seconds_read = clock.seconds();
  nlohmann::json j;
  j["command"] = "smooth-mesh";
  j["input"] = c.input;
  j["output"] = c.output;
  SmoothStats st;
  double seconds_recover = 0;
  std::optional<Lattice> lattice;  // the recovered one: its samples keep their side when simplifying
  if (kind) {
    if (mesh.triangles.empty()) throw InputError(c.input, "the mesh has no triangles");
    FairOptions fo = fair_defaults(*kind);
    c.overrides.apply(fo);
    fo.progress = bar.get();
    st = fair(mesh, fo);
    j["method"] = c.method;
  } else {
    LatticeMesh lm = recover_lattice(std::move(mesh), c.input);
    seconds_recover = clock.seconds() - seconds_read;
    ConstrainedOptions co;
    co.constraint = constraint;
    c.overrides.apply(co);
    co.progress = bar.get();
    st = constrained_smooth(lm, co);
    mesh = std::move(lm.mesh);
    lattice = lm.lattice;
    j["method"] = "constrained";
    j["constraint"] = constraint_name(constraint);
    j["recovered_lattice"] = lattice_json(lm.lattice);
    j["recovered_lattice"]["misfit_cells"] = lm.misfit;
  }
  if (c.simplify.faces || c.simplify.max_error) {
    SimplifyOptions so = c.simplify;
    so.lattice = lattice ? &*lattice : nullptr;  // taubin / laplacian: no lattice, no samples to keep
    so.progress = bar.get();
    j["simplify"] = simplify_stats_json(simplify(mesh, so), c.simplify);
  }
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  write_mesh(c.output, mesh, wo);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu vertices, %zu triangles, %s%s, %d iterations%s\n", c.output.c_str(),
                 mesh.vertex_count(), mesh.face_count(), c.method.c_str(),
                 kind ? "" : (std::string(" ") + constraint_name(constraint)).c_str(), st.iterations,
                 kind || st.converged ? "" : " (iteration cap reached)");
  if (!c.stats_json.empty()) {
    j["counts"] = {{"vertices", mesh.vertex_count()}, {"triangles", mesh.face_count()}};
    j["smoothing"] = smooth_stats_json(st);
    j["seconds"] = {{"read", seconds_read}, {"recover", seconds_recover}, {"smooth", st.seconds}, {"total", clock.seconds()}};
    j["peak_memory_bytes"] = peak_rss_bytes();
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_smooth_mesh(CLI::App& app, Global& g) {
  auto c = std::make_shared<SmoothMeshCmd>();
  auto* cmd = app.add_subcommand(
      "smooth-mesh",
      "Smooth a marching-cubes mesh without its volume (Bade et al.): the lattice is read back from the mesh and "
      "every vertex is kept in its cell-size box, on its cell edge, or in its diamond");
  cmd->add_option("input", c->input, "Marching-cubes mesh (.ply .obj .stl .off)")->required();
  cmd->add_option("-o,--output", c->output, "Output mesh (.ply .obj .stl .off .glb .gltf)")->required();
  cmd->add_option("--method", c->method, "constrained (Bade), taubin or laplacian (unconstrained, any mesh)")
      ->capture_default_str();
  c->constraint_option = cmd->add_option("--constraint", c->constraint,
                  "diamond | cell-edge (both keep every sample on its side) | cell-size (no guarantee)")
      ->capture_default_str();
  cmd->add_option("--iterations", c->overrides.iterations, "Iteration cap (default 1000; taubin 110, laplacian 20)");
  cmd->add_option("--tolerance", c->overrides.tolerance,
                  "Stop when no vertex moved more than this in one iteration, in cells (default 0.002)");
  bind_fairing(*cmd, c->overrides);
  bind_simplify(*cmd, c->simplify);
  cmd->add_flag("--ascii", c->ascii, "ASCII PLY instead of binary");
  cmd->add_option("--stats-json", c->stats_json, "Write the recovered lattice, iterations and timings as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_smooth_mesh(*c, g);
  });
}

}  // namespace voxpress::cli
