// Software rasterizer (voxpress/render/render.h): orthographic projection,
// edge functions over a supersampled z-buffer, flat Lambert shading with a
// key light above the viewer, box-filtered down to the output size.
#include "voxpress/render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "voxpress/core/error.h"
#include "voxpress/core/memory_budget.h"

namespace voxpress {

namespace {

struct Camera {
  Vec3 eye;    ///< unit vector from the scene towards the viewer
  Vec3 right;  ///< screen x
  Vec3 up;     ///< screen y
};

Camera camera_for(View view) {
  Vec3 eye, up_hint(0, 0, 1);
  switch (view) {
    case View::x: eye = Vec3(1, 0, 0); break;
    case View::y: eye = Vec3(0, -1, 0); break;
    case View::z: eye = Vec3(0, 0, 1), up_hint = Vec3(0, 1, 0); break;
    default: eye = Vec3(1.0, -1.35, 0.95).normalized(); break;
  }
  Camera c;
  c.eye = eye;
  c.right = up_hint.cross(eye).normalized();
  c.up = eye.cross(c.right);
  return c;
}

struct Rgb {
  double r, g, b;
};

Rgb rgb(const std::array<uint8_t, 3>& c) { return {double(c[0]), double(c[1]), double(c[2])}; }

// The region a face belongs to: the face attribute when present, else the
// region two or three of its vertices share (-1: curved).
int64_t face_region(const Mesh& m, const MeshAttribute* face, const MeshAttribute* vert, size_t f) {
  if (face) return int64_t(face->values[f]);
  if (!vert) return -1;
  const auto& t = m.triangles[f];
  const int64_t a = int64_t(vert->values[t[0]]), b = int64_t(vert->values[t[1]]), c = int64_t(vert->values[t[2]]);
  if (a == b || a == c) return a;
  return b == c ? b : -1;
}

}  // namespace

View parse_view(const std::string& name) {
  if (name == "iso") return View::iso;
  if (name == "x") return View::x;
  if (name == "y") return View::y;
  if (name == "z") return View::z;
  throw UsageError("unknown view '" + name + "' (iso, x, y or z)");
}

std::array<uint8_t, 3> region_color(int64_t region) {
  // Well-separated hues (golden-angle steps), pastel enough to show shading.
  const double h = std::fmod(double(region) * 0.61803398875 + 0.08, 1.0) * 6.0;
  const double s = region % 2 == 0 ? 0.55 : 0.40, v = region % 3 == 0 ? 0.95 : 0.85;
  const int i = int(h);
  const double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r, g, b;
  switch (i % 6) {
    case 0: r = v, g = t, b = p; break;
    case 1: r = q, g = v, b = p; break;
    case 2: r = p, g = v, b = t; break;
    case 3: r = p, g = q, b = v; break;
    case 4: r = t, g = p, b = v; break;
    default: r = v, g = p, b = q; break;
  }
  return {uint8_t(std::lround(r * 255)), uint8_t(std::lround(g * 255)), uint8_t(std::lround(b * 255))};
}

Texture render_mesh(const Mesh& mesh, const RenderOptions& o) {
  if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
    throw UsageError("picture size must be 16 to 8192 pixels on each side");
  if (o.supersample < 1 || o.supersample > 8) throw UsageError("supersampling must be 1 to 8");
  const int ss = o.supersample;
  const int64_t W = int64_t(o.width) * ss, H = int64_t(o.height) * ss;
  std::vector<float> depth(size_t(W * H), -std::numeric_limits<float>::infinity());
  std::vector<uint8_t> color(size_t(W * H) * 3);
  for (size_t p = 0; p < size_t(W * H); ++p)
    for (int c = 0; c < 3; ++c) color[3 * p + size_t(c)] = o.background[size_t(c)];

  const Camera cam = camera_for(o.view);
  // Fit the projected bounding rectangle with a 4 % margin.
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0, z0 = x0, z1 = -x0;
  auto extend = [&](const Vec3& p) {
    x0 = std::min(x0, cam.right.dot(p)), x1 = std::max(x1, cam.right.dot(p));
    y0 = std::min(y0, cam.up.dot(p)), y1 = std::max(y1, cam.up.dot(p));
    z0 = std::min(z0, cam.eye.dot(p)), z1 = std::max(z1, cam.eye.dot(p));
  };
  for (const Vec3& p : o.frame.empty() ? mesh.positions : o.frame) extend(p);
  Texture out;
  out.width = o.width, out.height = o.height;
  out.rgba.assign(size_t(o.width * o.height) * 4, 255);
  if (!mesh.positions.empty() && x1 >= x0) {
    const double span = std::max({x1 - x0, (y1 - y0) * double(W) / double(H), 1e-12});
    const double scale = 0.92 * double(W) / span, cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    std::vector<Eigen::Vector3d> s(mesh.positions.size());
    for (size_t v = 0; v < s.size(); ++v) {
      const Vec3& p = mesh.positions[v];
      s[v] = {(cam.right.dot(p) - cx) * scale + 0.5 * double(W), 0.5 * double(H) - (cam.up.dot(p) - cy) * scale,
              cam.eye.dot(p)};
    }
    const Vec3 light = (cam.eye + 0.7 * cam.up + 0.35 * cam.right).normalized();
    // A label map's interfaces (label_in: the label a face bounds, seen
    // from outside; interfaces_mesh) colour by label like flats by id.
    const MeshAttribute* face_reg = mesh.face_attribute("region") ? mesh.face_attribute("region") : mesh.face_attribute("label_in");
    const MeshAttribute* vert_reg = mesh.vertex_attribute("region");
    // Region colours need regions; a mesh without them is drawn as usual.
    const Coloring coloring = o.coloring == Coloring::regions && !face_reg && !vert_reg ? Coloring::automatic : o.coloring;
    const bool textured = coloring == Coloring::automatic && !mesh.texture.empty() &&
                          mesh.uvs.size() == mesh.positions.size();
    const bool vcolors = coloring == Coloring::automatic && !textured && mesh.colors.size() == mesh.positions.size();
    const Rgb base = rgb(o.base), curved = {205, 205, 205};

    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      const auto& t = mesh.triangles[f];
      const auto &a = s[t[0]], &b = s[t[1]], &c = s[t[2]];
      const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
      if (!(std::abs(area) > 1e-12)) continue;
      Vec3 n = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
      if (!(n.norm() > 0)) continue;
      n.normalize();
      double dim = 1.0;
      if (n.dot(cam.eye) < 0) n = -n, dim = 0.6;  // an inner side seen through an opening
      const double shade = dim * (0.34 + 0.46 * std::max(0.0, n.dot(light)) + 0.24 * std::max(0.0, n.dot(cam.eye)));
      Rgb face_color = base;
      if (coloring == Coloring::regions) {
        const int64_t r = face_region(mesh, face_reg, vert_reg, f);
        face_color = r >= 0 ? rgb(region_color(r)) : curved;
      }
      const int64_t ix0 = std::max<int64_t>(0, int64_t(std::floor(std::min({a.x(), b.x(), c.x()}))));
      const int64_t ix1 = std::min<int64_t>(W - 1, int64_t(std::ceil(std::max({a.x(), b.x(), c.x()}))));
      const int64_t iy0 = std::max<int64_t>(0, int64_t(std::floor(std::min({a.y(), b.y(), c.y()}))));
      const int64_t iy1 = std::min<int64_t>(H - 1, int64_t(std::ceil(std::max({a.y(), b.y(), c.y()}))));
      const double inv = 1.0 / area;
      for (int64_t y = iy0; y <= iy1; ++y)
        for (int64_t x = ix0; x <= ix1; ++x) {
          const double px = double(x) + 0.5, py = double(y) + 0.5;
          // Barycentric weights from the edge functions (either winding).
          const double wa = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) * inv;
          const double wb = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) * inv;
          const double wc = 1.0 - wa - wb;
          if (wa < 0 || wb < 0 || wc < 0) continue;
          const float z = float(wa * a.z() + wb * b.z() + wc * c.z());
          const size_t p = size_t(y * W + x);
          if (z <= depth[p]) continue;
          depth[p] = z;
          Rgb col = face_color;
          if (textured) {
            const Vec2 uv = wa * mesh.uvs[t[0]] + wb * mesh.uvs[t[1]] + wc * mesh.uvs[t[2]];
            const int64_t tx = std::clamp<int64_t>(int64_t(uv.x() * double(mesh.texture.width)), 0, mesh.texture.width - 1);
            const int64_t ty = std::clamp<int64_t>(int64_t(uv.y() * double(mesh.texture.height)), 0, mesh.texture.height - 1);
            const uint8_t* q = &mesh.texture.rgba[size_t(ty * mesh.texture.width + tx) * 4];
            col = {double(q[0]), double(q[1]), double(q[2])};
          } else if (vcolors) {
            const auto &ca = mesh.colors[t[0]], &cb = mesh.colors[t[1]], &cc = mesh.colors[t[2]];
            col = {wa * ca[0] + wb * cb[0] + wc * cc[0], wa * ca[1] + wb * cb[1] + wc * cc[1],
                   wa * ca[2] + wb * cb[2] + wc * cc[2]};
          }
          color[3 * p] = uint8_t(std::clamp(col.r * shade, 0.0, 255.0));
          color[3 * p + 1] = uint8_t(std::clamp(col.g * shade, 0.0, 255.0));
          color[3 * p + 2] = uint8_t(std::clamp(col.b * shade, 0.0, 255.0));
        }
    }

    // Strokes drawn where they are not behind the surface (a depth
    // tolerance of 0.4 % of the depth range): the triangles' edges thin and
    // grey (wireframe), the feature curves dark, about 1.6 output pixels wide.
    const double tol = 0.004 * std::max(z1 - z0, 1e-12);
    const auto stroke = [&](const Vec3& a, const Vec3& b, double radius, std::array<uint8_t, 3> rgb) {
      const int64_t r = int64_t(std::ceil(radius));
      const double len = std::hypot(b.x() - a.x(), b.y() - a.y());
      const int steps = std::max(1, int(std::ceil(len / (0.5 * ss))));
      for (int k = 0; k <= steps; ++k) {
        const double u = double(k) / steps;
        const double px = a.x() + u * (b.x() - a.x()), py = a.y() + u * (b.y() - a.y());
        const double pz = a.z() + u * (b.z() - a.z());
        for (int64_t dy = -r; dy <= r; ++dy)
          for (int64_t dx = -r; dx <= r; ++dx) {
            const int64_t x = int64_t(std::floor(px)) + dx, y = int64_t(std::floor(py)) + dy;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            if (std::hypot(double(x) + 0.5 - px, double(y) + 0.5 - py) > radius) continue;
            const size_t p = size_t(y * W + x);
            if (pz + tol < double(depth[p])) continue;
            color[3 * p] = rgb[0], color[3 * p + 1] = rgb[1], color[3 * p + 2] = rgb[2];
          }
      }
    };
    if (o.wireframe)
      for (const Triangle& t : mesh.triangles)
        for (int k = 0; k < 3; ++k)
          if (t[size_t(k)] < t[size_t((k + 1) % 3)])  // each edge once (closed meshes)
            stroke(s[t[size_t(k)]], s[t[size_t((k + 1) % 3)]], 0.35 * ss, {90, 96, 110});
    if (o.features)
      for (const auto& e : mesh.edges) stroke(s[e[0]], s[e[1]], 0.8 * ss, {25, 25, 35});
  }
  // Box filter down to the output size.
  for (int64_t y = 0; y < o.height; ++y)
    for (int64_t x = 0; x < o.width; ++x)
      for (int c = 0; c < 3; ++c) {
        unsigned sum = 0;
        for (int dy = 0; dy < ss; ++dy)
          for (int dx = 0; dx < ss; ++dx) sum += color[3 * size_t((y * ss + dy) * W + x * ss + dx) + size_t(c)];
        out.rgba[size_t(y * o.width + x) * 4 + size_t(c)] = uint8_t((sum + unsigned(ss * ss) / 2) / unsigned(ss * ss));
      }
  return out;
}

