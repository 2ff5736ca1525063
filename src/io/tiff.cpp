// TIFF volumes through libtiff: a multi-page file (one page per z slice) or
// a folder of single-page slices sorted by the numbers in their names.
//
// Samples: 1 (bilevel, stored bit value kept), 8, 16, 32 or 64 bits,
// unsigned, signed or IEEE float, one sample per pixel, strips or tiles, any
// compression libtiff decodes. Spacing: ImageJ's description ("spacing=" for
// z) with 1 / XResolution, 1 / YResolution in ImageJ's unit; otherwise the
// resolution converted to millimetres when its unit is inch or centimetre;
// otherwise 1. libtiff's own messages are captured into the error we throw.
#include <tiffio.h>

#include <algorithm>
#include <bit>
#include <cstdarg>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>

#include "formats.h"
#include "io_util.h"

namespace voxpress::detail {
namespace {

thread_local std::string g_tiff_error;

void on_error(const char* module, const char* fmt, va_list ap) {
  char buf[512];
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  g_tiff_error = (module && *module ? std::string(module) + ": " : std::string()) + buf;
}

void install_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    TIFFSetErrorHandler(on_error);
    TIFFSetWarningHandler(nullptr);
  });
}

struct TiffCloser {
  void operator()(TIFF* t) const {
    if (t) TIFFClose(t);
  }
};
using TiffPtr = std::unique_ptr<TIFF, TiffCloser>;

TiffPtr open_tiff(const std::string& path) {
  install_handlers();
  file_size(path);  // clear error for missing files
  g_tiff_error.clear();
  TiffPtr t(TIFFOpen(path.c_str(), "r"));
  if (!t) throw InputError(path, "not a readable TIFF file" + (g_tiff_error.empty() ? "" : " (" + g_tiff_error + ")"));
  return t;
}

struct PageInfo {
  uint32_t width = 0, height = 0;
  uint16_t bits = 1, format = SAMPLEFORMAT_UINT, spp = 1;
  ScalarType type = ScalarType::u8;
  bool operator==(const PageInfo& o) const {
    return width == o.width && height == o.height && bits == o.bits && format == o.format;
  }
};

PageInfo page_info(const std::string& path, TIFF* t) {
  PageInfo p;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &p.width);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, &p.height);
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &p.bits);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &p.format);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &p.spp);
  if (p.width == 0 || p.height == 0) throw InputError(path, "TIFF page with zero size");
  if (p.spp != 1)
    throw InputError(path, "TIFF with " + std::to_string(p.spp) + " samples per pixel (RGB?) is not supported; use a "
                                                                  "single-channel image");
  const bool sgn = p.format == SAMPLEFORMAT_INT, flt = p.format == SAMPLEFORMAT_IEEEFP;
  if (p.format != SAMPLEFORMAT_UINT && !sgn && !flt) throw InputError(path, "unsupported TIFF sample format");
  switch (p.bits) {
    case 1: p.type = ScalarType::u8; break;
    case 8: p.type = sgn ? ScalarType::i8 : ScalarType::u8; break;
    case 16: p.type = sgn ? ScalarType::i16 : ScalarType::u16; break;
    case 32: p.type = flt ? ScalarType::f32 : sgn ? ScalarType::i32 : ScalarType::u32; break;
    case 64: p.type = flt ? ScalarType::f64 : sgn ? ScalarType::i64 : ScalarType::u64; break;
    default: throw InputError(path, "unsupported TIFF bit depth " + std::to_string(p.bits));
  }
  if (flt && p.bits < 32) throw InputError(path, "unsupported TIFF float bit depth");
  return p;
}

