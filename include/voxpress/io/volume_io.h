// voxpress/io/volume_io.h — reading and writing volumes.
//
// Formats (chosen by extension, case-insensitive):
//   .nrrd .nhdr .seg.nrrd  NRRD: raw, gzip and text encodings, attached or
//                          detached data (single file or LIST), 3D Slicer
//                          segmentations (label maps and 4-D layered files)
//   .nii .nii.gz .hdr      NIfTI-1 and NIfTI-2 (nifti_clib); sform, else qform
//   .mha .mhd              MetaImage: LOCAL or separate data file, zlib compression
//   .tif .tiff             multi-page 3D TIFF (one page per slice, ImageJ spacing)
//   .h5 .hdf5              HDF5: FILE.h5:/dataset, or the file's only 3-D
//                          dataset; spacing from element_size_um (z, y, x)
//   a folder               2D TIFF slices, sorted by the numbers in their names
//   .raw .bin              raw samples, layout given by RawLayout
// Voxel types: 8/16/32/64-bit signed and unsigned integers, 32/64-bit float.
// Spacing, origin and direction are read into the Lattice; NRRD and
// MetaImage live in LPS space, NIfTI in RAS (lattice.space says which).
//
// Every reader validates the header and checks the payload size against the
// memory cap *before* allocating, never inflates more than the header
// declares, and throws InputError / LimitError naming the file and the problem.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "voxpress/core/volume.h"

namespace voxpress {

/// Layout of a headerless raw file.
struct RawLayout {
  std::array<int64_t, 3> dims{0, 0, 0};
  ScalarType type = ScalarType::u8;
  Vec3 spacing{1, 1, 1};
  Vec3 origin{0, 0, 0};
  bool big_endian = false;
  uint64_t header_bytes = 0;  ///< bytes to skip before the samples
};

struct ReadOptions {
  uint64_t max_bytes = 0;           ///< memory cap for the payload; 0 = default_memory_limit()
  std::optional<RawLayout> raw;     ///< required for .raw/.bin; makes any path read as raw
};

/// The default memory cap: VOXPRESS_MAX_MEMORY if set (e.g. "8G"), else 3/4
/// of the machine's physical memory.
uint64_t default_memory_limit();
/// Parses "123", "512K", "64M", "8G", "1T" (binary units). Throws UsageError.
uint64_t parse_byte_size(const std::string& text);
/// Parses a voxel type name: uint8 int8 uint16 int16 uint32 int32 uint64 int64
/// float32 float64 (and the aliases uchar, short, float, double ...).
ScalarType parse_scalar_type(const std::string& name);

/// Reads a volume; the format follows from the extension (or options.raw).
/// A path's lower-case extension, the compound ones (.nii.gz, .seg.nrrd,
/// .seg.nhdr) whole, "" when it has none: the rule every reader and writer
/// dispatches on.
std::string file_extension(const std::string& path);

ScalarVolume read_volume(const std::string& path, const ReadOptions& options = {});

struct WriteVolumeOptions {
  bool compress = true;  ///< gzip for NRRD and .nii.gz is implied by the name; zlib for .mha
};

/// Writes a volume (NRRD, NIfTI, MetaImage, multi-page TIFF or HDF5 by extension),
/// atomically: a failed write leaves no file behind.
void write_volume(const std::string& path, const ScalarVolume& volume, const WriteVolumeOptions& options = {});

}  // namespace voxpress
