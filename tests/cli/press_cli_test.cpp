// voxpress press, press2d and smooth-mesh from the command line: every
// sample kept on its side, flats and regions written, each method checked
// for what it promises, contours over the pixels, a Slicer-like STL smoothed
// without its volume.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "test_util.h"
#include "voxpress/eval/truth.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;
using test::count_lines;
using test::run_cli;

TEST(Cli, PressSmoothsAndKeepsEverySampleOnItsSide) {
  test::TempDir tmp;
  std::string out;
  ASSERT_EQ(run_cli("-q generate torus --res 48 --rotate random:5 --spacing 1,1,1.4 -o " + tmp.path("t.nrrd"), &out), 0)
      << out;
  ASSERT_EQ(run_cli("-q extract " + tmp.path("t.nrrd") + " -o " + tmp.path("mid.ply"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("p.ply") + " --check --stats-json " +
                        tmp.path("s.json"),
                    &out),
            0)
      << out;
  const auto st = nlohmann::json::parse(std::ifstream(tmp.path("s.json")));
  EXPECT_EQ(st["method"], "pressing");
  EXPECT_GT(st["pressing"]["iterations"].get<int>(), 0);
  EXPECT_LE(st["pressing"]["iterations"].get<int>(), st["pressing"]["max_iterations"].get<int>());
  EXPECT_EQ(st["checks"]["classification_violations"], 0);
  EXPECT_EQ(st["checks"]["mesh_ok"], true);
  ASSERT_EQ(run_cli("check " + tmp.path("p.ply") + " --volume " + tmp.path("t.nrrd"), &out), 0) << out;
  // Pressing is closer to the truth than the midpoint surface, in physical units too.
  auto rms = [&](const std::string& mesh) {
    EXPECT_EQ(run_cli("-q eval " + tmp.path(mesh) + " --volume " + tmp.path("t.nrrd") + " --samples 20000 --json " +
                          tmp.path("e.json"),
                      &out),
              0)
        << out;
    return nlohmann::json::parse(std::ifstream(tmp.path("e.json")))["voxels"]["result_to_truth"]["rms"].get<double>();
  };
  const double mid = rms("mid.ply"), pressed = rms("p.ply");
  EXPECT_LT(pressed, 0.6 * mid) << "midpoint " << mid << ", pressed " << pressed;
  // Options: a tolerance stops early; the same bytes for 1 and 2 threads.
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("q.ply") + " --tolerance 0.05 --stats-json " +
                        tmp.path("q.json"),
                    &out),
            0);
  EXPECT_LT(nlohmann::json::parse(std::ifstream(tmp.path("q.json")))["pressing"]["iterations"].get<int>(),
            st["pressing"]["iterations"].get<int>());
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("one.ply") + " --threads 1", &out), 0);
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("two.ply") + " --threads 2", &out), 0);
  EXPECT_EQ(test::read_file(tmp.path("one.ply")), test::read_file(tmp.path("two.ply")));
  EXPECT_EQ(test::read_file(tmp.path("one.ply")), test::read_file(tmp.path("p.ply")));
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("w.obj") + " --weighting tangent --plain "
                    "--iterations 20",
                    &out),
            0)
      << out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("k.ply") + " --circle-correction 0 --check", &out), 0)
      << out;
  EXPECT_NE(test::read_file(tmp.path("k.ply")), test::read_file(tmp.path("p.ply"))) << "--circle-correction 0 changes the result";
  // Bad usage and bad input.
  const auto before = tmp.files();
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.ply") + " --weighting sideways", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.ply") + " --circle-correction 60", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.ply") + " --method taubin --circle-correction 0", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.ply") + " --margin 0.7", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.ply") + " --iterations -1", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("nope.nrrd") + " -o " + tmp.path("x.ply"), &out), 1);
  EXPECT_EQ(count_lines(out), 1u) << out;
  EXPECT_NE(out.find("nope.nrrd"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + tmp.path("t.nrrd") + " -o " + tmp.path("x.xyz"), &out), 2);
  EXPECT_NE(out.find("x.xyz"), std::string::npos) << out;
  EXPECT_EQ(tmp.files(), before);
}