// Decodes the current page into out (width * height samples of p.type).
// The current page's directory and every tag value stored outside it lie
// inside the file (libtiff drops a value it cannot read, such as a cut
// XResolution, without an error, and the spacing would default to 1).
void check_directory_in_file(const std::string& path, TIFF* t, tdir_t page, uint64_t file_bytes) {
  const bool big = TIFFIsBigTIFF(t);
  const bool little = TIFFIsByteSwapped(t) != (std::endian::native == std::endian::little);  // the file's order
  auto truncated = [&] {
    return InputError(path, "truncated TIFF: page " + std::to_string(page) + "'s directory runs past the end of the file");
  };
  auto decode = [&](const std::byte* b, size_t width) {
    uint64_t v = 0;
    for (size_t i = 0; i < width; ++i) v = (v << 8) | uint64_t(std::to_integer<uint8_t>(b[little ? width - 1 - i : i]));
    return v;
  };
  // The directory: its entry count, then the entries and the link to the
  // next page, each read once.
  const uint64_t dir = TIFFCurrentDirOffset(t);
  const size_t count_width = big ? 8 : 2, entry = big ? 20 : 12, word = big ? 8 : 4;
  if (dir > file_bytes || count_width > file_bytes - dir) throw truncated();
  const uint64_t entries = decode(read_range(path, dir, count_width).data(), count_width);
  if (entries > (file_bytes - dir - count_width) / entry) throw truncated();
  const uint64_t block = entries * entry + word;
  if (block > file_bytes - dir - count_width) throw truncated();
  const auto bytes = read_range(path, dir + count_width, block);
  static constexpr uint8_t kTypeBytes[19] = {0, 1, 1, 2, 4, 8, 1, 1, 2, 4, 8, 4, 8, 4, 0, 0, 8, 8, 8};
  for (uint64_t e = 0; e < entries; ++e) {
    const std::byte* at = bytes.data() + e * entry;
    const uint64_t type = decode(at + 2, 2), n = decode(at + 4, word);
    const uint64_t width = type < 19 ? kTypeBytes[type] : 0;
    if (width == 0 || n == 0 || n > file_bytes / width || n * width <= word) continue;  // stored inline
    const uint64_t value_at = decode(at + 4 + word, word);
    if (value_at > file_bytes || n * width > file_bytes - value_at)
      throw InputError(path, "truncated TIFF: a value of page " + std::to_string(page) + " lies past the end of the file");
  }
}

// Every strip or tile of the current page lies inside the file (libtiff
// reads a cut strip short without an error).
void check_chunks_in_file(const std::string& path, TIFF* t, tdir_t page, uint64_t file_bytes) {
  check_directory_in_file(path, t, page, file_bytes);
  const bool tiled = TIFFIsTiled(t);
  uint64_t* offsets = nullptr;
  uint64_t* counts = nullptr;
  if (!TIFFGetField(t, tiled ? TIFFTAG_TILEOFFSETS : TIFFTAG_STRIPOFFSETS, &offsets) ||
      !TIFFGetField(t, tiled ? TIFFTAG_TILEBYTECOUNTS : TIFFTAG_STRIPBYTECOUNTS, &counts) || !offsets || !counts)
    throw InputError(path, "TIFF page " + std::to_string(page) + " has no data offsets");
  const uint32_t n = tiled ? TIFFNumberOfTiles(t) : TIFFNumberOfStrips(t);
  for (uint32_t i = 0; i < n; ++i)
    if (offsets[i] > file_bytes || counts[i] > file_bytes - offsets[i])
      throw InputError(path, "truncated TIFF: page " + std::to_string(page) + "'s data runs past the end of the file");
}

