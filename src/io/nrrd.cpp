// NRRD reader and writer (http://teem.sourceforge.net/nrrd/format.html).
//
// Supported: NRRD0001-5 magic; attached data or detached (".nhdr" with
// "data file: NAME" or "data file: LIST"); encodings raw, gzip, text; both
// endiannesses; "space directions" (with "none" for a non-spatial axis),
// "space origin", "spacings"; spaces LPS, RAS and LAS (converted to RAS);
// key/value pairs (3D Slicer's Segment<N>_* become ScalarVolume::segments).
// A 4-D file is accepted when its non-spatial axis (kind list/vector, or no
// space direction) is the first (fastest) one: it becomes `components`.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <type_traits>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

namespace fs = std::filesystem;

struct Header {
  std::map<std::string, std::string> fields;  // lower-cased field names
  std::map<std::string, std::string> keyvalues;
  std::vector<std::string> list_files;        // data file: LIST
  uint64_t data_offset = 0;                   // attached data start
  bool detached_header = false;               // no blank line reached (.nhdr)
};

Header parse_header(const std::string& path) {
  const uint64_t size = file_size(path);
  // Headers are small; read up to 1 MiB to find the blank line.
  const uint64_t probe = std::min<uint64_t>(size, 1 << 20);
  const auto bytes = read_range(path, 0, probe);
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (text.rfind("NRRD000", 0) != 0) throw InputError(path, "not a NRRD file (missing the NRRD000x magic line)");
  Header h;
  size_t pos = text.find('\n');
  if (pos == std::string::npos) throw InputError(path, "truncated NRRD header");
  ++pos;
  bool in_list = false;
  for (;;) {
    if (pos >= text.size()) {
      if (probe < size) throw InputError(path, "NRRD header longer than 1 MiB or missing its blank line");
      h.detached_header = true;
      break;
    }
    size_t end = text.find('\n', pos);
    const bool last = end == std::string::npos;
    if (last) end = text.size();
    std::string line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = last ? text.size() : end + 1;
    if (line.empty()) {
      h.data_offset = pos;
      break;
    }
    if (in_list) {
      h.list_files.push_back(trim(line));
      continue;
    }
    if (line[0] == '#') continue;
    const auto kv = line.find(":=");
    const auto colon = line.find(": ");
    if (kv != std::string::npos && (colon == std::string::npos || kv < colon)) {
      h.keyvalues[line.substr(0, kv)] = line.substr(kv + 2);
      continue;
    }
    if (colon == std::string::npos) throw InputError(path, "malformed NRRD header line '" + line + "'");
    const std::string name = lower(trim(line.substr(0, colon)));
    const std::string value = trim(line.substr(colon + 2));
    h.fields[name] = value;
    if ((name == "data file" || name == "datafile") && value.rfind("LIST", 0) == 0) in_list = true;
  }
  return h;
}

const std::string* field(const Header& h, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    auto it = h.fields.find(n);
    if (it != h.fields.end()) return &it->second;
  }
  return nullptr;
}

ScalarType nrrd_type(const std::string& path, const std::string& t) {
  static const std::map<std::string, ScalarType> types = {
      {"signed char", ScalarType::i8}, {"int8", ScalarType::i8}, {"int8_t", ScalarType::i8},
      {"uchar", ScalarType::u8}, {"unsigned char", ScalarType::u8}, {"uint8", ScalarType::u8},
      {"uint8_t", ScalarType::u8}, {"short", ScalarType::i16}, {"short int", ScalarType::i16},
      {"signed short", ScalarType::i16}, {"signed short int", ScalarType::i16}, {"int16", ScalarType::i16},
      {"int16_t", ScalarType::i16}, {"ushort", ScalarType::u16}, {"unsigned short", ScalarType::u16},
      {"unsigned short int", ScalarType::u16}, {"uint16", ScalarType::u16}, {"uint16_t", ScalarType::u16},
      {"int", ScalarType::i32}, {"signed int", ScalarType::i32}, {"int32", ScalarType::i32},
      {"int32_t", ScalarType::i32}, {"uint", ScalarType::u32}, {"unsigned int", ScalarType::u32},
      {"uint32", ScalarType::u32}, {"uint32_t", ScalarType::u32}, {"longlong", ScalarType::i64},
      {"long long", ScalarType::i64}, {"long long int", ScalarType::i64}, {"signed long long", ScalarType::i64},
      {"signed long long int", ScalarType::i64}, {"int64", ScalarType::i64}, {"int64_t", ScalarType::i64},
      {"ulonglong", ScalarType::u64}, {"unsigned long long", ScalarType::u64},
      {"unsigned long long int", ScalarType::u64}, {"uint64", ScalarType::u64}, {"uint64_t", ScalarType::u64},
      {"float", ScalarType::f32}, {"double", ScalarType::f64}};
  auto it = types.find(lower(t));
  if (it == types.end()) throw InputError(path, "unsupported NRRD type '" + t + "'");
  return it->second;
}

