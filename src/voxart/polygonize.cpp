// polygonize_voxel_art: the Muniz et al. pipeline over every part (see polygonize.h).
#include "voxpress/voxart/polygonize.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "../core/timing.h"
#include "../eval/mesh_query.h"
#include "atlas.h"
#include "voxpress/smooth/mesh_smoothing.h"
#include "voxpress/simplify/simplify.h"
#include "voxpress/smooth/pipeline.h"
#include "core/parallel.h"

namespace voxpress {

VoxartFairing parse_voxart_fairing(const std::string& name) {
  if (name == "lanczos") return VoxartFairing::lanczos;
  if (name == "taubin") return VoxartFairing::taubin;
  if (name == "pressing") return VoxartFairing::pressing;
  if (name == "none") return VoxartFairing::none;
  throw UsageError("unknown fairing '" + name + "' (expected lanczos, taubin, pressing or none)");
}

const char* voxart_fairing_name(VoxartFairing f) {
  switch (f) {
    case VoxartFairing::lanczos: return "lanczos";
    case VoxartFairing::taubin: return "taubin";
    case VoxartFairing::pressing: return "pressing";
    case VoxartFairing::none: return "none";
  }
  return "?";
}

AtlasPacker parse_atlas_packer(const std::string& name) {
  if (name == "best") return AtlasPacker::best;
  if (name == "paper") return AtlasPacker::paper;
  if (name == "shelf") return AtlasPacker::shelf;
  throw UsageError("unknown packer '" + name + "' (expected best, paper or shelf)");
}

namespace {

using detail::seconds_since;
using Clock = std::chrono::steady_clock;

uint32_t pack(const Rgba& c) { return uint32_t(c[0]) | uint32_t(c[1]) << 8 | uint32_t(c[2]) << 16; }

Vec3 barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return Vec3(1, 0, 0);
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return Vec3(1 - v - w, v, w);
}

// Quads -> triangles along the shorter diagonal (after fairing), in the
// part's frame mapped to the model's.
void append_quads(const QuadMesh& q, const ColorGrid& part, Mesh& out, std::vector<uint32_t>& tri_quad, uint32_t quad_base) {
  const uint32_t base = uint32_t(out.positions.size());
  for (const Vec3& p : q.positions) out.positions.push_back(part.linear * p + part.offset);
  for (uint32_t i = 0; i < q.quads.size(); ++i) {
    const auto& c = q.quads[i];
    const bool d02 = (q.positions[c[0]] - q.positions[c[2]]).squaredNorm() <= (q.positions[c[1]] - q.positions[c[3]]).squaredNorm();
    const Triangle t1 = d02 ? Triangle{c[0], c[1], c[2]} : Triangle{c[0], c[1], c[3]};
    const Triangle t2 = d02 ? Triangle{c[0], c[2], c[3]} : Triangle{c[1], c[2], c[3]};
    for (Triangle t : {t1, t2}) {
      for (uint32_t& v : t) v += base;
      out.triangles.push_back(t);
      tri_quad.push_back(quad_base + i);
    }
  }
}

}  // namespace

Mesh VoxartResult::surface() const {
  Mesh s;
  uint32_t n = 0;
  for (uint32_t v : surface_vertex) n = std::max(n, v + 1);
  s.positions.resize(n);
  for (size_t v = 0; v < surface_vertex.size(); ++v) s.positions[surface_vertex[v]] = mesh.positions[v];
  s.triangles = mesh.triangles;
  for (Triangle& t : s.triangles)
    for (uint32_t& v : t) v = surface_vertex[v];
  return s;
}

