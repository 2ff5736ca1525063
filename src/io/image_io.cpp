#include "voxpress/io/image_io.h"

#include <png.h>

#include <cmath>
#include <csetjmp>
#include <cstring>
#include <sstream>

#include "io_util.h"
#include "voxpress/io/volume_io.h"

namespace voxpress {
namespace {

GreyImage read_png(const std::string& path, uint64_t max_bytes) {
  const uint64_t size = detail::file_size(path);
  const auto bytes = detail::read_range(path, 0, size);
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size()))
    throw InputError(path, std::string("not a readable PNG (") + img.message + ")");
  struct Free {
    png_image* i;
    ~Free() { png_image_free(i); }
  } guard{&img};
  if (img.width == 0 || img.height == 0 || img.width > (1u << 20) || img.height > (1u << 20))
    throw InputError(path, "absurd PNG size");
  detail::check_limit(path, uint64_t(img.width) * img.height * 12, max_bytes, "the image");
  img.format = PNG_FORMAT_RGBA;
  std::vector<uint8_t> rgba(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, rgba.data(), 0, nullptr))
    throw InputError(path, std::string("truncated or corrupt PNG (") + img.message + ")");
  GreyImage g;
  g.width = img.width;
  g.height = img.height;
  g.value.resize(size_t(g.width * g.height));
  for (size_t i = 0; i < g.value.size(); ++i) {
    const uint8_t* p = &rgba[4 * i];
    const double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    const double a = p[3] / 255.0;
    g.value[i] = a * lum + (1 - a) * 255.0;  // composite over white
  }
  return g;
}

GreyImage read_netpbm(const std::string& path, uint64_t max_bytes) {
  const uint64_t size = detail::file_size(path);
  const auto bytes = detail::read_range(path, 0, size);
  const char* p = reinterpret_cast<const char*>(bytes.data());
  const char* end = p + bytes.size();
  if (bytes.size() < 2 || p[0] != 'P' || p[1] < '1' || p[1] > '6') throw InputError(path, "not a netpbm image");
  const int kind = p[1] - '0';
  p += 2;
  auto token = [&]() -> int64_t {
    while (p < end && (std::isspace(static_cast<unsigned char>(*p)) || *p == '#')) {
      if (*p == '#')
        while (p < end && *p != '\n') ++p;
      else
        ++p;
    }
    if (p >= end || !std::isdigit(static_cast<unsigned char>(*p))) throw InputError(path, "malformed netpbm header");
    int64_t v = 0;
    while (p < end && std::isdigit(static_cast<unsigned char>(*p))) {
      v = v * 10 + (*p++ - '0');
      if (v > (int64_t(1) << 31)) throw InputError(path, "absurd netpbm header value");
    }
    return v;
  };
  GreyImage g;
  g.width = token();
  g.height = token();
  if (g.width < 1 || g.height < 1 || g.width > (1 << 20) || g.height > (1 << 20))
    throw InputError(path, "absurd netpbm size");
  const bool bitmap = kind == 1 || kind == 4;
  const int64_t maxval = bitmap ? 1 : token();
  if (maxval < 1 || maxval > 65535) throw InputError(path, "invalid netpbm maxval");
  detail::check_limit(path, uint64_t(g.width * g.height) * 8, max_bytes, "the image");
  const bool ascii = kind <= 3;
  const int channels = (kind == 3 || kind == 6) ? 3 : 1;
  const size_t n = size_t(g.width * g.height);
  g.value.resize(n);
  if (!ascii) ++p;  // the single whitespace after the header
  auto truncated = [&] { throw InputError(path, "truncated netpbm pixel data"); };
  if (kind == 4) {
    const int64_t row = (g.width + 7) / 8;
    if (end - p < row * g.height) truncated();
    for (int64_t y = 0; y < g.height; ++y)
      for (int64_t x = 0; x < g.width; ++x) {
        const bool black = (uint8_t(p[y * row + x / 8]) >> (7 - x % 8)) & 1;
        g.value[size_t(y * g.width + x)] = black ? 0 : 255;
      }
    return g;
  }
  const int bytes_per = maxval > 255 ? 2 : 1;
  if (!ascii && end - p < int64_t(n) * channels * bytes_per) truncated();
  for (size_t i = 0; i < n; ++i) {
    double c[3];
    for (int k = 0; k < channels; ++k) {
      double v;
      if (kind == 1) {
        // Plain PBM: one character per pixel, whitespace optional ("0110").
        while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
        if (p >= end || (*p != '0' && *p != '1')) truncated();
        v = double(*p++ - '0');
      } else if (ascii) {
        try {
          v = double(token());
        } catch (const InputError&) {
          truncated();
        }
      } else if (bytes_per == 2) {
        v = double((uint8_t(p[0]) << 8) | uint8_t(p[1]));
        p += 2;
      } else {
        v = double(uint8_t(*p++));
      }
      c[k] = v;
    }
    if (kind == 1) {
      g.value[i] = c[0] != 0 ? 0 : 255;  // PBM: 1 is black
    } else {
      const double lum = channels == 3 ? 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2] : c[0];
      g.value[i] = 255.0 * lum / double(maxval);
    }
  }
  return g;
}

}  // namespace