void read_page(const std::string& path, TIFF* t, const PageInfo& p, std::byte* out, uint64_t max_bytes, tdir_t page,
               uint64_t file_bytes) {
  const size_t vs = scalar_size(p.type);
  const size_t row_bytes = p.bits == 1 ? (p.width + 7) / 8 : size_t(p.width) * vs;
  auto store_row = [&](const uint8_t* src, uint32_t y, uint32_t x0, uint32_t n) {
    std::byte* dst = out + (size_t(y) * p.width + x0) * vs;
    if (p.bits == 1) {
      for (uint32_t x = 0; x < n; ++x) dst[x] = std::byte((src[x >> 3] >> (7 - (x & 7))) & 1);
    } else {
      std::memcpy(dst, src, size_t(n) * vs);
    }
  };
  g_tiff_error.clear();
  if (TIFFIsTiled(t)) {
    if (p.bits == 1) throw InputError(path, "tiled bilevel TIFF is not supported");
    uint32_t tw = 0, th = 0;
    TIFFGetField(t, TIFFTAG_TILEWIDTH, &tw);
    TIFFGetField(t, TIFFTAG_TILELENGTH, &th);
    if (tw == 0 || th == 0) throw InputError(path, "TIFF tile size is zero");
    // The tile buffer is sized by the header: a tile larger than both the
    // image and 1024 x 1024 serves no purpose and would let a tiny file
    // claim gigabytes (found by bench/fuzz).
    if ((tw > p.width && tw > 1024) || (th > p.height && th > 1024))
      throw InputError(path, "TIFF tile " + std::to_string(tw) + " x " + std::to_string(th) +
                                 " is larger than the image (" + std::to_string(p.width) + " x " +
                                 std::to_string(p.height) + ")");
    const tmsize_t tile_bytes = TIFFTileSize(t);
    if (tile_bytes <= 0) throw InputError(path, "invalid TIFF tile size");
    check_limit(path, uint64_t(tile_bytes), max_bytes, "a TIFF tile");
    check_chunks_in_file(path, t, page, file_bytes);
    std::vector<uint8_t> tile(static_cast<size_t>(tile_bytes));
    for (uint32_t y0 = 0; y0 < p.height; y0 += th)
      for (uint32_t x0 = 0; x0 < p.width; x0 += tw) {
        if (TIFFReadTile(t, tile.data(), x0, y0, 0, 0) < 0)
          throw InputError(path, "corrupt TIFF tile" + (g_tiff_error.empty() ? "" : " (" + g_tiff_error + ")"));
        const uint32_t n = std::min(tw, p.width - x0);
        for (uint32_t y = y0; y < std::min(y0 + th, p.height); ++y)
          store_row(tile.data() + size_t(y - y0) * tw * vs, y, x0, n);
      }
    return;
  }
  check_chunks_in_file(path, t, page, file_bytes);
  std::vector<uint8_t> row(std::max<size_t>(size_t(TIFFScanlineSize(t)), row_bytes));
  for (uint32_t y = 0; y < p.height; ++y) {
    if (TIFFReadScanline(t, row.data(), y, 0) < 0)
      throw InputError(path, "truncated or corrupt TIFF data" + (g_tiff_error.empty() ? "" : " (" + g_tiff_error + ")"));
    store_row(row.data(), y, 0, p.width);
  }
}

// Spacing from the current page's tags.
void read_spacing(TIFF* t, ScalarVolume& v) {
  char* desc = nullptr;
  std::string description;
  if (TIFFGetField(t, TIFFTAG_IMAGEDESCRIPTION, &desc) && desc) description = desc;
  const bool imagej = description.rfind("ImageJ=", 0) == 0;
  float xres = 0, yres = 0;
  uint16_t unit = RESUNIT_NONE;
  TIFFGetField(t, TIFFTAG_XRESOLUTION, &xres);
  TIFFGetField(t, TIFFTAG_YRESOLUTION, &yres);
  TIFFGetFieldDefaulted(t, TIFFTAG_RESOLUTIONUNIT, &unit);
  double scale = 0;  // physical units per 1 / resolution
  if (imagej)
    scale = 1;
  else if (unit == RESUNIT_CENTIMETER)
    scale = 10;
  else if (unit == RESUNIT_INCH)
    scale = 25.4;
  if (scale > 0 && xres > 0 && yres > 0) {
    v.lattice.spacing.x() = scale / xres;
    v.lattice.spacing.y() = scale / yres;
  }
  if (imagej) {
    for (const auto& line : split_ws(description)) {
      if (line.rfind("spacing=", 0) == 0) {
        try {
          const double z = std::stod(line.substr(8));
          if (z > 0 && std::isfinite(z)) v.lattice.spacing.z() = z;
        } catch (const std::exception&) {
        }
      } else if (line.rfind("unit=", 0) == 0) {
        v.metadata["unit"] = line.substr(5);
      }
    }
  }
}

