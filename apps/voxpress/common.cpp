#include "common.h"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace voxpress::cli {

void Global::apply() const {
  static std::unique_ptr<tbb::global_control> control;
  if (threads > 0)
    control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled && ::isatty(2)) {}

void ProgressBar::begin(std::string_view stage, uint64_t total) {
  std::lock_guard lock(m_);
  stage_ = stage;
  total_ = std::max<uint64_t>(total, 1);
  last_percent_ = -1;
}

bool ProgressBar::update(uint64_t done) {
  const int percent = int(100 * std::min(done, total_) / total_);
  if (percent == last_percent_) return true;
  std::lock_guard lock(m_);
  if (percent > last_percent_) {
    last_percent_ = percent;
    draw(done, false);
  }
  return true;
}

void ProgressBar::end() {
  std::lock_guard lock(m_);
  draw(total_, true);
}

void ProgressBar::draw(uint64_t done, bool final) {
  constexpr int kWidth = 30;
  const int filled = int(kWidth * std::min(done, total_) / total_);
  std::fprintf(stderr, "\r%-14s [%.*s%*s] %3d%%", stage_.c_str(), filled, "##############################",
               kWidth - filled, "", int(100 * std::min(done, total_) / total_));
  if (final) std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
}

void InputOptions::bind(CLI::App& cmd) {
  cmd.add_option("--label", label, "Inside = samples with this label (a number), or 'all-nonzero'");
  cmd.add_option("--threshold", threshold, "Inside = samples >= T (grey-level volumes)");
  cmd.add_option("--segment", segment, "Inside = this segment of a 3D Slicer .seg.nrrd (name or ID)");
  auto* g = cmd.add_option_group("raw", "Headerless .raw/.bin input");
  g->add_option("--raw-dims", raw_dims, "X,Y,Z sample counts (makes the input raw)");
  g->add_option("--raw-type", raw_type, "uint8 int8 uint16 int16 uint32 int32 uint64 int64 float32 float64")
      ->capture_default_str();
  g->add_option("--raw-spacing", raw_spacing, "SX,SY,SZ cell size (default 1,1,1)");
  g->add_option("--raw-origin", raw_origin, "OX,OY,OZ position of the first sample (default 0,0,0)");
  g->add_flag("--raw-big-endian", raw_big_endian, "Samples are big-endian");
  g->add_option("--raw-header-bytes", raw_header_bytes, "Bytes to skip before the samples");
}

ReadOptions InputOptions::read_options(const Global& g) const {
  ReadOptions r;
  r.max_bytes = g.memory_limit();
  if (!raw_dims.empty()) {
    RawLayout layout;
    const Vec3 d = parse_vec3(raw_dims, "--raw-dims");
    for (int a = 0; a < 3; ++a) {
      if (d[a] < 1 || d[a] != std::floor(d[a])) throw UsageError("--raw-dims needs three positive integers");
      layout.dims[size_t(a)] = int64_t(d[a]);
    }
    layout.type = parse_scalar_type(raw_type);
    if (!raw_spacing.empty()) layout.spacing = parse_vec3(raw_spacing, "--raw-spacing");
    if (!raw_origin.empty()) layout.origin = parse_vec3(raw_origin, "--raw-origin");
    layout.big_endian = raw_big_endian;
    if (raw_header_bytes < 0) throw UsageError("--raw-header-bytes must be 0 or more");
    layout.header_bytes = uint64_t(raw_header_bytes);
    r.raw = layout;
  }
  return r;
}

Selection InputOptions::selection() const {
  const int given = int(!label.empty()) + int(threshold.has_value()) + int(!segment.empty());
  if (given > 1) throw UsageError("choose one of --label, --threshold and --segment");
  Selection s;
  if (!label.empty()) s = parse_label_selection(label);
  if (threshold) {
    s.kind = Selection::Kind::threshold;
    s.value = *threshold;
  }
  if (!segment.empty()) {
    s.kind = Selection::Kind::segment;
    s.segment = segment;
  }
  return s;
}

ScalarVolume load_volume(const std::string& path, const InputOptions& in, const Global& g) {
  return read_volume(path, in.read_options(g));
}

BinaryVolume load_binary(const std::string& path, const InputOptions& in, const Global& g) {
  const Selection sel = in.selection();  // usage errors before any I/O
  ScalarVolume scalar = load_volume(path, in, g);
  // The file's samples and their binary mask live together while binarising.
  const uint64_t cap = g.memory_limit(), both = scalar.bytes.size() + scalar.lattice.size();
  if (cap && both > cap)
    throw LimitError(path, "reading and binarising it needs about " + std::to_string(both >> 20) +
                               " MiB, above the memory limit of " + std::to_string(cap >> 20) + " MiB");
  BinaryVolume b = binarize(std::move(scalar), sel);
  require_mixed(b);
  return b;
}

