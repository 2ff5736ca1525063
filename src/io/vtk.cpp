// VTK polygon data: the legacy format (.vtk) and the XML format (.vtp), for
// 3D Slicer and ParaView users (https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html).
//
// Writers: legacy version 4.2 (what Slicer writes, read by every VTK since
// 2000), BINARY (big-endian) or ASCII; XML PolyData version 1.0 with a UInt64
// header, raw appended data, uncompressed. Positions as Float64, triangles as
// POLYGONS / Polys, normals, RGBA colours and every vertex attribute as point
// data, every face attribute as cell data (the first one active, so a viewer
// colours by it: a label map's label_in). The coordinate system is recorded
// the way Slicer reads it: "SPACE=LPS" in the legacy title line, a SPACE
// string array in the XML file's field data. Sharp edges (Mesh::edges) are not
// stored: VTK's cell data would then have to cover lines and polygons alike.
// Readers: legacy 2.0–5.1 POLYDATA, ASCII or BINARY (4.x cell lists and 5.x
// OFFSETS / CONNECTIVITY); XML PolyData of any byte order and header type,
// DataArrays inline (ascii, base64) or appended (raw, base64), uncompressed or
// zlib-compressed, several pieces. Polygons and triangle strips become
// triangles (cell data copied to each); one-component point and cell arrays
// become attributes, "Normals"/NORMALS normals, a four-component uint8 point
// array (or COLOR_SCALARS) colours; vertices, lines, vectors, tensors,
// texture coordinates and other field data are read past and dropped.
// Counts are checked against the bytes present before anything is allocated.
#include <pugixml.hpp>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <sstream>

#include "formats.h"
#include "io_util.h"
#include "vtk_data.h"

