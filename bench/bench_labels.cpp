// bench_labels: the shared pressing of a label map (issue 54) against exact
// truth. The phantom of tests/labels (a box, a sphere pressed into it, a
// sphere nested in that, a slab touching both: three- and four-label
// junctions) on an anisotropic lattice, rotated at random per seed, scaled
// by --scale. Per label: the RMS distance of its vertices to its true
// boundary for the midpoint surface, the shared press (press_shared_labels)
// and the label's mask alone through smooth_surface, both with the same
// options (by default flats and sharpening; --no-sharpen: flats only;
// --no-flats: plain); for the junction vertices (face centres and apexes),
// their distance to the true triple lines. Prints Markdown tables
// (docs/BENCHMARKS.md).
//   build/bench/bench_labels [--seeds N] [--scale S] [--iterations N] [--no-sharpen] [--no-flats]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <random>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

namespace {

using namespace voxpress;

bool ph_assembly(const std::string& phantom) { return phantom == "assembly"; }

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double box(const Vec3& q, const Vec3& c, const Vec3& h) {
  const Vec3 d = (q - c).cwiseAbs() - h;
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

// The phantom in its own frame (physical units, scaled): signed distances
// of the four solids, and of each label's region (max of exact distances:
// exact on the faces, a lower bound near their edges).
struct Phantom {
  Mat3 R;        // frame -> volume rotation
  Vec3 centre;   // the frame's origin in the volume
  double scale;  // solid sizes in units of the tests' phantom
  bool assembly = false;  // --phantom assembly: two boxes sharing part of a face
  Vec3 frame(const Vec3& p) const { return R.transpose() * (p - centre) / scale; }
  // The assembly's boxes (centre, half sizes), frame units.
  static constexpr double kBoxes[2][6] = {{-11, 0, 0, 11, 13, 11}, {9.5, 0, 0, 9.5, 11, 9.5}};
  double assembly_box(const Vec3& p, int L) const {
    const double* b = kBoxes[L - 1];
    return box(frame(p), Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5])) * scale;
  }
  // The assembly's box L as a closed mesh (physical frame).
  Mesh box_mesh(int L) const {
    const double* b = kBoxes[L - 1];
    Mesh m;
    for (int k = 0; k < 8; ++k) {
      const Vec3 q(b[0] + (k & 1 ? b[3] : -b[3]), b[1] + (k & 2 ? b[4] : -b[4]), b[2] + (k & 4 ? b[5] : -b[5]));
      m.positions.push_back(centre + R * (q * scale));
    }
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
  }
  std::array<double, 4> solids(const Vec3& p) const {
    const Vec3 q = frame(p);
    return {box(q, Vec3(-8, 0, 0), Vec3(7, 9, 8)), (q - Vec3(6, 0, 0)).norm() - 12, (q - Vec3(7, 0, 0)).norm() - 5,
            box(q, Vec3(0, 11, 0), Vec3(16, 2, 10))};
  }
  int label(const Vec3& p) const {
    if (assembly) return assembly_box(p, 1) < 0 ? 1 : assembly_box(p, 2) < 0 ? 2 : 0;
    const auto [b, s12, s5, slab] = solids(p);
    if (s5 < 0) return 3;
    if (s12 < 0) return 2;
    if (b < 0) return 1;
    return slab < 0 ? 4 : 0;
  }
  // Signed distance to label L's region (L = 0: the background), in scaled units.
  double region(const Vec3& p, int L) const {
    if (assembly) return L == 0 ? -std::min(assembly_box(p, 1), assembly_box(p, 2)) : assembly_box(p, L);
    const auto [b, s12, s5, slab] = solids(p);
    double d = 0;
    switch (L) {
      case 3: d = s5; break;
      case 2: d = std::max(s12, -s5); break;
      case 1: d = std::max(b, -s12); break;
      case 4: d = std::max({slab, -b, -s12}); break;
      default: d = -std::min({b, s12, slab}); break;
    }
    return d * scale;
  }
};

