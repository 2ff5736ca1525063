#include "io_util.h"

#include "voxpress/core/memory_budget.h"

#include "voxpress/io/atomic_file.h"

#include <signal.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

namespace voxpress::detail {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extension_of(const std::string& path) {
  const std::string name = lower(fs::path(path).filename().string());
  for (const char* compound : {".nii.gz", ".seg.nrrd", ".seg.nhdr"})
    if (name.size() > std::strlen(compound) && name.ends_with(compound)) return compound;
  const auto dot = name.rfind('.');
  return dot == std::string::npos || dot == 0 ? std::string() : name.substr(dot);
}

std::string trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

std::vector<std::string> split_ws(std::string_view s) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    size_t j = i;
    while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j]))) ++j;
    if (j > i) out.emplace_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

uint64_t file_size(const std::string& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(path, "no such file");
  if (fs::is_directory(status)) throw InputError(path, "is a directory, not a file");
  // A pipe or device (data file: /dev/stdin, /dev/zero) could block or never end.
  if (!fs::is_regular_file(status)) throw InputError(path, "is not a regular file (a device, pipe or socket)");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(path, "cannot read: " + ec.message());
  return size;
}

std::vector<std::byte> read_whole_file(const std::string& path, uint64_t cap, const std::string& what) {
  const uint64_t size = file_size(path);
  check_limit(path, size, cap, what);
  return read_range(path, 0, size);
}

void read_range_into(const std::string& path, uint64_t offset, std::byte* out, uint64_t size) {
  const uint64_t total = file_size(path);
  if (offset > total || size > total - offset)
    throw InputError(path, "truncated: the data needs " + std::to_string(size) + " bytes at offset " +
                               std::to_string(offset) + " but the file has " + std::to_string(total) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(std::streamoff(offset));
  in.read(reinterpret_cast<char*>(out), std::streamsize(size));
  if (uint64_t(in.gcount()) != size) throw InputError(path, "read error");
}

std::vector<std::byte> read_range(const std::string& path, uint64_t offset, uint64_t size) {
  std::vector<std::byte> buf(size);
  read_range_into(path, offset, buf.data(), size);
  return buf;
}

// A deflate stream expands at most 1032:1 (a 258-byte match in about two
// bits); a payload declaring more cannot hold it and is refused before any
// allocation or inflation (issue 73: a 24-byte gzip declaring 512 MiB).
void check_ratio(const std::string& path, size_t in_size, uint64_t expected) {
  const uint64_t most = (uint64_t(in_size) + 64) * kMaxDeflateRatio;
  if (expected > most)
    throw InputError(path, "the compressed payload has " + std::to_string(in_size) + " bytes, which can hold at most " +
                               std::to_string(most) + " (deflate expands at most " + std::to_string(kMaxDeflateRatio) +
                               ":1), but the header declares " + std::to_string(expected));
}

void inflate_stream(const std::string& path, const std::byte* in, size_t in_size, uint64_t expected,
                    const std::function<void(const std::byte*, size_t)>& sink, bool more_allowed) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK) throw InputError(path, "zlib initialisation failed");
  struct Guard {
    z_stream* z;
    ~Guard() { inflateEnd(z); }
  } guard{&zs};
  std::vector<std::byte> scratch(size_t(1) << 20);
  uint64_t produced = 0;
  size_t consumed = 0;
  bool ended = false;
  for (;;) {
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in + consumed));
    zs.avail_in = uInt(std::min<size_t>(in_size - consumed, size_t(1) << 30));
    zs.next_out = reinterpret_cast<Bytef*>(scratch.data());
    zs.avail_out = uInt(scratch.size());
    const uInt before_in = zs.avail_in;
    const int rc = inflate(&zs, Z_NO_FLUSH);
    consumed += before_in - zs.avail_in;
    const size_t wrote = scratch.size() - zs.avail_out;
    if (!more_allowed && wrote > expected - produced)
      throw InputError(path, "the compressed payload holds more than the " + std::to_string(expected) +
                                 " bytes the header declares (dimensions or type do not match the data)");
    if (wrote) sink(scratch.data(), wrote);
    produced += wrote;
    if (rc == Z_STREAM_END) {
      // Another gzip member may follow (concatenated gzip).
      size_t skip = consumed;
      while (skip < in_size && in[skip] == std::byte{0}) ++skip;
      if (skip + 2 <= in_size && in[skip] == std::byte{0x1f} && in[skip + 1] == std::byte{0x8b}) {
        consumed = skip;
        inflateReset(&zs);
        continue;
      }
      ended = true;
      break;
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR)
      throw InputError(path, std::string("corrupt compressed payload (zlib: ") + (zs.msg ? zs.msg : "error") + ")");
    if (consumed == in_size && wrote == 0) break;  // input exhausted before the stream's end
  }
  if (produced < expected)
    throw InputError(path, "truncated: the compressed payload holds " + std::to_string(produced) +
                               " bytes but the header declares " + std::to_string(expected));
  if (!ended)
    throw InputError(path, "truncated: the compressed payload ends before its end marker and check value "
                           "(a gzip without its CRC trailer)");
}

