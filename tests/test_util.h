// Helpers shared by the tests: temporary folders, random and adversarial
// volumes, the shared data folder, running the CLI.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "voxpress/eval/truth.h"
#include "voxpress/eval/voxelize.h"
#include "voxpress/voxpress.h"

namespace voxpress::test {

/// Runs f, expects an InputError on one line whose message names `path` and
/// contains `what`.
template <class F>
void expect_input_error(F&& f, const std::string& path, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << "no exception for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

/// A fresh, empty folder removed at the end of the test (its files of up to
/// 256 KiB are first copied to $VOXPRESS_KEEP_TEST_FILES when that is set:
/// bench/fuzz's seed corpora).
class TempDir {
 public:
  TempDir();
  ~TempDir();
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  const std::filesystem::path& dir() const { return dir_; }
  /// Names of the files the folder holds (to assert nothing partial was left).
  std::vector<std::string> files() const;

 private:
  std::filesystem::path dir_;
};

/// The bytes of a file ("" if it cannot be read).
std::string read_file(const std::string& path);

/// ../shared/data next to the repository, or "" when absent.
std::string shared_data();
/// Skips the current test with a message when ../shared/data is absent.
#define VOXPRESS_REQUIRE_SHARED_DATA()                                                          \
  do {                                                                                          \
    if (voxpress::test::shared_data().empty())                                                   \
      GTEST_SKIP() << "../shared/data is absent (clone it beside the repository to run this)"; \
  } while (0)

/// A model from ../shared/data/meshes voxelized at `res` with rotation
/// random:seed, and its exact truth in the volume's physical frame (the
/// caller checks that the shared data is present).
struct VoxelizedModel {
  BinaryVolume volume;
  Mesh physical;  ///< the model in the volume's physical frame
  std::unique_ptr<Truth> truth;
};
VoxelizedModel voxelized_shared_model(const std::string& file, int64_t res, int seed);
/// The same for a model built by the test (`name` labels its truth).
VoxelizedModel voxelized_model(const Mesh& model, const std::string& name, int64_t res, int seed);

/// Deterministic generator (splitmix64), independent of the standard library.
class Rng {
 public:
  explicit Rng(uint64_t seed) : s_(seed * 0x9e3779b97f4a7c15ull + 1) {}
  uint64_t next();
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  int64_t range(int64_t lo, int64_t hi) { return lo + int64_t(next() % uint64_t(hi - lo + 1)); }

 private:
  uint64_t s_;
};

BinaryVolume make_volume(int64_t nx, int64_t ny, int64_t nz);
BinaryVolume random_noise(Rng& rng, std::array<int64_t, 3> dims, double density);
/// A scalar volume of random values in [0, max_value] (as `type`), on a
/// rotated, anisotropic LPS lattice away from the origin.
ScalarVolume random_scalar_volume(ScalarType type, std::array<int64_t, 3> dims, uint64_t seed, int64_t components = 1,
                                  int64_t max_value = 100);
/// Writes a volume uncompressed (a raw NRRD streams block by block).
void write_raw_volume(const std::string& path, const ScalarVolume& v);
BinaryVolume random_blobs(Rng& rng, std::array<int64_t, 3> dims, int blobs);
/// Inside where (i + j + k) % 2 == 0 (every neighbour pair differs).
BinaryVolume checkerboard(std::array<int64_t, 3> dims, int period_axes = 7);

/// The volume with `lo` samples added before and `hi` after each axis
/// (negative: removed), its origin moved so that every sample stays where it
/// is; new samples are outside (background). A scalar volume comes back as
/// u8, one component (values 0..255).
BinaryVolume reframed(const BinaryVolume& v, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi);
ScalarVolume reframed(const ScalarVolume& v, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi);
/// The volume cropped to the box of its inside (non-zero) samples.
BinaryVolume cropped(const BinaryVolume& v);
ScalarVolume cropped(const ScalarVolume& v);

/// A named volume for property tests.
struct Case {
  std::string name;
  BinaryVolume volume;
};
/// The Foundation property-test corpus: hundreds of random, adversarial and
/// generated volumes (also reused by later methods' property tests).
std::vector<Case> property_volumes();

/// The CAD part at `res`, rotation random:3, on an anisotropic lattice
/// (0.7, 0.7, 1.9) far from the origin: a larger float32 rounding to keep
/// clear of.
BinaryVolume far_anisotropic_part(int64_t res);

/// The mesh with its positions rounded to float32, as STL and glTF store
/// them and as most viewers load PLY.
Mesh rounded_to_float32(Mesh m);
/// What the user gets, in double and after float32 rounding: closed,
/// 2-manifold, oriented, no self-intersection, every sample of `v` on its side.
void expect_guarantees(const Mesh& m, const BinaryVolume& v);

/// Writes bytes to a file (test inputs).
void write_file(const std::string& path, const std::string& bytes);

/// MagicaVoxel .vox building blocks: a little-endian int32, a chunk (id,
/// content, children), a DICT, and a whole file with one model (voxels are
/// x, y, z, colour index 1..255; an RGBA chunk when `palette` has 256
/// entries) followed by `extra` chunks inside MAIN.
std::string le32(int32_t v);
std::string vox_chunk(const std::string& id, const std::string& content, const std::string& children = {});
std::string vox_dict(const std::vector<std::pair<std::string, std::string>>& entries);
std::string vox_model(std::array<int, 3> size, const std::vector<std::array<uint8_t, 4>>& voxels);
std::string vox_file(const std::string& main_children, int32_t version = 150);

/// A little-endian float32; a minimal Westwood .vxl: one section "Body" of
/// 2 x 1 x 3 voxels holding 3 voxels (placement described in test_util.cpp).
std::string f32(float v);
std::string vxl_file();

/// Runs the voxpress CLI with `args`; returns the exit code, fills output
/// with stdout and stderr combined.
int run_cli(const std::string& args, std::string* output = nullptr);
/// A CLI run measured by the kernel: exit code (-1 if killed by a signal),
/// stdout and stderr combined, and the peak resident memory of the process
/// (wait4's ru_maxrss, KiB).
struct CliRun {
  int code = -1;
  std::string output;
  int64_t peak_kib = 0;
};
/// Runs the voxpress CLI with `args` (split on blanks) under an address-space
/// limit (RLIMIT_AS, bytes; 0 = none), so that a regression fails the test
/// instead of exhausting the machine.
CliRun run_cli_measured(const std::string& args, uint64_t address_space_limit = 0);
/// A generated shape at `res`, rotation random:seed, with its exact truth;
/// the box's edges and corners rounded by `fillet` cells (issue 75's
/// family; 0: sharp).
struct ShapeAndTruth {
  GeneratedShape shape;
  std::unique_ptr<Truth> truth;
};
inline ShapeAndTruth shape_and_truth(ShapeKind kind, int64_t res, int seed, double fillet = 0) {
  GenerateOptions o;
  o.res = res;
  o.rotation = parse_rotation("random:" + std::to_string(seed));
  o.fillet = fillet;
  ShapeAndTruth b{generate_shape(kind, o), nullptr};
  b.truth = shape_truth(kind, b.shape.linear, b.shape.translation, b.shape.fillet);
  return b;
}
inline ShapeAndTruth filleted_box(int64_t res, int seed, double fillet) {
  return shape_and_truth(ShapeKind::box, res, seed, fillet);
}
/// A rule of the feature layer on (every pass) and off, on `shape`: both
/// results and the rule's count with it on; the default's guarantees are
/// checked.
struct RuleOnOff {
  ShapeAndTruth box;
  SurfaceResult on, off;
  size_t count = 0;
};
inline RuleOnOff rule_on_off(ShapeAndTruth shape, Pass rule) {
  RuleOnOff r{std::move(shape), {}, {}, 0};
  SurfaceOptions off;
  off.passes.disable(rule);
  r.on = smooth_surface(r.box.shape.volume);
  r.off = smooth_surface(r.box.shape.volume, off);
  expect_guarantees(r.on.mesh, r.box.shape.volume);
  r.count = r.on.pass_times.count[size_t(rule)];
  return r;
}
inline RuleOnOff fillet_rule_on_off(int64_t res, int seed, double fillet, Pass rule) {
  return rule_on_off(filleted_box(res, seed, fillet), rule);
}
/// Lines in a command's output (one error = one line).
inline size_t count_lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// The driver's trace, cut where the table index stops increasing, is a
// sequence of stage runs; each must be exactly its stage's steps that
// runs() allows, in table order, and the stages must come in pipeline
// order (detection rounds, crease rounds, fit, sharpening): the pipeline's
// one sequence (src/smooth/sequence.h), for a binary run and a label map's
// shared surface (whose stages run once per label) alike.
inline void expect_trace_follows_table(const std::vector<Pass>& trace, const PassSet& on) {
  const auto& table = feature_passes();
  std::vector<std::vector<Pass>> runs_of_stage;
  for (size_t i = 0; i < trace.size(); ++i) {
    if (i == 0 || size_t(trace[i]) <= size_t(trace[i - 1]) || table[size_t(trace[i])].stage != table[size_t(trace[i - 1])].stage)
      runs_of_stage.emplace_back();
    runs_of_stage.back().push_back(trace[i]);
  }
  ASSERT_FALSE(runs_of_stage.empty());
  Stage last = Stage::detect;
  for (const std::vector<Pass>& r : runs_of_stage) {
    const Stage stage = table[size_t(r.front())].stage;
    EXPECT_GE(stage, last);
    last = stage;
    std::vector<Pass> expected;
    for (const PassInfo& p : table)
      if (p.stage == stage && p.run && runs(p, on)) expected.push_back(p.pass);
    EXPECT_EQ(r, expected) << "stage " << int(stage);
  }
}

}  // namespace voxpress::test
