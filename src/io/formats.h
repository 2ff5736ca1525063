// Per-format volume and mesh readers/writers (private); dispatch lives in
// volume_io.cpp and mesh_io.cpp.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/io/mesh_io.h"
#include "voxpress/io/volume_io.h"

namespace voxpress::detail {

/// Where a volume's raw (uncompressed) samples lie on disk, in order: what
/// VolumeFile reads boxes from.
struct RawPayload {
  struct Part {
    std::string file;
    uint64_t offset = 0, bytes = 0;
  };
  std::vector<Part> parts;  ///< empty: the payload is not raw (compressed, text)
  bool big_endian = false;  ///< the values need swapping
};

/// With `raw`, only the header is read (no bytes, no memory cap: the payload
/// is never loaded whole) and *raw tells where a raw payload lies.
ScalarVolume read_nrrd(const std::string& path, uint64_t max_bytes, RawPayload* raw = nullptr);
void write_nrrd(const std::string& path, const ScalarVolume& v, bool gzip);

ScalarVolume read_nifti(const std::string& path, uint64_t max_bytes);
void write_nifti(const std::string& path, const ScalarVolume& v);

ScalarVolume read_metaimage(const std::string& path, uint64_t max_bytes);
void write_metaimage(const std::string& path, const ScalarVolume& v, bool compress);

ScalarVolume read_tiff(const std::string& path, uint64_t max_bytes);
ScalarVolume read_tiff_folder(const std::string& path, uint64_t max_bytes);
void write_tiff(const std::string& path, const ScalarVolume& v);

/// HDF5: "FILE.h5:/dataset" names a dataset, "FILE.h5" means its only 3-D
/// dataset. split_hdf5_path gives {file, dataset or ""}.
std::pair<std::string, std::string> split_hdf5_path(const std::string& path);
bool is_hdf5_path(const std::string& path);
/// One open 3-D dataset: its header (lattice, type) and boxes read by
/// hyperslab (x fastest, `out` holds box.size() values). Thread-safe.
class Hdf5Dataset {
 public:
  explicit Hdf5Dataset(const std::string& path);
  ~Hdf5Dataset();
  ScalarVolume header;  ///< no bytes
  void read(const Box& box, std::byte* out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string source_;
};
ScalarVolume read_hdf5(const std::string& path, uint64_t max_bytes);
void write_hdf5(const std::string& path, const ScalarVolume& v, bool compress);

ScalarVolume read_raw(const std::string& path, const RawLayout& layout, uint64_t max_bytes, RawPayload* raw = nullptr);

Mesh read_ply(const std::string& path, uint64_t max_bytes);
void write_ply(const std::string& path, const Mesh& m, bool binary, Space space = Space::unknown);
Mesh read_obj(const std::string& path, uint64_t max_bytes);
void write_obj(const std::string& path, const Mesh& m);
Mesh read_stl(const std::string& path, uint64_t max_bytes);
void write_stl(const std::string& path, const Mesh& m, Space space = Space::unknown);
Mesh read_off(const std::string& path, uint64_t max_bytes);
void write_off(const std::string& path, const Mesh& m);
Mesh read_gltf(const std::string& path, uint64_t max_bytes, bool binary);
void write_gltf(const std::string& path, const Mesh& m, bool binary);
Mesh read_vtk(const std::string& path, uint64_t max_bytes);
void write_vtk(const std::string& path, const Mesh& m, bool binary, Space space);
Mesh read_vtp(const std::string& path, uint64_t max_bytes);
void write_vtp(const std::string& path, const Mesh& m, Space space);
void write_gltf_scene(const std::string& path, const std::vector<SceneMesh>& meshes, bool binary);

}  // namespace voxpress::detail
