// NIfTI-1 / NIfTI-2 through nifti_clib (nifti2_io reads both versions).
//
// Geometry: the sform when sform_code > 0, else the qform when qform_code > 0,
// else the pixdims (no orientation; "method 1" of the standard). Coordinates
// are RAS. Data scaling (scl_slope != 0 and not identity) is applied, giving
// float32 (or float64 for 64-bit input). Only 3-D data (a 4th dimension of 1)
// is accepted; RGB and complex types are refused.
//
// nifti_clib trusts the header: a dim[0] outside 1..7 makes it write past a
// stack array (found by bench/fuzz, docs/RELIABILITY.md). check_header()
// therefore validates the fields it indexes or sizes with before the file is
// handed to it.
#include <nifti2_io.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

struct NimDeleter {
  void operator()(nifti_image* n) const {
    if (n) nifti_image_free(n);
  }
};
using NimPtr = std::unique_ptr<nifti_image, NimDeleter>;

std::once_flag quiet_once;
void quiet() {
  std::call_once(quiet_once, [] { nifti_set_debug_level(0); });
}

ScalarType from_datatype(const std::string& path, int dt) {
  switch (dt) {
    case DT_UINT8: return ScalarType::u8;
    case DT_INT8: return ScalarType::i8;
    case DT_UINT16: return ScalarType::u16;
    case DT_INT16: return ScalarType::i16;
    case DT_UINT32: return ScalarType::u32;
    case DT_INT32: return ScalarType::i32;
    case DT_UINT64: return ScalarType::u64;
    case DT_INT64: return ScalarType::i64;
    case DT_FLOAT32: return ScalarType::f32;
    case DT_FLOAT64: return ScalarType::f64;
    default:
      throw InputError(path, std::string("unsupported NIfTI voxel type ") + nifti_datatype_string(dt) +
                                 " (integers and float32/64 only)");
  }
}

int to_datatype(ScalarType t) {
  switch (t) {
    case ScalarType::u8: return DT_UINT8;
    case ScalarType::i8: return DT_INT8;
    case ScalarType::u16: return DT_UINT16;
    case ScalarType::i16: return DT_INT16;
    case ScalarType::u32: return DT_UINT32;
    case ScalarType::i32: return DT_INT32;
    case ScalarType::u64: return DT_UINT64;
    case ScalarType::i64: return DT_INT64;
    case ScalarType::f32: return DT_FLOAT32;
    default: return DT_FLOAT64;
  }
}

// The first bytes of the file (gunzipped when compressed; gzread passes plain
// files through).
std::vector<unsigned char> head_bytes(const std::string& path, size_t n) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  std::vector<unsigned char> b(n);
  const int got = gzread(f, b.data(), unsigned(n));
  gzclose(f);
  b.resize(got > 0 ? size_t(got) : 0);
  return b;
}

template <class T>
T field(const std::vector<unsigned char>& b, size_t at, bool swap) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, b.data() + at, sizeof(T));
  if (swap) std::reverse(raw, raw + sizeof(T));
  T v;
  std::memcpy(&v, raw, sizeof(T));
  return v;
}