TEST(Cli, PressFindsFlatsAndWritesRegions) {
  test::TempDir tmp;
  std::string out;
  ASSERT_EQ(run_cli("-q generate box --res 48 --rotate random:4 -o " + tmp.path("b.nrrd"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("b.ply") + " --check --color-regions --stats-json " +
                        tmp.path("b.json"),
                    &out),
            0)
      << out;
  const auto st = nlohmann::json::parse(std::ifstream(tmp.path("b.json")));
  ASSERT_EQ(st["flats"]["count"], 6);
  ASSERT_EQ(st["flats"]["flats"].size(), 6u);
  size_t frozen = 0;
  for (const auto& f : st["flats"]["flats"]) {
    ASSERT_EQ(f["normal"].size(), 3u);
    const double len = std::hypot(f["normal"][0].get<double>(), f["normal"][1].get<double>(), f["normal"][2].get<double>());
    EXPECT_NEAR(len, 1, 1e-9);
    EXPECT_GT(f["area"].get<double>(), 64);
    frozen += f["sticks"].get<size_t>();
    EXPECT_TRUE(f.contains("offset"));
  }
  EXPECT_EQ(st["flats"]["frozen"].get<size_t>(), frozen);
  EXPECT_EQ(st["checks"]["classification_violations"], 0);
  const Mesh m = read_mesh(tmp.path("b.ply"));
  const MeshAttribute* region = m.vertex_attribute("region");
  ASSERT_TRUE(region != nullptr);
  ASSERT_TRUE(m.vertex_attribute("junction") != nullptr);
  EXPECT_EQ(m.colors.size(), m.vertex_count());
  size_t in_flats = 0;
  for (double r : region->values) {
    ASSERT_GE(r, -1);
    ASSERT_LT(r, 6);
    in_flats += r >= 0;
  }
  // Sharpening adds the chamfer leftovers that join a flat (and new vertices, curved).
  EXPECT_GE(in_flats, frozen);
  EXPECT_LT(in_flats, frozen + frozen / 5);
  // Sharpened by default: face regions, labelled sharp edges, the features file, eval's sharp-edge distances.
  EXPECT_TRUE(st.contains("sharpen"));
  EXPECT_GT(st["sharpen"]["sharp_edges"].get<size_t>(), 0u);
  EXPECT_EQ(st["sharpen"]["tangent_planes"].get<size_t>(), 0u);  // a box: no curved side
  EXPECT_EQ(st["sharpen"]["final_crease_vertices"].get<size_t>(), 0u);
  ASSERT_TRUE(m.face_attribute("region") != nullptr);
  ASSERT_TRUE(m.vertex_attribute("feature") != nullptr);
  EXPECT_EQ(m.edges.size(), st["sharpen"]["sharp_edges"].get<size_t>());
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("s.obj") + " --features " + tmp.path("f.ply"), &out), 0)
      << out;
  const Mesh features = read_mesh(tmp.path("f.ply"));
  EXPECT_TRUE(features.triangles.empty());
  EXPECT_EQ(features.edges.size(), m.edges.size());
  EXPECT_NE(test::read_file(tmp.path("s.obj")).find("\nl "), std::string::npos);
  ASSERT_EQ(run_cli("-q eval " + tmp.path("b.ply") + " --volume " + tmp.path("b.nrrd") + " --json " + tmp.path("e.json"), &out), 0)
      << out;
  const auto ev = nlohmann::json::parse(std::ifstream(tmp.path("e.json")));
  EXPECT_LT(ev["sharp_edges"]["voxels"]["hausdorff"].get<double>(), 3.0);
  EXPECT_EQ(ev["labelled_sharp_edges"].get<size_t>(), m.edges.size());
  // --sharp-match: the distance that counts as found, recorded in the report.
  ASSERT_EQ(run_cli("-q eval " + tmp.path("b.ply") + " --volume " + tmp.path("b.nrrd") + " --sharp-match 0.0001 --json " +
                        tmp.path("e2.json"),
                    &out),
            0)
      << out;
  const auto ev2 = nlohmann::json::parse(std::ifstream(tmp.path("e2.json")));
  EXPECT_DOUBLE_EQ(ev2["sharp_edges"]["voxels"]["match"].get<double>(), 0.0001);
  EXPECT_LT(ev2["sharp_edges"]["voxels"]["recall"].get<double>(), ev["sharp_edges"]["voxels"]["recall"].get<double>());
  EXPECT_EQ(run_cli("-q eval " + tmp.path("b.ply") + " --volume " + tmp.path("b.nrrd") + " --sharp-match -1", &out), 2);
  // --fixed-ends: recorded in the stats; the flats come from estimates with
  // fixed ends either way, so the mesh has the same elements (its few
  // curved pieces between barriers, near the corners, may move).
  EXPECT_TRUE(st["pressing"]["free_ends"].get<bool>());
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("fe.ply") +
                        " --check --color-regions --fixed-ends --stats-json " + tmp.path("fe.json"),
                    &out),
            0)
      << out;
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(tmp.path("fe.json")))["pressing"]["free_ends"].get<bool>());
  EXPECT_EQ(read_mesh(tmp.path("fe.ply")).triangles, read_mesh(tmp.path("b.ply")).triangles);
  EXPECT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("x.ply") + " --method taubin --fixed-ends", &out),
            2);
  EXPECT_NE(out.find("--fixed-ends applies to --method pressing only"), std::string::npos) << out;
  // --disable-pass curved-creases: a box has no crease between two curved
  // faces, so the counts are 0 and the surface does not change; the pass
  // table says it was off.
  EXPECT_EQ(st["flats"]["curved_crease_vertices"].get<size_t>(), 0u);
  EXPECT_EQ(st["sharpen"]["curved_crease_vertices"].get<size_t>(), 0u);
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("nc.ply") +
                        " --check --color-regions --disable-pass curved-creases --stats-json " + tmp.path("nc.json"),
                    &out),
            0)
      << out;
  EXPECT_EQ(test::read_file(tmp.path("nc.ply")), test::read_file(tmp.path("b.ply")));
  bool listed = false;
  const nlohmann::json nc = nlohmann::json::parse(std::ifstream(tmp.path("nc.json")));
  for (const auto& p : nc["passes"]) {
    if (p["name"] == "curved-creases") {
      listed = true;
      EXPECT_FALSE(p["enabled"].get<bool>());
    }
    // Every pass reports what it did: the detection's count is the flats'.
    if (p["name"] == "flats") {
      EXPECT_EQ(p["count"].get<size_t>(), nc["flats"]["count"].get<size_t>());
    }
    if (p["name"] == "free-ends") {
      EXPECT_EQ(p["count"].get<size_t>(), nc["flats"]["barriers"].get<size_t>());
    }
  }
  EXPECT_TRUE(listed);
  EXPECT_EQ(
      run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("x.ply") + " --method cesn --disable-pass snap",
              &out),
      2);
  EXPECT_NE(out.find("--disable-pass applies to --method pressing only"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("x.ply") + " --disable-pass snapp", &out), 2);
  EXPECT_NE(out.find("unknown pass 'snapp'"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.path("x.ply")));
  // --no-sharpen: the chamfered surface, vertex regions only; --features then is a usage error.
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("c.ply") + " --no-sharpen", &out), 0) << out;
  const Mesh chamfered = read_mesh(tmp.path("c.ply"));
  EXPECT_TRUE(chamfered.edges.empty());
  EXPECT_LT(chamfered.vertex_count(), m.vertex_count());
  EXPECT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("y.ply") + " --no-sharpen --features " +
                        tmp.path("y.obj"),
                    &out),
            2);
  EXPECT_FALSE(fs::exists(tmp.path("y.ply")));
  // --no-flats: plain Pressing, no regions.
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("n.ply") + " --no-flats --stats-json " +
                        tmp.path("n.json"),
                    &out),
            0);
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(tmp.path("n.json"))).contains("flats"));
  EXPECT_EQ(read_mesh(tmp.path("n.ply")).vertex_attribute("region"), nullptr);
  // A huge minimum area finds nothing; bad option values are usage errors.
  ASSERT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("m.ply") + " --min-flat-area 100000 --stats-json " +
                        tmp.path("m.json"),
                    &out),
            0);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(tmp.path("m.json")))["flats"]["count"], 0);
  EXPECT_EQ(run_cli("-q press " + tmp.path("b.nrrd") + " -o " + tmp.path("x.ply") + " --junction-angle 200", &out), 2);
  EXPECT_NE(out.find("--junction-angle"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.path("x.ply")));
}

