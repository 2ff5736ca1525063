// press --labels from the command line: every label of a label map in one
// process, each mesh checked, interfaces shared bit for bit between the
// label files, written in every format that keeps the face labels, and the
// options that do not apply refused.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include "test_util.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;
using test::count_lines;
using test::run_cli;

TEST(Cli, SharedLabelMapsPerLabel) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  test::TempDir tmp;
  const std::string f = test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz";
  std::string out;
  ASSERT_EQ(run_cli("-q extract " + f + " --label 5 -o " + tmp.path("liver.stl") + " --check", &out), 0) << out;
  ASSERT_EQ(run_cli("check " + tmp.path("liver.stl") + " --volume " + f + " --label 5", &out), 0) << out;
  EXPECT_NE(out.find("0 violations"), std::string::npos);
  EXPECT_EQ(run_cli("-q extract " + f + " --label 4242 -o " + tmp.path("none.stl"), &out), 1);
  EXPECT_NE(out.find("4242"), std::string::npos);
}

// A block (7), a ball (300) in a block (12), on an anisotropic lattice:
// three labels and the background, junction lines where they meet.
void write_three_labels(const std::string& path) {
  ScalarVolume v;
  v.lattice.dims = {20, 18, 16};
  v.lattice.spacing = Vec3(1, 1, 1.5);
  v.type = ScalarType::u16;
  v.bytes.assign(v.lattice.size() * 2, std::byte{0});
  auto* w = reinterpret_cast<uint16_t*>(v.bytes.data());
  for (int64_t k = 2; k < 14; ++k)
    for (int64_t j = 2; j < 16; ++j)
      for (int64_t i = 2; i < 18; ++i) {
        const double x = i - 10.0, y = j - 9.0, z = (k - 8.0) * 1.5;
        w[v.lattice.linear(i, j, k)] = x < 0 ? 7 : (x * x + y * y + z * z < 36 ? 300 : 12);
      }
  write_volume(path, v);
}

// press --labels --faces: the shared surface simplified once; every label's
// file, read back, checked against the map; extract --labels --faces too.
TEST(Cli, PressLabelsFacesSimplifiesTheSharedSurfaceOnce) {
  test::TempDir tmp;
  write_three_labels(tmp.path("map.nrrd"));
  std::string out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all -o " + tmp.path("o") +
                        " --faces 900 --check --stats-json " + tmp.path("s.json"),
                    &out),
            0)
      << out;
  const auto st = nlohmann::json::parse(test::read_file(tmp.path("s.json")));
  EXPECT_LE(st["shared_surface"]["simplify"]["faces"].get<uint64_t>(), 900u);
  EXPECT_GT(st["shared_surface"]["simplify"]["faces_before"].get<uint64_t>(), 2000u);
  EXPECT_EQ(st["interfaces"]["triangles"], st["shared_surface"]["simplify"]["faces"]);
  for (const auto& e : st["labels"])
    EXPECT_EQ(run_cli("check " + tmp.path("o/" + e["file"].get<std::string>()) + " --volume " + tmp.path("map.nrrd") +
                          " --label " + std::to_string(e["value"].get<int>()),
                      &out),
              0)
        << out;
  ASSERT_EQ(run_cli("-q extract " + tmp.path("map.nrrd") + " --labels -o " + tmp.path("mid.ply") +
                        " --faces 900 --check --stats-json " + tmp.path("m.json"),
                    &out),
            0)
      << out;
  EXPECT_LE(nlohmann::json::parse(test::read_file(tmp.path("m.json")))["triangles"].get<uint64_t>(), 900u);
}