// "(x,y,z)" -> vector; "none" -> nullopt.
std::optional<Vec3> parse_vector(const std::string& path, const std::string& s, const char* what) {
  if (lower(s) == "none") return std::nullopt;
  if (s.size() < 2 || s.front() != '(' || s.back() != ')')
    throw InputError(path, std::string("malformed ") + what + " '" + s + "'");
  std::vector<std::string> parts;
  std::stringstream in(s.substr(1, s.size() - 2));
  std::string p;
  while (std::getline(in, p, ',')) parts.push_back(p);
  if (parts.size() != 3) throw InputError(path, std::string(what) + " must have 3 components: '" + s + "'");
  Vec3 v;
  for (int a = 0; a < 3; ++a) v[a] = parse_double(path, parts[size_t(a)], what);
  return v;
}

// Splits "space directions" into per-axis tokens: "(a,b,c)" or "none".
std::vector<std::string> split_vectors(const std::string& s) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i >= s.size()) break;
    size_t j = i;
    if (s[i] == '(') {
      j = s.find(')', i);
      j = j == std::string::npos ? s.size() : j + 1;
    } else {
      while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j]))) ++j;
    }
    out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

void parse_text(const std::string& path, const std::string& text, ScalarVolume& v) {
  std::istringstream in(text);
  const uint64_t n = v.value_count();
  uint64_t k = 0;
  std::string tok;
  v.visit([&](auto values) {
    using T = typename decltype(values)::value_type;
    T* out = const_cast<T*>(values.data());
    while (k < n && in >> tok) {
      const double x = parse_double(path, tok, "text sample");
      // The conversion is undefined outside T's range (and for NaN into an integer type).
      const bool fits = std::is_floating_point_v<T>
                            ? !std::isfinite(x) || std::abs(x) <= double(std::numeric_limits<T>::max())
                            : x >= double(std::numeric_limits<T>::lowest()) && x < double(std::numeric_limits<T>::max()) + 1.0;
      if (!fits) throw InputError(path, "text sample " + tok + " does not fit the declared voxel type");
      out[k++] = T(x);
    }
  });
  if (k < n)
    throw InputError(path, "truncated: the text payload holds " + std::to_string(k) + " values but the header declares " +
                               std::to_string(n));
  if (in >> tok)
    throw InputError(path, "the text payload holds more than the " + std::to_string(n) + " values the header declares");
}

// NRRD accepts voxpress's integer type names as they are.
std::string nrrd_type_name(ScalarType t) {
  if (t == ScalarType::f32) return "float";
  if (t == ScalarType::f64) return "double";
  return scalar_name(t);
}

}  // namespace

