// Fidelity metrics (see include/voxpress/eval/metrics.h for the definitions).
//
// Passes: (1) the stick metric over the vertices (each vertex mapped to
// index space; on a stick when two coordinates are integers within 1e-4 and
// the stick's samples differ), one segment/truth crossing query per vertex;
// (2) result -> truth over area samples of the result and over its vertices;
// (3) truth -> result over area samples of the truth, against a BVH of the
// result. Work is split into fixed chunks whose partial sums are added in
// chunk order, so the figures are identical for any thread count.
#include "voxpress/eval/metrics.h"

#include <tbb/parallel_sort.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "mesh_query.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

struct Acc {
  double sum = 0, sum2 = 0, max = 0;
  size_t n = 0;
  void add(double d) {
    sum += d;
    sum2 += d * d;
    max = std::max(max, d);
    ++n;
  }
  void merge(const Acc& o) {
    sum += o.sum;
    sum2 += o.sum2;
    max = std::max(max, o.max);
    n += o.n;
  }
  DistanceStats stats() const {
    DistanceStats s;
    s.count = n;
    if (n) {
      s.mean = sum / double(n);
      s.rms = std::sqrt(sum2 / double(n));
      s.max = max;
    }
    return s;
  }
};

// Indices of `points` along a Morton (Z-order) curve over their bounding
// box: closest-point queries issued in this order hit the BVH's nodes in
// cache (3-4x faster than random order). Ties keep index order, so the
// order — and every sum accumulated along it — is deterministic.
std::vector<uint32_t> morton_order(const std::vector<Vec3>& points) {
  auto spread = [](uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
  };
  Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 ext = (hi - lo).cwiseMax(1e-300);
  std::vector<std::pair<uint64_t, uint32_t>> key(points.size());
  detail::parallel_for(points.size(), [&](size_t i) {
    const Vec3 u = ((points[i] - lo).cwiseQuotient(ext) * 2097151.0).cwiseMax(0.0).cwiseMin(2097151.0);
    key[i] = {spread(uint64_t(u.x())) | spread(uint64_t(u.y())) << 1 | spread(uint64_t(u.z())) << 2, uint32_t(i)};
  });
  tbb::parallel_sort(key.begin(), key.end());
  std::vector<uint32_t> order(points.size());
  for (size_t i = 0; i < key.size(); ++i) order[i] = key[i].second;
  return order;
}

// Runs f(begin, end, chunk) over fixed chunks of [0, n) in parallel.
template <class F>
void chunked(size_t n, size_t chunk, F&& f) {
  const size_t chunks = (n + chunk - 1) / chunk;
  detail::parallel_for(chunks, [&](size_t c) { f(c * chunk, std::min(n, (c + 1) * chunk), c); });
}

constexpr size_t kChunk = 4096;

// A physical difference in voxel units (cells): its length in index space.
double vox_length(const Mat3& to_index, const Vec3& d) {
  return (to_index * d).norm();
}

// (1) Stick metric.
void measure_sticks(const Mesh& result, const Truth& truth, const BinaryVolume& vol, const Mat3& to_index,
                    const Vec3& origin, EvalReport& r) {
  const size_t nchunks = (result.positions.size() + kChunk - 1) / kChunk;
  std::vector<Acc> acc_vox(nchunks), acc_phys(nchunks);
  chunked(result.positions.size(), kChunk, [&](size_t b, size_t e, size_t c) {
    for (size_t v = b; v < e; ++v) {
      const Vec3 u = to_index * (result.positions[v] - origin);
      int axis = -1, integral = 0;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(u[a] - std::round(u[a])) <= 1e-4)
          ++integral;
        else
          axis = a;
      }
      if (integral != 2 || axis < 0) continue;
      std::array<int64_t, 3> lo{};
      for (int a = 0; a < 3; ++a) lo[size_t(a)] = int64_t(a == axis ? std::floor(u[a]) : std::round(u[a]));
      auto hi = lo;
      hi[size_t(axis)] += 1;
      if (vol.at(lo[0], lo[1], lo[2]) == vol.at(hi[0], hi[1], hi[2])) continue;  // not a stick
      const double t = u[axis] - double(lo[size_t(axis)]);
      const Vec3 pa = vol.lattice.to_physical(Vec3(double(lo[0]), double(lo[1]), double(lo[2])));
      const Vec3 pb = vol.lattice.to_physical(Vec3(double(hi[0]), double(hi[1]), double(hi[2])));
      const double s = truth.crossing(pa, pb, t);
      if (std::isnan(s)) continue;
      acc_vox[c].add(std::abs(t - s));
      acc_phys[c].add(std::abs(t - s) * vol.lattice.spacing[axis]);
    }
  });
  Acc av, ap;
  for (size_t c = 0; c < nchunks; ++c) {
    av.merge(acc_vox[c]);
    ap.merge(acc_phys[c]);
  }
  r.stick_vertices = av.n;
  if (av.n) {
    r.stick_rms_vox = av.stats().rms;
    r.stick_max_vox = av.stats().max;
    r.stick_rms = ap.stats().rms;
  }
}

