// Sharp edges on a shared surface: each label's binary sharpening on the
// cubes it owns, checked against the whole shared surface. Theory of
// operation: include/voxpress/labels/shared_sharpen.h.
#include "voxpress/labels/shared_sharpen.h"


#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/clearance.h"
#include "core/timing.h"
#include "features/sharpener.h"
#include "label_view.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

using detail::Cube;
using detail::floor_of;
using detail::LabelView;
constexpr uint8_t kCreaseKind = 7;  // SharedSurface::kind of a vertex the sharpening inserted

// What one label's sharpening changes. Every change can be taken back
// alone (apply's `back`): a moved stick vertex to where it was, a new
// vertex onto the edge it was inserted on (a corner to the centroid of its
// edge vertices), so a triangle whose vertices are all back is a flat piece
// of the pressed triangle it came from.
struct LabelEdit {
  uint32_t label = 0;                             // index into SharedSurface::labels
  std::vector<uint32_t> idx;                      // the label's stick k -> shared vertex
  std::vector<std::pair<uint32_t, Vec3>> moved;   // shared vertex, new index-space position
  struct Fresh {
    Vec3 at = Vec3::Zero();                       // index space
    Cube cube{};                                  // the cube of the triangle it was inserted in
    uint32_t a = 0, b = 0;                        // edge vertex: the edge's ends (the label's sticks)
    double u = 0.5;                               // ... inserted at a + u (b - a)
    std::array<uint32_t, 3> from{};               // corner: its edge vertices (indices into fresh)
    bool corner = false;
  };
  std::vector<Fresh> fresh;
  struct Split {
    uint32_t f, begin, end;  // shared triangle, its children [begin, end)
  };
  std::vector<Split> splits;                      // by shared triangle
  std::vector<Triangle> children;                 // the label's numbering (its sticks, then its new vertices)
  SharpenStats stats;
  size_t cubes = 0;
  double delta = 0;                               // the clearance its sharpening kept (cells)
};

// Sharpens label L's view (Section 5, restricted to the cubes it may edit).
LabelEdit sharpen_label(LabelView v, const FlatSegmentation& seg, const SharpenOptions& o) {
  LabelEdit e;
  e.label = v.label;
  e.cubes = v.cubes;
  if (v.cubes == 0) return e;
  e.idx = std::move(v.idx);
  const StickSurface& surf = v.surf;
  const size_t n = surf.stick_count();
  const detail::Adjacency graph(surf.stick_count(), surf.triangles);
  sharpen_impl::Sharpener sh(surf, seg, o, graph);
  sh.editable = &v.editable;
  sh.fixed = &v.fixed;
  e.stats = sh.run().stats;
  e.delta = sh.delta;
  const Vec3 shift{double(v.lo[0]), double(v.lo[1]), double(v.lo[2])};
  for (size_t k = 0; k < n; ++k)
    if (sh.x[k] != surf.index_position(k))
      e.moved.push_back({e.idx[k], sh.x[k] + shift});
  for (size_t i = 0; i < sh.nv.size(); ++i) {
    const sharpen_impl::NewVertex& w = sh.nv[i];
    LabelEdit::Fresh f;
    f.at = sh.x[n + i] + shift;
    f.corner = w.corner;
    if (w.corner) {
      for (int k = 0; k < 3; ++k) f.from[size_t(k)] = w.from[size_t(k)] - uint32_t(n);
    } else {
      f.a = w.a, f.b = w.b, f.u = w.u;
    }
    e.fresh.push_back(f);
  }
  // The refined triangles of each split original triangle (sh.tris in
  // order of their parents).
  for (size_t i = 0; i < sh.tris.size();) {
    size_t j = i;
    while (j < sh.tris.size() && sh.parent[j] == sh.parent[i]) ++j;
    if (j - i > 1) {
      e.splits.push_back({v.shared_of[sh.parent[i]], uint32_t(e.children.size()), uint32_t(e.children.size() + j - i)});
      for (size_t k = i; k < j; ++k) {
        e.children.push_back(sh.tris[k]);
        for (uint32_t w : sh.tris[k])
          if (w >= n) e.fresh[w - n].cube = v.cube[sh.parent[i]];
      }
    }
    i = j;
  }
  std::sort(e.splits.begin(), e.splits.end(), [](const auto& p, const auto& q) { return p.f < q.f; });
  return e;
}

