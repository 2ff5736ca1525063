// Sharpening: the regions (leftovers, strips, snapped bands, junctions) and each side's plane.
// Theory of operation: sharpener.h and include/voxpress/features/sharpen.h.
#include "sharpener.h"

#include "feature_context.h"
#include "flat_geometry.h"
#include "core/parallel.h"

namespace voxpress::sharpen_impl {

const Plane* Sharpener::plane_of(uint32_t v) {
  if (plane_state[v] != 0) return plane_state[v] > 0 ? &plane[v] : nullptr;
  plane_state[v] = -1;
  const int32_t r = label[v];
  if (r >= 0) {
    const Flat& f = seg.flats[size_t(r)];
    plane[v] = {f.index_normal, f.index_offset};
    plane_state[v] = 1;
    return &plane[v];
  }
  if (tangent_plane(v, plane[v])) {
    ++st.tangent_planes;
  } else if (!ring_plane(v, plane[v])) {
    return nullptr;
  }
  plane_state[v] = 1;
  return &plane[v];
}

bool Sharpener::ring_plane(uint32_t v, Plane& out) const {
  std::vector<uint32_t> ring{v};
  detail::grow_rings(ring, 2, adj_off, adj);
  std::vector<Vec3> pts;
  Vec3 towards = Vec3::Zero();
  for (int pass = 0; pass < 2 && pts.size() < 3; ++pass) {
    pts.clear();
    towards.setZero();
    for (uint32_t q : ring)
      if (label[q] < 0 && (pass == 1 || !junction[q])) {
        pts.push_back(x[q]);
        towards[s.axis(q)] += s.lower_inside(q) ? 1 : -1;
      }
  }
  if (pts.size() < 3) return false;
  const detail::Pca p = detail::pca(pts);
  if (!(p.eigenvalues[1] > 1e-6)) return false;  // collinear points
  out = detail::oriented_plane(p, towards);
  return true;
}

bool Sharpener::chamfer(uint32_t u, uint32_t v) const {
  const int32_t a = label[u], b = label[v];
  if (a < 0 && b < 0 && crease_side[u] && crease_side[v])  // a curved/curved crease (curved_creases)
    return angle_deg(plane[u].n, plane[v].n) >= o.sharp_angle;
  if (a == b) return false;
  if (a >= 0 && b >= 0) {
    return degrees_between(seg.flats[size_t(a)].normal, seg.flats[size_t(b)].normal) >= detail::kMinAngle;
  }
  return junction[a < 0 ? u : v] != 0;
}

void Sharpener::thin_strips(std::vector<uint8_t>& mark) {
  const uint32_t W = uint32_t(o.passes.on(Pass::strips) ? detail::kStripRings : 0);
  if (W == 0) return;
  std::vector<uint32_t> depth(n, detail::kUnreached), front;
  for (uint32_t v = 0; v < n; ++v) {
    if (label[v] >= 0) continue;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
      if (label[adj[k]] >= 0) {
        depth[v] = 1;
        front.push_back(v);
        break;
      }
  }
  detail::spread_rings(std::move(front), 1, W + 1, adj_off, adj, depth,
                       [&](uint32_t, uint32_t w) { return label[w] < 0; });
  std::vector<uint8_t> thin(n, 0);
  for (uint32_t v = 0; v < n; ++v) {
    if (label[v] >= 0 || mark[v] || depth[v] > W) continue;
    detail::rings_around(v, W, adj_off, adj, [&](uint32_t w) { return label[w] < 0; }, rings);
    bool ok = true;
    for (const auto& [w, d] : rings.out) ok = ok && depth[w] <= W;
    thin[v] = ok;
  }
  // The curved vertices within W rings of one that is neither thin nor
  // marked (ring distance over curved vertices is symmetric).
  std::vector<uint32_t> near_deep(n, detail::kUnreached), deep;
  if (o.passes.on(Pass::rim_pockets)) {
    for (uint32_t v = 0; v < n; ++v)
      if (label[v] < 0 && !thin[v] && !mark[v]) {
        near_deep[v] = 0;
        deep.push_back(v);
      }
    detail::spread_rings(std::move(deep), 0, W, adj_off, adj, near_deep,
                         [&](uint32_t, uint32_t w) { return label[w] < 0; });
  }
  for (uint32_t v = 0; v < n; ++v)
    if (thin[v]) {
      mark[v] = near_deep[v] == detail::kUnreached ? kStrip : kRimStrip;
      ++st.passes.count[size_t(mark[v] == kStrip ? Pass::strips : Pass::rim_pockets)];
    }
}

// A strip (kStrip vertices, with the pockets kRimStrip beside them: one
// component over both) is a narrow curved band between two flats: a crease
// the flats stopped short of, or a fillet the lattice resolves. Joined
// vertex by vertex, a fillet's band was flattened onto its planes (the
// filleted boxes at r = 2-3 cells lost 4-8 % RMS to `--no-sharpen`), and
// judged vertex by vertex (each stick the flats' solid explains) a band
// came out half joined, worse than either. So the whole band decides,
// with round-borders' evidence (RoundingEvidence) on its two flats (the
// pair meeting at kMinAngle or more that most of its vertices' neighbours
// belong to): a band whose samples forbid a rounding of
// kRoundBorderRadius is a crease and joins; one that allows it and whose
// sticks the flats' solid (solid_crossing) explains at under kSnapShare
// (a fillet of radius r leaves its sticks ~0.4 r outside the solid) stays
// curved, every vertex of it. A band beside one flat only (a flat meeting
// a curved face), or whose kind (convex or concave) its vertices do not
// tell, joins as before: nothing says it is round.
size_t Sharpener::round_strips(std::vector<uint8_t>& mark) {
  const auto in_band = [&](uint32_t w) { return mark[w] == kStrip || mark[w] == kRimStrip; };
  std::vector<uint8_t> seen(n, 0);
  std::vector<uint32_t> band;
  std::vector<std::pair<int32_t, uint32_t>> votes;  // (flat, neighbours of the band on it)
  SnapScratch scratch;
  size_t kept = 0;
  for (uint32_t v0 = 0; v0 < n; ++v0) {
    if (mark[v0] != kStrip || seen[v0]) continue;
    band.assign(1, v0);
    seen[v0] = 1;
    for (size_t k = 0; k < band.size(); ++k)
      for (uint32_t q = adj_off[band[k]]; q < adj_off[band[k] + 1]; ++q)
        if (const uint32_t w = adj[q]; in_band(w) && !seen[w]) seen[w] = 1, band.push_back(w);
    // Its two flats: of the flats its vertices neighbour, the pair meeting
    // at kMinAngle or more with the most neighbours (ties: lower ids).
    votes.clear();
    for (uint32_t v : band)
      for (uint32_t q = adj_off[v]; q < adj_off[v + 1]; ++q)
        if (const int32_t f = label[adj[q]]; f >= 0) {
          auto it = std::find_if(votes.begin(), votes.end(), [f](const auto& e) { return e.first == f; });
          if (it == votes.end()) votes.push_back({f, 1});
          else ++it->second;
        }
    std::sort(votes.begin(), votes.end(),
              [](const auto& a, const auto& b) { return a.second != b.second ? a.second > b.second : a.first < b.first; });
    int32_t fa = -1, fb = -1;
    for (size_t i = 1; i < votes.size() && fb < 0; ++i)
      for (size_t j = 0; j < i && fb < 0; ++j)
        if (angle_deg(seg.flats[size_t(votes[i].first)].index_normal, seg.flats[size_t(votes[j].first)].index_normal) >=
            detail::kMinAngle)
          fa = votes[j].first, fb = votes[i].first;
    if (fb < 0) continue;
    const Flat &FA = seg.flats[size_t(fa)], &FB = seg.flats[size_t(fb)];
    const Plane A{FA.index_normal, FA.index_offset}, B{FB.index_normal, FB.index_offset};
    const int kind = detail::edge_kind(A, B, band, [&](uint32_t v) { return x[v]; });
    if (kind == 0) continue;
    detail::RoundingEvidence evidence;
    evidence.add_rings(A, B, kind, band, adj_off, adj, [&](uint32_t w) { return s.inside_sample(w); },
                       [&](uint32_t w) { return s.outside_sample(w); });
    if (evidence.forbids(detail::kRoundBorderRadius)) continue;
    size_t explained = 0;
    for (uint32_t v : band) {
      int32_t f;
      double t;
      explained += solid_crossing(v, false, uint32_t(detail::kSnapRings), scratch, f, t);
    }
    if (double(explained) >= detail::kSnapShare * double(band.size())) continue;
    for (uint32_t v : band) mark[v] = 0;
    ++kept;
  }
  return kept;
}

void Sharpener::snap_to_flats() {
  // Candidates: curved vertices, and members up to 2 rings from a border.
  const std::vector<uint32_t> depth = detail::region_border_rings(seg.region, 2, adj_off, adj);
  std::vector<int32_t> flat(n, -1);  // the flat whose plane the solid crosses v's stick on
  std::vector<double> t(n, 0);
  // Rings to the nearest flat member, up to twice kSnapRings: farther than
  // its reach, solid_crossing finds no flat (its ring holds no member), so
  // the vertex is not searched (on a CAD part most of a curved face).
  std::vector<uint32_t> to_flat(n, detail::kUnreached), members;
  for (uint32_t v = 0; v < n; ++v)
    if (seg.region[v] >= 0) to_flat[v] = 0, members.push_back(v);
  detail::spread_rings(std::move(members), 0, 2 * uint32_t(detail::kSnapRings), adj_off, adj, to_flat,
                       [](uint32_t, uint32_t) { return true; });
  tbb::enumerable_thread_specific<SnapScratch> scratch;
  detail::parallel_ranges(uint32_t(n), 256, [&](detail::IndexRange r) {
    SnapScratch& sc = scratch.local();
    for (uint32_t v = r.begin(); v < r.end(); ++v) {
      const bool member = seg.region[v] >= 0;
      if ((member && depth[v] > 2) || to_flat[v] > uint32_t(detail::kSnapRings)) continue;
      if (!solid_crossing(v, member, uint32_t(detail::kSnapRings), sc, flat[v], t[v]) || flat[v] == seg.region[v])
        flat[v] = -1;
    }
  });
  SnapScratch wide;
  for_each_curved_patch([&](const std::vector<uint32_t>& patch) {
    size_t explained = 0;
    for (uint32_t v : patch) explained += flat[v] >= 0;
    // A corner patch whose third face's flat stops more than snap_rings
    // rings away: the two near flats explain most of it, the rest only
    // with the third. Its unexplained vertices
    // look twice as far; a curved face, mostly unexplained, is not retried.
    if (explained >= patch.size() / 2 && double(explained) < detail::kSnapShare * double(patch.size()))
      for (uint32_t v : patch)
        if (flat[v] < 0) {
          if (to_flat[v] <= 2 * uint32_t(detail::kSnapRings) &&
              solid_crossing(v, false, 2 * uint32_t(detail::kSnapRings), wide, flat[v], t[v])) {
            ++explained;
          } else {
            flat[v] = -1;
          }
        }
    if (double(explained) < detail::kSnapShare * double(patch.size()))
      for (uint32_t v : patch) flat[v] = -1;
  });
  for (uint32_t v = 0; v < n; ++v) {
    if (flat[v] < 0) continue;
    slide(v, t[v]);  // t is already in [margin, 1 - margin]
    label[v] = flat[v];
    ++st.snapped;
  }
}

void Sharpener::join_leftovers() {
  std::vector<uint8_t> small(n, 0);
  for_each_curved_patch([&](const std::vector<uint32_t>& patch) {
    if (patch.size() < size_t(detail::kMinCurved))
      for (uint32_t v : patch) small[v] = kLeftover;
  });
  thin_strips(small);
  if (o.passes.on(Pass::round_strips)) st.passes.count[size_t(Pass::round_strips)] += round_strips(small);
  std::vector<std::pair<uint32_t, int32_t>> joins;
  std::vector<uint32_t> ring;
  for (uint32_t v = 0; v < n; ++v) {
    Plane unused;
    if (label[v] >= 0 || !(small[v] || (junction[v] && !ring_plane(v, unused)))) continue;
    int32_t best = -1;
    double best_d = INFINITY;
    // Every flat with a member within 3 rings competes: taking the first
    // ring that reaches one can have a vertex of a bottom rim join the
    // bottom's flat a cell below its plane while a tenth of a cell from
    // the side face's, and the crease chain detours around it.
    ring.assign(1, v);
    detail::grow_rings(ring, 3, adj_off, adj);
    for (uint32_t q : ring) {
      const int32_t f = label[q];
      if (f < 0) continue;
      const double d = std::abs(height(f, x[v]));
      if (d < best_d) best_d = d, best = f;
    }
    if (best >= 0) joins.push_back({v, best});
  }
  // A rim pocket's vertex joins only when the flat's plane crosses its
  // stick from the inside sample to the outside one (up to 0.1 cell
  // beyond either sample: a plane through a sample corner; a plane with
  // the outside sample below it does not bound the solid there), and
  // slides along the stick onto it, so no sample changes
  // side. Otherwise it lies past the crease, on the curved face: left on
  // the flat, off its plane, the crease vertex inserted next to it had to
  // move back past it, which turned triangles over, and that move was
  // cut back (CAD part 128: 110-160 crease vertices per seed, left about
  // 0.3 cell off the crease). It stays curved, and a junction when it has a flat and a
  // curved junction neighbour (the border there is sharp).
  std::vector<uint32_t> pocket;
  for (const auto& [v, f] : joins) {
    if (small[v] == kRimStrip) {
      const double t = flat_crossing(v, f);  // NaN unless crossed outwards
      if (!on_stick(t)) {
        pocket.push_back(v);
        continue;
      }
      pocket_slides.push_back({v, x[v]});  // judge_chains takes it back beside a chain left round
      slide(v, t);
    }
    label[v] = f;
    if (small[v] == kLeftover) leftovers.push_back(v);  // a thin strip's vertices keep their place
  }
  for (uint32_t v : pocket) {
    bool flat = false, sharp = false;
    for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
      flat |= label[adj[k]] >= 0;
      sharp |= label[adj[k]] < 0 && seg.junction[adj[k]];
    }
    junction[v] |= flat && sharp;
  }
}