TEST(Cli, Press2dWritesContoursOverThePixels) {
  test::TempDir tmp;
  // A dark ring on white, as binary PGM.
  const int w = 40, h = 32;
  std::string pgm = "P5\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double r2 = (x - 19.6) * (x - 19.6) + (y - 15.3) * (y - 15.3);
      pgm += char(r2 < 13 * 13 && r2 > 6 * 6 ? 10 : 250);
    }
  std::ofstream(tmp.path("ring.pgm"), std::ios::binary) << pgm;
  std::string out;
  ASSERT_EQ(run_cli("-q press2d " + tmp.path("ring.pgm") + " -o " + tmp.path("ring.svg") + " --midpoint --stats-json " +
                        tmp.path("s.json"),
                    &out),
            0)
      << out;
  const std::string svg = test::read_file(tmp.path("ring.svg"));
  EXPECT_NE(svg.find("<image"), std::string::npos);
  size_t closes = 0;  // "Z " ends a contour in a path (base64 pixel data has no spaces)
  for (size_t at = svg.find("Z "); at != std::string::npos; at = svg.find("Z ", at + 1)) ++closes;
  EXPECT_EQ(closes, 4u) << "two paths (midpoint, pressed) of two contours each";
  const auto st = nlohmann::json::parse(std::ifstream(tmp.path("s.json")));
  EXPECT_EQ(st["pressing"]["curves"], 2);
  EXPECT_EQ(st["width"], w);
  // --invert turns the white background into the object: three contours (outer border, ring's two sides).
  ASSERT_EQ(run_cli("-q press2d " + tmp.path("ring.pgm") + " -o " + tmp.path("inv.svg") + " --invert --no-pixels "
                    "--stats-json " + tmp.path("i.json"),
                    &out),
            0)
      << out;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(tmp.path("i.json")))["pressing"]["curves"], 3);
  EXPECT_EQ(test::read_file(tmp.path("inv.svg")).find("<image"), std::string::npos);
  // Bad inputs: one line naming the file, exit 1, nothing written; bad usage: exit 2.
  std::ofstream(tmp.path("white.pgm"), std::ios::binary) << "P5\n4 4\n255\n" << std::string(16, char(255));
  std::ofstream(tmp.path("cut.pgm"), std::ios::binary) << pgm.substr(0, pgm.size() / 2);
  std::ofstream(tmp.path("bad.png"), std::ios::binary) << "not a png";
  const auto before = tmp.files();
  for (const auto& [file, problem] : {std::pair<std::string, std::string>{"white.pgm", "no pixel is inside"},
                                      {"cut.pgm", "truncated"},
                                      {"bad.png", "PNG"},
                                      {"missing.png", "no such file"}}) {
    EXPECT_EQ(run_cli("-q press2d " + tmp.path(file) + " -o " + tmp.path("o.svg"), &out), 1) << file;
    EXPECT_EQ(count_lines(out), 1u) << out;
    EXPECT_NE(out.find(file), std::string::npos) << out;
    EXPECT_NE(out.find(problem), std::string::npos) << out;
  }
  EXPECT_EQ(run_cli("-q press2d " + tmp.path("ring.pgm") + " -o " + tmp.path("o.png"), &out), 2);
  EXPECT_EQ(tmp.files(), before);
}