// The nearest point where the boundaries of the labels `ls` all meet, from
// p (Gauss-Newton on their implicit functions, minimal-norm steps through
// the pseudo-inverse, central differences).
Vec3 onto_line(const Phantom& ph, const std::vector<int>& ls, Vec3 p) {
  const double h = 1e-4 * ph.scale;
  const int m = int(ls.size());
  for (int it = 0; it < 40; ++it) {
    Eigen::MatrixXd J(m, 3);
    Eigen::VectorXd f(m);
    for (int r = 0; r < m; ++r) {
      f[r] = ph.region(p, ls[size_t(r)]);
      for (int k = 0; k < 3; ++k) {
        Vec3 e = Vec3::Zero();
        e[k] = h;
        J(r, k) = (ph.region(p + e, ls[size_t(r)]) - ph.region(p - e, ls[size_t(r)])) / (2 * h);
      }
    }
    Vec3 step = J.completeOrthogonalDecomposition().pseudoInverse() * f;
    if (step.norm() > 0.25 * ph.scale) step *= 0.25 * ph.scale / step.norm();  // the functions are only piecewise smooth
    p -= step;
    if (step.norm() < 1e-9) break;
  }
  for (int L : ls)
    if (std::abs(ph.region(p, L)) > 1e-6) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  return p;
}

