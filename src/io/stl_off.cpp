// STL and OFF readers and writers.
//
// STL: a file whose size is exactly 84 + 50 * (count in bytes 80..83) is
// binary, whatever its header says (many binary STLs start with "solid");
// otherwise it must be ASCII ("solid ... facet ... vertex x y z ..."). STL
// stores every corner separately, so identical positions are welded.
// OFF: "OFF" (also COFF, NOFF, CNOFF; counts may follow on the same line),
// '#' comments, extra per-vertex values (colours) ignored, polygons fanned.
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

// Whitespace tokenizer over a buffer; '#' starts a comment.
class Tokens {
 public:
  Tokens(const std::string& path, const char* p, const char* end) : path_(path), p_(p), end_(end) {}
  bool next(std::string_view& tok) {
    for (;;) {
      while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
      if (p_ < end_ && *p_ == '#') {
        while (p_ < end_ && *p_ != '\n') ++p_;
        continue;
      }
      break;
    }
    if (p_ >= end_) return false;
    const char* s = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    tok = std::string_view(s, size_t(p_ - s));
    return true;
  }
  double number(const char* what) {
    std::string_view t;
    if (!next(t)) throw InputError(path_, std::string("truncated: expected ") + what);
    double v = 0;
    const char* b = t.data();
    if (*b == '+') ++b;
    auto [ptr, ec] = std::from_chars(b, t.data() + t.size(), v);
    if (ec != std::errc() || ptr != t.data() + t.size())
      throw InputError(path_, std::string("malformed ") + what + " '" + std::string(t) + "'");
    return v;
  }
  // Rest of the current line (after the last token read).
  void skip_line() {
    while (p_ < end_ && *p_ != '\n') ++p_;
  }
  std::string_view rest_of_line() {
    const char* s = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    return std::string_view(s, size_t(p_ - s));
  }
  uint64_t remaining() const { return uint64_t(end_ - p_); }

 private:
  const std::string& path_;
  const char* p_;
  const char* end_;
};

}  // namespace

