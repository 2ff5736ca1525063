// Texture atlas: charts, rasterization, packing, dilation (see atlas.h).
#include "atlas.h"


#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "voxpress/core/error.h"
#include "voxpress/core/memory_budget.h"
#include "core/parallel.h"

namespace voxpress::detail {
namespace {

constexpr int64_t kSub = 256;  // fixed-point steps per texel

struct Chart {
  std::vector<uint32_t> faces;
  Vec3 e1, e2;
  double s0 = 0, t0 = 0;   // local origin (texels) before the padding
  int64_t w = 0, h = 0;    // rectangle with padding
  int64_t x = 0, y = 0;    // placement in the texture
  std::vector<int32_t> owner;  // w * h: index into faces, -1 = none
};

struct FixedPoint {
  int64_t x, y;
};

// Projects a face's corners into the chart's local texel frame.
std::array<Vec2, 3> local_corners(const Mesh& m, const Chart& c, uint32_t f, double density, int pad) {
  std::array<Vec2, 3> out;
  for (int k = 0; k < 3; ++k) {
    const Vec3& p = m.positions[m.triangles[f][size_t(k)]];
    out[size_t(k)] = Vec2(p.dot(c.e1) * density - c.s0 + pad, p.dot(c.e2) * density - c.t0 + pad);
  }
  return out;
}

// Calls texel(x, y, l0, l1, l2) for every texel centre inside the triangle
// (top-left rule, fixed point), with barycentric weights.
template <class F>
void raster(const std::array<Vec2, 3>& q, int64_t w, int64_t h, F&& texel) {
  FixedPoint v[3];
  for (int k = 0; k < 3; ++k) v[k] = {std::llround(q[size_t(k)].x() * kSub), std::llround(q[size_t(k)].y() * kSub)};
  int64_t area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x);
  if (area == 0) return;
  int order[3] = {0, 1, 2};
  if (area < 0) {
    std::swap(order[1], order[2]);
    area = -area;
  }
  const FixedPoint a = v[order[0]], b = v[order[1]], c = v[order[2]];
  const int64_t x0 = std::max<int64_t>(0, std::min({a.x, b.x, c.x}) / kSub - 1);
  const int64_t x1 = std::min<int64_t>(w - 1, std::max({a.x, b.x, c.x}) / kSub + 1);
  const int64_t y0 = std::max<int64_t>(0, std::min({a.y, b.y, c.y}) / kSub - 1);
  const int64_t y1 = std::min<int64_t>(h - 1, std::max({a.y, b.y, c.y}) / kSub + 1);
  auto edge = [](const FixedPoint& p, const FixedPoint& r, int64_t px, int64_t py) {
    return (r.x - p.x) * (py - p.y) - (r.y - p.y) * (px - p.x);
  };
  auto top_left = [](const FixedPoint& p, const FixedPoint& r) { return r.y < p.y || (r.y == p.y && r.x < p.x); };
  const int64_t bias[3] = {top_left(b, c) ? 0 : -1, top_left(c, a) ? 0 : -1, top_left(a, b) ? 0 : -1};
  for (int64_t y = y0; y <= y1; ++y)
    for (int64_t x = x0; x <= x1; ++x) {
      const int64_t px = x * kSub + kSub / 2, py = y * kSub + kSub / 2;
      const int64_t w0 = edge(b, c, px, py), w1 = edge(c, a, px, py), w2 = edge(a, b, px, py);
      if (w0 + bias[0] < 0 || w1 + bias[1] < 0 || w2 + bias[2] < 0) continue;
      double l[3];
      l[order[0]] = double(w0) / double(area);
      l[order[1]] = double(w1) / double(area);
      l[order[2]] = double(w2) / double(area);
      texel(x, y, l[0], l[1], l[2]);
    }
}

// The chart's frame, rectangle and raster; false when the projection overlaps itself.
bool lay_out(const Mesh& m, Chart& c, const Vec3& n, double density, int pad) {
  int a = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n[k]) > std::abs(n[a])) a = k;
  Vec3 u = Vec3::Unit((a + 1) % 3);
  c.e1 = (u - u.dot(n) * n).normalized();
  c.e2 = n.cross(c.e1);
  double smin = INFINITY, tmin = INFINITY, smax = -INFINITY, tmax = -INFINITY;
  for (uint32_t f : c.faces)
    for (uint32_t v : m.triangles[f]) {
      const double s = m.positions[v].dot(c.e1) * density, t = m.positions[v].dot(c.e2) * density;
      smin = std::min(smin, s);
      smax = std::max(smax, s);
      tmin = std::min(tmin, t);
      tmax = std::max(tmax, t);
    }
  c.s0 = std::floor(smin);
  c.t0 = std::floor(tmin);
  c.w = int64_t(std::ceil(smax - c.s0)) + 2 * pad;
  c.h = int64_t(std::ceil(tmax - c.t0)) + 2 * pad;
  if (double(c.w) * double(c.h) > 1e9) throw LimitError("", "a texture chart would exceed 10^9 texels");
  c.owner.assign(size_t(c.w * c.h), -1);
  bool overlap = false;
  for (size_t i = 0; i < c.faces.size() && !overlap; ++i)
    raster(local_corners(m, c, c.faces[i], density, pad), c.w, c.h, [&](int64_t x, int64_t y, double, double, double) {
      int32_t& o = c.owner[size_t(y * c.w + x)];
      if (o >= 0) overlap = true;
      o = int32_t(i);
    });
  return !overlap;
}