// Per edit, which of its changes are taken back: its moved vertices, its
// new vertices.
struct Back {
  std::vector<uint8_t> moved, fresh;
};

// A changed triangle (new numbering) and the edit that changed it.
struct Changed {
  uint32_t f, edit;
};

// The edits of `use` applied to `base`, into s, each change at its place
// or, where `back` says, taken back; `changed` gets the triangles they
// change; `owner` the (edit, change) of every moved or new vertex
// (change k < moved.size(): moved k; else fresh k - moved.size()).
void apply(SharedSurface& s, const SharedSurface& base, const std::vector<LabelEdit>& edits,
           const std::vector<uint8_t>& use, const std::vector<Back>& back, std::vector<Changed>& changed,
           std::vector<std::pair<uint32_t, uint32_t>>& owner) {
  s.mesh.positions = base.mesh.positions;
  s.kind = base.kind;
  s.corner = base.corner;
  s.apexes = base.apexes;
  changed.clear();
  const size_t n0 = base.mesh.positions.size(), nt0 = base.mesh.triangles.size();
  owner.assign(n0, {UINT32_MAX, 0});
  std::vector<uint32_t> first_new(edits.size(), 0);
  std::vector<std::pair<uint32_t, uint32_t>> split_of(nt0, {UINT32_MAX, 0});
  for (uint32_t i = 0; i < edits.size(); ++i) {
    if (!use[i]) continue;
    const LabelEdit& e = edits[i];
    const size_t nm = e.moved.size();
    for (size_t k = 0; k < nm; ++k) {
      const auto& [v, p] = e.moved[k];
      if (!back[i].moved[k]) s.mesh.positions[v] = s.lattice.to_physical(p);
      owner[v] = {i, uint32_t(k)};
    }
    first_new[i] = uint32_t(s.mesh.positions.size());
    // New vertices taken back: edge vertices onto their edge as it now is,
    // then corners to their edge vertices' centroid.
    std::vector<Vec3> at(e.fresh.size());
    for (int corners = 0; corners < 2; ++corners)
      for (size_t k = 0; k < e.fresh.size(); ++k) {
        const LabelEdit::Fresh& f = e.fresh[k];
        if (f.corner != bool(corners)) continue;
        if (!back[i].fresh[k]) {
          at[k] = f.at;
        } else if (!f.corner) {
          const Vec3 xa = s.lattice.to_index(s.mesh.positions[e.idx[f.a]]);
          at[k] = xa + f.u * (s.lattice.to_index(s.mesh.positions[e.idx[f.b]]) - xa);
        } else {
          at[k] = (at[f.from[0]] + at[f.from[1]] + at[f.from[2]]) / 3;
        }
      }
    for (size_t k = 0; k < e.fresh.size(); ++k) {
      s.mesh.positions.push_back(s.lattice.to_physical(at[k]));
      s.kind.push_back(kCreaseKind);
      s.corner.push_back(e.fresh[k].cube);
      owner.push_back({i, uint32_t(nm + k)});
    }
    for (uint32_t j = 0; j < e.splits.size(); ++j) split_of[e.splits[j].f] = {i, j};
  }
  s.mesh.triangles.clear();
  s.sides.clear();
  for (uint32_t f = 0; f < nt0; ++f) {
    const auto [i, j] = split_of[f];
    if (i == UINT32_MAX) {
      const Triangle& t = base.mesh.triangles[f];
      const uint32_t by = std::min({owner[t[0]].first, owner[t[1]].first, owner[t[2]].first});
      if (by != UINT32_MAX) changed.push_back({uint32_t(s.mesh.triangles.size()), by});
      s.mesh.triangles.push_back(t);
      s.sides.push_back(base.sides[f]);
      continue;
    }
    const LabelEdit& e = edits[i];
    const uint32_t n = uint32_t(e.idx.size());
    for (uint32_t k = e.splits[j].begin; k < e.splits[j].end; ++k) {
      Triangle t = e.children[k];
      for (uint32_t& w : t) w = w < n ? e.idx[w] : first_new[i] + (w - n);
      if (base.sides[f][0] != e.label) std::swap(t[1], t[2]);  // wound as seen from `out`
      changed.push_back({uint32_t(s.mesh.triangles.size()), i});
      s.mesh.triangles.push_back(t);
      s.sides.push_back(base.sides[f]);
    }
  }
}

