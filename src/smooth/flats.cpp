// Flats by plane voting and junction points (Chica et al., Section 3), and
// the Pressing pipeline around them. Theory of operation:
// include/voxpress/smooth/flats.h. Everything here works in index space
// (planes are affine-invariant); normals and angles that are compared with
// user thresholds are taken in the physical frame.
#include "voxpress/smooth/flats.h"

#include "core/timing.h"
#include "feature_tuning.h"
#include "quadric.h"
#include "surface_graph.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
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

namespace voxpress {

using detail::seconds_since;

namespace {

// The narrowest flat: a share of the smallest flat's side, capped (cells).
double min_width(const FlatOptions& o) {
  return std::min(detail::kFlatMaxWidth, detail::kFlatWidthShare * std::sqrt(o.min_area));
}

constexpr double kPi = std::numbers::pi;
constexpr int kCube = 64;  // cube-map cells per face side: ~1.4 degrees
constexpr int kNormalRings = 3;  // smoothing rounds of the estimated normals
// The growth also takes a stick the current plane misses by up to this
// fraction of it (the refit must then stab it, or it leaves): the sticks a
// plane a hair off misses come in lattice rows that would cut a face in
// bands. Box 64, seeds 1-30: 28 -> 29 with six flats, stick error 0.074 ->
// 0.065; 0.1 and 0.2 found fewer faces on the CAD part at 64^3.
constexpr double kGrowSlack = 0.05;
constexpr int kExtendRounds = 4;  // rounds of flat extension up to sharp edges
// An accumulator cell seeds a cluster when it has at least this share of
// min_area voters; the flat itself must still reach min_area after growth
// (accept). Voters are the vertices whose estimated normal lies within the
// cone of the cell's direction, so a face whose estimate its rounded edges
// bend has far fewer voters than sticks: fandisk 128's two 600-cell side
// faces had 46 in their best cell and were never tried with a share of 1
// (docs/ARCHITECTURE.md, Flats: Greedy extraction).
constexpr double kSeedShare = 0.3;
// The curvature test (Detector::curved, FlatOptions::curved_gain): a flat's
// neighbourhood is its core grown kCurvedRings rings over the vertices whose
// normal is within kCurvedWindow degrees of the plane's.
constexpr int kCurvedRings = 10;
constexpr double kCurvedWindow = 30;
constexpr uint32_t kTangentRings[2] = {2, 6};  // the curved side's rings fitted by the tangent test
constexpr uint32_t kRimJunctionRings = 2;      // rim members this close to a junction stay (rim_tangent_angle)
// Cells: how far from the flat's plane the tangent side's fitted points must
// rise for the rim to leave it (a fillet does; the rounded estimate along a
// box's crease stays within ~0.6 and fits a quadric that looks tangent).
constexpr double kRimFilletRise = 1.5;
// Junction test: points whose middle PCA eigenvalue is below this share of
// the largest are a row (their plane is arbitrary).
constexpr double kThinRow = 0.15;
// Detector::restab (near-axis faces): candidates within kRestabRings rings
// whose normal is within kRestabWindow degrees; searched when the plane stabs
// less than kRestabTrigger of them (not below kRestabGiveUp), or always when
// it lies within kRestabRange of a low-index direction (kLowIndex); a core
// the acceptance tests refused, when it stabs at least kRestabForced; over directions
// within kRestabRange degrees (kRestabSteps coarse steps each way, then two
// 5 x 5 grids 4 and 16 times finer), with at most kRestabSample sticks;
// taken when it stabs kRestabGain x as many; at most kRestabRounds rounds.
// Measured on boxes, cylinders, tori, the CAD part and fandisk
// (docs/ARCHITECTURE.md, Flats: Stabbing refit).
constexpr int kRestabRings = 10;
constexpr double kRestabWindow = 15;
constexpr double kRestabTrigger = 0.9;
constexpr double kRestabGiveUp = 0.75;
constexpr double kRestabForced = 0.7;
constexpr double kRestabRange = 4;
constexpr int kRestabSteps = 4;
constexpr size_t kRestabSample = 2000;
constexpr double kRestabGain = 1.02;
constexpr int kRestabRounds = 6;
// The low-index lattice directions, one of each +- pair: the 3 axes, the 6
// face diagonals and the 4 body diagonals (restab's near-lattice search).
const std::array<Vec3, 13> kLowIndex = [] {
  std::array<Vec3, 13> d;
  size_t k = 0;
  for (int a = 0; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c)
        if (a > 0 || b > 0 || (b == 0 && c > 0)) d[k++] = Vec3(a, b, c).normalized();
  return d;
}();

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
  const int i = int(c % kCube), j = int(c / kCube % kCube), face = int(c / (kCube * kCube));
  const int a = face / 2;
  const double sign = face % 2 ? -1 : 1;
  auto coord = [](int k) { return std::tan(((k + 0.5) * 2.0 / kCube - 1) * kPi / 4); };
  Vec3 d;
  d[a] = sign;
  d[(a + 1) % 3] = coord(i);
  d[(a + 2) % 3] = coord(j);
  return d.normalized();
}

// Unit vectors spanning the plane orthogonal to unit n.
void frame(const Vec3& n, Vec3& u, Vec3& v) {
  const Vec3 h = std::abs(n.x()) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = n.cross(h).normalized();
  v = n.cross(u);
}

// A vertex's votes: the distinct cells of its normal and of six directions
// 0.7 cone away around it, each with the bin of the vertex's offset.
constexpr int kMaxVotes = 7;
int votes_of(const Vec3& n, const Vec3& x, double cone, uint64_t* out) {
  Vec3 u, v;
  frame(n, u, v);
  const double r = std::tan(0.7 * cone);
  int count = 0;
  for (int k = 0; k < kMaxVotes; ++k) {
    const double ang = k * kPi / 3;
    const Vec3 d = k == 0 ? n : Vec3((n + r * (std::cos(ang) * u + std::sin(ang) * v)).normalized());
    const uint32_t c = direction_cell(d);
    const double off = cell_direction(c).dot(x);
    const uint64_t key = (uint64_t(c) << 32) | uint32_t(int64_t(std::floor(off)) + (int64_t(1) << 30));
    bool dup = false;
    for (int q = 0; q < count; ++q) dup |= out[q] == key;
    if (!dup) out[count++] = key;
  }
  return count;
}

// ---------------------------------------------------------------- planes
using detail::fit_plane;
using detail::Pca;
using detail::pca;
using detail::Plane;

// The surface data the detector reads.
struct Surface {
  const StickSurface* s;
  std::vector<Vec3> x, nrm;         // estimated vertex positions and unit normals (index space)
  std::vector<double> area;         // a third of the incident triangle areas (index space)
  std::vector<uint32_t> adj_off, adj;  // vertex adjacency (CSR)
  // The estimated positions of vertices vs, into pts.
  void positions(const std::vector<uint32_t>& vs, std::vector<Vec3>& pts) const {
    pts.resize(vs.size());
    for (size_t q = 0; q < vs.size(); ++q) pts[q] = x[vs[q]];
  }
  // Samples of stick v: inside and outside endpoints.
  Vec3 inside(size_t v) const { return s->inside_sample(v); }
  Vec3 outside(size_t v) const { return s->outside_sample(v); }
};

// t (from the inside sample) where the plane crosses stick v, or NaN when it
// does not cross it with the margin.
double crossing(const Surface& S, size_t v, const Plane& P, double margin) {
  const double fi = P.n.dot(S.inside(v)) - P.c, fo = P.n.dot(S.outside(v)) - P.c;
  if (!(fi < 0 && fo > 0)) return std::numeric_limits<double>::quiet_NaN();
  const double t = -fi / (fo - fi);
  return t >= margin && t <= 1 - margin ? t : std::numeric_limits<double>::quiet_NaN();
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

// A sample a plane must leave strictly on one side (crease_refit).
struct SideConstraint {
  Vec3 p;
  bool outside;
  auto operator<=>(const SideConstraint& o) const {
    return std::tie(p.x(), p.y(), p.z(), outside) <=> std::tie(o.p.x(), o.p.y(), o.p.z(), o.outside);
  }
  bool operator==(const SideConstraint&) const = default;
};
constexpr double kSideMargin = 1e-6;  // cells: how strictly a SideConstraint's sample is on its side

constexpr int kCenterRounds = 4;  // chord-midpoint sweeps of constrained_fit's centring

// Section 3's plane refinement, our choice of "best": least squares inside
// the feasible set. With n = n_F + a u + b v (n_F the least-squares normal
// of the points, u, v orthonormal to it) and the plane n . (x - m) = c'
// through the points' mean m, the squared residuals are a quadratic in
// z = (a, b, c') minimised at z = 0, and "the plane stabs stick s with the
// margin" is two linear inequalities in z. With H = L L^T the residuals'
// Hessian and w = L^T z this is the minimum-norm point of a polytope.
// `sides` adds one-sided constraints (crease_refit), linear in z as well.
// With `center_within`, the plane then moves to the centre of the feasible
// set (see there). Returns false when the cluster is infeasible or the solver fails
// numerically (the caller keeps a feasible plane).
bool constrained_fit(const Surface& S, const std::vector<uint32_t>& cluster, const std::vector<Vec3>& pts,
                     const Vec3& towards, double margin, Plane& out, const std::vector<SideConstraint>& sides = {},
                     const std::vector<uint32_t>* center_within = nullptr) {
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

// ---------------------------------------------------------------- detection
struct Detector {
  const Surface& S;
  const FlatOptions& o;
  std::vector<int32_t>& region;  // -1 unassigned
  std::vector<uint32_t> mark;    // per vertex: stamp of the cluster being grown
  uint32_t stamp = 0;

  double cos_cone;
  std::vector<uint8_t> rim;  // per vertex: added by a rim growth (not a core member)
  // A core vertex: its stick stabbed, its estimated vertex within tol of the
  // plane and its estimated normal within the cone of the plane's.
  // With `slack` > 0 the plane may miss the stick by up to that fraction of
  // it (the growth's test, see kGrowSlack).
  bool near(uint32_t v, const Plane& P, double tol, double slack = 0) const {
    if (S.nrm[v].dot(P.n) < cos_cone || std::abs(P.n.dot(S.x[v]) - P.c) > tol) return false;
    if (slack <= 0) return !std::isnan(crossing(S, v, P, o.margin));
    const double fi = P.n.dot(S.inside(v)) - P.c, fo = P.n.dot(S.outside(v)) - P.c;
    if (!(fo > fi)) return false;
    const double t = -fi / (fo - fi);
    return t >= o.margin - slack && t <= 1 - o.margin + slack;
  }

  // Breadth-first growth of `cluster` (all marked with the current stamp)
  // over unassigned neighbours accepted by `ok`, at most `rings` rings (-1: no limit).
  template <class Ok>
  void grow(std::vector<uint32_t>& cluster, size_t from, int rings, Ok ok) {
    size_t begin = from, end = cluster.size();
    for (int r = 0; rings < 0 || r < rings; ++r) {
      for (size_t q = begin; q < end; ++q) {
        const uint32_t v = cluster[q];
        for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
          const uint32_t w = S.adj[k];
          if (mark[w] == stamp || region[w] >= 0 || !ok(w)) continue;
          mark[w] = stamp;
          cluster.push_back(w);
        }
      }
      if (cluster.size() == end) break;
      begin = end;
      end = cluster.size();
    }
  }

  // The rim: the stabbed sticks within rim_rings of `cluster`, flagged.
  void grow_rim(std::vector<uint32_t>& cluster, const Plane& P) {
    const size_t before = cluster.size();
    grow(cluster, 0, detail::kRimRings, [&](uint32_t w) { return !std::isnan(crossing(S, w, P, o.margin)); });
    for (size_t i = before; i < cluster.size(); ++i) rim[cluster[i]] = 1;
  }

  // A cluster from the voters of one accumulator cell; empty if rejected.
  // `rejected` receives the core of a rejected cluster.
  std::vector<uint32_t> cluster_from(const std::vector<uint32_t>& seeds, Plane& P, std::vector<uint32_t>& rejected) {
    std::vector<Vec3> pts;
    Vec3 mean_n = Vec3::Zero();
    for (uint32_t v : seeds) {
      pts.push_back(S.x[v]);
      mean_n += S.nrm[v];
    }
    P = fit_plane(pts, mean_n);
    // The largest connected set of seeds the plane holds.
    std::vector<uint32_t> best;
    const uint32_t seed_mark = ++stamp, visited = ++stamp;
    for (uint32_t v : seeds)
      if (near(v, P, detail::kFlatTolerance)) mark[v] = seed_mark;
    for (uint32_t v : seeds) {
      if (mark[v] != seed_mark) continue;
      std::vector<uint32_t> comp{v};
      mark[v] = visited;
      for (size_t q = 0; q < comp.size(); ++q)
        for (uint32_t k = S.adj_off[comp[q]]; k < S.adj_off[comp[q] + 1]; ++k) {
          const uint32_t w = S.adj[k];
          if (mark[w] == seed_mark) {
            mark[w] = visited;
            comp.push_back(w);
          }
        }
      if (comp.size() > best.size()) best.swap(comp);
    }
    if (best.size() < 3) return {};
    ++stamp;
    for (uint32_t v : best) mark[v] = stamp;
    std::vector<uint32_t> core = std::move(best);
    for (int round = 0; round < 12; ++round) {
      const size_t before = core.size();
      grow(core, 0, -1, [&](uint32_t w) { return near(w, P, detail::kFlatTolerance, kGrowSlack); });
      S.positions(core, pts);
      Plane next;
      if (!constrained_fit(S, core, pts, P.n, o.margin, next)) {
        // Fallback (no plane stabs them all): keep the members the current
        // plane stabs and move it towards the least-squares one as far as
        // feasibility allows.
        std::erase_if(core, [&](uint32_t v) { return std::isnan(crossing(S, v, P, o.margin)); });
        S.positions(core, pts);
        const Plane F = fit_plane(pts, P.n);
        next = lerp(P, F, feasible_step(S, core, P, F, o.margin));
      }
      const double moved = (next.n - P.n).norm() + std::abs(next.c - P.c);
      P = next;
      if (core.size() == before && moved < 1e-7) break;
    }
    // The stabbing refit (restab). An accepted core keeps its result only
    // when it explains its neighbourhood: next to a gently curved face
    // (fandisk) the search tilts the plane into it. A refused core whose
    // pillowed estimate failed the spread or bend test is rescued the same
    // way: a plane tangent to a curved surface stabs a strip and misses its
    // sides (measured with a 10-degree window, which holds fewer of a
    // strip's sides than the 15 used: cylinders at 128-256 0.58-0.79 of the
    // candidates, torus 0.74-0.85; pillowed box faces and the CAD part's
    // chamfer 0.93-1.0).
    bool ok = accept(core, P);
    if (o.passes.on(Pass::stab_refit) && (ok || area_of(core) >= o.min_area)) {
      std::vector<uint32_t> again = core;
      Plane Q = P;
      if (restab(again, Q, !ok) >= kRestabTrigger) {
        core.swap(again);
        P = Q;
        ok = true;
      }
    }
    if (ok && o.passes.on(Pass::curved_test) && curved(core, P)) ok = false;
    if (!ok) {
      rejected = std::move(core);
      return {};
    }
    ++stamp;  // restab marked its candidates: only the core may stay marked
    for (uint32_t v : core) mark[v] = stamp;
    grow_rim(core, P);
    return core;
  }

  // Beyond the paper: whether the plane of an accepted core is a tangent
  // strip of a curved face. The estimate cannot always tell: a small
  // cylinder's strip at 256^3 (the CAD part's rounded corners, 20 cells of
  // radius) passes the spread test, the stabbing refit rescues it (its plane
  // stabs 0.98 of the candidates), and in a second pass its frozen estimate
  // is exactly planar. The sticks can tell: around a face, the lattice turns
  // at its edges and no smooth surface stabs much more than the plane does;
  // around a strip, the curved face goes on, and a quadric fitted to the
  // neighbourhood's estimate stabs the sticks on both sides of the strip.
  // Measured (quadric / plane stabbed sticks): faces of boxes, cylinders
  // and the CAD part at 64-256 0.55-1.09, one piece of a box 64 face 1.21;
  // the CAD part's corner strips at 256^3 1.77-1.81; fandisk's flats at
  // 256^3 a continuum up to 2.24, those on its gently curved faces from
  // ~1.3. The default gain (FlatOptions::curved_gain) is 1.3: fandisk 256
  // seeds 1-3 drop from 27-36 flats to 13-14 and result->truth from
  // 0.060-0.064 to 0.055-0.057; the generated shapes are unchanged (1.2
  // would refuse the box piece: docs/ARCHITECTURE.md, Flats: Curvature test).
  bool curved(const std::vector<uint32_t>& core, const Plane& P) {
    std::vector<uint32_t> ext;
    neighbourhood(core, P, kCurvedRings, kCurvedWindow, ext);
    std::vector<Vec3> pts;
    S.positions(ext, pts);
    detail::Quadric Q;
    if (!Q.fit(pts, P.n)) return false;
    size_t by_quadric = 0;
    for (uint32_t v : ext) by_quadric += !std::isnan(Q.exit(S.inside(v), S.outside(v), 0.5, o.margin, 1 - o.margin));
    return double(by_quadric) > detail::kCurvedGain * double(stabbed_by(ext, P));
  }

  // The core and the unassigned vertices within `rings` rings of it whose
  // estimated normal is within `window` degrees of the plane's, into `out`
  // (restab's candidates, curved's neighbourhood). Returns the stamp they
  // all carry in `mark`.
  uint32_t neighbourhood(const std::vector<uint32_t>& core, const Plane& P, int rings, double window,
                         std::vector<uint32_t>& out) {
    const uint32_t m = ++stamp;
    for (uint32_t v : core) mark[v] = m;
    out = core;
    const double cos_window = std::cos(window * kPi / 180);
    grow(out, 0, rings, [&](uint32_t w) { return S.nrm[w].dot(P.n) >= cos_window; });
    return m;
  }

  // How many of the sticks of `vs` the plane stabs (with the margin).
  size_t stabbed_by(const std::vector<uint32_t>& vs, const Plane& P) const {
    size_t k = 0;
    for (uint32_t v : vs) k += !std::isnan(crossing(S, v, P, o.margin));
    return k;
  }

  // Beyond the paper: the plane that stabs the most sticks around an
  // accepted core, found without the estimate's positions. Near a lattice
  // axis (a face 2 degrees off z is terraces ~28 cells wide) or near a plane
  // containing one, the estimate of a face between sharp edges is a pillow:
  // Pressing bulges it up to a cell outwards over ten cells, since the
  // sticks of such a face bound its slope only loosely. The core then holds
  // a piece of the face, tilted 1-3 degrees (box 128 seed 15: three such
  // pieces instead of two faces). The truth stabs every stick of the face
  // whatever the estimate, so: when the plane stabs less than
  // kRestabTrigger of the candidates (the core and the unassigned vertices
  // within kRestabRings rings whose normal is within kRestabWindow of the
  // plane's), search the directions within kRestabRange of it for the plane
  // stabbing the most candidates (per direction, the offsets that stab a
  // stick form an interval: a sweep over their ends), and when it stabs
  // kRestabGain as many, take its connected stabbed set as the core and
  // refit (least squares inside the feasible set, as always). Repeat while
  // the core grows. `force`: a core the acceptance tests refused, searched
  // only when its plane already stabs kRestabForced of the candidates.
  // Returns the share of the final candidates the final plane stabs (the
  // caller keeps the result only when it is at least kRestabTrigger).
  double restab(std::vector<uint32_t>& core, Plane& P, bool force) {
    // Within kRestabRange of a low-index lattice direction (an axis, a face
    // or a body diagonal) the share says little: the lattice's samples lie
    // in layers across such a normal, so a plane tilted a little from it
    // crosses few layers, and a plane along the direction through one of
    // them stabs most of the face's sticks while lying up to half a cell
    // off. The CAD part's end faces at 128^3 seed 15 lie 2 degrees off z
    // and rise 1.1 cells across: an axis-aligned plane through one terrace
    // stabbed 0.90-0.92 of their candidates (or, once a flat took that
    // terrace, a plane through the next one 0.70); box 128 seed 48's face 1
    // degree off a face diagonal left a 3-degree plane through one layer as
    // a seventh flat. An accepted core's plane there is always searched; a
    // refused core's still from kRestabForced (cylinders' tangent strips
    // near a diagonal would cost their detection 80 % more). The result is
    // still kept only when it reaches kRestabTrigger; a face on the
    // direction gains nothing from the search and keeps its plane.
    const double cos_range = std::cos(kRestabRange * kPi / 180);
    const bool near_lattice = std::any_of(kLowIndex.begin(), kLowIndex.end(),
                                       [&](const Vec3& d) { return std::abs(P.n.dot(d)) > cos_range; });
    std::vector<uint32_t> cand, next;
    std::vector<Vec3> pts;
    for (int round = 0;; ++round) {
      const uint32_t core_mark = neighbourhood(core, P, kRestabRings, kRestabWindow, cand);
      const double share = double(stabbed_by(cand, P)) / double(cand.size());
      // Not forced (an accepted core), a plane that explains its
      // neighbourhood stays, and one far from explaining it (next to a
      // gently curved face: 0.46-0.68 on fandisk) is not searched: the
      // search would tilt it into that face. Forced (a rejected core), the
      // plane is searched from kRestabForced: the CAD part's 45-degree
      // chamfer at 128^3 seed 20 is rounded from both sides, its cores lean
      // 3-4 degrees, are refused, and stab 0.70-0.74 (at 0.9 they were not
      // searched, at 0.6 tori and fandisk at 256 paid 2-3x the detection
      // time for nothing). Cylinders reject hundreds of tangent-strip cores,
      // but a search only keeps what ends at kRestabTrigger.
      const bool stop = force ? share < kRestabForced
                              : !near_lattice && ((round == 0 && share >= kRestabTrigger) || share < kRestabGiveUp);
      if (round == kRestabRounds || stop) return share;
      Plane Q;
      size_t now = 0;
      const size_t best = most_stabbing(cand, P, Q, now);
      if (double(best) < kRestabGain * double(now)) return share;
      // The connected set of candidates (still marked core_mark: grow
      // marked them so) that Q stabs, from the core's stabbed vertices.
      const uint32_t taken = ++stamp;
      next.clear();
      for (uint32_t v : core)
        if (!std::isnan(crossing(S, v, Q, o.margin))) {
          mark[v] = taken;
          next.push_back(v);
        }
      grow(next, 0, -1, [&](uint32_t w) { return mark[w] == core_mark && !std::isnan(crossing(S, w, Q, o.margin)); });
      if (next.size() <= core.size()) return share;
      S.positions(next, pts);
      if (!constrained_fit(S, next, pts, Q.n, o.margin, P)) P = Q;
      core.swap(next);
    }
  }

  // The plane with normal within kRestabRange of P0's stabbing the most
  // sticks of `cand` (every stride-th, at most kRestabSample): a coarse then
  // a fine grid of directions; per direction, the best offset by a sweep.
  // Returns its count on those sticks; `now` receives P0's.
  size_t most_stabbing(const std::vector<uint32_t>& cand, const Plane& P0, Plane& out, size_t& now) const {
    const size_t stride = std::max<size_t>(1, cand.size() / kRestabSample);
    std::vector<uint32_t> use;
    for (size_t q = 0; q < cand.size(); q += stride) use.push_back(cand[q]);
    now = stabbed_by(use, P0);
    Vec3 u, v;
    frame(P0.n, u, v);
    struct Best {
      size_t count = 0;
      double c = 0;
    };
    // Starts and ends sorted apart and merged, a start first at equal
    // offsets; the best offset lies halfway to the next event.
    auto sweep = [&](const Vec3& d) {
      std::vector<double> starts, ends;
      starts.reserve(use.size());
      ends.reserve(use.size());
      for (uint32_t q : use) {
        const double a = d.dot(S.inside(q)), b = d.dot(S.outside(q));
        if (!(b > a)) continue;
        starts.push_back(a + o.margin * (b - a));
        ends.push_back(b - o.margin * (b - a));
      }
      std::sort(starts.begin(), starts.end());
      std::sort(ends.begin(), ends.end());
      Best r;
      size_t i = 0, j = 0;
      for (size_t open = 0; i < starts.size(); ++i) {
        while (ends[j] < starts[i]) ++j, --open;  // every start has its end at or after it
        if (++open > r.count) {
          r.count = open;
          const double next = i + 1 < starts.size() ? std::min(starts[i + 1], ends[j]) : ends[j];
          r.c = 0.5 * (starts[i] + next);
        }
      }
      return r;
    };
    Vec3 centre = P0.n;
    Best best = sweep(centre);
    Vec3 best_d = centre;
    const double coarse = kRestabRange / kRestabSteps;
    for (const auto& [step, half] : {std::pair{coarse, kRestabSteps}, std::pair{coarse / 4, 2}, std::pair{coarse / 16, 2}}) {
      const int side = 2 * half + 1;
      std::vector<Best> res(size_t(side * side));
      std::vector<Vec3> dir(res.size());
      const double h = std::tan(step * kPi / 180);
      for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) dir[size_t(i * side + j)] = (centre + (i - half) * h * u + (j - half) * h * v).normalized();
      tbb::parallel_for(size_t(0), res.size(), [&](size_t k) { res[k] = sweep(dir[k]); });
      for (size_t k = 0; k < res.size(); ++k)  // fixed order: deterministic
        if (res[k].count > best.count) {
          best = res[k];
          best_d = dir[k];
        }
      centre = best_d;
      frame(centre, u, v);
    }
    out = {best_d, best.c};
    return best.count;
  }

  // Section 3's minimum size, plus width and bend (beyond the paper: without
  // them a plane tangent to a cylinder holds a long strip of its sticks).
  double area_of(const std::vector<uint32_t>& vs) const {
    double area = 0;
    for (uint32_t v : vs) area += S.area[v];
    return area;
  }

  bool accept(const std::vector<uint32_t>& core, const Plane& P) const {
    if (area_of(core) < o.min_area) return false;
    // Spread of the normals about the plane's, robust to the rounded rims:
    // the median angle. A strip where a plane is tangent to a curved surface
    // is *defined* by the cone, so its normals fill it (median ~ cone / 2 at
    // any resolution, whether the strip is straight or a torus's ring); a
    // face's sit near the plane's normal. (Measured: strips 1.4-2.5 deg,
    // faces 0.2-1.25 deg with the default 3 deg cone.)
    std::vector<double> spread(core.size());
    for (size_t q = 0; q < core.size(); ++q) spread[q] = std::acos(std::clamp(S.nrm[core[q]].dot(P.n), -1.0, 1.0));
    std::nth_element(spread.begin(), spread.begin() + ptrdiff_t(spread.size() / 2), spread.end());
    // At 64^3 the estimate of a box is a pillow and its smaller faces spread
    // up to 1.8 deg: they are missed (docs/BENCHMARKS.md).
    if (spread[spread.size() / 2] > detail::kFlatMaxSpread * kPi / 180) return false;
    Vec3 u, v;
    frame(P.n, u, v);
    // In-plane coordinates, centred.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (uint32_t q : core) mean += Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v));
    mean /= double(core.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    // Normal bend: tangential normal components regressed on position,
    // (nu, nv) = A + B (pu, pv); B's largest singular value is a curvature.
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
    for (uint32_t q : core) {
      const Eigen::Vector2d p = Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v)) - mean;
      cov += p * p.transpose();
      const Eigen::Vector3d a(1, p.x(), p.y());
      ata += a * a.transpose();
      atb += a * Eigen::RowVector2d(S.nrm[q].dot(u), S.nrm[q].dot(v));
    }
    cov /= double(core.size());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> pe(cov);
    if (std::sqrt(12 * std::max(0.0, pe.eigenvalues()(0))) < min_width(o)) return false;
    const Eigen::Matrix<double, 3, 2> coef = ata.ldlt().solve(atb);
    Eigen::Matrix2d B = coef.bottomRows<2>().transpose();  // rows: nu, nv; columns: d/dpu, d/dpv
    const Eigen::Matrix2d sym = 0.5 * (B + B.transpose());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> be(sym);
    const int big = std::abs(be.eigenvalues()(0)) > std::abs(be.eigenvalues()(1)) ? 0 : 1;
    const double kappa = std::abs(be.eigenvalues()(big));
    const Eigen::Vector2d dir = be.eigenvectors().col(big);
    double lo = 1e300, hi = -1e300;
    for (uint32_t q : core) {
      const double s = Eigen::Vector2d(S.x[q].dot(u), S.x[q].dot(v)).dot(dir);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    return kappa * (hi - lo) <= detail::kFlatMaxBend * kPi / 180;
  }
};

// Beyond the paper: the flats' planes refitted with their creases' samples
// (docs/ARCHITECTURE.md, Flats: Crease refit). A flat's own sticks pin its
// plane poorly about a lattice axis the face nearly contains (box 128 seed
// 29: 0.13 degrees, 0.09 cell off at its corners, all its sticks still
// stabbed), but the samples along its sharp edges know more. At a convex
// crease the solid is the intersection of the flats' half-spaces, so each
// inside sample there is inside every plane, and each outside sample is
// outside at least one: the one plane it is not clearly (kCreaseClear)
// inside of, when there is one. At a concave crease (the union) the roles
// swap. The samples considered are those of the junctions and members
// within kCreaseRings rings of two or more flats, and within kCreaseWindow
// of the plane they constrain. A flat whose plane leaves such a sample on
// the wrong side is refitted: least squares of its members near the plane,
// inside the set stabbing all its members and keeping every constraint
// (constrained_fit), taken when it moves less than kCreaseTurn degrees.
// With FlatOptions::center_planes every flat is refitted in the first round
// and its plane moved to the centre of that feasible set (every member the
// least-squares plane stabs staying stabbed).
// Rounds until no plane moves. Returns whether any moved.
constexpr int kCreaseRings = 2;
constexpr int kCreaseReach = 8;
constexpr double kCreaseWindow = 0.25;  // cells
constexpr double kCreaseClear = 0.1;    // cells
constexpr double kCreaseTurn = 1;       // degrees
constexpr int kCreaseRounds = 3;
bool crease_refit(const Surface& S, const FlatOptions& o, FlatSegmentation& seg, std::vector<Plane>& planes,
                  std::vector<uint8_t>& moved) {
  const size_t n = S.x.size(), F = planes.size();
  moved.assign(F, 0);
  if (F < 2) return false;
  auto height = [&](int32_t f, const Vec3& p) { return planes[size_t(f)].n.dot(p) - planes[size_t(f)].c; };
  std::vector<std::vector<uint32_t>> members(F);
  for (size_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0) members[size_t(seg.region[v])].push_back(uint32_t(v));
  bool any = false;
  struct Scratch {
    detail::RingScratch rs, wide;
    std::vector<int32_t> near, wider;
    std::vector<std::pair<int32_t, SideConstraint>> sides;
    std::vector<uint8_t> broken;
  };
  // The constraints that junction or member v adds (see above).
  auto gather = [&](uint32_t v, Scratch& sc) {
    const int32_t own = seg.region[v];
    auto add = [&](int32_t f, const Vec3& p, bool outside) {
      const double h = height(f, p) * (outside ? 1 : -1);  // > 0: on its side
      if (h < -kCreaseWindow) return;
      sc.sides.push_back({f, {p, outside}});
      if (h <= 0) sc.broken[size_t(f)] = 1;
    };
    detail::rings_around(v, kCreaseRings, S.adj_off, S.adj, [](uint32_t) { return true; }, sc.rs);
    std::vector<int32_t>& near = sc.near;
    near.clear();
    detail::add_flats(sc.rs.out, seg.region, near);
    if (near.size() < 2) return;
    // Convex or concave: the members here (on their planes) lie inside the other flats' planes, or outside.
    const int kind = detail::crease_kind(
        sc.rs.out, seg.region, near, [&](uint32_t w) -> Vec3 { return S.inside(w) + seg.t[w] * (S.outside(w) - S.inside(w)); },
        height);
    if (kind == 0) return;
    const bool convex = kind > 0;
    // Every plane but v's own keeps the sample that must be on its side of all of them.
    const Vec3 all = convex ? S.inside(v) : S.outside(v);
    for (int32_t g : near)
      if (g != own) add(g, all, !convex);
    if (own >= 0) return;  // a member's own plane separates its samples: the disjunction holds
    // The disjunction must know every plane that may bound the solid here
    // (a corner's third face, whose rim may stop a few rings short).
    detail::rings_around(v, kCreaseReach, S.adj_off, S.adj, [](uint32_t) { return true; }, sc.wide);
    sc.wider = near;
    detail::add_flats(sc.wide.out, seg.region, sc.wider);
    // The sample that must be on the other side of one plane: the plane it is not clearly inside (outside) of.
    const Vec3 one = convex ? S.outside(v) : S.inside(v);
    const double sg = convex ? 1 : -1;
    int32_t pick = -1;
    bool clear = true;
    for (int32_t g : sc.wider)
      if (sg * height(g, one) > -kCreaseClear) {
        if (pick >= 0) clear = false;
        pick = g;
      }
    if (pick >= 0 && clear) add(pick, one, convex);
  };
  std::vector<Vec3> pts;
  for (int round = 0; round < kCreaseRounds; ++round) {
    // Ring distance to a border between regions (flats, curved): beyond
    // kCreaseRings, no other flat is near and a member is inner.
    const std::vector<uint32_t> depth = detail::region_border_rings(seg.region, kCreaseRings, S.adj_off, S.adj);
    tbb::enumerable_thread_specific<Scratch> scratch([F] {
      Scratch sc;
      sc.broken.assign(F, 0);
      return sc;
    });
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(n), 1024), [&](const tbb::blocked_range<uint32_t>& r) {
      Scratch& sc = scratch.local();
      for (uint32_t v = r.begin(); v < r.end(); ++v)
        if ((seg.region[v] >= 0 || seg.junction[v]) && depth[v] != detail::kUnreached) gather(v, sc);
    });
    // Merged, then sorted: the same constraints in the same order for any number of threads.
    std::vector<std::vector<SideConstraint>> sides(F);
    std::vector<uint8_t> broken(F, 0);
    for (const Scratch& sc : scratch) {
      for (const auto& [f, q] : sc.sides) sides[size_t(f)].push_back(q);
      for (size_t f = 0; f < F; ++f) broken[f] |= sc.broken[f];
    }
    bool again = false;
    for (size_t f = 0; f < F; ++f) {
      if (!broken[f] && !(o.passes.on(Pass::center_planes) && round == 0)) continue;
      std::sort(sides[f].begin(), sides[f].end());
      sides[f].erase(std::unique(sides[f].begin(), sides[f].end()), sides[f].end());
      // Fitted: the members more than kCreaseRings rings from any other
      // region (next to one, a member may be another face's stick the rim
      // took, which no plane near the true one stabs); the least squares
      // over those near the plane.
      std::vector<uint32_t> inner, core;
      for (uint32_t v : members[f]) {
        if (depth[v] != detail::kUnreached) continue;
        inner.push_back(v);
        if (std::abs(planes[f].n.dot(S.x[v]) - planes[f].c) <= detail::kFlatTolerance) core.push_back(v);
      }
      if (core.size() < 3) continue;
      S.positions(core, pts);
      Plane P;
      if (!constrained_fit(S, inner, pts, planes[f].n, kSideMargin, P, sides[f], o.passes.on(Pass::center_planes) ? &members[f] : nullptr))
        continue;
      if (detail::degrees_between(P.n, planes[f].n) > kCreaseTurn) continue;
      planes[f] = P;
      moved[f] = 1;
      again = true;
      // The members it no longer stabs with the margin leave (the extension
      // may give them to a neighbour; Pressing places them).
      std::vector<uint32_t> kept;
      for (uint32_t v : members[f]) {
        if (std::isnan(crossing(S, v, P, o.margin))) {
          seg.region[v] = -1;
          seg.t[v] = std::numeric_limits<double>::quiet_NaN();
        } else {
          kept.push_back(v);
        }
      }
      members[f] = std::move(kept);
    }
    if (!again) break;
    any = true;
  }
  return any;
}

