// voxpress press2d IMG -o OUT.svg: a binary image's contours, pressed.
#include <cstdio>
#include <filesystem>

#include "common.h"

namespace voxpress::cli {
namespace {

struct Press2dCmd {
  std::string input, output, stats_json;
  double threshold = 128;
  bool invert = false, no_pixels = false, midpoint = false;
  PressCli smooth;
};

void run_press2d(const Press2dCmd& c, const Global& g) {
  check_paths({c.input}, {{c.output, OutputKind::svg}, {c.stats_json, OutputKind::json}});

  const PressOptions o = c.smooth.resolve();
  const GreyImage img = read_image(c.input, g.memory_limit());
  std::vector<uint8_t> inside(img.value.size());
  uint64_t count = 0;
  for (size_t i = 0; i < inside.size(); ++i) {
    inside[i] = (img.value[i] < c.threshold) != c.invert ? 1 : 0;
    count += inside[i];
  }
  if (count == 0) throw InputError(c.input, "no pixel is inside (check --threshold / --invert)");
  if (count == inside.size()) throw InputError(c.input, "every pixel is inside (check --threshold / --invert)");
  const Contours2D midpoint = extract_contours(img.width, img.height, std::move(inside));
  Contours2D pressed = midpoint;
  const PressStats st = press(pressed, o);
  SvgOptions so;
  so.pixels = !c.no_pixels;
  so.midpoint = c.midpoint;
  write_contours_svg(c.output, pressed, &midpoint, so);
  if (!g.quiet)
    std::fprintf(stderr, "%s: %zu contours, %zu vertices, %d iterations\n", c.output.c_str(), st.curves,
                 pressed.t.size(), st.iterations);
  if (!c.stats_json.empty()) {
    nlohmann::json j;
    j["command"] = "press2d";
    j["input"] = c.input;
    j["output"] = c.output;
    j["width"] = img.width;
    j["height"] = img.height;
    j["inside_pixels"] = count;
    j["pressing"] = press_stats_json(st, o);
    write_json(c.stats_json, j);
  }
}

}  // namespace

void register_press2d(CLI::App& app, Global& g) {
  auto c = std::make_shared<Press2dCmd>();
  auto* cmd = app.add_subcommand("press2d", "Pressed contours of a binary image (PNG, PBM/PGM/PPM) as SVG");
  cmd->add_option("input", c->input, "Image (.png .pbm .pgm .ppm)")->required();
  cmd->add_option("-o,--output", c->output, "Output SVG")->required();
  cmd->add_option("--threshold", c->threshold, "Inside = luminance below this (0..255)")->capture_default_str();
  cmd->add_flag("--invert", c->invert, "Inside = luminance at or above the threshold (bright objects)");
  cmd->add_flag("--no-pixels", c->no_pixels, "Do not draw the pixels under the contours");
  cmd->add_flag("--midpoint", c->midpoint, "Also draw the unsmoothed midpoint contours");
  c->smooth.bind(*cmd, false);  // no flats in 2D: no barriers
  cmd->add_option("--stats-json", c->stats_json, "Write counts and timings as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_press2d(*c, g);
  });
}

}  // namespace voxpress::cli
