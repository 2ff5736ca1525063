// One libFuzzer target per reader (issue 11). Each target is this file
// compiled with VOXPRESS_FUZZ_KIND and VOXPRESS_FUZZ_EXT: the input bytes are
// written to a file with that extension in a private folder and read through
// the public reader, exactly as the CLI reads a user's file. A reader may
// refuse the input only with voxpress::InputError (or LimitError); any other
// exception, a crash, a sanitizer report, a leak, a hang (-timeout) or an
// allocation above libFuzzer's -rss_limit_mb is a finding.
//
// Kinds: volume (NRRD, NIfTI, MetaImage, TIFF), raw (the first 16 bytes
// choose the layout), mesh (PLY, OBJ, STL, OFF), voxart (.vox, .vxl),
// hva (the tests' one-section .vxl with the input as its .hva), image (PNG, PNM).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_util.h"
#include "voxpress/io/image_io.h"
#include "voxpress/io/mesh_io.h"
#include "voxpress/io/volume_io.h"
#include "voxpress/voxart/voxel_art.h"

#ifndef VOXPRESS_FUZZ_KIND
#error "define VOXPRESS_FUZZ_KIND (volume, raw, mesh, voxart, hva or image)"
#endif

namespace fs = std::filesystem;
using namespace voxpress;

namespace {

constexpr uint64_t kCap = uint64_t(64) << 20;  // the readers' memory cap during fuzzing

#define VOXPRESS_KIND_volume 1
#define VOXPRESS_KIND_raw 2
#define VOXPRESS_KIND_mesh 3
#define VOXPRESS_KIND_voxart 4
#define VOXPRESS_KIND_hva 5
#define VOXPRESS_KIND_image 6
#define VOXPRESS_CAT(a, b) a##b
#define VOXPRESS_KIND_ID(k) VOXPRESS_CAT(VOXPRESS_KIND_, k)
constexpr int kKind = VOXPRESS_KIND_ID(VOXPRESS_FUZZ_KIND);

const fs::path& folder() {
  static const fs::path dir = [] {
    const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    fs::path d = base / ("voxpress-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  static const bool cleanup = [] {
    // Removed at a normal exit; bench/fuzz sweeps what crashed processes leave.
    return std::atexit([] {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }) == 0;
  }();
  (void)cleanup;
  return dir;
}

void write(const fs::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path path = folder() / (std::string("input") + VOXPRESS_FUZZ_EXT);
  try {
    if constexpr (kKind == VOXPRESS_KIND_volume) {
      write(path, data, size);
      ReadOptions o;
      o.max_bytes = kCap;
      (void)read_volume(path.string(), o);
    } else if constexpr (kKind == VOXPRESS_KIND_raw) {
      // Layout from the first 16 bytes: dims (1..64 each), type, endianness,
      // header bytes; the rest is the file.
      if (size < 16) return 0;
      RawLayout l;
      for (int a = 0; a < 3; ++a) l.dims[a] = 1 + (data[a] % 64);
      l.type = static_cast<ScalarType>(data[3] % 10);
      l.big_endian = data[4] & 1;
      l.header_bytes = data[5] % 32;
      l.spacing = Vec3(0.25 + data[6] % 8, 1.0, 0.5 + data[7] % 3);
      write(path, data + 16, size - 16);
      ReadOptions o;
      o.max_bytes = kCap;
      o.raw = l;
      (void)read_volume(path.string(), o);
    } else if constexpr (kKind == VOXPRESS_KIND_mesh) {
      write(path, data, size);
      MeshReadOptions o;
      o.max_bytes = kCap;
      (void)read_mesh(path.string(), o);
    } else if constexpr (kKind == VOXPRESS_KIND_voxart || kKind == VOXPRESS_KIND_hva) {
      fs::path model = path;
      if constexpr (kKind == VOXPRESS_KIND_hva) {
        static const std::string vxl = test::vxl_file();
        model = folder() / "input.vxl";
        write(model, reinterpret_cast<const uint8_t*>(vxl.data()), vxl.size());
      }
      write(path, data, size);
      VoxelArtReadOptions o;
      o.max_bytes = kCap;
      (void)read_voxel_art(model.string(), o);
    } else if constexpr (kKind == VOXPRESS_KIND_image) {
      write(path, data, size);
      (void)read_image(path.string(), kCap);
    }
  } catch (const InputError&) {
    // The documented refusal: one line naming the file.
  }
  // Anything else escapes: libFuzzer reports an uncaught exception as a crash.
  return 0;
}