namespace {

// The lattice (and the component count of a 4-D list axis) from the header.
void read_geometry(const std::string& path, const Header& h, int64_t dim, const std::vector<int64_t>& n,
                   ScalarVolume& v) {
  // Which axis is non-spatial (for 4-D): kinds, else a "none" space direction.
  std::vector<std::string> kinds;
  if (const auto* k = field(h, {"kinds"})) kinds = split_ws(*k);
  std::vector<std::string> dirs;
  if (const auto* d = field(h, {"space directions"})) dirs = split_vectors(*d);
  if (!dirs.empty() && int64_t(dirs.size()) != dim) throw InputError(path, "'space directions' does not list 'dimension' entries");
  int nonspatial = -1;
  if (dim == 4) {
    for (int a = 0; a < 4; ++a) {
      const bool list_kind = a < int(kinds.size()) && kinds[size_t(a)] != "domain" && kinds[size_t(a)] != "space";
      const bool no_dir = !dirs.empty() && lower(dirs[size_t(a)]) == "none";
      if (list_kind || no_dir) {
        nonspatial = a;
        break;
      }
    }
    if (nonspatial != 0)
      throw InputError(path, "4-D NRRD is supported only with its non-spatial (list) axis first, as 3D Slicer writes it");
    v.components = n[0];
  }
  const int first = dim == 4 ? 1 : 0;
  for (int a = 0; a < 3; ++a) v.lattice.dims[size_t(a)] = a < dim - first ? n[size_t(first + a)] : 1;

  // Space.
  std::string space;
  if (const auto* s = field(h, {"space"})) space = lower(*s);
  bool flip_x_to_ras = false;
  if (space == "left-posterior-superior" || space == "lps") {
    v.lattice.space = Space::LPS;
  } else if (space == "right-anterior-superior" || space == "ras") {
    v.lattice.space = Space::RAS;
  } else if (space == "left-anterior-superior" || space == "las") {
    v.lattice.space = Space::RAS;
    flip_x_to_ras = true;
  }
  // Geometry.
  if (!dirs.empty()) {
    for (int a = 0; a < dim - first; ++a) {
      const auto d = parse_vector(path, dirs[size_t(first + a)], "space direction");
      if (!d) throw InputError(path, "spatial axis " + std::to_string(first + a) + " has no space direction");
      const double len = d->norm();
      if (!(len > 0) || !std::isfinite(len)) throw InputError(path, "zero or invalid space direction");
      v.lattice.spacing[a] = len;
      v.lattice.direction.col(a) = *d / len;
    }
    if (dim - first == 2) v.lattice.direction.col(2) = v.lattice.direction.col(0).cross(v.lattice.direction.col(1));
  } else if (const auto* sp = field(h, {"spacings"})) {
    const auto tok = split_ws(*sp);
    if (int64_t(tok.size()) != dim) throw InputError(path, "'spacings' does not list 'dimension' values");
    for (int a = 0; a < dim - first; ++a) {
      const double s = parse_double(path, tok[size_t(first + a)], "spacings");
      // No silent default: a spatial axis's spacing is a finite non-zero number
      // (negative flips the axis, as teem reads it) (issue 73).
      if (!std::isfinite(s) || s == 0)
        throw InputError(path, "'spacings' gives spatial axis " + std::to_string(first + a) + " the spacing " +
                                   tok[size_t(first + a)] + " (must be a finite non-zero number)");
      v.lattice.spacing[a] = std::abs(s);
      if (s < 0) v.lattice.direction.col(a) *= -1;
    }
  }
  if (const auto* o = field(h, {"space origin"})) {
    if (auto p = parse_vector(path, *o, "space origin")) v.lattice.origin = *p;
  }
  if (flip_x_to_ras) {
    v.lattice.origin.x() = -v.lattice.origin.x();
    v.lattice.direction.row(0) *= -1;
  }
  try {
    v.lattice.validate();
  } catch (const UsageError& e) {
    throw InputError(path, e.what());
  }

}

// The key/value metadata and Slicer's segments.
void read_segments(const std::string& path, const Header& h, ScalarVolume& v) {
  v.metadata = h.keyvalues;
  for (const auto& [key, value] : h.keyvalues) {
    if (key.rfind("Segment", 0) != 0 || !key.ends_with("_ID")) continue;
    const std::string prefix = key.substr(0, key.size() - 3);
    Segment s;
    s.id = value;
    auto get = [&](const char* suffix) -> const std::string* {
      auto it = h.keyvalues.find(prefix + suffix);
      return it == h.keyvalues.end() ? nullptr : &it->second;
    };
    s.name = get("_Name") ? *get("_Name") : value;
    if (const auto* lv = get("_LabelValue")) s.label = parse_double(path, *lv, prefix + "_LabelValue");
    // A NaN label matches no sample: the segment was dropped from --labels all (issue 73).
    if (!std::isfinite(s.label)) throw InputError(path, prefix + "_LabelValue is " + format_double(s.label) + ", not a label");
    if (const auto* ly = get("_Layer")) s.layer = parse_int(path, *ly, prefix + "_Layer");
    v.segments.push_back(s);
  }

}

// The detached data files ('data file', or 'LIST' lines), each checked to
// exist; empty for data attached after the header.
std::vector<std::string> data_files(const std::string& path, const Header& h) {
  std::vector<std::string> files;
  if (const auto* df = field(h, {"data file", "datafile"})) {
    const fs::path base = fs::path(path).parent_path();
    if (df->rfind("LIST", 0) == 0) {
      for (const auto& f : h.list_files)
        if (!f.empty()) files.push_back((base / f).string());
    } else if (split_ws(*df).size() > 1) {
      throw InputError(path, "NRRD 'data file' with a format pattern is not supported (use a single file or LIST)");
    } else {
      files.push_back((base / *df).string());
    }
    if (files.empty()) throw InputError(path, "'data file: LIST' names no file");
    // Named from the header the user gave, with the file it is missing.
    std::error_code ec;
    for (const auto& f : files)
      if (!fs::exists(f, ec)) throw InputError(path, "its data file " + f + " does not exist");
  } else if (h.detached_header) {
    throw InputError(path, "the NRRD header has no blank line and no 'data file' field");
  }
  return files;
}

}  // namespace

