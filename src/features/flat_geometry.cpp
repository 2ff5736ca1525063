// The flats' direction cells and plane fits. Theory of operation:
// flat_geometry.h and include/voxpress/features/flats.h.
#include "flat_geometry.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <tuple>
#include "core/parallel.h"

namespace voxpress::flats_impl {

class MinNorm {
 public:
  MinNorm(const std::vector<Eigen::Vector3d>& a, const std::vector<double>& b) : a_(a), b_(b), order_(a.size()) {
    // A fixed pseudo-random order: deterministic results.
    std::vector<std::pair<uint64_t, uint32_t>> key(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
      uint64_t z = i + 0x9E3779B97F4A7C15ull;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      key[i] = {z ^ (z >> 31), uint32_t(i)};
    }
    std::sort(key.begin(), key.end());
    for (size_t i = 0; i < a.size(); ++i) order_[i] = key[i].second;
  }
  bool solve(Eigen::Vector3d& w) {
    int E[3];
    return solve(order_.size(), E, 0, w);
  }

 private:
  // The point of {a_e . w = b_e, e in E} nearest the origin.
  bool project(const int* E, int k, Eigen::Vector3d& w) const {
    if (k == 0) {
      w.setZero();
      return true;
    }
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (int q = 0; q < k; ++q) {
      A.col(q) = a_[size_t(E[q])];
      rhs(q) = b_[size_t(E[q])];
    }
    const Eigen::MatrixXd Ak = A.leftCols(k);
    const Eigen::MatrixXd G = Ak.transpose() * Ak;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(G);
    lu.setThreshold(1e-12);
    if (lu.rank() < k) return false;
    w = Ak * lu.solve(rhs.head(k));
    return true;
  }
  bool solve(size_t count, int* E, int k, Eigen::Vector3d& w) {
    if (!project(E, k, w)) return false;
    for (size_t q = 0; q < count; ++q) {
      const uint32_t i = order_[q];
      if (a_[i].dot(w) >= b_[i] - 1e-12 * (1 + std::abs(b_[i]))) continue;
      if (k == 3) return false;  // only rounding can get here
      E[k] = int(i);
      if (!solve(q, E, k + 1, w)) return false;
    }
    return true;
  }
  const std::vector<Eigen::Vector3d>& a_;
  const std::vector<double>& b_;
  std::vector<uint32_t> order_;
};

// ---------------------------------------------------------------- directions
// Equal-angle cube map: face (axis a, sign), the two other coordinates
// divided by |d_a| and mapped through atan, so cells span equal angles along
// each face axis (solid angles within a factor 1.4 of each other; a plain
// cube map has 5.2, a latitude-longitude grid is unbounded at the poles).
uint32_t direction_cell(const Vec3& d) {
  int a = 0;
  if (std::abs(d.y()) > std::abs(d[a])) a = 1;
  if (std::abs(d.z()) > std::abs(d[a])) a = 2;
  const double m = std::abs(d[a]);
  const int face = 2 * a + (d[a] < 0);
  auto cell = [m](double x) {
    const double s = std::atan(x / m) * (4 / kPi);  // [-1, 1]
    return std::clamp(int(std::floor((s + 1) * 0.5 * kCube)), 0, kCube - 1);
  };
  return uint32_t((face * kCube + cell(d[(a + 2) % 3])) * kCube + cell(d[(a + 1) % 3]));
}

Vec3 cell_direction(uint32_t c) {
  // Every cell's direction, computed once (each vertex looks up seven).
  static const std::vector<Vec3> table = [] {
    std::vector<Vec3> t(6 * kCube * kCube);
    auto coord = [](int k) { return std::tan(((k + 0.5) * 2.0 / kCube - 1) * kPi / 4); };
    for (uint32_t q = 0; q < t.size(); ++q) {
      const int i = int(q % kCube), j = int(q / kCube % kCube), face = int(q / (kCube * kCube));
      const int a = face / 2;
      Vec3 d;
      d[a] = face % 2 ? -1 : 1;
      d[(a + 1) % 3] = coord(i);
      d[(a + 2) % 3] = coord(j);
      t[q] = d.normalized();
    }
    return t;
  }();
  return table[c];
}

// Unit vectors spanning the plane orthogonal to unit n.
void frame(const Vec3& n, Vec3& u, Vec3& v) {
  const Vec3 h = std::abs(n.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = n.cross(h).normalized();
  v = n.cross(u);
}

// A vertex's votes: the distinct cells of its normal and of six directions
// 0.7 cone away around it, each with the bin of the vertex's offset.
int votes_of(const Vec3& n, const Vec3& x, double cone, uint64_t* out) {
  Vec3 u, v;
  frame(n, u, v);
  const double r = std::tan(0.7 * cone);
  static const auto ring = [] {  // cos and sin of the six directions' angles
    std::array<std::array<double, 2>, kDirections> cs{};
    for (int k = 1; k < kDirections; ++k) cs[size_t(k)] = {std::cos(k * kPi / 3), std::sin(k * kPi / 3)};
    return cs;
  }();
  int count = 0;
  for (int k = 0; k < kDirections; ++k) {
    const auto& [c_k, s_k] = ring[size_t(k)];
    const Vec3 d = k == 0 ? n : Vec3((n + r * (c_k * u + s_k * v)).normalized());
    const uint32_t c = direction_cell(d);
    const double off = cell_direction(c).dot(x);
    for (uint32_t grid = 0; grid < 2; ++grid) {  // bit 31 of the bin word: the staggered grid
      const int64_t bin = int64_t(std::floor(off + 0.5 * grid)) + (int64_t(1) << 29);
      const uint64_t key = (uint64_t(c) << 32) | (uint64_t(grid) << 31) | uint32_t(bin);
      bool dup = false;
      for (int q = 0; q < count; ++q) dup |= out[q] == key;
      if (!dup) out[count++] = key;
    }
  }
  return count;
}

// ---------------------------------------------------------------- votes
Votes cast_votes(const Surface& S, double cone) {
  const size_t n = S.x.size();
  const double cos_cone = std::cos(cone);
  Votes V;
  // Only vertices whose normal agrees with every neighbour's within the
  // cone vote (curved regions then vote little).
  std::vector<uint64_t> keys(n * kMaxVotes);
  V.count.assign(n, 0);
  detail::parallel_ranges(n, 4096, [&](detail::IndexRange r) {
    for (size_t v = r.begin(); v < r.end(); ++v) {
      bool planar = true;
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1] && planar; ++k)
        planar = S.nrm[v].dot(S.nrm[S.adj[k]]) >= cos_cone;
      if (planar) V.count[v] = uint8_t(votes_of(S.nrm[v], S.x[v], cone, &keys[v * kMaxVotes]));
    }
  });
  // The (key, voter) pairs in the order of a sort by key then voter: a
  // counting sort by direction cell (each bucket keeps the voters in
  // order), then each bucket sorted by offset bin, (bin, voter) packed in
  // one word. Runs of one key are the accumulator's cells.
  constexpr size_t kCells = 6 * kCube * kCube;  // direction cells
  std::vector<uint64_t> bucket(kCells + 1, 0);
  for (size_t v = 0; v < n; ++v) {
    V.voters += V.count[v] > 0;
    for (uint32_t q = 0; q < V.count[v]; ++q) ++bucket[(keys[v * kMaxVotes + q] >> 32) + 1];
  }
  for (size_t c = 0; c < kCells; ++c) bucket[c + 1] += bucket[c];
  V.votes = bucket[kCells];
  std::vector<uint64_t> sorted(V.votes);  // offset bin << 32 | voter
  {
    std::vector<uint64_t> at(bucket.begin(), bucket.end() - 1);
    for (size_t v = 0; v < n; ++v)
      for (uint32_t q = 0; q < V.count[v]; ++q) {
        const uint64_t key = keys[v * kMaxVotes + q];
        sorted[at[key >> 32]++] = (key << 32) | v;
      }
  }
  detail::parallel_for(kCells, [&](size_t c) {
    std::sort(sorted.begin() + ptrdiff_t(bucket[c]), sorted.begin() + ptrdiff_t(bucket[c + 1]));
  });
  V.voter.resize(V.votes);
  for (size_t d = 0; d < kCells; ++d)
    for (uint64_t i = bucket[d]; i < bucket[d + 1]; ++i) {
      V.voter[i] = uint32_t(sorted[i]);
      const uint64_t key = (uint64_t(d) << 32) | (sorted[i] >> 32);
      if (i == bucket[d] || key != V.cell_key.back()) {
        V.cell_key.push_back(key);
        V.cell_begin.push_back(uint32_t(i));
        V.cell_count.push_back(0);
      }
      ++V.cell_count.back();
    }
  V.cell_begin.push_back(uint32_t(V.votes));
  // Each vote's cell, by the voter's vote slot (unvoting's look-up).
  V.vote_cell.assign(n * kMaxVotes, 0);
  detail::parallel_for(V.cell_key.size(), [&](size_t c) {
    for (uint32_t i = V.cell_begin[c]; i < V.cell_begin[c + 1]; ++i) {
      const uint32_t v = V.voter[i];
      for (uint32_t q = 0; q < V.count[v]; ++q)
        if (keys[v * kMaxVotes + q] == V.cell_key[c]) V.vote_cell[v * kMaxVotes + q] = uint32_t(c);
    }
  });
  return V;
}