void inflate_exact(const std::string& path, const std::byte* in, size_t in_size, std::byte* out, uint64_t expected) {
  check_ratio(path, in_size, expected);
  uint64_t at = 0;
  inflate_stream(path, in, in_size, expected, [&](const std::byte* p, size_t n) {
    std::memcpy(out + at, p, n);
    at += n;
  }, false);
}

std::vector<std::byte> inflate_grown(const std::string& path, const std::byte* in, size_t in_size, uint64_t expected) {
  check_ratio(path, in_size, expected);
  // A single gzip member ends with its length modulo 2^32. When that is not
  // the declared size (another length, several members, padding), the stream
  // is first inflated without keeping anything, so a payload holding more or
  // less than declared is refused before the buffer exists (16 MiB of
  // gzipped zeros declaring 1 GiB peaked at 1.06 GB).
  const bool gzip = in_size >= 18 && in[0] == std::byte{0x1f} && in[1] == std::byte{0x8b};
  uint32_t isize = 0;
  if (gzip)
    for (int b = 3; b >= 0; --b) isize = (isize << 8) | uint32_t(in[in_size - 4 + size_t(b)]);
  if (!gzip || isize != uint32_t(expected)) inflate_stream(path, in, in_size, expected, [](const std::byte*, size_t) {}, false);
  // Reserved, not filled: the pages are touched as the data arrives.
  std::vector<std::byte> out;
  out.reserve(expected);
  inflate_stream(path, in, in_size, expected, [&](const std::byte* p, size_t n) { out.insert(out.end(), p, p + n); },
                 false);
  return out;
}

std::vector<std::byte> deflate_buffer(const std::byte* in, size_t size, bool gzip_wrapper, int level) {
  z_stream zs{};
  if (deflateInit2(&zs, level, Z_DEFLATED, gzip_wrapper ? 16 + 15 : 15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("zlib initialisation failed");
  std::vector<std::byte> out;
  size_t consumed = 0;
  const size_t kChunk = size_t(1) << 30;
  int rc = Z_OK;
  do {
    const size_t take = std::min(size - consumed, kChunk);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in + consumed));
    zs.avail_in = uInt(take);
    consumed += take;
    const int flush = consumed == size ? Z_FINISH : Z_NO_FLUSH;
    do {
      const size_t pos = out.size();
      out.resize(pos + (1u << 20));
      zs.next_out = reinterpret_cast<Bytef*>(out.data() + pos);
      zs.avail_out = 1u << 20;
      rc = deflate(&zs, flush);
      out.resize(pos + (1u << 20) - zs.avail_out);
    } while (zs.avail_out == 0);
  } while (consumed < size || rc != Z_STREAM_END);
  deflateEnd(&zs);
  return out;
}

void swap_bytes(std::byte* data, uint64_t count, size_t width) {
  if (width <= 1) return;
  for (uint64_t i = 0; i < count; ++i) std::reverse(data + i * width, data + (i + 1) * width);
}

std::string format_bytes(uint64_t bytes) {
  // "--max-memory 1K" said "needs 0 MiB, above the limit of 0 MiB" (issue 73).
  if (bytes >= (uint64_t(1) << 20)) return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= 1024) return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + " bytes";
}

