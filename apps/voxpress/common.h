// Shared pieces of the voxpress subcommands: global options, the progress
// bar, input selection (labels, thresholds, raw layouts) and --stats-json.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "voxpress/voxpress.h"

namespace voxpress::cli {

/// Options every subcommand shares (bound on the main app).
struct Global {
  int threads = 0;             ///< 0 = all cores
  bool quiet = false;
  std::string max_memory;      ///< e.g. "8G"; empty = default_memory_limit()
  uint64_t memory_limit() const { return max_memory.empty() ? default_memory_limit() : parse_byte_size(max_memory); }
  /// Applies --threads (once, before a subcommand runs).
  void apply() const;
};

/// A progress bar on stderr, drawn only when stderr is a terminal and
/// --quiet is off; thread-safe and throttled.
class ProgressBar : public Progress {
 public:
  explicit ProgressBar(bool enabled);
  void begin(std::string_view stage, uint64_t total) override;
  bool update(uint64_t done) override;
  void end() override;
  Progress* get() { return enabled_ ? this : nullptr; }

 private:
  void draw(uint64_t done, bool final);
  bool enabled_;
  std::mutex m_;
  std::string stage_;
  uint64_t total_ = 1;
  int last_percent_ = -1;
};

/// How a volume file becomes a binary volume.
struct InputOptions {
  std::string label;               ///< "N" or "all-nonzero"
  std::optional<double> threshold;
  std::string segment;
  std::string raw_dims, raw_type = "uint8", raw_spacing, raw_origin;
  bool raw_big_endian = false;
  int64_t raw_header_bytes = 0;  // signed: -1 wrapped to 2^64-1 (issue 73)