void Sharpener::inherit_junctions() {
  std::vector<uint32_t> heirs;
  for (uint32_t v = 0; v < n; ++v)
    if (label[v] >= 0 && seg.region[v] < 0 && junction[v] && std::abs(height(label[v], x[v])) <= kPastSample)
      sharp_neighbours(v, heirs);
  st.inherited_junctions += mark_junctions(heirs);
}

void Sharpener::sharp_neighbours(uint32_t v, std::vector<uint32_t>& out) const {
  const Vec3& normal = seg.flats[size_t(label[v])].index_normal;
  for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k) {
    Plane p;
    if (const uint32_t q = adj[k];
        label[q] < 0 && !junction[q] && ring_plane(q, p) && angle_deg(p.n, normal) >= o.sharp_angle)
      out.push_back(q);
  }
}

int32_t Sharpener::nearest_neighbour_flat(uint32_t v, double& distance) const {
  int32_t f = -1;
  distance = INFINITY;
  for (uint32_t k = adj_off[v]; k < adj_off[v + 1]; ++k)
    if (const int32_t r = label[adj[k]]; r >= 0 && std::abs(height(r, x[v])) < distance)
      distance = std::abs(height(r, x[v])), f = r;
  return f;
}

size_t Sharpener::mark_junctions(const std::vector<uint32_t>& vertices) {
  size_t fresh = 0;
  for (uint32_t q : vertices) {
    fresh += !junction[q];
    junction[q] = 1;
  }
  return fresh;
}

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t snap_step(FeatureContext& c) {
  c.sharpen->snap_to_flats();
  return c.sharpen->st.snapped;
}

size_t leftovers_step(FeatureContext& c) {
  c.sharpen->join_leftovers();
  return c.sharpen->leftovers.size();  // the strips and rim pockets count themselves
}

size_t inherit_junctions_step(FeatureContext& c) {
  c.sharpen->inherit_junctions();
  return c.sharpen->st.inherited_junctions;
}

}  // namespace voxpress::detail
