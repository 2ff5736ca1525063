// Sharp edge recovery (Chica et al., Section 5): the run (Stage::sharpen's
// passes, from the table in passes.cpp), the moves and the output.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "feature_context.h"

namespace voxpress::sharpen_impl {

SharpenResult Sharpener::run() {
  const auto t0 = std::chrono::steady_clock::now();
  x.resize(n);
  for (size_t v = 0; v < n; ++v) x[v] = s.index_position(v);
  plane_state.assign(n, 0);
  on_wall.assign(n, 0);
  crease_side.assign(n, 0);
  plane.resize(n);
  label = seg.region;
  junction = seg.junction;
  junction.resize(n, 0);
  if (!seg.flats.empty()) {
    detail::FeatureContext ctx{o.passes, st.passes};
    ctx.sharpen = this;
    detail::run_stage(Stage::sharpen, ctx);
  }
  if (tris.empty()) {  // no flats (or no chamfer): the surface's own triangles
    tris = s.triangles;
    parent.resize(tris.size());
    std::iota(parent.begin(), parent.end(), 0u);
  }
  SharpenResult r;
  r.mesh = output();
  st.passes.count[size_t(Pass::tangent_planes)] = st.tangent_planes;
  st.passes.count[size_t(Pass::sample_wedges)] = st.wedge_shifts;
  st.sharp_edges = r.mesh.edges.size();
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The steps were timed by the driver; `sharpen` also takes the rest
  // (the setup and the output).
  double steps = 0;
  for (size_t p = 0; p < size_t(Pass::count); ++p) steps += st.passes.seconds[p];
  st.passes.seconds[size_t(Pass::sharpen)] += std::max(0.0, st.seconds - steps);
  r.stats = st;
  return r;
}

size_t Sharpener::move_all() {
  index();
  spread_targets();
  // The moves, in order: leftovers onto their flat, edge vertices onto
  // their crease, then corners (Section 5). A move blocked by a
  // neighbour that has not moved yet is retried in the next round; from
  // round kRounds on, the remaining moves are cut back to what is
  // allowed; those whose target lies on flats' planes only are retried
  // (neighbours' cut-back moves may unblock them) while any vertex still
  // advances, for up to kRounds more rounds. Targets from a curved
  // side's fit are not pushed further (a leaning curved side's plane
  // would carry the vertex past the truth).
  std::vector<std::pair<uint32_t, Vec3>> jobs;
  std::vector<uint8_t> retry;
  for (uint32_t v : leftovers) {
    jobs.push_back({v, x[v] - height(label[v], x[v]) * seg.flats[size_t(label[v])].index_normal});
    retry.push_back(1);
  }
  for (int corners = 0; corners < 2; ++corners)
    for (size_t i = 0; i < nv.size(); ++i)
      if (nv[i].moves && nv[i].corner == bool(corners)) {
        jobs.push_back({uint32_t(n + i), nv[i].target});
        retry.push_back(nv[i].on_flats);
      }
  std::vector<uint8_t> done(jobs.size(), 0);
  // Neighbours that block each other (two vertices of one thin triangle)
  // get there together: a blocked vertex goes half way instead.
  for (int round = 0; round < 2 * kRounds; ++round) {
    const bool cut = round + 1 >= kRounds;
    bool advanced = false;
    for (size_t j = 0; j < jobs.size(); ++j) {
      if (done[j] || (round >= kRounds && !retry[j])) continue;
      const uint32_t v = jobs[j].first;
      const Vec3 before = x[v];
      done[j] = move(v, jobs[j].second, cut);
      if (!done[j] && !cut) move(v, (x[v] + jobs[j].second) / 2, false);
      advanced |= (x[v] - before).squaredNorm() > kAdvance * kAdvance;
    }
    if (cut && !advanced) break;
  }
  smooth_chains();
  return size_t(std::count(done.begin(), done.end(), 1));
}

Mesh Sharpener::output() const {
  Mesh m;
  const Mat3 M = s.lattice.index_to_physical_matrix();
  m.positions.resize(x.size());
  for (size_t v = 0; v < x.size(); ++v) m.positions[v] = s.lattice.origin + M * x[v];
  m.triangles = tris;
  if (s.lattice.flips_orientation())
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  MeshAttribute region{"region", ScalarType::i32, std::vector<double>(x.size(), -1)};
  MeshAttribute junction_flag{"junction", ScalarType::u8, std::vector<double>(x.size(), 0)};
  MeshAttribute feature{"feature", ScalarType::u8, std::vector<double>(x.size(), 0)};
  for (size_t v = 0; v < n; ++v) {
    region.values[v] = label[v];
    junction_flag.values[v] = junction[v];
  }
  // Sharp feature edges: new edges whose edge vertex lies on a sharp crease.
  for (const auto& e : feature_edges) {
    const NewVertex& a = nv[e[0] - n];
    const NewVertex& b = nv[e[1] - n];
    const bool sharp = (a.corner || a.sharp) && (b.corner || b.sharp);
    if (!sharp) continue;
    m.edges.push_back(e);
    feature.values[e[0]] = feature.values[e[1]] = 1;
  }
  // A face belongs to flat f when all its original vertices do (so flats'
  // faces are planar); otherwise it is curved.
  MeshAttribute face_region{"region", ScalarType::i32, std::vector<double>(tris.size(), -1)};
  for (size_t f = 0; f < tris.size(); ++f) {
    int32_t r = -2;
    for (uint32_t v : tris[f]) {
      if (v >= n) continue;
      const int32_t rv = label[v];
      r = r == -2 || r == rv ? rv : -1;
    }
    face_region.values[f] = r < 0 ? -1 : r;
  }
  if (o.colors) {
    m.colors.resize(x.size());
    for (size_t v = 0; v < x.size(); ++v)
      m.colors[v] = feature.values[v] ? std::array<uint8_t, 4>{200, 20, 20, 255}
                                      : region_color(int32_t(region.values[v]), junction_flag.values[v] != 0);
  }
  m.vertex_attributes = {std::move(region), std::move(junction_flag), std::move(feature)};
  m.face_attributes = {std::move(face_region)};
  return m;
}

Vec3 solve_planes(const Plane* planes, int count, const Vec3& x0, double floor) {
  Mat3 A = Mat3::Zero();
  Vec3 r = Vec3::Zero();
  for (int i = 0; i < count; ++i) {
    A += planes[i].n * planes[i].n.transpose();
    r += planes[i].n * (planes[i].c - planes[i].n.dot(x0));
  }
  Eigen::SelfAdjointEigenSolver<Mat3> es(A);
  Vec3 dx = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double l = es.eigenvalues()[k];
    if (l < floor) continue;
    const Vec3 e = es.eigenvectors().col(k);
    dx += e * (e.dot(r) / l);
  }
  return x0 + dx;
}

}  // namespace voxpress::sharpen_impl

namespace voxpress {

SharpenResult sharpen(const StickSurface& surface, const FlatSegmentation& flats, const SharpenOptions& options) {
  return detail::sharpen(surface, flats, options, detail::Adjacency(surface.stick_count(), surface.triangles));
}

SharpenResult detail::sharpen(const StickSurface& surface, const FlatSegmentation& flats, const SharpenOptions& options,
                              const Adjacency& graph) {
  if (!flats.region.empty() && flats.region.size() != surface.stick_count())
    throw std::invalid_argument("sharpen: segmentation does not match the surface");
  FlatSegmentation none;  // no segmentation: every vertex curved
  if (flats.region.empty()) none.region.assign(surface.stick_count(), -1);
  sharpen_impl::Sharpener sh(surface, flats.region.empty() ? none : flats, options, graph);
  return sh.run();
}

}  // namespace voxpress

namespace voxpress::detail {

size_t moves_step(FeatureContext& c) { return c.sharpen->nv.empty() ? 0 : c.sharpen->move_all(); }

}  // namespace voxpress::detail
