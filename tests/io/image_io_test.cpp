// 2D images for press2d: PNG and netpbm readers agree on the same picture,
// bad files fail with the file's name, and the SVG holds the contours.
#include <fstream>
#include <regex>

#include "test_util.h"
#include "voxpress/io/image_io.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;

// A w x h test picture: a dark disc on white, with a grey ramp row.
std::vector<uint8_t> picture(int w, int h) {
  std::vector<uint8_t> g(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dx = x - 0.45 * w, dy = y - 0.55 * h;
      g[size_t(y * w + x)] = dx * dx + dy * dy < 0.1 * w * h ? 20 : 255;
      if (y == 0) g[size_t(x)] = uint8_t(255 * x / (w - 1));
    }
  return g;
}

TEST(ImageIo, PngAndNetpbmVariantsReadTheSamePicture) {
  test::TempDir tmp;
  const int w = 23, h = 17;
  const auto g = picture(w, h);
  std::vector<uint8_t> rgba(size_t(w * h) * 4);
  for (size_t i = 0; i < g.size(); ++i) rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = g[i], rgba[4 * i + 3] = 255;
  write_png(tmp.path("a.png"), w, h, rgba);
  const std::string header = std::to_string(w) + " " + std::to_string(h);
  // Binary PGM, ASCII PGM with a comment, 16-bit PGM, binary PPM.
  test::write_file(tmp.path("b.pgm"), "P5\n" + header + "\n255\n" + std::string(g.begin(), g.end()));
  std::string ascii = "P2\n# made by the test\n" + header + "\n255\n";
  for (uint8_t v : g) ascii += std::to_string(v) + " ";
  test::write_file(tmp.path("c.pgm"), ascii);
  std::string wide = "P5\n" + header + "\n65535\n";
  for (uint8_t v : g) wide += std::string{char(v), char(v)};  // v * 257
  test::write_file(tmp.path("d.pgm"), wide);
  std::string ppm = "P6\n" + header + "\n255\n";
  for (uint8_t v : g) ppm += std::string(3, char(v));
  test::write_file(tmp.path("e.ppm"), ppm);
  for (const std::string name : {"a.png", "b.pgm", "c.pgm", "d.pgm", "e.ppm"}) {
    SCOPED_TRACE(name);
    const GreyImage img = read_image(tmp.path(name));
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    for (size_t i = 0; i < g.size(); ++i) ASSERT_NEAR(img.value[i], g[i], 0.51) << i;
  }
  // PBM: 1 is black. Binary rows are padded to whole bytes.
  std::string p1 = "P1\n" + header + "\n", p4 = "P4\n" + header + "\n";
  for (int y = 0; y < h; ++y) {
    std::vector<uint8_t> row((w + 7) / 8, 0);
    for (int x = 0; x < w; ++x) {
      const bool black = g[size_t(y * w + x)] < 128;
      p1 += black ? "1" : "0";
      if (black) row[size_t(x / 8)] |= uint8_t(0x80 >> (x % 8));
    }
    p1 += "\n";
    p4 += std::string(row.begin(), row.end());
  }
  test::write_file(tmp.path("f.pbm"), p1);
  test::write_file(tmp.path("g.pbm"), p4);
  for (const std::string name : {"f.pbm", "g.pbm"}) {
    const GreyImage img = read_image(tmp.path(name));
    ASSERT_EQ(img.width, w);
    for (size_t i = 0; i < g.size(); ++i) ASSERT_EQ(img.value[i] < 128, g[i] < 128) << name << " " << i;
  }
}

TEST(ImageIo, BadImagesNameTheFileAndTheProblem) {
  test::TempDir tmp;
  const auto g = picture(40, 30);
  std::vector<uint8_t> rgba(g.size() * 4, 255);
  write_png(tmp.path("ok.png"), 40, 30, rgba);
  const std::string png = test::read_file(tmp.path("ok.png"));
  test::write_file(tmp.path("trunc.png"), png.substr(0, png.size() / 2));
  test::write_file(tmp.path("notpng.png"), "hello, this is not a PNG");
  test::write_file(tmp.path("trunc.pgm"), "P5\n40 30\n255\n" + std::string(100, 'x'));
  test::write_file(tmp.path("huge.pgm"), "P5\n2000000000 2000000000\n255\n");
  test::write_file(tmp.path("maxval.pgm"), "P5\n4 4\n0\n" + std::string(16, 'x'));
  test::write_file(tmp.path("header.pgm"), "P5\n4 four\n255\n");
  test::write_file(tmp.path("notpbm.pgm"), "GIF89a");
  test::write_file(tmp.path("a.gif"), "GIF89a");
  const std::pair<std::string, std::string> cases[] = {
      {"missing.png", "no such file"}, {"trunc.png", "PNG"},       {"notpng.png", "not a readable PNG"},
      {"trunc.pgm", "truncated"},      {"huge.pgm", "absurd"},     {"maxval.pgm", "maxval"},
      {"header.pgm", "malformed"},     {"notpbm.pgm", "netpbm"},  {"a.gif", "unknown image format"},
  };
  for (const auto& [name, problem] : cases) {
    SCOPED_TRACE(name);
    try {
      read_image(tmp.path(name));
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
    }
  }
}

TEST(ImageIo, SvgHoldsEveryContourVertex) {
  test::TempDir tmp;
  const int w = 30, h = 20;
  const auto g = picture(w, h);
  std::vector<uint8_t> inside(g.size());
  for (size_t i = 0; i < g.size(); ++i) inside[i] = g[i] < 128;
  const Contours2D mid = extract_contours(w, h, inside);
  Contours2D pressed = mid;
  press(pressed);
  SvgOptions o;
  o.midpoint = true;
  write_contours_svg(tmp.path("c.svg"), pressed, &mid, o);
  const std::string svg = test::read_file(tmp.path("c.svg"));
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // Two paths (midpoint, pressed), each with one M per contour and one point per vertex.
  const std::regex path_re("<path d=\"([^\"]*)\"");
  std::vector<std::string> paths;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), path_re); it != std::sregex_iterator(); ++it)
    paths.push_back((*it)[1]);
  ASSERT_EQ(paths.size(), 2u);
  const size_t contours = mid.offsets.size() - 1;
  for (const std::string& d : paths) {
    EXPECT_EQ(size_t(std::count(d.begin(), d.end(), 'M')), contours);
    EXPECT_EQ(size_t(std::count(d.begin(), d.end(), 'M') + std::count(d.begin(), d.end(), 'L')), mid.t.size());
  }
  // The pressed path's first point is the first vertex (pixel centres at +0.5).
  const auto p = pressed.position(pressed.ids[0]);
  std::istringstream first(paths[1].substr(1));
  double x = 0, y = 0;
  first >> x >> y;
  EXPECT_NEAR(x, p[0] + 0.5, 1e-6);
  EXPECT_NEAR(y, p[1] + 0.5, 1e-6);
  o.pixels = false;
  write_contours_svg(tmp.path("bare.svg"), pressed, &mid, o);
  EXPECT_EQ(test::read_file(tmp.path("bare.svg")).find("<image"), std::string::npos);
}

}  // namespace
}  // namespace voxpress