  /// Adds --label, --threshold, --segment and the --raw-* options to a command.
  void bind(CLI::App& cmd);
  ReadOptions read_options(const Global& g) const;
  Selection selection() const;
};

ScalarVolume load_volume(const std::string& path, const InputOptions& in, const Global& g);
/// Reads, binarises and checks that the volume is neither empty nor full.
BinaryVolume load_binary(const std::string& path, const InputOptions& in, const Global& g);

/// A volume read, binarised and turned into its stick surface: the first
/// steps of `extract` and `press`.
struct VolumeSurface {
  BinaryVolume volume;
  StickSurface surface;
  ExtractStats stats;
  double seconds_read = 0, seconds_extract = 0;
};
VolumeSurface load_surface(const std::string& path, const InputOptions& in, const Global& g, Progress* progress);
/// The --stats-json fields `extract` and `press` share: command, input,
/// output, lattice and counts.
nlohmann::json surface_stats_json(const char* command, const std::string& input, const std::string& output,
                                  const Lattice& lattice, const ExtractStats& extract, const Mesh& mesh);

/// Parses "a,b,c" into a Vec3 (for --spacing, --raw-spacing, ...).
Vec3 parse_vec3(const std::string& text, const std::string& option);

/// The smoothing options of `press` and `press2d`.
struct PressCli {
  PressOptions options;
  std::string weighting = "equal";
  bool plain = false;
  bool fixed_ends = false;
  CLI::Option* iterations_option = nullptr;  ///< to tell a given --iterations from the default
  CLI::Option* tolerance_option = nullptr;
  /// `barriers`: the command presses next to flats (press), so --fixed-ends applies.
  void bind(CLI::App& cmd, bool barriers = true);
  /// The options with the weighting, --plain and --fixed-ends applied; throws UsageError.
  PressOptions resolve() const;
};
nlohmann::json press_stats_json(const PressStats& st, const PressOptions& o);

/// Adds --lambda and --mu (Taubin / Laplacian) to a command or group.
void bind_fairing(CLI::App& cmd, MethodOverrides& overrides);
/// "taubin" or "laplacian" -> its kind; nullopt otherwise.
std::optional<FairOptions::Kind> fair_kind(const std::string& method);
nlohmann::json smooth_stats_json(const SmoothStats& st);

/// Adds --faces and --max-error (the simplifier) to a command.
void bind_simplify(CLI::App& cmd, SimplifyOptions& o);
nlohmann::json simplify_stats_json(const SimplifyStats& st, const SimplifyOptions& o);
// The feature layer's pass table as run (--stats-json "passes").
nlohmann::json passes_json(const PassSet& on, const PassTimes& t);

/// `--check` of extract and press: check_mesh and the classification against
/// the volume, before anything is written. When strict (methods that promise
/// both), throws Error ("the <what> surface failed its checks: ...") on a
/// failure; returns the "checks" object for --stats-json.
nlohmann::json check_surface(const Mesh& mesh, const BinaryVolume& volume, Progress* progress, const std::string& what,
                             bool strict = true);
/// The same with the volume read a slab of planes at a time (press --chunk).
nlohmann::json check_surface(const Mesh& mesh, const Lattice& lattice, const PlaneReader& planes, Progress* progress,
                             const std::string& what, bool strict = true);

/// --res --rotate --spacing --margin: how generate and voxelize place a solid
/// on a new lattice (GenerateOptions and VoxelizeOptions share these fields).
struct PlacementCli {
  std::string rotate = "none", spacing = "1,1,1";
  int64_t res, margin = 2;
  explicit PlacementCli(int64_t default_res) : res(default_res) {}
  /// `what` names the solid in the help ("shape", "model").
  void bind(CLI::App& cmd, const std::string& what);
  template <class Options>
  void apply(Options& o, const Global& g, Progress* progress) const {
    o.res = res;
    o.margin = margin;
    o.rotation = parse_rotation(rotate);
    o.spacing = parse_vec3(spacing, "--spacing");
    o.max_bytes = g.memory_limit();
    o.progress = progress;
  }
};

/// Wall-clock stopwatch for --stats-json.
class Stopwatch {
 public:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

/// What an output path must name (its extension).
enum class OutputKind { mesh, volume, json, png, svg, html, features };
/// Before any work: each output's folder exists and is writable, the output
/// is not a folder and its extension is one its kind writes; no two paths of
/// the command (inputs and outputs; empty ones are skipped) name the same
/// file. Throws UsageError naming the path.
void check_paths(const std::vector<std::string>& inputs,
                 const std::vector<std::pair<std::string, OutputKind>>& outputs);

nlohmann::json lattice_json(const Lattice& l);
/// Writes a JSON document atomically (pretty-printed).
void write_json(const std::string& path, const nlohmann::json& j);
/// Peak resident memory of this process so far (VmHWM), in bytes.
uint64_t peak_rss_bytes();


/// `press --labels`: one mesh per label into a folder (cmd_press_labels.cpp).
struct LabelOutput {
  std::string labels;      ///< "all" or "1,5,7"
  std::string names_file;  ///< --label-names: "VALUE NAME" lines
  std::string folder;      ///< -o
  std::string format = "ply";
  std::string stats_json;
  bool ascii = false, check = false;
  bool separate = false;   ///< --separate: each label alone (press_labels), not the shared surface
  std::optional<ChunkOptions> chunks;  ///< --chunk: the file read block by block
};
/// Throws UsageError for an unknown format, an -o that is a file, a missing
/// or unwritable parent folder: before any work.
void check_label_output(const LabelOutput& o);
void run_press_labels(const std::string& input, const InputOptions& in, const SurfaceOptions& options,
                      const LabelOutput& o, const Global& g);

// Subcommand registration (one file each).
void register_info(CLI::App& app, Global& g);
void register_extract(CLI::App& app, Global& g);
void register_generate(CLI::App& app, Global& g);
void register_check(CLI::App& app, Global& g);
void register_voxelize(CLI::App& app, Global& g);
void register_eval(CLI::App& app, Global& g);
void register_press(CLI::App& app, Global& g);
void register_press2d(CLI::App& app, Global& g);
void register_smooth_mesh(CLI::App& app, Global& g);
void register_voxart(CLI::App& app, Global& g);
void register_render(CLI::App& app, Global& g);
void register_report(CLI::App& app, Global& g);

/// Paths the render and report commands accept besides volumes.
bool is_mesh_path(const std::string& path);       ///< .ply .obj .stl .off (readable meshes)
bool is_voxel_art_path(const std::string& path);  ///< .vox .vxl
/// A volume's surface for display: "voxels" (cell faces), "midpoint", or a
/// press method name with its defaults (throws UsageError otherwise). For a
/// press method, `result` (when given) receives its stats (mesh moved out).
/// `max_bytes`: the memory cap for the surface and its making with what the
/// caller holds besides the volume, `held_bytes` (0: no cap).
Mesh display_surface(const BinaryVolume& volume, const std::string& method, uint64_t max_bytes, uint64_t held_bytes,
                     SurfaceResult* result = nullptr);

}  // namespace voxpress::cli
