// PLY reader and writer.
//
// Reader: ASCII, binary_little_endian and binary_big_endian; any number of
// elements and properties. "vertex" x/y/z become positions, nx/ny/nz normals,
// red/green/blue[/alpha] colours, anything else a vertex attribute; a "face"
// list named vertex_indices (or vertex_index) gives polygons, fanned into
// triangles, and its scalar properties become face attributes (copied to
// each triangle of a polygon); "edge" vertex1/vertex2 become labelled edges.
// Other elements (materials, ...) are skipped.
// Counts are checked against the bytes present before anything is allocated.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

enum class PType { i8, u8, i16, u16, i32, u32, f32, f64 };

bool parse_ptype(const std::string& s, PType& t) {
  static const std::pair<const char*, PType> names[] = {
      {"char", PType::i8},   {"int8", PType::i8},     {"uchar", PType::u8},   {"uint8", PType::u8},
      {"short", PType::i16}, {"int16", PType::i16},   {"ushort", PType::u16}, {"uint16", PType::u16},
      {"int", PType::i32},   {"int32", PType::i32},   {"uint", PType::u32},   {"uint32", PType::u32},
      {"float", PType::f32}, {"float32", PType::f32}, {"double", PType::f64}, {"float64", PType::f64}};
  for (const auto& [n, v] : names)
    if (s == n) {
      t = v;
      return true;
    }
  return false;
}

size_t psize(PType t) {
  switch (t) {
    case PType::i8:
    case PType::u8: return 1;
    case PType::i16:
    case PType::u16: return 2;
    case PType::i32:
    case PType::u32:
    case PType::f32: return 4;
    default: return 8;
  }
}

ScalarType to_scalar(PType t) {
  switch (t) {
    case PType::i8: return ScalarType::i8;
    case PType::u8: return ScalarType::u8;
    case PType::i16: return ScalarType::i16;
    case PType::u16: return ScalarType::u16;
    case PType::i32: return ScalarType::i32;
    case PType::u32: return ScalarType::u32;
    case PType::f32: return ScalarType::f32;
    default: return ScalarType::f64;
  }
}

const char* ply_name(ScalarType t) {
  switch (t) {
    case ScalarType::i8: return "char";
    case ScalarType::u8: return "uchar";
    case ScalarType::i16: return "short";
    case ScalarType::u16: return "ushort";
    case ScalarType::i32: return "int";
    case ScalarType::u32: return "uint";
    case ScalarType::f32: return "float";
    default: return "double";
  }
}

struct Property {
  std::string name;
  PType type = PType::f32;
  bool list = false;
  PType count_type = PType::u8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

class Cursor {
 public:
  Cursor(const std::string& path, const char* p, const char* end, int mode)
      : path_(path), p_(p), end_(end), mode_(mode) {}
  // mode 0: ascii, 1: little endian, 2: big endian
  double read(PType t) {
    if (mode_ == 0) return ascii();
    const size_t n = psize(t);
    if (size_t(end_ - p_) < n) truncated();
    unsigned char b[8];
    std::memcpy(b, p_, n);
    p_ += n;
    if ((mode_ == 2) == (std::endian::native == std::endian::little)) std::reverse(b, b + n);
    switch (t) {
      case PType::i8: return double(int8_t(b[0]));
      case PType::u8: return double(b[0]);
      case PType::i16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PType::u16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PType::i32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PType::u32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PType::f32: { float v; std::memcpy(&v, b, 4); return v; }
      default: { double v; std::memcpy(&v, b, 8); return v; }
    }
  }
  /// A list's length: a whole number in [0, limit] (NaN and negatives refused).
  uint64_t length(PType t, double limit, const std::string& what) {
    const double n = read(t);
    if (!whole_in(n, 0, limit)) throw InputError(path_, what);
    return uint64_t(n);
  }
  uint64_t remaining() const { return uint64_t(end_ - p_); }
  [[noreturn]] void truncated() const { throw InputError(path_, "truncated: the data ends before every element was read"); }

