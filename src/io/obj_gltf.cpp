// OBJ (tinyobjloader, double precision) and glTF 2.0 / GLB (tinygltf).
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "formats.h"
#include "io_util.h"
#include "voxpress/io/image_io.h"

namespace voxpress::detail {
namespace {
const auto& fmt = format_double;
}  // namespace

namespace {
// tinyobjloader reads a number it cannot parse as 0 (`v nan 0 0`, `v abc 0
// 0`) and an index it cannot parse as a missing one. Before it runs, every
// numeric field of the records it reads (v, vt, vn, f, l) must parse whole:
// a float for v / vt / vn (finite), index[/index[/index]] for f and l.
void check_obj_numbers(const std::string& path, uint64_t max_bytes) {
  const auto bytes = read_whole_file(path, max_bytes, "reading the OBJ file");
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  size_t line_no = 0;
  for (size_t pos = 0; pos < text.size();) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto words = split_ws(line);
    if (words.empty()) continue;
    const std::string& key = words[0];
    const bool vec = key == "v" || key == "vt" || key == "vn", elem = key == "f" || key == "l";
    if (!vec && !elem) continue;
    const std::string where = "line " + std::to_string(line_no) + " (" + key + ")";
    if (words.size() < (key == "vt" ? 2u : key == "l" ? 3u : 4u)) throw InputError(path, where + ": too few values");
    for (size_t w = 1; w < words.size(); ++w) {
      const std::string& tok = words[w];
      if (vec) {
        double x = 0;
        const char* first = tok.data() + (tok[0] == '+' ? 1 : 0);
        const auto [ptr, ec] = std::from_chars(first, tok.data() + tok.size(), x);
        if (ec != std::errc() || ptr != tok.data() + tok.size() || !std::isfinite(x))
          throw InputError(path, where + ": '" + tok + "' is not a finite number");
        continue;
      }
      // index, index/index, index//index or index/index/index; nonzero integers.
      size_t start = 0;
      for (int part = 0; part < 3 && start <= tok.size(); ++part) {
        const size_t slash = std::min(tok.find('/', start), tok.size());
        const std::string_view piece(tok.data() + start, slash - start);
        if (!(piece.empty() && part > 0)) {
          long long i = 0;
          const auto [ptr, ec] = std::from_chars(piece.data(), piece.data() + piece.size(), i);
          if (ec != std::errc() || ptr != piece.data() + piece.size() || i == 0)
            throw InputError(path, where + ": '" + tok + "' is not a vertex index");
        }
        start = slash + 1;
        if (slash == tok.size()) break;
        if (part == 2) throw InputError(path, where + ": '" + tok + "' is not a vertex index");
      }
    }
  }
}
}  // namespace

Mesh read_obj(const std::string& path, uint64_t max_bytes) {
  const uint64_t fs = file_size(path);
  check_limit(path, fs * 4, max_bytes, "parsing the OBJ file");
  check_obj_numbers(path, max_bytes);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  const std::string base = std::filesystem::path(path).parent_path().string() + "/";
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), base.c_str(), true, false)) {
    std::string e = trim(err);
    if (const auto nl = e.find('\n'); nl != std::string::npos) e = e.substr(0, nl);
    throw InputError(path, "cannot parse OBJ" + (e.empty() ? "" : " (" + e + ")"));
  }
  Mesh m;
  const size_t nv = attrib.vertices.size() / 3;
  m.positions.resize(nv);
  for (size_t v = 0; v < nv; ++v)
    m.positions[v] = Vec3(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
  for (const auto& sh : shapes) {
    size_t offset = 0;
    for (size_t f = 0; f < sh.mesh.num_face_vertices.size(); ++f) {
      const size_t n = sh.mesh.num_face_vertices[f];
      if (n < 3) throw InputError(path, "OBJ face with fewer than 3 vertices");
      for (size_t q = 1; q + 1 < n; ++q) {
        Triangle t;
        const size_t corners[3] = {offset, offset + q, offset + q + 1};
        for (int c = 0; c < 3; ++c) {
          const int idx = sh.mesh.indices[corners[c]].vertex_index;
          if (idx < 0 || size_t(idx) >= nv) throw InputError(path, "OBJ face uses a missing vertex");
          t[size_t(c)] = uint32_t(idx);
        }
        m.triangles.push_back(t);
      }
      offset += n;
    }
  }
  for (const auto& sh : shapes) {
    size_t offset = 0;
    for (const int n : sh.lines.num_line_vertices) {
      for (int q = 0; q + 1 < n; ++q) {
        const int a = sh.lines.indices[offset + size_t(q)].vertex_index, b = sh.lines.indices[offset + size_t(q) + 1].vertex_index;
        if (a < 0 || b < 0 || size_t(a) >= nv || size_t(b) >= nv) throw InputError(path, "OBJ line uses a missing vertex");
        m.edges.push_back({uint32_t(a), uint32_t(b)});
      }
      offset += size_t(n);
    }
  }
  if (m.triangles.empty()) throw InputError(path, "the OBJ file holds no faces");
  m.validate(path);
  return m;
}