bool natural_less(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t i2 = i, j2 = j;
      while (i2 < a.size() && a[i2] == '0') ++i2;
      while (j2 < b.size() && b[j2] == '0') ++j2;
      size_t ie = i2, je = j2;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      if (ie - i2 != je - j2) return ie - i2 < je - j2;
      const int c = a.compare(i2, ie - i2, b, j2, je - j2);
      if (c != 0) return c < 0;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

ScalarVolume read_tiff(const std::string& path, uint64_t max_bytes) {
  TiffPtr t = open_tiff(path);
  ScalarVolume v;
  v.source = path;
  const PageInfo first = page_info(path, t.get());
  const tdir_t pages = TIFFNumberOfDirectories(t.get());
  if (pages == 0) throw InputError(path, "TIFF without pages");
  const uint64_t file_bytes = file_size(path);
  v.type = first.type;
  v.lattice.dims = {int64_t(first.width), int64_t(first.height), int64_t(pages)};
  const size_t vs = scalar_size(v.type);
  const uint64_t count = checked_count(path, v.lattice.dims, 1, vs);
  check_limit(path, count * vs, max_bytes, "the volume");
  read_spacing(t.get(), v);
  v.bytes.resize(count * vs);
  const uint64_t page_bytes = uint64_t(first.width) * first.height * vs;
  for (tdir_t z = 0; z < pages; ++z) {
    if (!TIFFSetDirectory(t.get(), z)) throw InputError(path, "cannot read TIFF page " + std::to_string(z));
    const PageInfo p = page_info(path, t.get());
    if (!(p == first)) throw InputError(path, "TIFF page " + std::to_string(z) + " differs in size or type from page 0");
    read_page(path, t.get(), p, v.bytes.data() + z * page_bytes, max_bytes, z, file_bytes);
  }
  // libtiff counts the pages it can reach: a cut file ends its chain early.
  // The last page it reached must be the last one the file names.
  if (!TIFFLastDirectory(t.get()))
    throw InputError(path, "truncated TIFF: page " + std::to_string(pages) + " links to a page past the end of the file");
  return v;
}

ScalarVolume read_tiff_folder(const std::string& dir, uint64_t max_bytes) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (!e.is_regular_file()) continue;
    const std::string ext = extension_of(e.path().string());
    if (ext == ".tif" || ext == ".tiff") files.push_back(e.path().filename().string());
  }
  if (ec) throw InputError(dir, "cannot list the folder: " + ec.message());
  if (files.empty()) throw InputError(dir, "the folder holds no .tif/.tiff slices");
  std::sort(files.begin(), files.end(), natural_less);
  ScalarVolume v;
  v.source = dir;
  PageInfo first;
  uint64_t page_bytes = 0;
  for (size_t z = 0; z < files.size(); ++z) {
    const std::string path = (std::filesystem::path(dir) / files[z]).string();
    TiffPtr t = open_tiff(path);
    const PageInfo p = page_info(path, t.get());
    if (z == 0) {
      first = p;
      v.type = p.type;
      v.lattice.dims = {int64_t(p.width), int64_t(p.height), int64_t(files.size())};
      const size_t vs = scalar_size(v.type);
      const uint64_t count = checked_count(dir, v.lattice.dims, 1, vs);
      check_limit(dir, count * vs, max_bytes, "the volume");
      read_spacing(t.get(), v);
      v.bytes.resize(count * vs);
      page_bytes = uint64_t(p.width) * p.height * vs;
    } else if (!(p == first)) {
      throw InputError(path, "slice differs in size or type from " + files[0]);
    }
    read_page(path, t.get(), p, v.bytes.data() + z * page_bytes, max_bytes, 0, file_size(path));
  }
  return v;
}