 private:
  double ascii() {
    while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    if (p_ >= end_) truncated();
    const char* s = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    double v = 0;
    const char* b = s;
    if (*b == '+') ++b;
    auto [ptr, ec] = std::from_chars(b, p_, v);
    if (ec != std::errc() || ptr != p_) throw InputError(path_, "malformed number '" + std::string(s, p_) + "' in PLY data");
    return v;
  }
  const std::string& path_;
  const char* p_;
  const char* end_;
  int mode_;
};

// The header's format (0 ascii, 1 binary little-endian, 2 big-endian) and
// elements, from the text before end_header.
int parse_ply_header(const std::string& path, const std::string& text, std::vector<Element>& elements) {
  std::istringstream hs(text);
  std::string line;
  int mode = -1;
  std::getline(hs, line);  // "ply"
  while (std::getline(hs, line)) {
    const auto tok = split_ws(line);
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() < 2) throw InputError(path, "malformed PLY format line");
      if (tok[1] == "ascii")
        mode = 0;
      else if (tok[1] == "binary_little_endian")
        mode = 1;
      else if (tok[1] == "binary_big_endian")
        mode = 2;
      else
        throw InputError(path, "unknown PLY format '" + tok[1] + "'");
    } else if (tok[0] == "element") {
      if (tok.size() != 3) throw InputError(path, "malformed PLY element line '" + line + "'");
      Element e;
      e.name = tok[1];
      const int64_t c = parse_int(path, tok[2], "element count");
      if (c < 0) throw InputError(path, "negative PLY element count");
      e.count = uint64_t(c);
      elements.push_back(e);
    } else if (tok[0] == "property") {
      if (elements.empty()) throw InputError(path, "PLY property before any element");
      Property p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.list = true;
        if (!parse_ptype(tok[2], p.count_type) || !parse_ptype(tok[3], p.type))
          throw InputError(path, "unknown PLY type in '" + line + "'");
        p.name = tok[4];
      } else if (tok.size() == 3) {
        if (!parse_ptype(tok[1], p.type)) throw InputError(path, "unknown PLY type '" + tok[1] + "'");
        p.name = tok[2];
      } else {
        throw InputError(path, "malformed PLY property line '" + line + "'");
      }
      elements.back().props.push_back(p);
    } else {
      throw InputError(path, "unexpected PLY header line '" + line + "'");
    }
  }
  if (mode < 0) throw InputError(path, "PLY header has no format line");
  return mode;
}

// One record of element e: its scalar properties into rec (lists read past).
void read_record(const Element& e, Cursor& cur, std::vector<double>& rec) {
  for (size_t k = 0; k < e.props.size(); ++k) {
    const Property& p = e.props[k];
    if (p.list) {
      const uint64_t n = cur.length(p.count_type, 1e9, "invalid list length in element '" + e.name + "'");
      for (uint64_t q = 0; q < n; ++q) cur.read(p.type);
    } else {
      rec[k] = cur.read(p.type);
    }
  }
}

// The vertex element: positions, and normals, colours and other scalar
// properties when present.
void read_ply_vertices(const std::string& path, const Element& e, Cursor& cur, uint64_t max_bytes, Mesh& m) {
  check_limit(path, e.count * 48, max_bytes, "the vertices");
  int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ir = -1, ig = -1, ib = -1, ia = -1;
  std::vector<int> other;
  for (int k = 0; k < int(e.props.size()); ++k) {
    const Property& p = e.props[size_t(k)];
    if (p.list) continue;
    const std::string& n = p.name;
    int* slot = n == "x" ? &ix : n == "y" ? &iy : n == "z" ? &iz : n == "nx" ? &inx : n == "ny" ? &iny
              : n == "nz" ? &inz : (n == "red" || n == "r") ? &ir : (n == "green" || n == "g") ? &ig
              : (n == "blue" || n == "b") ? &ib : (n == "alpha" || n == "a") ? &ia : nullptr;
    if (slot && *slot < 0)
      *slot = k;
    else
      other.push_back(k);
  }
  if (ix < 0 || iy < 0 || iz < 0) throw InputError(path, "PLY vertices lack x, y or z");
  const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
  const bool colors = ir >= 0 && ig >= 0 && ib >= 0;
  m.positions.resize(e.count);
  if (normals) m.normals.resize(e.count);
  if (colors) m.colors.resize(e.count);
  for (int k : other) m.vertex_attributes.push_back({e.props[size_t(k)].name, to_scalar(e.props[size_t(k)].type), {}});
  std::vector<double> rec(e.props.size());
  for (uint64_t v = 0; v < e.count; ++v) {
    read_record(e, cur, rec);
    m.positions[v] = Vec3(rec[size_t(ix)], rec[size_t(iy)], rec[size_t(iz)]);
    if (normals) m.normals[v] = Vec3(rec[size_t(inx)], rec[size_t(iny)], rec[size_t(inz)]);
    if (colors) {
      auto c = [&](int k) {
        const bool fl = e.props[size_t(k)].type == PType::f32 || e.props[size_t(k)].type == PType::f64;
        const double x = fl ? rec[size_t(k)] * 255.0 : rec[size_t(k)];
        return uint8_t(std::clamp(std::lround(x), 0L, 255L));
      };
      m.colors[v] = {c(ir), c(ig), c(ib), ia >= 0 ? c(ia) : uint8_t(255)};
    }
    for (size_t a = 0; a < other.size(); ++a) m.vertex_attributes[a].values.push_back(rec[size_t(other[a])]);
  }
}