ScalarVolume read_nrrd(const std::string& path, uint64_t max_bytes, RawPayload* raw) {
  const Header h = parse_header(path);
  ScalarVolume v;
  v.source = path;
  const std::string* type = field(h, {"type"});
  const std::string* dimension = field(h, {"dimension"});
  const std::string* sizes = field(h, {"sizes"});
  const std::string* encoding = field(h, {"encoding"});
  if (!type || !dimension || !sizes || !encoding)
    throw InputError(path, "NRRD header lacks one of the required fields type, dimension, sizes, encoding");
  v.type = nrrd_type(path, *type);
  const int64_t dim = parse_int(path, *dimension, "dimension");
  const auto size_tokens = split_ws(*sizes);
  if (dim < 2 || dim > 4) throw InputError(path, "NRRD dimension " + std::to_string(dim) + " is not supported (2, 3 or 4)");
  if (int64_t(size_tokens.size()) != dim) throw InputError(path, "'sizes' does not list 'dimension' values");
  std::vector<int64_t> n;
  for (const auto& s : size_tokens) n.push_back(parse_int(path, s, "sizes"));
  read_geometry(path, h, dim, n, v);
  read_segments(path, h, v);

  // Payload.
  const size_t vs = scalar_size(v.type);
  const uint64_t count = checked_count(path, v.lattice.dims, v.components, vs);
  const uint64_t bytes = count * vs;
  if (!raw) check_limit(path, bytes, max_bytes, "the volume");  // streamed, it is read block by block
  const std::string enc = lower(*encoding);
  bool big = false;
  if (const auto* e = field(h, {"endian"})) big = lower(*e) == "big";
  int64_t line_skip = 0, byte_skip = 0;
  if (const auto* s = field(h, {"line skip", "lineskip"})) line_skip = parse_int(path, *s, "line skip");
  if (const auto* s = field(h, {"byte skip", "byteskip"})) byte_skip = parse_int(path, *s, "byte skip");
  // -1 (the data is the file's last bytes) is the one negative value NRRD
  // defines, for raw data only; -5 was read as 0 (issue 73).
  if (line_skip < 0) throw InputError(path, "'line skip' is " + std::to_string(line_skip) + " (must be 0 or more)");
  if (byte_skip < -1 || (byte_skip == -1 && enc != "raw"))
    throw InputError(path, "'byte skip' is " + std::to_string(byte_skip) +
                               (byte_skip == -1 ? " with " + enc + " encoding (-1 applies to raw data only)"
                                                : " (must be -1 or more)"));

  // Data sources: (file, offset) pairs; attached data lives after the header.
  const std::vector<std::string> files = data_files(path, h);
  const bool attached = files.empty();
  auto data_start = [&](const std::string& file) -> uint64_t {
    uint64_t off = attached ? h.data_offset : 0;
    if (line_skip > 0) {
      const auto buf = read_range(file, off, std::min<uint64_t>(file_size(file) - off, 1 << 20));
      int64_t lines = 0;
      size_t i = 0;
      while (i < buf.size() && lines < line_skip)
        if (buf[i++] == std::byte{'\n'}) ++lines;
      if (lines < line_skip) throw InputError(file, "cannot skip " + std::to_string(line_skip) + " lines");
      off += i;
    }
    return off;
  };

  if (raw) raw->parts.clear();
  if (raw && enc != "raw") return v;  // compressed or text: no box can be read without the rest
  if (enc == "raw") {
    if (files.size() > 1 && bytes % files.size()) throw InputError(path, "LIST files cannot split the data evenly");
    const uint64_t per_file = bytes / std::max<size_t>(files.size(), 1);
    const std::vector<std::string> sources = attached ? std::vector<std::string>{path} : files;
    std::vector<RawPayload::Part> parts;
    for (size_t f = 0; f < sources.size(); ++f) {
      const std::string& file = sources[f];
      const uint64_t off = data_part(file, file_size(file), data_start(file), byte_skip, per_file);
      parts.push_back({file, off, per_file});
    }
    if (raw) {
      raw->parts = std::move(parts);
      raw->big_endian = big && vs > 1;
      return v;
    }
    v.bytes.resize(bytes);
    for (size_t f = 0; f < parts.size(); ++f)
      read_range_into(parts[f].file, parts[f].offset, v.bytes.data() + f * per_file, per_file);
  } else if (enc == "gzip" || enc == "gz") {
    const std::vector<std::string> sources = attached ? std::vector<std::string>{path} : files;
    std::vector<std::byte> compressed;
    for (const auto& file : sources) {
      const uint64_t off = data_start(file) + uint64_t(std::max<int64_t>(byte_skip, 0));
      const uint64_t fsize = file_size(file);
      if (off >= fsize) throw InputError(file, "truncated: no compressed data after the header");
      check_limit(file, fsize - off, max_bytes, "the compressed payload");
      auto part = read_range(file, off, fsize - off);
      compressed.insert(compressed.end(), part.begin(), part.end());
    }
    v.bytes = inflate_grown(path, compressed.data(), compressed.size(), bytes);
  } else if (enc == "text" || enc == "txt" || enc == "ascii") {
    const std::vector<std::string> sources = attached ? std::vector<std::string>{path} : files;
    std::vector<std::pair<std::string, uint64_t>> parts;  // file, offset
    uint64_t text_bytes = 0;
    for (const auto& file : sources) {
      parts.push_back({file, data_start(file)});
      text_bytes += file_size(file) - parts.back().second;
    }
    // Each value takes a character and a separator: a payload shorter than
    // that cannot hold the declared values (issue 73: 100 bytes declaring 2^29
    // values allocated 538 MB before failing). The samples are allocated only then.
    if (count > (text_bytes + 1) / 2)
      throw InputError(path, "truncated: the text payload has " + std::to_string(text_bytes) +
                                 " bytes, too few for the " + std::to_string(count) +
                                 " values the header declares (at least 2 bytes each)");
    check_limit(path, text_bytes, max_bytes, "the text payload");
    std::string text;
    text.reserve(text_bytes + parts.size());
    for (const auto& [file, off] : parts) {
      const auto part = read_range(file, off, file_size(file) - off);
      text.append(reinterpret_cast<const char*>(part.data()), part.size());
      text.push_back('\n');
    }
    v.bytes.resize(bytes);
    parse_text(path, text, v);
    big = false;  // already native
  } else if (enc == "bzip2" || enc == "bz2" || enc == "hex") {
    throw InputError(path, "NRRD encoding '" + *encoding + "' is not supported (use raw, gzip or text)");
  } else {
    throw InputError(path, "unknown NRRD encoding '" + *encoding + "'");
  }
  if (big && vs > 1) swap_bytes(v.bytes.data(), count, vs);
  return v;
}