VolumeSurface load_surface(const std::string& path, const InputOptions& in, const Global& g, Progress* progress) {
  VolumeSurface vs;
  Stopwatch clock;
  vs.volume = load_binary(path, in, g);
  vs.seconds_read = clock.seconds();
  ExtractOptions eo;
  eo.progress = progress;
  eo.max_bytes = g.memory_limit();
  vs.surface = extract_sticks(vs.volume, eo, &vs.stats);
  vs.seconds_extract = clock.seconds() - vs.seconds_read;
  return vs;
}

nlohmann::json surface_stats_json(const char* command, const std::string& input, const std::string& output,
                                  const Lattice& lattice, const ExtractStats& extract, const Mesh& mesh) {
  nlohmann::json j;
  j["command"] = command;
  j["input"] = input;
  j["output"] = output;
  j["lattice"] = lattice_json(lattice);
  j["counts"] = {{"samples", extract.samples}, {"sticks", extract.sticks}, {"vertices", mesh.vertex_count()},
                 {"triangles", mesh.face_count()}};
  return j;
}

void PressCli::bind(CLI::App& cmd, bool barriers) {
  auto* g = cmd.add_option_group("smoothing", "Pressing (constrained bilaplacian smoothing)");
  iterations_option = g->add_option("--iterations", options.iterations,
                                    "Maximum iterations (other methods: cap 1000 for cesn and the constraints, "
                                    "110 taubin, 20 laplacian)")
                          ->capture_default_str();
  tolerance_option = g->add_option("--tolerance", options.tolerance,
                                   "Pressing: stop when the residual max |T(t) - t| of the map at d is at most this "
                                   "(fraction of a stick); cesn and the constraints: when no vertex moves more "
                                   "(cells, default 0.002)")
                         ->capture_default_str();
  g->add_option("--step", options.step, "s in C'' = C + s^2 L^2(C)")->capture_default_str();
  g->add_option("--arc-length", options.arc_length, "d: virtual-neighbour distance, in cells")->capture_default_str();
  g->add_option("--margin", options.margin, "Keep t in [margin, 1 - margin]")->capture_default_str();
  g->add_option("--levels", options.levels,
                "Coarse-to-fine stages of d (1: the paper's single d; 0: by the surface's extent, 2 below 192 cells, "
                "one more each time it doubles)")
      ->capture_default_str();
  g->add_option("--momentum", options.momentum, "Heavy-ball momentum (0: the paper's plain iteration)")
      ->capture_default_str();
  g->add_option("--weighting", weighting, "equal | normal | tangent (combining a stick's two proposals)")
      ->capture_default_str();
  g->add_flag("--plain", plain, "Bilaplacian of the actual neighbours, no arc-length resampling (paper Fig. 5)");
  g->add_option("--circle-correction", options.circle_correction,
                "Degrees: largest chord turning angle whose circle shrinkage is cancelled (0: the paper's bilaplacian)")
      ->capture_default_str();
  if (barriers)
    g->add_flag("--fixed-ends", fixed_ends,
                "Curve pieces next to a sharp flat border keep the flat's last vertex as a fixed end (default: free "
                "ends, aligned with the curved side)");
}

PressOptions PressCli::resolve() const {
  PressOptions o = options;
  if (weighting == "equal")
    o.weighting = PressOptions::Weighting::equal;
  else if (weighting == "normal")
    o.weighting = PressOptions::Weighting::normal;
  else if (weighting == "tangent")
    o.weighting = PressOptions::Weighting::tangent;
  else
    throw UsageError("--weighting must be equal, normal or tangent");
  o.resample = !plain;
  if (!(o.circle_correction >= 0 && o.circle_correction <= 45)) throw UsageError("--circle-correction must be in [0, 45]");
  o.free_ends = !fixed_ends;
  if (o.iterations < 0) throw UsageError("--iterations must be >= 0");
  if (!(o.margin > 0 && o.margin < 0.5)) throw UsageError("--margin must be in (0, 0.5)");
  if (!(o.arc_length > 0) || !(o.step > 0)) throw UsageError("--arc-length and --step must be > 0");
  if (o.levels < 0 || o.levels > 8) throw UsageError("--levels must be between 0 (automatic) and 8");
  if (!(o.momentum >= 0 && o.momentum < 1)) throw UsageError("--momentum must be in [0, 1)");
  return o;
}

void bind_fairing(CLI::App& cmd, MethodOverrides& overrides) {
  cmd.add_option("--lambda", overrides.lambda, "Taubin / Laplacian step (default 0.7143 taubin, 0.5 laplacian)");
  cmd.add_option("--mu", overrides.mu, "Taubin's negative step (default -0.7692)");
}

