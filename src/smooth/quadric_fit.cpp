// Beyond the paper: the local quadric fit after pressing. Theory of
// operation: include/voxpress/smooth/pressing.h (fit_local_quadrics).
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "quadric.h"
#include "stick_solid.h"
#include "surface_graph.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress {

namespace {

// Quadric::stab's weight. The curved creases use 100; here each vertex has
// its own fit, and at 100 the active sets' jumps between neighbouring fits
// roughen the surface (sphere 128 normal error 0.47 -> 0.75 degrees); 10
// keeps most of the gain on fandisk and the sphere (measured by
// `bench/press_eval fandisk.off 128 N` and `bench/press_eval sphere 128 1`).
constexpr double kStabWeight = 10;

// A trusted fit, stored compactly (u and w follow from n).
struct StoredQuadric {
  Vec3 m, n;
  Eigen::Matrix<double, 6, 1> q;
};

struct FitScratch {
  detail::RingScratch rings;
  std::vector<Vec3> pts, ins, outs;
};

}  // namespace

QuadricFitStats fit_local_quadrics(StickSurface& s, const std::vector<int32_t>& region,
                                   const std::vector<uint8_t>& junction, const QuadricFitOptions& o,
                                   const std::vector<uint8_t>* only) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.stick_count();
  if (!region.empty() && region.size() != n) throw std::invalid_argument("fit_local_quadrics: regions do not match the sticks");
  if (!junction.empty() && junction.size() != n)
    throw std::invalid_argument("fit_local_quadrics: junction flags do not match the sticks");
  if (only && only->size() != n) throw std::invalid_argument("fit_local_quadrics: `only` does not match the sticks");
  QuadricFitStats st;
  if (o.rings <= 0 || n == 0) return st;
  const auto fresh = [&](size_t v) { return (region.empty() || region[v] < 0) && (junction.empty() || !junction[v]); };
  std::vector<uint32_t> off, adj;
  detail::vertex_adjacency(n, s.triangles, off, adj);
  // Per vertex, once (every fit reads ~90 neighbours): its position and its
  // stick's inside and outside samples (lattice points: exact in float).
  std::vector<Vec3> x(n);
  std::vector<std::array<Eigen::Vector3f, 2>> samples(n);
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    x[v] = s.index_position(v);
    samples[v] = {s.inside_sample(v).cast<float>(), s.outside_sample(v).cast<float>()};
  });
  const auto inside = [&](size_t v) { return Vec3(samples[v][0].cast<double>()); };
  const auto outside = [&](size_t v) { return Vec3(samples[v][1].cast<double>()); };
  // Each fresh vertex's quadric, when trusted (`fitted`).
  std::vector<StoredQuadric> quad(n);
  std::vector<uint8_t> fitted(n, 0);
  // With `only`: the quadrics its vertices' moves read (theirs and their neighbours').
  std::vector<uint8_t> needed;
  if (only) {
    needed.assign(n, 0);
    for (size_t v = 0; v < n; ++v)
      if ((*only)[v]) {
        needed[v] = 1;
        for (uint32_t k = off[v]; k < off[v + 1]; ++k) needed[adj[k]] = 1;
      }
  }
  tbb::enumerable_thread_specific<FitScratch> scratch;
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    if (!fresh(v) || (only && !needed[v])) return;
    FitScratch& f = scratch.local();
    detail::rings_around(uint32_t(v), uint32_t(o.rings), off, adj, [&](uint32_t w) { return fresh(w); }, f.rings);
    f.pts.clear();
    f.ins.clear();
    f.outs.clear();
    Vec3 outward = Vec3::Zero();
    for (const auto& [w, ring] : f.rings.out) {
      f.pts.push_back(x[w]);
      f.ins.push_back(inside(w));
      f.outs.push_back(outside(w));
      outward[s.axis(w)] += s.lower_inside(w) ? 1 : -1;
    }
    detail::Quadric q;
    if (!q.fit(f.pts, outward) || q.residual > o.residual) return;
    q.stab(f.pts, f.ins, f.outs, o.stab_eps, kStabWeight, detail::kStabSolves);
    quad[v] = {q.m, q.n, q.q};
    fitted[v] = 1;
  });
  // New t per vertex (from the lower sample, as StickSurface::t), NaN:
  // unchanged. Each fitted vertex moves to the mean of the exits of its
  // stick from its own quadric and from its fitted neighbours' (the one
  // nearest its own exit): neighbouring fits differ by their active sets and
  // their windows, and the mean blends them as a partition of unity would
  // (sphere 128 normal error 0.57 -> 0.53 degrees, r->t 0.0318 -> 0.0316;
  // two rings 0.51 degrees; fandisk unchanged).
  std::vector<double> next(n, std::numeric_limits<double>::quiet_NaN());
  const auto quadric = [&](size_t v) {
    detail::Quadric q;
    q.set_frame(quad[v].m, quad[v].n);
    q.q = quad[v].q;
    return q;
  };
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    if (!fitted[v] || (only && !(*only)[v])) return;
    const bool lower_in = s.lower_inside(v);
    const Vec3 in = inside(v), out = outside(v);
    const double own = detail::stab(quadric(v), in, out, lower_in ? s.t[v] : 1 - s.t[v], o.margin);
    if (std::isnan(own)) {
      next[v] = -1;  // fitted, not crossed within the margins
      return;
    }
    double sum = own, count = 1;
    for (uint32_t k = off[v]; k < off[v + 1]; ++k) {
      const uint32_t w = adj[k];
      if (!fitted[w]) continue;
      const double t = detail::stab(quadric(w), in, out, own, o.margin);
      if (std::isnan(t)) continue;
      sum += t;
      count += 1;
    }
    const double t = sum / count;  // within the margins: a mean of values there
    next[v] = lower_in ? t : 1 - t;
  });
  for (size_t v = 0; v < n; ++v) {
    if (std::isnan(next[v])) continue;
    ++st.fitted;
    if (next[v] < 0 || next[v] == s.t[v]) continue;
    s.t[v] = next[v];
    ++st.moved;
  }
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

}  // namespace voxpress
