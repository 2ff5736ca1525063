// Beyond the paper: the local quadric fit after pressing. Theory of
// operation: include/voxpress/smooth/pressing.h (fit_local_quadrics).
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "quadric.h"
#include "stick_solid.h"
#include "surface_graph.h"
#include "voxpress/smooth/pressing.h"
#include "core/parallel.h"

namespace voxpress {

namespace detail {

Pca pca(const std::vector<Vec3>& pts) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : pts) mean += p;
  mean /= double(pts.size());
  Mat3 cov = Mat3::Zero();
  for (const Vec3& p : pts) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  return {mean, es.eigenvalues(), es.eigenvectors().col(0)};
}

bool Quadric::fit(const std::vector<Vec3>& pts, const Vec3& outward) {
  if (pts.size() < 12) return false;
  const Pca p = pca(pts);
  set_frame(p.mean, p.normal.dot(outward) < 0 ? Vec3(-p.normal) : p.normal);
  normal_matrix.setZero();
  normal_rhs.setZero();
  heights_squared = 0;
  Vec6 r;
  for (const Vec3& x : pts) {
    const double z = row(x, r);
    normal_matrix.noalias() += r * r.transpose();
    normal_rhs += z * r;
    heights_squared += z * z;
  }
  const Eigen::LDLT<Mat6> ldlt(normal_matrix);
  if (ldlt.info() != Eigen::Success) return false;
  const Vec6 D = ldlt.vectorD().cwiseAbs();
  if (!(D.minCoeff() > 1e-12 * D.maxCoeff())) return false;
  q = ldlt.solve(normal_rhs);
  residual = rms(pts.size());
  return true;
}

void Quadric::stab(const std::vector<Vec3>& pts, const std::vector<Vec3>& ins, const std::vector<Vec3>& outs, double eps,
                 double weight, int iters) {
  // Each sample's design row and target, once (2k: inside, 2k + 1: outside).
  thread_local std::vector<Vec6> rs;
  thread_local std::vector<double> zs;
  thread_local std::vector<uint8_t> active;
  rs.resize(2 * ins.size());
  zs.resize(2 * ins.size());
  active.assign(2 * ins.size(), 0);
  for (size_t k = 0; k < ins.size(); ++k) {
    zs[2 * k] = row(ins[k], rs[2 * k]);
    zs[2 * k + 1] = row(outs[k], rs[2 * k + 1]);
  }
  Mat6 N = normal_matrix;
  Vec6 rhs = normal_rhs;
  for (int it = 0; it < iters; ++it) {
    bool changed = false;
    for (size_t k = 0; k < 2 * ins.size(); ++k) {
      if (active[k]) continue;
      const double gap = zs[k] - rs[k].dot(q);  // the sample's height over the surface
      if (k % 2 ? gap >= eps : gap <= -eps) continue;
      active[k] = 1;
      changed = true;
      N.noalias() += weight * rs[k] * rs[k].transpose();
      rhs += weight * (zs[k] + (k % 2 ? -eps : eps)) * rs[k];
    }
    if (!changed) break;
    q = N.ldlt().solve(rhs);
  }
  residual = rms(pts.size());
}

}  // namespace detail

