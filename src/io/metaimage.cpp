// MetaImage (.mha / .mhd) reader and writer.
//
// Header lines "Key = Value" up to ElementDataFile, which must come last:
// LOCAL (data follows in the same file), a file name relative to the header,
// or LIST (one file per slice on the following lines). CompressedData = True
// means a zlib stream. TransformMatrix lists the direction of index axis 0,
// then 1, then 2 (ITK's convention); coordinates are LPS (ITK's physical space).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

ScalarType met_type(const std::string& path, const std::string& t) {
  static const std::map<std::string, ScalarType> types = {
      {"MET_UCHAR", ScalarType::u8},   {"MET_CHAR", ScalarType::i8},    {"MET_USHORT", ScalarType::u16},
      {"MET_SHORT", ScalarType::i16},  {"MET_UINT", ScalarType::u32},   {"MET_INT", ScalarType::i32},
      {"MET_ULONG", ScalarType::u32},  {"MET_LONG", ScalarType::i32},   {"MET_ULONG_LONG", ScalarType::u64},
      {"MET_LONG_LONG", ScalarType::i64}, {"MET_FLOAT", ScalarType::f32}, {"MET_DOUBLE", ScalarType::f64}};
  auto it = types.find(t);
  if (it == types.end()) throw InputError(path, "unsupported MetaImage ElementType '" + t + "'");
  return it->second;
}

const char* met_name(ScalarType t) {
  switch (t) {
    case ScalarType::u8: return "MET_UCHAR";
    case ScalarType::i8: return "MET_CHAR";
    case ScalarType::u16: return "MET_USHORT";
    case ScalarType::i16: return "MET_SHORT";
    case ScalarType::u32: return "MET_UINT";
    case ScalarType::i32: return "MET_INT";
    case ScalarType::u64: return "MET_ULONG_LONG";
    case ScalarType::i64: return "MET_LONG_LONG";
    case ScalarType::f32: return "MET_FLOAT";
    default: return "MET_DOUBLE";
  }
}

bool truthy(const std::string& s) {
  const std::string l = lower(s);
  return l == "true" || l == "1" || l == "yes";
}

std::vector<double> numbers(const std::string& path, const std::string& s, const std::string& key) {
  std::vector<double> out;
  for (const auto& t : split_ws(s)) out.push_back(parse_double(path, t, key));
  return out;
}

// The header's "Key = Value" lines up to ElementDataFile (keys lower-cased),
// the LIST's file names, and where LOCAL data starts.
struct MetaHeader {
  std::map<std::string, std::string> kv;
  std::vector<std::string> list_files;
  uint64_t data_offset = 0;
  const std::string* get(const char* k) const {
    const auto it = kv.find(k);
    return it == kv.end() ? nullptr : &it->second;
  }
};

MetaHeader read_header(const std::string& path) {
  const uint64_t fsize = file_size(path);
  const auto head = read_range(path, 0, std::min<uint64_t>(fsize, 1 << 20));
  const std::string text(reinterpret_cast<const char*>(head.data()), head.size());
  MetaHeader h;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = std::min(end + 1, text.size());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw InputError(path, "malformed MetaImage header line '" + line + "'");
    const std::string key = lower(trim(line.substr(0, eq)));
    const std::string value = trim(line.substr(eq + 1));
    h.kv[key] = value;
    if (key != "elementdatafile") continue;
    h.data_offset = pos;
    if (value.rfind("LIST", 0) == 0)
      while (pos < text.size()) {
        size_t e = text.find('\n', pos);
        if (e == std::string::npos) e = text.size();
        const std::string f = trim(text.substr(pos, e - pos));
        pos = std::min(e + 1, text.size());
        if (!f.empty()) h.list_files.push_back(f);
      }
    return h;
  }
  throw InputError(path, "not a MetaImage file (no ElementDataFile line)");
}

