// bench/compare: every method over every case, evaluated against the truth,
// written as a Markdown table into docs/BENCHMARKS.md (between the markers
// <!-- compare:begin --> and <!-- compare:end -->).
//
// Cases: the generated shapes at 64, 128 and 256 samples (random rotations),
// and the meshes of ../shared/data voxelized at 128 and 256 (when present).
// Each method runs as its own `voxpress` process so that its wall time and
// peak memory are its own (the process reports its VmHWM in --stats-json:
// wait4's ru_maxrss would include this parent, which posix_spawn shares
// memory with until exec); the result is then evaluated in this process.
//
//   build/bench/bench_compare --cli build/bin/voxpress [--quick] [--write docs/BENCHMARKS.md]
#include <spawn.h>
#include <sys/wait.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

extern char** environ;

namespace {

using namespace voxpress;
namespace fs = std::filesystem;

struct CliMethod {
  std::string name;
  std::vector<std::string> args;  // with IN and OUT placeholders
};

// Methods join this list as they land.
const std::vector<CliMethod> kMethods = {
    {"midpoint", {"extract", "IN", "-o", "OUT"}},
    {"pressing, no flats", {"press", "IN", "-o", "OUT", "--no-flats"}},
    {"pressing, no sharpen", {"press", "IN", "-o", "OUT", "--no-sharpen"}},
    {"pressing", {"press", "IN", "-o", "OUT"}},
    {"taubin", {"press", "IN", "-o", "OUT", "--method", "taubin"}},
    {"laplacian", {"press", "IN", "-o", "OUT", "--method", "laplacian"}},
    {"cesn", {"press", "IN", "-o", "OUT", "--method", "cesn"}},
    {"cell-size (Bade)", {"press", "IN", "-o", "OUT", "--method", "cell-size"}},
    {"cell-edge (Bade)", {"press", "IN", "-o", "OUT", "--method", "cell-edge"}},
    {"diamond (Bade)", {"press", "IN", "-o", "OUT", "--method", "diamond"}},
};

struct Run {
  double seconds = 0;
  double peak_mib = 0;  // from the process's --stats-json
  int status = -1;
};

Run run(const std::string& cli, const std::vector<std::string>& args) {
  std::vector<std::string> argv_s{cli, "-q"};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  pid_t pid;
  Run r;
  if (posix_spawn(&pid, cli.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return r;
  int status = 0;
  waitpid(pid, &status, 0);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

struct Case {
  std::string name;
  std::string volume_path;
  std::unique_ptr<Truth> truth;
  BinaryVolume volume;
};

std::string fmt(double v, int digits = 4) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"voxpress method comparison"};
  std::string cli = "build/bin/voxpress", write, data = "../shared/data";
  bool quick = false;
  size_t samples = 200000;
  std::vector<std::string> only;
  app.add_option("--cli", cli, "voxpress executable")->capture_default_str();
  app.add_option("--write", write, "Markdown file whose compare section is replaced");
  app.add_option("--data", data, "Shared data folder (meshes/ is used when present)")->capture_default_str();
  app.add_option("--samples", samples, "Area samples per direction")->capture_default_str();
  app.add_flag("--quick", quick, "Only 64 and 128 for generated shapes, 128 for meshes");
  app.add_option("--only", only, "Only these methods (names as in the table, e.g. pressing midpoint)");
  CLI11_PARSE(app, argc, argv);

  const fs::path work = fs::temp_directory_path() / ("voxpress-compare-" + std::to_string(::getpid()));
  fs::create_directories(work);
  std::vector<int64_t> shape_res = quick ? std::vector<int64_t>{64, 128} : std::vector<int64_t>{64, 128, 256};
  std::vector<int64_t> mesh_res = quick ? std::vector<int64_t>{128} : std::vector<int64_t>{128, 256};

  std::ostringstream md;
  md << "Command: `bench/compare` (" << samples << " area samples per direction; times and peak memory of the whole "
     << "`voxpress` process: read, method, write). Distances in voxels. Stick = Pressing Table 2 metric (n/a when fewer than half the vertices lie on sticks). "
     << "r→t / t→r: result-to-truth / truth-to-result. Viol. = samples on the wrong side. Sharp H = two-sided "
     << "Hausdorff between the true sharp curves (dihedral > 30°) and the labelled ones; sharp found = share of the "
     << "true sharp curves' length within half a voxel of a labelled one (recall) / of the labelled length within "
     << "half a voxel of a true one (precision).\n\n";
  md << "| case | method | stick RMS | r→t RMS | t→r RMS | r→t max | t→r max | normal err. | sharp H | sharp found | viol. | "
        "triangles | time | peak |\n";
  md << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";

  auto do_case = [&](Case& c) {
    for (const CliMethod& m : kMethods) {
      if (!only.empty() && std::find(only.begin(), only.end(), m.name) == only.end()) continue;
      const std::string out = (work / (c.name + "-" + m.name + ".ply")).string();
      const std::string stats = (work / "stats.json").string();
      std::vector<std::string> args;
      for (const auto& a : m.args) args.push_back(a == "IN" ? c.volume_path : a == "OUT" ? out : a);
      args.push_back("--stats-json");
      args.push_back(stats);
      Run r = run(cli, args);
      if (r.status == 0) {
        std::ifstream in(stats);
        r.peak_mib = double(nlohmann::json::parse(in).value("peak_memory_bytes", uint64_t(0))) / (1 << 20);
      }
      if (r.status != 0) {
        md << "| " << c.name << " | " << m.name << " | failed (exit " << r.status << ") |||||||||||\n";
        continue;
      }
      const Mesh result = read_mesh(out);
      EvalOptions eo;
      eo.volume = &c.volume;
      eo.samples = samples;
      eo.self_intersections = false;
      const EvalReport e = evaluate(result, *c.truth, eo);
      // The stick metric needs the vertices on their sticks; methods that
      // move them off (Taubin, CESN, cell-size, diamond) only have a few
      // there by accident.
      const bool on_sticks = e.stick_rms_vox && 2 * e.stick_vertices >= e.vertices;
      md << "| " << c.name << " | " << m.name << " | " << (on_sticks ? fmt(*e.stick_rms_vox) : "n/a") << " | "
         << fmt(e.result_to_truth_vox.rms) << " | " << fmt(e.truth_to_result_vox.rms) << " | "
         << fmt(e.result_to_truth_vox.max, 3) << " | " << fmt(e.truth_to_result_vox.max, 3) << " | "
         << fmt(e.normal_error_deg, 2) << "° | "
         << (e.sharp_edge_hausdorff_vox ? fmt(*e.sharp_edge_hausdorff_vox, 3) : std::string("-")) << " | "
         << (!e.sharp_recall      ? std::string("-")
             : e.sharp_precision ? fmt(100 * *e.sharp_recall, 1) + " / " + fmt(100 * *e.sharp_precision, 1) + " %"
                                 : fmt(100 * *e.sharp_recall, 1) + " %")
         << " | "
         << *e.classification_violations << " | " << e.faces << " | "
         << fmt(r.seconds, 2) << " s | " << fmt(r.peak_mib, 0) << " MiB |\n";
      std::fprintf(stderr, "%-28s %-10s stick %s r->t %.4f normal %.2f\n", c.name.c_str(), m.name.c_str(),
                   on_sticks ? fmt(*e.stick_rms_vox).c_str() : "n/a", e.result_to_truth_vox.rms,
                   e.normal_error_deg);
      fs::remove(out);
    }
  };

  for (ShapeKind k : all_shapes())
    for (int64_t res : shape_res) {
      Case c;
      c.name = std::string(shape_name(k)) + " " + std::to_string(res);
      GenerateOptions o;
      o.res = res;
      o.rotation = parse_rotation("random:" + std::to_string(res));
      GeneratedShape g = generate_shape(k, o);
      c.volume_path = (work / (std::string(shape_name(k)) + std::to_string(res) + ".nrrd")).string();
      write_volume(c.volume_path, to_scalar(g.volume));
      c.truth = shape_truth(k, g.linear, g.translation);
      c.volume = std::move(g.volume);
      do_case(c);
    }
  const fs::path meshes = fs::path(data) / "meshes";
  if (fs::exists(meshes)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(meshes)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files)
      for (int64_t res : mesh_res) {
        Case c;
        c.name = f.filename().string() + " " + std::to_string(res);
        const Mesh model = read_mesh(f.string());
        VoxelizeOptions o;
        o.res = res;
        o.rotation = parse_rotation("random:" + std::to_string(res));
        Voxelized v = voxelize(model, o, f.string());
        c.volume_path = (work / (f.stem().string() + std::to_string(res) + ".nrrd")).string();
        write_volume(c.volume_path, to_scalar(v.volume));
        Mesh physical = model;
        for (Vec3& p : physical.positions) p = v.placement.translation + v.placement.linear * p;
        c.truth = mesh_truth(std::move(physical), f.filename().string());
        c.volume = std::move(v.volume);
        do_case(c);
      }
  } else {
    md << "\n(`" << meshes.string() << "` absent: shared meshes skipped.)\n";
  }
  fs::remove_all(work);

  const std::string table = md.str();
  if (write.empty()) {
    std::printf("%s", table.c_str());
    return 0;
  }
  std::ifstream in(write);
  std::stringstream doc;
  doc << in.rdbuf();
  std::string text = doc.str();
  const std::string begin = "<!-- compare:begin -->", end = "<!-- compare:end -->";
  const auto b = text.find(begin), e = text.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    std::fprintf(stderr, "%s has no %s ... %s section\n", write.c_str(), begin.c_str(), end.c_str());
    return 1;
  }
  text = text.substr(0, b + begin.size()) + "\n" + table + text.substr(e);
  write_file_atomically(write, [&](std::ostream& out) { out << text; });
  std::fprintf(stderr, "updated %s\n", write.c_str());
  return 0;
}
