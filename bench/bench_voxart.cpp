// bench_voxart: per-step times of the voxel-art pipeline (Muniz et al.,
// Table 1) on the largest .vox / .vxl files of ../shared/data (skipped when
// absent) and on generated coloured models (a 60 k-voxel ball, a 128^3
// blob). Medians over runs; prints a Markdown table (docs/BENCHMARKS.md).
//   build/bench/bench_voxart [--runs N] [--shared DIR]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

// A ball of the given radius coloured in bands (about 4/3 pi r^3 voxels).
ColorGrid ball(int64_t r) {
  ColorGrid g;
  const int64_t n = 2 * r + 2;
  g.dims = {n, n, n};
  g.voxels.assign(size_t(n * n * n), Rgba{0, 0, 0, 0});
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i) {
        const double x = double(i) + 0.5 - double(n) / 2, y = double(j) + 0.5 - double(n) / 2, z = double(k) + 0.5 - double(n) / 2;
        if (x * x + y * y + z * z < double(r * r))
          g.voxels[g.index(i, j, k)] = {uint8_t(40 * ((k / 4) % 6)), uint8_t(200 - 30 * ((i / 5) % 5)), 90, 255};
      }
  g.name = "ball";
  return g;
}

// A 128^3 organic blob: union of smooth bumps, coloured by height and angle.
ColorGrid blob128() {
  ColorGrid g;
  const int64_t n = 128;
  g.dims = {n, n, n};
  g.voxels.assign(size_t(n * n * n), Rgba{0, 0, 0, 0});
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i) {
        const double x = (double(i) - 64) / 50, y = (double(j) - 64) / 50, z = (double(k) - 64) / 50;
        const double f = x * x + y * y + z * z - 0.55 - 0.18 * std::sin(5 * x) * std::cos(4 * y) - 0.12 * std::sin(6 * z + 2 * x);
        if (f < 0)
          g.voxels[g.index(i, j, k)] = {uint8_t(60 + 30 * (k / 16)), uint8_t(100 + 20 * ((i + j) / 32 % 5)), uint8_t(200 - k), 255};
      }
  g.name = "blob128";
  return g;
}

struct Row {
  std::string name;
  VoxartStats st;
  double taubin = 0;
};

VoxartStats median_run(const VoxelArt& art, const VoxartOptions& o, int runs) {
  std::vector<VoxartStats> all;
  for (int r = 0; r < runs; ++r) all.push_back(polygonize_voxel_art(art, o).stats);
  std::sort(all.begin(), all.end(), [](const VoxartStats& a, const VoxartStats& b) { return a.seconds_total < b.seconds_total; });
  return all[all.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("bench_voxart");
  int runs = 3;
  std::string shared = std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string() + "/shared/data";
  app.add_option("--runs", runs);
  app.add_option("--shared", shared);
  CLI11_PARSE(app, argc, argv);
  std::vector<std::pair<std::string, VoxelArt>> cases;
  for (const char* f : {"vox/monu1.vox", "vox/menger.vox", "vox/dragon.vox", "vox/teapot.vox", "vxl/legs.vxl", "vxl/cc.vxl"}) {
    const std::string p = shared + "/" + f;
    if (std::filesystem::exists(p)) cases.push_back({f, read_voxel_art(p)});
  }
  if (cases.empty()) std::printf("(../shared/data absent: generated models only)\n\n");
  for (ColorGrid g : {ball(24), blob128()}) {
    VoxelArt a;
    a.parts.push_back(std::move(g));
    a.source = a.parts[0].name;
    cases.push_back({a.source, std::move(a)});
  }
  std::printf("| model | voxels | triangles | extraction | fairing (Lanczos) | attributes | atlas | total | texture | "
              "used | Taubin x10 | simplify to 10 %% | atlas after |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, art] : cases) {
    VoxartOptions o;
    const VoxartStats s = median_run(art, o, runs);
    VoxartOptions t = o;
    t.fairing = VoxartFairing::taubin;
    const VoxartStats ts = median_run(art, t, 1);
    VoxartOptions q = o;
    q.target_faces = std::max<uint64_t>(500, s.triangles / 10);
    const VoxartStats qs = median_run(art, q, 1);
    auto ms = [](double x) { return x * 1000; };
    std::printf("| %s | %llu | %llu | %.0f ms | %.0f ms | %.0f ms | %.0f ms | %.0f ms | %lldx%lld (%d/voxel) | %.0f %% | %.0f ms | "
                "%.0f ms | %.0f ms, colours %.2f %% |\n",
                name.c_str(), (unsigned long long)s.voxels, (unsigned long long)s.triangles, ms(s.seconds_extract),
                ms(s.seconds_fair), ms(s.seconds_attributes), ms(s.seconds_atlas), ms(s.seconds_total),
                (long long)s.texture_width, (long long)s.texture_height, s.texels_per_voxel, 100 * s.utilisation,
                ms(ts.seconds_fair), ms(qs.seconds_simplify), ms(qs.seconds_atlas), 100 * qs.color_exact);
    std::fflush(stdout);
  }
  return 0;
}