Surface make_surface(const StickSurface& s, const std::vector<double>& t) {
  Surface S;
  S.s = &s;
  const size_t n = s.stick_count();
  S.x.resize(n);
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
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
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    const double l = S.nrm[v].norm();
    S.nrm[v] = l > 0 ? Vec3(S.nrm[v] / l) : Vec3(0, 0, 1);
  });
  detail::vertex_adjacency(n, s.triangles, S.adj_off, S.adj);
  // Per-vertex normals of the pressed surface still carry a few degrees of
  // staircase noise; averaging over a few rings brings them under one.
  std::vector<Vec3> next(n);
  for (int round = 0; round < kNormalRings; ++round) {
    tbb::parallel_for(size_t(0), n, [&](size_t v) {
      Vec3 sum = S.nrm[v];
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) sum += S.nrm[S.adj[k]];
      const double l = sum.norm();
      next[v] = l > 0 ? Vec3(sum / l) : S.nrm[v];
    });
    S.nrm.swap(next);
  }
  return S;
}


}  // namespace

size_t FlatSegmentation::frozen_count() const {
  size_t c = 0;
  for (int32_t r : region) c += r >= 0;
  return c;
}

FlatSegmentation find_flats(const StickSurface& s, const SliceCurves& curves, const std::vector<double>& estimate,
                            const FlatOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.stick_count();
  if (estimate.size() != n) throw std::invalid_argument("find_flats: the estimate does not match the sticks");
  FlatSegmentation seg;
  seg.region.assign(n, -1);
  seg.t.assign(n, std::numeric_limits<double>::quiet_NaN());
  seg.junction.assign(n, 0);
  seg.barrier.assign(n, 0);
  if (n == 0) return seg;
  const Surface S = make_surface(s, estimate);
  const double cone = detail::kFlatCone * kPi / 180, cos_cone = std::cos(cone);

  // ---- Votes (Section 3): only vertices whose normal agrees with every
  // neighbour's within the cone (curved regions then vote little).
  std::vector<uint64_t> keys(n * kMaxVotes);
  std::vector<uint8_t> count(n, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v < r.end(); ++v) {
      bool planar = true;
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1] && planar; ++k)
        planar = S.nrm[v].dot(S.nrm[S.adj[k]]) >= cos_cone;
      if (planar) count[v] = uint8_t(votes_of(S.nrm[v], S.x[v], cone, &keys[v * kMaxVotes]));
    }
  });
  std::vector<uint64_t> offsets(n + 1, 0);
  for (size_t v = 0; v < n; ++v) offsets[v + 1] = offsets[v] + count[v];
  seg.stats.votes = offsets[n];
  // (key, voter) pairs sorted: runs are accumulator cells with their voters.
  struct Vote {
    uint64_t key;
    uint32_t voter;
    bool operator<(const Vote& b) const { return key < b.key || (key == b.key && voter < b.voter); }
  };
  std::vector<Vote> votes(offsets[n]);
  tbb::parallel_for(size_t(0), n, [&](size_t v) {
    for (uint32_t q = 0; q < count[v]; ++q) votes[offsets[v] + q] = {keys[v * kMaxVotes + q], uint32_t(v)};
  });
  for (size_t v = 0; v < n; ++v) seg.stats.voters += count[v] > 0;
  tbb::parallel_sort(votes.begin(), votes.end());
  std::vector<uint64_t> cell_key;
  std::vector<uint32_t> cell_begin, cell_count;
  for (size_t i = 0; i < votes.size(); ++i)
    if (i == 0 || votes[i].key != votes[i - 1].key) {
      cell_key.push_back(votes[i].key);
      cell_begin.push_back(uint32_t(i));
      cell_count.push_back(0);
      ++cell_count.back();
    } else {
      ++cell_count.back();
    }
  cell_begin.push_back(uint32_t(votes.size()));
  seg.stats.cells = cell_key.size();
  auto cell_of = [&](uint64_t key) {
    return size_t(std::lower_bound(cell_key.begin(), cell_key.end(), key) - cell_key.begin());
  };

  // ---- Greedy extraction, best cell first (lazy max-heap; ties by cell index).
  std::priority_queue<std::pair<uint32_t, int64_t>> heap;
  for (size_t c = 0; c < cell_key.size(); ++c) heap.push({cell_count[c], -int64_t(c)});
  Detector det{S, o, seg.region, std::vector<uint32_t>(n, 0), 0, cos_cone, std::vector<uint8_t>(n, 0)};
  ProgressCounter progress(o.progress, "flats", 0);
  const Mat3 M = s.lattice.index_to_physical_matrix();
  const Mat3 Minv_t = M.inverse().transpose();
  auto flat_of = [&](const Plane& P) {
    Flat f;
    f.index_normal = P.n;
    f.index_offset = P.c;
    // Physical plane: n_i . M^-1 (x - origin) = c.
    const Vec3 np = Minv_t * P.n;
    f.normal = np.normalized();
    f.offset = (P.c + np.dot(s.lattice.origin)) / np.norm();
    return f;
  };
  // Members were stabbed with the margin; only rounding could put t a hair
  // outside it, so clamp (the sign test cannot fail: see crossing).
  auto frozen_t = [&](uint32_t v, const Plane& P) {
    const double fi = P.n.dot(S.inside(v)) - P.c, fo = P.n.dot(S.outside(v)) - P.c;
    if (!(fi < 0 && fo > 0)) throw std::logic_error("find_flats: a flat's plane does not cross one of its sticks");
    return std::clamp(-fi / (fo - fi), o.margin, 1 - o.margin);
  };
  std::vector<uint32_t> seeds;
  auto unvote = [&](uint32_t v) {  // drops the stick's votes from the accumulator
    for (uint32_t q = 0; q < count[v]; ++q) {
      const uint64_t key = keys[v * kMaxVotes + q];
      const size_t cc = cell_of(key);
      if (cell_key[cc] == key && cell_count[cc] > 0) --cell_count[cc];
    }
    count[v] = 0;
  };
  while (!heap.empty()) {
    const auto [cnt, neg] = heap.top();
    heap.pop();
    const size_t c = size_t(-neg);
    if (cnt != cell_count[c]) {
      if (cell_count[c] > 0) heap.push({cell_count[c], neg});
      continue;
    }
    // Too few voters to seed a cluster: nothing left can (kSeedShare).
    if (double(cnt) < kSeedShare * o.min_area) break;
    ++seg.stats.tried;
    seeds.clear();
    for (uint32_t i = cell_begin[c]; i < cell_begin[c + 1]; ++i)
      if (seg.region[votes[i].voter] < 0) seeds.push_back(votes[i].voter);
    cell_count[c] = 0;  // used: accepted or not, this cell is done
    if (double(seeds.size()) < kSeedShare * o.min_area) continue;
    Plane P;
    std::vector<uint32_t> rejected;
    const std::vector<uint32_t> members = det.cluster_from(seeds, P, rejected);
    // A rejected core's vertices stop voting (they may still join a flat
    // grown from elsewhere): without this a cylinder's wall is tried once per
    // direction cell along its circle of normals.
    for (uint32_t v : rejected) unvote(v);
    if (members.empty()) continue;
    const int32_t id = int32_t(seg.flats.size());
    for (uint32_t v : members) {
      seg.region[v] = id;
      seg.t[v] = frozen_t(v, P);
      unvote(v);
    }
    seg.flats.push_back(flat_of(P));
    progress.add(1);
  }
  // ---- Merge (beyond the paper): the greedy growth can take one face as
  // two flats, each fitted to a piece whose estimate leans its own way (CAD
  // part 64 seed 50: a piece of the plate's side 2.5 degrees off). Adjacent
  // flats whose normals are within merge_angle become one when one plane
  // stabs the sticks of both cores (the constrained fit) and, of their
  // members, at least 90 %; the rim is then grown again around them.
  if (o.passes.on(Pass::merge) && seg.flats.size() > 1) {
    const double cos_merge = std::cos(detail::kMergeAngle * kPi / 180);
    detail::RingScratch rs;
    std::vector<std::vector<uint32_t>> members(seg.flats.size());
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) members[size_t(seg.region[v])].push_back(uint32_t(v));
    std::vector<Plane> planes(seg.flats.size());
    for (size_t f = 0; f < planes.size(); ++f) planes[f] = {seg.flats[f].index_normal, seg.flats[f].index_offset};
    // The members of flats a and b that plane P stabs.
    auto members_stabbed = [&](size_t a, size_t b, const Plane& P) {
      std::vector<uint32_t> stabbed;
      for (size_t f : {a, b})
        for (uint32_t v : members[f])
          if (!std::isnan(crossing(S, v, P, o.margin))) stabbed.push_back(v);
      return stabbed;
    };
    // The plane stabbing the cores of flats a and b: their members near
    // their own plane, then (when no plane stabs them all) only those
    // `inner` rings inside their flat, since a tilted plane's core reaches
    // past the face's rounded edges. When that plane stabs fewer than `need`
    // of their members (or none stabs the cores), each flat's own plane is
    // tried too: a face split into an accurate piece and one whose core
    // reaches onto a rounded edge (CAD part 128 seed 1's chamfer since the
    // circle correction: 0.26 degrees apart, no plane stabbing both cores,
    // each plane stabbing 98 % of the other's members). Returns the members
    // the chosen plane P stabs.
    auto joint = [&](size_t a, size_t b, double need, Plane& P) {
      std::vector<uint32_t> core, stabbed;
      std::vector<Vec3> pts;
      for (const uint32_t inner : {0u, 3u}) {
        core.clear();
        for (size_t f : {a, b})
          for (uint32_t v : members[f]) {
            if (!det.near(v, planes[f], detail::kFlatTolerance)) continue;
            bool in = true;
            if (inner > 0) {
              detail::rings_around(v, inner, S.adj_off, S.adj, [](uint32_t) { return true; }, rs);
              for (const auto& [w, d] : rs.out) in &= seg.region[w] == int32_t(f);
            }
            if (in) core.push_back(v);
          }
        S.positions(core, pts);
        if (core.size() < 3 || !constrained_fit(S, core, pts, planes[a].n, o.margin, P)) continue;
        stabbed = members_stabbed(a, b, P);
        break;
      }
      for (const size_t f : {a, b}) {
        if (double(stabbed.size()) >= need) break;
        std::vector<uint32_t> own = members_stabbed(a, b, planes[f]);
        if (own.size() > stabbed.size()) {
          stabbed = std::move(own);
          P = planes[f];
        }
      }
      return stabbed;
    };
    for (bool merged = true; merged;) {
      merged = false;
      for (size_t a = 0; a < members.size() && !merged; ++a) {
        std::vector<uint8_t> touches(members.size(), 0);
        for (uint32_t v : members[a])
          for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k)
            if (const int32_t r = seg.region[S.adj[k]]; r >= 0) touches[size_t(r)] = 1;
        for (size_t b = a + 1; b < members.size() && !merged; ++b) {
          if (!touches[b] || planes[a].n.dot(planes[b].n) < cos_merge) continue;
          Plane P;
          const double need = 0.9 * double(members[a].size() + members[b].size());
          std::vector<uint32_t> both = joint(a, b, need, P);
          if (double(both.size()) < need) continue;
          for (size_t f : {a, b})
            for (uint32_t v : members[f]) {
              seg.region[v] = -1;
              seg.t[v] = std::numeric_limits<double>::quiet_NaN();
              det.rim[v] = 0;
            }
          ++det.stamp;
          for (uint32_t v : both) det.mark[v] = det.stamp;
          det.grow_rim(both, P);
          for (uint32_t v : both) seg.region[v] = int32_t(a);
          members[a] = std::move(both);
          members[b].clear();
          planes[a] = P;
          merged = true;
        }
      }
    }
    // Renumber the survivors in order, with their planes and frozen t.
    std::vector<Flat> kept;
    std::vector<int32_t> id(members.size(), -1);
    for (size_t f = 0; f < members.size(); ++f) {
      if (members[f].empty()) continue;
      id[f] = int32_t(kept.size());
      kept.push_back(flat_of(planes[f]));
      for (uint32_t v : members[f]) seg.t[v] = frozen_t(v, planes[f]);
    }
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) seg.region[v] = id[size_t(seg.region[v])];
    seg.flats = std::move(kept);
  }
  seg.stats.seconds_detect = seconds_since(t0);

  // ---- Junctions (Section 3): fresh vertices next to a frozen one whose
  // fresh 2-ring plane leans more than junction_angle from the flat.
  const auto t1 = std::chrono::steady_clock::now();
  const double cos_j = std::cos(o.junction_angle * kPi / 180);
  const double cell = std::cbrt(std::abs(M.determinant()));
  tbb::enumerable_thread_specific<detail::RingScratch> scratch;
  // Beyond the paper: whether the curved side of fresh vertex v continues
  // flat f tangentially within `cos_max`: a quadric fitted to the fresh
  // vertices kTangentRings away (on the estimate) fits within
  // tangent_residual and its normal, where v projects onto the flat, is
  // within that angle of the flat's. A fillet passes; at a true crease the
  // estimate is rounded, so the fit is poor or its normal there leans. With
  // min_rise > 0 the fitted points must also reach that many cells off the
  // flat's plane.
  const auto fresh = [&](uint32_t w) { return seg.region[w] < 0; };
  // The flat of v's first frozen neighbour, or -1.
  const auto first_flat = [&](size_t v) {
    int32_t f0 = -1;
    for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1] && f0 < 0; ++k) f0 = seg.region[S.adj[k]];
    return f0;
  };
  auto tangent = [&](uint32_t v, int32_t f, double cos_max, double min_rise, detail::RingScratch& rs,
                     std::vector<Vec3>& pts) {
    detail::rings_around(v, kTangentRings[1], S.adj_off, S.adj, fresh, rs);
    pts.clear();
    Vec3 outward = Vec3::Zero();
    for (const auto& [w, d] : rs.out)
      if (d >= kTangentRings[0]) {
        pts.push_back(M * S.x[w]);
        outward += M * (S.outside(w) - S.inside(w));
      }
    detail::Quadric Q;
    const Flat& F = seg.flats[size_t(f)];
    if (min_rise > 0) {
      double rise = 0;
      for (const Vec3& p : pts) rise = std::max(rise, std::abs(F.normal.dot(p) - F.offset));
      if (rise < min_rise * cell) return false;
    }
    if (!Q.fit(pts, outward) || Q.residual > detail::kTangentResidual * cell) return false;
    const Vec3 p = M * S.x[v];
    const Vec3 foot = p - (F.normal.dot(p) - F.offset) * F.normal;
    return std::abs(Q.normal_at(foot).dot(F.normal)) >= cos_max;
  };
  auto detect_junctions = [&] {
  std::fill(seg.junction.begin(), seg.junction.end(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<Vec3> pts;
      detail::RingScratch& rs = scratch.local();
      for (size_t v = r.begin(); v < r.end(); ++v) {
        if (seg.region[v] >= 0) continue;
        const int32_t f0 = first_flat(v);
        if (f0 < 0) continue;
        // Fresh vertices of the 2-ring (v included), in physical space.
        detail::rings_around(uint32_t(v), 2, S.adj_off, S.adj, fresh, rs);
        bool sharp = true;  // too few fresh vertices for a plane: squeezed between flats
        if (rs.out.size() >= 3) {
          pts.clear();
          // Beyond the paper: fresh vertices on the plane of v's (first)
          // flat are its rim stopped short, not the curved side. Left in,
          // where a rim stopped a cell or two short of a crease the plane
          // leaned halfway between the two sides, under junction_angle
          // (CAD part 128 seed 30's boss rim: 26.6 degrees), so no junction
          // marked the crease and the flat never reached it. Without them
          // the points can be a thin row along the crease, whose plane is
          // any plane through it (box 128 seed 8: the crease refit then
          // moved a face 0.1 cell); then all of them are used.
          Pca q;
          bool off_plane = false;  // q is the plane of the points off the flat's plane
          if (o.passes.on(Pass::ring_off_plane)) {
            const Flat& F = seg.flats[size_t(f0)];
            for (const auto& [w, d] : rs.out) {
              const Vec3 p = M * S.x[w];
              if (w == v || std::abs(F.normal.dot(p) - F.offset) > detail::kJunctionRingOffPlane * cell) pts.push_back(p);
            }
            if (pts.size() >= 3) {
              q = pca(pts);
              off_plane = q.eigenvalues(1) >= kThinRow * q.eigenvalues(2);
            }
          }
          if (!off_plane) {
            pts.clear();
            for (const auto& [w, d] : rs.out) pts.push_back(M * S.x[w]);
            q = pca(pts);
          }
          if (q.eigenvalues(1) > 1e-9 * std::max(1.0, q.eigenvalues(2))) {  // not collinear
            const Vec3 ns = q.normal;
            // The neighbouring flats the plane leans past the angle from.
            std::array<int32_t, 4> leaning{};
            size_t leaning_count = 0;
            for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
              const int32_t f = seg.region[S.adj[k]];
              if (f < 0 || std::abs(ns.dot(seg.flats[size_t(f)].normal)) >= cos_j) continue;
              if (std::find(leaning.begin(), leaning.begin() + leaning_count, f) == leaning.begin() + leaning_count &&
                  leaning_count < leaning.size())
                leaning[leaning_count++] = f;
            }
            // Beyond the paper: a curved face tangent to the flat (a
            // fillet) leans past the angle a couple of rings from the border
            // once the flat's rim has reached onto it. The estimate is not
            // rounded there (there is no crease to round), so the tangent
            // test's quadric is good and its normal at the flat is the
            // flat's: smooth. Each flat is judged on its own: a fillet
            // tangent to one flat can meet another at a crease (CAD part
            // 128 seed 3: 35 and 75 degrees from the two flats beside one
            // vertex; judging the tangent one alone left a gap in the
            // other's crease, 0.72 voxel from any label).
            sharp = false;
            for (size_t i = 0; i < leaning_count && !sharp; ++i)
              sharp = !(o.passes.on(Pass::tangent_borders) && tangent(uint32_t(v), leaning[i], cos_j, 0, rs, pts));
          }
        }
        seg.junction[v] = sharp;
      }
    });
  };
  std::vector<Plane> planes(seg.flats.size());
  std::vector<Vec3> centroid(seg.flats.size(), Vec3::Zero());
  {
    std::vector<size_t> members(seg.flats.size(), 0);
    for (size_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0) {
        centroid[size_t(seg.region[v])] += S.x[v];
        ++members[size_t(seg.region[v])];
      }
    for (size_t f = 0; f < planes.size(); ++f) {
      planes[f] = {seg.flats[f].index_normal, seg.flats[f].index_offset};
      centroid[f] /= double(std::max<size_t>(members[f], 1));
    }
  }
  // Beyond the paper: flats reach their sharp edges. At a convex edge the
  // solid is the intersection of the two half-spaces, so every stick there
  // is stabbed by at least one of the planes and its true crossing is the
  // one nearest its inside sample; at a concave edge (union) the farthest.
  // A fresh vertex flagged as a junction joins a neighbouring flat whose
  // plane stabs its stick, and a frozen vertex moves to a neighbouring flat
  // when that rule prefers it; a few rounds, junctions recomputed each time.
  // Smooth borders (no junction) are left to the smoothing.
  auto prefer = [&](int32_t f, double tf, int32_t g, double tg) {
    // true when (g, tg) is the better crossing than (f, tf) for this stick
    const bool convex = planes[size_t(g)].n.dot(centroid[size_t(f)]) < planes[size_t(g)].c;
    return convex ? tg < tf : tg > tf;
  };
  std::vector<uint8_t> refitted;
  bool stale = true;  // regions changed since the junctions were last detected
  for (int round = 0; round < kExtendRounds && !seg.flats.empty(); ++round) {
    if (stale) detect_junctions();
    stale = false;
    // Beyond the paper: the planes also keep their creases' samples on the right side.
    const bool refit = o.passes.on(Pass::crease_refit) && crease_refit(S, o, seg, planes, refitted);
    if (refit) {
      for (size_t f = 0; f < planes.size(); ++f)
        if (refitted[f]) seg.flats[f] = flat_of(planes[f]);
      for (size_t v = 0; v < n; ++v)
        if (const int32_t f = seg.region[v]; f >= 0 && refitted[size_t(f)]) seg.t[v] = frozen_t(uint32_t(v), planes[size_t(f)]);
      detect_junctions();
    }
    std::vector<std::pair<uint32_t, int32_t>> moves;
    for (size_t v = 0; v < n; ++v) {
      const int32_t cur = seg.region[v];
      if (cur < 0 && !seg.junction[v]) continue;
      int32_t best = cur;
      double tb = cur >= 0 ? crossing(S, v, planes[size_t(cur)], 0) : 0;
      for (uint32_t k = S.adj_off[v]; k < S.adj_off[v + 1]; ++k) {
        const int32_t g = seg.region[S.adj[k]];
        if (g < 0 || g == best) continue;
        const double tg = crossing(S, v, planes[size_t(g)], o.margin);
        if (std::isnan(tg)) continue;
        if (best < 0 || prefer(best, tb, g, tg)) {
          best = g;
          tb = tg;
        }
      }
      if (best != cur) moves.push_back({uint32_t(v), best});
    }
    if (moves.empty() && !refit) break;
    for (const auto& [v, f] : moves) {
      seg.region[v] = f;
      seg.t[v] = crossing(S, v, planes[size_t(f)], o.margin);
    }
    stale = !moves.empty();
  }
  if (stale) detect_junctions();
  // Beyond the paper: the rim leaves the tangent fillets. The rim takes the
  // stabbed sticks two rings past the core so that a flat reaches its
  // creases, where the estimate was rounded; at a smooth border onto a
  // curved face tangent to the flat it runs onto that face instead, where a
  // plane stabs sticks as long as the face stays within a stick of it, and
  // freezes them up to ~0.4 cell off the truth (a 6-cell fillet two cells
  // past its foot). Where the curved side passes the tangent test within
  // rim_tangent_angle and rises kRimFilletRise off the plane, the rim's
  // members next to the border (one ring) go back to the curved side, unless
  // a junction is within two rings (the rim is the flat's reach to that
  // crease).
  if (o.passes.on(Pass::rim_tangent) && !seg.flats.empty()) {
    const double cos_t = std::cos(detail::kRimTangentAngle * kPi / 180);
    std::vector<uint32_t> near_junction(n, detail::kUnreached), near_tangent(n, detail::kUnreached), junctions;
    std::vector<std::pair<uint32_t, int32_t>> borders;  // a smooth border's fresh vertex and its first flat neighbour
    for (uint32_t v = 0; v < n; ++v) {
      if (seg.region[v] >= 0) continue;
      if (seg.junction[v]) {
        near_junction[v] = 0;
        junctions.push_back(v);
        continue;
      }
      if (const int32_t f0 = first_flat(v); f0 >= 0) borders.push_back({v, f0});
    }
    // The smooth borders that are tangent (in parallel; each test reads the
    // regions only).
    std::vector<uint8_t> is_tangent(borders.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, borders.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<Vec3> pts;
      detail::RingScratch& rs = scratch.local();
      for (size_t i = r.begin(); i < r.end(); ++i)
        is_tangent[i] = tangent(borders[i].first, borders[i].second, cos_t, kRimFilletRise, rs, pts);
    });
    std::vector<uint32_t> tangent_borders;
    for (size_t i = 0; i < borders.size(); ++i)
      if (is_tangent[i]) {
        near_tangent[borders[i].first] = 0;
        tangent_borders.push_back(borders[i].first);
      }
    const auto any = [](uint32_t, uint32_t) { return true; };
    detail::spread_rings(std::move(junctions), 0, kRimJunctionRings, S.adj_off, S.adj, near_junction, any);
    detail::spread_rings(std::move(tangent_borders), 0, 1, S.adj_off, S.adj, near_tangent, any);
    size_t released = 0;
    for (uint32_t v = 0; v < n; ++v)
      if (seg.region[v] >= 0 && det.rim[v] && near_tangent[v] != detail::kUnreached &&
          near_junction[v] == detail::kUnreached) {
        seg.region[v] = -1;
        seg.t[v] = std::numeric_limits<double>::quiet_NaN();
        ++released;
      }
    seg.stats.rim_released = released;
    if (released > 0) detect_junctions();
  }
  // Sizes, once the extension has settled the members. Index-space area ->
  // physical: |det M| |M^-T n| for a plane of unit index normal n.
  for (Flat& f : seg.flats) f.sticks = 0, f.area_cells = 0;
  for (size_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0) {
      Flat& f = seg.flats[size_t(seg.region[v])];
      ++f.sticks;
      f.area_cells += S.area[v];
    }
  for (Flat& f : seg.flats) f.area = f.area_cells * std::abs(M.determinant()) * (Minv_t * f.index_normal).norm();
  // Barriers: frozen vertices next to a junction along a slice curve.
  for (int a = 0; a < 3; ++a) {
    const auto& ids = curves.ids[a];
    const auto& off = curves.offsets[a];
    for (size_t cv = 0; cv + 1 < off.size(); ++cv) {
      const uint32_t b = off[cv], m = off[cv + 1] - b;
      for (uint32_t i = 0; i < m; ++i) {
        const uint32_t p = ids[b + i], q = ids[b + (i + 1) % m];
        if (seg.region[p] >= 0 && seg.junction[q]) seg.barrier[p] = 1;
        if (seg.region[q] >= 0 && seg.junction[p]) seg.barrier[q] = 1;
      }
    }
  }
  for (size_t v = 0; v < n; ++v) {
    seg.stats.junctions += seg.junction[v];
    seg.stats.barriers += seg.barrier[v];
  }
  seg.stats.seconds_junctions = seconds_since(t1);
  return seg;
}

