// Hostile inputs from the command line (issue 73): memory bombs and values
// that were silently replaced. Every input is generated here; each case
// asserts the exit code, one line naming the file, no output left behind and,
// for the memory bombs, the peak resident memory the kernel measured (the run
// is held under an address-space limit, so a regression fails instead of
// exhausting the machine).
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>

#include "io/io_util.h"
#include "test_util.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;
using test::count_lines;
using test::le32;
using test::vox_chunk;
using test::vox_dict;

// Address space a small run may take (TBB and glibc reserve a few hundred MiB
// of it without touching it) and the resident peak it may reach.
constexpr uint64_t kAddressSpace = uint64_t(1536) << 20;
constexpr int64_t kPeakKib = 100 << 10;

// Exit code 1, one line naming `name`, `what` in it, and a peak under kPeakKib.
void expect_refused(const test::CliRun& r, const std::string& name, const std::string& what) {
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1u) << r.output;
  EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(what), std::string::npos) << r.output;
  EXPECT_LT(r.peak_kib, kPeakKib) << r.output;
}

// A small label map: labels 7 and 300 in a 12³ box.
void write_label_map(const std::string& path) {
  ScalarVolume v;
  v.lattice.dims = {12, 12, 12};
  v.type = ScalarType::u16;
  v.bytes.assign(v.lattice.size() * 2, std::byte{0});
  auto* w = reinterpret_cast<uint16_t*>(v.bytes.data());
  for (int64_t k = 2; k < 10; ++k)
    for (int64_t j = 2; j < 10; ++j)
      for (int64_t i = 2; i < 10; ++i) w[v.lattice.linear(i, j, k)] = i < 6 ? 7 : 300;
  write_volume(path, v);
}

// --label-names is a bounded regular file: /dev/zero ran 24 s, peaked at
// 16.8 GB and exited 0 with the names ignored; a folder was ignored silently.
TEST(Hostile, LabelNamesMustBeABoundedRegularFile) {
  test::TempDir tmp;
  write_label_map(tmp.path("map.nrrd"));
  fs::create_directory(tmp.path("folder"));
  std::string big(kMaxLabelNamesBytes + 1, ' ');
  for (size_t i = 0; i + 1 < big.size(); i += 64) big[i] = '#', big[i + 63] = '\n';
  test::write_file(tmp.path("big.txt"), big);
  const std::string press = "-q press " + tmp.path("map.nrrd") + " --labels all -o " + tmp.path("out") + " --label-names ";
  expect_refused(test::run_cli_measured(press + "/dev/zero", kAddressSpace), "/dev/zero", "not a regular file");
  expect_refused(test::run_cli_measured(press + tmp.path("folder"), kAddressSpace), tmp.path("folder"),
                 "is a directory");
  expect_refused(test::run_cli_measured(press + tmp.path("big.txt"), kAddressSpace), tmp.path("big.txt"), "MiB");
  EXPECT_FALSE(fs::exists(tmp.path("out")));
  // The same table within the cap is read.
  test::write_file(tmp.path("names.txt"), "# organs\n7 left\n300 right\n");
  const test::CliRun ok = test::run_cli_measured(press + tmp.path("names.txt"), kAddressSpace);
  ASSERT_EQ(ok.code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(tmp.path("out/left.ply")));
  EXPECT_TRUE(fs::exists(tmp.path("out/right.ply")));
}

}  // namespace
}  // namespace voxpress