TEST(Cli, SmoothMeshRecoversTheLatticeOfAnStlAndKeepsTheGuarantee) {
  test::TempDir tmp;
  std::string out;
  ASSERT_EQ(run_cli("-q generate torus --res 40 --rotate random:2 --spacing 0.7,0.7,1.3 -o " + tmp.path("t.nrrd"), &out), 0)
      << out;
  ASSERT_EQ(run_cli("-q extract " + tmp.path("t.nrrd") + " -o " + tmp.path("mc.stl"), &out), 0) << out;
  for (const std::string c : {"diamond", "cell-edge"}) {
    ASSERT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path(c + ".ply") + " --constraint " + c +
                          " --stats-json " + tmp.path(c + ".json"),
                      &out),
              0)
        << out;
    const auto st = nlohmann::json::parse(std::ifstream(tmp.path(c + ".json")));
    EXPECT_EQ(st["constraint"], c);
    EXPECT_NEAR(st["recovered_lattice"]["spacing"][2].get<double>(), 1.3, 1e-5);
    EXPECT_NEAR(st["recovered_lattice"]["spacing"][0].get<double>(), 0.7, 1e-5);
    EXPECT_EQ(st["smoothing"]["converged"], true);
    // Without the volume, and still every sample on its side.
    EXPECT_EQ(run_cli("check " + tmp.path(c + ".ply") + " --volume " + tmp.path("t.nrrd"), &out), 0) << c << out;
  }
  ASSERT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path("t.obj") + " --method taubin --iterations 5",
                    &out),
            0)
      << out;
  // A smoothed mesh is not a marching-cubes mesh: one line naming the file, exit 1, no output.
  EXPECT_EQ(run_cli("-q smooth-mesh " + tmp.path("t.obj") + " -o " + tmp.path("bad.ply"), &out), 1);
  EXPECT_NE(out.find(tmp.path("t.obj") + ": not an axis-aligned marching-cubes mesh"), std::string::npos) << out;
  EXPECT_EQ(count_lines(out), 1u) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.path("bad.ply")));
  EXPECT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path("x.ply") + " --constraint round", &out), 2);
  EXPECT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path("x.ply") + " --method taubin --constraint diamond",
                    &out),
            2);
  EXPECT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path("x.ply") + " --lambda 0.4", &out), 2);
  EXPECT_EQ(run_cli("-q smooth-mesh " + tmp.path("none.stl") + " -o " + tmp.path("x.ply"), &out), 1);
}