std::string base64(const std::vector<uint8_t>& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (size_t i = 0; i < in.size(); i += 3) {
    const uint32_t v = uint32_t(in[i]) << 16 | (i + 1 < in.size() ? uint32_t(in[i + 1]) << 8 : 0) |
                       (i + 2 < in.size() ? uint32_t(in[i + 2]) : 0);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < in.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? k[v & 63] : '=';
  }
  return out;
}

GreyImage read_image(const std::string& path, uint64_t max_bytes) {
  const uint64_t cap = max_bytes ? max_bytes : default_memory_limit();
  const std::string ext = detail::extension_of(path);
  if (ext == ".png") return read_png(path, cap);
  if (ext == ".pbm" || ext == ".pgm" || ext == ".ppm" || ext == ".pnm") return read_netpbm(path, cap);
  detail::file_size(path);
  throw InputError(path, "unknown image format '" + ext + "' (use .png, .pbm, .pgm, .ppm)");
}

std::vector<uint8_t> encode_png(int64_t width, int64_t height, const std::vector<uint8_t>& rgba) {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = png_uint_32(width);
  img.height = png_uint_32(height);
  img.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&img, nullptr, &size, 0, rgba.data(), 0, nullptr))
    throw Error(std::string("PNG encoding failed: ") + img.message);
  std::vector<uint8_t> out(size);
  if (!png_image_write_to_memory(&img, out.data(), &size, 0, rgba.data(), 0, nullptr))
    throw Error(std::string("PNG encoding failed: ") + img.message);
  out.resize(size);
  return out;
}

void write_png(const std::string& path, int64_t width, int64_t height, const std::vector<uint8_t>& rgba) {
  const auto png = encode_png(width, height, rgba);
  detail::write_stream_atomically(
      path, [&](std::ostream& out) { out.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size())); });
}

void write_contours_svg(const std::string& path, const Contours2D& c, const Contours2D* mid, const SvgOptions& o) {
  const double scale = o.scale > 0 ? o.scale : std::max(1.0, 1000.0 / double(std::max(c.width, c.height)));
  std::ostringstream svg;
  svg.precision(6);
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << double(c.width) * scale << "\" height=\""
      << double(c.height) * scale << "\" viewBox=\"0 0 " << c.width << ' ' << c.height << "\">\n";
  svg << "<rect width=\"" << c.width << "\" height=\"" << c.height << "\" fill=\"white\"/>\n";
  if (o.pixels) {
    std::vector<uint8_t> rgba(size_t(c.width * c.height) * 4);
    for (size_t i = 0; i < c.inside.size(); ++i) {
      const uint8_t v = c.inside[i] ? 200 : 255;
      rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = v;
      rgba[4 * i + 3] = 255;
    }
    svg << "<image width=\"" << c.width << "\" height=\"" << c.height
        << "\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,"
        << base64(encode_png(c.width, c.height, rgba)) << "\"/>\n";
  }
  auto path_of = [&](const Contours2D& k) {
    std::ostringstream d;
    d.precision(8);
    for (size_t curve = 0; curve + 1 < k.offsets.size(); ++curve) {
      for (uint32_t i = k.offsets[curve]; i < k.offsets[curve + 1]; ++i) {
        const auto p = k.position(k.ids[i]);
        d << (i == k.offsets[curve] ? 'M' : 'L') << p[0] + 0.5 << ' ' << p[1] + 0.5 << ' ';
      }
      d << "Z ";
    }
    return d.str();
  };
  const double stroke = 1.5 / scale;
  if (mid && o.midpoint)
    svg << "<path d=\"" << path_of(*mid) << "\" fill=\"none\" stroke=\"#c0392b\" stroke-width=\"" << stroke << "\"/>\n";
  svg << "<path d=\"" << path_of(c) << "\" fill=\"none\" stroke=\"#1f4e99\" stroke-width=\"" << 1.5 * stroke
      << "\"/>\n</svg>\n";
  const std::string text = svg.str();
  detail::write_stream_atomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace voxpress