struct Row {
  double mid = 0, shared = 0, binary = 0;
  size_t n = 0, n_mid = 0;
  double t2r_shared = 0, t2r_binary = 0;  // assembly: squared truth -> result RMS per map
  size_t maps = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Shared pressing of the label phantom against exact truth"};
  int seeds = 5;
  double scale = 1;
  app.add_option("--seeds", seeds, "Random rotations")->check(CLI::Range(1, 100));
  app.add_option("--scale", scale, "Solid size in units of the tests' phantom (1: 44 x 40 x 30 samples)")
      ->check(CLI::Range(0.5, 8.0));
  PressOptions po;
  app.add_option("--iterations", po.iterations, "Pressing iterations (both stages, and the binary press)")->capture_default_str();
  std::string phantom = "organs";
  app.add_option("--phantom", phantom, "organs: box, sphere pressed into it, nested sphere, slab; assembly: two boxes "
                 "sharing part of a face")->check(CLI::IsMember({"organs", "assembly"}));
  bool no_flats = false, no_sharpen = false;
  app.add_flag("--no-flats", no_flats, "Press both without flats (and so without sharpening)");
  app.add_flag("--no-sharpen", no_sharpen, "Press both with flats, without sharpening");
  CLI11_PARSE(app, argc, argv);
  SurfaceOptions so;
  so.press = po;
  if (no_flats) so.passes.disable(Pass::flats);
  if (no_sharpen || no_flats) so.passes.disable(Pass::sharpen);
  const char* what = no_flats ? "without flats" : no_sharpen ? "with flats, without sharpening" : "with flats and sharpening";
  const Vec3 spacing(1, 1.2, 1.5);
  const double cell = std::cbrt(spacing.prod());
  std::array<Row, 5> rows{};
  std::vector<double> junction, junction_mid;  // distances to the true triple lines, voxels
  size_t unresolved = 0;
  std::map<std::pair<int, int>, std::array<double, 3>> interfaces;  // shared, midpoint sums, count                       // junction vertices whose projection did not converge
  double t_shared = 0, t_binary = 0;
  size_t sharpened = 0;  // crease vertices the shared surface got
  for (int seed = 1; seed <= seeds; ++seed) {
    std::mt19937_64 rng{uint64_t(seed)};
    std::uniform_real_distribution<double> U(-1, 1);
    Phantom ph;
    ph.R = Eigen::AngleAxisd(std::acos(-1.0) * U(rng), Vec3(U(rng), U(rng), U(rng)).normalized()).toRotationMatrix();
    ph.scale = scale;
    ph.assembly = phantom == "assembly";
    ScalarVolume v;
    // The phantom's reach (radius ~ 27 scaled units) fits in the box.
    const int64_t n = int64_t(std::ceil(58 * scale));
    v.lattice.dims = {int64_t(std::ceil(n / spacing[0])), int64_t(std::ceil(n / spacing[1])),
                      int64_t(std::ceil(n / spacing[2]))};
    v.lattice.spacing = spacing;
    ph.centre = Vec3(double(v.lattice.dims[0] - 1), double(v.lattice.dims[1] - 1), double(v.lattice.dims[2] - 1))
                    .cwiseProduct(spacing) / 2 + Vec3(U(rng), U(rng), U(rng)) * 0.5;
    v.type = ScalarType::u8;
    v.bytes.resize(size_t(v.lattice.size()));
    for (int64_t k = 0; k < v.lattice.dims[2]; ++k)
      for (int64_t j = 0; j < v.lattice.dims[1]; ++j)
        for (int64_t i = 0; i < v.lattice.dims[0]; ++i)
          v.bytes[size_t(v.lattice.linear(i, j, k))] =
              std::byte(ph.label(v.lattice.to_physical(Vec3(double(i), double(j), double(k)))));
    const SharedSurface mid = extract_shared_surface(v);
    double t0 = now();
    const SharedLabels sl = press_shared_labels(v, label_table(v), so);
    t_shared += now() - t0;
    const SharedSurface& s = sl.surface;
    const SharedPressStats& st = sl.press;
    sharpened += sl.sharpen.inserted;
    for (uint32_t L = 1; L < s.labels.size(); ++L) {
      const int value = int(s.labels[L]);
      auto rms = [&](const Mesh& m) {
        double sum = 0;
        for (const Vec3& p : m.positions) sum += std::pow(ph.region(p, value) / cell, 2);
        return sum;
      };
      Row& r = rows[size_t(value)];
      const Mesh pm = label_mesh(s, L);
      const Mesh mm = label_mesh(mid, L);
      r.mid += rms(mm);
      r.n_mid += mm.positions.size();
      r.shared += rms(pm);
      Selection sel;
      sel.kind = Selection::Kind::label;
      sel.value = value;
      t0 = now();
      const SurfaceResult sr = smooth_surface(binarize(v, sel), so);
      const Mesh& bm = sr.mesh;
      t_binary += now() - t0;
      r.binary += rms(bm) * double(pm.positions.size()) / double(bm.positions.size());
      r.n += pm.positions.size();
      if (ph.assembly) {  // truth -> result: what a chamfer cuts off a crease
        EvalOptions eo;
        eo.samples = 100000;
        eo.self_intersections = false;
        const auto truth = mesh_truth(ph.box_mesh(value), "box");
        r.t2r_shared += std::pow(evaluate(pm, *truth, eo).truth_to_result.rms / cell, 2);
        r.t2r_binary += std::pow(evaluate(bm, *truth, eo).truth_to_result.rms / cell, 2);
        ++r.maps;
      }
    }
    // Per interface: the RMS over its stick vertices (junction points and
    // crease vertices left out).
    for (size_t f = 0; f < s.sides.size(); ++f) {
      const int a = int(s.labels[s.sides[f][0]]), b = int(s.labels[s.sides[f][1]]);
      for (uint32_t w : s.mesh.triangles[f]) {
        if (s.kind[w] >= 3) continue;
        auto& e = interfaces[{std::min(a, b), std::max(a, b)}];
        e[0] += std::pow(ph.region(s.mesh.positions[w], a) / cell, 2);
        e[1] += std::pow(ph.region(mid.mesh.positions[w], a) / cell, 2);
        e[2] += 1;
      }
    }
    // Junction vertices: the triple line of two of the labels around each.
    std::vector<std::vector<int>> around(s.mesh.positions.size());
    for (size_t f = 0; f < s.sides.size(); ++f)
      for (uint32_t w : s.mesh.triangles[f])
        for (uint32_t L : s.sides[f])
          if (std::find(around[w].begin(), around[w].end(), int(s.labels[L])) == around[w].end())
            around[w].push_back(int(s.labels[L]));
    for (size_t w = 0; w < s.mesh.positions.size(); ++w) {
      if (s.kind[w] < 3 || s.kind[w] > 6 || around[w].size() < 3) continue;
      // The nearest point where three of its labels meet (the triple
      // lines of its labels, or their four-label point).
      auto distance = [&](const Vec3& p) {
        double best = 1e30;
        const auto& A = around[w];
        for (size_t a = 0; a < A.size(); ++a)
          for (size_t b = a + 1; b < A.size(); ++b)
            for (size_t c = b + 1; c < A.size(); ++c)
              if (const double d = (onto_line(ph, {A[a], A[b], A[c]}, p) - p).norm() / cell; d < best) best = d;
        return best;
      };
      const double ds = distance(s.mesh.positions[w]), dm = distance(mid.mesh.positions[w]);
      if (ds < 1e30 && dm < 1e30) {  // both projections converged
        junction.push_back(ds);
        junction_mid.push_back(dm);
      } else {
        ++unresolved;
      }
    }
    std::fprintf(stderr, "seed %d: %zu junction curves, %zu cubes pinned, %zu reset\n", seed, st.junction_curves,
                 st.cubes_pinned, st.cubes_reset);
  }
  std::printf("Label phantom (%s), scale %.2f, spacing 1 x 1.2 x 1.5, %d random rotations, %s: vertex RMS to each "
              "label's true boundary (voxels)\n\n",
              phantom.c_str(), scale, seeds, what);
  std::printf("| label | midpoint | shared press | the label alone (smooth_surface) | shared / alone |\n|---|---|---|---|---|\n");
  const char* organs[] = {"", "1 box", "2 sphere (pressed into the box)", "3 nested sphere", "4 slab"};
  const char* boxes[] = {"", "1 larger box", "2 smaller box", "", ""};
  const char* const* names = ph_assembly(phantom) ? boxes : organs;
  for (int L = 1; L <= 4; ++L) {
    const Row& r = rows[size_t(L)];
    if (r.n == 0) continue;
    const double m = std::sqrt(r.mid / double(r.n_mid)), sh = std::sqrt(r.shared / double(r.n)),
                 bi = std::sqrt(r.binary / double(r.n));
    std::printf("| %s | %.4f | %.4f | %.4f | %.3f |\n", names[L], m, sh, bi, sh / bi);
  }
  if (ph_assembly(phantom)) {
    std::printf("\nTruth -> result RMS (voxels; sampled on each true box: sees what a chamfer cuts off):\n\n"
                "| label | shared press | the label alone | shared / alone |\n|---|---|---|---|\n");
    for (int L = 1; L <= 2; ++L) {
      const Row& r = rows[size_t(L)];
      const double sh = std::sqrt(r.t2r_shared / double(r.maps)), bi = std::sqrt(r.t2r_binary / double(r.maps));
      std::printf("| %s | %.4f | %.4f | %.3f |\n", names[L], sh, bi, sh / bi);
    }
  }
  std::printf("\nPer interface (stick vertices of its triangles, counted once per triangle):\n\n| labels | midpoint | "
              "shared press |\n|---|---|---|\n");
  for (const auto& [k, e] : interfaces)
    std::printf("| %d / %d | %.4f | %.4f |\n", k.first, k.second, std::sqrt(e[1] / e[2]), std::sqrt(e[0] / e[2]));
  std::printf("\nJunction vertices (face centres and apexes where 3+ labels meet), distance to the true triple "
              "lines (voxels):\n\n| surface | vertices | mean | median | 95th percentile | max | within 0.5 voxel |\n"
              "|---|---|---|---|---|---|---|\n");
  for (auto* list : {&junction_mid, &junction}) {
    std::vector<double>& d = *list;
    std::sort(d.begin(), d.end());
    double mean = 0;
    for (double x : d) mean += x;
    const double n = double(std::max<size_t>(d.size(), 1));
    auto q = [&](double f) { return d.empty() ? 0.0 : d[size_t(f * double(d.size() - 1))]; };
    const auto within = std::count_if(d.begin(), d.end(), [](double x) { return x <= 0.5; });
    std::printf("| %s | %zu (+%zu unresolved) | %.3f | %.3f | %.3f | %.3f | %.1f %% |\n", list == &junction ? "shared press" : "midpoint",
                d.size(), unresolved, mean / n, q(0.5), q(0.95), q(1.0), 100.0 * double(within) / n);
  }
  std::printf("\nCrease vertices inserted on the shared surface: %.1f per map\n", double(sharpened) / seeds);
  std::printf("\nTime: shared press %.3f s per map, the labels one by one %.3f s per map\n", t_shared / seeds,
              t_binary / seeds);
  return 0;
}
