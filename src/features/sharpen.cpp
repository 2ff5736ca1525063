// Sharp edge recovery (Chica et al., Section 5): the run and its output.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

namespace voxpress::sharpen_impl {

SharpenResult Sharpener::run() {
  const auto t0 = std::chrono::steady_clock::now();
  detail::vertex_adjacency(n, s.triangles, adj_off, adj);
  x.resize(n);
  for (size_t v = 0; v < n; ++v) x[v] = s.index_position(v);
  plane_state.assign(n, 0);
  on_wall.assign(n, 0);
  plane.resize(n);
  label = seg.region;
  junction = seg.junction;
  junction.resize(n, 0);
  // Each step timed as its pass (the base steps as `sharpen`).
  auto timed = [&](Pass p, auto&& step) {
    const auto t = std::chrono::steady_clock::now();
    step();
    st.passes.add(p, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
  };
  if (!seg.flats.empty()) {
    timed(Pass::snap, [&] { snap_to_flats(); });
    timed(Pass::strips, [&] { join_leftovers(); });
    timed(Pass::inherit_junctions, [&] { inherit_junctions(); });
    timed(Pass::walls, [&] { fit_walls(); });
    timed(Pass::final_crease, [&] { final_crease_fit(); });
    timed(Pass::past_crease, [&] { past_creases(); });
    timed(Pass::curved_creases, [&] { curved_creases(); });
    timed(Pass::sharpen, [&] { subdivide(); });
  } else {
    tris = s.triangles;
    parent.resize(tris.size());
    std::iota(parent.begin(), parent.end(), 0u);
  }
  if (!nv.empty()) {
    build_chains();
    const auto t = std::chrono::steady_clock::now();
    judge_chains();  // before index(): it may slide rim pockets
    st.passes.add(Pass::round_chains, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
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
  }
  SharpenResult r;
  r.mesh = output();
  st.passes.count[size_t(Pass::snap)] = st.snapped;
  st.passes.count[size_t(Pass::walls)] = st.wall_vertices;
  st.passes.count[size_t(Pass::final_crease)] = st.final_crease_vertices;
  st.passes.count[size_t(Pass::past_crease)] = st.past_crease + st.left_flat;
  st.passes.count[size_t(Pass::inherit_junctions)] = st.inherited_junctions;
  st.passes.count[size_t(Pass::curved_creases)] += st.curved_crease_vertices;
  st.passes.count[size_t(Pass::tangent_planes)] = st.tangent_planes;
  st.passes.count[size_t(Pass::sample_wedges)] = st.wedge_shifts;
  st.passes.count[size_t(Pass::round_chains)] = st.round_chains;
  st.passes.count[size_t(Pass::sharpen)] = st.inserted;
  st.sharp_edges = r.mesh.edges.size();
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double others = 0;
  for (size_t p = 0; p < size_t(Pass::count); ++p)
    if (Pass(p) != Pass::sharpen) others += st.passes.seconds[p];
  st.passes.seconds[size_t(Pass::sharpen)] = st.seconds - others;
  r.stats = st;
  return r;
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
  if (!flats.region.empty() && flats.region.size() != surface.stick_count())
    throw std::invalid_argument("sharpen: segmentation does not match the surface");
  FlatSegmentation none;  // no segmentation: every vertex curved
  if (flats.region.empty()) none.region.assign(surface.stick_count(), -1);
  sharpen_impl::Sharpener sh(surface, flats.region.empty() ? none : flats, options);
  return sh.run();
}

}  // namespace voxpress
