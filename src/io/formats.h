// Per-format volume and mesh readers/writers (private); dispatch lives in
// volume_io.cpp and mesh_io.cpp.
#pragma once

#include <string>
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

ScalarVolume read_raw(const std::string& path, const RawLayout& layout, uint64_t max_bytes, RawPayload* raw = nullptr);

Mesh read_ply(const std::string& path, uint64_t max_bytes);
void write_ply(const std::string& path, const Mesh& m, bool binary);
Mesh read_obj(const std::string& path, uint64_t max_bytes);
void write_obj(const std::string& path, const Mesh& m);
Mesh read_stl(const std::string& path, uint64_t max_bytes);
void write_stl(const std::string& path, const Mesh& m);
Mesh read_off(const std::string& path, uint64_t max_bytes);
void write_off(const std::string& path, const Mesh& m);
Mesh read_gltf(const std::string& path, uint64_t max_bytes, bool binary);
void write_gltf(const std::string& path, const Mesh& m, bool binary);

}  // namespace voxpress::detail