// The lattice and the sample type.
void read_geometry(const std::string& path, const MetaHeader& h, ScalarVolume& v) {
  v.lattice.space = Space::LPS;
  const std::string* ndims = h.get("ndims");
  const std::string* dimsize = h.get("dimsize");
  const std::string* etype = h.get("elementtype");
  if (!ndims || !dimsize || !etype) throw InputError(path, "MetaImage header lacks NDims, DimSize or ElementType");
  const int64_t nd = parse_int(path, *ndims, "NDims");
  if (nd < 2 || nd > 3) throw InputError(path, "MetaImage with NDims = " + std::to_string(nd) + " is not supported");
  const auto ds = numbers(path, *dimsize, "DimSize");
  if (int64_t(ds.size()) != nd) throw InputError(path, "DimSize does not list NDims values");
  for (int a = 0; a < 3; ++a) {
    const double d = a < nd ? ds[size_t(a)] : 1;
    if (!whole_in(d, 1, 0x1p40))
      throw InputError(path, "DimSize values must be whole numbers from 1 to 2^40");
    v.lattice.dims[size_t(a)] = int64_t(d);
  }
  if (const auto* ch = h.get("elementnumberofchannels"); ch && parse_int(path, *ch, "ElementNumberOfChannels") != 1)
    throw InputError(path, "multi-channel MetaImage is not supported");
  v.type = met_type(path, *etype);
  const std::string* sp = h.get("elementspacing");
  if (!sp) sp = h.get("elementsize");
  if (sp) {
    const auto s = numbers(path, *sp, "ElementSpacing");
    for (int a = 0; a < std::min<int>(int(nd), int(s.size())); ++a) v.lattice.spacing[a] = s[size_t(a)];
  }
  for (const char* k : {"offset", "origin", "position"})
    if (const auto* o = h.get(k)) {
      const auto s = numbers(path, *o, "Offset");
      for (int a = 0; a < std::min<int>(int(nd), int(s.size())); ++a) v.lattice.origin[a] = s[size_t(a)];
      break;
    }
  for (const char* k : {"transformmatrix", "rotation", "orientation"})
    if (const auto* t = h.get(k)) {
      const auto s = numbers(path, *t, "TransformMatrix");
      if (int64_t(s.size()) != nd * nd) throw InputError(path, "TransformMatrix must have NDims^2 values");
      for (int a = 0; a < nd; ++a)
        for (int r = 0; r < nd; ++r) v.lattice.direction(r, a) = s[size_t(a * nd + r)];
      if (nd == 2) v.lattice.direction.col(2) = Vec3::UnitZ();
      break;
    }
  try {
    v.lattice.validate();
  } catch (const UsageError& e) {
    throw InputError(path, e.what());
  }
}

// The files the data is in, each with the offset where its part starts
// (before HeaderSize), every one present.
std::vector<std::pair<std::string, uint64_t>> data_sources(const std::string& path, const MetaHeader& h) {
  const std::string& df = *h.get("elementdatafile");
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  std::vector<std::pair<std::string, uint64_t>> sources;  // file, offset
  if (df == "LOCAL") {
    sources.push_back({path, h.data_offset});
  } else if (df.rfind("LIST", 0) == 0) {
    for (const auto& f : h.list_files) sources.push_back({(base / f).string(), 0});
    if (sources.empty()) throw InputError(path, "ElementDataFile = LIST names no file");
  } else if (split_ws(df).size() > 1) {
    throw InputError(path, "MetaImage ElementDataFile patterns are not supported");
  } else {
    sources.push_back({(base / df).string(), 0});
  }
  // Named from the header the user gave, with the file it is missing (an MHD
  // named only its data file).
  for (const auto& src : sources)
    if (std::error_code ec; !std::filesystem::exists(src.first, ec))
      throw InputError(path, "its data file " + src.first + " does not exist");
  return sources;
}

// `bytes` of raw data from the sources: each holds an equal part, after
// HeaderSize bytes (-1: the part ends the file), and exactly that much.
void read_raw(const std::string& path, const std::vector<std::pair<std::string, uint64_t>>& sources,
              int64_t header_size, uint64_t bytes, std::vector<std::byte>& out) {
  out.resize(bytes);
  if (sources.size() > 1 && bytes % sources.size()) throw InputError(path, "LIST files cannot split the data evenly");
  const uint64_t per = bytes / sources.size();
  for (size_t i = 0; i < sources.size(); ++i) {
    const auto& [file, off0] = sources[i];
    const uint64_t off = data_part(file, file_size(file), off0, header_size, per);
    read_range_into(file, off, out.data() + i * per, per);
  }
}