namespace {

// Everything after the quads grows with them (the atlas with its texels,
// charged once packed): charged before any of it is made (issue 73, item 1).
// Returns the bytes held: the grids, the quads' share and the run's.
uint64_t charge_quads(const VoxelArt& art, uint64_t quads, uint64_t cap) {
  uint64_t held = quads * kVoxartBytesPerQuad + kRunBytesFixed;
  for (const ColorGrid& g : art.parts) held += uint64_t(g.dims[0] * g.dims[1] * g.dims[2]) * kVoxartBytesPerCell;
  charge_memory(art.source, held, cap,
                "its " + std::to_string(quads) + " voxel faces (" + std::to_string(kVoxartBytesPerQuad) +
                    " bytes each, with the grids)");
  return held;
}

// A bad option is a usage error before any work.
void check_voxart_options(const VoxelArt& art, const VoxartOptions& options) {
  if (art.parts.empty()) throw InputError(art.source, "no voxel model to convert");
  if (!(options.lambda > 0 && options.lambda <= 2)) throw UsageError("--lambda must be in (0, 2]");
  if (!(options.chart_angle > 0 && options.chart_angle <= 90)) throw UsageError("--chart-angle must be in (0, 90]");
  // A bad texture size was exit 1 (an input error) or accepted (issue 73).
  if (options.max_texture < 1 || options.max_texture > (int64_t(1) << 16))
    throw UsageError("--max-texture must be from 1 to 65536 texels");
  if (options.texels_per_voxel < 0 || options.texels_per_voxel > 64)
    throw UsageError("--texels-per-voxel must be from 1 to 64");
  if (options.padding < 1 || options.padding > 16) throw UsageError("--padding must be 1..16 texels");
}

// 1. Solid and cuberille quads, per part.
std::vector<QuadMesh> extract_quads(const VoxelArt& art, VoxartStats& st) {
  std::vector<QuadMesh> quads;
  for (const ColorGrid& g : art.parts) {
    quads.push_back(solid_cuberille(g));
    st.voxels += g.count();
    st.quads += quads.back().quads.size();
    st.split_vertices += quads.back().split_vertices;
    st.filled_cavities += quads.back().filled_cavities;
    st.separated_edges += quads.back().separated_edges;
  }
  return quads;
}

// 2. Fairing by pressing: the unfaired cube faces go to `reference` (with
// their quads in ref_quad), each part's pressed solid to `work`.
void press_parts(const std::vector<QuadMesh>& quads, const VoxelArt& art, Mesh& work, Mesh& reference,
                 std::vector<uint32_t>& ref_quad) {
  uint32_t base = 0;
  for (size_t p = 0; p < quads.size(); ++p) {
    append_quads(quads[p], art.parts[p], reference, ref_quad, base);
    base += uint32_t(quads[p].quads.size());
    const ColorGrid& g = art.parts[p];
    BinaryVolume vol;
    vol.lattice.dims = g.dims;
    vol.lattice.origin = Vec3(0.5, 0.5, 0.5);  // samples at voxel centres
    vol.inside = fill_solid(g);
    vol.source = art.source;
    SurfaceOptions so;
    Mesh m = smooth_surface(vol, so).mesh;
    const uint32_t vb = uint32_t(work.positions.size());
    for (const Vec3& x : m.positions) work.positions.push_back(g.linear * x + g.offset);
    for (Triangle t : m.triangles) {
      for (uint32_t& v : t) v += vb;
      work.triangles.push_back(t);
    }
  }
}

// 2. Fairing of the quads themselves (Lanczos, Taubin or none), then
// triangulated into `work` (with their quads in tri_quad); faired_center
// gets the faired voxel face centres.
void fair_parts(std::vector<QuadMesh>& quads, const VoxelArt& art, const VoxartOptions& options, Mesh& work,
                std::vector<uint32_t>& tri_quad, std::vector<Vec3>& faired_center) {
  uint32_t base = 0;
  for (size_t p = 0; p < quads.size(); ++p) {
    QuadMesh& q = quads[p];
    if (options.fairing == VoxartFairing::lanczos) fair_lanczos(q, options.lambda);
    if (options.fairing == VoxartFairing::taubin) {
      // MeshLab's Taubin defaults (lambda 0.5, mu -0.53), as the paper's
      // comparison, on the triangulated quads in voxel units.
      Mesh m;
      std::vector<uint32_t> unused;
      append_quads(q, ColorGrid{}, m, unused, 0);
      FairOptions fo = fair_defaults(FairOptions::Kind::taubin);
      fo.lambda = 0.5;
      fo.mu = -0.53;
      fo.iterations = options.taubin_iterations;
      fair(m, fo);
      q.positions = m.positions;
    }
    for (size_t i = 0; i < q.quads.size(); ++i) {
      Vec3 c = Vec3::Zero();
      for (uint32_t v : q.quads[i]) c += q.positions[v];
      faired_center[base + i] = art.parts[p].linear * (c / 4) + art.parts[p].offset;
    }
    append_quads(q, art.parts[p], work, tri_quad, base);
    base += uint32_t(q.quads.size());
  }
}

// 4. Simplification (before the atlas; see polygonize.h), each face keyed
// by its colour: its quad's, or for pressing the reference's at its centroid.
template <class ReferenceColor>
void simplify_by_color(Mesh& work, const VoxartOptions& options, bool pressing, const ReferenceColor& reference_color,
                       const std::vector<Rgba>& quad_color, const std::vector<uint32_t>& tri_quad) {
  std::vector<uint32_t> keys(work.triangles.size());
  if (pressing)
    for (size_t f = 0; f < keys.size(); ++f) {
      const auto& t = work.triangles[f];
      keys[f] = pack(reference_color((work.positions[t[0]] + work.positions[t[1]] + work.positions[t[2]]) / 3));
    }
  else
    for (size_t f = 0; f < keys.size(); ++f) keys[f] = pack(quad_color[tri_quad[f]]);
  SimplifyOptions so;
  so.faces = options.target_faces;
  so.soft_keys = std::move(keys);
  voxpress::simplify(work, so);
}

// 3. Attributes (Section 4.4): normals from the distinct adjacent face
// normals, colours from the adjacent faces (only without a texture, the
// only output that carries them).
template <class FaceColor>
void vertex_attributes(Mesh& work, bool texture, const FaceColor& face_color) {
  const size_t nv = work.positions.size(), nf = work.triangles.size();
  std::vector<Vec3> fn(nf);
  std::vector<Rgba> fc(texture ? 0 : nf);
  std::vector<uint32_t> start(nv + 1, 0), adj(3 * nf);
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = work.triangles[f];
    const Vec3 n = (work.positions[t[1]] - work.positions[t[0]]).cross(work.positions[t[2]] - work.positions[t[0]]);
    fn[f] = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::Zero();
    for (uint32_t v : t) ++start[v + 1];
  }
  detail::parallel_for(fc.size(), [&](size_t f) {
    const auto& t = work.triangles[f];
    fc[f] = face_color(uint32_t(f), (work.positions[t[0]] + work.positions[t[1]] + work.positions[t[2]]) / 3);
  });
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (uint32_t f = 0; f < nf; ++f)
    for (uint32_t v : work.triangles[f]) adj[fill[v]++] = f;
  work.normals.assign(nv, Vec3::UnitZ());
  if (!texture) work.colors.assign(nv, Rgba{0, 0, 0, 255});
  detail::parallel_for(nv, [&](size_t v) {
    std::vector<Vec3> seen;
    Vec3 sum = Vec3::Zero();
    double rgb[3] = {0, 0, 0};
    for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
      const uint32_t f = adj[k];
      if (!fc.empty())
        for (int c = 0; c < 3; ++c) rgb[c] += fc[f][size_t(c)];
      const Vec3& n = fn[f];
      if (std::none_of(seen.begin(), seen.end(), [&](const Vec3& s) { return (s - n).squaredNorm() < 1e-12; })) {
        seen.push_back(n);
        sum += n;
      }
    }
    if (sum.norm() > 0) work.normals[v] = sum.normalized();
    const double k = std::max<double>(1, start[v + 1] - start[v]);
    if (!fc.empty())
      for (int c = 0; c < 3; ++c) work.colors[v][size_t(c)] = uint8_t(std::lround(rgb[c] / k));
  });
}

