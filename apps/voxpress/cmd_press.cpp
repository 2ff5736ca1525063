// voxpress press IN -o OUT: the volume's smooth surface by smooth_surface()
// — Pressing with flats, junctions and sharp edges, or a baseline method.
#include <tbb/parallel_for.h>

#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>

#include "common.h"

namespace voxpress::cli {
namespace {

struct PressCmd {
  std::string input, output, stats_json;
  InputOptions in;
  PressCli smooth;
  FlatOptions flats;
  SharpenOptions sharpen;
  QuadricFitOptions fit;
  std::string features;
  std::vector<std::string> disabled_passes;
  bool no_flats = false, no_sharpen = false, color_regions = false;
  bool ascii = false, check = false, separate = false;
  std::string method = "pressing";
  std::string labels, label_names, format = "ply";
  MethodOverrides overrides;  ///< --lambda, --mu; --iterations / --tolerance are PressCli's
  ChunkOptions chunks;
  SimplifyOptions simplify;  ///< --faces, --max-error
  CLI::App* cmd = nullptr;
};

nlohmann::json flats_json(const FlatSegmentation& seg, const FlatOptions& o) {
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < seg.flats.size(); ++i) {
    const Flat& f = seg.flats[i];
    list.push_back({{"id", i},
                    {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
                    {"offset", f.offset},
                    {"sticks", f.sticks},
                    {"area", f.area},
                    {"area_cells", f.area_cells}});
  }
  const FlatStats& st = seg.stats;
  return {{"count", seg.flats.size()},
          {"flats", list},
          {"frozen", seg.frozen_count()},
          {"junctions", st.junctions},
          {"barriers", st.barriers},
          {"rim_released", st.rim_released},
          {"crease_vertices", st.crease_vertices},
          {"curved_crease_vertices", st.curved_crease_vertices},
          {"votes", st.votes},
          {"voters", st.voters},
          {"cells", st.cells},
          {"cells_tried", st.tried},
          {"min_area_cells", o.min_area},
          {"junction_angle", o.junction_angle},
          {"seconds",
           {{"estimate", st.seconds_estimate},
            {"detect", st.seconds_detect},
            {"junctions", st.seconds_junctions},
            {"creases", st.seconds_creases}}}};
}

nlohmann::json sharpen_json(const SharpenStats& st, const SharpenOptions& o) {
  return {{"chamfer_edges", st.chamfer_edges},
          {"chamfer_triangles", st.chamfer_triangles},
          {"inserted_vertices", st.inserted},
          {"corner_vertices", st.corners},
          {"fallbacks", st.fallbacks},
          {"tangent_planes", st.tangent_planes},
          {"past_crease", st.past_crease},
          {"left_flat", st.left_flat},
          {"inherited_junctions", st.inherited_junctions},
          {"wedge_checks", st.wedge_checks},
          {"wedge_shifts", st.wedge_shifts},
          {"wall_vertices", st.wall_vertices},
          {"final_crease_vertices", st.final_crease_vertices},
          {"curved_crease_vertices", st.curved_crease_vertices},
          {"snapped", st.snapped},
          {"cut_back", st.cut_back},
          {"sharp_edges", st.sharp_edges},
          {"sharp_angle", o.sharp_angle},
          {"seconds", st.seconds}};
}

// The sharp feature curves alone: their vertices and edges, no faces.
void write_features(const std::string& path, const Mesh& mesh) {
  Mesh f;
  std::vector<uint32_t> id(mesh.vertex_count(), UINT32_MAX);
  for (const auto& e : mesh.edges) {
    std::array<uint32_t, 2> out{};
    for (int k = 0; k < 2; ++k) {
      uint32_t& i = id[e[size_t(k)]];
      if (i == UINT32_MAX) {
        i = uint32_t(f.positions.size());
        f.positions.push_back(mesh.positions[e[size_t(k)]]);
      }
      out[size_t(k)] = i;
    }
    f.edges.push_back(out);
  }
  write_mesh(path, f);
}

// The volume's surface, in memory or block by block (--chunk), and how to
// check a mesh against the volume's samples.
struct Pressed {
  SurfaceResult r;
  Lattice lattice;
  double seconds_read = 0;
  std::function<nlohmann::json(const Mesh&, bool strict)> check;
  std::optional<ChunkedStats> chunks;
  bool streamed = false;
};

Pressed press_in_memory(const PressCmd& c, const SurfaceOptions& so, const Global& g, Progress* progress) {
  Stopwatch clock;
  auto volume = std::make_shared<const BinaryVolume>(load_binary(c.input, c.in, g));
  Pressed p;
  p.seconds_read = clock.seconds();
  p.r = smooth_surface(*volume, so);
  p.lattice = volume->lattice;
  p.check = [=](const Mesh& m, bool strict) { return check_surface(m, *volume, progress, c.method, strict); };
  return p;
}

// press --chunk: the file read block by block (VolumeFile streams raw NRRD
// and .raw; other files are read whole first), an automatic selection
// resolved on one pass over the blocks, --check on slabs of planes.
Pressed press_chunked_file(const PressCmd& c, const SurfaceOptions& so, const Global& g, Progress* progress) {
  if (c.chunks.halo > 0)
    for (const char* name : {"--features", "--color-regions", "--min-flat-area", "--junction-angle", "--sharp-angle",
                             "--no-sharpen"})
      if (c.cmd->count(name)) throw UsageError(std::string(name) + " does not apply with --halo (blocks pressed apart: no flats)");
  Selection selection = c.in.selection();  // usage errors before any I/O
  Stopwatch clock;
  auto file = std::make_shared<const VolumeFile>(c.input, c.in.read_options(g));
  const Lattice& lattice = file->header().lattice;
  const ChunkGrid grid(lattice.dims, c.chunks);
  if (selection.kind == Selection::Kind::automatic) {  // which value the mask holds: one pass over the blocks
    ValueSummary values;
    std::mutex mu;
    ProgressCounter counter(progress, "values", grid.count());
    tbb::parallel_for(size_t(0), grid.count(), [&](size_t b) {
      const ValueSummary part = summarize_values(file->read(grid.core(b)));
      std::lock_guard lock(mu);
      values.merge(part);  // min, max, or and a set union: order-independent
      counter.add(1);
    });
    selection = resolve_selection(file->header(), selection, values);
  }
  Pressed p;
  p.seconds_read = clock.seconds();
  const BlockReader read = [file, selection](const Box& box) { return select_samples(file->read(box), selection); };
  ChunkedStats st;
  p.r = press_chunked(lattice, c.input, read, so, c.chunks, &st);
  p.chunks = st;
  p.lattice = lattice;
  p.streamed = file->streams();
  p.check = [=](const Mesh& m, bool strict) {
    const Lattice& l = file->header().lattice;
    const PlaneReader planes = [&](int64_t k0, int64_t k1) { return read(Box{{0, 0, k0}, {l.dims[0], l.dims[1], k1}}); };
    return check_surface(m, l, planes, progress, c.method, strict);
  };
  return p;
}

void run_press(const PressCmd& c, const Global& g) {
  const bool labels = !c.labels.empty();
  if (labels) {
    for (const char* name : {"--label", "--threshold", "--segment", "--features", "--halo"})
      if (c.cmd->count(name)) throw UsageError(std::string(name) + " does not apply with --labels");
    check_paths({c.input}, {{c.stats_json, OutputKind::json}});
  } else {
    for (const char* name : {"--label-names", "--format", "--separate"})
      if (c.cmd->count(name)) throw UsageError(std::string(name) + " needs --labels");
    check_paths({c.input}, {{c.output, OutputKind::mesh}, {c.features, OutputKind::features}, {c.stats_json, OutputKind::json}});
  }

  SurfaceOptions so;
  so.method = parse_method(c.method);
  const bool pressing = so.method == Method::pressing;
  if (!pressing)
    for (const char* name :
         {"--no-flats", "--min-flat-area", "--junction-angle", "--color-regions", "--no-sharpen", "--sharp-angle",
          "--features", "--disable-pass", "--step", "--arc-length", "--margin", "--levels", "--momentum", "--weighting",
          "--plain", "--circle-correction", "--fixed-ends", "--fit-rings"})
      if (c.cmd->count(name)) throw UsageError(std::string(name) + " applies to --method pressing only");
  so.press = c.smooth.resolve();
  so.flat = c.flats;
  so.fit = c.fit;
  so.sharp = c.sharpen;
  if (c.no_flats) so.passes.disable(Pass::flats);
  if (c.no_sharpen) so.passes.disable(Pass::sharpen);
  for (const std::string& name : c.disabled_passes) so.passes.disable(name);
  if (!c.features.empty() && !(so.passes.on(Pass::flats) && so.passes.on(Pass::sharpen)))
    throw UsageError("--features needs sharpening (drop --no-flats / --no-sharpen / --disable-pass flats|sharpen)");
  so.color_regions = c.color_regions;
  if (!pressing) {  // pressing reads these from so.press, with its own defaults
    if (c.smooth.iterations_option->count()) so.overrides.iterations = c.smooth.options.iterations;
    if (c.smooth.tolerance_option->count()) so.overrides.tolerance = c.smooth.options.tolerance;
  }
  so.overrides.lambda = c.overrides.lambda;
  so.overrides.mu = c.overrides.mu;
  so.extract.max_bytes = g.memory_limit();
  so.simplify = c.simplify;
  if (labels) {
    // The shared surface has no region colours and no quadric fit.
    if (pressing && !c.separate)
      for (const char* name : {"--color-regions", "--fit-rings"})
        if (c.cmd->count(name))
          throw UsageError(std::string(name) + " applies to --separate only (the shared surface has no region colours or quadric fit)");
    LabelOutput o;
    o.labels = c.labels;
    o.names_file = c.label_names;
    o.folder = c.output;
    o.format = c.format;
    o.stats_json = c.stats_json;
    o.ascii = c.ascii;
    o.check = c.check;
    o.separate = c.separate;
    if (c.cmd->count("--chunk")) o.chunks = c.chunks;
    run_press_labels(c.input, c.in, so, o, g);
    return;
  }
  if (c.cmd->count("--halo") && !c.cmd->count("--chunk")) throw UsageError("--halo needs --chunk");
  Stopwatch clock;
  ProgressBar bar(!g.quiet);
  so.progress = bar.get();
  const Pressed p = c.cmd->count("--chunk") ? press_chunked_file(c, so, g, bar.get()) : press_in_memory(c, so, g, bar.get());
  const SurfaceResult& r = p.r;
  const Mesh& mesh = r.mesh;
  const double seconds_read = p.seconds_read;
  // Methods without the in/out guarantee have their checks reported, not enforced.
  const bool strict = keeps_classification(so.method);
  const nlohmann::json checks = c.check ? p.check(mesh, strict) : nlohmann::json();
  MeshWriteOptions wo;
  wo.ascii = c.ascii;
  wo.space = p.lattice.space;
  write_mesh(c.output, mesh, wo);
  if (!c.features.empty()) write_features(c.features, mesh);
  const int iterations = pressing ? r.press.iterations : so.method == Method::cesn ? r.net.iterations : r.smooth.iterations;
  if (!g.quiet) {
    if (pressing)
      std::fprintf(stderr, "%s: %zu vertices, %zu triangles, %zu flats (%zu frozen vertices, %zu junctions), %zu sharp edges, %d iterations (residual %.2g)\n",
                   c.output.c_str(), mesh.vertex_count(), mesh.face_count(), r.flats.flats.size(), r.flats.frozen_count(),
                   size_t(r.flats.stats.junctions), mesh.edges.size(), iterations, r.press.residual);
    else
      std::fprintf(stderr, "%s: %zu vertices, %zu triangles, %s, %d iterations\n", c.output.c_str(), mesh.vertex_count(),
                   mesh.face_count(), c.method.c_str(), iterations);
    if (c.check && !strict)
      std::fprintf(stderr, "%s: %llu samples on the wrong side, %zu self-intersections (%s promises neither)\n",
                   c.output.c_str(), (unsigned long long)checks["classification_violations"].get<uint64_t>(),
                   checks["self_intersections"].get<size_t>(), c.method.c_str());
    if (p.chunks)
      std::fprintf(stderr, "%s: %zu blocks of %lld, %s; %s\n", c.output.c_str(), p.chunks->blocks,
                   (long long)c.chunks.chunk,
                   c.chunks.halo ? ("pressed apart with a halo of " + std::to_string(c.chunks.halo) + " in " +
                                   std::to_string(p.chunks->rounds) + " rounds").c_str()
                                 : "stitched and smoothed whole (exact)",
                   p.streamed ? "read from disk block by block" : "the file was read whole (only raw NRRD and .raw stream)");
  }
  if (!c.stats_json.empty()) {
    nlohmann::json j = surface_stats_json("press", c.input, c.output, p.lattice, r.extract, mesh);
    j["method"] = c.method;
    if (const auto& st = p.chunks)
      j["chunks"] = {{"chunk", c.chunks.chunk}, {"halo", c.chunks.halo}, {"blocks", st->blocks},
                     {"blocks_with_surface", st->pressed}, {"rounds", st->rounds}, {"streamed", p.streamed},
                     {"seconds", {{"summary", st->seconds_summary}, {"blocks", st->seconds_blocks},
                                  {"stitch", st->seconds_stitch}}}};
    if (pressing) {
      j["pressing"] = press_stats_json(r.press, so.press);
      const bool features = so.passes.on(Pass::flats);
      if (features) j["flats"] = flats_json(r.flats, so.flat);
      j["quadric_fit"] = {{"rings", so.fit.rings}, {"fitted", r.fit.fitted}, {"moved", r.fit.moved}};
      if (features && so.passes.on(Pass::sharpen)) j["sharpen"] = sharpen_json(r.sharpen, so.sharp);
      j["passes"] = passes_json(so.passes, r.pass_times);
      j["seconds"] = {{"read", seconds_read}, {"extract", r.seconds_extract}, {"press", r.press.seconds},
                      {"quadric_fit", r.fit.seconds}, {"sharpen", r.sharpen.seconds}, {"total", clock.seconds()}};
    } else {
      if (so.method == Method::cesn)
        j["smoothing"] = {{"iterations", r.net.iterations},      {"converged", r.net.converged},
                          {"last_max_change", r.net.last_max_change}, {"patch_vertices", r.net.patch_vertices},
                          {"split_cells", r.net.split_cells},    {"face_vertices", r.net.face_vertices},
                          {"quads", r.net.quads},                {"seconds_build", r.net.seconds_build},
                          {"seconds_relax", r.net.seconds_relax}};
      else
        j["smoothing"] = smooth_stats_json(r.smooth);
      j["seconds"] = {{"read", seconds_read}, {"extract", r.seconds_extract}, {"smooth", r.seconds_smooth},
                      {"total", clock.seconds()}};
    }
    if (so.simplify.faces || so.simplify.max_error) j["simplify"] = simplify_stats_json(r.simplify, so.simplify);
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
  cmd->add_option("-o,--output", c->output, "Output mesh (.ply .obj .stl .off .glb .gltf); with --labels, a folder")
      ->required();
  c->cmd = cmd;
  auto* lm = cmd->add_option_group("label maps", "Every label at once: one closed mesh per label in the -o folder");
  lm->add_option("--labels", c->labels,
                 "all, or values like 1,5,7: one mesh per label, FOLDER/<name or label_N>.<format>, and "
                 "FOLDER/labels.json");
  lm->add_option("--label-names", c->label_names, "Label names, one 'VALUE NAME' per line (segment names of a "
                                                  ".seg.nrrd are used without it)");
  lm->add_option("--format", c->format, "Mesh format of --labels: ply, obj, stl, off, glb, gltf, vtk, vtp")->capture_default_str();
  lm->add_flag("--separate", c->separate,
               "Mesh each label alone, with its own flats and sharpening (touching labels' surfaces are then not "
               "shared: they may overlap near their common wall); default: one shared surface, pressed, plus "
               "FOLDER/interfaces.ply (.vtk / .vtp with that --format)");
  cmd->add_option("--method", c->method,
                  "Smoothing method: pressing, cesn, diamond, cell-edge, cell-size, taubin or laplacian (all but "
                  "pressing are baselines; docs/ARCHITECTURE.md)")
      ->capture_default_str();
  c->in.bind(*cmd);
  c->smooth.bind(*cmd);
  cmd->add_option("--fit-rings", c->fit.rings,
                  "After pressing, move each curved vertex onto the quadric fitted to the curved vertices within this "
                  "many rings, when it fits (0: off)")
      ->check(CLI::Range(0, 12))
      ->capture_default_str();
  bind_fairing(*cmd->add_option_group("fairing", "Taubin / Laplacian (--method taubin|laplacian)"), c->overrides);
  auto* f = cmd->add_option_group("flats", "Flats (plane voting) and junctions");
  f->add_flag("--no-flats", c->no_flats, "Do not look for flats: every vertex is smoothed");
  f->add_option("--min-flat-area", c->flats.min_area, "Smallest flat, in cell areas")
      ->check(CLI::Range(0.0, 1e12))
      ->capture_default_str();
  f->add_option("--junction-angle", c->flats.junction_angle,
                "Degrees between a flat and its curved neighbour above which their border is sharp")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  f->add_flag("--color-regions", c->color_regions,
              "Colour the vertices by region (flats, curved grey, junctions orange, sharp curves red)");
  auto* sh = cmd->add_option_group("sharpen", "Sharp edge recovery (needs flats)");
  sh->add_flag("--no-sharpen", c->no_sharpen, "Keep the chamfers: do not insert the sharp edges");
  sh->add_option("--sharp-angle", c->sharpen.sharp_angle, "Degrees between two faces above which their crease is labelled sharp")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  std::string pass_names;
  for (const PassInfo& p : feature_passes()) pass_names += std::string(pass_names.empty() ? "" : ", ") + p.name;
  cmd->add_option("--disable-pass", c->disabled_passes,
                  "Switch off a pass of the feature layer (repeat or comma-separate; docs/ARCHITECTURE.md, The feature "
                  "layer): " + pass_names)
      ->delimiter(',');
  sh->add_option("--features", c->features, "Also write the sharp curves alone (.ply edges or .obj lines)");
  auto* ch = cmd->add_option_group("chunks", "Block by block, for volumes larger than memory");
  ch->add_option("--chunk", c->chunks.chunk,
                 "Read the volume in blocks of this many samples per side (raw NRRD / .raw from disk) and stitch "
                 "their sticks: the same mesh as without, the volume never whole in memory (with --labels: the "
                 "shared surface of every label, from the blocks)")
      ->check(CLI::Range(int64_t(8), int64_t(1) << 20));
  ch->add_option("--halo", c->chunks.halo,
                 "Also press each block apart, reading this many samples around it, in rounds that exchange the "
                 "blocks' borders (what Dask workers do; Pressing only, no flats): the whole run's surface up to "
                 "rounding; wider: fewer rounds; too narrow for one sweep: refused, naming the smallest")
      ->check(CLI::Range(int64_t(1), int64_t(256)));
  bind_simplify(*cmd, c->simplify);
  cmd->add_flag("--ascii", c->ascii, "ASCII PLY instead of binary");
  cmd->add_flag("--check", c->check, "Verify the mesh (check_mesh + classification) before writing");
  cmd->add_option("--stats-json", c->stats_json, "Write timings and counts as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_press(*c, g);
  });
}

}  // namespace voxpress::cli