struct Packing {
  int64_t width = 0, height = 0;
  std::vector<std::array<int64_t, 2>> at;
};

// The paper's packer (Section 4.5).
Packing pack_paper(const std::vector<Chart>& charts) {
  struct PackNode {
    int64_t w, h;
    int32_t left = -1, right = -1;
    bool stacked = false;  // right below left (else right beside left)
  };
  std::vector<PackNode> nodes;
  std::set<std::pair<int64_t, int32_t>> hb, vb;
  for (const Chart& c : charts) {
    nodes.push_back({c.w, c.h});
    hb.insert({c.w, int32_t(nodes.size() - 1)});
    vb.insert({c.h, int32_t(nodes.size() - 1)});
  }
  auto area = [&](int32_t i) { return nodes[size_t(i)].w * nodes[size_t(i)].h; };
  while (hb.size() > 1) {
    // The two narrowest (stacked) or the two shortest (side by side): the
    // "last two" of the paper's buffers sorted by decreasing size.
    const int32_t a1 = hb.begin()->second, a2 = std::next(hb.begin())->second;
    const int32_t b1 = vb.begin()->second, b2 = std::next(vb.begin())->second;
    const PackNode A{std::max(nodes[size_t(a1)].w, nodes[size_t(a2)].w), nodes[size_t(a1)].h + nodes[size_t(a2)].h, a1, a2, true};
    const PackNode B{nodes[size_t(b1)].w + nodes[size_t(b2)].w, std::max(nodes[size_t(b1)].h, nodes[size_t(b2)].h), b1, b2, false};
    // Waste measured against the enclosing square (the paper squares the
    // result): plain bounding-box waste keeps stacking narrow charts into
    // one ever taller column.
    const int64_t wa = std::max(A.w, A.h) * std::max(A.w, A.h) - area(a1) - area(a2);
    const int64_t wb = std::max(B.w, B.h) * std::max(B.w, B.h) - area(b1) - area(b2);
    const PackNode chosen = wa <= wb ? A : B;
    for (int32_t i : {chosen.left, chosen.right}) {
      hb.erase({nodes[size_t(i)].w, i});
      vb.erase({nodes[size_t(i)].h, i});
    }
    nodes.push_back(chosen);
    hb.insert({chosen.w, int32_t(nodes.size() - 1)});
    vb.insert({chosen.h, int32_t(nodes.size() - 1)});
  }
  const int32_t root = hb.begin()->second;
  Packing p;
  const int64_t side = std::max(nodes[size_t(root)].w, nodes[size_t(root)].h);
  p.width = p.height = side;
  p.at.resize(charts.size());
  // Square, with the content centred along its shorter side.
  std::vector<std::tuple<int32_t, int64_t, int64_t>> stack{
      {root, (side - nodes[size_t(root)].w) / 2, (side - nodes[size_t(root)].h) / 2}};
  while (!stack.empty()) {
    auto [i, x, y] = stack.back();
    stack.pop_back();
    const PackNode& n = nodes[size_t(i)];
    if (n.left < 0) {
      p.at[size_t(i)] = {x, y};
      continue;
    }
    stack.push_back({n.left, x, y});
    if (n.stacked)
      stack.push_back({n.right, x, y + nodes[size_t(n.left)].h});
    else
      stack.push_back({n.right, x + nodes[size_t(n.left)].w, y});
  }
  return p;
}

// Shelves: charts by decreasing height, left to right in rows of a width
// near the square root of the total area.
Packing pack_shelf(const std::vector<Chart>& charts) {
  std::vector<size_t> order(charts.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::tie(charts[b].h, charts[b].w, a) < std::tie(charts[a].h, charts[a].w, b);
  });
  double total = 0;
  int64_t widest = 0;
  for (const Chart& c : charts) {
    total += double(c.w) * double(c.h);
    widest = std::max(widest, c.w);
  }
  Packing p;
  p.width = std::max<int64_t>(widest, int64_t(std::ceil(std::sqrt(total * 1.05))));
  p.at.resize(charts.size());
  int64_t x = 0, y = 0, row = 0;
  for (size_t i : order) {
    if (x + charts[i].w > p.width) {
      y += row;
      x = 0;
      row = 0;
    }
    p.at[i] = {x, y};
    x += charts[i].w;
    row = std::max(row, charts[i].h);
  }
  p.height = y + row;
  return p;
}

}  // namespace

