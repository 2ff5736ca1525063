// EXPERIMENT (issue 74): a two-grid FAS cycle for the press, the coarse
// level being the press of the volume subsampled by 2 (each coarse stick
// holds exactly one fine stick: A != C iff exactly one of A-B, B-C differs).
//   build/bench/mg_exp --res 64 --cycles 20 --pre 4 --post 4 --coarse 40
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>

#include "smooth/curve_kernel.h"
#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

using namespace voxpress;

namespace {

struct Level {
  BinaryVolume volume;
  StickSurface s;
  SliceCurves curves;
  detail::Layout L;
  detail::SweepFn sweep;
  std::vector<double> lo, hi;  // per vertex (layout order): the bounds
};

BinaryVolume subsample(const BinaryVolume& v) {
  BinaryVolume c;
  c.lattice = v.lattice;
  for (int a = 0; a < 3; ++a) {
    c.lattice.dims[size_t(a)] = (v.lattice.dims[size_t(a)] + 1) / 2;
    c.lattice.spacing[a] = 2 * v.lattice.spacing[a];
  }
  c.inside.assign(size_t(c.lattice.size()), 0);
  for (int64_t k = 0; k < c.lattice.dims[2]; ++k)
    for (int64_t j = 0; j < c.lattice.dims[1]; ++j)
      for (int64_t i = 0; i < c.lattice.dims[0]; ++i)
        c.inside[size_t(c.lattice.linear(i, j, k))] = v.at(2 * i, 2 * j, 2 * k);
  c.source = v.source;
  return c;
}

double residual(const std::vector<double>& t, const std::vector<double>& step, const Level& l) {
  double r = 0;
  for (size_t i = 0; i < t.size(); ++i) r = std::max(r, std::abs(std::clamp(t[i] + step[i], l.lo[i], l.hi[i]) - t[i]));
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("two-grid FAS experiment");
  int res = 64, cycles = 20, pre = 4, post = 4, coarse_sweeps = 40, seed = 1, harmonic = 6;
  double damp = 1.0, momentum = 0.5;
  std::string shape = "sphere";
  app.add_option("--res", res);
  app.add_option("--shape", shape);
  app.add_option("--seed", seed);
  app.add_option("--cycles", cycles);
  app.add_option("--pre", pre);
  app.add_option("--post", post);
  app.add_option("--coarse", coarse_sweeps);
  app.add_option("--damp", damp);
  app.add_option("--momentum", momentum);
  app.add_option("--harmonic", harmonic);
  double perturb = 0;
  app.add_option("--perturb", perturb, "start from the fixed point (3000 sweeps) plus this smooth perturbation");
  CLI11_PARSE(app, argc, argv);
  GenerateOptions g;
  g.res = res;
  g.rotation = parse_rotation("random:" + std::to_string(seed));
  const ShapeKind kind = parse_shape(shape);
  const GeneratedShape gs = generate_shape(kind, g);
  PressOptions po;
  po.tolerance = 0;
  static const std::vector<uint8_t> none;
  Level F, C;
  F.volume = gs.volume;
  C.volume = subsample(F.volume);
  for (Level* l : {&F, &C}) {
    l->s = extract_sticks(l->volume);
    l->curves = build_slice_curves(l->s);
    detail::make_layout(l->s, l->curves, l->L);
    l->sweep = detail::make_sweep(l->L.families, 2, none, none, po, l->s.stick_count());
    l->lo.assign(l->s.stick_count(), po.margin);
    l->hi.assign(l->s.stick_count(), 1 - po.margin);
  }
  const size_t nf = F.s.stick_count(), nc = C.s.stick_count();
  std::printf("fine %zu vertices, coarse %zu\n", nf, nc);
  // Coarse vertex -> fine vertex (layout order) and half.
  std::vector<uint64_t> keys(nf);
  for (size_t i = 0; i < nf; ++i) {
    const auto l = F.s.lower_index(i);
    keys[i] = stick_key(F.s.lattice.dims, {l[0] + 1, l[1] + 1, l[2] + 1}, F.s.axis(i));
  }
  std::vector<uint32_t> fine_of(nc);
  std::vector<uint8_t> half(nc), carrier(nf, 0);
  for (size_t c = 0; c < nc; ++c) {
    const auto lc = C.s.lower_index(c);
    const int a = C.s.axis(c);
    int found = 0;
    for (int h = 0; h < 2; ++h) {
      std::array<int64_t, 3> lf{2 * lc[0] + 1, 2 * lc[1] + 1, 2 * lc[2] + 1};
      lf[size_t(a)] += h;
      if (lf[size_t(a)] < 0) continue;
      const uint64_t key = stick_key(F.s.lattice.dims, lf, a);
      const auto it = std::lower_bound(keys.begin(), keys.end(), key);
      if (it != keys.end() && *it == key) {
        const size_t fi = size_t(it - keys.begin());
        if (F.s.lower_inside(fi) != C.s.lower_inside(c) && h == 0) std::printf("orientation mismatch\n");
        const uint32_t cv = C.L.new_of[c];
        fine_of[cv] = F.L.new_of[fi];
        half[cv] = uint8_t(h);
        carrier[F.L.new_of[fi]] = 1;
        ++found;
      }
    }
    if (found != 1) {
      std::printf("coarse stick %zu: %d fine sticks\n", c, found);
      return 1;
    }
  }
  for (size_t cv = 0; cv < nc; ++cv) {
    C.lo[cv] = (half[cv] + po.margin) / 2;
    C.hi[cv] = (half[cv] + 1 - po.margin) / 2;
  }
  // Fine adjacency (layout order) for the harmonic prolongation.
  std::vector<std::vector<uint32_t>> adj(nf);
  for (const Triangle& tr : F.s.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = F.L.new_of[tr[size_t(e)]], b = F.L.new_of[tr[size_t((e + 1) % 3)]];
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
  for (auto& v : adj) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  std::vector<int> axis_of(nf);
  for (size_t i = 0; i < nf; ++i) axis_of[i] = F.s.axis(F.L.old_of[i]);

  std::vector<double> tf(nf, 0.5), sf(nf), tc(nc), tcR(nc), sc(nc), fc(nc), vel;
  auto smooth = [&](Level& l, std::vector<double>& t, std::vector<double>& s, int sweeps, const std::vector<double>* rhs) {
    vel.assign(t.size(), 0);
    for (int it = 0; it < sweeps; ++it) {
      l.sweep(t, 1, s);
      for (size_t i = 0; i < t.size(); ++i) {
        const double N = std::clamp(t[i] + s[i], l.lo[i], l.hi[i]) - t[i];  // the projected step
        const double dt = N - (rhs ? (*rhs)[i] : 0) + momentum * vel[i];
        const double tn = std::clamp(t[i] + dt, l.lo[i], l.hi[i]);
        vel[i] = tn - t[i];
        t[i] = tn;
      }
    }
  };
  // Index-space position of fine vertex v, for normals.
  auto fine_pos = [&](size_t v) {
    const auto l = F.s.lower_index(F.L.old_of[v]);
    Vec3 p{double(l[0]), double(l[1]), double(l[2])};
    p[axis_of[v]] += tf[v];
    return p;
  };
  std::vector<Vec3> normal(nf, Vec3::Zero());
  auto update_normals = [&]() {
    std::fill(normal.begin(), normal.end(), Vec3::Zero());
    for (const Triangle& tr : F.s.triangles) {
      const uint32_t a = F.L.new_of[tr[0]], b = F.L.new_of[tr[1]], c = F.L.new_of[tr[2]];
      const Vec3 n = (fine_pos(b) - fine_pos(a)).cross(fine_pos(c) - fine_pos(a));
      normal[a] += n, normal[b] += n, normal[c] += n;
    }
    for (auto& n : normal) n.normalize();
  };
  int restrict_rings = 1;
  if (const char* e = std::getenv("MG_RINGS")) restrict_rings = std::atoi(e);
  std::vector<double> tstar;
  if (perturb > 0) {
    tstar.assign(nf, 0.5);
    smooth(F, tstar, sf, 3000, nullptr);
    F.sweep(tstar, 1, sf);
    std::printf("t*: residual %.3e\n", residual(tstar, sf, F));
    tf = tstar;
    update_normals();
    for (size_t v = 0; v < nf; ++v) {
      const Vec3 p = fine_pos(v) / double(res);
      const double na = normal[v][axis_of[v]];
      const double dn = perturb * std::sin(6.28 * p.x()) * std::cos(6.28 * p.y());
      if (std::abs(na) > 0.3) tf[v] = std::clamp(tstar[v] + dn / na, F.lo[v], F.hi[v]);
    }
  }
  auto err = [&]() {
    double mx = 0;
    for (size_t v = 0; v < nf && !tstar.empty(); ++v) mx = std::max(mx, std::abs(tf[v] - tstar[v]));
    return mx;
  };
  const auto t0 = std::chrono::steady_clock::now();
  int fine_sweeps = 0;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    smooth(F, tf, sf, pre, nullptr);
    fine_sweeps += pre;
    F.sweep(tf, 1, sf);
    const double r_before = residual(tf, sf, F);
    for (size_t cv = 0; cv < nc; ++cv) tcR[cv] = (half[cv] + tf[fine_of[cv]]) / 2;
    C.sweep(tcR, 1, sc);
    update_normals();
    {  // the residual restricted as a normal force, averaged over rings
      std::vector<double> rho(nf), rho2(nf);
      for (size_t v = 0; v < nf; ++v) rho[v] = (std::clamp(tf[v] + sf[v], F.lo[v], F.hi[v]) - tf[v]) * normal[v][axis_of[v]];
      for (int h = 0; h < restrict_rings; ++h) {
        for (size_t v = 0; v < nf; ++v) {
          double sum = rho[v];
          for (uint32_t w : adj[v]) sum += rho[w];
          rho2[v] = sum / double(1 + adj[v].size());
        }
        rho.swap(rho2);
      }
      for (size_t cv = 0; cv < nc; ++cv) {
        const uint32_t v = fine_of[cv];
        const double na = normal[v][axis_of[v]];
        const double r = std::abs(na) > 0.2 ? rho[v] / na : std::clamp(tf[v] + sf[v], F.lo[v], F.hi[v]) - tf[v];
        fc[cv] = (std::clamp(tcR[cv] + sc[cv], C.lo[cv], C.hi[cv]) - tcR[cv]) - 8 * r;
      }
    }
    {
      double m1 = 0, m2 = 0;
      std::vector<double> s0(nc);
      C.sweep(tcR, 1, s0);
      for (size_t cv = 0; cv < nc; ++cv) {
        const double N = std::clamp(tcR[cv] + s0[cv], C.lo[cv], C.hi[cv]) - tcR[cv];
        m1 = std::max(m1, std::abs(N - fc[cv])), m2 = std::max(m2, std::abs(N));
      }
      std::printf("   |N_c(tcR) - f_c| %.3e, |N_c(tcR)| %.3e\n", m1, m2);
    }
    tc = tcR;
    smooth(C, tc, sc, coarse_sweeps, &fc);
    // Correction: carriers exactly; the others by harmonic interpolation of
    // the normal displacement over the fine surface.
    std::vector<double> dn(nf, 0), dn2(nf), dtc(nf, 0);
    for (size_t cv = 0; cv < nc; ++cv) {
      const uint32_t v = fine_of[cv];
      dtc[v] = damp * 2 * (tc[cv] - tcR[cv]);
      dn[v] = dtc[v] * normal[v][axis_of[v]];
    }
    for (int h = 0; h < harmonic; ++h) {
      for (size_t v = 0; v < nf; ++v) {
        if (carrier[v] && !std::getenv("MG_SMOOTH_ALL")) {
          dn2[v] = dn[v];
          continue;
        }
        double sum = 0;
        for (uint32_t w : adj[v]) sum += dn[w];
        dn2[v] = adj[v].empty() ? 0 : sum / double(adj[v].size());
      }
      dn.swap(dn2);
    }
    for (size_t v = 0; v < nf; ++v) {
      const double na = normal[v][axis_of[v]];
      const double dt = carrier[v] && !std::getenv("MG_SMOOTH_ALL") ? dtc[v] : std::abs(na) > 0.2 ? dn[v] / na : 0;
      tf[v] = std::clamp(tf[v] + dt, F.lo[v], F.hi[v]);
    }
    F.sweep(tf, 1, sf);
    const double r_mid = residual(tf, sf, F);
    double cmax = 0, csum = 0;
    size_t big = 0;
    for (size_t cv = 0; cv < nc; ++cv) {
      const double e = std::abs(2 * (tc[cv] - tcR[cv]));
      cmax = std::max(cmax, e), csum += e * e, big += e > 0.1;
    }
    std::printf("   coarse correction max %.3e rms %.3e, %zu above 0.1; error to t* %.3e\n", cmax, std::sqrt(csum / double(nc)), big, err());
    smooth(F, tf, sf, post, nullptr);
    fine_sweeps += post;
    F.sweep(tf, 1, sf);
    std::printf("   error after post %.3e\n", err());
    std::printf("cycle %2d: residual before %.3e, after correction %.3e, after post %.3e (fine sweeps %d)\n", cycle,
                r_before, r_mid, residual(tf, sf, F), fine_sweeps);
  }
  std::printf("seconds %.3f\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  // Reference: plain sweeps with momentum from the midpoint (same schedule as smooth).
  std::vector<double> tp(nf, 0.5);
  smooth(F, tp, sf, fine_sweeps, nullptr);
  F.sweep(tp, 1, sf);
  std::printf("plain %d sweeps: residual %.3e\n", fine_sweeps, residual(tp, sf, F));
  double mx = 0;
  for (size_t i = 0; i < nf; ++i) mx = std::max(mx, std::abs(tp[i] - tf[i]));
  std::printf("max |t_mg - t_plain| %.3e\n", mx);
  return 0;
}