namespace voxpress::detail {

namespace {
struct VtkType {
  const char* legacy;
  const char* xml;
  ScalarType type;
};
constexpr VtkType kTypes[] = {
    {"unsigned_char", "UInt8", ScalarType::u8},      {"char", "Int8", ScalarType::i8},
    {"unsigned_short", "UInt16", ScalarType::u16},   {"short", "Int16", ScalarType::i16},
    {"unsigned_int", "UInt32", ScalarType::u32},     {"int", "Int32", ScalarType::i32},
    {"vtktypeuint64", "UInt64", ScalarType::u64},    {"vtktypeint64", "Int64", ScalarType::i64},
    {"float", "Float32", ScalarType::f32},           {"double", "Float64", ScalarType::f64},
    {"unsigned_long", nullptr, ScalarType::u64},     {"long", nullptr, ScalarType::i64},
    {"vtkIdType", nullptr, ScalarType::i64},         {"signed_char", nullptr, ScalarType::i8},
    {"unsigned_long_long", nullptr, ScalarType::u64}, {"long_long", nullptr, ScalarType::i64},
    {nullptr, "Int", ScalarType::i32},               {nullptr, "Float", ScalarType::f32}};
}  // namespace

ScalarType vtk_type(const std::string& path, const std::string& name, bool xml) {
  for (const VtkType& t : kTypes)
    if (const char* n = xml ? t.xml : t.legacy; n && name == n) return t.type;
  throw InputError(path, "unsupported VTK data type '" + name + "'");
}
const char* vtk_type_name(ScalarType t, bool xml) {
  for (const VtkType& k : kTypes)
    if (k.type == t && (xml ? k.xml : k.legacy)) return xml ? k.xml : k.legacy;
  return xml ? "Float64" : "double";
}

// `count` values of type t from raw bytes (swapped from the other byte order).
std::vector<double> vtk_decode(const std::byte* p, uint64_t count, ScalarType t, bool swap) {
  const size_t w = scalar_size(t);
  std::vector<double> out(count);
  std::byte tmp[8];
  for (uint64_t i = 0; i < count; ++i) {
    std::memcpy(tmp, p + i * w, w);
    if (swap) std::reverse(tmp, tmp + w);
    switch (t) {
      case ScalarType::u8: out[i] = double(uint8_t(tmp[0])); break;
      case ScalarType::i8: out[i] = double(int8_t(tmp[0])); break;
#define VOXPRESS_VTK_CASE(E, T) \
  case ScalarType::E: {         \
    T v;                        \
    std::memcpy(&v, tmp, w);    \
    out[i] = double(v);         \
    break;                      \
  }
      VOXPRESS_VTK_CASE(u16, uint16_t) VOXPRESS_VTK_CASE(i16, int16_t) VOXPRESS_VTK_CASE(u32, uint32_t)
      VOXPRESS_VTK_CASE(i32, int32_t) VOXPRESS_VTK_CASE(u64, uint64_t) VOXPRESS_VTK_CASE(i64, int64_t)
      VOXPRESS_VTK_CASE(f32, float) VOXPRESS_VTK_CASE(f64, double)
#undef VOXPRESS_VTK_CASE
    }
  }
  return out;
}

// Appends x as type t to buf (big-endian when `big`).
void vtk_put(std::string& buf, ScalarType t, double x, bool big) {
  std::byte b[8];
  switch (t) {
    case ScalarType::u8: b[0] = std::byte(uint8_t(x)); break;
    case ScalarType::i8: b[0] = std::byte(uint8_t(int8_t(x))); break;
#define VOXPRESS_VTK_PUT(E, T) \
  case ScalarType::E: {        \
    const T v = T(x);          \
    std::memcpy(b, &v, sizeof v); \
    break;                     \
  }
      VOXPRESS_VTK_PUT(u16, uint16_t) VOXPRESS_VTK_PUT(i16, int16_t) VOXPRESS_VTK_PUT(u32, uint32_t)
      VOXPRESS_VTK_PUT(i32, int32_t) VOXPRESS_VTK_PUT(u64, uint64_t) VOXPRESS_VTK_PUT(i64, int64_t)
      VOXPRESS_VTK_PUT(f32, float) VOXPRESS_VTK_PUT(f64, double)
#undef VOXPRESS_VTK_PUT
  }
  const size_t w = scalar_size(t);
  if (big) std::reverse(b, b + w);
  buf.append(reinterpret_cast<const char*>(b), w);
}

// Cells from a legacy 4.x list ([k, ids...] per cell) or 5.x / XML offsets + connectivity.
VtkCells vtk_cells_from_list(const std::string& path, const std::vector<double>& list, uint64_t count) {
  VtkCells c;
  size_t i = 0;
  for (uint64_t k = 0; k < count; ++k) {
    if (i >= list.size() || !whole_in(list[i], 0, double(list.size() - i - 1)))
      throw InputError(path, "cell " + std::to_string(k) + " has a bad size or runs past its list");
    const size_t n = size_t(list[i++]);
    for (size_t j = 0; j < n; ++j, ++i) {
      if (!whole_in(list[i], 0, 4294967295.0)) throw InputError(path, "cell " + std::to_string(k) + " holds a bad index");
      c.ids.push_back(int64_t(list[i]));
    }
    c.offsets.push_back(int64_t(c.ids.size()));
  }
  if (i != list.size()) throw InputError(path, "a cell list holds more values than its cells use");
  return c;
}
VtkCells vtk_cells_from_offsets(const std::string& path, const std::vector<double>& offsets, const std::vector<double>& ids,
                         bool leading_zero) {
  VtkCells c;
  c.ids.reserve(ids.size());
  for (double v : ids) {
    if (!whole_in(v, 0, 4294967295.0)) throw InputError(path, "cell connectivity holds a bad index");
    c.ids.push_back(int64_t(v));
  }
  int64_t last = 0;
  for (size_t k = leading_zero ? 1 : 0; k < offsets.size(); ++k) {
    if (!whole_in(offsets[k], double(last), double(ids.size())))
      throw InputError(path, "cell offsets are not increasing within the connectivity");
    c.offsets.push_back(last = int64_t(offsets[k]));
  }
  if (last != int64_t(ids.size())) throw InputError(path, "cell offsets do not end at the connectivity's length");
  return c;
}

Mesh vtk_to_mesh(const std::string& path, VtkData& g) {
  Mesh m;
  const size_t n = g.points.size() / 3;
  m.positions.resize(n);
  for (size_t v = 0; v < n; ++v) m.positions[v] = Vec3(g.points[3 * v], g.points[3 * v + 1], g.points[3 * v + 2]);
  // Polygons fanned, strips unrolled; `source` = the cell id of each triangle.
  std::vector<size_t> source;
  const size_t first_poly = g.verts.count() + g.lines.count();
  auto id = [&](int64_t i) {
    if (i < 0 || uint64_t(i) >= n) throw InputError(path, "a cell uses vertex " + std::to_string(i) + " of " + std::to_string(n));
    return uint32_t(i);
  };
  for (size_t c = 0; c < g.polys.count(); ++c)
    for (int64_t k = g.polys.offsets[c] + 2; k < g.polys.offsets[c + 1]; ++k) {
      m.triangles.push_back({id(g.polys.ids[size_t(g.polys.offsets[c])]), id(g.polys.ids[size_t(k - 1)]), id(g.polys.ids[size_t(k)])});
      source.push_back(first_poly + c);
    }
  for (size_t c = 0; c < g.strips.count(); ++c)
    for (int64_t k = g.strips.offsets[c] + 2; k < g.strips.offsets[c + 1]; ++k) {
      const uint32_t a = id(g.strips.ids[size_t(k - 2)]), b = id(g.strips.ids[size_t(k - 1)]), d = id(g.strips.ids[size_t(k)]);
      const bool odd = (k - g.strips.offsets[c]) % 2 == 1;
      m.triangles.push_back(odd ? Triangle{b, a, d} : Triangle{a, b, d});
      source.push_back(first_poly + g.polys.count() + c);
    }
  if (m.triangles.empty()) throw InputError(path, "the VTK file holds no polygons");
  for (VtkArray& a : g.point) {
    if (a.normals && a.comps == 3) {
      m.normals.resize(n);
      for (size_t v = 0; v < n; ++v) m.normals[v] = Vec3(a.values[3 * v], a.values[3 * v + 1], a.values[3 * v + 2]);
    } else if (a.colors && a.comps == 4) {
      m.colors.resize(n);
      const double scale = a.type == ScalarType::u8 ? 1.0 : 255.0;  // COLOR_SCALARS in ASCII are in [0, 1]
      for (size_t v = 0; v < n; ++v)
        for (int c = 0; c < 4; ++c) {
          const double x = std::round(a.values[4 * v + size_t(c)] * scale);
          m.colors[v][size_t(c)] = std::isfinite(x) ? uint8_t(std::clamp(x, 0.0, 255.0)) : 0;  // no NaN to integer
        }
    } else if (a.comps == 1) {
      m.vertex_attributes.push_back({a.name, a.type, std::move(a.values)});
    }
  }
  for (VtkArray& a : g.cell) {
    if (a.comps != 1) continue;
    MeshAttribute f{a.name, a.type, {}};
    f.values.reserve(source.size());
    for (size_t s : source) f.values.push_back(a.values[s]);
    m.face_attributes.push_back(std::move(f));
  }
  m.validate(path);
  return m;
}

namespace {

class Legacy {
 public:
  Legacy(const std::string& path, const std::vector<std::byte>& buf)
      : path_(path), p_(reinterpret_cast<const char*>(buf.data())), end_(p_ + buf.size()) {}
  std::string line() {
    const char* s = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    std::string l(s, size_t(p_ - s));
    if (p_ < end_) ++p_;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    return l;
  }
  bool word(std::string& w) {
    while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    if (p_ >= end_) return false;
    const char* s = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    w.assign(s, size_t(p_ - s));
    return true;
  }
  std::string need(const char* what) {
    std::string w;
    if (!word(w)) throw InputError(path_, std::string("truncated: expected ") + what);
    return w;
  }
  uint64_t count(const char* what, double hi = 4294967295.0) {
    const std::string w = need(what);
    double v = 0;
    auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (ec != std::errc() || ptr != w.data() + w.size() || !whole_in(v, 0, hi))
      throw InputError(path_, std::string("bad ") + what + " '" + w + "'");
    return uint64_t(v);
  }
  // `count` values of type t, after the keyword line.
  std::vector<double> values(uint64_t count, ScalarType t, bool binary, uint64_t cap, const char* what) {
    check_limit(path_, count * 8, cap, what);
    if (binary) {
      while (p_ < end_ && *p_ != '\n') ++p_;  // the rest of the keyword line
      if (p_ < end_) ++p_;
      const uint64_t bytes = count * scalar_size(t);
      if (uint64_t(end_ - p_) < bytes) throw InputError(path_, std::string("truncated ") + what);
      auto out = vtk_decode(reinterpret_cast<const std::byte*>(p_), count, t, std::endian::native == std::endian::little);
      p_ += bytes;
      return out;
    }
    if (uint64_t(end_ - p_) < count) throw InputError(path_, std::string("truncated ") + what);
    std::vector<double> out(count);
    for (uint64_t i = 0; i < count; ++i) {
      std::string w;
      if (!word(w)) throw InputError(path_, std::string("truncated ") + what);
      out[i] = parse_double(path_, w, what);
      if (t != ScalarType::f32 && t != ScalarType::f64 && out[i] != std::floor(out[i]))
        throw InputError(path_, std::string(what) + ": '" + w + "' is not a whole number");
    }
    return out;
  }
  // A string array's values, read past: ASCII one per line; binary each
  // after a length whose first byte's top bits give its size (11: 6 bits in
  // 1 byte, 10: 14 bits in 2, 01: 30 bits in 4, 00: 62 bits in 8).
  void skip_strings(uint64_t count, bool binary) {
    line();  // the rest of the keyword line
    for (uint64_t i = 0; i < count; ++i) {
      if (!binary) {
        if (p_ >= end_) throw InputError(path_, "truncated string array");
        line();
        continue;
      }
      if (p_ >= end_) throw InputError(path_, "truncated string array");
      const uint8_t b0 = uint8_t(*p_);
      const int bytes = b0 >= 0xC0 ? 1 : b0 >= 0x80 ? 2 : b0 >= 0x40 ? 4 : 8;
      if (end_ - p_ < bytes) throw InputError(path_, "truncated string array");
      uint64_t len = b0 & (bytes == 8 ? 0x3F : 0x3F);
      for (int k = 1; k < bytes; ++k) len = (len << 8) | uint8_t(p_[k]);
      p_ += bytes;
      if (uint64_t(end_ - p_) < len) throw InputError(path_, "truncated string array");
      p_ += len;
    }
  }
  // METADATA blocks (5.x) end at an empty line.
  void skip_metadata() {
    line();
    while (p_ < end_ && !trim(line()).empty()) {}
  }

