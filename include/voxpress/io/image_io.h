// voxpress/io/image_io.h — 2D images for press2d, and PNG output.
//
// Readers: PNG (libpng: 1-16 bit, grey, RGB, palette, alpha composited over
// white) and netpbm (P1-P6: PBM, PGM, PPM, ASCII or binary, maxval up to
// 65535). Pixels become luminance in [0, 255], row-major, y down.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/smooth/pressing.h"

namespace voxpress {

struct GreyImage {
  int64_t width = 0, height = 0;
  std::vector<double> value;  ///< luminance in [0, 255], width * height, row-major
};

/// Reads .png, .pbm, .pgm, .ppm or .pnm. Throws InputError (missing,
/// malformed, truncated, absurd size) naming the file.
GreyImage read_image(const std::string& path, uint64_t max_bytes = 0);

/// Writes an 8-bit RGBA PNG (rgba: width * height * 4), atomically.
void write_png(const std::string& path, int64_t width, int64_t height, const std::vector<uint8_t>& rgba);
/// Encodes an 8-bit RGBA PNG in memory.
std::vector<uint8_t> encode_png(int64_t width, int64_t height, const std::vector<uint8_t>& rgba);
/// Standard base64 (with '=' padding), for data embedded in text formats
/// (the SVG's pixels, the HTML report's meshes).
std::string base64(const std::vector<uint8_t>& data);

struct SvgOptions {
  bool pixels = true;     ///< draw the inside pixels underneath (embedded PNG)
  bool midpoint = false;  ///< also draw the unsmoothed (midpoint) contours
  double scale = 0;       ///< output pixels per image pixel; 0 = fit about 1000 px
};

/// Writes pressed contours as SVG (sample (x, y) at the centre of pixel (x, y)).
/// `midpoint` holds the contours before pressing, drawn when options.midpoint.
void write_contours_svg(const std::string& path, const Contours2D& pressed, const Contours2D* midpoint,
                        const SvgOptions& options = {});

}  // namespace voxpress