std::optional<FairOptions::Kind> fair_kind(const std::string& method) {
  if (method == "taubin") return FairOptions::Kind::taubin;
  if (method == "laplacian") return FairOptions::Kind::laplacian;
  return std::nullopt;
}

nlohmann::json smooth_stats_json(const SmoothStats& st) {
  return {{"iterations", st.iterations},
          {"converged", st.converged},
          {"last_max_change", st.last_max_change},
          {"seconds", st.seconds}};
}

void bind_simplify(CLI::App& cmd, SimplifyOptions& o) {
  auto* g = cmd.add_option_group("simplify", "Fewer triangles, every sample still on its side");
  g->add_option("--faces", o.faces, "Simplify to at most this many triangles (fewer collapses only where one would "
                                    "move a sample across, fold or cross the surface, or exceed --max-error)");
  g->add_option("--max-error", o.max_error, "Simplify, keeping every input vertex within this distance of the result "
                                            "(physical units, e.g. mm; with --faces, both hold)")
      ->check(CLI::Range(0.0, 1e30));
}

nlohmann::json simplify_stats_json(const SimplifyStats& st, const SimplifyOptions& o) {
  return {{"faces_target", o.faces},          {"max_error", o.max_error},
          {"faces_before", st.faces_before},  {"faces", st.faces_after},
          {"vertices", st.vertices_after},    {"collapses", st.collapses},
          {"in_plane", st.in_plane},
          {"error", st.error},
          {"refused", {{"topology", st.refused_topology}, {"shape", st.refused_shape}, {"samples", st.refused_samples},
                       {"clash", st.refused_clash}, {"error", st.refused_error}}},
          {"seconds", st.seconds}};
}

nlohmann::json press_stats_json(const PressStats& st, const PressOptions& o) {
  return {{"iterations", st.iterations},    {"max_iterations", o.iterations},
          {"residual", st.residual}, {"tolerance", o.tolerance}, {"curves", st.curves},
          {"fresh", st.fresh},              {"frozen", st.frozen},
          {"seconds", st.seconds},          {"levels", st.levels},
          {"momentum", o.momentum},         {"arc_length", o.arc_length},
          {"step", o.step},                 {"resample", o.resample},
          {"free_ends", o.free_ends}};
}

namespace {

nlohmann::json report_checks(const MeshCheck& mc, const ClassificationReport& cr, const std::string& what, bool strict) {
  if (strict && (!mc.ok() || cr.violations))
    throw Error("the " + what + " surface failed its checks: " +
                (mc.problems.empty() ? std::to_string(cr.violations) + " classification violations" : mc.problems[0]));
  return {{"mesh_ok", mc.ok()},
          {"closed", mc.closed()},
          {"manifold", mc.manifold()},
          {"oriented", mc.oriented()},
          {"self_intersections", mc.self_intersections},
          {"problems", mc.problems},
          {"classification_violations", cr.violations}};
}

}  // namespace

nlohmann::json check_surface(const Mesh& mesh, const BinaryVolume& volume, Progress* progress, const std::string& what,
                             bool strict) {
  const MeshCheck mc = check_mesh(mesh);
  ClassificationOptions co;
  co.progress = progress;
  return report_checks(mc, check_classification(mesh, volume, co), what, strict);
}

nlohmann::json check_surface(const Mesh& mesh, const Lattice& lattice, const PlaneReader& planes, Progress* progress,
                             const std::string& what, bool strict) {
  const MeshCheck mc = check_mesh(mesh);
  ClassificationOptions co;
  co.progress = progress;
  return report_checks(mc, check_classification(mesh, lattice, planes, co), what, strict);
}

void PlacementCli::bind(CLI::App& cmd, const std::string& what) {
  cmd.add_option("--res", res, "Samples along the physically longest side")->capture_default_str();
  cmd.add_option("--rotate", rotate, "random:SEED, AX,AY,AZ in degrees, or none")->capture_default_str();
  cmd.add_option("--spacing", spacing, "Cell size SX,SY,SZ (anisotropic lattices)")->capture_default_str();
  cmd.add_option("--margin", margin, "Outside samples around the " + what)->capture_default_str();
}

nlohmann::json lattice_json(const Lattice& l) {
  nlohmann::json j;
  j["dims"] = {l.dims[0], l.dims[1], l.dims[2]};
  j["spacing"] = {l.spacing.x(), l.spacing.y(), l.spacing.z()};
  j["origin"] = {l.origin.x(), l.origin.y(), l.origin.z()};
  nlohmann::json d = nlohmann::json::array();
  for (int a = 0; a < 3; ++a) d.push_back({l.direction(0, a), l.direction(1, a), l.direction(2, a)});
  j["direction_columns"] = d;
  j["space"] = space_name(l.space);
  return j;
}

