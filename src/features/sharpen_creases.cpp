// Sharpening: the final crease fit, vertices past their crease, curved creases.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "feature_context.h"
#include "core/parallel.h"

namespace voxpress::sharpen_impl {

uint32_t Sharpener::add_vertex(const NewVertex& v, const Vec3& at) {
  nv.push_back(v);
  x.push_back(at);
  return uint32_t(n + nv.size() - 1);
}

void Sharpener::final_crease_fit() {
  const detail::CreaseFit c{.rings = detail::kFinalCreaseRings,
                            .fit_rings = detail::kFinalCreaseFitRings,
                            .residual = detail::kFinalCreaseResidual,
                            .margin = o.margin,
                            .max_move = detail::kFinalCreaseMaxMove};
  for (const auto& [v, t] : detail::crease_targets(s, seg.flats, label, junction, x, adj_off, adj, c)) {
    slide(v, t);
    ++st.final_crease_vertices;
  }
}

int Sharpener::crease_kind_near(uint32_t v, int32_t f, std::vector<uint32_t>& ring) const {
  size_t below = 0, above = 0;
  ring.assign(1, v);
  detail::grow_rings(ring, 2, adj_off, adj);
  for (uint32_t w : ring)
    if (label[w] < 0 && !junction[w]) (height(f, x[w]) < 0 ? below : above) += 1;
  return below > 0 && below >= 3 * above ? 1 : above > 0 && above >= 3 * below ? -1 : 0;
}

void Sharpener::past_creases() {
  struct Move {
    uint32_t v;
    int32_t label;  // the flat it joins, or -1 (it leaves its flat)
    double t;       // where on its stick it goes (NaN: it stays where it is)
  };
  std::vector<Move> moves;
  std::vector<uint32_t> ring;
  for (uint32_t v = 0; v < n; ++v) {
    if (label[v] < 0 && junction[v]) {  // a curved junction: past the crease on the flat?
      double best;
      const int32_t f = nearest_neighbour_flat(v, best);
      if (f < 0) continue;
      const double tf = flat_crossing(v, f);
      const bool crossed = on_stick(tf);
      if (!crossed && best > kPastSample) continue;
      Plane side;  // uncached (plane_of's cache would keep curved_creases from setting it)
      if (!tangent_plane(v, side)) continue;
      const int kind = crease_kind_near(v, f, ring);
      if (crossed) {
        const double tc = leaves_at(v, side);
        if ((kind > 0 && tf < tc) || (kind < 0 && tf > tc)) moves.push_back({v, f, tf});
      } else {
        const double hc = side.n.dot(x[v]) - side.c;  // on the flat's plane already: where is the side's?
        if ((kind > 0 && hc < -kPastSample) || (kind < 0 && hc > kPastSample)) moves.push_back({v, f, NAN});
      }
    } else if (const int32_t f = label[v]; f >= 0) {  // a member: past the crease on the curved face?
      uint32_t w = kNone;  // its nearest curved junction neighbour
      double d2 = INFINITY;
      for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
        if (const uint32_t q = adj[k]; label[q] < 0 && junction[q] && (x[q] - x[v]).squaredNorm() < d2)
          d2 = (x[q] - x[v]).squaredNorm(), w = q;
      if (w == kNone) continue;
      Plane side;
      if (!tangent_plane(w, side) || angle_deg(side.n, seg.flats[size_t(f)].index_normal) < o.sharp_angle) continue;
      const int kind = crease_kind_near(v, f, ring);
      const double tf = flat_crossing(v, f), tc = stick_crossing(v, side.n, side.c);
      if (!on_stick(tc) || !std::isfinite(tf)) continue;
      if ((kind > 0 && tc < tf - kLeaveMargin) || (kind < 0 && tc > tf + kLeaveMargin)) moves.push_back({v, -1, tc});
    }
  }
  for (const Move& m : moves) {
    if (std::isfinite(m.t)) slide(m.v, m.t);
    label[m.v] = m.label;
    if (m.label >= 0) {
      ++st.past_crease;
    } else {
      junction[m.v] = 1;
      ++st.left_flat;
    }
  }
  for (const Move& m : moves)
    if (m.label >= 0)
      for (uint32_t k = adj_off[m.v]; k < adj_off[m.v + 1]; ++k)
        if (label[adj[k]] < 0) junction[adj[k]] = 1;
}

void Sharpener::curved_creases() {
  detail::CurvedCreaseFit c;
  c.sharp_angle = o.sharp_angle;
  c.margin = o.margin;
  c.network = o.passes.on(Pass::crease_network);
  // A thin wall's vertices are junctions on their wall's fitted plane, a
  // face of their own: they stay, but are the wall's side of a crease
  // with a curved face (without its vertices the 2-means sees one side
  // only, and a wall's steep crease with a curved face goes unlabelled).
  std::vector<uint8_t> role(n);
  for (size_t v = 0; v < n; ++v)
    role[v] = !junction[v] ? detail::kCreaseFree : on_wall[v] ? detail::kCreaseSide : detail::kCreaseSkip;
  std::vector<Vec3> normal;
  const auto found =
      detail::curved_crease_targets(s, label, role, x, adj_off, adj, c, &normal, &st.passes.count[size_t(Pass::crease_network)]);
  for (const auto& f : found) {
    slide(f.v, f.t);
    if (plane_state[f.v] != 0) continue;
    crease_side[f.v] = 1;
    plane[f.v] = f.chosen;
    plane_state[f.v] = 1;
  }
  st.curved_crease_vertices = found.size();
  for (const auto& f : found) {
    const uint32_t v = f.v;
    if (crease_side[v] != 1) continue;
    const Vec3 mine = physical_normal(f.chosen.n), theirs = physical_normal(f.other.n);
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      const uint32_t w = adj[k];
      if (label[w] >= 0 || junction[w] || plane_state[w] != 0) continue;
      if (normal[w].dot(theirs) > normal[w].dot(mine)) {
        crease_side[w] = 2;
        plane[w] = f.other;
        plane_state[w] = 1;
      }
    }
  }
}

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t final_crease_step(FeatureContext& c) {
  c.sharpen->final_crease_fit();
  return c.sharpen->st.final_crease_vertices;
}

size_t past_crease_step(FeatureContext& c) {
  c.sharpen->past_creases();
  return c.sharpen->st.past_crease + c.sharpen->st.left_flat;
}

size_t final_curved_creases_step(FeatureContext& c) {
  c.sharpen->curved_creases();
  return c.sharpen->st.curved_crease_vertices;
}

}  // namespace voxpress::detail
