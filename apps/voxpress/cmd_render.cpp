// voxpress render IN... -o OUT.png: pictures without a GPU (software
// rasterizer, flat shading). Several inputs are drawn side by side with the
// same camera; a volume is drawn as the surface of --method.
#include <cstdio>
#include <sstream>

#include "common.h"
#include "voxpress/core/memory_budget.h"
#include "voxpress/render/render.h"

namespace voxpress::cli {

bool is_mesh_path(const std::string& path) {
  try {
    const MeshFormat f = mesh_format_from_path(path);
    return f != MeshFormat::gltf && f != MeshFormat::glb;
  } catch (const InputError&) {
    return false;
  }
}

bool is_voxel_art_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".vox" || ext == ".vxl";
}

Mesh display_surface(const BinaryVolume& volume, const std::string& method, uint64_t max_bytes, uint64_t held_bytes,
                     SurfaceResult* result) {
  if (method == "voxels") return voxel_faces(volume, max_bytes, held_bytes);
  ExtractOptions eo;
  eo.max_bytes = max_bytes;
  eo.held_bytes = held_bytes;
  if (method == "midpoint") return to_mesh(extract_sticks(volume, eo));
  SurfaceOptions o;
  o.method = parse_method(method);
  o.extract.max_bytes = max_bytes;
  o.extract.held_bytes = held_bytes;
  SurfaceResult r = smooth_surface(volume, o);
  Mesh mesh = std::move(r.mesh);
  if (result) *result = std::move(r);
  return mesh;
}

namespace {

struct RenderCmd {
  std::vector<std::string> inputs;
  std::string output, view = "iso", size = "800x600", color = "auto", method;
  bool no_features = false, wireframe = false;
  InputOptions in;
};

void run_render(const RenderCmd& c, const Global& g) {
  check_paths(c.inputs, {{c.output, OutputKind::png}});

  if (!c.output.ends_with(".png")) throw UsageError("render writes a .png picture, not '" + c.output + "'");
  RenderOptions o;
  o.view = parse_view(c.view);
  int w = 0, h = 0;
  char extra = 0;
  if (std::sscanf(c.size.c_str(), "%dx%d%c", &w, &h, &extra) != 2) throw UsageError("--size must be WxH, e.g. 800x600");
  o.width = w, o.height = h;
  if (c.color == "regions")
    o.coloring = Coloring::regions;
  else if (c.color == "plain")
    o.coloring = Coloring::plain;
  else if (c.color != "auto")
    throw UsageError("--color must be auto, regions or plain");
  o.features = !c.no_features;
  o.wireframe = c.wireframe;
  // One method for every input, or one per input.
  std::vector<std::string> methods;
  {
    std::stringstream ss(c.method);
    for (std::string m; std::getline(ss, m, ',');) methods.push_back(m);
  }
  if (methods.size() > 1 && methods.size() != c.inputs.size())
    throw UsageError("--method lists " + std::to_string(methods.size()) + " methods for " +
                     std::to_string(c.inputs.size()) + " inputs (give one, or one per input)");
  std::vector<Mesh> meshes;
  std::vector<Texture> pictures;
  uint64_t read_residue = 0;
  for (size_t i = 0; i < c.inputs.size(); ++i) {
    const std::string& path = c.inputs[i];
    const std::string method = methods.empty() ? "" : methods.size() == 1 ? methods[0] : methods[i];
    Mesh mesh;
    if (is_mesh_path(path)) {
      MeshReadOptions ro;
      ro.max_bytes = g.memory_limit();
      mesh = read_mesh(path, ro);
    } else if (is_voxel_art_path(path)) {
      VoxelArtReadOptions ro;
      ro.max_bytes = g.memory_limit();
      VoxartOptions vo;
      vo.y_up = false;  // the render camera is Z-up
      vo.max_bytes = g.memory_limit();
      vo.fairing = parse_voxart_fairing(method.empty() ? "lanczos" : method == "voxels" ? "none" : method);
      mesh = polygonize_voxel_art(read_voxel_art(path, ro), vo).mesh;
    } else {
      mesh = display_surface(load_binary(path, c.in, g), method.empty() ? "pressing" : method, g.memory_limit(), 0);
    }
    if (mesh.triangles.empty()) throw InputError(path, "has no triangles to draw");
    meshes.push_back(std::move(mesh));
    // The meshes so far and one supersampled picture each (memory_budget.h);
    // a mesh file's parse stays in the heap while the pictures are drawn.
    if (is_mesh_path(path)) read_residue += std::filesystem::file_size(path) * kRenderBytesPerMeshFileByte;
    uint64_t need = read_residue;
    for (const Mesh& m : meshes)
      need += m.positions.size() * kMeshBytesPerVertex + m.triangles.size() * kMeshBytesPerTriangle +
              m.texture.rgba.size() + uint64_t(o.width) * uint64_t(o.height) *
                                          (uint64_t(o.supersample * o.supersample) * kRenderBytesPerSupersample + 4);
    charge_memory(path, need, g.memory_limit(),
                  "reading and drawing it (the mesh and a " + std::to_string(o.width) + " x " + std::to_string(o.height) +
                      " picture supersampled " + std::to_string(o.supersample) + "x)");
  }
  // Several inputs share one scale: each picture frames every input's vertices.
  if (meshes.size() > 1)
    for (const Mesh& m : meshes) o.frame.insert(o.frame.end(), m.positions.begin(), m.positions.end());
  for (const Mesh& m : meshes) pictures.push_back(render_mesh(m, o));
  const Texture picture = pictures.size() == 1 ? pictures[0] : side_by_side(pictures);
  write_png(c.output, picture.width, picture.height, picture.rgba);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %lld x %lld picture of %zu input(s)\n", c.output.c_str(), (long long)picture.width,
                 (long long)picture.height, c.inputs.size());
}

}  // namespace

void register_render(CLI::App& app, Global& g) {
  auto c = std::make_shared<RenderCmd>();
  auto* cmd = app.add_subcommand("render",
                                 "Draw meshes, volumes or voxel art to a PNG without a GPU (flat shading; several "
                                 "inputs side by side, same camera)");
  cmd->add_option("inputs", c->inputs, "Meshes (.ply .obj .stl .off), volumes, or voxel art (.vox .vxl)")
      ->required();
  cmd->add_option("-o,--output", c->output, "Output picture (.png)")->required();
  cmd->add_option("--view", c->view, "iso, x, y or z (looking along -x, +y, -z)")->capture_default_str();
  cmd->add_option("--size", c->size, "Size of each picture, WxH pixels")->capture_default_str();
  cmd->add_option("--color", c->color, "auto (texture / vertex colours), regions (one colour per flat, curved grey), "
                                       "plain")
      ->capture_default_str();
  cmd->add_option("--method", c->method,
                  "One for all inputs or one per input (comma-separated). Volumes: voxels, midpoint, or a press "
                  "method (default pressing); voxel art: voxels, lanczos (default), taubin, pressing");
  cmd->add_flag("--no-features", c->no_features, "Do not draw the sharp feature curves");
  cmd->add_flag("--wireframe", c->wireframe, "Also draw every triangle's edges (thin, grey)");
  c->in.bind(*cmd);
  cmd->callback([c, &g] {
    g.apply();
    run_render(*c, g);
  });
}

}  // namespace voxpress::cli
