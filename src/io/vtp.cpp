// VTK XML polygon data (.vtp): reader and writer. What is read and written:
// src/io/vtk.cpp. The XML is parsed by pugixml; raw appended data is not
// XML, so the markup before <AppendedData> is parsed (closed by </VTKFile>)
// and the data after its '_' is read by offset.
#include <pugixml.hpp>

#include <algorithm>
#include <bit>
#include <utility>
#include <cstring>

#include "formats.h"
#include "io_util.h"
#include "vtk_data.h"

namespace voxpress::detail {
namespace {

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// The bytes of a data block, raw or base64 (whitespace skipped; padding may
// end a quartet anywhere, as when VTK encodes a header apart from its data).
class Source {
 public:
  Source(const std::string& path, std::string_view s, bool b64) : path_(path), s_(s), b64_(b64) {}
  std::vector<std::byte> take(uint64_t n) {
    std::vector<std::byte> out;
    if (!b64_) {
      if (s_.size() < n) throw InputError(path_, "truncated DataArray data");
      out.assign(reinterpret_cast<const std::byte*>(s_.data()), reinterpret_cast<const std::byte*>(s_.data()) + n);
      s_.remove_prefix(n);
      return out;
    }
    if (n > 3 * (s_.size() / 4) + 3) throw InputError(path_, "truncated DataArray data");
    out.reserve(n);
    while (out.size() < n) {
      if (have_ == 0) quartet();
      out.push_back(pending_[3 - have_--]);
    }
    return out;
  }
  // At most the bytes left (base64: an upper bound before whitespace).
  uint64_t most_left() const { return b64_ ? 3 * (s_.size() / 4) + 3 : s_.size(); }

 private:
  void quartet() {
    int q[4], k = 0;
    while (k < 4) {
      if (s_.empty()) throw InputError(path_, "truncated DataArray data");
      const char c = s_.front();
      s_.remove_prefix(1);
      if (std::isspace(static_cast<unsigned char>(c))) continue;
      q[k++] = c == '=' ? -2 : base64_value(c);
      if (q[k - 1] == -1) throw InputError(path_, "bad base64 character in a DataArray");
    }
    if (q[0] < 0 || q[1] < 0 || (q[2] < 0 && q[3] >= 0)) throw InputError(path_, "bad base64 padding in a DataArray");
    have_ = q[2] < 0 ? 1 : q[3] < 0 ? 2 : 3;
    const std::byte b[3] = {std::byte((q[0] << 2) | (q[1] >> 4)), std::byte(((q[1] & 15) << 4) | (std::max(q[2], 0) >> 2)),
                            std::byte(((std::max(q[2], 0) & 3) << 6) | std::max(q[3], 0))};
    for (int i = 0; i < have_; ++i) pending_[3 - have_ + i] = b[i];
  }
  const std::string& path_;
  std::string_view s_;
  bool b64_;
  std::byte pending_[3]{};
  int have_ = 0;
};

class Reader {
 public:
  Reader(const std::string& path, uint64_t cap) : path_(path), cap_(cap) {}