// Validates what nifti_clib relies on: the header size (and from it the
// version and byte order), dim[0] in 1..7, positive extents, a known data
// type and a sane data offset; and that no field placing or scaling the
// samples is infinite or NaN. Returns vox_offset.
uint64_t check_header(const std::string& path) {
  const auto b = head_bytes(path, 540);
  if (b.size() < 348) throw InputError(path, "truncated: too small for a NIfTI header");
  const int32_t size = field<int32_t>(b, 0, false), swapped = field<int32_t>(b, 0, true);
  const bool swap = size != 348 && size != 540;
  const int32_t hdr = swap ? swapped : size;
  if (hdr != 348 && hdr != 540)
    throw InputError(path, "not a NIfTI file (header size field is " + std::to_string(size) + ", expected 348 or 540)");
  if (hdr == 540 && b.size() < 540) throw InputError(path, "truncated: too small for a NIfTI-2 header");
  const bool v2 = hdr == 540;
  int64_t dim[8];
  for (int d = 0; d < 8; ++d)
    dim[d] = v2 ? field<int64_t>(b, 16 + 8 * size_t(d), swap) : field<int16_t>(b, 40 + 2 * size_t(d), swap);
  if (dim[0] < 1 || dim[0] > 7)
    throw InputError(path, "invalid NIfTI header: dim[0] is " + std::to_string(dim[0]) + " (must be 1 to 7)");
  for (int d = 1; d <= dim[0]; ++d)
    if (dim[d] < 1 || dim[d] > (int64_t(1) << 40))
      throw InputError(path, "invalid NIfTI header: dim[" + std::to_string(d) + "] is " + std::to_string(dim[d]));
  const int dt = field<int16_t>(b, v2 ? 12 : 70, swap);
  (void)from_datatype(path, dt);
  const double offset = v2 ? double(field<int64_t>(b, 168, swap)) : double(field<float>(b, 108, swap));
  if (!(offset >= 0 && offset < 0x1p40) || offset != std::floor(offset))
    throw InputError(path, "invalid NIfTI header: vox_offset is " + format_double(offset));
  // Every value that places or scales the samples must be a number: nifti_clib
  // would replace an infinite offset by 0 or drop a NaN scaling (issue 73).
  auto real = [&](size_t at1, size_t at2) { return v2 ? field<double>(b, at2, swap) : double(field<float>(b, at1, swap)); };
  auto require_finite = [&](const std::string& name, double x) {
    if (!std::isfinite(x)) throw InputError(path, "invalid NIfTI header: " + name + " is " + format_double(x));
  };
  for (int d = 1; d <= std::min<int64_t>(dim[0], 3); ++d)
    require_finite("pixdim[" + std::to_string(d) + "]", real(76 + 4 * size_t(d), 104 + 8 * size_t(d)));
  const char* axis = "xyz";
  for (size_t a = 0; a < 3; ++a) {
    require_finite(std::string("quatern_") + "bcd"[a], real(256 + 4 * a, 352 + 8 * a));
    require_finite(std::string("qoffset_") + axis[a], real(268 + 4 * a, 376 + 8 * a));
    for (size_t c = 0; c < 4; ++c)
      require_finite(std::string("srow_") + axis[a] + "[" + std::to_string(c) + "]",
                     real(280 + 16 * a + 4 * c, 400 + 32 * a + 8 * c));
  }
  // Scaling: a slope of 0 means none (the standard), as does nibabel's NaN
  // slope with a NaN or zero intercept; any other non-finite value is refused.
  const double slope = real(112, 176), inter = real(116, 184);
  const bool unscaled_nan = std::isnan(slope) && (std::isnan(inter) || inter == 0);
  if (!unscaled_nan) {
    require_finite("scl_slope", slope);
    if (slope != 0) require_finite("scl_inter", inter);
  }
  return uint64_t(offset);
}

// The samples of a gzipped single-file NIfTI, inflated by us rather than by
// nifti_clib's gzread, which accepted a stream without its CRC trailer and
// allocated the declared size up front: the payload must be able to hold the
// declared data (at most 1032:1), the buffer grows as the data arrives, and
// the stream must end with its check value (issue 73).
std::vector<std::byte> load_gzipped(const std::string& path, const nifti_image& nim, uint64_t count, size_t vs,
                                    uint64_t max_bytes) {
  const uint64_t fsize = file_size(path);
  check_limit(path, fsize, max_bytes, "the compressed file");
  const std::vector<std::byte> z = read_range(path, 0, fsize);
  const uint64_t offset = uint64_t(nim.iname_offset), bytes = count * vs;
  check_ratio(path, z.size(), offset + bytes);
  std::vector<std::byte> out;
  out.reserve(bytes);
  uint64_t at = 0;  // position in the inflated stream
  inflate_stream(path, z.data(), z.size(), offset + bytes, [&](const std::byte* p, size_t n) {
    const uint64_t lo = std::max(at, offset), hi = std::min(at + n, offset + bytes);
    if (lo < hi) out.insert(out.end(), p + (lo - at), p + (hi - at));
    at += n;
  }, true);  // bytes after the samples are ignored, as for a .nii
  if (nim.byteorder != nifti_short_order()) swap_bytes(out.data(), count, vs);
  return out;
}

