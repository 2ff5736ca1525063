// Shared helpers of the readers and writers (private).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "voxpress/core/error.h"
#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"

namespace voxpress::detail {

/// Lower-case extension including compound ones: ".nii.gz", ".seg.nrrd", ".nrrd".
std::string extension_of(const std::string& path);
std::string lower(std::string s);
std::string trim(std::string_view s);
std::vector<std::string> split_ws(std::string_view s);

/// Size of a regular file; throws InputError (missing, directory, unreadable).
uint64_t file_size(const std::string& path);
/// Reads [offset, offset + size) of a file; throws InputError naming `label`
/// when the file is shorter.
std::vector<std::byte> read_range(const std::string& path, uint64_t offset, uint64_t size);
/// A whole file, refused with LimitError(path, ...) above `cap` bytes.
std::vector<std::byte> read_whole_file(const std::string& path, uint64_t cap, const std::string& what);
void read_range_into(const std::string& path, uint64_t offset, std::byte* out, uint64_t size);

/// Inflates a gzip or zlib stream (auto-detected, multi-member gzip allowed)
/// into exactly `expected` bytes without ever writing more: a stream that
/// holds fewer bytes is "truncated", one that holds more is a size mismatch.
/// Throws InputError(path, ...).
/// A payload that cannot hold `expected` bytes (kMaxDeflateRatio:1) is refused.
void check_ratio(const std::string& path, size_t in_size, uint64_t expected);
/// Inflates a gzip or zlib stream (auto-detected; gzip members may follow one
/// another), handing the output to `sink` in pieces of at most 1 MiB. Throws
/// InputError(path, ...) when the stream holds fewer than `expected` bytes, is
/// corrupt, ends before its end marker and check value (a gzip without its
/// CRC trailer was accepted), or — unless `more_allowed` — holds more (before
/// passing them on).
void inflate_stream(const std::string& path, const std::byte* in, size_t in_size, uint64_t expected,
                    const std::function<void(const std::byte*, size_t)>& sink, bool more_allowed);
/// A payload that cannot hold `expected` bytes (deflate expands at most
/// kMaxDeflateRatio:1) and a stream ending before its end marker and check
/// value (a gzip without its CRC trailer) are refused too.
void inflate_exact(const std::string& path, const std::byte* in, size_t in_size, std::byte* out, uint64_t expected);
/// The same into a new buffer whose memory follows the data as it arrives
/// (reserved, not filled); a gzip whose length trailer is not `expected` is
/// first inflated without keeping anything, so a payload holding more or
/// less than declared is refused before the buffer exists.
std::vector<std::byte> inflate_grown(const std::string& path, const std::byte* in, size_t in_size, uint64_t expected);
inline constexpr uint64_t kMaxDeflateRatio = 1032;
/// gzip (wrapper = 16 + 15) or zlib (15) compression of a buffer.
std::vector<std::byte> deflate_buffer(const std::byte* in, size_t size, bool gzip_wrapper, int level = 1);

/// A textured mesh as the closed solid, for formats that keep no texture
/// (PLY, OFF, VTK, VTP): no uvs or texture, the vertices split at chart
/// seams welded back.
Mesh welded_solid(const Mesh& m);

/// Reverses the byte order of `count` values of `width` bytes in place.
void swap_bytes(std::byte* data, uint64_t count, size_t width);

/// A whole number in [lo, hi]: what a count or an index read as a double
/// must be before it is converted to an integer (NaN never is).
inline bool whole_in(double x, double lo, double hi) { return x >= lo && x <= hi && x == std::floor(x); }

/// A size for a message: "12 MiB", "3 KiB" or "100 bytes".
std::string format_bytes(uint64_t bytes);
/// Throws LimitError(path, ...) if `bytes` exceeds the cap (0 = no cap).
void check_limit(const std::string& path, uint64_t bytes, uint64_t cap, const std::string& what);
/// Where a part of `per` bytes of raw data starts in `file` (fsize bytes):
/// `skip` bytes past `start`, or with skip -1 the file's last `per` bytes
/// (NRRD's byte skip, MetaImage's HeaderSize). Throws InputError naming the
/// file unless the part is all there and, with skip >= 0, all that follows.
uint64_t data_part(const std::string& file, uint64_t fsize, uint64_t start, int64_t skip, uint64_t per);
/// dims product with overflow check; throws InputError on absurd dimensions.
uint64_t checked_count(const std::string& path, const std::array<int64_t, 3>& dims, int64_t components,
                       size_t value_size);

/// Shortest decimal text that reads back as exactly the same double.
std::string format_double(double x);
/// A value of type t as text: floats as format_double (f32 rounded first),
/// integers in full ("100000", never "1e+05", which other readers refuse).
std::string format_typed(ScalarType t, double x);

/// Parses a floating-point number; throws InputError(path, what + ...) otherwise.
double parse_double(const std::string& path, const std::string& text, const std::string& what);
int64_t parse_int(const std::string& path, const std::string& text, const std::string& what);

/// Unlinks every temporary of a write in progress; async-signal-safe.
void remove_temporaries_on_signal() noexcept;
/// Writes a file atomically: `write` receives the path of a temporary file in
/// the destination folder (same extension, so format-sniffing libraries see
/// the right suffix); on success it is renamed over `path`, on any exception
/// it is removed and the exception propagates. A reader of `path` therefore
/// never sees a partial file, even if the process is killed.
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);
/// Same, with an ofstream opened in binary mode on the temporary file.
void write_stream_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace voxpress::detail
