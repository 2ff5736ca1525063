// HDF5 volumes (libhdf5's C API): one 3-D dataset of integers or floats,
// read whole or box by box with hyperslab selections, so chunked and
// compressed datasets stream (HDF5 decodes only the chunks a box touches).
//
// The dataset is FILE.h5:/path/in/file, or the only 3-D dataset of the file.
// HDF5 stores C order, (z, y, x) with x fastest: the samples' own order.
// Spacing: the attribute element_size_um (z, y, x), the convention of Fiji's
// HDF5 plugin, ilastik and BigDataViewer, in micrometres as written. voxpress
// also writes and reads `origin` (x, y, z) and `direction` (3x3, row-major,
// columns the axes), so its own files round-trip their lattice.
#include <hdf5.h>

#include <cstring>
#include <mutex>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {

namespace h5 {

// Every HDF5 call goes through this lock: VolumeFile::read is called from
// parallel blocks, and a libhdf5 built without thread safety needs it
// (Debian's is thread-safe, which serialises calls anyway).
std::mutex& hdf5_lock() {
  static std::mutex m;
  return m;
}

// An hid_t closed by its own close function.
struct Handle {
  hid_t id = H5I_INVALID_HID;
  herr_t (*close)(hid_t) = nullptr;
  Handle() = default;
  Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Handle() {
    if (id >= 0 && close) close(id);
  }
  Handle(Handle&& o) noexcept : id(o.id), close(o.close) { o.id = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    std::swap(id, o.id);
    std::swap(close, o.close);
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  explicit operator bool() const { return id >= 0; }
};

void h5_quiet() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }  // errors become exceptions, not stderr dumps

hid_t memory_type(ScalarType t) {
  switch (t) {
    case ScalarType::u8: return H5T_NATIVE_UINT8;
    case ScalarType::i8: return H5T_NATIVE_INT8;
    case ScalarType::u16: return H5T_NATIVE_UINT16;
    case ScalarType::i16: return H5T_NATIVE_INT16;
    case ScalarType::u32: return H5T_NATIVE_UINT32;
    case ScalarType::i32: return H5T_NATIVE_INT32;
    case ScalarType::u64: return H5T_NATIVE_UINT64;
    case ScalarType::i64: return H5T_NATIVE_INT64;
    case ScalarType::f32: return H5T_NATIVE_FLOAT;
    case ScalarType::f64: return H5T_NATIVE_DOUBLE;
  }
  return H5T_NATIVE_UINT8;
}

ScalarType scalar_type_of(const std::string& label, hid_t type) {
  const size_t size = H5Tget_size(type);
  switch (H5Tget_class(type)) {
    case H5T_INTEGER: {
      const bool sign = H5Tget_sign(type) == H5T_SGN_2;
      if (size == 1) return sign ? ScalarType::i8 : ScalarType::u8;
      if (size == 2) return sign ? ScalarType::i16 : ScalarType::u16;
      if (size == 4) return sign ? ScalarType::i32 : ScalarType::u32;
      if (size == 8) return sign ? ScalarType::i64 : ScalarType::u64;
      break;
    }
    case H5T_FLOAT:
      if (size == 4) return ScalarType::f32;
      if (size == 8) return ScalarType::f64;
      break;
    default: break;
  }
  throw InputError(label, "unsupported HDF5 sample type (integers of 1-8 bytes and 32/64-bit floats are)");
}

// Names of the 3-D datasets of a file, depth first.
herr_t collect(hid_t obj, const char* name, const H5O_info_t* info, void* out) {
  if (info->type != H5O_TYPE_DATASET) return 0;
  Handle ds(H5Dopen2(obj, name, H5P_DEFAULT), H5Dclose);
  if (!ds) return 0;
  Handle space(H5Dget_space(ds.id), H5Sclose);
  if (space && H5Sget_simple_extent_ndims(space.id) == 3)
    static_cast<std::vector<std::string>*>(out)->push_back(std::string("/") + name);
  return 0;
}

// Reads an attribute of `count` doubles if present; false when absent.
bool read_attribute(const std::string& label, hid_t ds, const char* name, double* out, size_t count) {
  if (H5Aexists(ds, name) <= 0) return false;
  Handle a(H5Aopen(ds, name, H5P_DEFAULT), H5Aclose);
  Handle space(a ? H5Aget_space(a.id) : H5I_INVALID_HID, H5Sclose);
  if (!space || H5Sget_simple_extent_npoints(space.id) != hssize_t(count))
    throw InputError(label, std::string("attribute ") + name + " must hold " + std::to_string(count) + " numbers");
  if (H5Aread(a.id, H5T_NATIVE_DOUBLE, out) < 0)
    throw InputError(label, std::string("attribute ") + name + " is not numeric");
  return true;
}

void write_attribute(hid_t ds, const char* name, const double* values, hsize_t count) {
  Handle space(H5Screate_simple(1, &count, nullptr), H5Sclose);
  Handle a(H5Acreate2(ds, name, H5T_IEEE_F64LE, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!a || H5Awrite(a.id, H5T_NATIVE_DOUBLE, values) < 0) throw Error("HDF5: cannot write attribute " + std::string(name));
}

}  // namespace h5

using namespace h5;

std::pair<std::string, std::string> split_hdf5_path(const std::string& path) {
  const std::string low = lower(path);
  for (const char* ext : {".h5:", ".hdf5:", ".hdf:"}) {
    const auto at = low.rfind(ext);
    if (at != std::string::npos) {
      const size_t end = at + std::strlen(ext) - 1;
      return {path.substr(0, end), path.substr(end + 1)};
    }
  }
  return {path, ""};
}

bool is_hdf5_path(const std::string& path) {
  const std::string ext = extension_of(split_hdf5_path(path).first);
  return ext == ".h5" || ext == ".hdf5" || ext == ".hdf";
}

struct Hdf5Dataset::Impl {
  Handle file, dataset, space;
};

Hdf5Dataset::Hdf5Dataset(const std::string& path) : impl_(std::make_unique<Impl>()) {
  auto [file, name] = split_hdf5_path(path);
  std::lock_guard lock(hdf5_lock());
  h5_quiet();
  file_size(file);  // missing, a folder, unreadable: the common message
  if (H5Fis_hdf5(file.c_str()) <= 0)
    throw InputError(file, "not an HDF5 file (or its superblock is damaged)");
  impl_->file = Handle(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!impl_->file) throw InputError(file, "cannot open the HDF5 file (damaged or truncated)");
  if (name.empty()) {
    std::vector<std::string> names;
    if (H5Ovisit2(impl_->file.id, H5_INDEX_NAME, H5_ITER_NATIVE, collect, &names, H5O_INFO_BASIC) < 0)
      throw InputError(file, "cannot list the datasets (damaged file)");
    if (names.empty()) throw InputError(file, "holds no 3-D dataset");
    if (names.size() > 1) {
      std::string list;
      for (size_t i = 0; i < names.size() && i < 8; ++i) list += (i ? ", " : "") + names[i];
      throw InputError(file, std::to_string(names.size()) + " 3-D datasets (" + list +
                                 "): name one as " + file + ":" + names[0]);
    }
    name = names[0];
  }
  source_ = file + ":" + name;
  impl_->dataset = Handle(H5Dopen2(impl_->file.id, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!impl_->dataset) throw InputError(file, "no dataset " + name);
  impl_->space = Handle(H5Dget_space(impl_->dataset.id), H5Sclose);
  if (!impl_->space || H5Sget_simple_extent_ndims(impl_->space.id) != 3)
    throw InputError(source_, "is not a 3-D dataset");
  hsize_t d[3];
  H5Sget_simple_extent_dims(impl_->space.id, d, nullptr);
  Handle type(H5Dget_type(impl_->dataset.id), H5Tclose);
  ScalarVolume& v = header;
  v.source = source_;
  v.type = scalar_type_of(source_, type.id);
  for (int a = 0; a < 3; ++a) {
    if (d[2 - a] < 1 || d[2 - a] > hsize_t(1) << 40) throw InputError(source_, "absurd dimension " + std::to_string(d[2 - a]));
    v.lattice.dims[a] = int64_t(d[2 - a]);
  }
  checked_count(source_, v.lattice.dims, 1, scalar_size(v.type));
  double zyx[3], origin[3], direction[9];
  if (read_attribute(source_, impl_->dataset.id, "element_size_um", zyx, 3))
    v.lattice.spacing = Vec3(zyx[2], zyx[1], zyx[0]);
  if (read_attribute(source_, impl_->dataset.id, "origin", origin, 3)) v.lattice.origin = Vec3(origin[0], origin[1], origin[2]);
  if (read_attribute(source_, impl_->dataset.id, "direction", direction, 9))
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) v.lattice.direction(r, c) = direction[3 * r + c];
  try {
    v.lattice.validate();
  } catch (const UsageError& e) {
    throw InputError(source_, std::string("invalid spacing or direction: ") + e.what());
  }
}

Hdf5Dataset::~Hdf5Dataset() {
  std::lock_guard lock(hdf5_lock());
  impl_.reset();
}

void Hdf5Dataset::read(const Box& box, std::byte* out) const {
  std::lock_guard lock(hdf5_lock());
  h5_quiet();
  const auto n = box.dims();
  hsize_t start[3], count[3];
  for (int a = 0; a < 3; ++a) {
    start[2 - a] = hsize_t(box.lo[a]);
    count[2 - a] = hsize_t(n[a]);
  }
  Handle file_space(H5Scopy(impl_->space.id), H5Sclose);
  Handle memory(H5Screate_simple(3, count, nullptr), H5Sclose);
  if (!file_space || !memory || H5Sselect_hyperslab(file_space.id, H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
      H5Dread(impl_->dataset.id, memory_type(header.type), memory.id, file_space.id, H5P_DEFAULT, out) < 0)
    throw InputError(source_, "cannot read the samples (truncated or damaged file)");
}

ScalarVolume read_hdf5(const std::string& path, uint64_t max_bytes) {
  Hdf5Dataset ds(path);
  ScalarVolume v = ds.header;
  const uint64_t bytes = v.lattice.size() * scalar_size(v.type);
  check_limit(v.source, bytes, max_bytes, "the samples");
  v.bytes.resize(bytes);
  ds.read(Box{{0, 0, 0}, v.lattice.dims}, v.bytes.data());
  return v;
}

void write_hdf5(const std::string& path, const ScalarVolume& v, bool compress) {
  if (v.components != 1) throw UsageError(path + ": HDF5 output holds one value per sample");
  const auto parts = split_hdf5_path(path);
  const std::string& file = parts.first;
  const std::string& name = parts.second;
  write_atomically(file, [&](const std::string& tmp) {
    std::lock_guard lock(hdf5_lock());
    h5_quiet();
    Handle f(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (!f) throw Error(file + ": cannot create the HDF5 file");
    const auto& d = v.lattice.dims;
    const hsize_t dims[3] = {hsize_t(d[2]), hsize_t(d[1]), hsize_t(d[0])};
    // Chunks of 64^3 (clipped) with gzip level 1: blocks read back without
    // decoding the whole volume, at about NRRD-gzip's size.
    const hsize_t chunk[3] = {std::min<hsize_t>(dims[0], 64), std::min<hsize_t>(dims[1], 64), std::min<hsize_t>(dims[2], 64)};
    Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_chunk(props.id, 3, chunk);
    if (compress) H5Pset_deflate(props.id, 1);
    Handle space(H5Screate_simple(3, dims, nullptr), H5Sclose);
    Handle links(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(links.id, 1);
    const std::string ds_name = name.empty() ? "/volume" : name;
    Handle type(H5Tcopy(memory_type(v.type)), H5Tclose);
    Handle ds(H5Dcreate2(f.id, ds_name.c_str(), type.id, space.id, links.id, props.id, H5P_DEFAULT), H5Dclose);
    if (!ds || H5Dwrite(ds.id, memory_type(v.type), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.bytes.data()) < 0)
      throw Error(file + ": cannot write the HDF5 dataset " + ds_name);
    const auto& s = v.lattice.spacing;
    const double zyx[3] = {s.z(), s.y(), s.x()};
    const double origin[3] = {v.lattice.origin.x(), v.lattice.origin.y(), v.lattice.origin.z()};
    double direction[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) direction[3 * r + c] = v.lattice.direction(r, c);
    write_attribute(ds.id, "element_size_um", zyx, 3);
    write_attribute(ds.id, "origin", origin, 3);
    write_attribute(ds.id, "direction", direction, 9);
  });
}

}  // namespace voxpress::detail