double crossing(const Surface& S, size_t v, const Plane& P, double margin) {
  return detail::stab(P, S.inside(v), S.outside(v), margin);
}

// The largest lambda in [0, 1] such that (1 - lambda) P0 + lambda P1 stabs
// every stick of `cluster` with the margin (P0 does). The constraints
// -f(in) - m (f(out) - f(in)) >= 0 and f(out) - m (f(out) - f(in)) >= 0 are
// linear in (n, c), so each bounds lambda in closed form.
double feasible_step(const Surface& S, const std::vector<uint32_t>& cluster, const Plane& P0, const Plane& P1,
                     double m) {
  double lambda = 1;
  auto g = [&](const Plane& P, uint32_t v, double& g1, double& g2) {
    const double fi = P.n.dot(S.inside(v)) - P.c, fo = P.n.dot(S.outside(v)) - P.c;
    g1 = -fi - m * (fo - fi);
    g2 = fo - m * (fo - fi);
  };
  for (uint32_t v : cluster) {
    double a1, a2, b1, b2;
    g(P0, v, a1, a2);
    g(P1, v, b1, b2);
    if (b1 < 0) lambda = std::min(lambda, std::max(0.0, a1) / (std::max(0.0, a1) - b1));
    if (b2 < 0) lambda = std::min(lambda, std::max(0.0, a2) / (std::max(0.0, a2) - b2));
  }
  return lambda * (1 - 1e-9);
}