 private:
  const std::string& path_;
  const char* p_;
  const char* end_;
};

}  // namespace

Mesh read_vtk(const std::string& path, uint64_t max_bytes) {
  const auto buf = read_whole_file(path, max_bytes, "the VTK file");
  Legacy in(path, buf);
  const std::string first = in.line();
  if (first.rfind("# vtk DataFile Version", 0) != 0) throw InputError(path, "not a legacy VTK file (no '# vtk DataFile Version' line)");
  const double version = std::atof(first.c_str() + 22);
  in.line();  // the title
  const std::string mode = lower(trim(in.line()));
  if (mode != "ascii" && mode != "binary") throw InputError(path, "the third line must be ASCII or BINARY, not '" + mode + "'");
  const bool binary = mode == "binary";
  if (lower(in.need("DATASET")) != "dataset") throw InputError(path, "expected DATASET");
  if (const std::string d = in.need("the dataset type"); lower(d) != "polydata")
    throw InputError(path, "is a VTK " + d + " dataset, not POLYDATA (a surface mesh)");
  VtkData g;
  std::vector<VtkArray>* target = nullptr;
  uint64_t target_count = 0, points = 0;
  bool have_points = false;
  std::string w;
  while (in.word(w)) {
    const std::string k = lower(w);
    if (k == "points") {
      points = in.count("point count");
      g.points = in.values(3 * points, vtk_type(path, in.need("point type"), false), binary, max_bytes, "POINTS");
      have_points = true;
    } else if (k == "vertices" || k == "lines" || k == "polygons" || k == "triangle_strips") {
      const uint64_t a = in.count("cell count"), b = in.count("cell list size");
      VtkCells& c = k == "vertices" ? g.verts : k == "lines" ? g.lines : k == "polygons" ? g.polys : g.strips;
      if (version >= 5) {  // a = offsets (cells + 1), b = connectivity
        if (lower(in.need("OFFSETS")) != "offsets") throw InputError(path, "expected OFFSETS after " + w);
        const auto off = in.values(a, vtk_type(path, in.need("offset type"), false), binary, max_bytes, "OFFSETS");
        if (lower(in.need("CONNECTIVITY")) != "connectivity") throw InputError(path, "expected CONNECTIVITY after OFFSETS");
        const auto ids = in.values(b, vtk_type(path, in.need("connectivity type"), false), binary, max_bytes, "CONNECTIVITY");
        if (off.empty() || off[0] != 0) throw InputError(path, "OFFSETS must start at 0");
        c = vtk_cells_from_offsets(path, off, ids, true);
      } else {  // [k, ids...] per cell
        c = vtk_cells_from_list(path, in.values(b, ScalarType::i32, binary, max_bytes, w.c_str()), a);
      }
    } else if (k == "point_data" || k == "cell_data") {
      target_count = in.count("data count");
      target = k == "point_data" ? &g.point : &g.cell;
    } else if (k == "scalars" || k == "normals" || k == "color_scalars" || k == "vectors" || k == "tensors" ||
               k == "texture_coordinates") {
      if (!target) throw InputError(path, w + " before POINT_DATA or CELL_DATA");
      VtkArray a;
      a.name = in.need("array name");
      if (k == "color_scalars") {
        a.comps = int64_t(in.count("component count", 4));
        a.type = binary ? ScalarType::u8 : ScalarType::f32;
        a.colors = true;
      } else {
        if (k == "texture_coordinates") a.comps = int64_t(in.count("dimension", 3));
        a.type = vtk_type(path, in.need("array type"), false);
        if (k == "normals" || k == "vectors") a.comps = 3;
        if (k == "tensors") a.comps = 9;
        a.normals = k == "normals";
      }
      if (k == "scalars") {
        std::string next = in.need("LOOKUP_TABLE");
        if (lower(next) != "lookup_table") {  // the optional component count
          a.comps = int64_t(parse_int(path, next, "component count"));
          if (a.comps < 1 || a.comps > 4) throw InputError(path, "bad component count '" + next + "'");
          next = in.need("LOOKUP_TABLE");
        }
        if (lower(next) != "lookup_table") throw InputError(path, "expected LOOKUP_TABLE after SCALARS");
        in.need("table name");
      }
      a.values = in.values(target_count * uint64_t(a.comps), a.type, binary, max_bytes, "a data array");
      if (k != "vectors" && k != "tensors" && k != "texture_coordinates") target->push_back(std::move(a));
    } else if (k == "lookup_table") {
      in.need("table name");
      const uint64_t size = in.count("table size");
      in.values(4 * size, binary ? ScalarType::u8 : ScalarType::f32, binary, max_bytes, "LOOKUP_TABLE");
    } else if (k == "field") {
      in.need("field name");
      const uint64_t arrays = in.count("array count", 1e6);
      for (uint64_t i = 0; i < arrays; ++i) {
        VtkArray a;
        a.name = in.need("array name");
        if (lower(a.name) == "metadata") { in.skip_metadata(); --i; continue; }
        a.comps = int64_t(in.count("component count", 1e6));
        const uint64_t tuples = in.count("tuple count");
        const std::string type = in.need("array type");
        if (type == "string" || type == "utf8_string") {
          in.skip_strings(tuples * uint64_t(a.comps), binary);
          continue;
        }
        a.type = vtk_type(path, type, false);
        a.values = in.values(tuples * uint64_t(a.comps), a.type, binary, max_bytes, "a FIELD array");
        if (target && tuples == target_count) target->push_back(std::move(a));
      }
    } else if (k == "metadata") {
      in.skip_metadata();
    } else {
      throw InputError(path, "unknown VTK keyword '" + w + "'");
    }
  }
  if (!have_points) throw InputError(path, "the VTK file has no POINTS");
  for (const auto* arrays : {&g.point, &g.cell})
    for (const VtkArray& a : *arrays)
      if (a.values.size() != (arrays == &g.point ? points : g.verts.count() + g.lines.count() + g.polys.count() + g.strips.count()) * uint64_t(a.comps))
        throw InputError(path, "data array '" + a.name + "' does not match the number of " + (arrays == &g.point ? "points" : "cells"));
  return vtk_to_mesh(path, g);
}

void write_vtk(const std::string& path, const Mesh& m, bool binary, Space space) {
  m.validate(path);
  if (!m.uvs.empty()) return write_vtk(path, welded_solid(m), binary, space);  // no texture: the closed solid
  write_stream_atomically(path, [&](std::ostream& out) {
    std::string buf;
    auto flush = [&] {
      out.write(buf.data(), std::streamsize(buf.size()));
      buf.clear();
    };
    auto value = [&](ScalarType t, double x) {
      if (binary) return vtk_put(buf, t, x, true);
      buf += format_typed(t, x);
      buf += ' ';
    };
    auto end_row = [&] {
      if (!binary) buf.back() = '\n';
      if (buf.size() > (1 << 20)) flush();
    };
    buf += "# vtk DataFile Version 4.2\nwritten by voxpress";
    if (space != Space::unknown) buf += std::string(". SPACE=") + space_name(space);
    buf += binary ? "\nBINARY\n" : "\nASCII\n";
    buf += "DATASET POLYDATA\nPOINTS " + std::to_string(m.positions.size()) + " double\n";
    for (const Vec3& p : m.positions) {
      for (int a = 0; a < 3; ++a) value(ScalarType::f64, p[a]);
      end_row();
    }
    buf += (binary ? "\n" : "") + std::string("POLYGONS ") + std::to_string(m.triangles.size()) + " " +
           std::to_string(4 * m.triangles.size()) + "\n";
    for (const Triangle& t : m.triangles) {
      value(ScalarType::i32, 3);
      for (uint32_t v : t) value(ScalarType::i32, double(v));
      end_row();
    }
    const bool point_data = !m.normals.empty() || !m.colors.empty() || !m.vertex_attributes.empty();
    if (point_data) buf += (binary ? "\n" : "") + std::string("POINT_DATA ") + std::to_string(m.positions.size());
    if (!m.normals.empty()) {
      buf += "\nNORMALS Normals float\n";
      for (const Vec3& nrm : m.normals) {
        for (int a = 0; a < 3; ++a) value(ScalarType::f32, nrm[a]);
        end_row();
      }
    }
    if (!m.colors.empty()) {
      buf += "\nCOLOR_SCALARS RGBA 4\n";
      for (const auto& c : m.colors) {
        for (uint8_t x : c) binary ? vtk_put(buf, ScalarType::u8, x, true) : value(ScalarType::f32, x / 255.0);
        end_row();
      }
    }
    // The first attribute as SCALARS (the active one, which viewers colour
    // by), the others as FIELD arrays: VTK's reader skips any SCALARS after
    // the first unless asked, but reads every FIELD array.
    auto scalars = [&](const std::vector<MeshAttribute>& attrs) {
      for (size_t i = 0; i < attrs.size(); ++i) {
        const MeshAttribute& a = attrs[i];
        if (i == 0) buf += "\nSCALARS " + a.name + " " + vtk_type_name(a.type, false) + " 1\nLOOKUP_TABLE default\n";
        if (i == 1) buf += "\nFIELD FieldData " + std::to_string(attrs.size() - 1);
        if (i >= 1) buf += "\n" + a.name + " 1 " + std::to_string(a.values.size()) + " " + vtk_type_name(a.type, false) + "\n";
        for (double x : a.values) {
          value(a.type, x);
          if (!binary && buf.size() > (1 << 20)) flush();
        }
        end_row();
      }
    };
    scalars(m.vertex_attributes);
    if (!m.face_attributes.empty()) {
      buf += (binary || point_data ? "\n" : "") + std::string("CELL_DATA ") + std::to_string(m.triangles.size());
      scalars(m.face_attributes);
    }
    if (binary) buf += '\n';
    flush();
  });
}

}  // namespace voxpress::detail