// Colour fidelity: each voxel face's centre (on the output surface) looked
// up in the output's colours (nearest texel, or the nearest vertex colour).
struct ColorFidelity {
  const std::vector<Rgba>& quad_color;
  const std::vector<Vec3>& quad_center;    // unfaired voxel face centres, model frame
  const std::vector<Vec3>& faired_center;  // voxel face centres on the faired surface
  bool direct, pressing;

  // The fraction of voxel faces whose centre in `out` has their voxel's colour.
  double operator()(const Mesh& out) const {
    std::optional<detail::MeshQuery> q;
    if (!direct) q.emplace(out);
    std::vector<uint8_t> exact(quad_color.size(), 0);
    detail::parallel_for(quad_color.size(), [&](size_t i) {
      uint32_t f;
      Vec3 p;
      if (direct) {
        // The first triangle of the quad, at the point nearest the faired centre.
        f = uint32_t(2 * i);
        const auto& t = out.triangles[f];
        p = detail::closest_on_triangle(faired_center[i], out.positions[t[0]], out.positions[t[1]], out.positions[t[2]]);
      } else {
        const auto hit = q->closest(pressing ? quad_center[i] : faired_center[i]);
        f = hit.face;
        p = hit.point;
      }
      const auto& t = out.triangles[f];
      const Vec3 l = barycentric(p, out.positions[t[0]], out.positions[t[1]], out.positions[t[2]]);
      Rgba got;
      if (!out.texture.empty()) {
        got = detail::sample_texture(out.texture, l[0] * out.uvs[t[0]] + l[1] * out.uvs[t[1]] + l[2] * out.uvs[t[2]]);
      } else {
        int best = 0;
        for (int c = 1; c < 3; ++c)
          if (l[c] > l[best]) best = c;
        got = out.colors[t[size_t(best)]];
      }
      exact[i] = got[0] == quad_color[i][0] && got[1] == quad_color[i][1] && got[2] == quad_color[i][2];
    });
    uint64_t n = 0;
    for (uint8_t e : exact) n += e;
    return double(n) / double(quad_color.size());
  }
};