// (2) Result -> truth: area samples (mean, RMS, max, normal error) and vertices (max).
void measure_result_to_truth(const Mesh& result, const Truth& truth, const detail::MeshQuery& result_query,
                             const EvalOptions& o, const Mat3& to_index, EvalReport& r) {
  auto vox = [&](const Vec3& d) { return vox_length(to_index, d); };
  const size_t n = result.triangles.empty() ? 0 : o.samples;
  std::vector<Vec3> pts(n);
  std::vector<uint32_t> face(n);
  detail::parallel_for(n, [&](size_t i) {
    const auto s = result_query.sample(o.seed, i);
    pts[i] = s.point;
    face[i] = s.face;
  });
  const std::vector<uint32_t> order = morton_order(pts);
  const size_t nchunks = (n + kChunk - 1) / kChunk;
  std::vector<Acc> phys(nchunks), voxs(nchunks);
  std::vector<double> angle(nchunks, 0);
  chunked(n, kChunk, [&](size_t b, size_t e, size_t c) {
    for (size_t k = b; k < e; ++k) {
      const uint32_t i = order[k];
      const SurfacePoint q = truth.closest(pts[i], &result_query.normal(face[i]));
      phys[c].add((q.point - pts[i]).norm());
      voxs[c].add(vox(q.point - pts[i]));
      const double cosang = std::clamp(result_query.normal(face[i]).dot(q.normal), -1.0, 1.0);
      angle[c] += std::acos(cosang);
    }
  });
  Acc p, x;
  double ang = 0;
  for (size_t c = 0; c < nchunks; ++c) {
    p.merge(phys[c]);
    x.merge(voxs[c]);
    ang += angle[c];
  }
  // Vertices contribute to the maxima only (they are not area-uniform).
  const size_t vchunks = (result.positions.size() + kChunk - 1) / kChunk;
  std::vector<double> vmax(vchunks, 0), vmax_vox(vchunks, 0);
  chunked(result.positions.size(), kChunk, [&](size_t b, size_t e, size_t c) {
    for (size_t v = b; v < e; ++v) {
      const SurfacePoint q = truth.closest(result.positions[v]);
      vmax[c] = std::max(vmax[c], (q.point - result.positions[v]).norm());
      vmax_vox[c] = std::max(vmax_vox[c], vox(q.point - result.positions[v]));
    }
  });
  r.result_to_truth = p.stats();
  r.result_to_truth_vox = x.stats();
  for (size_t c = 0; c < vchunks; ++c) {
    r.result_to_truth.max = std::max(r.result_to_truth.max, vmax[c]);
    r.result_to_truth_vox.max = std::max(r.result_to_truth_vox.max, vmax_vox[c]);
  }
  r.normal_error_deg = p.n ? ang / double(p.n) * 180 / std::numbers::pi : 0;
}