bool gzipped(const std::string& path) {
  const auto b = read_range(path, 0, std::min<uint64_t>(file_size(path), 2));
  return b.size() == 2 && b[0] == std::byte{0x1f} && b[1] == std::byte{0x8b};
}

}  // namespace

ScalarVolume read_nifti(const std::string& path, uint64_t max_bytes) {
  quiet();
  const uint64_t fsize = file_size(path);
  const std::string ext = extension_of(path);
  if (ext != ".nii.gz" && fsize < 348) throw InputError(path, "truncated: too small for a NIfTI header");
  const uint64_t vox_offset = check_header(path);
  NimPtr nim(nifti_image_read(path.c_str(), 0));
  if (!nim) throw InputError(path, "not a readable NIfTI-1/2 file (bad or truncated header)");
  // nifti_clib reads from the end of the header when vox_offset does not fit
  // its int (1e12): the data would come from the wrong place (issue 73).
  const bool single = nim->iname && nim->fname && std::strcmp(nim->iname, nim->fname) == 0;
  if (single && vox_offset > uint64_t(nim->iname_offset))
    throw InputError(path, "invalid NIfTI header: vox_offset " + std::to_string(vox_offset) +
                               (ext == ".nii" && vox_offset > fsize ? " is beyond the end of the file (" +
                                                                          std::to_string(fsize) + " bytes)"
                                                                    : " cannot be honoured"));
  ScalarVolume v;
  v.source = path;
  for (int d = 4; d <= 7; ++d)
    if (nim->dim[0] >= d && nim->dim[d] > 1)
      throw InputError(path, "NIfTI with " + std::to_string(nim->dim[d]) + " volumes along dimension " +
                                 std::to_string(d) + " is not supported (3-D only)");
  v.type = from_datatype(path, nim->datatype);
  v.lattice.dims = {nim->nx, nim->dim[0] >= 2 ? nim->ny : 1, nim->dim[0] >= 3 ? nim->nz : 1};
  const size_t vs = scalar_size(v.type);
  const uint64_t count = checked_count(path, v.lattice.dims, 1, vs);
  if (uint64_t(nim->nvox) != count) throw InputError(path, "inconsistent NIfTI dimensions");
  check_limit(path, count * vs, max_bytes, "the volume");
  // For an uncompressed single file the payload size is known up front.
  if (ext == ".nii" && single) {
    const uint64_t need = uint64_t(nim->iname_offset) + count * vs;
    if (fsize < need)
      throw InputError(path, "truncated: the header declares " + std::to_string(count * vs) + " bytes of data at offset " +
                                 std::to_string(nim->iname_offset) + " but the file has " + std::to_string(fsize) +
                                 " bytes");
  }
  // Geometry.
  nifti_dmat44 m;
  if (nim->sform_code > 0) {
    m = nim->sto_xyz;
    v.lattice.space = Space::RAS;
  } else if (nim->qform_code > 0) {
    m = nim->qto_xyz;
    v.lattice.space = Space::RAS;
  } else {
    std::memset(&m, 0, sizeof m);
    m.m[0][0] = nim->dx > 0 ? nim->dx : 1;
    m.m[1][1] = nim->dy > 0 ? nim->dy : 1;
    m.m[2][2] = nim->dz > 0 ? nim->dz : 1;
  }
  for (int a = 0; a < 3; ++a) {
    Vec3 col(m.m[0][a], m.m[1][a], m.m[2][a]);
    const double len = col.norm();
    if (!(len > 0) || !std::isfinite(len)) throw InputError(path, "degenerate NIfTI orientation matrix");
    v.lattice.spacing[a] = len;
    v.lattice.direction.col(a) = col / len;
    v.lattice.origin[a] = m.m[a][3];
  }
  try {
    v.lattice.validate();
  } catch (const UsageError& e) {
    throw InputError(path, e.what());
  }
  std::vector<std::byte> data;
  if (single && gzipped(path)) {
    data = load_gzipped(path, *nim, count, vs, max_bytes);
  } else {
    if (nifti_image_load(nim.get()) != 0 || !nim->data)
      throw InputError(path, "truncated or corrupt NIfTI image data");
    data.assign(static_cast<const std::byte*>(nim->data), static_cast<const std::byte*>(nim->data) + count * vs);
    nifti_image_unload(nim.get());
  }
  const bool scaled = nim->scl_slope != 0 && std::isfinite(nim->scl_slope) &&
                      (nim->scl_slope != 1 || nim->scl_inter != 0);
  if (!scaled) {
    v.bytes = std::move(data);
    return v;
  }
  // Apply the scaling: y = slope * x + inter.
  ScalarVolume raw = v;
  raw.bytes = std::move(data);
  const double slope = nim->scl_slope, inter = nim->scl_inter;
  nim.reset();
  v.type = vs == 8 ? ScalarType::f64 : ScalarType::f32;
  v.bytes.resize(count * scalar_size(v.type));
  raw.visit([&](auto values) {
    if (v.type == ScalarType::f64) {
      auto* out = reinterpret_cast<double*>(v.bytes.data());
      for (uint64_t i = 0; i < count; ++i) out[i] = slope * double(values[i]) + inter;
    } else {
      auto* out = reinterpret_cast<float*>(v.bytes.data());
      for (uint64_t i = 0; i < count; ++i) out[i] = float(slope * double(values[i]) + inter);
    }
  });
  v.metadata["scl_slope"] = std::to_string(slope);
  v.metadata["scl_inter"] = std::to_string(inter);
  return v;
}

