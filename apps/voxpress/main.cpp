// voxpress — command-line front end. Each subcommand lives in its own file
// and only calls library stages; this file owns the one place where
// exceptions become a message and an exit code:
//   0 success   1 bad input (file missing, malformed, limit hit, check failed)
//   2 bad usage (options)   3 internal error (a bug: please report it)
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "common.h"

namespace {
constexpr size_t kMaxErrorChars = 600;  // what one error line may quote
}

int main(int argc, char** argv) {
  using namespace voxpress;
  CLI::App app{"voxpress — smooth, accurate solids from binary voxel volumes", "voxpress"};
  app.set_version_flag("--version", std::string("voxpress ") + kVersion);
  app.require_subcommand(1);
  cli::Global g;
  app.add_option("--threads", g.threads, "Worker threads (default: all cores)")->check(CLI::Range(0, 4096));
  app.add_flag("-q,--quiet", g.quiet, "No progress bar");
  app.add_option("--max-memory", g.max_memory, "Refuse inputs needing more memory than this (e.g. 8G; default: "
                                               "3/4 of RAM or $VOXPRESS_MAX_MEMORY)");
  app.fallthrough();
  cli::register_info(app, g);
  cli::register_extract(app, g);
  cli::register_generate(app, g);
  cli::register_check(app, g);
  cli::register_voxelize(app, g);
  cli::register_eval(app, g);
  cli::register_press(app, g);
  cli::register_press2d(app, g);
  cli::register_smooth_mesh(app, g);
  cli::register_voxart(app, g);
  cli::register_render(app, g);
  cli::register_report(app, g);

  // One line, of bounded length: a broken glTF buffer echoed its whole 161 KB
  // data URI (issue 73). The file's name comes first and is kept.
  auto line = [](const char* what) {
    std::string m(what);
    std::replace(m.begin(), m.end(), '\n', ' ');
    if (m.size() > kMaxErrorChars)
      m = m.substr(0, kMaxErrorChars) + "... (" + std::to_string(m.size() - kMaxErrorChars) + " more characters)";
    return m;
  };
  remove_temporaries_on_signals();  // Ctrl-C while writing left the hidden temporary (issue 73)
  try {
    // Every output of the run appears together, once it has succeeded
    // (check_paths refused bad output paths before any work).
    OutputGroup outputs;
    app.parse(argc, argv);
    outputs.commit();
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "voxpress: error: %s (see voxpress --help)\n", line(e.what()).c_str());
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "voxpress: error: %s\n", line(e.what()).c_str());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "voxpress: error: %s\n", line(e.what()).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "voxpress: internal error: %s\n", line(e.what()).c_str());
    return 3;
  }
  return 0;
}
