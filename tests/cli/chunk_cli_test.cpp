// press --chunk from the command line: a raw NRRD or an HDF5 dataset
// streamed block by block and the same samples gzip-compressed (read whole)
// write the same bytes,
// without a halo the bytes of `press` itself, pass --check, resolve an
// automatic selection over the whole file, and bad options leave no output.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "../labels/label_volumes.h"
#include "test_util.h"

namespace voxpress {
namespace {

using test::run_cli;

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(std::ifstream(path)); }

TEST(ChunkCli, StreamedAndWholeFilesWriteTheSameCheckedBytes) {
  test::TempDir tmp;
  std::string out;
  ASSERT_EQ(run_cli("-q generate cad-part --res 48 --rotate random:2 --spacing 1,1,1.5 -o " + tmp.path("gz.nrrd"), &out), 0)
      << out;
  test::write_raw_volume(tmp.path("raw.nrrd"), read_volume(tmp.path("gz.nrrd")));
  for (const char* name : {"raw", "gz"}) {
    const std::string in = tmp.path(std::string(name) + ".nrrd");
    ASSERT_EQ(run_cli("-q press " + in + " --chunk 16 --halo 14 --check --stats-json " + tmp.path(std::string(name) + ".json") +
                          " -o " + tmp.path(std::string(name) + ".ply"),
                      &out),
              0)
        << out;
    EXPECT_EQ(read_json(tmp.path(std::string(name) + ".json"))["chunks"]["streamed"].get<bool>(), std::string(name) == "raw");
    EXPECT_EQ(read_json(tmp.path(std::string(name) + ".json"))["checks"]["classification_violations"].get<uint64_t>(), 0u);
  }
  const std::string a = test::read_file(tmp.path("raw.ply")), b = test::read_file(tmp.path("gz.ply"));
  EXPECT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "the streamed and the whole file's meshes differ";
  // Without a halo (exact): `press` on the whole volume, byte for byte, flats and sharp edges included.
  ASSERT_EQ(run_cli("-q press " + tmp.path("gz.nrrd") + " -o " + tmp.path("whole.ply"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("raw.nrrd") + " --chunk 16 --check -o " + tmp.path("exact.ply"), &out), 0) << out;
  EXPECT_TRUE(test::read_file(tmp.path("whole.ply")) == test::read_file(tmp.path("exact.ply")));
  // HDF5 (chunked, gzip) streams by hyperslab: the same bytes again.
  ASSERT_EQ(run_cli("-q generate cad-part --res 48 --rotate random:2 --spacing 1,1,1.5 -o " + tmp.path("v.h5"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("v.h5") + ":/volume --chunk 16 --check --stats-json " + tmp.path("h5.json") +
                        " -o " + tmp.path("h5.ply"),
                    &out),
            0)
      << out;
  EXPECT_TRUE(read_json(tmp.path("h5.json"))["chunks"]["streamed"].get<bool>());
  EXPECT_TRUE(test::read_file(tmp.path("whole.ply")) == test::read_file(tmp.path("h5.ply")));
  EXPECT_FALSE(test::read_file(tmp.path("whole.ply")) == a);  // the halo run has no flats
  // A memory cap below what smoothing the stitched surface needs: refused before it, nothing written.
  EXPECT_EQ(run_cli("-q --max-memory 1M press " + tmp.path("raw.nrrd") + " --chunk 16 -o " + tmp.path("capped.ply"), &out), 1);
  EXPECT_NE(out.find("memory limit"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.path("capped.ply")));
  // 1 and 2 threads: the same bytes.
  ASSERT_EQ(run_cli("-q --threads 1 press " + tmp.path("raw.nrrd") + " --chunk 16 --halo 14 -o " + tmp.path("one.ply")), 0);
  EXPECT_TRUE(test::read_file(tmp.path("one.ply")) == a);
}

TEST(ChunkCli, SelectionsResolveOverTheWholeFileAndBadOptionsWriteNothing) {
  test::TempDir tmp;
  // Two labels far apart: most blocks see one value or none.
  ScalarVolume v;
  v.lattice.dims = {40, 20, 20};
  v.bytes.assign(v.lattice.size(), std::byte{0});
  for (int64_t k = 4; k < 16; ++k)
    for (int64_t j = 4; j < 16; ++j) {
      for (int64_t i = 3; i < 12; ++i) v.bytes[v.lattice.linear(i, j, k)] = std::byte{1};
      for (int64_t i = 28; i < 37; ++i) v.bytes[v.lattice.linear(i, j, k)] = std::byte{2};
    }
  test::write_raw_volume(tmp.path("labels.nrrd"), v);
  const std::string in = tmp.path("labels.nrrd"), o = " -o " + tmp.path("x.ply");
  std::string out;
  EXPECT_EQ(run_cli("-q press " + in + " --chunk 10 --halo 4" + o, &out), 1);
  EXPECT_NE(out.find("label map with 2 labels"), std::string::npos) << out;
  EXPECT_NE(out.find("labels.nrrd"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + in + " --chunk 10 --halo 4 --label 7" + o, &out), 1);
  EXPECT_NE(out.find("empty"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + in + " --halo 4" + o, &out), 2);
  EXPECT_EQ(run_cli("-q press " + in + " --chunk 4" + o, &out), 2);
  EXPECT_EQ(run_cli("-q press " + in + " --chunk 10 --halo 4 --no-sharpen" + o, &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("absent.nrrd") + " --chunk 10" + o, &out), 1);
  EXPECT_FALSE(std::filesystem::exists(tmp.path("x.ply")));
  // --label 2 streamed equals --label 2 on a mask of label 2 alone.
  ASSERT_EQ(run_cli("-q press " + in + " --chunk 10 --halo 9 --label 2 --check -o " + tmp.path("two.ply"), &out), 0) << out;
  for (auto& b : v.bytes) b = b == std::byte{2} ? std::byte{1} : std::byte{0};
  test::write_raw_volume(tmp.path("two.nrrd"), v);
  ASSERT_EQ(run_cli("-q press " + tmp.path("two.nrrd") + " --chunk 10 --halo 9 -o " + tmp.path("mask.ply"), &out), 0) << out;
  EXPECT_TRUE(test::read_file(tmp.path("two.ply")) == test::read_file(tmp.path("mask.ply")));
}

// press --labels --chunk: the label map streamed block by block writes the
// in-memory run's files byte for byte (flats read from the file by label
// box), each label checked; options that do not apply write nothing.
TEST(ChunkCli, LabelMapsStreamToTheInMemoryBytes) {
  test::TempDir tmp;
  test::write_raw_volume(tmp.path("map.nrrd"), test::assembly(4).volume);  // two boxes: flats
  const std::string in = tmp.path("map.nrrd");
  std::string out;
  ASSERT_EQ(run_cli("-q press " + in + " --labels all --check -o " + tmp.path("whole"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + in + " --labels all --chunk 16 --check --stats-json " + tmp.path("s.json") + " -o " +
                        tmp.path("blocks"),
                    &out),
            0)
      << out;
  const nlohmann::json j = read_json(tmp.path("s.json"));
  EXPECT_TRUE(j["chunks"]["streamed"].get<bool>());
  EXPECT_EQ(j["chunks"]["blocks"].get<int>(), 64);
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(tmp.path("whole"))) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(test::read_file(e.path().string()) == test::read_file(tmp.path("blocks/" + name))) << name;
    ++files;
  }
  EXPECT_EQ(files, 4u);  // two labels, interfaces.ply, labels.json
  size_t flats = 0;  // the box's faces: the flats' masks were read from the file
  for (const auto& e : j["labels"]) {
    EXPECT_EQ(e["checks"]["classification_violations"].get<uint64_t>(), 0u);
    flats += e["flats"].get<size_t>();
  }
  EXPECT_GT(flats, 0u);
  for (const char* bad : {" --chunk 8 --separate", " --chunk 8 --halo 2", " --chunk 8 --method taubin"}) {
    EXPECT_EQ(run_cli("-q press " + in + " --labels all" + bad + " -o " + tmp.path("no"), &out), 2) << bad;
    EXPECT_FALSE(std::filesystem::exists(tmp.path("no"))) << bad;
  }
}

}  // namespace
}  // namespace voxpress