void write_nifti(const std::string& path, const ScalarVolume& v) {
  quiet();
  if (v.components != 1) throw UsageError("NIfTI output holds one component per sample");
  const int64_t dims[8] = {3, v.lattice.dims[0], v.lattice.dims[1], v.lattice.dims[2], 1, 1, 1, 1};
  NimPtr nim(nifti_make_new_nim(dims, to_datatype(v.type), 0));
  if (!nim) throw Error("nifti_clib could not create an image");
  // Physical transform in RAS.
  Mat3 M = v.lattice.index_to_physical_matrix();
  Vec3 o = v.lattice.origin;
  if (v.lattice.space == Space::LPS) {
    M.row(0) *= -1;
    M.row(1) *= -1;
    o.x() = -o.x();
    o.y() = -o.y();
  }
  nim->dx = nim->pixdim[1] = v.lattice.spacing[0];
  nim->dy = nim->pixdim[2] = v.lattice.spacing[1];
  nim->dz = nim->pixdim[3] = v.lattice.spacing[2];
  nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) nim->sto_xyz.m[r][c] = M(r, c);
    nim->sto_xyz.m[r][3] = o[r];
  }
  nim->sto_xyz.m[3][0] = nim->sto_xyz.m[3][1] = nim->sto_xyz.m[3][2] = 0;
  nim->sto_xyz.m[3][3] = 1;
  // Also a qform when the matrix is a rotation times spacing (the usual case).
  nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  nifti_dmat44_to_quatern(nim->sto_xyz, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x,
                          &nim->qoffset_y, &nim->qoffset_z, nullptr, nullptr, nullptr, &nim->qfac);
  nim->qto_xyz = nim->sto_xyz;
  write_atomically(path, [&](const std::string& tmp) {
    if (nifti_set_filenames(nim.get(), tmp.c_str(), 0, 1) != 0) throw InputError(path, "invalid NIfTI file name");
    nim->data = const_cast<std::byte*>(v.bytes.data());
    nifti_image_write(nim.get());
    nim->data = nullptr;
    std::error_code ec;
    if (!std::filesystem::exists(tmp, ec) || std::filesystem::file_size(tmp, ec) == 0)
      throw InputError(path, "nifti_clib failed to write the file");
  });
}

}  // namespace voxpress::detail