void apply_flats(StickSurface& s, const FlatSegmentation& f) {
  for (size_t v = 0; v < s.stick_count(); ++v) {
    if (f.region[v] < 0) {
      s.t[v] = 0.5;
      continue;
    }
    // seg.t is measured from the inside sample; StickSurface::t from the lower one.
    s.t[v] = s.lower_inside(v) ? f.t[v] : 1 - f.t[v];
  }
}

FeaturePressStats press_with_flats(StickSurface& s, const SliceCurves& curves, const PressOptions& po,
                                   const FlatOptions* fo, FlatSegmentation* out) {
  FeaturePressStats st;
  if (!fo) {
    st.press = press(s, curves, po);
    if (out) {
      *out = FlatSegmentation{};
      out->region.assign(s.stick_count(), -1);
    }
    return st;
  }
  const auto t0 = std::chrono::steady_clock::now();
  StickSurface est = s;
  PressOptions eo = po;
  eo.iterations = detail::kEstimateIterations;  // fixed: the flats do not depend on po.iterations
  // nor on po.levels: the detection's thresholds were tuned on 2 stages (with
  // 3, CAD part 256 seed 30 gains a 242-stick piece of a face, 3.4 degrees
  // off it, that no plane merges back).
  eo.levels = 2;
  eo.tolerance = 0;
  eo.progress = nullptr;
  eo.free_ends = false;  // see PressOptions::free_ends
  press(est, curves, eo);
  double t_est = seconds_since(t0);
  // The crease refit serves the final planes only: refitting a first pass's
  // piece of a face (box 64 seed 15: 1.8 degrees off) changed the second
  // estimate enough to lose that face.
  FlatOptions early = *fo;
  early.passes.disable(Pass::crease_refit);
  FlatSegmentation seg = find_flats(s, curves, est.t, detail::kDetectionPasses > 1 ? early : *fo);
  // Beyond the paper: a second pass. The estimate of a face next to rounded
  // edges is a pillow whose normals spread past the acceptance test (64^3
  // boxes, thin plates). Pressed again with the first pass's flats frozen,
  // their edges are sharp and the faces between them flat, so the second
  // detection (from scratch, on the new estimate) finds the faces the
  // first missed. Box 64, seeds 1-30: 162 -> 177 of 180 faces.
  auto frozen_of = [](const FlatSegmentation& f) {
    std::vector<uint8_t> frozen(f.region.size());
    for (size_t v = 0; v < frozen.size(); ++v) frozen[v] = f.region[v] >= 0;
    return frozen;
  };
  for (int pass = 1; pass < detail::kDetectionPasses && !seg.flats.empty(); ++pass) {
    const auto t1 = std::chrono::steady_clock::now();
    est = s;
    apply_flats(est, seg);
    press(est, curves, eo, frozen_of(seg), seg.barrier);
    t_est += seconds_since(t1);
    const FlatStats before = seg.stats;
    seg = find_flats(s, curves, est.t, pass + 1 < detail::kDetectionPasses ? early : *fo);
    seg.stats.seconds_detect += before.seconds_detect;
    seg.stats.seconds_junctions += before.seconds_junctions;
  }
  seg.stats.seconds_estimate = t_est;
  apply_flats(s, seg);
  // Beyond the paper: the vertices near sharp flat/curved borders placed
  // by the curved side's fit (fit_creases), and those of creases between
  // two curved faces by both sides' fits (fit_curved_creases), then the rest pressed again
  // around them; the iterations are shared out so the cost is unchanged.
  // Each round re-presses a fifth of the iterations (fewer past 4 rounds, so
  // the first press keeps a share).
  const bool creases = fo->passes.on(Pass::crease_fit) && seg.stats.junctions > 0;
  const int rest = creases ? po.iterations / std::max(5, detail::kCreaseRounds + 1) : 0;
  PressOptions first = po;
  first.iterations = po.iterations - detail::kCreaseRounds * rest;
  st.press = press(s, curves, first, frozen_of(seg), seg.barrier);
  for (int round = 0; creases && round < detail::kCreaseRounds; ++round) {
    std::vector<uint8_t> fixed;
    const auto t2 = std::chrono::steady_clock::now();
    seg.stats.crease_vertices = fit_creases(s, seg, *fo, &fixed);
    st.passes.add(Pass::crease_fit, seconds_since(t2), round + 1 == detail::kCreaseRounds ? seg.stats.crease_vertices : 0);
    const auto t3 = std::chrono::steady_clock::now();
    // The curved crease vertices cut the slice curves too (barriers), so
    // neither side's bilaplacian reaches across them.
    std::vector<uint8_t> barrier = seg.barrier;
    barrier.resize(s.stick_count(), 0);
    seg.stats.curved_crease_vertices = fit_curved_creases(s, seg, *fo, fixed, &barrier);
    st.passes.add(Pass::curved_creases, seconds_since(t3),
                  round + 1 == detail::kCreaseRounds ? seg.stats.curved_crease_vertices : 0);
    seg.stats.seconds_creases += seconds_since(t2);
    for (size_t v = 0; v < fixed.size(); ++v) fixed[v] |= seg.region[v] >= 0;
    PressOptions again = po;
    again.iterations = rest;
    again.levels = 1;  // the fine stage goes on
    const PressStats ps = press(s, curves, again, fixed, barrier);
    st.press.iterations += ps.iterations;
    st.press.seconds += ps.seconds;
    st.press.last_max_change = ps.last_max_change;
  }
  st.flats = seg.stats;
  st.passes.add(Pass::flats, seg.stats.seconds_estimate + seg.stats.seconds_detect + seg.stats.seconds_junctions,
                seg.flats.size());
  if (out) *out = std::move(seg);
  return st;
}

