#include "voxpress/io/volume_io.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "formats.h"
#include "io_util.h"

namespace voxpress {

uint64_t parse_byte_size(const std::string& text) {
  const std::string t = detail::trim(text);
  size_t i = 0;
  while (i < t.size() && (std::isdigit(static_cast<unsigned char>(t[i])) || t[i] == '.')) ++i;
  if (i == 0) throw UsageError("invalid size '" + text + "' (use e.g. 512M, 8G)");
  double v = 0;
  try {
    v = std::stod(t.substr(0, i));
  } catch (const std::exception&) {
    throw UsageError("invalid size '" + text + "'");
  }
  const std::string unit = detail::lower(t.substr(i));
  double mult = 1;
  if (unit.empty() || unit == "b")
    mult = 1;
  else if (unit == "k" || unit == "kb" || unit == "kib")
    mult = 1024.0;
  else if (unit == "m" || unit == "mb" || unit == "mib")
    mult = 1024.0 * 1024;
  else if (unit == "g" || unit == "gb" || unit == "gib")
    mult = 1024.0 * 1024 * 1024;
  else if (unit == "t" || unit == "tb" || unit == "tib")
    mult = 1024.0 * 1024 * 1024 * 1024;
  else
    throw UsageError("invalid size unit in '" + text + "' (use K, M, G or T)");
  const double bytes = v * mult;
  if (!(bytes >= 1) || bytes > 1e19) throw UsageError("invalid size '" + text + "'");
  return uint64_t(bytes);
}

uint64_t default_memory_limit() {
  if (const char* env = std::getenv("VOXPRESS_MAX_MEMORY"); env && *env) return parse_byte_size(env);
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page > 0) return uint64_t(pages) * uint64_t(page) / 4 * 3;
  return uint64_t(8) << 30;
}

ScalarType parse_scalar_type(const std::string& name) {
  static const std::map<std::string, ScalarType> names = {
      {"uint8", ScalarType::u8},   {"uchar", ScalarType::u8},   {"int8", ScalarType::i8},
      {"char", ScalarType::i8},    {"uint16", ScalarType::u16}, {"ushort", ScalarType::u16},
      {"int16", ScalarType::i16},  {"short", ScalarType::i16},  {"uint32", ScalarType::u32},
      {"uint", ScalarType::u32},   {"int32", ScalarType::i32},  {"int", ScalarType::i32},
      {"uint64", ScalarType::u64}, {"int64", ScalarType::i64},  {"float32", ScalarType::f32},
      {"float", ScalarType::f32},  {"float64", ScalarType::f64}, {"double", ScalarType::f64}};
  auto it = names.find(detail::lower(name));
  if (it == names.end())
    throw UsageError("unknown voxel type '" + name + "' (uint8 int8 uint16 int16 uint32 int32 uint64 int64 float32 float64)");
  return it->second;
}

namespace detail {

ScalarVolume read_raw(const std::string& path, const RawLayout& layout, uint64_t max_bytes, RawPayload* raw) {
  ScalarVolume v;
  v.source = path;
  v.type = layout.type;
  v.lattice.dims = layout.dims;
  v.lattice.spacing = layout.spacing;
  v.lattice.origin = layout.origin;
  try {
    v.lattice.validate();
  } catch (const UsageError& e) {
    throw UsageError(std::string("raw layout: ") + e.what());
  }
  const size_t vs = scalar_size(v.type);
  const uint64_t count = checked_count(path, v.lattice.dims, 1, vs);
  if (!raw) check_limit(path, count * vs, max_bytes, "the volume");
  const uint64_t fs = file_size(path);
  const uint64_t need = layout.header_bytes + count * vs;
  if (fs < need)
    throw InputError(path, "truncated: the raw layout needs " + std::to_string(need) + " bytes but the file has " +
                               std::to_string(fs));
  if (fs > need)
    throw InputError(path, "the file size does not match the raw layout: " + std::to_string(fs) + " bytes, " +
                               std::to_string(need) + " expected (check the dimensions, type and header bytes)");
  if (raw) {
    raw->parts = {{path, layout.header_bytes, count * vs}};
    raw->big_endian = layout.big_endian && vs > 1;
    return v;
  }
  v.bytes.resize(count * vs);
  read_range_into(path, layout.header_bytes, v.bytes.data(), count * vs);
  if (layout.big_endian) swap_bytes(v.bytes.data(), count, vs);
  return v;
}

}  // namespace detail

std::string file_extension(const std::string& path) { return detail::extension_of(path); }

ScalarVolume read_volume(const std::string& path, const ReadOptions& options) {
  const uint64_t cap = options.max_bytes ? options.max_bytes : default_memory_limit();
  if (options.raw) return detail::read_raw(path, *options.raw, cap);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return detail::read_tiff_folder(path, cap);
  if (detail::is_hdf5_path(path)) return detail::read_hdf5(path, cap);
  const std::string ext = detail::extension_of(path);
  if (ext == ".nrrd" || ext == ".nhdr" || ext == ".seg.nrrd" || ext == ".seg.nhdr") return detail::read_nrrd(path, cap);
  if (ext == ".nii" || ext == ".nii.gz" || ext == ".hdr") return detail::read_nifti(path, cap);
  if (ext == ".mha" || ext == ".mhd") return detail::read_metaimage(path, cap);
  if (ext == ".tif" || ext == ".tiff") return detail::read_tiff(path, cap);
  if (ext == ".raw" || ext == ".bin")
    throw UsageError(path + ": a raw file needs its layout: --raw-dims X,Y,Z and --raw-type T");
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "no such file");
  throw InputError(path, "unknown volume format '" + ext +
                             "' (supported: .nrrd .nhdr .seg.nrrd .nii .nii.gz .mha .mhd .tif .tiff .h5 .hdf5, a folder of "
                             "TIFF slices, .raw with --raw-dims)");
}

void write_volume(const std::string& path, const ScalarVolume& volume, const WriteVolumeOptions& options) {
  const std::string ext = detail::extension_of(path);
  if (volume.bytes.size() != volume.value_count() * scalar_size(volume.type))
    throw UsageError("write_volume: data size does not match the lattice");
  if (detail::is_hdf5_path(path)) return detail::write_hdf5(path, volume, options.compress);
  if (ext == ".nrrd" || ext == ".seg.nrrd") return detail::write_nrrd(path, volume, options.compress);
  if (ext == ".nii" || ext == ".nii.gz") return detail::write_nifti(path, volume);
  if (ext == ".mha") return detail::write_metaimage(path, volume, options.compress);
  if (ext == ".tif" || ext == ".tiff") return detail::write_tiff(path, volume);
  throw UsageError(path + ": cannot write volume format '" + ext + "' (use .nrrd, .nii, .nii.gz, .mha, .tif or .h5)");
}

}  // namespace voxpress
