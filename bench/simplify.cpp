// bench_simplify: voxpress's simplifier against meshoptimizer's
// meshopt_simplify at the same face counts, in the same run (issue 76).
//
// Each case is pressed by the default pipeline; then, per ratio of its
// faces, both simplifiers reduce that mesh and each result is measured
// against the exact truth by evaluate() (RMS result -> truth and Hausdorff
// in voxels, mean normal error), checked (check_mesh, the classification of
// every sample) and timed (the simplification alone, one thread).
//
//   build/bench/bench_simplify --shape cad-part --res 128 --rotate random:1
//   build/bench/bench_simplify --model ../shared/data/meshes/fandisk.off --res 128
//   build/bench/bench_simplify --volume ../shared/data/medical/totalseg_aorta.nii.gz
// A real volume has no truth: its rows measure against the unsimplified
// pressed surface instead.
#include <meshoptimizer.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <unistd.h>
#include <sstream>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

std::vector<double> split(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stod(item));
  return out;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// meshopt_simplify to `faces` triangles, no error cap, the default options
// (its edge-collapse keeps the topology; float positions as it takes them).
Mesh meshopt(const Mesh& in, uint64_t faces, double& seconds) {
  std::vector<float> pos(3 * in.positions.size());
  for (size_t v = 0; v < in.positions.size(); ++v)
    for (int k = 0; k < 3; ++k) pos[3 * v + size_t(k)] = float(in.positions[v][k]);
  std::vector<uint32_t> idx(3 * in.triangles.size());
  for (size_t f = 0; f < in.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) idx[3 * f + size_t(k)] = in.triangles[f][size_t(k)];
  std::vector<uint32_t> out(idx.size());
  const auto t0 = std::chrono::steady_clock::now();
  float error = 0;
  out.resize(meshopt_simplify(out.data(), idx.data(), idx.size(), pos.data(), in.positions.size(), 12, 3 * faces, 1.0f,
                              0, &error));
  seconds = seconds_since(t0);
  Mesh m;
  std::vector<uint32_t> remap(in.positions.size(), UINT32_MAX);
  for (size_t i = 0; i < out.size(); i += 3) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      uint32_t& r = remap[out[i + size_t(k)]];
      if (r == UINT32_MAX) {
        r = uint32_t(m.positions.size());
        m.positions.push_back(in.positions[out[i + size_t(k)]]);
      }
      t[size_t(k)] = r;
    }
    m.triangles.push_back(t);
  }
  return m;
}

struct Row {
  std::string who;
  uint64_t faces = 0;
  double seconds = 0, rms = 0, hausdorff = 0, normal = 0;
  uint64_t violations = 0, intersections = 0;
  uint64_t stl_violations = 0, stl_intersections = 0;  // the mesh written as STL (float32) and read back
  bool ok = false;
};

Row measure(const std::string& who, const Mesh& m, double seconds, const Truth& truth, const BinaryVolume& volume,
            size_t samples) {
  EvalOptions eo;
  eo.volume = &volume;
  eo.samples = samples;
  const EvalReport e = evaluate(m, truth, eo);
  Row r;
  r.who = who;
  r.faces = m.triangles.size();
  r.seconds = seconds;
  r.rms = e.result_to_truth_vox.rms;
  r.hausdorff = e.hausdorff_vox.value_or(0);
  r.normal = e.normal_error_deg;
  r.violations = e.classification_violations.value_or(0);
  r.intersections = e.mesh.self_intersections;
  r.ok = e.mesh.ok();
  const std::string stl = "/tmp/bench_simplify_" + std::to_string(::getpid()) + ".stl";
  write_mesh(stl, m);
  const Mesh back = read_mesh(stl);
  std::remove(stl.c_str());
  r.stl_violations = check_classification(back, volume).violations;
  r.stl_intersections = check_mesh(back).self_intersections;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"voxpress's simplifier against meshopt_simplify at the same face counts"};
  std::string shape = "cad-part", model, volume_file, rotate = "random:1", ratios_arg = "0.1,0.02,0.005";
  int64_t res = 128;
  size_t samples = 100000;
  app.add_option("--shape", shape, "Generated shape (sphere, torus, box, cylinder, cad-part)")->capture_default_str();
  app.add_option("--model", model, "A closed mesh to voxelize instead (its own truth)");
  app.add_option("--volume", volume_file, "A real volume (mask): measured against its unsimplified pressed surface");
  app.add_option("--res", res, "Resolution")->capture_default_str();
  app.add_option("--rotate", rotate, "Rotation (random:N, AX,AY,AZ or none)")->capture_default_str();
  app.add_option("--ratios", ratios_arg, "Face ratios")->capture_default_str();
  app.add_option("--samples", samples, "Area samples per direction for the metrics")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  BinaryVolume volume;
  std::unique_ptr<Truth> truth;
  std::string name;
  if (!volume_file.empty()) {
    volume = binarize(read_volume(volume_file), Selection{});
    name = volume_file;
  } else if (!model.empty()) {
    const Mesh m = read_mesh(model);
    VoxelizeOptions vo;
    vo.res = res;
    vo.rotation = parse_rotation(rotate);
    Voxelized v = voxelize(m, vo, model);
    Mesh physical = m;
    for (Vec3& p : physical.positions) p = v.placement.translation + v.placement.linear * p;
    volume = std::move(v.volume);
    truth = mesh_truth(std::move(physical), model);
    name = model;
  } else {
    GenerateOptions go;
    go.res = res;
    go.rotation = parse_rotation(rotate);
    const ShapeKind kind = parse_shape(shape);
    GeneratedShape g = generate_shape(kind, go);
    truth = shape_truth(kind, g.linear, g.translation);
    volume = std::move(g.volume);
    name = shape;
  }
  auto t0 = std::chrono::steady_clock::now();
  const SurfaceResult pressed = smooth_surface(volume);
  const double press_seconds = seconds_since(t0);
  const Mesh& full = pressed.mesh;
  if (!truth) truth = mesh_truth(full, "the pressed surface");
  std::vector<Row> rows{measure("pressed", full, press_seconds, *truth, volume, samples)};
  for (double ratio : split(ratios_arg)) {
    const uint64_t faces = uint64_t(ratio * double(full.triangles.size()));
    Mesh ours = full;
    SimplifyOptions so;
    so.faces = faces;
    so.lattice = &volume.lattice;
    t0 = std::chrono::steady_clock::now();
    simplify(ours, so);
    rows.push_back(measure("voxpress " + std::to_string(ratio), ours, seconds_since(t0), *truth, volume, samples));
    double s = 0;
    const Mesh theirs = meshopt(full, faces, s);
    rows.push_back(measure("meshopt " + std::to_string(ratio), theirs, s, *truth, volume, samples));
  }
  std::printf("%s, res %lld, rotation %s (%zu faces pressed)\n", name.c_str(), (long long)res, rotate.c_str(),
              full.triangles.size());
  std::printf("| simplifier, ratio | faces | seconds | RMS r->t (vox) | Hausdorff (vox) | normal (deg) | samples on the "
              "wrong side | self-intersections | the same as STL |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows)
    std::printf("| %s | %llu | %.3f | %.4f | %.3f | %.2f | %llu | %llu | %llu / %llu |\n", r.who.c_str(),
                (unsigned long long)r.faces, r.seconds, r.rms, r.hausdorff, r.normal, (unsigned long long)r.violations,
                (unsigned long long)r.intersections, (unsigned long long)r.stl_violations,
                (unsigned long long)r.stl_intersections);
  return 0;
}