// 5. Texture atlas (or, without a texture, `work` as it is) into
// result.mesh, with the colour fidelity and the atlas figures in the stats.
template <class FaceColor>
void texture_atlas(const Mesh& work, const VoxelArt& art, const VoxartOptions& options, uint64_t held, bool direct,
                   const FaceColor& face_color, const ColorFidelity& color_exact, VoxartResult& result) {
  VoxartStats& st = result.stats;
  Mesh& out = result.mesh;
  if (options.texture) {
    // Texel density: texels per voxel edge (the smallest voxel edge of all parts).
    double voxel = INFINITY;
    for (const ColorGrid& g : art.parts)
      for (int a = 0; a < 3; ++a) voxel = std::min(voxel, g.linear.col(a).norm());
    int k = options.texels_per_voxel > 0 ? options.texels_per_voxel : 4;
    for (;;) {
      detail::AtlasOptions ao;
      ao.angle_degrees = options.chart_angle;
      ao.texels_per_unit = k / voxel;
      ao.padding = options.padding;
      ao.packer = options.packer;
      ao.max_side = options.max_texture;
      ao.max_bytes = options.max_bytes;
      ao.held_bytes = held;
      ao.source = art.source;
      detail::AtlasResult a = detail::build_atlas(work, ao, face_color);
      const int64_t side = std::max(a.mesh.texture.width, a.mesh.texture.height);
      const bool too_big = side > options.max_texture;
      if (!too_big) st.color_exact = color_exact(a.mesh);
      // Automatic density: finer while some faired voxel face is too small
      // to own the texel at its centre (thin parts shrink under fairing).
      if (!too_big && options.texels_per_voxel == 0 && direct && st.color_exact < 1 && k < 16 &&
          2 * side <= options.max_texture) {
        k *= 2;
        continue;
      }
      if (too_big) {
        if (options.texels_per_voxel == 0 && k > 1) {
          k /= 2;
          continue;
        }
        throw LimitError(art.source, "the texture atlas would be " + std::to_string(a.mesh.texture.width) + " x " +
                                         std::to_string(a.mesh.texture.height) + " texels, above the " +
                                         std::to_string(options.max_texture) + " limit (simplify with --faces)");
      }
      out = std::move(a.mesh);
      result.surface_vertex = std::move(a.source_vertex);
      st.charts = a.charts;
      st.utilisation_paper = a.utilisation_paper;
      st.utilisation_shelf = a.utilisation_shelf;
      st.packer = a.packer;
      st.utilisation = double(a.covered_texels) / (double(out.texture.width) * double(out.texture.height));
      break;
    }
    st.texels_per_voxel = k;
    st.texture_width = out.texture.width;
    st.texture_height = out.texture.height;
  } else {
    out = work;
    st.color_exact = color_exact(out);
    result.surface_vertex.resize(out.positions.size());
    for (uint32_t v = 0; v < out.positions.size(); ++v) result.surface_vertex[v] = v;
  }
}

}  // namespace