// press --labels: one mesh per label into a folder, each read back and
// checked against the whole volume for its own label; names from a table;
// bad requests leave no folder at all.
TEST(Cli, PressLabelsWritesOneCheckedMeshPerLabel) {
  test::TempDir tmp;
  write_three_labels(tmp.path("map.nrrd"));
  test::write_file(tmp.path("names.txt"), "7 left block\n300 ball\n");
  std::string out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --label-names " + tmp.path("names.txt") +
                        " -o " + tmp.path("organs") + " --check",
                    &out),
            0)
      << out;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(tmp.path("organs/labels.json")));
  ASSERT_EQ(j["labels"].size(), 3u);
  for (const auto& e : j["labels"]) {
    const std::string file = tmp.path("organs/" + e["file"].get<std::string>());
    ASSERT_TRUE(fs::exists(file)) << file;
    EXPECT_EQ(run_cli("check " + file + " --volume " + tmp.path("map.nrrd") + " --label " +
                          std::to_string(e["value"].get<int>()),
                      &out),
              0)
        << out;
    EXPECT_NE(out.find("0 violations"), std::string::npos) << out;
    EXPECT_GE(e["touches"].size(), 2u);  // the background and a neighbour label
  }
  EXPECT_TRUE(fs::exists(tmp.path("organs/left_block.ply")));
  EXPECT_TRUE(fs::exists(tmp.path("organs/ball.ply")));
  EXPECT_TRUE(fs::exists(tmp.path("organs/label_12.ply")));
  // Shared interfaces, read back: every triangle of interfaces.ply is in the
  // files of its two labels (the background has none), once each, with
  // opposite orientations, at bit-identical positions; nothing else is.
  EXPECT_TRUE(j["shared"].get<bool>());
  const Mesh all = read_mesh(tmp.path("organs/interfaces.ply"));
  ASSERT_EQ(all.face_attributes.size(), 2u);
  using Key = std::array<float, 9>;
  auto key = [](const Mesh& m, const Triangle& t, bool flip) {
    Key k;
    const uint32_t order[3] = {t[0], flip ? t[2] : t[1], flip ? t[1] : t[2]};
    size_t first = 0;  // rotate the smallest vertex first: one key per oriented triangle
    for (size_t i = 1; i < 3; ++i)
      if (std::lexicographical_compare(m.positions[order[i]].data(), m.positions[order[i]].data() + 3,
                                       m.positions[order[first]].data(), m.positions[order[first]].data() + 3))
        first = i;
    for (size_t i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) k[3 * i + size_t(a)] = float(m.positions[order[(first + i) % 3]][a]);
    return k;
  };
  std::map<int, std::multiset<Key>> want;  // the oriented triangles each label's file must hold
  for (size_t f = 0; f < all.triangles.size(); ++f) {
    const int in = int(all.face_attributes[0].values[f]), outside = int(all.face_attributes[1].values[f]);
    if (in != 0) want[in].insert(key(all, all.triangles[f], false));
    if (outside != 0) want[outside].insert(key(all, all.triangles[f], true));
  }
  for (const auto& [value, file] : {std::pair{7, "left_block.ply"}, {300, "ball.ply"}, {12, "label_12.ply"}}) {
    const Mesh m = read_mesh(tmp.path(std::string("organs/") + file));
    std::multiset<Key> got;
    for (const Triangle& t : m.triangles) got.insert(key(m, t, false));
    EXPECT_TRUE(got == want[value]) << file;
  }
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --separate -o " + tmp.path("alone"), &out), 0)
      << out;
  EXPECT_FALSE(nlohmann::json::parse(test::read_file(tmp.path("alone/labels.json")))["shared"].get<bool>());
  EXPECT_FALSE(fs::exists(tmp.path("alone/interfaces.ply")));
  // The shared surface is fitted and sharpened like one label alone;
  // --no-sharpen keeps its chamfers.
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --no-sharpen --stats-json " +
                        tmp.path("ns.json") + " -o " + tmp.path("chamfered"),
                    &out),
            0)
      << out;
  const nlohmann::json ns = nlohmann::json::parse(test::read_file(tmp.path("ns.json")))["shared_surface"];
  EXPECT_EQ(ns["sharpen"]["crease_vertices"].get<size_t>(), 0u);
  EXPECT_EQ(ns["quadric_fit"]["labels"].get<size_t>(), 3u);
  // The residual each stage of the shared press reached (issue 74): a
  // fraction of the stick, above 0 since 100 sweeps do not converge.
  for (const char* stage : {"junctions", "interfaces"}) {
    const double r = ns["residual"][stage].get<double>();
    EXPECT_TRUE(r > 0 && r < 1) << stage << " " << r;
  }
  // Region colours need --separate (the shared surface has none); --separate
  // needs --labels.
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --color-regions -o " + tmp.path("none"), &out), 2);
  EXPECT_NE(out.find("--separate"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --separate -o " + tmp.path("x.ply"), &out), 2);
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels 300,7 --format stl -o " + tmp.path("two"), &out), 0)
      << out;
  EXPECT_EQ(fs::exists(tmp.path("two/label_300.stl")) + fs::exists(tmp.path("two/label_7.stl")), 2);
  // --format glb: also one scene, a named node per label.
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --format glb -o " + tmp.path("glbs"), &out), 0)
      << out;
  {
    const std::string glb = test::read_file(tmp.path("glbs/all_labels.glb"));
    ASSERT_GT(glb.size(), 20u);
    uint32_t json_bytes = 0;
    std::memcpy(&json_bytes, glb.data() + 12, 4);
    const nlohmann::json gj = nlohmann::json::parse(glb.substr(20, json_bytes));
    ASSERT_EQ(gj["nodes"].size(), 3u);
    std::set<std::string> names;
    for (const auto& node : gj["nodes"]) names.insert(node["name"].get<std::string>());
    EXPECT_EQ(names, (std::set<std::string>{"label_7", "label_300", "label_12"}));
    size_t triangles = 0;
    for (const char* f : {"glbs/label_7.glb", "glbs/label_300.glb", "glbs/label_12.glb"})
      triangles += read_mesh(tmp.path(f)).triangles.size();
    EXPECT_EQ(read_mesh(tmp.path("glbs/all_labels.glb")).triangles.size(), triangles);
  }
  EXPECT_FALSE(fs::exists(tmp.path("two/label_12.stl")));
  // --format vtp|vtk: the interfaces in that format too (VTK keeps the face labels).
  for (const std::string fmt : {"vtp", "vtk"}) {
    ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --format " + fmt + " -o " + tmp.path(fmt), &out), 0)
        << out;
    const Mesh back = read_mesh(tmp.path(fmt + "/interfaces." + fmt));
    EXPECT_FALSE(fs::exists(tmp.path(fmt + "/interfaces.ply")));
    EXPECT_EQ(back.positions, all.positions);
    EXPECT_EQ(back.triangles, all.triangles);
    ASSERT_EQ(back.face_attributes.size(), 2u);
    for (size_t a = 0; a < 2; ++a) EXPECT_EQ(back.face_attributes[a].values, all.face_attributes[a].values);
  }
  ASSERT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels 7,7 -o " + tmp.path("once"), &out), 0) << out;
  EXPECT_EQ(nlohmann::json::parse(test::read_file(tmp.path("once/labels.json")))["labels"].size(), 1u);
  // Refused before any output: absent label, -o a file, bad table, bad format, --label with --labels.
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels 7,99 -o " + tmp.path("none"), &out), 1);
  EXPECT_NE(out.find("99"), std::string::npos);
  EXPECT_EQ(count_lines(out), 1u) << out;
  EXPECT_FALSE(fs::exists(tmp.path("none")));
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all -o " + tmp.path("names.txt"), &out), 2);
  test::write_file(tmp.path("bad.txt"), "7\n");
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --label-names " + tmp.path("bad.txt") +
                        " -o " + tmp.path("none"),
                    &out),
            1);
  EXPECT_NE(out.find("bad.txt"), std::string::npos);
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --format xyz -o " + tmp.path("none"), &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --labels all --label 7 -o " + tmp.path("none"), &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("map.nrrd") + " --label-names " + tmp.path("names.txt") + " --label 7 -o " +
                        tmp.path("x.ply"),
                    &out),
            2);
  EXPECT_FALSE(fs::exists(tmp.path("none")));
  EXPECT_FALSE(fs::exists(tmp.path("x.ply")));
  // A memory cap below what pressing the shared surface needs: one line, nothing written.
  EXPECT_EQ(run_cli("-q --max-memory 200K press " + tmp.path("map.nrrd") + " --labels all -o " + tmp.path("none"), &out), 1);
  EXPECT_NE(out.find("memory limit"), std::string::npos) << out;
  EXPECT_EQ(count_lines(out), 1u) << out;
  EXPECT_FALSE(fs::exists(tmp.path("none")));
}

}  // namespace
}  // namespace voxpress