// Minimum-norm point of {w : a_i . w >= b_i} in R^3, by Seidel's randomized
// incremental method (an LP-type problem of combinatorial dimension 3): if
// constraint i cuts off the optimum of the earlier ones, the new optimum lies
// on its boundary, so recurse on it with one more equality. Expected O(m).

bool constrained_fit(const Surface& S, const std::vector<uint32_t>& cluster, const std::vector<Vec3>& pts,
                     const Vec3& towards, double margin, Plane& out, const std::vector<SideConstraint>& sides,
                     const std::vector<uint32_t>* center_within) {
  Vec3 m = Vec3::Zero();
  for (const Vec3& p : pts) m += p;
  m /= double(pts.size());
  const Plane F = fit_plane(pts, towards);
  Vec3 u, v;
  frame(F.n, u, v);
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (const Vec3& p : pts) {
    const Eigen::Vector3d z(u.dot(p - m), v.dot(p - m), -1);
    H += z * z.transpose();
  }
  H += 1e-12 * H.trace() * Eigen::Matrix3d::Identity();
  const Eigen::LLT<Eigen::Matrix3d> llt(H);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix3d L = llt.matrixL();
  // The optimum lies on some sticks' margin; solved with a hair more margin
  // its rounded plane still passes the check below (without this, every
  // fit whose optimum touched a margin failed by 1e-15 and fell back to the
  // line search).
  const double mq = margin + 1e-9;
  std::vector<Eigen::Vector3d> A;
  std::vector<double> B;
  A.reserve(2 * cluster.size());
  B.reserve(2 * cluster.size());
  auto add_stick = [&](uint32_t s) {
    // f(p) = n_F . (p - m) + phi(p) . z with phi(p) = (u . (p - m), v . (p - m), -1).
    const Vec3 pi = S.inside(s) - m, po = S.outside(s) - m;
    const Eigen::Vector3d phi_i(u.dot(pi), v.dot(pi), -1), phi_o(u.dot(po), v.dot(po), -1);
    const double fi = F.n.dot(pi), fo = F.n.dot(po);
    // g1 = -(1 - m) f(in) - m f(out) >= 0,  g2 = (1 - m) f(out) + m f(in) >= 0.
    const Eigen::Vector3d g1 = -(1 - mq) * phi_i - mq * phi_o, g2 = (1 - mq) * phi_o + mq * phi_i;
    const double k1 = -(1 - mq) * fi - mq * fo, k2 = (1 - mq) * fo + mq * fi;
    // g . z = g . L^-T w = (L^-1 g) . w
    A.push_back(L.triangularView<Eigen::Lower>().solve(g1));
    B.push_back(-k1);
    A.push_back(L.triangularView<Eigen::Lower>().solve(g2));
    B.push_back(-k2);
  };
  for (uint32_t s : cluster) add_stick(s);
  for (const SideConstraint& q : sides) {
    // outside: f(p) >= kSideMargin; inside: -f(p) >= kSideMargin.
    const Vec3 pq = q.p - m;
    const double sg = q.outside ? 1 : -1;
    const Eigen::Vector3d g = sg * Eigen::Vector3d(u.dot(pq), v.dot(pq), -1);
    A.push_back(L.triangularView<Eigen::Lower>().solve(g));
    B.push_back(kSideMargin * (1 + 1e-6) - sg * F.n.dot(pq));
  }
  MinNorm qp(A, B);
  Eigen::Vector3d w;
  if (!qp.solve(w)) return false;
  auto plane_of = [&](const Eigen::Vector3d& at) {
    const Eigen::Vector3d z = L.transpose().triangularView<Eigen::Upper>().solve(at);
    Plane P{F.n + z(0) * u + z(1) * v, 0};
    P.c = z(2) + P.n.dot(m);
    const double len = P.n.norm();
    P.n /= len;
    P.c /= len;
    return P;
  };
  if (center_within) {
    // Beyond the paper (FlatOptions::center_planes): from the least-squares
    // plane to the centre of the feasible set, the sticks of `center_within`
    // it stabs joining the constraints. Each step moves w to the midpoint of
    // its chord through the polytope along one of seven fixed directions
    // (whitened axes and diagonals); kCenterRounds sweeps.
    const Plane P0 = plane_of(w);
    const bool sorted = std::is_sorted(cluster.begin(), cluster.end());
    for (uint32_t s : *center_within)
      if (!(sorted && std::binary_search(cluster.begin(), cluster.end(), s)) && !std::isnan(crossing(S, s, P0, margin)))
        add_stick(s);
    for (int round = 0; round < kCenterRounds; ++round)
      for (int d = 0; d < 7; ++d) {
        const Eigen::Vector3d e = d < 3 ? Eigen::Vector3d::Unit(d)
                                        : Eigen::Vector3d(1, (d & 1) ? 1 : -1, (d & 2) ? 1 : -1).normalized();
        // The chord's ends (min / max: the same for any thread count).
        using Range = std::pair<double, double>;
        const Range chord = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, A.size(), 4096), Range{-1e300, 1e300},
            [&](const tbb::blocked_range<size_t>& r, Range c) {
              for (size_t i = r.begin(); i < r.end(); ++i) {
                const double ae = A[i].dot(e), slack = std::max(0.0, A[i].dot(w) - B[i]);
                if (ae > 1e-15) c.first = std::max(c.first, -slack / ae);
                else if (ae < -1e-15) c.second = std::min(c.second, slack / -ae);
              }
              return c;
            },
            [](const Range& a, const Range& b) { return Range{std::max(a.first, b.first), std::min(a.second, b.second)}; });
        const auto [lo, hi] = chord;
        if (lo > -1e299 && hi < 1e299 && hi > lo) w += 0.5 * (lo + hi) * e;
      }
  }
  const Plane P = plane_of(w);
  for (uint32_t s : cluster)
    if (std::isnan(crossing(S, s, P, margin))) return false;
  for (const SideConstraint& q : sides)
    if ((P.n.dot(q.p) - P.c) * (q.outside ? 1 : -1) <= 0) return false;
  out = P;
  return true;
}