VoxartResult polygonize_voxel_art(const VoxelArt& art, const VoxartOptions& options) {
  const auto t_start = Clock::now();
  VoxartResult result;
  VoxartStats& st = result.stats;
  check_voxart_options(art, options);

  // 1. Solid and cuberille quads, per part.
  auto t0 = Clock::now();
  std::vector<QuadMesh> quads = extract_quads(art, st);
  const uint64_t held = charge_quads(art, st.quads, options.max_bytes);
  std::vector<Rgba> quad_color;
  std::vector<Vec3> quad_center;  // unfaired voxel face centres, model frame
  for (size_t p = 0; p < quads.size(); ++p) {
    quad_color.insert(quad_color.end(), quads[p].colors.begin(), quads[p].colors.end());
    for (const Vec3& c : quads[p].centers) quad_center.push_back(art.parts[p].linear * c + art.parts[p].offset);
  }
  st.seconds_extract = seconds_since(t0);

  // 2. Fairing.
  t0 = Clock::now();
  Mesh work;                    // the faired triangle mesh, model frame
  std::vector<uint32_t> tri_quad;  // its triangles' quads (not for pressing)
  Mesh reference;               // where texel colours come from: unfaired cuberille for pressing
  std::vector<uint32_t> ref_quad;
  std::vector<Vec3> faired_center = quad_center;  // voxel face centres on the faired surface
  const bool pressing = options.fairing == VoxartFairing::pressing;
  if (pressing)
    press_parts(quads, art, work, reference, ref_quad);
  else
    fair_parts(quads, art, options, work, tri_quad, faired_center);
  st.seconds_fair = seconds_since(t0);
  // Final triangle f is a triangle of quad tri_quad[f] unless the surface was
  // pressed or will be simplified; then colours come from the closest point
  // of `reference` (the faired surface before simplification, or the cube
  // faces for pressing), queried through a BVH built only in that case.
  const bool simplify = options.target_faces > 0 && options.target_faces < work.triangles.size();
  const bool direct = !pressing && !simplify;
  if (!pressing && simplify) {
    reference = work;
    ref_quad = tri_quad;
  }
  std::optional<detail::MeshQuery> ref_query;
  if (!direct) ref_query.emplace(reference);
  auto reference_color = [&](const Vec3& p) { return quad_color[ref_quad[ref_query->closest(p).face]]; };

  // 4. Simplification (before the atlas; see polygonize.h).
  t0 = Clock::now();
  if (simplify) simplify_by_color(work, options, pressing, reference_color, quad_color, tri_quad);
  st.seconds_simplify = seconds_since(t0);
  auto face_color = [&](uint32_t f, const Vec3& p) { return direct ? quad_color[tri_quad[f]] : reference_color(p); };

  // 3. Attributes.
  t0 = Clock::now();
  vertex_attributes(work, options.texture, face_color);
  st.seconds_attributes = seconds_since(t0);

  // 5. Texture atlas.
  t0 = Clock::now();
  const ColorFidelity color_exact{quad_color, quad_center, faired_center, direct, pressing};
  texture_atlas(work, art, options, held, direct, face_color, color_exact, result);
  st.seconds_atlas = seconds_since(t0);
  st.seconds_total = seconds_since(t_start);

  Mesh& out = result.mesh;
  if (options.y_up) {
    // Voxel art is Z-up; glTF is Y-up: (x, y, z) -> (x, z, -y), a rotation.
    for (Vec3& p : out.positions) p = Vec3(p.x(), p.z(), -p.y());
    for (Vec3& n : out.normals) n = Vec3(n.x(), n.z(), -n.y());
  }
  st.vertices = out.positions.size();
  st.triangles = out.triangles.size();
  return result;
}

}  // namespace voxpress
