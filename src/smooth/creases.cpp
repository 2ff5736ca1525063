// Beyond the paper: the fresh vertices next to a sharp flat border placed by
// the curved side's own surface, extrapolated up to the flat. Theory of
// operation: include/voxpress/smooth/flats.h (fit_creases).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "crease_fit.h"
#include "quadric.h"
#include "surface_graph.h"
#include "voxpress/smooth/flats.h"

namespace voxpress {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

namespace detail {

std::vector<std::pair<uint32_t, double>> crease_targets(const StickSurface& sticks, const std::vector<Flat>& flats,
                                                        const std::vector<int32_t>& region,
                                                        const std::vector<uint8_t>& junction,
                                                        const std::vector<Vec3>& x, const std::vector<uint32_t>& off,
                                                        const std::vector<uint32_t>& adj, const CreaseFit& c) {
  const size_t n = region.size();
  // Ring distance of each curved vertex from the junctions (over curved
  // vertices) up to R, beyond that kUnreached, and the flat of the junction
  // it was reached from.
  std::vector<uint32_t> dist(n, kUnreached);
  std::vector<int32_t> flat(n, -1);
  std::vector<uint32_t> front;
  for (size_t v = 0; v < n; ++v) {
    if (region[v] >= 0 || !junction[v]) continue;
    for (uint32_t k = off[v]; k < off[v + 1] && flat[v] < 0; ++k) flat[v] = region[adj[k]];
    if (flat[v] < 0) continue;
    dist[v] = 0;
    front.push_back(uint32_t(v));
  }
  const uint32_t R = uint32_t(c.rings), F = uint32_t(c.fit_rings);
  spread_rings(std::move(front), 0, R, off, adj, dist, [&](uint32_t v, uint32_t w) {
    if (region[w] >= 0) return false;
    flat[w] = flat[v];
    return true;
  });
  std::vector<uint32_t> members;
  for (size_t v = 0; v < n; ++v)
    if (dist[v] <= R) members.push_back(uint32_t(v));
  std::vector<double> t_new(members.size(), std::numeric_limits<double>::quiet_NaN());
  tbb::enumerable_thread_specific<RingScratch> scratch;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    RingScratch& rs = scratch.local();
    std::vector<Vec3> pts;
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const uint32_t v = members[i];
      // Anchors: curved vertices beyond the zone, within R + F rings of v.
      rings_around(v, R + F, off, adj, [&](uint32_t w) { return region[w] < 0; }, rs);
      pts.clear();
      Vec3 outward = Vec3::Zero();
      for (const auto& [w, d] : rs.out)
        if (dist[w] > R) {
          pts.push_back(x[w]);
          outward += sticks.outside_sample(w) - sticks.inside_sample(w);
        }
      Quadric Q;
      if (!Q.fit(pts, outward) || Q.residual > c.residual) continue;
      const Vec3 in = sticks.inside_sample(v), out = sticks.outside_sample(v);
      const double tv = (x[v] - in).dot(out - in);
      const double tc = Q.exit(in, out, tv, -1, 2);
      if (std::isnan(tc)) continue;
      // The flat's plane (index space) and the rule between the two sides.
      const Flat& f = flats[size_t(flat[v])];
      const double fi = f.index_normal.dot(in) - f.index_offset, fo = f.index_normal.dot(out) - f.index_offset;
      const double tf = fi >= 0 ? -kInf : fo <= 0 ? kInf : -fi / (fo - fi);
      const bool convex = f.index_normal.dot(Q.m) < f.index_offset;
      const double t = std::clamp(convex ? std::min(tc, tf) : std::max(tc, tf), c.margin, 1 - c.margin);
      if (std::abs(t - tv) <= c.max_move) t_new[i] = t;
    }
  });
  std::vector<std::pair<uint32_t, double>> targets;
  for (size_t i = 0; i < members.size(); ++i)
    if (!std::isnan(t_new[i])) targets.push_back({members[i], t_new[i]});
  return targets;
}

}  // namespace detail

size_t fit_creases(StickSurface& s, const FlatSegmentation& seg, const FlatOptions& o, std::vector<uint8_t>* zone) {
  const size_t n = s.stick_count();
  if (zone) zone->assign(n, 0);
  if (seg.flats.empty() || o.crease_rings < 0) return 0;
  std::vector<uint32_t> off, adj;
  detail::vertex_adjacency(n, s.triangles, off, adj);
  std::vector<Vec3> x(n);
  tbb::parallel_for(size_t(0), n, [&](size_t v) { x[v] = s.index_position(v); });
  const detail::CreaseFit c{
      .rings = o.crease_rings, .fit_rings = o.crease_fit_rings, .residual = o.crease_residual, .margin = o.margin};
  const auto targets = detail::crease_targets(s, seg.flats, seg.region, seg.junction, x, off, adj, c);
  for (const auto& [v, t] : targets) {
    s.t[v] = s.lower_inside(v) ? t : 1 - t;
    if (zone) (*zone)[v] = 1;
  }
  return targets.size();
}

}  // namespace voxpress