// Which changed triangles degenerate, or meet or come within their edit's
// clearance of any triangle of s beyond what they share (exact).
std::vector<uint8_t> failing(const SharedSurface& s, const std::vector<Changed>& changed,
                             const std::vector<LabelEdit>& edits) {
  std::vector<uint8_t> bad(changed.size(), 0);
  if (changed.empty()) return bad;
  const auto& tris = s.mesh.triangles;
  std::vector<Vec3> x(s.mesh.positions.size());
  detail::parallel_for(x.size(), [&](size_t v) { x[v] = s.lattice.to_index(s.mesh.positions[v]); });
  auto box = [&](uint32_t f, double grow) {
    const Triangle& t = tris[f];
    return std::pair<Vec3, Vec3>{x[t[0]].cwiseMin(x[t[1]]).cwiseMin(x[t[2]]).array() - grow,
                                 x[t[0]].cwiseMax(x[t[1]]).cwiseMax(x[t[2]]).array() + grow};
  };
  auto for_cubes = [](const std::pair<Vec3, Vec3>& b, auto&& f) {
    const Cube lo = floor_of(b.first), hi = floor_of(b.second);
    for (int64_t k = lo[2]; k <= hi[2]; ++k)
      for (int64_t j = lo[1]; j <= hi[1]; ++j)
        for (int64_t i = lo[0]; i <= hi[0]; ++i) f(Cube{i, j, k});
  };
  // The sharpener kept its clearance in its own frame; the round trip
  // through physical coordinates may shave a few ulps off it.
  auto delta = [&](const Changed& c) { return edits[c.edit].delta * (1 - 1e-9); };
  // The cubes the changed triangles reach, and every triangle meeting them.
  std::vector<Cube> near;
  for (const Changed& c : changed) for_cubes(box(c.f, delta(c)), [&](const Cube& q) { near.push_back(q); });
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  std::vector<std::pair<Cube, uint32_t>> in;
  for (uint32_t f = 0; f < tris.size(); ++f)
    for_cubes(box(f, 0), [&](const Cube& q) {
      if (std::binary_search(near.begin(), near.end(), q)) in.push_back({q, f});
    });
  std::sort(in.begin(), in.end());
  detail::parallel_for(changed.size(), [&](size_t k) {
    const uint32_t f = changed[k].f;
    const double d = delta(changed[k]);
    const Triangle& a = tris[f];
    const Vec3 pa[3] = {x[a[0]], x[a[1]], x[a[2]]};
    const uint32_t ia[3] = {a[0], a[1], a[2]};
    if (detail::triangle_too_thin(pa[0], pa[1], pa[2], d)) {
      bad[k] = 1;
      return;
    }
    const auto fb = box(f, d);
    for_cubes(fb, [&](const Cube& c) {
      for (auto it = std::lower_bound(in.begin(), in.end(), std::pair<Cube, uint32_t>{c, 0});
           !bad[k] && it != in.end() && it->first == c; ++it) {
        if (it->second == f) continue;
        const auto gb = box(it->second, 0);
        if ((gb.first.array() > fb.second.array()).any() || (fb.first.array() > gb.second.array()).any()) continue;
        const Triangle& b = tris[it->second];
        const Vec3 pb[3] = {x[b[0]], x[b[1]], x[b[2]]};
        const uint32_t ib[3] = {b[0], b[1], b[2]};
        bad[k] = detail::triangles_clash(pa, ia, pb, ib, d);
      }
    });
  });
  return bad;
}

}  // namespace