Plane lerp(const Plane& a, const Plane& b, double l) {
  Plane p{(1 - l) * a.n + l * b.n, (1 - l) * a.c + l * b.c};
  const double len = p.n.norm();
  p.n /= len;
  p.c /= len;
  return p;
}


Surface make_surface(const StickSurface& s, const std::vector<double>& t, const detail::Adjacency& graph) {
  Surface S{&s, {}, {}, {}, graph.off, graph.adj};
  const size_t n = s.stick_count();
  S.x.resize(n);
  detail::parallel_for(n, [&](size_t v) {
    Vec3 p = s.sample_points(v)[0];
    p[s.axis(v)] += t[v];
    S.x[v] = p;
  });
  S.nrm.assign(n, Vec3::Zero());
  S.area.assign(n, 0);
  for (const Triangle& tr : s.triangles) {
    const Vec3 c = (S.x[tr[1]] - S.x[tr[0]]).cross(S.x[tr[2]] - S.x[tr[0]]);
    for (uint32_t v : tr) {
      S.nrm[v] += c;
      S.area[v] += c.norm() / 6;
    }
  }
  detail::parallel_for(n, [&](size_t v) {
    const double l = S.nrm[v].norm();
    S.nrm[v] = l > 0 ? Vec3(S.nrm[v] / l) : Vec3(0, 0, 1);
  });
  // Per-vertex normals of the pressed surface still carry a few degrees of
  // staircase noise; averaging over a few rings brings them under one.
  std::vector<Vec3> next(n);
  for (int round = 0; round < kNormalRings; ++round) {
    detail::parallel_for(n, [&](size_t v) {
      Vec3 sum = S.nrm[v];
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) sum += S.nrm[S.adj[k]];
      const double l = sum.norm();
      next[v] = l > 0 ? Vec3(sum / l) : S.nrm[v];
    });
    S.nrm.swap(next);
  }
  return S;
}


}  // namespace voxpress::flats_impl