// The face element: triangles (polygons as fans) and scalar face properties.
void read_ply_faces(const std::string& path, const Element& e, Cursor& cur, uint64_t max_bytes, Mesh& m) {
  check_limit(path, e.count * 12, max_bytes, "the faces");
  int idx = -1;
  std::vector<int> other;
  for (int k = 0; k < int(e.props.size()); ++k) {
    const Property& p = e.props[size_t(k)];
    if (p.list && idx < 0 && (p.name == "vertex_indices" || p.name == "vertex_index"))
      idx = k;
    else if (!p.list)
      other.push_back(k);
  }
  if (idx < 0) throw InputError(path, "PLY faces lack a vertex_indices list");
  for (int k : other) m.face_attributes.push_back({e.props[size_t(k)].name, to_scalar(e.props[size_t(k)].type), {}});
  m.triangles.reserve(e.count);
  std::vector<double> rec(e.props.size());
  std::vector<uint32_t> poly;
  for (uint64_t f = 0; f < e.count; ++f) {
    poly.clear();
    for (size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (p.list) {
        const uint64_t n = cur.length(p.count_type, 1e6, "face " + std::to_string(f) + " has an invalid vertex count");
        for (uint64_t q = 0; q < n; ++q) {
          const double x = cur.read(p.type);
          if (int(k) == idx) {
            if (!whole_in(x, 0, 4294967294.0))
              throw InputError(path, "face " + std::to_string(f) + " has an invalid vertex index");
            poly.push_back(uint32_t(x));
          }
        }
      } else {
        rec[k] = cur.read(p.type);
      }
    }
    if (poly.size() < 3) throw InputError(path, "face " + std::to_string(f) + " has fewer than 3 vertices");
    for (size_t q = 1; q + 1 < poly.size(); ++q) {
      m.triangles.push_back({poly[0], poly[q], poly[q + 1]});
      for (size_t a = 0; a < other.size(); ++a) m.face_attributes[a].values.push_back(rec[size_t(other[a])]);
    }
  }
}

// Labelled edges (vertex1, vertex2; other properties skipped).
void read_ply_edges(const std::string& path, const Element& e, Cursor& cur, uint64_t max_bytes, Mesh& m) {
  int i1 = -1, i2 = -1;
  for (int k = 0; k < int(e.props.size()); ++k) {
    if (e.props[size_t(k)].list) continue;
    if (e.props[size_t(k)].name == "vertex1") i1 = k;
    if (e.props[size_t(k)].name == "vertex2") i2 = k;
  }
  check_limit(path, e.count * 8, max_bytes, "the edges");
  std::vector<double> rec(e.props.size());
  for (uint64_t r = 0; r < e.count; ++r) {
    read_record(e, cur, rec);
    if (i1 < 0 || i2 < 0) continue;
    const double a = rec[size_t(i1)], b = rec[size_t(i2)];
    if (!whole_in(a, 0, 4294967294.0) || !whole_in(b, 0, 4294967294.0))
      throw InputError(path, "edge " + std::to_string(r) + " has an invalid vertex index");
    m.edges.push_back({uint32_t(a), uint32_t(b)});
  }
}

// Any other element, read past.
void skip_ply_element(const Element& e, Cursor& cur) {
  std::vector<double> rec(e.props.size());
  for (uint64_t r = 0; r < e.count; ++r) read_record(e, cur, rec);
}

}  // namespace

Mesh read_ply(const std::string& path, uint64_t max_bytes) {
  const auto buf = read_whole_file(path, max_bytes, "the file");
  const char* data = reinterpret_cast<const char*>(buf.data());
  const std::string head(data, std::min<size_t>(buf.size(), 1 << 20));
  if (head.rfind("ply", 0) != 0 || head.size() < 4 || (head[3] != '\n' && head[3] != '\r'))
    throw InputError(path, "not a PLY file (missing the 'ply' magic line)");
  size_t end_header = head.find("end_header");
  if (end_header == std::string::npos) throw InputError(path, "PLY header has no end_header line");
  size_t body = head.find('\n', end_header);
  if (body == std::string::npos) throw InputError(path, "truncated PLY header");
  ++body;
  std::vector<Element> elements;
  const int mode = parse_ply_header(path, head.substr(0, end_header), elements);

  Mesh m;
  Cursor cur(path, data + body, data + buf.size(), mode);
  bool have_vertices = false, have_faces = false;
  for (const Element& e : elements) {
    // Each record needs at least one byte per property (binary) or two (ascii).
    uint64_t min_record = 0;
    for (const Property& p : e.props) min_record += mode == 0 ? 2 : (p.list ? psize(p.count_type) : psize(p.type));
    if (min_record && e.count > cur.remaining() / min_record + 1) cur.truncated();
    // An element without properties holds no data: its count, however large,
    // must not become a loop (found by bench/fuzz: 6.6e8 empty records took
    // 0.6 s, 2^63 would never end). vertex and face report what they lack.
    if (e.props.empty() && e.name != "vertex" && e.name != "face") continue;
    if (e.name == "vertex" && !have_vertices) {
      have_vertices = true;
      read_ply_vertices(path, e, cur, max_bytes, m);
    } else if (e.name == "face" && !have_faces) {
      have_faces = true;
      read_ply_faces(path, e, cur, max_bytes, m);
    } else if (e.name == "edge" && m.edges.empty()) {
      read_ply_edges(path, e, cur, max_bytes, m);
    } else {
      skip_ply_element(e, cur);
    }
  }
  if (!have_vertices) throw InputError(path, "PLY file has no vertex element");
  m.validate(path);
  return m;
}