// (2b) Result -> truth RMS by Dunavant's 7-point rule (degree 5) on every
// triangle: the same points for the same triangle, so two meshes that
// differ in a few places differ only there.
void measure_result_to_truth_rule(const Mesh& result, const Truth& truth, bool with_volume, const Mat3& to_index,
                                  EvalReport& r) {
  auto vox = [&](const Vec3& d) { return vox_length(to_index, d); };
  constexpr double a1 = 0.059715871789770, b1 = 0.470142064105115;
  constexpr double a2 = 0.797426985353087, b2 = 0.101286507323456;
  constexpr double w1 = 0.132394152788506, w2 = 0.125939180544827;
  constexpr std::array<std::array<double, 4>, 7> rule{{{1 / 3.0, 1 / 3.0, 1 / 3.0, 0.225},
                                                       {a1, b1, b1, w1},
                                                       {b1, a1, b1, w1},
                                                       {b1, b1, a1, w1},
                                                       {a2, b2, b2, w2},
                                                       {b2, a2, b2, w2},
                                                       {b2, b2, a2, w2}}};
  const size_t nf = result.triangles.size(), nchunks = (nf + kChunk - 1) / kChunk;
  std::vector<std::array<double, 3>> part(nchunks, {0, 0, 0});  // area, area * phys^2, area * vox^2
  chunked(nf, kChunk, [&](size_t b, size_t e, size_t c) {
    for (size_t f = b; f < e; ++f) {
      const Triangle& t = result.triangles[f];
      const Vec3 &A = result.positions[t[0]], &B = result.positions[t[1]], &C = result.positions[t[2]];
      const double area = 0.5 * (B - A).cross(C - A).norm();
      double sp = 0, sv = 0;
      for (const auto& [u, v, w, weight] : rule) {
        const Vec3 x = u * A + v * B + w * C;
        const Vec3 d = truth.closest(x).point - x;
        const double dv = vox(d);
        sp += weight * d.squaredNorm();
        sv += weight * dv * dv;
      }
      part[c][0] += area;
      part[c][1] += area * sp;
      part[c][2] += area * sv;
    }
  });
  std::array<double, 3> sum{0, 0, 0};
  for (const auto& q : part)
    for (int k = 0; k < 3; ++k) sum[size_t(k)] += q[size_t(k)];
  if (sum[0] > 0) {
    r.result_to_truth_rule_rms = std::sqrt(sum[1] / sum[0]);
    if (with_volume) r.result_to_truth_rule_rms_vox = std::sqrt(sum[2] / sum[0]);
  }
}

// (3) Truth -> result.
void measure_truth_to_result(const Mesh& result, const Truth& truth, const detail::MeshQuery& result_query,
                             const EvalOptions& o, const Mat3& to_index, EvalReport& r) {
  auto vox = [&](const Vec3& d) { return vox_length(to_index, d); };
  const size_t n = result.triangles.empty() ? 0 : o.samples;
  std::vector<Vec3> pts(n);
  detail::parallel_for(n, [&](size_t i) { pts[i] = truth.sample(o.seed + 7919, i).point; });
  const std::vector<uint32_t> order = morton_order(pts);
  const size_t nchunks = (n + kChunk - 1) / kChunk;
  std::vector<Acc> phys(nchunks), voxs(nchunks);
  chunked(n, kChunk, [&](size_t b, size_t e, size_t c) {
    for (size_t k = b; k < e; ++k) {
      const Vec3& p = pts[order[k]];
      const auto q = result_query.closest(p);
      phys[c].add(std::sqrt(q.dist2));
      voxs[c].add(vox(q.point - p));
    }
  });
  Acc p, x;
  for (size_t c = 0; c < nchunks; ++c) {
    p.merge(phys[c]);
    x.merge(voxs[c]);
  }
  r.truth_to_result = p.stats();
  r.truth_to_result_vox = x.stats();
}

// Largest distance (physical, voxels) from the segments `from`, sampled
// every `step`, to the segments `to`. Each sample point stands for
// length / (k + 1) of its segment: `share` is the length within
// match_vox voxels of the other set.
void directed_sharp_distance(const std::vector<std::array<Vec3, 2>>& from, const std::vector<std::array<Vec3, 2>>& to,
                             double step, double match_vox, const Mat3& to_index, double& phys, double& voxels,
                             double& share) {
  auto vox = [&](const Vec3& d) { return vox_length(to_index, d); };
  std::vector<Vec3> pts;
  std::vector<double> weight;
  for (const auto& sgm : from) {
    const double len = (sgm[1] - sgm[0]).norm();
    const int k = std::max(1, int(std::ceil(len / step)));
    for (int i = 0; i <= k; ++i) {
      pts.push_back(sgm[0] + (sgm[1] - sgm[0]) * (double(i) / k));
      weight.push_back(len / (k + 1));
    }
  }
  std::vector<double> dp(pts.size()), dv(pts.size());
  detail::parallel_for(pts.size(), [&](size_t i) {
    const Vec3 diff = closest_on_segments(pts[i], to) - pts[i];
    dp[i] = diff.norm();
    dv[i] = vox(diff);
  });
  phys = dp.empty() ? 0 : *std::max_element(dp.begin(), dp.end());
  voxels = dv.empty() ? 0 : *std::max_element(dv.begin(), dv.end());
  double near = 0, total = 0;  // sequential: the same sum for any thread count
  for (size_t i = 0; i < pts.size(); ++i) {
    total += weight[i];
    if (dv[i] <= match_vox) near += weight[i];
  }
  share = total > 0 ? near / total : 0;
}