void check_limit(const std::string& path, uint64_t bytes, uint64_t cap, const std::string& what) {
  if (cap && bytes > cap)
    throw LimitError(path, what + " needs " + format_bytes(bytes) + ", above the memory limit of " + format_bytes(cap) +
                               " (raise it with --max-memory)");
}

uint64_t data_part(const std::string& file, uint64_t fsize, uint64_t start, int64_t skip, uint64_t per) {
  const uint64_t off = skip == -1 ? (fsize >= per ? fsize - per : 0) : start + uint64_t(std::max<int64_t>(skip, 0));
  const uint64_t avail = fsize > off ? fsize - off : 0;
  if (avail < per)
    throw InputError(file, "truncated: the header declares " + std::to_string(per) + " bytes of data but " +
                               std::to_string(avail) + " are present");
  if (avail > per && skip != -1)
    throw InputError(file, "the data size does not match the header: " + std::to_string(avail) + " bytes present, " +
                               std::to_string(per) + " declared");
  return off;
}

uint64_t checked_count(const std::string& path, const std::array<int64_t, 3>& dims, int64_t components,
                       size_t value_size) {
  uint64_t n = 1;
  constexpr uint64_t kMax = uint64_t(1) << 62;
  for (int64_t d : {dims[0], dims[1], dims[2], components}) {
    if (d < 1) throw InputError(path, "invalid dimension " + std::to_string(d));
    if (uint64_t(d) > kMax / n) throw LimitError(path, "absurd dimensions: the sample count overflows");
    n *= uint64_t(d);
  }
  if (n > kMax / value_size) throw LimitError(path, "absurd dimensions: the data size overflows");
  return n;
}

std::string format_double(double x) {
  char tmp[32];
  const auto r = std::to_chars(tmp, tmp + sizeof tmp, x);
  return std::string(tmp, r.ptr);
}

Mesh welded_solid(const Mesh& m) {
  Mesh solid = m;
  solid.uvs.clear();
  solid.texture = {};
  weld_identical_vertices(solid);
  return solid;
}

std::string format_typed(ScalarType t, double x) {
  if (t == ScalarType::f32) return format_double(double(float(x)));
  if (t == ScalarType::f64) return format_double(x);
  if (t == ScalarType::u64) return std::to_string(uint64_t(x));
  return std::to_string(int64_t(x));
}

double parse_double(const std::string& path, const std::string& text, const std::string& what) {
  const std::string t = trim(text);
  double v = 0;
  auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size()) {
    // Accept the spellings from_chars rejects ("+1", "nan").
    const std::string l = lower(t);
    if (l == "nan" || l == "+nan" || l == "-nan") return std::numeric_limits<double>::quiet_NaN();
    if (!t.empty() && t[0] == '+') return parse_double(path, t.substr(1), what);
    throw InputError(path, what + ": '" + t + "' is not a number");
  }
  return v;
}

int64_t parse_int(const std::string& path, const std::string& text, const std::string& what) {
  const std::string t = trim(text);
  int64_t v = 0;
  const char* b = t.data();
  if (!t.empty() && t[0] == '+') ++b;
  auto [ptr, ec] = std::from_chars(b, t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size()) throw InputError(path, what + ": '" + t + "' is not an integer");
  return v;
}

namespace {

// A run killed while writing (SIGKILL, power loss) leaves its hidden
// temporary ".NAME.tmpPID-N.ext" behind, never a partial NAME. The next
// write of NAME removes those whose process is gone.
void remove_stale_temporaries(const fs::path& dir, const std::string& prefix) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.starts_with(prefix)) continue;
    long pid = 0;
    const char* first = name.data() + prefix.size();
    const auto [end, err] = std::from_chars(first, name.data() + name.size(), pid);
    if (err != std::errc() || end == first || *end != '-' || pid <= 0 || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) == -1 && errno == ESRCH) fs::remove(e.path(), ec);
  }
}

}  // namespace

