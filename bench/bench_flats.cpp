// Flats (plane voting) and junctions: detection time and quality, and the
// Table 2 stages (midpoint, midpoint + tiles, + smoothing) on generated
// shapes and shared models, randomly rotated.
//   build/bench/bench_flats                      # the table in docs/BENCHMARKS.md
//   build/bench/bench_flats --shape box --res 64 --seeds 20
//   build/bench/bench_flats --model ../shared/data/meshes/fandisk.off --res 128 --seeds 3 [--split]
// A true planar face is "found" when a flat's plane is within 1 degree and
// half a cell of it; a flat matching no true face is "spurious". For models
// every planar face of the mesh counts (a coarsely tessellated curved face
// is many small planar faces), so only flat counts and errors are printed.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

struct Case {
  std::string name;
  BinaryVolume volume;
  std::unique_ptr<Truth> truth;
  std::vector<PlanarFace> faces;  // physical; empty when not judged
};

double stick_rms(const StickSurface& s, const Truth& truth, const BinaryVolume& v) {
  EvalOptions eo;
  eo.volume = &v;
  eo.samples = 20000;
  eo.self_intersections = false;
  return evaluate(to_mesh(s), truth, eo).stick_rms_vox.value_or(NAN);
}

void run(const Case& c, const FlatOptions& fo, int iterations, bool header, bool split, const std::string& dump) {
  if (header)
    std::printf("| case | flats | true faces >= min | found | spurious | worst angle (deg) | estimate s | detect s | "
                "junctions s | stick: midpoint | + tiles | + smoothing | r->t RMS | normal err (deg) | violations | "
                "check |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  StickSurface s = extract_sticks(c.volume);
  const SliceCurves curves = build_slice_curves(s);
  const double mid = stick_rms(s, *c.truth, c.volume);
  PressOptions po;
  po.iterations = iterations;
  FlatSegmentation seg;
  const FeaturePressStats st = press_with_flats(s, curves, po, &fo, &seg);
  // "+ smoothing" is what `voxpress press` hands to sharpening: Pressing with
  // the flats, then the local quadric fit.
  QuadricFitOptions qo;
  qo.margin = po.margin;
  fit_local_quadrics(s, seg.region, seg.junction, qo);
  StickSurface tiles = s;
  apply_flats(tiles, seg);
  const double with_tiles = stick_rms(tiles, *c.truth, c.volume);
  // True crossing of stick v (NaN if none) and the vertex at t, physical.
  auto stick = [&](const StickSurface& x, size_t v, Vec3& p) {
    const Lattice& L = c.volume.lattice;
    const auto [a, b] = x.sample_points(v);
    p = L.to_physical(a + x.t[v] * (b - a));
    return c.truth->crossing(L.to_physical(a), L.to_physical(b), x.t[v]);
  };
  if (split) {
    // Where the stick error sits: by vertex class (frozen / junction /
    // fresh) for "+ tiles" and the final surface; the final error by
    // distance to the nearest true sharp edge (dihedral > 30 degrees); and
    // per flat, with the distance of its vertices to the truth.
    const double cell = std::cbrt(c.volume.lattice.spacing.prod());
    const char* names[3] = {"frozen", "junction", "fresh"};
    for (const StickSurface* x : {&tiles, &s}) {
      double sum[3] = {0, 0, 0}, cnt[3] = {0, 0, 0};
      for (size_t v = 0; v < x->stick_count(); ++v) {
        Vec3 p;
        const double tt = stick(*x, v, p);
        if (std::isnan(tt)) continue;
        const int k = seg.region[v] >= 0 ? 0 : seg.junction[v] ? 1 : 2;
        sum[k] += (tt - x->t[v]) * (tt - x->t[v]);
        ++cnt[k];
      }
      std::fprintf(stderr, "%s:", x == &s ? "final" : "tiles");
      for (int k = 0; k < 3; ++k) std::fprintf(stderr, " %s %.0f rms %.4f |", names[k], cnt[k], std::sqrt(sum[k] / std::max(cnt[k], 1.0)));
      std::fprintf(stderr, "\n");
    }
    const auto edges = c.truth->sharp_edges(30);
    const double bounds[] = {0.5, 1, 1.5, 2, 3, 1e300};
    double bs[2][6] = {}, bc[2][6] = {}, bsg[2][6] = {};
    std::vector<double> fs(seg.flats.size()), fd(seg.flats.size()), fc(seg.flats.size());
    for (size_t v = 0; v < s.stick_count(); ++v) {
      Vec3 p;
      const double tt = stick(s, v, p);
      if (std::isnan(tt)) continue;
      const double e2 = (tt - s.t[v]) * (tt - s.t[v]);
      const double d = edges.empty() ? 1e300 : (closest_on_segments(p, edges) - p).norm() / cell;
      int k = 0;
      while (d > bounds[k]) ++k;
      const int cls = seg.region[v] >= 0 ? 0 : 1;
      bs[cls][k] += e2;
      bc[cls][k] += 1;
      bsg[cls][k] += (s.lower_inside(v) ? 1 : -1) * (s.t[v] - tt);  // > 0: outside the truth
      if (cls == 0) {
        const size_t f = size_t(seg.region[v]);
        fs[f] += e2;
        fd[f] += (c.truth->closest(p).point - p).squaredNorm() / (cell * cell);
        fc[f] += 1;
      }
    }
    for (int cls = 0; cls < 2; ++cls) {
      std::fprintf(stderr, "%s, by distance to a true sharp edge (cells):", cls ? "fresh" : "frozen");
      for (int k = 0; k < 6; ++k)
        std::fprintf(stderr, " %s%.1f: %.0f rms %.3f mean %+.3f |", k < 5 ? "<=" : ">", bounds[std::min(k, 4)], bc[cls][k],
                     std::sqrt(bs[cls][k] / std::max(bc[cls][k], 1.0)), bsg[cls][k] / std::max(bc[cls][k], 1.0));
      std::fprintf(stderr, "\n");
    }
    for (size_t f = 0; f < fs.size(); ++f)
      std::fprintf(stderr, "flat %zu: %.0f sticks, stick rms %.4f, distance rms %.4f, normal (%.3f %.3f %.3f)\n", f, fc[f],
                   std::sqrt(fs[f] / std::max(fc[f], 1.0)), std::sqrt(fd[f] / std::max(fc[f], 1.0)), seg.flats[f].normal.x(),
                   seg.flats[f].normal.y(), seg.flats[f].normal.z());
  }
  if (!dump.empty()) {
    // The final surface coloured by stick error: white 0, red >= 0.5 cell;
    // vertices whose stick the truth does not cross are blue.
    Mesh m = to_mesh(s);
    m.colors.resize(m.vertex_count());
    for (size_t v = 0; v < s.stick_count(); ++v) {
      Vec3 p;
      const double tt = stick(s, v, p);
      const double e = std::isnan(tt) ? -1 : std::min(std::abs(tt - s.t[v]) / 0.5, 1.0);
      const auto g = uint8_t(255 * (1 - std::max(e, 0.0)));
      m.colors[v] = e < 0 ? std::array<uint8_t, 4>{0, 0, 255, 255} : std::array<uint8_t, 4>{255, g, g, 255};
    }
    const std::string path = dump + c.name + ".ply";
    write_mesh(path, m);
    std::fprintf(stderr, "wrote %s\n", path.c_str());
  }
  EvalOptions eo;
  eo.volume = &c.volume;
  const EvalReport r = evaluate(to_mesh(s), *c.truth, eo);
  // Planes against the true faces.
  const double cell = std::cbrt(c.volume.lattice.spacing.prod());
  size_t expected = 0, found = 0, spurious = 0;
  double worst = 0;
  auto angle = [](const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / std::numbers::pi; };
  auto matches = [&](const Flat& f, const PlanarFace& t) {
    return angle(f.normal, t.normal) < 1 && std::abs(f.offset - t.offset) < 0.5 * cell;
  };
  if (!c.faces.empty()) {
    for (const PlanarFace& t : c.faces) {
      if (t.area / (cell * cell) < fo.min_area) continue;
      ++expected;
      bool hit = false;
      for (const Flat& f : seg.flats) hit |= matches(f, t);
      found += hit;
      if (!hit && split)
        std::fprintf(stderr, "missed face: area %.0f cells^2 normal (%.3f %.3f %.3f)\n", t.area / (cell * cell), t.normal.x(), t.normal.y(), t.normal.z());
    }
    for (const Flat& f : seg.flats) {
      bool any = false;
      double best = 180;
      for (const PlanarFace& t : c.faces) {
        any |= matches(f, t);
        if (std::abs(f.offset - t.offset) < 0.5 * cell) best = std::min(best, angle(f.normal, t.normal));
      }
      spurious += !any;
      worst = std::max(worst, best);
    }
  }
  const auto& fs = st.flats;
  std::printf("| %s | %zu | %s | %s | %s | %s | %.3f | %.3f | %.3f | %.4f | %.4f | %.4f | %.4f | %.2f | %llu | %s |\n",
              c.name.c_str(), seg.flats.size(), c.faces.empty() ? "-" : std::to_string(expected).c_str(),
              c.faces.empty() ? "-" : std::to_string(found).c_str(), c.faces.empty() ? "-" : std::to_string(spurious).c_str(),
              c.faces.empty() ? "-" : (std::to_string(worst).substr(0, 5)).c_str(), fs.seconds_estimate, fs.seconds_detect,
              fs.seconds_junctions, mid, with_tiles, r.stick_rms_vox.value_or(NAN), r.result_to_truth_vox.rms,
              r.normal_error_deg, (unsigned long long)r.classification_violations.value_or(0), r.mesh.ok() ? "ok" : "FAIL");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) try {
  CLI::App app{"voxpress flats benchmark"};
  std::string shape, model;
  int64_t res = 0;
  int seeds = 0, first_seed = 1, iterations = 100;
  FlatOptions fo;
  bool split = false;
  std::string dump, rotate;
  app.add_flag("--split", split,
               "Also print (stderr) where the stick error sits (vertex class, distance to the true sharp edges, each flat), missed faces, a model's planar faces");
  app.add_option("--dump", dump, "Write each final surface coloured by stick error (white 0, red >= 0.5 cell) to PREFIX<case>.ply");
  app.add_option("--shape", shape, "box | cylinder | cad-part | sphere | torus");
  app.add_option("--model", model, "a closed mesh to voxelize");
  app.add_option("--res", res);
  app.add_option("--seeds", seeds);
  app.add_option("--first-seed", first_seed, "Seeds run from here (default 1)");
  app.add_option("--iterations", iterations);
  app.add_option("--rotate", rotate, "One fixed rotation (AX,AY,AZ degrees, e.g. 0,0,0) instead of random:SEED; one case per job");
  app.add_option("--min-flat-area", fo.min_area);
  std::vector<std::string> disabled;
  app.add_option("--disable-pass", disabled, "Feature passes to switch off (voxpress press --help lists them)")->delimiter(',');
  CLI11_PARSE(app, argc, argv);
  for (const std::string& name : disabled) fo.passes.disable(name);
  struct Job {
    std::string shape, model;
    int64_t res;
    int seeds;
  };
  std::vector<Job> jobs;
  if (shape.empty() && model.empty()) {
    jobs = {{"box", "", 64, 3},       {"box", "", 128, 3},      {"cylinder", "", 64, 2}, {"cylinder", "", 128, 2},
            {"cad-part", "", 64, 2},  {"cad-part", "", 128, 2}, {"cad-part", "", 256, 1}, {"sphere", "", 128, 1},
            {"torus", "", 128, 1}};
    const std::string fandisk = "../shared/data/meshes/fandisk.off";
    if (std::filesystem::exists(fandisk)) {
      jobs.push_back({"", fandisk, 128, 3});
      jobs.push_back({"", fandisk, 256, 2});
    } else {
      std::fprintf(stderr, "%s absent: fandisk rows skipped\n", fandisk.c_str());
    }
  } else {
    jobs.push_back({shape, model, res ? res : 128, seeds ? seeds : 1});
  }
  bool header = true;
  for (const Job& j : jobs)
    for (int seed = first_seed; seed < first_seed + (rotate.empty() ? j.seeds : 1); ++seed) {
      Case c;
      const std::string rot = rotate.empty() ? "random:" + std::to_string(seed) : rotate;
      const std::string tag = rotate.empty() ? " seed " + std::to_string(seed) : " rotate " + rotate;
      if (!j.shape.empty()) {
        GenerateOptions go;
        go.res = j.res;
        go.rotation = parse_rotation(rot);
        GeneratedShape g = generate_shape(parse_shape(j.shape), go);
        c.truth = shape_truth(g.kind, g.linear, g.translation);
        for (const PlanarFace& f : shape_planar_faces(g.kind)) c.faces.push_back(transform_face(f, g.linear, g.translation));
        if (g.kind == ShapeKind::sphere || g.kind == ShapeKind::torus) c.faces.push_back({Vec3(0, 0, 1), 1e300, 0});
        c.volume = std::move(g.volume);
        c.name = j.shape + " " + std::to_string(j.res) + tag;
      } else {
        const Mesh m = read_mesh(j.model);
        VoxelizeOptions vo;
        vo.res = j.res;
        vo.rotation = parse_rotation(rot);
        Voxelized v = voxelize(m, vo, j.model);
        Mesh phys = m;
        for (Vec3& p : phys.positions) p = v.placement.translation + v.placement.linear * p;
        if (split) {
          double total = 0, planar = 0;
          for (const PlanarFace& f : planar_faces(phys)) {
            total += f.area;
            const double cells = f.area / std::pow(v.placement.lattice.spacing.prod(), 2.0 / 3);
            if (cells >= fo.min_area) {
              planar += f.area;
              std::fprintf(stderr, "  planar face: area %.0f cells^2 normal (%.3f %.3f %.3f)\n", cells, f.normal.x(), f.normal.y(), f.normal.z());
            }
          }
          std::fprintf(stderr, "planar fraction (faces >= min area): %.3f\n", planar / total);
        }
        c.truth = mesh_truth(std::move(phys), j.model);
        c.volume = std::move(v.volume);
        c.name = std::filesystem::path(j.model).stem().string() + " " + std::to_string(j.res) + tag;
      }
      run(c, fo, iterations, header, split, dump);
      header = false;
    }
  return 0;
} catch (const std::exception& e) {  // a missing or unreadable --model: one line, no abort
  std::fprintf(stderr, "bench_flats: %s\n", e.what());
  return 1;
}