void write_tiff(const std::string& path, const ScalarVolume& v) {
  install_handlers();
  if (v.components != 1) throw UsageError("TIFF output holds one component per sample");
  const size_t vs = scalar_size(v.type);
  const uint16_t format = scalar_is_float(v.type) ? SAMPLEFORMAT_IEEEFP
                          : (v.type == ScalarType::i8 || v.type == ScalarType::i16 || v.type == ScalarType::i32 ||
                             v.type == ScalarType::i64)
                              ? SAMPLEFORMAT_INT
                              : SAMPLEFORMAT_UINT;
  const auto& d = v.lattice.dims;
  const std::string description = "ImageJ=1.11a\nimages=" + std::to_string(d[2]) + "\nslices=" + std::to_string(d[2]) +
                                  "\nspacing=" + std::to_string(v.lattice.spacing.z()) + "\n";
  write_atomically(path, [&](const std::string& tmp) {
    g_tiff_error.clear();
    TiffPtr t(TIFFOpen(tmp.c_str(), d[0] * d[1] * d[2] * int64_t(vs) > (int64_t(1) << 31) ? "w8" : "w"));
    if (!t) throw InputError(path, "cannot write TIFF" + (g_tiff_error.empty() ? "" : " (" + g_tiff_error + ")"));
    for (int64_t z = 0; z < d[2]; ++z) {
      TIFF* tf = t.get();
      TIFFSetField(tf, TIFFTAG_IMAGEWIDTH, uint32_t(d[0]));
      TIFFSetField(tf, TIFFTAG_IMAGELENGTH, uint32_t(d[1]));
      TIFFSetField(tf, TIFFTAG_BITSPERSAMPLE, uint16_t(8 * vs));
      TIFFSetField(tf, TIFFTAG_SAMPLEFORMAT, format);
      TIFFSetField(tf, TIFFTAG_SAMPLESPERPIXEL, uint16_t(1));
      TIFFSetField(tf, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
      TIFFSetField(tf, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
      TIFFSetField(tf, TIFFTAG_COMPRESSION, COMPRESSION_DEFLATE);
      TIFFSetField(tf, TIFFTAG_ROWSPERSTRIP, uint32_t(std::max<int64_t>(1, 65536 / (d[0] * int64_t(vs)))));
      TIFFSetField(tf, TIFFTAG_XRESOLUTION, float(1.0 / v.lattice.spacing.x()));
      TIFFSetField(tf, TIFFTAG_YRESOLUTION, float(1.0 / v.lattice.spacing.y()));
      TIFFSetField(tf, TIFFTAG_RESOLUTIONUNIT, uint16_t(RESUNIT_NONE));
      if (z == 0) TIFFSetField(tf, TIFFTAG_IMAGEDESCRIPTION, description.c_str());
      if (d[2] > 1) {
        TIFFSetField(tf, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
        TIFFSetField(tf, TIFFTAG_PAGENUMBER, uint16_t(z), uint16_t(d[2]));
      }
      for (int64_t y = 0; y < d[1]; ++y) {
        auto* row = const_cast<std::byte*>(v.bytes.data() + (size_t(z * d[1] + y) * size_t(d[0])) * vs);
        if (TIFFWriteScanline(tf, row, uint32_t(y), 0) < 0) throw InputError(path, "TIFF write failed");
      }
      if (!TIFFWriteDirectory(tf)) throw InputError(path, "TIFF write failed");
    }
  });
}

}  // namespace voxpress::detail