void write_nrrd(const std::string& path, const ScalarVolume& v, bool gzip) {
  std::ostringstream hdr;
  hdr.precision(17);
  const bool layered = v.components > 1;
  hdr << "NRRD0004\n# written by voxpress\n";
  hdr << "type: " << nrrd_type_name(v.type) << "\n";
  hdr << "dimension: " << (layered ? 4 : 3) << "\n";
  if (v.lattice.space == Space::LPS)
    hdr << "space: left-posterior-superior\n";
  else if (v.lattice.space == Space::RAS)
    hdr << "space: right-anterior-superior\n";
  else
    hdr << "space dimension: 3\n";
  hdr << "sizes:";
  if (layered) hdr << " " << v.components;
  for (int64_t d : v.lattice.dims) hdr << " " << d;
  hdr << "\nspace directions:";
  if (layered) hdr << " none";
  const Mat3 M = v.lattice.index_to_physical_matrix();
  for (int a = 0; a < 3; ++a) hdr << " (" << M(0, a) << "," << M(1, a) << "," << M(2, a) << ")";
  hdr << "\nkinds:" << (layered ? " list" : "") << " domain domain domain\n";
  hdr << "endian: little\n";
  hdr << "encoding: " << (gzip ? "gzip" : "raw") << "\n";
  hdr << "space origin: (" << v.lattice.origin.x() << "," << v.lattice.origin.y() << "," << v.lattice.origin.z() << ")\n";
  for (const auto& [key, value] : v.metadata) {
    if (key.find(":=") != std::string::npos || key.find('\n') != std::string::npos ||
        value.find('\n') != std::string::npos)
      continue;
    hdr << key << ":=" << value << "\n";
  }
  hdr << "\n";
  const std::string header = hdr.str();
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(header.data(), std::streamsize(header.size()));
    if (gzip) {
      const auto z = deflate_buffer(v.bytes.data(), v.bytes.size(), true);
      out.write(reinterpret_cast<const char*>(z.data()), std::streamsize(z.size()));
    } else {
      out.write(reinterpret_cast<const char*>(v.bytes.data()), std::streamsize(v.bytes.size()));
    }
  });
}

}  // namespace voxpress::detail