void write_ply(const std::string& path, const Mesh& m, bool binary, Space space) {
  m.validate(path);
  if (!m.uvs.empty()) return write_ply(path, welded_solid(m), binary, space);  // no texture: the closed solid
  std::ostringstream h;
  h << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\ncomment written by voxpress\n";
  if (space != Space::unknown) h << "comment SPACE=" << space_name(space) << "\n";  // read by 3D Slicer
  h << "element vertex " << m.positions.size() << "\nproperty double x\nproperty double y\nproperty double z\n";
  if (!m.normals.empty()) h << "property float nx\nproperty float ny\nproperty float nz\n";
  if (!m.colors.empty()) h << "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  for (const auto& a : m.vertex_attributes) h << "property " << ply_name(a.type) << " " << a.name << "\n";
  h << "element face " << m.triangles.size() << "\nproperty list uchar int vertex_indices\n";
  for (const auto& a : m.face_attributes) h << "property " << ply_name(a.type) << " " << a.name << "\n";
  if (!m.edges.empty()) h << "element edge " << m.edges.size() << "\nproperty int vertex1\nproperty int vertex2\n";
  h << "end_header\n";
  const std::string header = h.str();
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(header.data(), std::streamsize(header.size()));
    std::string buf;
    auto put = [&](const void* p, size_t n) { buf.append(static_cast<const char*>(p), n); };
    auto put_typed = [&](ScalarType t, double x) {
      if (!binary) {
        if (!buf.empty() && buf.back() != '\n') buf.push_back(' ');
        buf += format_typed(t, x);
        return;
      }
      switch (t) {
        case ScalarType::i8: { int8_t v = int8_t(x); put(&v, 1); break; }
        case ScalarType::u8: { uint8_t v = uint8_t(x); put(&v, 1); break; }
        case ScalarType::i16: { int16_t v = int16_t(x); put(&v, 2); break; }
        case ScalarType::u16: { uint16_t v = uint16_t(x); put(&v, 2); break; }
        case ScalarType::i32: { int32_t v = int32_t(x); put(&v, 4); break; }
        case ScalarType::u32: { uint32_t v = uint32_t(x); put(&v, 4); break; }
        case ScalarType::f32: { float v = float(x); put(&v, 4); break; }
        default: put(&x, 8); break;
      }
    };
    auto flush = [&] {
      out.write(buf.data(), std::streamsize(buf.size()));
      buf.clear();
    };
    for (size_t v = 0; v < m.positions.size(); ++v) {
      for (int a = 0; a < 3; ++a) put_typed(ScalarType::f64, m.positions[v][a]);
      if (!m.normals.empty())
        for (int a = 0; a < 3; ++a) put_typed(ScalarType::f32, m.normals[v][a]);
      if (!m.colors.empty())
        for (int c = 0; c < 4; ++c) put_typed(ScalarType::u8, m.colors[v][size_t(c)]);
      for (const auto& a : m.vertex_attributes) put_typed(a.type, a.values[v]);
      if (!binary) buf.push_back('\n');
      if (buf.size() > (1 << 20)) flush();
    }
    for (size_t f = 0; f < m.triangles.size(); ++f) {
      put_typed(ScalarType::u8, 3);
      for (uint32_t i : m.triangles[f]) put_typed(ScalarType::i32, double(i));
      for (const auto& a : m.face_attributes) put_typed(a.type, a.values[f]);
      if (!binary) buf.push_back('\n');
      if (buf.size() > (1 << 20)) flush();
    }
    for (const auto& e : m.edges) {
      put_typed(ScalarType::i32, double(e[0]));
      put_typed(ScalarType::i32, double(e[1]));
      if (!binary) buf.push_back('\n');
      if (buf.size() > (1 << 20)) flush();
    }
    flush();
  });
}

}  // namespace voxpress::detail