  VtkData read() {
    buf_ = read_whole_file(path_, cap_, "the VTP file");
    const std::string_view all(reinterpret_cast<const char*>(buf_.data()), buf_.size());
    std::string xml(all);
    if (const size_t a = all.find("<AppendedData"); a != std::string_view::npos) {
      const size_t close = all.find('>', a), under = close == std::string_view::npos ? close : all.find('_', close);
      if (under == std::string_view::npos) throw InputError(path_, "<AppendedData> without its '_' marker");
      pugi::xml_document tag;
      const std::string closed = std::string(all.substr(a, close + 1 - a)) + "</AppendedData>";
      if (!tag.load_buffer(closed.data(), closed.size()))
        throw InputError(path_, "malformed <AppendedData> tag");
      base64_appended_ = std::string(tag.first_child().attribute("encoding").as_string("raw")) == "base64";
      appended_ = all.substr(under + 1);
      xml = std::string(all.substr(0, a)) + "</VTKFile>";
    }
    pugi::xml_document doc;
    if (const auto r = doc.load_buffer(xml.data(), xml.size()); !r)
      throw InputError(path_, std::string("malformed XML (") + r.description() + " at byte " + std::to_string(r.offset) + ")");
    const pugi::xml_node root = doc.child("VTKFile");
    if (!root) throw InputError(path_, "not a VTK XML file (no <VTKFile>)");
    if (const std::string t = root.attribute("type").as_string(); t != "PolyData")
      throw InputError(path_, "is a VTK " + (t.empty() ? std::string("XML") : t) + " file, not PolyData (a surface mesh)");
    swap_ = std::string(root.attribute("byte_order").as_string("LittleEndian")) !=
            (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian");
    const std::string ht = root.attribute("header_type").as_string("UInt32");
    if (ht != "UInt32" && ht != "UInt64") throw InputError(path_, "unsupported header_type '" + ht + "'");
    header_ = ht == "UInt64" ? ScalarType::u64 : ScalarType::u32;
    const std::string comp = root.attribute("compressor").as_string();
    if (!comp.empty() && comp != "vtkZLibDataCompressor")
      throw InputError(path_, "unsupported compressor '" + comp + "' (zlib is read)");
    compressed_ = !comp.empty();
    const pugi::xml_node poly = root.child("PolyData");
    if (!poly) throw InputError(path_, "no <PolyData> element");
    VtkData out;
    bool first = true;
    for (pugi::xml_node piece : poly.children("Piece")) add_piece(piece, out, std::exchange(first, false));
    return out;
  }

 private:
  uint64_t count_of(pugi::xml_node n, const char* attr) const {
    const double v = n.attribute(attr).as_double(0);
    if (!whole_in(v, 0, 4294967295.0)) throw InputError(path_, std::string("bad ") + attr);
    return uint64_t(v);
  }

  // The values of a DataArray, which must hold `expected` tuples.
  VtkArray array(pugi::xml_node d, uint64_t expected) {
    VtkArray a;
    a.name = d.attribute("Name").as_string();
    a.type = vtk_type(path_, d.attribute("type").as_string(), true);
    const double comps = d.attribute("NumberOfComponents").as_double(1);
    if (!whole_in(comps, 1, 1e6)) throw InputError(path_, "bad NumberOfComponents of '" + a.name + "'");
    a.comps = int64_t(comps);
    const uint64_t count = expected * uint64_t(a.comps);
    check_limit(path_, count * 8, cap_, "a DataArray");
    const std::string format = d.attribute("format").as_string("ascii");
    if (format == "ascii") {
      const std::vector<std::string> words = split_ws(d.text().get());
      if (words.size() != count) throw InputError(path_, "DataArray '" + a.name + "' holds " + std::to_string(words.size()) + " values, not " + std::to_string(count));
      a.values.reserve(count);
      for (const std::string& w : words) a.values.push_back(parse_double(path_, w, "DataArray '" + a.name + "'"));
    } else if (format == "binary" || format == "appended") {
      std::vector<std::byte> bytes;
      if (format == "binary") {
        bytes = block(d.text().get(), true);
      } else {
        const double off = d.attribute("offset").as_double(-1);
        if (!whole_in(off, 0, double(appended_.size()))) throw InputError(path_, "DataArray '" + a.name + "' has a bad offset");
        bytes = block(appended_.substr(size_t(off)), base64_appended_);
      }
      if (bytes.size() != count * scalar_size(a.type))
        throw InputError(path_, "DataArray '" + a.name + "' holds " + std::to_string(bytes.size()) + " bytes, not the " +
                                    std::to_string(count * scalar_size(a.type)) + " its tuples need");
      a.values = vtk_decode(bytes.data(), count, a.type, swap_);
    } else {
      throw InputError(path_, "unknown DataArray format '" + format + "'");
    }
    return a;
  }

  // One data block: a header (its byte count, or the zlib block table) and its data.
  std::vector<std::byte> block(std::string_view text, bool b64) {
    Source src(path_, text, b64);
    const size_t hs = scalar_size(header_);
    auto header_value = [&](const std::vector<std::byte>& h, size_t i) {
      const double v = vtk_decode(h.data() + i * hs, 1, header_, swap_)[0];
      if (v > double(cap_)) throw LimitError(path_, "a DataArray of " + format_double(v) + " bytes is above the memory limit");
      return uint64_t(v);
    };
    if (!compressed_) return src.take(header_value(src.take(hs), 0));
    const std::vector<std::byte> h = src.take(3 * hs);
    const uint64_t blocks = header_value(h, 0), size = header_value(h, 1), last = header_value(h, 2);
    if (blocks > 0 && (blocks - 1) > cap_ / std::max<uint64_t>(size, 1)) throw LimitError(path_, "a compressed DataArray above the memory limit");
    const uint64_t total = blocks == 0 ? 0 : (blocks - 1) * size + (last ? last : size);
    check_limit(path_, total, cap_, "a compressed DataArray");
    const std::vector<std::byte> sizes = src.take(blocks * hs);
    // The packed blocks must be in the file and able to inflate to the
    // declared total (deflate: at most kMaxDeflateRatio:1) before anything is
    // reserved; the output grows as each block is inflated (issue 73: a
    // 100-byte file declaring 2.4 GB was allocated, and zeroed, up front).
    uint64_t packed_total = 0;
    for (uint64_t b = 0; b < blocks; ++b) {
      packed_total += header_value(sizes, b);
      if (packed_total > src.most_left()) throw InputError(path_, "truncated DataArray data");
    }
    check_ratio(path_, size_t(packed_total), total);
    std::vector<std::byte> out;
    out.reserve(total);
    for (uint64_t b = 0; b < blocks; ++b) {
      const std::vector<std::byte> packed = src.take(header_value(sizes, b));
      const uint64_t want = b + 1 == blocks && last ? last : size;
      out.resize(out.size() + want);
      inflate_exact(path_, packed.data(), packed.size(), out.data() + out.size() - want, want);
    }
    return out;
  }

  void add_piece(pugi::xml_node piece, VtkData& out, bool first_piece) {
    const uint64_t np = count_of(piece, "NumberOfPoints"), base = out.points.size() / 3;
    const pugi::xml_node pts = piece.child("Points").child("DataArray");
    if (!pts && np > 0) throw InputError(path_, "a Piece without <Points>");
    if (pts) {
      VtkArray p = array(pts, np);
      if (p.comps != 3) throw InputError(path_, "Points must have 3 components");
      out.points.insert(out.points.end(), p.values.begin(), p.values.end());
    }
    const char* kinds[4] = {"Verts", "Lines", "Polys", "Strips"};
    VtkCells* cells[4] = {&out.verts, &out.lines, &out.polys, &out.strips};
    uint64_t ncells = 0;
    for (int k = 0; k < 4; ++k) {
      const uint64_t n = count_of(piece, (std::string("NumberOf") + kinds[k]).c_str());
      ncells += n;
      if (n == 0) continue;
      pugi::xml_node conn, offs;
      for (pugi::xml_node d : piece.child(kinds[k]).children("DataArray")) {
        if (std::string(d.attribute("Name").as_string()) == "connectivity") conn = d;
        if (std::string(d.attribute("Name").as_string()) == "offsets") offs = d;
      }
      if (!conn || !offs) throw InputError(path_, std::string("<") + kinds[k] + "> needs its connectivity and offsets");
      const VtkArray o = array(offs, n);
      const double length = o.values.empty() ? 0 : o.values.back();
      if (!whole_in(length, 0, 4294967295.0)) throw InputError(path_, "bad cell offsets");
      VtkArray c = array(conn, uint64_t(length));
      for (double& id : c.values) id += double(base);
      const VtkCells add = vtk_cells_from_offsets(path_, o.values, c.values, false);
      VtkCells& to = *cells[k];
      const int64_t shift = int64_t(to.ids.size());
      to.ids.insert(to.ids.end(), add.ids.begin(), add.ids.end());
      for (size_t i = 1; i < add.offsets.size(); ++i) to.offsets.push_back(add.offsets[i] + shift);
    }
    // Point and cell data of this piece (arrays by position in the piece).
    auto data = [&](pugi::xml_node node, uint64_t n, std::vector<VtkArray>& arrays, bool point) {
      const std::string normals = node.attribute("Normals").as_string();
      std::vector<VtkArray> here;
      for (pugi::xml_node d : node.children("DataArray")) {
        VtkArray a = array(d, n);
        a.normals = point && a.comps == 3 && (a.name == normals || a.name == "Normals");
        a.colors = point && a.comps == 4 && a.type == ScalarType::u8;
        here.push_back(std::move(a));
      }
      if (first_piece) {
        arrays = std::move(here);
      } else {  // a later piece: its arrays append to the same names
        if (here.size() != arrays.size()) throw InputError(path_, "pieces with different data arrays");
        for (size_t i = 0; i < here.size(); ++i) arrays[i].values.insert(arrays[i].values.end(), here[i].values.begin(), here[i].values.end());
      }
    };
    data(piece.child("PointData"), np, out.point, true);
    // Cell data covers verts, lines, polys, strips in that order; pieces
    // with cell data and more than one cell kind across pieces are refused.
    mixed_ = mixed_ || ncells != count_of(piece, "NumberOfPolys");
    if (piece.child("CellData").child("DataArray") && !first_piece && mixed_)
      throw InputError(path_, "cell data over several pieces holding other cells than polygons is not supported");
    data(piece.child("CellData"), ncells, out.cell, false);
  }

  const std::string& path_;
  uint64_t cap_;
  std::vector<std::byte> buf_;
  std::string_view appended_;
  bool base64_appended_ = false, swap_ = false, compressed_ = false, mixed_ = false;
  ScalarType header_ = ScalarType::u32;
};

}  // namespace

Mesh read_vtp(const std::string& path, uint64_t max_bytes) {
  Reader r(path, max_bytes);
  VtkData d = r.read();
  return vtk_to_mesh(path, d);
}

void write_vtp(const std::string& path, const Mesh& m, Space space) {
  m.validate(path);
  if (!m.uvs.empty()) return write_vtp(path, welded_solid(m), space);  // no texture: the closed solid
  // Every array's bytes go to the appended block, each after its UInt64 size.
  std::string data, arrays_point, arrays_cell;
  auto add = [&](std::string& xml, const std::string& name, ScalarType t, int comps, size_t count, auto&& value) {
    xml += "        <DataArray type=\"" + std::string(vtk_type_name(t, true)) + "\"" +
           (name.empty() ? "" : " Name=\"" + name + "\"") +
           (comps > 1 ? " NumberOfComponents=\"" + std::to_string(comps) + "\"" : "") + " format=\"appended\" offset=\"" +
           std::to_string(data.size()) + "\"/>\n";
    vtk_put(data, ScalarType::u64, double(count * size_t(comps) * scalar_size(t)), false);
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < comps; ++c) vtk_put(data, t, value(i, c), false);
  };
  const size_t nv = m.positions.size(), nf = m.triangles.size();
  const ScalarType index = nv > 2147483647u ? ScalarType::i64 : ScalarType::i32;
  const ScalarType offset = 3 * uint64_t(nf) > 2147483647u ? ScalarType::i64 : ScalarType::i32;
  std::string points, polys;
  add(points, "Points", ScalarType::f64, 3, nv, [&](size_t v, int a) { return m.positions[v][a]; });
  add(polys, "connectivity", index, 1, 3 * nf, [&](size_t i, int) { return double(m.triangles[i / 3][i % 3]); });
  add(polys, "offsets", offset, 1, nf, [&](size_t f, int) { return double(3 * (f + 1)); });
  if (!m.normals.empty()) add(arrays_point, "Normals", ScalarType::f32, 3, nv, [&](size_t v, int a) { return m.normals[v][a]; });
  if (!m.colors.empty()) add(arrays_point, "RGBA", ScalarType::u8, 4, nv, [&](size_t v, int c) { return double(m.colors[v][size_t(c)]); });
  for (const MeshAttribute& a : m.vertex_attributes) add(arrays_point, a.name, a.type, 1, nv, [&](size_t v, int) { return a.values[v]; });
  for (const MeshAttribute& a : m.face_attributes) add(arrays_cell, a.name, a.type, 1, nf, [&](size_t f, int) { return a.values[f]; });
  std::string x = "<?xml version=\"1.0\"?>\n<!-- written by voxpress -->\n"
                  "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n";
  if (space != Space::unknown) {  // as 3D Slicer records it: a SPACE string array
    x += "    <FieldData>\n      <Array type=\"String\" Name=\"SPACE\" NumberOfTuples=\"1\" format=\"ascii\">";
    for (const char* c = space_name(space); *c; ++c) x += std::to_string(int(*c)) + " ";
    x += "0</Array>\n    </FieldData>\n";
  }
  x += "    <Piece NumberOfPoints=\"" + std::to_string(nv) + "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
       std::to_string(nf) + "\">\n";
  x += "      <PointData" + std::string(m.normals.empty() ? "" : " Normals=\"Normals\"") + ">\n" + arrays_point + "      </PointData>\n";
  x += "      <CellData" + (m.face_attributes.empty() ? std::string() : " Scalars=\"" + m.face_attributes[0].name + "\"") + ">\n" +
       arrays_cell + "      </CellData>\n";
  x += "      <Points>\n" + points + "      </Points>\n      <Polys>\n" + polys + "      </Polys>\n";
  x += "    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(x.data(), std::streamsize(x.size()));
    out.write(data.data(), std::streamsize(data.size()));
    const std::string end = "\n  </AppendedData>\n</VTKFile>\n";
    out.write(end.data(), std::streamsize(end.size()));
  });
}

}  // namespace voxpress::detail