namespace {

// Quadric::stab's weight. The curved creases use 100; here each site has
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

// Quadrics are fitted at sites only (every fresh vertex a site or next to
// one) and each fresh vertex blends the exits of its stick from the sites'
// quadrics within this many rings: the fits of neighbours share most of
// their ~90 points, so fitting each is repeated work. Against a fit at every
// vertex blended over one ring (`build/bench/bench_compare --quick --only
// pressing`): RMS geomean 0.998, normal error 0.997, the fit 2.2x faster;
// sites within one ring only: 1.005 and 1.015; the second ring at weight
// 1/4: 0.999 and 1.000.
constexpr uint32_t kBlendRings = 2;

// Rounds of the site choice before every vertex still undecided becomes a
// site: hashed priorities decide every vertex in 4 rounds on the 256^3
// sphere and CAD part (34 k, 2 k, 37, 0 of 297 k open after each); only a
// long chain of falling priorities would take a round per pair.
constexpr int kSiteRounds = 64;

// A priority that only the vertex's neighbourhood decides (its 1-ring's
// samples relative to its own, hashed), so the sites do not depend on
// where the lattice is, on the stick order, or on a block's extent.
uint64_t site_priority(const StickSurface& s, const std::vector<uint32_t>& off, const std::vector<uint32_t>& adj,
                       uint32_t v, std::vector<uint32_t>& codes) {
  const Vec3 base = s.inside_sample(v);
  codes.clear();
  for (uint32_t k = off[v]; k < off[v + 1]; ++k) {
    const Vec3 a = s.inside_sample(adj[k]) - base, b = s.outside_sample(adj[k]) - base;
    uint32_t c = 0;
    for (int i = 0; i < 3; ++i) c = c * 8 + uint32_t(int(a[i]) + 4), c = c * 8 + uint32_t(int(b[i]) + 4);
    codes.push_back(c);
  }
  std::sort(codes.begin(), codes.end());
  uint64_t h = 0x9E3779B97F4A7C15ull + uint64_t(s.axis(v));
  for (uint32_t c : codes) {  // splitmix64 over the sorted codes
    h += 0x9E3779B97F4A7C15ull + c;
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    h ^= h >> 31;
  }
  return h;
}

// The sites among the vertices `ok` accepts, by rounds (Luby's maximal
// independent set with fixed priorities): an undecided vertex whose
// priority is at least each undecided neighbour's becomes a site, and its
// neighbours are covered. Symmetric neighbourhoods (ties) give neighbouring
// sites, never an uncovered vertex. Deterministic for any thread count.
template <class Ok>
std::vector<uint8_t> choose_sites(const StickSurface& s, const std::vector<uint32_t>& off,
                                  const std::vector<uint32_t>& adj, Ok ok) {
  const size_t n = s.stick_count();
  std::vector<uint64_t> prio(n, 0);
  tbb::enumerable_thread_specific<std::vector<uint32_t>> codes;
  detail::parallel_for(n, [&](size_t v) {
    if (ok(v)) prio[v] = site_priority(s, off, adj, uint32_t(v), codes.local());
  });
  enum : uint8_t { kOut, kOpen, kSite, kCovered };
  std::vector<uint8_t> state(n, kOut), next;
  std::vector<uint32_t> open;
  for (size_t v = 0; v < n; ++v)
    if (ok(v)) state[v] = kOpen, open.push_back(uint32_t(v));
  for (int round = 0; !open.empty(); ++round) {
    if (round == kSiteRounds) {  // a long chain of falling priorities: the rest are sites
      for (uint32_t v : open) state[v] = kSite;
      break;
    }
    next = state;
    detail::parallel_for(open.size(), [&](size_t i) {
      const uint32_t v = open[i];
      for (uint32_t k = off[v]; k < off[v + 1]; ++k)
        if (state[adj[k]] == kOpen && prio[adj[k]] > prio[v]) return;
      next[v] = kSite;
    });
    detail::parallel_for(open.size(), [&](size_t i) {
      const uint32_t v = open[i];
      if (next[v] == kSite) return;
      for (uint32_t k = off[v]; k < off[v + 1]; ++k)
        if (next[adj[k]] == kSite) {
          next[v] = kCovered;
          return;
        }
    });
    state.swap(next);
    std::erase_if(open, [&](uint32_t v) { return state[v] != kOpen; });
  }
  std::vector<uint8_t> site(n);
  for (size_t v = 0; v < n; ++v) site[v] = state[v] == kSite;
  return site;
}

struct FitScratch {
  detail::RingScratch rings;
  std::vector<Vec3> pts, ins, outs;
};

}  // namespace

QuadricFitStats fit_local_quadrics(StickSurface& s, const std::vector<int32_t>& region,
                                   const std::vector<uint8_t>& junction, const QuadricFitOptions& o,
                                   const std::vector<uint8_t>* only) {
  if (o.rings <= 0 || s.stick_count() == 0) return detail::fit_local_quadrics(s, region, junction, o, only, {});
  return detail::fit_local_quadrics(s, region, junction, o, only, detail::Adjacency(s.stick_count(), s.triangles));
}