namespace {
// The open OutputGroup's pending (temporary, name) pairs; null when none is open.
thread_local std::vector<std::pair<fs::path, fs::path>>* g_pending = nullptr;

// The temporaries that exist now, in fixed storage a signal handler may read
// (SIGINT / SIGTERM during a write left the hidden .tmpPID file, issue 73).
constexpr size_t kTemporarySlots = 512, kTemporaryPath = 4096;
char g_temporaries[kTemporarySlots][kTemporaryPath];
std::atomic<bool> g_temporary_used[kTemporarySlots];
std::mutex g_temporary_mutex;

void track_temporary(const fs::path& tmp) {
  const std::string p = tmp.string();
  if (p.size() >= kTemporaryPath) return;  // not cleaned on a signal; the next run removes it
  std::lock_guard lock(g_temporary_mutex);
  for (size_t i = 0; i < kTemporarySlots; ++i)
    if (!g_temporary_used[i].load()) {
      std::memcpy(g_temporaries[i], p.c_str(), p.size() + 1);
      g_temporary_used[i].store(true);
      return;
    }
}

void untrack_temporary(const fs::path& tmp) {
  const std::string p = tmp.string();
  std::lock_guard lock(g_temporary_mutex);
  for (size_t i = 0; i < kTemporarySlots; ++i)
    if (g_temporary_used[i].load() && p == g_temporaries[i]) {
      g_temporary_used[i].store(false);
      return;
    }
}
}  // namespace

void remove_temporaries_on_signal() noexcept {
  for (size_t i = 0; i < kTemporarySlots; ++i)
    if (g_temporary_used[i].load()) ::unlink(g_temporaries[i]);  // async-signal-safe
}

void write_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(path, "the output folder does not exist");
  const std::string ext = extension_of(path);
  // Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+.
  std::string name(".");
  name.append(target.filename().string()).append(".tmp").append(std::to_string(::getpid()));
  name.append("-").append(std::to_string(counter++)).append(ext);
  const fs::path tmp = dir / name;
  remove_stale_temporaries(dir, std::string(".").append(target.filename().string()).append(".tmp"));
  track_temporary(tmp);
  try {
    write(tmp.string());
    if (g_pending) {
      // A second write of one name in a group replaces the first.
      for (auto& [t, final_name] : *g_pending)
        if (final_name == target) {
          fs::remove(t, ec);
          untrack_temporary(t);
          t = tmp;
          return;
        }
      g_pending->emplace_back(tmp, target);
      return;
    }
    fs::rename(tmp, target, ec);
    if (ec) throw InputError(path, "cannot write: " + ec.message());
    untrack_temporary(tmp);
  } catch (...) {
    fs::remove(tmp, ec);
    untrack_temporary(tmp);
    throw;
  }
}

void write_stream_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
    write(out);
    out.flush();
    if (!out) throw InputError(path, "write failed (disk full?)");
  });
}

}  // namespace voxpress::detail

namespace voxpress {
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  detail::write_stream_atomically(path, write);
}

namespace fs = std::filesystem;

OutputGroup::OutputGroup() {
  if (detail::g_pending) throw std::logic_error("OutputGroup: groups do not nest");
  detail::g_pending = new std::vector<std::pair<fs::path, fs::path>>();
}

OutputGroup::~OutputGroup() {
  if (!detail::g_pending) return;
  std::error_code ec;
  for (const auto& [tmp, name] : *detail::g_pending) {
    fs::remove(tmp, ec);
    detail::untrack_temporary(tmp);
  }
  delete detail::g_pending;
  detail::g_pending = nullptr;
}

void OutputGroup::commit_open() {
  auto* pending = detail::g_pending;
  if (!pending) return;
  for (size_t i = 0; i < pending->size(); ++i) {
    std::error_code ec;
    fs::rename((*pending)[i].first, (*pending)[i].second, ec);
    if (!ec) detail::untrack_temporary((*pending)[i].first);
    if (ec) {
      pending->erase(pending->begin(), pending->begin() + std::ptrdiff_t(i));
      throw InputError((*pending)[0].second.string(), "cannot write: " + ec.message());
    }
  }
  pending->clear();
}

void OutputGroup::commit() { commit_open(); }

namespace {
extern "C" void remove_temporaries_and_die(int sig) {
  detail::remove_temporaries_on_signal();
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}
}  // namespace

void remove_temporaries_on_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa {};
    sa.sa_handler = remove_temporaries_and_die;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}
void charge_memory(const std::string& path, uint64_t bytes, uint64_t cap, const std::string& what) {
  detail::check_limit(path, bytes, cap, what);
}

}  // namespace voxpress