SharedSharpenStats sharpen_shared(SharedSurface& s, const SharedFlats& flats, const LabelMasks& masks,
                                  const std::vector<LabelInfo>& labels, const SharpenOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  SharedSharpenStats st;
  // The labels with flats, by their index in s.labels.
  const std::vector<size_t> info_of = detail::listed_labels(s, labels);
  std::vector<uint8_t> sharpens(s.labels.size(), 0);
  for (size_t l = 0; l < s.labels.size(); ++l)
    sharpens[l] = info_of[l] < flats.segmentations.size() && !flats.segmentations[info_of[l]].flats.empty();
  if (std::find(sharpens.begin(), sharpens.end(), 1) == sharpens.end()) return st;
  const detail::Ownership own = detail::ownership(s, sharpens);
  const detail::SharedSticks sticks(s);
  std::vector<uint32_t> todo;
  for (uint32_t l = 0; l < s.labels.size(); ++l)
    if (!own.mine[l].empty()) todo.push_back(l);
  SharpenOptions o = options;
  o.progress = nullptr;
  std::vector<LabelEdit> edits(todo.size());
  detail::parallel_for(todo.size(), [&](size_t i) {
    const uint32_t l = todo[i];
    const LabelInfo& info = labels[info_of[l]];
    edits[i] = sharpen_label(detail::label_view(s, own, sticks, masks(info), detail::mask_origin(info.lo), l),
                             flats.segmentations[info_of[l]], o);
  });
  // Applied together and checked against the whole surface. The changes
  // around a triangle that fails are taken back (a new edge vertex with its
  // edge's ends), and the check runs again, until none fails: the changes
  // only ever go back, and a triangle whose changes are all back is a flat
  // piece of a pressed one. An edit that fails with nothing left to take
  // back is undone whole.
  const SharedSurface base = s;
  std::vector<uint8_t> use(edits.size());
  std::vector<Back> back(edits.size());
  for (size_t i = 0; i < edits.size(); ++i) {
    use[i] = !edits[i].moved.empty() || !edits[i].splits.empty();
    back[i].moved.assign(edits[i].moved.size(), 0);
    back[i].fresh.assign(edits[i].fresh.size(), 0);
  }
  std::vector<Changed> changed;
  std::vector<std::pair<uint32_t, uint32_t>> owner;
  for (;;) {
    apply(s, base, edits, use, back, changed, owner);
    const std::vector<uint8_t> bad = failing(s, changed, edits);
    bool any = false, progress = false;
    auto take_back = [&](uint32_t v) {
      const auto [i, c] = owner[v];
      if (i == UINT32_MAX) return;
      const size_t nm = edits[i].moved.size();
      uint8_t& flag = c < nm ? back[i].moved[c] : back[i].fresh[c - nm];
      progress |= !flag;
      flag = 1;
    };
    for (size_t k = 0; k < changed.size(); ++k) {
      if (!bad[k]) continue;
      any = true;
      for (uint32_t v : s.mesh.triangles[changed[k].f]) {
        take_back(v);
        const auto [i, c] = owner[v];
        if (i == UINT32_MAX || c < edits[i].moved.size()) continue;
        const LabelEdit::Fresh& f = edits[i].fresh[c - edits[i].moved.size()];
        if (!f.corner) take_back(edits[i].idx[f.a]), take_back(edits[i].idx[f.b]);
      }
    }
    if (!any) break;
    if (!progress)
      for (size_t k = 0; k < changed.size(); ++k)
        if (bad[k] && use[changed[k].edit]) {
          use[changed[k].edit] = 0;
          ++st.labels_undone;
        }
  }
  for (size_t i = 0; i < edits.size(); ++i) {
    if (!use[i]) continue;
    for (uint8_t b : back[i].moved) st.taken_back += b;
    for (uint8_t b : back[i].fresh) st.taken_back += b;
  }
  s.mesh.normals.clear();
  for (size_t i = 0; i < edits.size(); ++i) {
    st.cubes += edits[i].cubes;
    st.passes.add(edits[i].stats.passes);
    if (!use[i]) continue;
    ++st.labels;
    st.inserted += edits[i].stats.inserted + edits[i].stats.corners;
    st.corners += edits[i].stats.corners;
    st.moved += edits[i].moved.size() - size_t(std::count(back[i].moved.begin(), back[i].moved.end(), 1));
    st.sharp_edges += edits[i].stats.sharp_edges;
  }
  st.seconds = detail::seconds_since(t0);
  return st;
}

}  // namespace voxpress
