// voxpress press IN --labels all|1,5,7 -o FOLDER: every selected label of a
// label map (or every segment of a .seg.nrrd) pressed in one process, one
// closed mesh per label, plus FOLDER/labels.json (value, name, file, counts,
// the labels each one touches). By default the meshes are cut from one
// pressed shared surface (labels/shared_press.h; FOLDER/interfaces.ply, .vtk
// or .vtp holds it, each interface once; with --format glb|gltf, FOLDER/all_labels.glb
// holds every label as a coloured node); --separate, a layered .seg.nrrd or a baseline
// method meshes each label alone. Nothing is written unless every label
// succeeds (and passes --check).
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <memory>
#include <set>
#include <unistd.h>

#include "common.h"
#include "voxpress/core/memory_budget.h"

namespace voxpress::cli {
namespace {

// Integer labels as JSON integers (labels.json reads "5", not "5.0").
nlohmann::json value_json(double v) {
  if (v == std::floor(v) && std::abs(v) < 9e15) return int64_t(v);
  return v;
}

// A file name from a segment / table name: letters, digits, '-', '_' and
// '.' kept, anything else '_'.
std::string file_stem(const std::string& name) {
  std::string out;
  for (unsigned char ch : name) out += (std::isalnum(ch) || ch == '-' || ch == '_' || ch == '.') ? char(ch) : '_';
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  // At most 120 characters: with "label_N_" and the extension the name stays
  // under the 255 bytes of a file name (a 5,000-character name failed with
  // "File name too long" after the folder was made, issue 73). Two names cut
  // to the same stem fall back to label_N_<stem>, which the value keeps apart.
  if (out.size() > 120) out.resize(120);
  return out;
}

// A label's colour in the scene: hues spread by the golden ratio of its
// value (neighbouring values far apart), fixed saturation and value.
std::array<double, 4> label_color(double value) {
  const double h = std::fmod(std::abs(value) * 0.6180339887498949, 1.0) * 6, s = 0.55, v = 0.9;
  const int i = int(h) % 6;
  const double f = h - std::floor(h), p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  const double rgb[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  return {rgb[i][0], rgb[i][1], rgb[i][2], 1.0};
}

}  // namespace

void check_label_output(const LabelOutput& o) {
  namespace fs = std::filesystem;
  static const std::set<std::string> formats = {"ply", "obj", "stl", "off", "glb", "gltf", "vtk", "vtp"};
  if (!formats.count(o.format))
    throw UsageError("--format must be one of ply, obj, stl, off, glb, gltf, vtk, vtp, not '" + o.format + "'");
  std::error_code ec;
  if (fs::exists(o.folder, ec) && !fs::is_directory(o.folder, ec))
    throw UsageError(o.folder + ": with --labels, -o names a folder (one mesh per label), and this is a file");
  fs::path parent = fs::path(o.folder).lexically_normal().parent_path();
  if (fs::path(o.folder).lexically_normal().filename().empty()) parent = parent.parent_path();  // "organs/"
  if (parent.empty()) parent = ".";
  const fs::path target = fs::is_directory(o.folder, ec) ? fs::path(o.folder) : parent;
  if (!fs::is_directory(target, ec)) throw UsageError(o.folder + ": the folder " + target.string() + " does not exist");
  if (::access(target.c_str(), W_OK) != 0) throw UsageError(o.folder + ": " + target.string() + " is not writable");
  if (!o.names_file.empty()) check_paths({o.names_file}, {});
}

namespace {

// One label's output: its mesh and what labels.json says about it.
struct LabelPiece {
  LabelInfo label;
  Mesh mesh;
  size_t flats = 0;
};

// The stats of the shared surface's press for --stats-json.
nlohmann::json shared_json(const SharedLabels& r) {
  const SharedSurface& s = r.surface;
  const SharedPressStats& ps = r.press;
  const std::optional<SharedFlats>& flats = r.flats;
  nlohmann::json stats = {
      {"vertices",
       {{"sticks", s.stick_vertices}, {"face_centres", s.face_vertices}, {"apexes", s.apex_vertices},
        {"creases", r.sharpen.inserted}}},
      {"junction_curves", ps.junction_curves},
      {"junction_vertices",
       {{"moving", ps.junction_moving}, {"fixed", ps.junction_fixed}, {"on_flats", ps.junction_on_flats}}},
      {"plane_curves", ps.plane_curves},
      {"continued_through_junctions", ps.continued},
      {"iterations", {{"junctions", ps.junctions.iterations}, {"interfaces", ps.interfaces.iterations}}},
      {"residual", {{"junctions", ps.junctions.residual}, {"interfaces", ps.interfaces.residual}}},
      {"cubes_pinned", ps.cubes_pinned},
      {"cubes_reset", ps.cubes_reset},
      {"flats", nlohmann::json::array()},
      {"flat_vertices", ps.flat_vertices},
      {"quadric_fit",
       {{"labels", r.fit.labels},
        {"cubes", r.fit.cubes},
        {"fitted", r.fit.fitted},
        {"moved", r.fit.moved},
        {"cubes_put_back", r.fit.cubes_put_back}}},
      {"sharpen",
       {{"labels", r.sharpen.labels},
        {"cubes", r.sharpen.cubes},
        {"crease_vertices", r.sharpen.inserted},
        {"corners", r.sharpen.corners},
        {"moved", r.sharpen.moved},
        {"sharp_edges", r.sharpen.sharp_edges},
        {"taken_back", r.sharpen.taken_back},
        {"labels_undone", r.sharpen.labels_undone}}},
      {"seconds",
       {{"extract", r.seconds_extract},
        {"flats", flats ? flats->seconds : 0.0},
        {"press", ps.seconds},
        {"quadric_fit", r.fit.seconds},
        {"sharpen", r.sharpen.seconds}}}};
  if (flats)  // each flat: the label it was found on, its plane and area
    for (size_t i = 0; i < flats->flats.size(); ++i) {
      const Flat& f = flats->flats[i];
      stats["flats"].push_back({{"label", flats->flat_label[i]},
                                {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
                                {"offset", f.offset},
                                {"area", f.area},
                                {"sticks", f.sticks}});
    }
  return stats;
}

// Each chosen label's closed mesh cut from the pressed shared surface, so
// touching labels share their interface vertex for vertex.
std::vector<LabelPiece> shared_pieces(const SharedLabels& r, const std::vector<LabelInfo>& chosen) {
  const SharedSurface& s = r.surface;
  std::vector<LabelPiece> out;
  for (const LabelInfo& l : chosen) {
    const auto it = std::find(s.labels.begin(), s.labels.end(), uint32_t(l.value));
    out.push_back({l, label_mesh(s, uint32_t(it - s.labels.begin())), r.flats ? r.flats->flats_of(l.value) : 0});
  }
  return out;
}

// The label map: in memory, or (--chunk) a file read block by block, its
// table and shared surface from one pass over the blocks.
struct LabelSource {
  std::optional<ScalarVolume> volume;
  std::shared_ptr<const VolumeFile> file;
  Lattice lattice;
  LabelTable table;
  std::optional<SharedSurface> surface;  // --chunk: assembled from the blocks
  LabelMasks masks;
  double seconds_extract = 0;
  size_t blocks = 0;
  bool streamed = false;
};

LabelSource open_labels(const std::string& input, const InputOptions& in, const LabelOutput& o, const Global& g,
                        Progress* progress) {
  LabelSource src;
  if (!o.chunks) {
    src.volume = load_volume(input, in, g);
    src.lattice = src.volume->lattice;
    src.table = label_table(*src.volume);
    return src;  // masks: set by the caller once src has its place (masks_in keeps a reference)
  }
  src.file = std::make_shared<const VolumeFile>(input, in.read_options(g));
  src.lattice = src.file->header().lattice;
  src.streamed = src.file->streams();
  const BoxRead read = [file = src.file](const Box& box) { return file->read(box); };
  Stopwatch clock;
  ChunkedLabels c = extract_labels_chunked(src.file->header(), read, *o.chunks, progress);
  src.seconds_extract = clock.seconds();
  src.table = std::move(c.table);
  src.surface = std::move(c.surface);
  src.blocks = c.blocks;
  src.masks = masks_read(src.lattice, input, read);
  return src;
}

}  // namespace

// The label map in memory, its masks and each label's meshes and flats stay
// while the labels are pressed (memory_budget.h): charged here, and the
// presses are given what is left (the shared one charges 256 bytes per
// interface triangle). --chunk streams the map: nothing is held.
uint64_t charge_label_map(const LabelSource& src, size_t labels, const std::string& input, SurfaceOptions& so) {
  if (!src.volume) return 0;
  const uint64_t held = src.volume->lattice.size() * kLabelBytesPerSample + labels * kLabelBytesPerLabel;
  charge_memory(input, held, so.extract.max_bytes,
                "the label map with its masks and " + std::to_string(labels) + " labels");
  if (so.extract.max_bytes) so.extract.max_bytes -= held;
  return held;
}

void run_press_labels(const std::string& input, const InputOptions& in, const SurfaceOptions& options,
                      const LabelOutput& o, const Global& g) {
  namespace fs = std::filesystem;
  check_label_output(o);
  if (o.chunks && o.separate) throw UsageError("--separate does not apply with --chunk (the shared surface is meshed block by block)");
  if (o.chunks && options.method != Method::pressing) throw UsageError("--chunk with --labels runs --method pressing only");
  Stopwatch clock;
  ProgressBar bar(!g.quiet);
  // The names first: a bad table is refused before the volume is read.
  const auto names = o.names_file.empty() ? std::map<double, std::string>{} : read_label_names(o.names_file);
  LabelSource src = open_labels(input, in, o, g, bar.get());
  if (src.volume) src.masks = masks_in(*src.volume);
  LabelTable& table = src.table;
  if (!o.names_file.empty()) {
    for (LabelInfo& l : table.labels)
      if (auto it = names.find(l.value); it != names.end()) l.name = it->second;
  }
  const std::vector<LabelInfo> chosen = select_labels(table, parse_label_list(o.labels), input);
  const double seconds_read = clock.seconds();
  SurfaceOptions so = options;
  so.progress = bar.get();
  const uint64_t held = charge_label_map(src, chosen.size(), input, so);
  // Layers of a .seg.nrrd overlap: each is meshed alone, as are the baselines.
  const bool shared = !o.separate && !table.layered && so.method == Method::pressing;
  const bool strict = keeps_classification(so.method);
  Mesh combined;
  nlohmann::json shared_stats;
  std::vector<LabelPiece> pieces;
  try {
    if (shared) {
      SharedLabels r = src.surface ? press_shared_labels(std::move(*src.surface), src.masks, table, so, input)
                                   : press_shared_labels(*src.volume, table, so);
      if (src.surface) r.seconds_extract = src.seconds_extract;
      shared_stats = shared_json(r);
      if (so.simplify.faces || so.simplify.max_error) shared_stats["simplify"] = simplify_stats_json(r.simplify, so.simplify);
      shared_stats["passes"] = passes_json(so.passes, r.passes);
      pieces = shared_pieces(r, chosen);
      combined = interfaces_mesh(r.surface);
    } else {
      for (LabelSurface& s : press_labels(*src.volume, chosen, so))
        pieces.push_back({s.label, std::move(s.result.mesh), s.result.flats.flats.size()});
    }
  } catch (const LimitError& e) {
    if (!held) throw;
    throw LimitError(e.path(), e.problem() + " left after the " + std::to_string(held >> 20) +
                                   " MiB the label map and its labels hold");
  }

  // File names: the label's name when it has one and no other label shares it.
  std::map<std::string, int> uses;
  for (const LabelInfo& l : chosen) ++uses[file_stem(l.name)];
  nlohmann::json list = nlohmann::json::array();
  std::vector<std::string> files;
  for (const LabelPiece& s : pieces) {
    const std::string stem = file_stem(s.label.name);
    // Layers of a .seg.nrrd may reuse a value: the layer is then part of the name.
    const std::string layer = table.layered ? "_layer" + std::to_string(s.label.layer) : "";
    const std::string base = !stem.empty() && uses[stem] == 1
                                 ? stem
                                 : "label_" + format_value(s.label.value) + layer + (stem.empty() ? "" : "_" + stem);
    files.push_back((fs::path(o.folder) / (base + "." + o.format)).string());
    nlohmann::json e = {{"value", value_json(s.label.value)}, {"name", s.label.name},
                        {"layer", s.label.layer},             {"file", base + "." + o.format},
                        {"samples", s.label.samples},         {"vertices", s.mesh.vertex_count()},
                        {"triangles", s.mesh.face_count()},   {"flats", s.flats}};
    nlohmann::json touches = nlohmann::json::array();
    for (const LabelContact& c : table.contacts)
      if (c.a == s.label.value || c.b == s.label.value)
        touches.push_back({{"label", value_json(c.a == s.label.value ? c.b : c.a)}, {"sticks", c.sticks}});
    e["touches"] = touches;
    if (o.check) {
      const BinaryVolume mask = src.masks(s.label);
      e["checks"] = check_surface(s.mesh, mask, bar.get(), "label " + format_value(s.label.value), strict);
    }
    list.push_back(e);
  }
  // Everything computed and checked: now the outputs.
  fs::create_directories(o.folder);
  MeshWriteOptions wo;
  wo.ascii = o.ascii;
  wo.space = src.lattice.space;
  for (size_t i = 0; i < pieces.size(); ++i) write_mesh(files[i], pieces[i].mesh, wo);
  nlohmann::json manifest = {{"input", input},
                             {"layered", table.layered},
                             {"shared", shared},
                             {"lattice", lattice_json(src.lattice)},
                             {"labels", list}};
  if (shared) {
    // The whole surface, each interface once, its two labels as face
    // attributes: in the chosen format where it keeps them (PLY, VTK, VTP).
    const std::string name = "interfaces." + (o.format == "vtk" || o.format == "vtp" ? o.format : std::string("ply"));
    write_mesh((fs::path(o.folder) / name).string(), combined, wo);
    manifest["interfaces"] = {{"file", name},
                              {"vertices", combined.vertex_count()},
                              {"triangles", combined.face_count()}};
  }
  if (o.format == "glb" || o.format == "gltf") {
    // Every label in one scene, a node each with its colour, for viewers.
    std::vector<SceneMesh> scene;
    for (size_t i = 0; i < pieces.size(); ++i)
      scene.push_back({fs::path(files[i]).stem().string(), &pieces[i].mesh, label_color(pieces[i].label.value)});
    write_scene((fs::path(o.folder) / ("all_labels." + o.format)).string(), scene);
    manifest["scene"] = "all_labels." + o.format;
  }
  write_json((fs::path(o.folder) / "labels.json").string(), manifest);
  size_t vertices = 0, triangles = 0;
  for (const LabelPiece& s : pieces) {
    vertices += s.mesh.vertex_count();
    triangles += s.mesh.face_count();
  }
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu labels%s, %zu vertices, %zu triangles%s, %.2f s\n", o.folder.c_str(), pieces.size(),
                 table.layered ? " (layered segmentation: each segment meshed on its own layer)" : "", vertices,
                 triangles, shared ? " (interfaces shared: interfaces file holds each once)" : "", clock.seconds());
  if (!o.stats_json.empty()) {
    nlohmann::json j = manifest;
    j["command"] = "press --labels";
    j["seconds"] = {{"read", seconds_read}, {"total", clock.seconds()}};
    if (shared) j["shared_surface"] = shared_stats;
    if (o.chunks) j["chunks"] = {{"chunk", o.chunks->chunk}, {"blocks", src.blocks}, {"streamed", src.streamed}};
    j["peak_memory_bytes"] = peak_rss_bytes();
    write_json(o.stats_json, j);
  }
}

}  // namespace voxpress::cli