void add_region_attributes(Mesh& mesh, const FlatSegmentation& f, bool colors) {
  const size_t n = mesh.vertex_count();
  if (f.region.size() != n) throw std::invalid_argument("add_region_attributes: segmentation does not match the mesh");
  MeshAttribute region{"region", ScalarType::i32, std::vector<double>(n)};
  MeshAttribute junction{"junction", ScalarType::u8, std::vector<double>(n)};
  for (size_t v = 0; v < n; ++v) {
    region.values[v] = f.region[v];
    junction.values[v] = f.junction.empty() ? 0 : f.junction[v];
  }
  mesh.vertex_attributes.push_back(std::move(region));
  mesh.vertex_attributes.push_back(std::move(junction));
  if (!colors) return;
  mesh.colors.resize(n);
  for (size_t v = 0; v < n; ++v) mesh.colors[v] = region_color(f.region[v], !f.junction.empty() && f.junction[v]);
}

std::array<uint8_t, 4> region_color(int32_t region, bool junction) {
  if (junction) return {255, 140, 0, 255};
  if (region < 0) return {170, 170, 170, 255};
  // Golden-angle hues: neighbouring ids get distant colours.
  const double h = std::fmod(double(region) * 137.50776, 360.0) / 60.0;
  const double x = 1 - std::abs(std::fmod(h, 2.0) - 1);
  double rgb[3] = {0, 0, 0};
  const int sector = int(h);
  const int order[6][2] = {{0, 1}, {1, 0}, {1, 2}, {2, 1}, {2, 0}, {0, 2}};  // HSV sectors: (full, rising)
  rgb[order[sector][0]] = 1;
  rgb[order[sector][1]] = x;
  for (double& c : rgb) c = 0.25 + 0.65 * c;
  return {uint8_t(255 * rgb[0]), uint8_t(255 * rgb[1]), uint8_t(255 * rgb[2]), 255};
}

}  // namespace voxpress
