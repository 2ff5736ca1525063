// MagicaVoxel .vox reader.
//
// Format: "VOX " + version, then a MAIN chunk whose children are SIZE / XYZI
// pairs (one per model, optionally announced by PACK), an optional RGBA
// palette (entry i is the colour of index i + 1) and, in files written since
// MagicaVoxel 0.99, the scene graph: nTRN (transform: child node, frames
// whose "_r" byte encodes a signed axis permutation and "_t" a translation),
// nGRP (children), nSHP (model), LAYR (hidden layers). A model of size s
// placed by (R, t) puts voxel v at R (v - floor(s / 2)) + t (MagicaVoxel
// rotates about the model's centre voxel). Chunks we do not use (MATL, MATT,
// rOBJ, rCAM, NOTE, IMAP, and unknown ones) are skipped by their sizes.
#include <algorithm>
#include <bit>
#include <map>

#include "../io/io_util.h"
#include "byte_cursor.h"
#include "voxpress/io/volume_io.h"
#include "voxel_art_formats.h"

static_assert(std::endian::native == std::endian::little, "the .vox/.vxl readers assume a little-endian host");

namespace voxpress {

const std::array<Rgba, 256>& magicavoxel_default_palette() {
  // The palette MagicaVoxel uses without an RGBA chunk: the 6x6x6 cube of
  // {ff, cc, 99, 66, 33, 00} (blue fastest, its final black dropped), then
  // ten shades each of red, green, blue and grey.
  static const std::array<Rgba, 256> palette = [] {
    std::array<Rgba, 256> p{};
    const uint8_t cube[6] = {0xff, 0xcc, 0x99, 0x66, 0x33, 0x00};
    size_t i = 1;
    for (uint8_t r : cube)
      for (uint8_t g : cube)
        for (uint8_t b : cube) p[i++] = {r, g, b, 255};
    --i;
    const uint8_t ramp[10] = {0xee, 0xdd, 0xbb, 0xaa, 0x88, 0x77, 0x55, 0x44, 0x22, 0x11};
    for (int channel = 0; channel < 4; ++channel)
      for (uint8_t v : ramp) {
        Rgba c{0, 0, 0, 255};
        for (int a = 0; a < 3; ++a)
          if (channel == 3 || channel == a) c[size_t(a)] = v;
        p[i++] = c;
      }
    return p;
  }();
  return palette;
}

namespace detail {
namespace {

struct VoxModel {
  std::array<int64_t, 3> size{};
  std::vector<std::array<uint8_t, 4>> voxels;  // x, y, z, colour index
};

using Dict = std::map<std::string, std::string>;

struct SceneNode {
  enum Kind { transform, group, shape } kind = transform;
  Dict attributes;
  Dict frame;                   // transform: the first frame's attributes
  int32_t layer = -1;           // transform
  std::vector<int32_t> children;  // transform: one; group: many; shape: model ids
};

// A signed axis permutation and a translation: x -> R x + t.
struct Placement {
  std::array<std::array<int64_t, 3>, 3> r{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<int64_t, 3> t{0, 0, 0};
  std::array<int64_t, 3> apply(const std::array<int64_t, 3>& v) const {
    std::array<int64_t, 3> o{};
    for (int a = 0; a < 3; ++a) o[size_t(a)] = r[size_t(a)][0] * v[0] + r[size_t(a)][1] * v[1] + r[size_t(a)][2] * v[2] + t[size_t(a)];
    return o;
  }
  Placement then(const Placement& parent) const {  // parent ∘ this
    Placement o;
    for (size_t i = 0; i < 3; ++i)
      for (size_t j = 0; j < 3; ++j) o.r[i][j] = parent.r[i][0] * r[0][j] + parent.r[i][1] * r[1][j] + parent.r[i][2] * r[2][j];
    for (size_t i = 0; i < 3; ++i) o.t[i] = parent.r[i][0] * t[0] + parent.r[i][1] * t[1] + parent.r[i][2] * t[2] + parent.t[i];
    return o;
  }
};

Dict read_dict(const std::string& path, ByteCursor& c) {
  const uint32_t n = c.u32("dictionary");
  if (n > c.left() / 8) throw InputError(path, "dictionary of " + std::to_string(n) + " entries is larger than its chunk");
  Dict d;
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t kn = c.u32("dictionary key");
    std::string k = c.text(kn, "dictionary key");
    const uint32_t vn = c.u32("dictionary value");
    d[k] = c.text(vn, "dictionary value");
  }
  return d;
}

Placement parse_frame(const std::string& path, const Dict& frame) {
  Placement p;
  if (auto it = frame.find("_r"); it != frame.end()) {
    const int64_t bits = parse_int(path, it->second, "nTRN rotation");
    const int i0 = int(bits & 3), i1 = int((bits >> 2) & 3);
    if (bits < 0 || bits > 127 || i0 > 2 || i1 > 2 || i0 == i1)
      throw InputError(path, "nTRN rotation " + it->second + " is not a signed axis permutation");
    const int col[3] = {i0, i1, 3 - i0 - i1};
    for (size_t row = 0; row < 3; ++row) {
      p.r[row] = {0, 0, 0};
      p.r[row][size_t(col[row])] = (bits >> (4 + row)) & 1 ? -1 : 1;
    }
  }
  if (auto it = frame.find("_t"); it != frame.end()) {
    const auto parts = split_ws(it->second);
    if (parts.size() != 3) throw InputError(path, "nTRN translation '" + it->second + "' is not three integers");
    for (size_t a = 0; a < 3; ++a) {
      p.t[a] = parse_int(path, parts[a], "nTRN translation");
      if (std::abs(p.t[a]) > (int64_t(1) << 24)) throw InputError(path, "nTRN translation " + parts[a] + " is absurd");
    }
  }
  return p;
}

// What a scene-graph node places, computed without expanding it: how many
// shape instances and the box of their painted voxels (a signed axis
// permutation maps a box onto a box). A group listing one child twice,
// nested 40 deep, places 2^40 instances from a 3 KB file (issue 73).
struct Reach {
  uint64_t instances = 0;  // saturating
  bool any = false;        // some painted voxel
  std::array<int64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
  void add(const Reach& o) {
    instances = o.instances > UINT64_MAX - instances ? UINT64_MAX : instances + o.instances;
    if (!o.any) return;
    for (size_t a = 0; a < 3; ++a) {
      lo[a] = any ? std::min(lo[a], o.lo[a]) : o.lo[a];
      hi[a] = any ? std::max(hi[a], o.hi[a]) : o.hi[a];
    }
    any = true;
  }
  Reach placed(const Placement& p) const {
    Reach r = *this;
    if (!any) return r;
    const auto a = p.apply(lo), b = p.apply(hi);
    for (size_t i = 0; i < 3; ++i) r.lo[i] = std::min(a[i], b[i]), r.hi[i] = std::max(a[i], b[i]);
    return r;
  }
};

bool hidden(const SceneNode& n, const std::map<int32_t, bool>& hidden_layers) {
  if (auto h = n.attributes.find("_hidden"); h != n.attributes.end() && h->second == "1") return true;
  auto l = hidden_layers.find(n.layer);
  return l != hidden_layers.end() && l->second;
}

// The Reach of node `root` (post-order with an explicit stack, each node
// once; a node met again while in progress is a cycle). `models` gives each
// model's Reach as one instance placed by centred().
Reach scene_reach(const std::string& path, const std::map<int32_t, SceneNode>& nodes,
                  const std::map<int32_t, bool>& hidden_layers, const std::vector<Reach>& models, int32_t root) {
  std::map<int32_t, Reach> done;
  std::map<int32_t, bool> open;
  std::vector<std::pair<int32_t, bool>> stack{{root, false}};  // node, children already pushed
  while (!stack.empty()) {
    auto [id, expanded] = stack.back();
    stack.pop_back();
    if (done.count(id)) continue;
    auto found = nodes.find(id);
    if (found == nodes.end()) throw InputError(path, "scene node " + std::to_string(id) + " is referenced but missing");
    const SceneNode& n = found->second;
    const bool skip = n.kind == SceneNode::transform && hidden(n, hidden_layers);
    if (!expanded && n.kind != SceneNode::shape && !skip) {
      if (open[id]) throw InputError(path, "the scene graph has a cycle");
      open[id] = true;
      stack.push_back({id, true});
      for (int32_t ch : n.children)
        if (!done.count(ch)) stack.push_back({ch, false});
      continue;
    }
    Reach r;
    if (skip) {
    } else if (n.kind == SceneNode::transform) {
      r = done.at(n.children[0]).placed(parse_frame(path, n.frame));
    } else if (n.kind == SceneNode::group) {
      for (int32_t ch : n.children) r.add(done.at(ch));
    } else {
      for (int32_t m : n.children) {
        if (m < 0 || size_t(m) >= models.size())
          throw InputError(path, "shape node " + std::to_string(id) + " uses model " + std::to_string(m) +
                                     " but the file has " + std::to_string(models.size()));
        r.add(models[size_t(m)]);
      }
    }
    open[id] = false;
    done[id] = r;
  }
  return done.at(root);
}

// Refuses, before anything is expanded, a scene whose instances or grid do
// not fit the cap: the instance list, and the grid with the buffers the
// voxel-art pipeline keeps per cell (kVoxartBytesPerCell).
void check_scene(const std::string& path, const Reach& reach, uint64_t cap) {
  if (!reach.any) throw InputError(path, "the model is empty (no voxel)");
  const uint64_t per_instance = 128;  // an Instance and its share of the walk
  if (cap && reach.instances > cap / per_instance)
    throw LimitError(path, "the scene graph places " +
                               (reach.instances == UINT64_MAX ? std::string("more than 2^64") : std::to_string(reach.instances)) +
                               " shape instances, above what the memory limit of " + format_bytes(cap) +
                               " holds (raise it with --max-memory)");
  std::array<int64_t, 3> dims{};
  for (size_t a = 0; a < 3; ++a) dims[a] = reach.hi[a] - reach.lo[a] + 1;
  const uint64_t cells = checked_count(path, dims, 1, kVoxartBytesPerCell);
  check_limit(path, cells * kVoxartBytesPerCell, cap,
              "the voxel grid of " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                  std::to_string(dims[2]) + " cells (" + std::to_string(kVoxartBytesPerCell) + " bytes each)");
}

}  // namespace

namespace {

// The file's chunks: models, palette, scene nodes and layers.
struct VoxChunks {
  uint32_t version = 0;
  std::vector<VoxModel> models;
  std::array<Rgba, 256> palette = magicavoxel_default_palette();
  bool has_palette = false;
  std::map<int32_t, SceneNode> nodes;
  std::map<int32_t, bool> hidden_layers;
};

VoxChunks read_vox_chunks(const std::string& path, const std::vector<std::byte>& data, uint64_t cap) {
  ByteCursor c(path, data, 0, data.size());
  if (c.left() < 8 || c.text(4, "header") != "VOX ") throw InputError(path, "not a MagicaVoxel file (no 'VOX ' magic)");
  VoxChunks out;
  out.version = c.u32("header");
  if (c.text(4, "MAIN chunk") != "MAIN") throw InputError(path, "no MAIN chunk after the header");
  const uint32_t main_content = c.u32("MAIN chunk"), main_children = c.u32("MAIN chunk");
  c.skip(main_content, "MAIN chunk");
  if (main_children > c.left()) throw InputError(path, "truncated: MAIN declares " + std::to_string(main_children) +
                                                           " bytes of chunks, " + std::to_string(c.left()) + " remain");
  const size_t end = c.pos() + main_children;
  auto& models = out.models;
  auto& palette = out.palette;
  auto& has_palette = out.has_palette;
  auto& nodes = out.nodes;
  auto& hidden_layers = out.hidden_layers;
  uint64_t voxel_total = 0;
  while (c.pos() < end) {
    ByteCursor head(path, data, c.pos(), end);
    const std::string id = head.text(4, "chunk header");
    const uint32_t content = head.u32("chunk header"), children = head.u32("chunk header");
    if (content > head.left() || children > head.left() - content)
      throw InputError(path, "truncated chunk '" + id + "' (declares " + std::to_string(content + uint64_t(children)) +
                                 " bytes, " + std::to_string(head.left()) + " remain)");
    ByteCursor body(path, data, head.pos(), head.pos() + content);
    c.seek(head.pos() + content + children, "chunk");
    {
      if (id == "SIZE") {
        VoxModel m;
        for (auto& s : m.size) {
          s = body.i32("SIZE chunk");
          if (s < 1 || s > 2048) throw InputError(path, "model size " + std::to_string(s) + " is out of range (1..2048)");
        }
        models.push_back(std::move(m));
      } else if (id == "XYZI") {
        if (models.empty() || !models.back().voxels.empty()) throw InputError(path, "XYZI chunk without its SIZE chunk");
        VoxModel& m = models.back();
        const uint32_t n = body.u32("XYZI chunk");
        if (uint64_t(n) * 4 > body.left())
          throw InputError(path, "truncated XYZI chunk (" + std::to_string(n) + " voxels declared)");
        voxel_total += n;
        check_limit(path, voxel_total * 4, cap, "the voxel lists");
        m.voxels.resize(n);
        for (auto& v : m.voxels) {
          for (auto& b : v) b = body.u8("XYZI chunk");
          for (size_t a = 0; a < 3; ++a)
            if (v[a] >= m.size[a])
              throw InputError(path, "voxel (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " +
                                         std::to_string(v[2]) + ") lies outside its model of size " + std::to_string(m.size[0]) +
                                         "x" + std::to_string(m.size[1]) + "x" + std::to_string(m.size[2]));
        }
      } else if (id == "RGBA") {
        for (size_t i = 0; i < 256; ++i) {
          Rgba col;
          for (auto& b : col) b = body.u8("RGBA chunk");
          if (i < 255) palette[i + 1] = col;
        }
        has_palette = true;
      } else if (id == "nTRN" || id == "nGRP" || id == "nSHP") {
        const int32_t nid = body.i32("scene node");
        SceneNode node;
        node.attributes = read_dict(path, body);
        if (id == "nTRN") {
          node.kind = SceneNode::transform;
          node.children.push_back(body.i32("nTRN chunk"));
          body.i32("nTRN chunk");  // reserved
          node.layer = body.i32("nTRN chunk");
          const uint32_t frames = body.u32("nTRN chunk");
          for (uint32_t f = 0; f < frames; ++f) {
            Dict d = read_dict(path, body);
            if (f == 0) node.frame = std::move(d);  // the first key frame places the node
          }
        } else if (id == "nGRP") {
          node.kind = SceneNode::group;
          const uint32_t n = body.u32("nGRP chunk");
          if (uint64_t(n) * 4 > body.left()) throw InputError(path, "truncated nGRP chunk");
          for (uint32_t i = 0; i < n; ++i) node.children.push_back(body.i32("nGRP chunk"));
        } else {
          node.kind = SceneNode::shape;
          const uint32_t n = body.u32("nSHP chunk");
          for (uint32_t i = 0; i < n; ++i) {
            const int32_t model = body.i32("nSHP chunk");
            read_dict(path, body);
            if (i == 0) node.children.push_back(model);
          }
        }
        if (!nodes.emplace(nid, std::move(node)).second) throw InputError(path, "scene node " + std::to_string(nid) + " is defined twice");
      } else if (id == "LAYR") {
        const int32_t lid = body.i32("LAYR chunk");
        const Dict d = read_dict(path, body);
        auto it = d.find("_hidden");
        hidden_layers[lid] = it != d.end() && it->second == "1";
      }
    }
  }
  if (models.empty()) throw InputError(path, "no model (SIZE / XYZI chunks) in the file");
  return out;
}

struct Instance {
  size_t model;
  Placement place;
};

// The shape instances of the scene graph from node 0 (hidden nodes and
// layers left out), each placed by `centred`.
template <class Centred>
std::vector<Instance> scene_instances(const std::string& path, const VoxChunks& f, Centred&& centred) {
  const auto& nodes = f.nodes;
  const auto& hidden_layers = f.hidden_layers;
  const auto& models = f.models;
  std::vector<Instance> instances;
  // Walk the scene graph from node 0 with an explicit stack; a path longer
  // than the number of nodes means a cycle.
  struct Item {
    int32_t node;
    Placement place;
    size_t depth;
  };
  std::vector<Item> stack{{0, Placement{}, 0}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    if (it.depth > nodes.size()) throw InputError(path, "the scene graph has a cycle");
    auto found = nodes.find(it.node);
    if (found == nodes.end()) throw InputError(path, "scene node " + std::to_string(it.node) + " is referenced but missing");
    const SceneNode& n = found->second;
    if (n.kind == SceneNode::transform) {
      auto h = n.attributes.find("_hidden");
      if (h != n.attributes.end() && h->second == "1") continue;
      if (auto l = hidden_layers.find(n.layer); l != hidden_layers.end() && l->second) continue;
      stack.push_back({n.children[0], parse_frame(path, n.frame).then(it.place), it.depth + 1});
    } else if (n.kind == SceneNode::group) {
      for (auto ch = n.children.rbegin(); ch != n.children.rend(); ++ch) stack.push_back({*ch, it.place, it.depth + 1});
    } else {
      for (int32_t m : n.children) {
        if (m < 0 || size_t(m) >= models.size())
          throw InputError(path, "shape node " + std::to_string(it.node) + " uses model " + std::to_string(m) +
                                     " but the file has " + std::to_string(models.size()));
        instances.push_back({size_t(m), centred(size_t(m), it.place)});
      }
    }
  }
  return instances;
}

}  // namespace

VoxelArt read_vox(const std::string& path, const VoxelArtReadOptions& options) {
  const uint64_t cap = options.max_bytes ? options.max_bytes : default_memory_limit();
  const auto data = read_whole_file(path, cap, "reading the .vox file");
  const VoxChunks f = read_vox_chunks(path, data, cap);
  const auto& models = f.models;
  const auto& nodes = f.nodes;

  // Which models go where.
  std::vector<Instance> instances;
  VoxelArt art;
  art.source = path;
  art.format = "vox";
  art.notes.push_back("version " + std::to_string(f.version) + ", " + std::to_string(models.size()) + " model(s), " +
                      (f.has_palette ? "RGBA palette" : "default palette"));
  auto centred = [&](size_t m, const Placement& p) {
    Placement q;  // v -> p(v - floor(s / 2))
    for (size_t a = 0; a < 3; ++a) q.t[a] = -(models[m].size[a] / 2);
    return q.then(p);
  };
  if (options.model >= 0 && size_t(options.model) >= models.size())
    throw UsageError(path + ": --model " + std::to_string(options.model) + " but the file has " +
                     std::to_string(models.size()) + " model(s)");
  // Each model as one instance, untransformed (its painted voxels' box), and
  // as the scene graph's shapes place it (centred()).
  std::vector<Reach> model_reach(models.size()), centred_reach(models.size());
  for (size_t m = 0; m < models.size(); ++m) {
    Reach& r = model_reach[m];
    r.instances = 1;
    for (const auto& v : models[m].voxels) {
      if (v[3] == 0) continue;
      const std::array<int64_t, 3> w{v[0], v[1], v[2]};
      r.add(Reach{0, true, w, w});
    }
    centred_reach[m] = r.placed(centred(m, Placement{}));
  }
  const Reach reach = options.model >= 0 ? model_reach[size_t(options.model)]
                      : nodes.count(0)   ? scene_reach(path, nodes, f.hidden_layers, centred_reach, 0)
                                         : model_reach[0];
  check_scene(path, reach, cap);
  if (options.model >= 0) {
    instances.push_back({size_t(options.model), Placement{}});
    art.notes.push_back("model " + std::to_string(options.model) + " only, untransformed");
  } else if (nodes.count(0)) {
    instances = scene_instances(path, f, centred);
    art.notes.push_back(std::to_string(instances.size()) + " shape instance(s) from the scene graph");
  } else {
    instances.push_back({0, Placement{}});
    if (models.size() > 1)
      art.notes.push_back("no scene graph: model 0 of " + std::to_string(models.size()) +
                          " (animation frames; --model K picks another)");
  }

  // One grid spanning every instance (its box and size checked above).
  const std::array<int64_t, 3>& lo = reach.lo;
  ColorGrid g;
  for (size_t a = 0; a < 3; ++a) g.dims[a] = reach.hi[a] - lo[a] + 1;
  g.voxels.assign(uint64_t(g.dims[0]) * uint64_t(g.dims[1]) * uint64_t(g.dims[2]), Rgba{0, 0, 0, 0});
  g.offset = Vec3(double(lo[0]), double(lo[1]), double(lo[2]));
  g.name = std::filesystem::path(path).stem().string();
  for (const Instance& in : instances)
    for (const auto& v : models[in.model].voxels) {
      if (v[3] == 0) continue;  // index 0 is "empty" in MagicaVoxel
      const auto w = in.place.apply({v[0], v[1], v[2]});
      Rgba col = f.palette[v[3]];
      col[3] = 255;
      g.voxels[g.index(w[0] - lo[0], w[1] - lo[1], w[2] - lo[2])] = col;
    }
  art.parts.push_back(std::move(g));
  return art;
}

}  // namespace detail
}  // namespace voxpress
