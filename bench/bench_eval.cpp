// Voxelization and evaluation throughput (issue 3):
//   Voxelize/armadillo/256   the largest mesh of ../shared/data (86 k faces) at 256 (skipped when absent)
//   Eval/analytic            a 1.1 M-vertex result (sphere midpoint surface at 512) against the analytic sphere
//   Eval/mesh                the same result against a 1 M-triangle mesh truth
// Times are wall-clock for one call; 400 k area samples per direction.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

std::string shared_mesh(const char* name) {
  for (const char* base : {"../shared/data/meshes/", "../../shared/data/meshes/", "../../../shared/data/meshes/"})
    if (std::filesystem::exists(std::string(base) + name)) return std::string(base) + name;
  return "";
}

void Voxelize(benchmark::State& state) {
  const std::string path = shared_mesh("armadillo.obj");
  if (path.empty()) {
    state.SkipWithError("../shared/data/meshes/armadillo.obj is absent");
    return;
  }
  const Mesh model = read_mesh(path);
  VoxelizeOptions o;
  o.res = state.range(0);
  o.rotation = parse_rotation("random:1");
  uint64_t inside = 0;
  for (auto _ : state) inside = voxelize(model, o, path).volume.count_inside();
  state.counters["faces"] = double(model.triangles.size());
  state.counters["inside"] = double(inside);
}

struct EvalFixture {
  GeneratedShape shape;
  Mesh result;
  std::unique_ptr<Truth> analytic, mesh;
  EvalFixture() {
    GenerateOptions o;
    o.res = 512;
    o.rotation = parse_rotation("random:2");
    shape = generate_shape(ShapeKind::sphere, o);
    result = to_mesh(extract_sticks(shape.volume));
    analytic = shape_truth(ShapeKind::sphere, shape.linear, shape.translation);
    // A ~1 M-triangle truth: a finer sphere's midpoint mesh projected onto the sphere.
    GenerateOptions fine;
    fine.res = 360;
    const GeneratedShape f = generate_shape(ShapeKind::sphere, fine);
    Mesh m = to_mesh(extract_sticks(f.volume));
    for (Vec3& p : m.positions)
      p = shape.translation + shape.scale * (p - f.translation).normalized();
    mesh = mesh_truth(std::move(m), "fine sphere");
  }
};

EvalFixture& fixture() {
  static EvalFixture f;
  return f;
}

void Eval(benchmark::State& state) {
  EvalFixture& f = fixture();
  const Truth& truth = state.range(0) == 0 ? *f.analytic : *f.mesh;
  EvalOptions o;
  o.volume = &f.shape.volume;
  o.self_intersections = false;
  EvalReport r;
  for (auto _ : state) r = evaluate(f.result, truth, o);
  state.counters["result_vertices"] = double(f.result.positions.size());
  state.counters["stick_rms"] = r.stick_rms_vox.value_or(-1);
  state.SetLabel(truth.describe());
}

BENCHMARK(Voxelize)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(Eval)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