namespace {
// The same file: by identity when both exist, by their absolute, normal
// paths otherwise.
bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(fs::absolute(a), ec) == fs::weakly_canonical(fs::absolute(b), ec);
}
}  // namespace

void check_paths(const std::vector<std::string>& inputs,
                 const std::vector<std::pair<std::string, OutputKind>>& outputs) {
  namespace fs = std::filesystem;
  std::vector<std::string> all;
  for (const auto& p : inputs)
    if (!p.empty()) all.push_back(p);
  for (const auto& o : outputs)
    if (!o.first.empty()) all.push_back(o.first);
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size(); ++j)
      if (same_file(all[i], all[j]))
        throw UsageError(all[j] + ": names the same file as " + all[i] + " (each input and output needs its own)");
  for (const auto& [path, kind] : outputs) {
    // -o "" failed after the whole press with "unknown mesh format ''" (issue
    // 73); the other kinds are optional outputs, empty when not asked for.
    if (path.empty() && kind != OutputKind::json && kind != OutputKind::features)
      throw UsageError("-o: the output file name is empty");
    if (path.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw UsageError(path + ": is a folder; give a file name for the output");
    const std::string ext = file_extension(path);
    auto known = [&](std::initializer_list<const char*> exts) {
      for (const char* e : exts)
        if (ext == e) return true;
      return false;
    };
    const char* expected = nullptr;
    switch (kind) {
      case OutputKind::mesh:
        if (!known({".ply", ".obj", ".stl", ".off", ".glb", ".gltf", ".vtk", ".vtp"}))
          expected = ".ply .obj .stl .off .glb .gltf .vtk .vtp";
        break;
      case OutputKind::volume:
        if (!known({".nrrd", ".seg.nrrd", ".nii", ".nii.gz", ".mha", ".tif", ".tiff", ".h5", ".hdf5"}))
          expected = ".nrrd .nii .nii.gz .mha .tif .h5";
        break;
      case OutputKind::json: if (!known({".json"})) expected = ".json"; break;
      case OutputKind::png: if (!known({".png"})) expected = ".png"; break;
      case OutputKind::svg: if (!known({".svg"})) expected = ".svg"; break;
      case OutputKind::html: if (!known({".html", ".htm"})) expected = ".html"; break;
      case OutputKind::features: if (!known({".ply", ".obj"})) expected = ".ply .obj"; break;
    }
    if (expected)
      throw UsageError(path + ": unknown output format '" + ext + "' (use " + expected + ")");
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    if (!fs::is_directory(dir, ec)) throw UsageError(path + ": the output folder " + dir.string() + " does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw UsageError(path + ": the output folder " + dir.string() + " is not writable");
  }
}

void write_json(const std::string& path, const nlohmann::json& j) {
  const std::string text = j.dump(2) + "\n";
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

uint64_t peak_rss_bytes() {
  // VmHWM belongs to this address space (reset by exec), unlike ru_maxrss,
  // which a child spawned with vfork semantics inherits from its parent.
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return uint64_t(std::stoull(line.substr(6))) * 1024;
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return uint64_t(ru.ru_maxrss) * 1024;
}

Vec3 parse_vec3(const std::string& text, const std::string& option) {
  std::stringstream in(text);
  std::string part;
  Vec3 v;
  int n = 0;
  while (std::getline(in, part, ',')) {
    if (n >= 3) throw UsageError(option + " expects three comma-separated numbers, got '" + text + "'");
    try {
      size_t used = 0;
      v[n] = std::stod(part, &used);
      if (used != part.size() || !std::isfinite(v[n])) throw std::invalid_argument("junk");
    } catch (const std::exception&) {
      throw UsageError(option + " expects three comma-separated numbers, got '" + text + "'");
    }
    ++n;
  }
  if (n != 3) throw UsageError(option + " expects three comma-separated numbers, got '" + text + "'");
  return v;
}

// The feature layer's pass table as run: name, paper section, stage, rule
// (a decision inside a pass) or step, on/off, seconds and the pass's own
// count (vertices placed, flats found, ...).
nlohmann::json passes_json(const PassSet& on, const PassTimes& t) {
  static const char* const stages[] = {"detect", "press", "crease-round", "fit", "sharpen"};
  nlohmann::json list = nlohmann::json::array();
  for (const PassInfo& p : feature_passes())
    list.push_back({{"name", p.name},
                    {"section", p.section},
                    {"stage", stages[size_t(p.stage)]},
                    {"rule", p.run == nullptr},
                    {"enabled", on.on(p.pass)},
                    {"seconds", t.seconds[size_t(p.pass)]},
                    {"count", t.count[size_t(p.pass)]}});
  return list;
}

}  // namespace voxpress::cli