QuadricFitStats detail::fit_local_quadrics(StickSurface& s, const std::vector<int32_t>& region,
                                           const std::vector<uint8_t>& junction, const QuadricFitOptions& o,
                                           const std::vector<uint8_t>* only, const Adjacency& graph) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.stick_count();
  if (!region.empty() && region.size() != n) throw std::invalid_argument("fit_local_quadrics: regions do not match the sticks");
  if (!junction.empty() && junction.size() != n)
    throw std::invalid_argument("fit_local_quadrics: junction flags do not match the sticks");
  if (only && only->size() != n) throw std::invalid_argument("fit_local_quadrics: `only` does not match the sticks");
  QuadricFitStats st;
  if (o.rings <= 0 || n == 0) return st;
  const auto fresh = [&](size_t v) { return (region.empty() || region[v] < 0) && (junction.empty() || !junction[v]); };
  const std::vector<uint32_t>&off = graph.off, &adj = graph.adj;
  // Per vertex, once (every fit reads ~90 neighbours): its position and its
  // stick's inside and outside samples (lattice points: exact in float).
  std::vector<Vec3> x(n);
  std::vector<std::array<Eigen::Vector3f, 2>> samples(n);
  detail::parallel_for(n, [&](size_t v) {
    x[v] = s.index_position(v);
    samples[v] = {s.inside_sample(v).cast<float>(), s.outside_sample(v).cast<float>()};
  });
  const auto inside = [&](size_t v) { return Vec3(samples[v][0].cast<double>()); };
  const auto outside = [&](size_t v) { return Vec3(samples[v][1].cast<double>()); };
  // Each fresh vertex's quadric, when trusted (`fitted`).
  std::vector<StoredQuadric> quad(n);
  std::vector<uint8_t> fitted(n, 0);
  const std::vector<uint8_t> site = choose_sites(s, off, adj, fresh);
  tbb::enumerable_thread_specific<FitScratch> scratch;
  // With `only`: the sites its vertices' moves read (within kBlendRings).
  std::vector<uint8_t> needed;
  if (only) {
    needed.assign(n, 0);
    for (size_t v = 0; v < n; ++v)
      if ((*only)[v]) {
        detail::RingScratch& rs = scratch.local().rings;
        detail::rings_around(uint32_t(v), kBlendRings, off, adj, [](uint32_t) { return true; }, rs);
        for (const auto& [w, ring] : rs.out) needed[w] = 1;
      }
  }
  detail::parallel_for(n, [&](size_t v) {
    if (!site[v] || (only && !needed[v])) return;
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
  // unchanged. Each fresh vertex moves to the mean of the exits of its
  // stick from the fitted sites' quadrics within kBlendRings (the one
  // nearest its own quadric's exit when it is a fitted site, else nearest
  // its t): neighbouring fits differ by their active sets and their
  // windows, and the mean blends them as a partition of unity would.
  std::vector<double> next(n, std::numeric_limits<double>::quiet_NaN());
  const auto quadric = [&](size_t v) {
    detail::Quadric q;
    q.set_frame(quad[v].m, quad[v].n);
    q.q = quad[v].q;
    return q;
  };
  detail::parallel_for(n, [&](size_t v) {
    if (!fresh(v) || (only && !(*only)[v])) return;
    const bool lower_in = s.lower_inside(v);
    const Vec3 in = inside(v), out = outside(v);
    double own = lower_in ? s.t[v] : 1 - s.t[v], sum = 0, count = 0;
    if (fitted[v]) {
      own = detail::stab(quadric(v), in, out, own, o.margin);
      if (std::isnan(own)) {
        next[v] = -1;  // fitted, not crossed within the margins
        return;
      }
      sum = own;
      count = 1;
    }
    detail::RingScratch& rs = scratch.local().rings;
    detail::rings_around(uint32_t(v), kBlendRings, off, adj, [&](uint32_t w) { return fresh(w); }, rs);
    for (const auto& [w, ring] : rs.out) {
      if (w == v || !fitted[w]) continue;
      const double t = detail::stab(quadric(w), in, out, own, o.margin);
      if (std::isnan(t)) continue;
      sum += t;
      count += 1;
    }
    if (count == 0) return;  // no trusted quadric around
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