// The zlib stream the sources hold one after the other (CompressedDataSize
// may cut it), inflated to exactly `bytes`.
void read_compressed(const std::string& path, const MetaHeader& h,
                     const std::vector<std::pair<std::string, uint64_t>>& sources, uint64_t bytes, uint64_t max_bytes,
                     std::vector<std::byte>& out) {
  std::vector<std::byte> z;
  for (const auto& [file, off] : sources) {
    const uint64_t fs = file_size(file);
    if (off >= fs) throw InputError(file, "truncated: no compressed data");
    check_limit(file, fs - off, max_bytes, "the compressed payload");
    auto part = read_range(file, off, fs - off);
    z.insert(z.end(), part.begin(), part.end());
  }
  if (const auto* cs = h.get("compresseddatasize")) {
    const int64_t n = parse_int(path, *cs, "CompressedDataSize");
    if (n > 0 && uint64_t(n) < z.size()) z.resize(size_t(n));
  }
  out = inflate_grown(path, z.data(), z.size(), bytes);
}

}  // namespace

ScalarVolume read_metaimage(const std::string& path, uint64_t max_bytes) {
  const MetaHeader h = read_header(path);
  ScalarVolume v;
  v.source = path;
  read_geometry(path, h, v);
  const size_t vs = scalar_size(v.type);
  const uint64_t count = checked_count(path, v.lattice.dims, 1, vs);
  const uint64_t bytes = count * vs;
  check_limit(path, bytes, max_bytes, "the volume");
  bool big = false;
  for (const char* k : {"binarydatabyteordermsb", "elementbyteordermsb"})
    if (const auto* b = h.get(k)) big = truthy(*b);
  const bool compressed = h.get("compresseddata") && truthy(*h.get("compresseddata"));
  // ASCII data (BinaryData = False) was refused as "data size does not match" (issue 73).
  if (const auto* bd = h.get("binarydata"); bd && !truthy(*bd))
    throw InputError(path, "BinaryData = " + *bd + ": text (ASCII) MetaImage data is not supported");
  int64_t header_size = 0;
  if (const auto* hs = h.get("headersize")) header_size = parse_int(path, *hs, "HeaderSize");
  if (header_size < -1) throw InputError(path, "HeaderSize is " + std::to_string(header_size) + " (must be -1 or more)");
  const auto sources = data_sources(path, h);
  if (compressed)
    read_compressed(path, h, sources, bytes, max_bytes, v.bytes);
  else
    read_raw(path, sources, header_size, bytes, v.bytes);
  if (big && vs > 1) swap_bytes(v.bytes.data(), count, vs);
  return v;
}

void write_metaimage(const std::string& path, const ScalarVolume& v, bool compress) {
  if (v.components != 1) throw UsageError("MetaImage output holds one component per sample");
  if (extension_of(path) != ".mha") throw UsageError("voxpress writes MetaImage as a single .mha file");
  std::vector<std::byte> z;
  if (compress) z = deflate_buffer(v.bytes.data(), v.bytes.size(), false);
  std::ostringstream h;
  h.precision(17);
  h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n";
  h << "CompressedData = " << (compress ? "True" : "False") << "\n";
  if (compress) h << "CompressedDataSize = " << z.size() << "\n";
  h << "TransformMatrix =";
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) h << " " << v.lattice.direction(r, a);
  h << "\nOffset = " << v.lattice.origin.x() << " " << v.lattice.origin.y() << " " << v.lattice.origin.z() << "\n";
  h << "ElementSpacing = " << v.lattice.spacing.x() << " " << v.lattice.spacing.y() << " " << v.lattice.spacing.z()
    << "\n";
  h << "DimSize = " << v.lattice.dims[0] << " " << v.lattice.dims[1] << " " << v.lattice.dims[2] << "\n";
  h << "ElementType = " << met_name(v.type) << "\nElementDataFile = LOCAL\n";
  const std::string header = h.str();
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(header.data(), std::streamsize(header.size()));
    const auto& data = compress ? z : v.bytes;
    out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  });
}

}  // namespace voxpress::detail
