// voxpress/io/volume_file.h — a volume file read box by box (press --chunk).
//
// Opening reads the header only. Raw (uncompressed) NRRD — attached,
// detached or a LIST of files — and headerless .raw files stream: reading a
// box costs that box's bytes (one read per plane, or per row when a plane's
// rows are long), so memory is bounded by the box, not the volume. Other
// files (gzip or text NRRD, NIfTI, MetaImage, TIFF) cannot be read in part
// without decoding what precedes it: they are read whole at open, within the
// memory cap, and streams() is false.
#pragma once

#include <memory>
#include <string>

#include "voxpress/core/volume.h"
#include "voxpress/io/volume_io.h"

namespace voxpress {

class VolumeFile {
 public:
  /// Throws what read_volume throws for a bad header or a truncated payload.
  explicit VolumeFile(const std::string& path, const ReadOptions& options = {});
  ~VolumeFile();
  VolumeFile(VolumeFile&&) noexcept;
  VolumeFile& operator=(VolumeFile&&) noexcept;

  /// Lattice, type, components, segments and metadata; no bytes.
  const ScalarVolume& header() const;
  /// True when boxes are read from disk as asked (the payload is raw).
  bool streams() const;
  /// The samples of `box` (inside the volume, UsageError otherwise) as a
  /// volume of the box's size placed where the box lies. Thread-safe.
  ScalarVolume read(const Box& box) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxpress
