// Sharp edge recovery (Chica et al., Section 5): the new vertices form
// chains along the new edges (its last paragraph). Beyond the paper, each
// chain is judged as a whole on whether the volume shows an edge sharper
// than the lattice resolves (issue 75; Pass::round_chains).
//
// Theory of operation. A chain (edge vertices joined by new edges, cut at
// corners) lies between two planes per edge vertex (two flats, a flat and a
// curved side's tangent or ring plane, two curved sides). Its samples
// bound how round the true edge may be: at a convex crease every inside
// sample of the sticks around the chain (each edge vertex's two ends and
// their 1-rings on its two regions) lies inside the true solid, so a
// fillet tangent to both planes that would cut one off is ruled out; at a
// concave one the outside samples play that part. The smallest such radius
// over the chain, r_allow, is the rounding its own sticks allow (a sharp
// box edge at 128^3 allows 0.04-0.46 cell, an edge filleted with radius r
// allows r to r + 0.07; bench_fillets). An edge along a lattice axis allows
// up to ~1.7 cells whether it is sharp or not (no sample nearer its apex),
// so the samples must also demand a rounding: one of the others (outside at
// a convex crease, inside at a concave one) lying more than kRoundEvidence
// inside both planes, where only a rounded edge puts it. A chain whose
// samples allow a fillet of kRoundRadius or more and demand one stays
// round: its vertices stay where they were inserted, on the chamfer's
// edges, so the pressed surface is unchanged there, and are not labelled;
// so does a corner whose chains all stay round. A chain keeps its crease
// when it has no decided sample (no convex or concave vertex) or when none
// of its samples bounds the rounding at all (its planes lean past them).
// Rim pockets that join_leftovers slid onto their flat's plane go back
// beside a chain left round (below): along a fillet tangent to the flat the
// slide flattens the fillet's start.
#include "sharpener.h"

#include "feature_context.h"
#include "flat_geometry.h"

namespace voxpress::sharpen_impl {

void Sharpener::judge_chains() {
  const size_t m = nv.size();
  std::vector<uint8_t> rejected(m, 0);
  std::vector<uint32_t> chain(m, kNone), members, near;
  for (uint32_t i0 = 0; i0 < m; ++i0) {
    if (nv[i0].corner || chain[i0] != kNone) continue;
    members.assign(1, i0);  // the chain: a walk over the new edges, corners left out
    chain[i0] = i0;
    for (size_t k = 0; k < members.size(); ++k) {
      const uint32_t i = members[k];
      for (int e = 0; e < std::min<int>(chain_degree[i], 2); ++e) {
        const uint32_t j = chain_nb[i][size_t(e)] - uint32_t(n);
        if (!nv[j].corner && chain[j] == kNone) chain[j] = i0, members.push_back(j);
      }
    }
    detail::RoundingEvidence evidence;
    for (uint32_t i : members) {
      const NewVertex& v = nv[i];
      const Plane* pa = plane_of(v.a);
      const Plane* pb = plane_of(v.b);
      if (!pa || !pb) continue;
      const double sa = pa->n.dot(x[v.b]) - pa->c, sb = pb->n.dot(x[v.a]) - pb->c;
      const int kind = sa < 0 && sb < 0 ? 1 : sa > 0 && sb > 0 ? -1 : 0;  // convex, concave, undecided
      if (kind == 0) continue;
      near.clear();
      for (uint32_t e : {v.a, v.b}) {
        near.push_back(e);
        for (uint32_t k = adj_off[e]; k < adj_off[e + 1]; ++k)
          if (label[adj[k]] == label[v.a] || label[adj[k]] == label[v.b]) near.push_back(adj[k]);
      }
      for (uint32_t q : near) evidence.add(*pa, *pb, kind, s.inside_sample(q), s.outside_sample(q));
    }
    if (!evidence.round(detail::kRoundRadius)) continue;
    ++st.round_chains;
    for (uint32_t i : members) nv[i].moves = nv[i].sharp = false, rejected[i] = 1;
  }
  for (uint32_t i = 0; i < m; ++i)
    if (nv[i].corner) {
      bool all = true;
      for (uint32_t e : nv[i].from) all &= e != kNone && rejected[e - n];
      if (all) nv[i].moves = nv[i].sharp = false;
    }
  // The rim pockets within kCreaseRings rings of a chain left round, on no
  // kept crease's edge, go back where they were before join_leftovers slid
  // them onto their flat's plane (along a fillet tangent to the flat the
  // slide flattens the fillet's start); the new vertices on their edges
  // follow (still on those edges).
  std::vector<uint8_t> kept(n, 0);
  std::vector<uint32_t> near_round;
  for (uint32_t i = 0; i < m; ++i)
    if (!nv[i].corner) {
      if (rejected[i]) {
        near_round.push_back(nv[i].a), near_round.push_back(nv[i].b);
      } else {
        kept[nv[i].a] = kept[nv[i].b] = 1;
      }
    }
  if (near_round.empty()) return;
  std::sort(near_round.begin(), near_round.end());
  near_round.erase(std::unique(near_round.begin(), near_round.end()), near_round.end());
  detail::grow_rings(near_round, detail::kCreaseRings, adj_off, adj);
  std::vector<uint8_t> round(n, 0);
  for (uint32_t v : near_round) round[v] = 1;
  bool moved = false;
  for (const auto& [v, before] : pocket_slides)
    if (round[v] && !kept[v] && !(fixed && (*fixed)[v])) x[v] = before, moved = true;
  if (!moved) return;
  for (uint32_t i = 0; i < m; ++i)
    if (!nv[i].corner) x[n + i] = x[nv[i].a] + nv[i].u * (x[nv[i].b] - x[nv[i].a]);
  for (uint32_t i = 0; i < m; ++i)
    if (nv[i].corner) x[n + i] = (x[nv[i].from[0]] + x[nv[i].from[1]] + x[nv[i].from[2]]) / 3;
}

}  // namespace voxpress::sharpen_impl

namespace voxpress::detail {

size_t round_chains_step(FeatureContext& c) {
  if (c.sharpen->nv.empty()) return 0;
  c.sharpen->judge_chains();  // before the moves' index(): it may slide rim pockets
  return c.sharpen->st.round_chains;
}

}  // namespace voxpress::detail