TEST(Cli, PressRunsEveryMethodAndChecksOnlyWhatEachPromises) {
  test::TempDir tmp;
  std::string out;
  ASSERT_EQ(run_cli("-q generate sphere --res 32 --rotate random:1 -o " + tmp.path("s.nrrd"), &out), 0) << out;
  for (const std::string m : {"cesn", "diamond", "cell-edge", "cell-size", "taubin", "laplacian"}) {
    ASSERT_EQ(run_cli("-q press " + tmp.path("s.nrrd") + " -o " + tmp.path(m + ".ply") + " --method " + m +
                          " --check --stats-json " + tmp.path(m + ".json"),
                      &out),
              0)
        << m << out;
    const auto st = nlohmann::json::parse(std::ifstream(tmp.path(m + ".json")));
    EXPECT_EQ(st["method"], m);
    EXPECT_GT(st["smoothing"]["iterations"].get<int>(), 0) << m;
    EXPECT_EQ(st["checks"]["closed"], true) << m;
    EXPECT_EQ(st["checks"]["manifold"], true) << m;
    if (m == "diamond" || m == "cell-edge") {
      EXPECT_EQ(st["checks"]["classification_violations"], 0) << m;
    }
  }
  ASSERT_EQ(run_cli("-q press " + tmp.path("s.nrrd") + " -o " + tmp.path("few.ply") + " --method cesn --iterations 2 "
                        "--stats-json " + tmp.path("few.json"),
                    &out),
            0)
      << out;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(tmp.path("few.json")))["smoothing"]["iterations"], 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("s.nrrd") + " -o " + tmp.path("x.ply") + " --method blur", &out), 2);
  EXPECT_EQ(run_cli("-q press " + tmp.path("s.nrrd") + " -o " + tmp.path("x.ply") + " --method taubin --no-flats", &out), 2);
  EXPECT_NE(out.find("--no-flats applies to --method pressing only"), std::string::npos) << out;
  EXPECT_EQ(run_cli("-q press " + tmp.path("s.nrrd") + " -o " + tmp.path("x.ply") + " --lambda 0.2", &out), 2);
  EXPECT_FALSE(std::filesystem::exists(tmp.path("x.ply")));
}

