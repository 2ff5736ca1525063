// voxpress voxart MODEL.vox|MODEL.vxl -o OUT.glb: voxel art to a textured,
// faired, simplified mesh (Muniz et al.).
#include <cstdio>

#include "common.h"
#include "voxpress/voxart/polygonize.h"

namespace voxpress::cli {
namespace {

struct VoxartCmd {
  std::string input, output, stats_json, fairing = "lanczos", packer = "best";
  VoxartOptions options;
  int64_t model = -1, frame = 0;
  bool no_texture = false, z_up = false, ascii = false, texels_given = false;
};

void run_voxart(VoxartCmd c, const Global& g) {
  check_paths({c.input}, {{c.output, OutputKind::mesh}, {c.stats_json, OutputKind::json}});

  // 0 is the library's "automatic"; asked for on the command line it is a mistake.
  if (c.texels_given && c.options.texels_per_voxel < 1) throw UsageError("--texels-per-voxel must be from 1 to 64");
  c.options.fairing = parse_voxart_fairing(c.fairing);
  c.options.packer = parse_atlas_packer(c.packer);
  c.options.texture = !c.no_texture;
  c.options.y_up = !c.z_up;
  c.options.max_bytes = g.memory_limit();
  Stopwatch clock;
  VoxelArtReadOptions ro;
  ro.max_bytes = g.memory_limit();
  ro.model = c.model;
  ro.frame = c.frame;
  const VoxelArt art = read_voxel_art(c.input, ro);
  const double seconds_read = clock.seconds();
  const VoxartResult r = polygonize_voxel_art(art, c.options);
  MeshCheckOptions mo;
  mo.self_intersections = false;
  const MeshCheck check = check_mesh(r.surface(), mo);
  if (!check.closed() || !check.manifold() || !check.oriented())
    throw std::logic_error(c.input + ": internal error: the surface is not a closed oriented 2-manifold (" +
                           (check.problems.empty() ? std::string("?") : check.problems.front()) + ")");
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  write_mesh(c.output, r.mesh, wo);
  const VoxartStats& s = r.stats;
  if (!g.quiet) {
    for (const std::string& n : art.notes) std::fprintf(stderr, "%s: %s\n", c.input.c_str(), n.c_str());
    std::fprintf(stderr, "%s: %llu voxels -> %llu triangles (%s)", c.output.c_str(), (unsigned long long)s.voxels,
                 (unsigned long long)s.triangles, voxart_fairing_name(c.options.fairing));
    if (c.options.texture)
      std::fprintf(stderr, ", %lld x %lld texture, %llu charts, %.0f %% used (%s packer), colours %.2f %% exact",
                   (long long)s.texture_width, (long long)s.texture_height, (unsigned long long)s.charts,
                   100 * s.utilisation, s.packer.c_str(), 100 * s.color_exact);
    std::fprintf(stderr, "\n");
  }
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "voxart";
    j["input"] = c.input;
    j["output"] = c.output;
    j["format"] = art.format;
    j["notes"] = art.notes;
    j["fairing"] = voxart_fairing_name(c.options.fairing);
    j["counts"] = {{"parts", art.parts.size()},     {"voxels", s.voxels},
                   {"quads", s.quads},              {"split_vertices", s.split_vertices},
                   {"filled_cavities", s.filled_cavities}, {"separated_edges", s.separated_edges}, {"vertices", s.vertices},
                   {"triangles", s.triangles},      {"surface_vertices", check.vertices},
                   {"components", check.components}, {"euler", check.euler}};
    j["surface"] = {{"closed", check.closed()}, {"manifold", check.manifold()}, {"oriented", check.oriented()}};
    if (c.options.texture)
      j["atlas"] = {{"charts", s.charts},
                    {"width", s.texture_width},
                    {"height", s.texture_height},
                    {"texels_per_voxel", s.texels_per_voxel},
                    {"packer", s.packer},
                    {"utilisation", s.utilisation},
                    {"utilisation_paper", s.utilisation_paper},
                    {"utilisation_shelf", s.utilisation_shelf}};
    j["color_exact"] = s.color_exact;
    j["seconds"] = {{"read", seconds_read},          {"extract", s.seconds_extract},
                    {"fair", s.seconds_fair},        {"simplify", s.seconds_simplify},
                    {"attributes", s.seconds_attributes}, {"atlas", s.seconds_atlas},
                    {"pipeline", s.seconds_total},   {"total", clock.seconds()}};
    j["peak_memory_bytes"] = peak_rss_bytes();
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_voxart(CLI::App& app, Global& g) {
  auto c = std::make_shared<VoxartCmd>();
  auto* cmd = app.add_subcommand("voxart",
                                 "Voxel art (.vox, .vxl) to a textured, faired, simplified mesh (Muniz et al.): "
                                 "closed 2-manifold surface, texture atlas with the voxel colours");
  cmd->add_option("input", c->input, "MagicaVoxel .vox or Westwood .vxl (its .hva beside it is used)")->required();
  cmd->add_option("-o,--output", c->output, "Output: .glb / .gltf (embedded texture), .obj (+ .mtl + .png), .ply")
      ->required();
  cmd->add_option("--fairing", c->fairing, "lanczos (the paper, one pass), taubin (10 iterations), pressing, none")
      ->capture_default_str();
  cmd->add_option("--faces", c->options.target_faces, "Simplify to at most this many triangles (0 = keep all)");
  cmd->add_option("--lambda", c->options.lambda, "Lanczos fairing constant (Eq. 8)")->capture_default_str();
  cmd->add_flag("--no-texture", c->no_texture, "Per-vertex colours instead of a texture atlas");
  cmd->add_option("--texels-per-voxel", c->options.texels_per_voxel,
                  "Texture density (default 4, halved while the texture exceeds --max-texture)");
  cmd->add_option("--max-texture", c->options.max_texture, "Largest texture side in texels")->capture_default_str();
  cmd->add_option("--chart-angle", c->options.chart_angle, "Chart growth limit, degrees from the seed's normal")
      ->capture_default_str();
  cmd->add_option("--packer", c->packer, "best, paper (Hb/Vb binary merging) or shelf")->capture_default_str();
  cmd->add_option("--padding", c->options.padding, "Texels of dilated colour around each chart")->capture_default_str();
  cmd->add_option("--model", c->model, ".vox: convert only model K, untransformed");
  cmd->add_option("--frame", c->frame, ".vxl: .hva animation frame placing the sections")->capture_default_str();
  cmd->add_flag("--z-up", c->z_up, "Keep the voxel file's Z-up frame (default: Y-up, as glTF expects)");
  cmd->add_flag("--ascii", c->ascii, "ASCII PLY instead of binary");
  cmd->add_option("--stats-json", c->stats_json, "Write counts, atlas figures, colour fidelity and step times as JSON");
  cmd->callback([c, cmd, &g] {
    c->texels_given = cmd->count("--texels-per-voxel") > 0;
    g.apply();
    run_voxart(*c, g);
  });
}

}  // namespace voxpress::cli