Texture side_by_side(const std::vector<Texture>& pictures, int gap) {
  Texture out;
  if (pictures.empty()) return out;
  for (const Texture& p : pictures) out.width += p.width, out.height = std::max(out.height, p.height);
  out.width += int64_t(gap) * int64_t(pictures.size() - 1);
  const uint8_t* corner = pictures[0].rgba.data();
  out.rgba.resize(size_t(out.width * out.height) * 4);
  for (size_t i = 0; i < out.rgba.size(); ++i) out.rgba[i] = corner[i % 4];
  int64_t x0 = 0;
  for (const Texture& p : pictures) {
    for (int64_t y = 0; y < p.height; ++y)
      std::copy_n(&p.rgba[size_t(y * p.width) * 4], size_t(p.width) * 4, &out.rgba[size_t(y * out.width + x0) * 4]);
    x0 += p.width + gap;
  }
  return out;
}

Mesh voxel_faces(const BinaryVolume& volume, uint64_t max_bytes, uint64_t held_bytes) {
  const Lattice& L = volume.lattice;
  const auto& d = L.dims;
  if (max_bytes) {  // counted before anything is built
    const uint64_t faces = tbb::parallel_reduce(
        tbb::blocked_range<int64_t>(0, d[2]), uint64_t(0),
        [&](const tbb::blocked_range<int64_t>& r, uint64_t acc) {
          for (int64_t k = r.begin(); k < r.end(); ++k)
            for (int64_t j = 0; j < d[1]; ++j)
              for (int64_t i = 0; i < d[0]; ++i)
                if (volume.at(i, j, k))
                  acc += !volume.at(i - 1, j, k) + !volume.at(i + 1, j, k) + !volume.at(i, j - 1, k) +
                         !volume.at(i, j + 1, k) + !volume.at(i, j, k - 1) + !volume.at(i, j, k + 1);
          return acc;
        },
        std::plus<>());
    charge_memory(volume.source, held_bytes + volume.inside.size() + faces * kVoxelFaceBytes + kRunBytesFixed, max_bytes,
                  "drawing its " + std::to_string(faces) + " voxel faces (" + std::to_string(kVoxelFaceBytes) +
                      " bytes each)");
  }
  Mesh m;
  std::unordered_map<uint64_t, uint32_t> corner_index;
  const uint64_t cx = uint64_t(d[0]) + 1, cy = uint64_t(d[1]) + 1;
  auto corner = [&](int64_t i, int64_t j, int64_t k) {
    const uint64_t key = uint64_t(i) + cx * (uint64_t(j) + cy * uint64_t(k));
    const auto [it, added] = corner_index.try_emplace(key, uint32_t(m.positions.size()));
    if (added) m.positions.push_back(L.to_physical(Vec3(double(i) - 0.5, double(j) - 0.5, double(k) - 0.5)));
    return it->second;
  };
  // A mirroring index-to-physical map turns every face inside out.
  const bool flip = L.index_to_physical_matrix().determinant() < 0;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        if (!volume.at(i, j, k)) continue;
        const std::array<int64_t, 3> ijk{i, j, k};
        for (int a = 0; a < 3; ++a)
          for (int side : {1, -1}) {
            std::array<int64_t, 3> n = ijk;
            n[size_t(a)] += side;
            if (volume.at(n[0], n[1], n[2])) continue;
            // Corners of the face: the cell corner at +side along a, spanned by b and c.
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            std::array<int64_t, 3> base = ijk;
            if (side > 0) base[size_t(a)] += 1;
            std::array<uint32_t, 4> q;
            for (int v = 0; v < 4; ++v) {
              std::array<int64_t, 3> p = base;
              p[size_t(b)] += (v == 1 || v == 2);
              p[size_t(c)] += (v >= 2);
              q[size_t(v)] = corner(p[0], p[1], p[2]);
            }
            const bool ccw = (side > 0) != flip;
            if (ccw)
              m.triangles.push_back({q[0], q[1], q[2]}), m.triangles.push_back({q[0], q[2], q[3]});
            else
              m.triangles.push_back({q[0], q[2], q[1]}), m.triangles.push_back({q[0], q[3], q[2]});
          }
      }
  return m;
}

}  // namespace voxpress
