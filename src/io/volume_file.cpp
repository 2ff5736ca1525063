// VolumeFile: boxes of a raw payload read with pread (no whole-volume
// buffer), or crops of a volume read whole when its encoding cannot stream.
#include "voxpress/io/volume_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "formats.h"
#include "io_util.h"

namespace voxpress {

namespace {

// Bytes of one plane's rows read in one call when the box is narrower than
// the volume: whole rows cost a few times the box's bytes in memory copies,
// far less than one system call per short row.
constexpr uint64_t kPlaneSpanBytes = uint64_t(4) << 20;

}  // namespace

struct VolumeFile::Impl {
  struct Fd {
    int fd = -1;
    explicit Fd(const std::string& path) : fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
      if (fd < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
    }
    ~Fd() {
      if (fd >= 0) ::close(fd);
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
  };
  ScalarVolume header;
  detail::RawPayload raw;
  std::vector<std::unique_ptr<Fd>> fds;  // one per part
  std::vector<uint64_t> starts;          // logical offset of each part
  ScalarVolume whole;                    // when the payload does not stream
  std::unique_ptr<detail::Hdf5Dataset> h5;

  // Logical bytes [offset, offset + size) of the payload.
  void read_bytes(uint64_t offset, uint64_t size, std::byte* out) const {
    size_t p = size_t(std::upper_bound(starts.begin(), starts.end(), offset) - starts.begin()) - 1;
    while (size > 0) {
      const auto& part = raw.parts[p];
      const uint64_t in_part = offset - starts[p];
      const uint64_t n = std::min(size, part.bytes - in_part);
      uint64_t done = 0;
      while (done < n) {
        const ssize_t got = ::pread(fds[p]->fd, out + done, n - done, off_t(part.offset + in_part + done));
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0)
          throw InputError(part.file, got < 0 ? std::string("read failed: ") + std::strerror(errno)
                                              : std::string("truncated while reading (did the file change?)"));
        done += uint64_t(got);
      }
      out += n;
      offset += n;
      size -= n;
      ++p;
    }
  }
};

VolumeFile::VolumeFile(const std::string& path, const ReadOptions& options) : impl_(std::make_unique<Impl>()) {
  const std::string ext = detail::extension_of(path);
  std::error_code ec;
  const bool nrrd = ext == ".nrrd" || ext == ".nhdr" || ext == ".seg.nrrd" || ext == ".seg.nhdr";
  if (!options.raw && detail::is_hdf5_path(path)) {
    impl_->h5 = std::make_unique<detail::Hdf5Dataset>(path);
    impl_->header = impl_->h5->header;
    return;
  }
  if (options.raw && !std::filesystem::is_directory(path, ec)) {
    impl_->header = detail::read_raw(path, *options.raw, 0, &impl_->raw);
  } else if (nrrd && !std::filesystem::is_directory(path, ec)) {
    impl_->header = detail::read_nrrd(path, 0, &impl_->raw);
  }
  if (impl_->raw.parts.empty()) {  // not streamable: read whole, keep the header apart
    impl_->whole = read_volume(path, options);
    std::swap(impl_->whole.bytes, impl_->header.bytes);  // the header without copying the samples
    impl_->header = impl_->whole;
    std::swap(impl_->whole.bytes, impl_->header.bytes);
    return;
  }
  uint64_t start = 0;
  for (const auto& part : impl_->raw.parts) {
    impl_->fds.push_back(std::make_unique<Impl::Fd>(part.file));
    impl_->starts.push_back(start);
    start += part.bytes;
  }
}

VolumeFile::~VolumeFile() = default;
VolumeFile::VolumeFile(VolumeFile&&) noexcept = default;
VolumeFile& VolumeFile::operator=(VolumeFile&&) noexcept = default;

const ScalarVolume& VolumeFile::header() const { return impl_->header; }
bool VolumeFile::streams() const { return impl_->h5 != nullptr || !impl_->raw.parts.empty(); }

ScalarVolume VolumeFile::read(const Box& box) const {
  const ScalarVolume& h = impl_->header;
  const auto& n = h.lattice.dims;
  for (int a = 0; a < 3; ++a)
    if (box.lo[a] < 0 || box.hi[a] > n[a] || box.lo[a] >= box.hi[a])
      throw UsageError("VolumeFile::read: the box lies outside " + h.source);
  ScalarVolume v;
  v.lattice = box_lattice(h.lattice, box);
  v.type = h.type;
  v.components = h.components;
  v.segments = h.segments;
  v.source = h.source;
  const uint64_t value = uint64_t(h.components) * scalar_size(h.type);  // bytes per sample
  const auto d = box.dims();
  const uint64_t row = uint64_t(d[0]) * value;
  v.bytes.resize(box.size() * value);
  if (impl_->h5) {
    impl_->h5->read(box, v.bytes.data());
    return v;
  }
  const std::byte* src_whole = impl_->whole.bytes.data();
  auto at = [&](int64_t i, int64_t j, int64_t k) { return ((uint64_t(k) * uint64_t(n[1]) + uint64_t(j)) * uint64_t(n[0]) + uint64_t(i)) * value; };
  std::byte* out = v.bytes.data();
  const uint64_t span = at(0, box.hi[1], 0) - at(0, box.lo[1], 0);  // one plane's rows of the box, whole
  std::vector<std::byte> plane(streams() && span <= kPlaneSpanBytes && d[0] < n[0] ? span : 0);
  for (int64_t k = box.lo[2]; k < box.hi[2]; ++k) {
    if (!streams()) {
      for (int64_t j = box.lo[1]; j < box.hi[1]; ++j, out += row) std::memcpy(out, src_whole + at(box.lo[0], j, k), row);
    } else if (!plane.empty()) {
      impl_->read_bytes(at(0, box.lo[1], k), span, plane.data());
      for (int64_t j = box.lo[1]; j < box.hi[1]; ++j, out += row)
        std::memcpy(out, plane.data() + at(box.lo[0], j, 0) - at(0, box.lo[1], 0), row);
    } else if (d[0] == n[0]) {  // whole rows: the plane's part of the box is contiguous
      impl_->read_bytes(at(0, box.lo[1], k), row * uint64_t(d[1]), out);
      out += row * uint64_t(d[1]);
    } else {
      for (int64_t j = box.lo[1]; j < box.hi[1]; ++j, out += row) impl_->read_bytes(at(box.lo[0], j, k), row, out);
    }
  }
  if (impl_->raw.big_endian) detail::swap_bytes(v.bytes.data(), box.size() * uint64_t(h.components), scalar_size(h.type));
  return v;
}

}  // namespace voxpress