void write_obj(const std::string& path, const Mesh& m) {
  m.validate(path);
  // A texture goes beside the OBJ as STEM.png with STEM.mtl naming it; both
  // are written (atomically) before the OBJ, so a complete OBJ always finds them.
  const std::filesystem::path obj_path(path);
  const std::string stem = obj_path.stem().string();
  if (!m.texture.empty()) {
    const auto dir = obj_path.parent_path();
    write_png((dir / (stem + ".png")).string(), m.texture.width, m.texture.height, m.texture.rgba);
    write_stream_atomically((dir / (stem + ".mtl")).string(), [&](std::ostream& out) {
      out << "# written by voxpress\nnewmtl voxpress\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " << stem
          << ".png\n";
    });
  }
  // A textured mesh splits its vertices at chart seams; OBJ indexes
  // positions and texture coordinates apart, so the positions are written
  // welded (the file is the closed solid) and each corner keeps its own vt.
  std::vector<uint32_t> pos_of(m.positions.size()), kept;
  if (!m.uvs.empty()) {
    pos_of = identical_positions(m, &kept);
  } else {
    for (uint32_t v = 0; v < pos_of.size(); ++v) pos_of[v] = v;
    kept = pos_of;
  }
  write_stream_atomically(path, [&](std::ostream& out) {
    std::string buf = "# written by voxpress\n";
    if (!m.texture.empty()) buf += "mtllib " + stem + ".mtl\nusemtl voxpress\n";
    for (const uint32_t v : kept) {
      const Vec3& p = m.positions[v];
      buf += "v " + fmt(p.x()) + " " + fmt(p.y()) + " " + fmt(p.z());
      if (!m.colors.empty())
        for (int c = 0; c < 3; ++c) {
          buf += ' ';
          buf += fmt(m.colors[v][size_t(c)] / 255.0);
        }
      buf += "\n";
      if (buf.size() > (1 << 20)) {
        out << buf;
        buf.clear();
      }
    }
    const bool vn = !m.normals.empty(), vt = !m.uvs.empty();
    if (vn)
      for (const Vec3& n : m.normals) buf += "vn " + fmt(n.x()) + " " + fmt(n.y()) + " " + fmt(n.z()) + "\n";
    // OBJ's v axis points up the image, glTF's (ours) down.
    if (vt)
      for (const Vec2& t : m.uvs) buf += "vt " + fmt(t.x()) + " " + fmt(1.0 - t.y()) + "\n";
    // Faces with a "region" attribute are grouped per region (g flat_<id>,
    // g curved), in a stable order; labelled edges become "l" records.
    std::vector<size_t> order(m.triangles.size());
    for (size_t f = 0; f < order.size(); ++f) order[f] = f;
    const MeshAttribute* region = m.face_attribute("region");
    if (region)
      std::stable_sort(order.begin(), order.end(),
                       [&](size_t a, size_t b) { return region->values[a] < region->values[b]; });
    for (size_t k = 0; k < order.size(); ++k) {
      if (region && (k == 0 || region->values[order[k]] != region->values[order[k - 1]])) {
        const double r = region->values[order[k]];
        buf += r < 0 ? std::string("g curved\n") : "g flat_" + std::to_string(int64_t(r)) + "\n";
      }
      buf += "f";
      for (uint32_t i : m.triangles[order[k]]) {
        const std::string id = std::to_string(i + 1);
        buf += ' ';  // appended, not " " + ...: GCC 12 warns falsely (-Wrestrict) on that
        buf += std::to_string(pos_of[i] + 1);
        if (vt || vn) buf += "/" + (vt ? id : std::string()) + (vn ? "/" + id : std::string());
      }
      buf += "\n";
      if (buf.size() > (1 << 20)) {
        out << buf;
        buf.clear();
      }
    }
    if (!m.edges.empty()) buf += "g sharp_edges\n";
    for (const auto& e : m.edges)
      buf += "l " + std::to_string(pos_of[e[0]] + 1) + " " + std::to_string(pos_of[e[1]] + 1) + "\n";
    out << buf;
  });
}

Mesh read_gltf(const std::string& path, uint64_t max_bytes, bool binary) {
  const uint64_t fs = file_size(path);
  check_limit(path, fs * 3, max_bytes, "parsing the glTF file");
  tinygltf::TinyGLTF loader;
  // Images are not needed to check or measure a mesh (and a missing one
  // would fail the whole load).
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                           void*) { return true; },
                        nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok) {
    std::string e = trim(err);
    if (const auto nl = e.find('\n'); nl != std::string::npos) e = e.substr(0, nl);
    throw InputError(path, "cannot parse glTF" + (e.empty() ? "" : " (" + e + ")"));
  }
  for (const auto& node : model.nodes)
    if (!node.matrix.empty() || !node.translation.empty() || !node.rotation.empty() || !node.scale.empty())
      throw InputError(path, "glTF node transforms are not supported (positions are read as stored)");
  // One accessor's elements as doubles, checked against its buffer.
  auto read_accessor = [&](int index, int want_type, std::vector<double>& out) {
    if (index < 0 || size_t(index) >= model.accessors.size()) throw InputError(path, "glTF accessor index out of range");
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.type != want_type) throw InputError(path, "glTF accessor of an unexpected type");
    if (a.sparse.isSparse) throw InputError(path, "sparse glTF accessors are not supported");
    if (a.bufferView < 0 || size_t(a.bufferView) >= model.bufferViews.size())
      throw InputError(path, "glTF accessor without a buffer view");
    const tinygltf::BufferView& bv = model.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model.buffers.size()) throw InputError(path, "glTF buffer index out of range");
    const auto& data = model.buffers[size_t(bv.buffer)].data;
    const int comps = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (comps <= 0 || csize <= 0) throw InputError(path, "glTF accessor of an unknown component type");
    const uint64_t elem = uint64_t(comps) * uint64_t(csize);
    const uint64_t stride = bv.byteStride ? bv.byteStride : elem;
    const uint64_t start = uint64_t(bv.byteOffset) + uint64_t(a.byteOffset);
    if (a.count > 0 && (stride < elem || start + (uint64_t(a.count) - 1) * stride + elem > data.size() ||
                        uint64_t(a.byteOffset) + (uint64_t(a.count) - 1) * stride + elem > bv.byteLength))
      throw InputError(path, "glTF accessor runs past its buffer (truncated?)");
    check_limit(path, uint64_t(a.count) * uint64_t(comps) * 8, max_bytes, "reading a glTF accessor");
    out.resize(size_t(a.count) * size_t(comps));
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < comps; ++c) {
        const unsigned char* p = data.data() + start + i * stride + uint64_t(c) * uint64_t(csize);
        double v = 0;
        switch (a.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); v = f; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, p, 4); v = u; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t u; std::memcpy(&u, p, 2); v = u; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = *p; break;
          default: throw InputError(path, "glTF accessor of an unsupported component type");
        }
        out[i * size_t(comps) + size_t(c)] = v;
      }
  };
  Mesh m;
  std::vector<double> pos, idx;
  for (const auto& mesh : model.meshes)
    for (const auto& prim : mesh.primitives) {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // points and lines carry no faces
      const auto it = prim.attributes.find("POSITION");
      if (it == prim.attributes.end()) throw InputError(path, "glTF primitive without positions");
      if (model.accessors[size_t(std::max(0, it->second))].componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        throw InputError(path, "glTF positions must be float32");
      read_accessor(it->second, TINYGLTF_TYPE_VEC3, pos);
      const size_t base = m.positions.size(), nv = pos.size() / 3;
      for (size_t v = 0; v < nv; ++v) m.positions.emplace_back(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
      if (prim.indices >= 0) {
        read_accessor(prim.indices, TINYGLTF_TYPE_SCALAR, idx);
      } else {
        idx.resize(nv);
        for (size_t v = 0; v < nv; ++v) idx[v] = double(v);
      }
      if (idx.size() % 3) throw InputError(path, "glTF triangle indices are not a multiple of 3");
      for (size_t i = 0; i < idx.size(); i += 3) {
        Triangle t;
        for (int c = 0; c < 3; ++c) {
          if (idx[i + size_t(c)] >= double(nv)) throw InputError(path, "glTF face uses a missing vertex");
          t[size_t(c)] = uint32_t(base + size_t(idx[i + size_t(c)]));
        }
        m.triangles.push_back(t);
      }
    }
  if (m.triangles.empty()) throw InputError(path, "the glTF file holds no triangles");
  // glTF has one index per corner for every attribute, so a textured mesh
  // repeats its seam vertices; welded like STL's, the file reads as its solid.
  weld_identical_vertices(m);
  m.validate(path);
  return m;
}

void write_gltf_scene(const std::string& path, const std::vector<SceneMesh>& meshes, bool binary) {
  if (meshes.empty()) throw UsageError(path + ": a glTF scene needs at least one mesh");
  for (const SceneMesh& e : meshes) {
    e.mesh->validate(path);
    if (e.mesh->triangles.empty()) throw UsageError(path + ": glTF output needs at least one triangle (" + e.name + ")");
  }
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "voxpress";
  tinygltf::Buffer buffer;
  tinygltf::Scene scene;
  auto add_view = [&](const void* data, size_t bytes, int target) {
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* b = static_cast<const unsigned char*>(data);
    buffer.data.insert(buffer.data.end(), b, b + bytes);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
  };
  auto add_accessor = [&](int view, int component, size_t count, int type, bool normalized = false) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component;
    a.count = count;
    a.type = type;
    a.normalized = normalized;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  };
  for (const SceneMesh& e : meshes) {
  const Mesh& m = *e.mesh;
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  // Positions (float32, with the bounds the specification requires).
  std::vector<float> pos(3 * m.positions.size());
  std::vector<double> lo(3, INFINITY), hi(3, -INFINITY);
  for (size_t v = 0; v < m.positions.size(); ++v)
    for (int a = 0; a < 3; ++a) {
      pos[3 * v + size_t(a)] = float(m.positions[v][a]);
      lo[size_t(a)] = std::min(lo[size_t(a)], double(pos[3 * v + size_t(a)]));
      hi[size_t(a)] = std::max(hi[size_t(a)], double(pos[3 * v + size_t(a)]));
    }
  int acc = add_accessor(add_view(pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                         TINYGLTF_COMPONENT_TYPE_FLOAT, m.positions.size(), TINYGLTF_TYPE_VEC3);
  model.accessors[size_t(acc)].minValues = lo;
  model.accessors[size_t(acc)].maxValues = hi;
  prim.attributes["POSITION"] = acc;
  if (!m.normals.empty()) {
    std::vector<float> n(3 * m.normals.size());
    for (size_t v = 0; v < m.normals.size(); ++v) {
      Vec3 u = m.normals[v];
      const double len = u.norm();
      u = len > 0 ? Vec3(u / len) : Vec3(0, 0, 1);
      for (int a = 0; a < 3; ++a) n[3 * v + size_t(a)] = float(u[a]);
    }
    prim.attributes["NORMAL"] = add_accessor(add_view(n.data(), n.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, m.normals.size(), TINYGLTF_TYPE_VEC3);
  }
  if (!m.colors.empty())
    prim.attributes["COLOR_0"] =
        add_accessor(add_view(m.colors.data(), m.colors.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, m.colors.size(), TINYGLTF_TYPE_VEC4, true);
  if (!m.uvs.empty()) {
    std::vector<float> t(2 * m.uvs.size());
    for (size_t v = 0; v < m.uvs.size(); ++v) {
      t[2 * v] = float(m.uvs[v].x());
      t[2 * v + 1] = float(m.uvs[v].y());
    }
    prim.attributes["TEXCOORD_0"] = add_accessor(add_view(t.data(), t.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                                                 TINYGLTF_COMPONENT_TYPE_FLOAT, m.uvs.size(), TINYGLTF_TYPE_VEC2);
  }
  prim.indices = add_accessor(add_view(m.triangles.data(), m.triangles.size() * 12, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, m.triangles.size() * 3, TINYGLTF_TYPE_SCALAR);
  tinygltf::Material mat;
  mat.name = e.name;
  mat.pbrMetallicRoughness.baseColorFactor = {e.color[0], e.color[1], e.color[2], e.color[3]};
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = 0.8;
  mat.doubleSided = false;
  if (!m.texture.empty() && !m.uvs.empty()) {
    // The texture as an embedded PNG (a buffer view, also in .gltf's single
    // data-URI buffer), sampled nearest so voxel colours stay crisp.
    const auto png = encode_png(m.texture.width, m.texture.height, m.texture.rgba);
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = png.size();
    buffer.data.insert(buffer.data.end(), png.begin(), png.end());
    model.bufferViews.push_back(view);
    tinygltf::Image image;
    image.name = "voxpress_diffuse";
    image.mimeType = "image/png";
    image.bufferView = int(model.bufferViews.size() - 1);
    model.images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_NEAREST;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_NEAREST;
    sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = int(model.images.size() - 1);
    texture.sampler = int(model.samplers.size() - 1);
    model.textures.push_back(texture);
    mat.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
    mat.pbrMetallicRoughness.baseColorTexture.index = int(model.textures.size() - 1);
    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
  }
  model.materials.push_back(mat);
  prim.material = int(model.materials.size() - 1);
  tinygltf::Mesh mesh;
  mesh.name = e.name;
  mesh.primitives.push_back(prim);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = int(model.meshes.size() - 1);
  if (meshes.size() > 1) node.name = e.name;
  model.nodes.push_back(node);
  scene.nodes.push_back(int(model.nodes.size() - 1));
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  model.buffers.push_back(std::move(buffer));
  write_stream_atomically(path, [&](std::ostream& out) {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, !binary, binary)) throw InputError(path, "glTF writer failed");
  });
}

void write_gltf(const std::string& path, const Mesh& m, bool binary) {
  write_gltf_scene(path, {{"voxpress", &m, {0.8, 0.8, 0.8, 1.0}}}, binary);
}

}  // namespace voxpress::detail