// (4) Sharp curves, both ways: every point of one set to the nearest
// segment of the other, sampled every tenth of a cell.
void measure_sharp_curves(const Mesh& result, const Truth& truth, const EvalOptions& o, const Mat3& to_index,
                          EvalReport& r) {
  const BinaryVolume* vol = o.volume;
  const auto true_sharp = truth.sharp_edges(o.sharp_angle_deg);
  r.true_sharp_edges = true_sharp.size();
  r.labelled_sharp_edges = result.edges.size();
  if (!result.edges.empty() && !true_sharp.empty()) {
    std::vector<std::array<Vec3, 2>> labelled;
    labelled.reserve(result.edges.size());
    for (const auto& e : result.edges) labelled.push_back({result.positions[e[0]], result.positions[e[1]]});
    // Without a volume, the step is a thousandth of the truth's bounding box diagonal.
    double step = 0;
    if (vol) {
      step = 0.1 / to_index.norm() * std::sqrt(3.0);
    } else {
      Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
      for (const auto& sgm : true_sharp)
        for (const Vec3& p : sgm) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      step = (hi - lo).norm() / 1000;
    }
    double tp = 0, tvx = 0, lp = 0, lv = 0, recall = 0, precision = 0;
    directed_sharp_distance(true_sharp, labelled, step, o.sharp_match_vox, to_index, tp, tvx, recall);
    directed_sharp_distance(labelled, true_sharp, step, o.sharp_match_vox, to_index, lp, lv, precision);
    r.sharp_true_to_labelled = tp;
    r.sharp_labelled_to_true = lp;
    r.sharp_edge_hausdorff = std::max(tp, lp);
    if (vol) {
      r.sharp_true_to_labelled_vox = tvx;
      r.sharp_labelled_to_true_vox = lv;
      r.sharp_edge_hausdorff_vox = std::max(tvx, lv);
      r.sharp_recall = recall;
      r.sharp_precision = precision;
    }
  } else if (vol && !true_sharp.empty()) {
    r.sharp_recall = 0;  // nothing labelled: none of the true curves is found
  } else if (vol && !result.edges.empty()) {
    r.sharp_precision = 0;  // labelled curves on a truth without any: none of their length is real
  }
}

}  // namespace

EvalReport evaluate(const Mesh& result, const Truth& truth, const EvalOptions& o) {
  EvalReport r;
  r.truth = truth.describe();
  r.vertices = result.positions.size();
  r.faces = result.triangles.size();
  const BinaryVolume* vol = o.volume;
  Mat3 to_index = Mat3::Identity();
  Vec3 origin = Vec3::Zero();
  if (vol) {
    to_index = vol->lattice.index_to_physical_matrix().inverse();
    origin = vol->lattice.origin;
  }

  if (vol) measure_sticks(result, truth, *vol, to_index, origin, r);
  if (o.progress) o.progress->begin("distances", 3);

  const detail::MeshQuery result_query(result);
  measure_result_to_truth(result, truth, result_query, o, to_index, r);
  if (o.quadrature && !result.triangles.empty())
    measure_result_to_truth_rule(result, truth, vol != nullptr, to_index, r);
  if (o.progress) o.progress->update(1);

  measure_truth_to_result(result, truth, result_query, o, to_index, r);
  if (o.progress) o.progress->update(2);
  r.hausdorff = std::max(r.result_to_truth.max, r.truth_to_result.max);
  if (vol) r.hausdorff_vox = std::max(r.result_to_truth_vox.max, r.truth_to_result_vox.max);
  const double tv = truth.volume();
  r.volume_ratio = tv > 0 ? signed_volume(result) / tv : 0;
  measure_sharp_curves(result, truth, o, to_index, r);

  MeshCheckOptions mo;
  mo.self_intersections = o.self_intersections;
  r.mesh = check_mesh(result, mo);
  if (vol) r.classification_violations = check_classification(result, *vol).violations;
  if (o.progress) {
    o.progress->update(3);
    o.progress->end();
  }
  return r;
}

Vec3 closest_on_segments(const Vec3& p, const std::vector<std::array<Vec3, 2>>& segments) {
  double best = INFINITY;
  Vec3 closest = p;
  for (const auto& sgm : segments) {
    const Vec3 e = sgm[1] - sgm[0];
    const double l2 = e.squaredNorm();
    const double u = l2 > 0 ? std::clamp((p - sgm[0]).dot(e) / l2, 0.0, 1.0) : 0.0;
    const Vec3 q = sgm[0] + u * e;
    if ((q - p).squaredNorm() < best) best = (q - p).squaredNorm(), closest = q;
  }
  return closest;
}

}  // namespace voxpress