Rgba sample_texture(const Texture& t, const Vec2& uv) {
  const int64_t x = std::clamp<int64_t>(int64_t(std::floor(uv.x() * double(t.width))), 0, t.width - 1);
  const int64_t y = std::clamp<int64_t>(int64_t(std::floor(uv.y() * double(t.height))), 0, t.height - 1);
  const size_t o = size_t(4 * (y * t.width + x));
  return {t.rgba[o], t.rgba[o + 1], t.rgba[o + 2], t.rgba[o + 3]};
}

namespace {

// The texture and its encoding, with what the caller holds, before it is made.
void charge_texture(const Packing& pk, const AtlasOptions& options) {
  const uint64_t need = options.held_bytes + uint64_t(pk.width) * uint64_t(pk.height) * kVoxartBytesPerTexel;
  charge_memory(options.source, need, options.max_bytes,
                "the texture atlas of " + std::to_string(pk.width) + " x " + std::to_string(pk.height) +
                    " texels, with the mesh,");
}

}  // namespace

AtlasResult build_atlas(const Mesh& m, const AtlasOptions& options,
                        const std::function<Rgba(uint32_t, const Vec3&)>& color) {
  const size_t nf = m.triangles.size();
  const double density = options.texels_per_unit;
  const int pad = options.padding;
  std::vector<Vec3> normal(nf);
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    const Vec3 n = (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
    normal[f] = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
  }
  // Edge neighbours (faces sharing an edge), from sorted half-edges.
  std::vector<std::array<uint32_t, 3>> he;  // a, b, face
  he.reserve(3 * nf);
  for (uint32_t f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = m.triangles[f][size_t(c)], b = m.triangles[f][size_t((c + 1) % 3)];
      he.push_back({std::min(a, b), std::max(a, b), f});
    }
  std::sort(he.begin(), he.end());
  std::vector<uint32_t> nb_start(nf + 1, 0), nb;
  std::vector<std::array<uint32_t, 2>> pairs;
  for (size_t i = 0, j; i < he.size(); i = j) {
    for (j = i; j < he.size() && he[j][0] == he[i][0] && he[j][1] == he[i][1]; ++j) {
    }
    for (size_t p = i; p < j; ++p)
      for (size_t q = i; q < j; ++q)
        if (p != q) pairs.push_back({he[p][2], he[q][2]});
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& p : pairs) ++nb_start[p[0] + 1];
  for (size_t f = 0; f < nf; ++f) nb_start[f + 1] += nb_start[f];
  for (const auto& p : pairs) nb.push_back(p[1]);
  pairs = {};
  he = {};

  // Seeds: most axis-aligned first.
  std::vector<uint32_t> order(nf);
  for (uint32_t f = 0; f < nf; ++f) order[f] = f;
  std::vector<double> align(nf);
  for (size_t f = 0; f < nf; ++f) align[f] = normal[f].cwiseAbs().maxCoeff();
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return align[a] > align[b]; });
  std::vector<uint32_t> rank(nf);
  for (uint32_t i = 0; i < nf; ++i) rank[order[i]] = i;

  // Grow charts over a subset of faces (all at first; a failed chart's faces
  // later) with a given angle.
  std::vector<Chart> charts;
  std::vector<int32_t> chart_of(nf, -1);
  std::vector<std::pair<std::vector<uint32_t>, double>> work{{order, options.angle_degrees}};
  std::vector<uint8_t> in_subset(nf, 0);
  while (!work.empty()) {
    auto [subset, angle] = std::move(work.back());
    work.pop_back();
    const double cos_max = std::cos(angle * std::numbers::pi / 180);
    for (uint32_t f : subset) in_subset[f] = 1;
    for (uint32_t seed : subset) {
      if (!in_subset[seed]) continue;
      Chart c;
      in_subset[seed] = 0;
      c.faces.push_back(seed);
      for (size_t head = 0; angle > 0 && head < c.faces.size(); ++head) {
        const uint32_t f = c.faces[head];
        for (uint32_t k = nb_start[f]; k < nb_start[f + 1]; ++k) {
          const uint32_t g = nb[k];
          if (in_subset[g] && normal[g].dot(normal[seed]) >= cos_max) {
            in_subset[g] = 0;
            c.faces.push_back(g);
          }
        }
      }
      // A single face cannot overlap itself (its raster is still needed).
      if (lay_out(m, c, normal[seed], density, pad) || c.faces.size() == 1) {
        for (uint32_t f : c.faces) chart_of[f] = int32_t(charts.size());
        charts.push_back(std::move(c));
      } else {
        std::sort(c.faces.begin(), c.faces.end(), [&](uint32_t a, uint32_t b) { return rank[a] < rank[b]; });
        work.push_back({std::move(c.faces), angle / 2 < 1 ? 0.0 : angle / 2});
      }
    }
  }
  // Pack.
  AtlasResult out;
  const Packing paper = pack_paper(charts), shelf = pack_shelf(charts);
  uint64_t covered = 0;
  for (const Chart& c : charts)
    for (int32_t o : c.owner) covered += o >= 0;
  out.covered_texels = covered;
  out.charts = charts.size();
  out.utilisation_paper = double(covered) / (double(paper.width) * double(paper.height));
  out.utilisation_shelf = double(covered) / (double(shelf.width) * double(shelf.height));
  bool use_paper = options.packer == AtlasPacker::paper ||
                   (options.packer == AtlasPacker::best && out.utilisation_paper >= out.utilisation_shelf);
  const Packing& pk = use_paper ? paper : shelf;
  out.packer = use_paper ? "paper" : "shelf";
  for (size_t i = 0; i < charts.size(); ++i) {
    charts[i].x = pk.at[i][0];
    charts[i].y = pk.at[i][1];
  }
  Texture& tex = out.mesh.texture;
  tex.width = pk.width;
  tex.height = pk.height;
  if (std::max(pk.width, pk.height) > options.max_side) return out;  // refused or retried by the caller
  charge_texture(pk, options);
  tex.rgba.assign(size_t(4 * tex.width * tex.height), 0);
  // Render each chart (in parallel: charts own disjoint rectangles), then
  // dilate its colours into its padding.
  detail::parallel_ranges(charts.size(), 16, [&](detail::IndexRange r) {
    for (size_t ci = r.begin(); ci != r.end(); ++ci) {
      const Chart& c = charts[ci];
      std::vector<Rgba> local(size_t(c.w * c.h), Rgba{0, 0, 0, 0});
      for (size_t i = 0; i < c.faces.size(); ++i) {
        const uint32_t f = c.faces[i];
        const auto& t = m.triangles[f];
        raster(local_corners(m, c, f, density, pad), c.w, c.h, [&](int64_t x, int64_t y, double l0, double l1, double l2) {
          if (c.owner[size_t(y * c.w + x)] != int32_t(i)) return;
          const Vec3 p = l0 * m.positions[t[0]] + l1 * m.positions[t[1]] + l2 * m.positions[t[2]];
          Rgba col = color(f, p);
          col[3] = 255;
          local[size_t(y * c.w + x)] = col;
        });
      }
      for (int pass = 0; pass < pad + 1; ++pass) {
        std::vector<Rgba> next = local;
        for (int64_t y = 0; y < c.h; ++y)
          for (int64_t x = 0; x < c.w; ++x) {
            if (local[size_t(y * c.w + x)][3]) continue;
            const int64_t dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
            for (int k = 0; k < 4; ++k) {
              const int64_t qx = x + dx[k], qy = y + dy[k];
              if (qx < 0 || qy < 0 || qx >= c.w || qy >= c.h || !local[size_t(qy * c.w + qx)][3]) continue;
              next[size_t(y * c.w + x)] = local[size_t(qy * c.w + qx)];
              break;
            }
          }
        local.swap(next);
      }
      for (int64_t y = 0; y < c.h; ++y)
        for (int64_t x = 0; x < c.w; ++x) {
          const Rgba& col = local[size_t(y * c.w + x)];
          uint8_t* o = &tex.rgba[size_t(4 * ((c.y + y) * tex.width + c.x + x))];
          o[0] = col[0];
          o[1] = col[1];
          o[2] = col[2];
          o[3] = 255;
        }
    }
  });
  // Vertices split per chart, with their texture coordinates.
  Mesh& om = out.mesh;
  om.triangles = m.triangles;
  std::vector<uint32_t> seen(m.positions.size(), UINT32_MAX), seen_chart(m.positions.size(), UINT32_MAX);
  for (size_t ci = 0; ci < charts.size(); ++ci) {
    const Chart& c = charts[ci];
    for (uint32_t f : c.faces) {
      const auto q = local_corners(m, c, f, density, pad);
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = m.triangles[f][size_t(k)];
        if (seen_chart[v] != ci) {
          seen_chart[v] = uint32_t(ci);
          seen[v] = uint32_t(om.positions.size());
          om.positions.push_back(m.positions[v]);
          if (!m.normals.empty()) om.normals.push_back(m.normals[v]);
          out.source_vertex.push_back(v);
          om.uvs.emplace_back((q[size_t(k)].x() + double(c.x)) / double(tex.width),
                              (q[size_t(k)].y() + double(c.y)) / double(tex.height));
        }
        om.triangles[f][size_t(k)] = seen[v];
      }
    }
  }
  return out;
}

}  // namespace voxpress::detail