// --faces and --max-error: press, extract and smooth-mesh simplify what they
// write, every sample still on its side (checked on the file as written by
// `check`), the figures in --stats-json; a bad bound is a usage error.
TEST(Cli, FacesSimplifiesAndKeepsEverySampleOnItsSide) {
  test::TempDir tmp;
  std::string out;
  const std::string vol = tmp.path("c.nrrd");
  ASSERT_EQ(run_cli("-q generate cad-part --res 32 --rotate random:2 -o " + vol, &out), 0) << out;
  ASSERT_EQ(run_cli("-q press " + vol + " -o " + tmp.path("p.stl") + " --faces 600 --check --stats-json " +
                        tmp.path("p.json"),
                    &out),
            0)
      << out;
  const auto st = nlohmann::json::parse(std::ifstream(tmp.path("p.json")));
  EXPECT_LE(st["simplify"]["faces"].get<uint64_t>(), 600u);
  EXPECT_GT(st["simplify"]["faces_before"].get<uint64_t>(), 3000u);
  EXPECT_EQ(st["counts"]["triangles"], st["simplify"]["faces"]);
  EXPECT_EQ(st["checks"]["classification_violations"], 0);
  ASSERT_EQ(run_cli("check " + tmp.path("p.stl") + " --volume " + vol, &out), 0) << out;
  // extract: the midpoint surface within half a cell of itself.
  ASSERT_EQ(run_cli("-q extract " + vol + " -o " + tmp.path("m.ply") + " --max-error 0.5 --stats-json " + tmp.path("m.json"), &out), 0)
      << out;
  const auto sm = nlohmann::json::parse(std::ifstream(tmp.path("m.json")));
  EXPECT_LE(sm["simplify"]["error"].get<double>(), 0.5);
  EXPECT_LT(sm["simplify"]["faces"].get<uint64_t>(), sm["simplify"]["faces_before"].get<uint64_t>() / 2);
  ASSERT_EQ(run_cli("check " + tmp.path("m.ply") + " --volume " + vol, &out), 0) << out;
  // smooth-mesh: the lattice read back from the midpoint mesh keeps its samples.
  ASSERT_EQ(run_cli("-q extract " + vol + " -o " + tmp.path("mc.stl"), &out), 0) << out;
  ASSERT_EQ(run_cli("-q smooth-mesh " + tmp.path("mc.stl") + " -o " + tmp.path("sm.ply") + " --faces 800", &out), 0) << out;
  ASSERT_EQ(run_cli("check " + tmp.path("sm.ply") + " --volume " + vol, &out), 0) << out;
  EXPECT_NE(run_cli("-q press " + vol + " -o " + tmp.path("x.ply") + " --max-error -1", &out), 0);
  EXPECT_NE(out.find("--max-error"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path("x.ply")));
}

}  // namespace
}  // namespace voxpress