Mesh read_stl(const std::string& path, uint64_t max_bytes) {
  const uint64_t fs = file_size(path);
  check_limit(path, fs, max_bytes, "the file");
  const auto buf = read_range(path, 0, fs);
  Mesh m;
  uint32_t count = 0;
  if (fs >= 84) std::memcpy(&count, buf.data() + 80, 4);
  if (fs >= 84 && fs == 84 + 50 * uint64_t(count)) {
    m.positions.reserve(size_t(count) * 3);
    m.triangles.reserve(count);
    for (uint32_t f = 0; f < count; ++f) {
      const std::byte* rec = buf.data() + 84 + 50 * size_t(f);
      for (int c = 0; c < 3; ++c) {
        float xyz[3];
        std::memcpy(xyz, rec + 12 + 12 * c, 12);
        m.positions.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
      m.triangles.push_back({3 * f, 3 * f + 1, 3 * f + 2});
    }
  } else {
    const char* p = reinterpret_cast<const char*>(buf.data());
    std::string start(p, std::min<size_t>(fs, 5));
    if (lower(start) != "solid") {
      if (fs >= 84)
        throw InputError(path, "not an STL file: the size does not match a binary STL of " + std::to_string(count) +
                                   " triangles (truncated?) and it does not start with 'solid'");
      throw InputError(path, "not an STL file (too small)");
    }
    Tokens tk(path, p, p + fs);
    std::string_view t;
    tk.next(t);  // solid
    tk.skip_line();
    std::vector<Vec3> corner;
    while (tk.next(t)) {
      const std::string w = lower(std::string(t));
      if (w == "vertex") {
        Vec3 v;
        for (int a = 0; a < 3; ++a) v[a] = tk.number("vertex coordinate");
        corner.push_back(v);
      } else if (w == "endloop") {
        if (corner.size() < 3) throw InputError(path, "ASCII STL facet with fewer than 3 vertices");
        const uint32_t base = uint32_t(m.positions.size());
        for (const Vec3& v : corner) m.positions.push_back(v);
        for (size_t q = 1; q + 1 < corner.size(); ++q)
          m.triangles.push_back({base, base + uint32_t(q), base + uint32_t(q + 1)});
        corner.clear();
      } else if (w == "normal") {
        for (int a = 0; a < 3; ++a) tk.number("facet normal");
      } else if (w == "facet" || w == "outer" || w == "loop" || w == "endfacet") {
      } else if (w == "endsolid") {
        tk.skip_line();
      } else if (w == "solid") {
        tk.skip_line();
      } else {
        throw InputError(path, "unexpected token '" + std::string(t) + "' in ASCII STL");
      }
    }
    if (!corner.empty()) throw InputError(path, "truncated ASCII STL (facet without endloop)");
  }
  if (m.triangles.empty()) throw InputError(path, "the STL file holds no triangles");
  weld_identical_vertices(m);
  m.validate(path);
  return m;
}

void write_stl(const std::string& path, const Mesh& m, Space space) {
  m.validate(path);
  write_stream_atomically(path, [&](std::ostream& out) {
    char header[80] = {};
    std::snprintf(header, sizeof header, "binary STL written by voxpress%s%s", space == Space::unknown ? "" : ". SPACE=",
                  space == Space::unknown ? "" : space_name(space));  // read by 3D Slicer
    out.write(header, 80);
    const uint32_t n = uint32_t(m.triangles.size());
    out.write(reinterpret_cast<const char*>(&n), 4);
    std::string buf;
    buf.reserve(50 * 4096);
    for (const Triangle& t : m.triangles) {
      const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
      Vec3 nrm = (b - a).cross(c - a);
      const double len = nrm.norm();
      if (len > 0) nrm /= len;
      float rec[12];
      for (int k = 0; k < 3; ++k) {
        rec[k] = float(nrm[k]);
        rec[3 + k] = float(a[k]);
        rec[6 + k] = float(b[k]);
        rec[9 + k] = float(c[k]);
      }
      buf.append(reinterpret_cast<const char*>(rec), 48);
      buf.append(2, '\0');
      if (buf.size() >= 50 * 4096) {
        out.write(buf.data(), std::streamsize(buf.size()));
        buf.clear();
      }
    }
    out.write(buf.data(), std::streamsize(buf.size()));
  });
}

Mesh read_off(const std::string& path, uint64_t max_bytes) {
  const uint64_t fs = file_size(path);
  check_limit(path, fs, max_bytes, "the file");
  const auto buf = read_range(path, 0, fs);
  const char* p = reinterpret_cast<const char*>(buf.data());
  const char* end = p + fs;
  // Non-empty lines with comments removed.
  auto next_line = [&](std::string_view& line) {
    while (p < end) {
      const char* s = p;
      while (p < end && *p != '\n') ++p;
      std::string_view l(s, size_t(p - s));
      if (p < end) ++p;
      if (const auto hash = l.find('#'); hash != std::string_view::npos) l = l.substr(0, hash);
      if (!trim(l).empty()) {
        line = l;
        return true;
      }
    }
    return false;
  };
  std::string_view line;
  if (!next_line(line)) throw InputError(path, "empty file");
  Tokens head(path, line.data(), line.data() + line.size());
  std::string_view magic;
  head.next(magic);
  const std::string mg(magic);
  if (mg.size() < 3 || mg.substr(mg.size() - 3) != "OFF") throw InputError(path, "not an OFF file (missing the OFF magic)");
  if (mg.find("ST") != std::string::npos || mg.find('4') != std::string::npos || mg.find('n') != std::string::npos)
    throw InputError(path, "OFF variant '" + mg + "' is not supported");
  std::string_view count_text = head.rest_of_line();  // counts may share the magic line
  if (trim(count_text) == "BINARY") throw InputError(path, "binary OFF is not supported");
  if (trim(count_text).empty()) {
    if (!next_line(line)) throw InputError(path, "truncated: no OFF counts");
    count_text = line;
  }
  Tokens counts(path, count_text.data(), count_text.data() + count_text.size());
  const double nv = counts.number("vertex count");
  const double nf = counts.number("face count");
  const double any = std::numeric_limits<double>::infinity();
  if (!whole_in(nv, 0, any) || !whole_in(nf, 0, any)) throw InputError(path, "invalid OFF counts");
  if (nv * 6 > double(end - p) + 6 || nf * 6 > double(end - p) + 6)
    throw InputError(path, "truncated: the OFF counts exceed what the file can hold");
  check_limit(path, uint64_t(nv) * 48 + uint64_t(nf) * 12, max_bytes, "the mesh");
  Mesh m;
  m.positions.resize(uint64_t(nv));
  for (uint64_t v = 0; v < uint64_t(nv); ++v) {
    if (!next_line(line)) throw InputError(path, "truncated: fewer vertices than the header declares");
    Tokens lt(path, line.data(), line.data() + line.size());
    for (int a = 0; a < 3; ++a) m.positions[v][a] = lt.number("vertex coordinate");  // extra values: colours
  }
  m.triangles.reserve(uint64_t(nf));
  std::vector<uint32_t> poly;
  for (uint64_t f = 0; f < uint64_t(nf); ++f) {
    if (!next_line(line)) throw InputError(path, "truncated: fewer faces than the header declares");
    Tokens lt(path, line.data(), line.data() + line.size());
    const double n = lt.number("face size");
    if (!whole_in(n, 3, 1e6)) throw InputError(path, "face " + std::to_string(f) + " has an invalid size");
    poly.resize(size_t(n));
    for (auto& i : poly) {
      const double x = lt.number("vertex index");
      if (!whole_in(x, 0, nv - 1))
        throw InputError(path, "face " + std::to_string(f) + " uses vertex " + format_double(x) + " but there are " +
                                   format_double(nv) + " vertices");
      i = uint32_t(x);
    }
    for (size_t q = 1; q + 1 < poly.size(); ++q) m.triangles.push_back({poly[0], poly[q], poly[q + 1]});
  }
  m.validate(path);
  return m;
}

void write_off(const std::string& path, const Mesh& m) {
  m.validate(path);
  if (!m.uvs.empty()) return write_off(path, welded_solid(m));  // no texture: the closed solid
  write_stream_atomically(path, [&](std::ostream& out) {
    std::string buf = "OFF\n" + std::to_string(m.positions.size()) + " " + std::to_string(m.triangles.size()) + " 0\n";
    for (const Vec3& p : m.positions) {
      buf += format_double(p.x()) + " " + format_double(p.y()) + " " + format_double(p.z()) + "\n";
      if (buf.size() > (1 << 20)) {
        out << buf;
        buf.clear();
      }
    }
    for (const Triangle& t : m.triangles) {
      buf += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
      if (buf.size() > (1 << 20)) {
        out << buf;
        buf.clear();
      }
    }
    out << buf;
  });
}

}  // namespace voxpress::detail
