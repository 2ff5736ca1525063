// Mesh writers round-trip through the readers; real meshes read as documented.
#include <tiny_gltf.h>

#include <fstream>

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include "test_util.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;

Mesh sample_mesh() {
  test::Rng rng(3);
  const BinaryVolume v = test::random_blobs(rng, {10, 9, 8}, 2);
  Mesh m = to_mesh(extract_sticks(v));
  for (auto& p : m.positions) p = p * 0.37 + Vec3(-3.1, 12.000001, 1e3);
  return m;
}

void expect_same_geometry(const Mesh& a, const Mesh& b, double tol) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles, b.triangles);
  for (size_t i = 0; i < a.positions.size(); ++i) ASSERT_LE((a.positions[i] - b.positions[i]).norm(), tol) << i;
}

TEST(MeshIO, PlyRoundTripKeepsEverything) {
  test::TempDir tmp;
  Mesh m = sample_mesh();
  m.normals = vertex_normals(m);
  m.colors.resize(m.positions.size());
  for (size_t i = 0; i < m.colors.size(); ++i) m.colors[i] = {uint8_t(i), uint8_t(2 * i), 7, 255};
  MeshAttribute region{"region", ScalarType::i32, {}};
  for (size_t i = 0; i < m.positions.size(); ++i) region.values.push_back(double(int(i % 5) - 1));
  m.vertex_attributes.push_back(region);
  MeshAttribute quality{"quality", ScalarType::f32, {}};
  for (size_t f = 0; f < m.triangles.size(); ++f) quality.values.push_back(double(float(0.25 * double(f))));
  m.face_attributes.push_back(quality);
  m.edges = {{0, 1}, {1, 2}, {5, 3}};
  for (bool ascii : {false, true}) {
    MeshWriteOptions o;
    o.ascii = ascii;
    write_mesh(tmp.path("m.ply"), m, o);
    const Mesh r = read_mesh(tmp.path("m.ply"));
    expect_same_geometry(m, r, 0.0);  // doubles round-trip exactly
    ASSERT_EQ(r.colors, m.colors);
    ASSERT_EQ(r.normals.size(), m.normals.size());
    EXPECT_LT((r.normals[5] - m.normals[5]).norm(), 1e-6);
    ASSERT_TRUE(r.vertex_attribute("region"));
    EXPECT_EQ(r.vertex_attribute("region")->values, region.values);
    EXPECT_EQ(r.vertex_attribute("region")->type, ScalarType::i32);
    ASSERT_TRUE(r.face_attribute("quality"));
    EXPECT_EQ(r.face_attribute("quality")->values, quality.values);
    EXPECT_EQ(r.edges, m.edges);
  }
}

TEST(MeshIO, ObjGroupsRegionsAndWritesEdgesAsLines) {
  test::TempDir tmp;
  Mesh m = sample_mesh();
  MeshAttribute region{"region", ScalarType::i32, {}};
  for (size_t f = 0; f < m.triangles.size(); ++f) region.values.push_back(double(int(f % 3) - 1));
  m.face_attributes.push_back(region);
  m.edges = {{0, 1}, {2, 3}};
  write_mesh(tmp.path("m.obj"), m);
  const std::string text = test::read_file(tmp.path("m.obj"));
  EXPECT_NE(text.find("g curved\n"), std::string::npos);
  EXPECT_NE(text.find("g flat_0\n"), std::string::npos);
  EXPECT_NE(text.find("g flat_1\n"), std::string::npos);
  const Mesh r = read_mesh(tmp.path("m.obj"));
  EXPECT_EQ(r.face_count(), m.face_count());
  EXPECT_EQ(r.edges, m.edges);
  // An edge naming a missing vertex is refused.
  Mesh bad = m;
  bad.edges.push_back({0, uint32_t(m.vertex_count())});
  EXPECT_THROW(write_mesh(tmp.path("bad.ply"), bad), InputError);
  EXPECT_FALSE(fs::exists(tmp.path("bad.ply")));
}

TEST(MeshIO, ObjOffStlRoundTrips) {
  test::TempDir tmp;
  const Mesh m = sample_mesh();
  write_mesh(tmp.path("m.off"), m);
  expect_same_geometry(m, read_mesh(tmp.path("m.off")), 0.0);
  // tinyobjloader's number parser is not correctly rounded: within an ulp or two.
  write_mesh(tmp.path("m.obj"), m);
  expect_same_geometry(m, read_mesh(tmp.path("m.obj")), 1e-12 * 1e3);
  write_mesh(tmp.path("m.stl"), m);
  const Mesh s = read_mesh(tmp.path("m.stl"));  // float32, welded back to shared vertices
  EXPECT_EQ(s.positions.size(), m.positions.size());
  EXPECT_EQ(s.triangles.size(), m.triangles.size());
  EXPECT_TRUE(check_mesh(s).ok());
  EXPECT_NEAR(signed_volume(s), signed_volume(m), 1e-3 * signed_volume(m));
  // The binary STL header must not start with "solid" (readers would take it for ASCII).
  std::ifstream in(tmp.path("m.stl"), std::ios::binary);
  char head[5];
  in.read(head, 5);
  EXPECT_NE(std::string(head, 5), "solid");
}

TEST(MeshIO, AsciiStlAndOffVariants) {
  test::TempDir tmp;
  std::ofstream(tmp.path("a.stl")) << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                      "vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\n"
                                      "vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
  const Mesh a = read_mesh(tmp.path("a.stl"));
  EXPECT_EQ(a.positions.size(), 4u);
  EXPECT_EQ(a.triangles.size(), 2u);
  std::ofstream(tmp.path("c.off")) << "COFF 4 1 0\n# comment\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n1 1 0 0 0 0 255\n"
                                      "0 1 0 0 0 0 255\n4 0 1 2 3\n\n";
  const Mesh c = read_mesh(tmp.path("c.off"));
  EXPECT_EQ(c.triangles.size(), 2u);
  std::ofstream(tmp.path("bad.off")) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  EXPECT_THROW(read_mesh(tmp.path("bad.off")), InputError);
  std::ofstream(tmp.path("short.off")) << "OFF\n30 10 0\n0 0 0\n";
  EXPECT_THROW(read_mesh(tmp.path("short.off")), InputError);
  std::ofstream(tmp.path("bad.ply")) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n";
  EXPECT_THROW(read_mesh(tmp.path("bad.ply")), InputError);
  std::ofstream(tmp.path("trunc.ply")) << "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\n"
                                          "property float x\nproperty float y\nproperty float z\nend_header\nabc";
  EXPECT_THROW(read_mesh(tmp.path("trunc.ply")), InputError);
  std::ofstream(tmp.path("trunc.stl"), std::ios::binary) << std::string(80, ' ') << std::string("\x10\0\0\0", 4)
                                                         << std::string(100, '\0');
  EXPECT_THROW(read_mesh(tmp.path("trunc.stl")), InputError);
  EXPECT_THROW(read_mesh(tmp.path("nothing.ply")), InputError);
  EXPECT_THROW(read_mesh(tmp.path("x.3ds")), InputError);
}

TEST(MeshIO, GlbAndGltfReadBackWithTinygltf) {
  test::TempDir tmp;
  Mesh m = sample_mesh();
  m.normals = vertex_normals(m);
  m.colors.assign(m.positions.size(), {200, 100, 50, 255});
  write_mesh(tmp.path("m.glb"), m);
  write_mesh(tmp.path("m.gltf"), m);
  for (const std::string name : {"m.glb", "m.gltf"}) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool ok = name.ends_with(".glb") ? loader.LoadBinaryFromFile(&model, &err, &warn, tmp.path(name))
                                           : loader.LoadASCIIFromFile(&model, &err, &warn, tmp.path(name));
    ASSERT_TRUE(ok) << err;
    ASSERT_EQ(model.meshes.size(), 1u);
    const auto& prim = model.meshes[0].primitives[0];
    const auto& pos = model.accessors[size_t(prim.attributes.at("POSITION"))];
    EXPECT_EQ(pos.count, m.positions.size());
    EXPECT_EQ(model.accessors[size_t(prim.indices)].count, 3 * m.triangles.size());
    EXPECT_TRUE(prim.attributes.count("NORMAL"));
    EXPECT_TRUE(prim.attributes.count("COLOR_0"));
    // First position matches (float32).
    const auto& view = model.bufferViews[size_t(pos.bufferView)];
    float p0[3];
    std::memcpy(p0, model.buffers[0].data.data() + view.byteOffset, 12);
    EXPECT_NEAR(p0[0], m.positions[0].x(), 1e-3);
    EXPECT_NEAR(pos.minValues[2], bounding_box(m)[0].z(), 1e-3);
  }
}

// read_mesh reads back what voxpress writes as glTF, float32 positions as stored.
TEST(MeshIO, GlbAndGltfReadBackThroughReadMesh) {
  test::TempDir tmp;
  const Mesh m = sample_mesh();
  for (const std::string name : {"r.glb", "r.gltf"}) {
    SCOPED_TRACE(name);
    write_mesh(tmp.path(name), m);
    const Mesh back = read_mesh(tmp.path(name));
    ASSERT_EQ(back.positions.size(), m.positions.size());
    ASSERT_EQ(back.triangles, m.triangles);
    for (size_t v = 0; v < m.positions.size(); ++v)
      ASSERT_EQ(back.positions[v], m.positions[v].cast<float>().cast<double>());
    const std::string bytes = test::read_file(tmp.path(name));
    test::write_file(tmp.path("cut_" + name), bytes.substr(0, bytes.size() / 2));
    EXPECT_THROW(read_mesh(tmp.path("cut_" + name)), InputError);
  }
}

// Every numeric field of an OBJ must parse: tinyobjloader alone reads
// `nan` and `abc` as 0 (which then passed check).
TEST(MeshIO, ObjNumbersThatDoNotParseAreErrors) {
  test::TempDir tmp;
  const std::string tail = "v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n";
  test::write_file(tmp.path("ok.obj"), "v 0 0 0\n" + tail);
  EXPECT_EQ(read_mesh(tmp.path("ok.obj")).face_count(), 4u);
  for (const std::string bad : {"v nan 0 0\n", "v abc 0 0\n", "v 0 0 inf\n", "v 0 0\n", "v 1e999 0 0\n",
                                "v 0 0 0\nvt 0.5 x\n", "v 0 0 0\nvn 0 0 1q\n"}) {
    SCOPED_TRACE(bad);
    test::write_file(tmp.path("bad.obj"), bad + tail);
    try {
      read_mesh(tmp.path("bad.obj"));
      ADD_FAILURE() << "read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.obj"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("line"), std::string::npos);
    }
  }
  for (const std::string bad : {"f 1 2 x\n", "f 1 2 0\n", "f 1/a 2 3\n", "f 1/2/3/4 2 3\n"}) {
    SCOPED_TRACE(bad);
    test::write_file(tmp.path("badf.obj"), "v 0 0 0\n" + tail + bad);
    EXPECT_THROW(read_mesh(tmp.path("badf.obj")), InputError);
  }
}

// A run's outputs appear together or not at all (OutputGroup): an OBJ's
// texture and MTL never without their OBJ, a JSON report never without the
// mesh it describes.
TEST(MeshIO, OutputGroupWritesEverythingOrNothing) {
  test::TempDir tmp;
  Mesh m = sample_mesh();
  m.uvs.assign(m.positions.size(), Vec2(0.5, 0.5));
  m.texture.width = m.texture.height = 2;
  m.texture.rgba.assign(16, 200);
  {
    OutputGroup group;
    write_mesh(tmp.path("t.obj"), m);
    write_file_atomically(tmp.path("t.json"), [](std::ostream& o) { o << "{}"; });
    // Nothing visible before the commit, only temporaries.
    for (const std::string& f : tmp.files()) EXPECT_EQ(f[0], '.') << f;
  }  // not committed: the temporaries are removed
  EXPECT_TRUE(tmp.files().empty());
  {
    OutputGroup group;
    write_mesh(tmp.path("t.obj"), m);
    write_file_atomically(tmp.path("t.json"), [](std::ostream& o) { o << "{}"; });
    group.commit();
  }
  EXPECT_EQ(tmp.files(), (std::vector<std::string>{"t.json", "t.mtl", "t.obj", "t.png"}));
  // A process that dies before its commit (as under SIGKILL) leaves no named output.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    OutputGroup group;
    write_mesh(tmp.path("k.obj"), m);
    _exit(0);  // no destructor, no commit
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  for (const std::string& f : tmp.files()) EXPECT_FALSE(f.starts_with("k.")) << f;
  EXPECT_THROW({ OutputGroup a; OutputGroup b; }, std::logic_error);
}

// SIGINT / SIGTERM in the middle of a write left the hidden temporary (issue
// 73): with remove_temporaries_on_signals() (the CLI installs it) the process
// still dies by the signal, and neither the temporary nor the name is left,
// for a plain write and for one pending in an uncommitted group.
TEST(MeshIO, SignalsWhileWritingLeaveNoTemporary) {
  test::TempDir tmp;
  for (int sig : {SIGTERM, SIGINT}) {
    for (bool grouped : {false, true}) {
      SCOPED_TRACE(std::to_string(sig) + (grouped ? " grouped" : ""));
      const pid_t pid = fork();
      ASSERT_GE(pid, 0);
      if (pid == 0) {
        remove_temporaries_on_signals();
        std::unique_ptr<OutputGroup> group(grouped ? new OutputGroup : nullptr);
        if (grouped) write_file_atomically(tmp.path("done.json"), [](std::ostream& o) { o << "{}"; });
        write_file_atomically(tmp.path("s.json"), [&](std::ostream& o) {
          o << "{\"partial\": ";
          o.flush();
          ::raise(sig);  // in the middle of the write
        });
        _exit(0);
      }
      int status = 0;
      ASSERT_EQ(waitpid(pid, &status, 0), pid);
      EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
      EXPECT_TRUE(tmp.files().empty()) << (tmp.files().empty() ? "" : tmp.files()[0]);
    }
  }
}

TEST(MeshIO, FailedWritesLeaveNoFile) {
  test::TempDir tmp;
  Mesh bad = sample_mesh();
  bad.triangles.push_back({0, 1, 999999});
  EXPECT_THROW(write_mesh(tmp.path("bad.ply"), bad), InputError);
  EXPECT_TRUE(tmp.files().empty());
  EXPECT_THROW(write_mesh(tmp.path("missing/dir.ply"), sample_mesh()), InputError);
  EXPECT_THROW(write_mesh(tmp.path("m.xyz"), sample_mesh()), InputError);
  EXPECT_TRUE(tmp.files().empty());
}

struct MeshFact {
  const char* file;
  size_t vertices, faces;
  int64_t genus;
};

TEST(MeshIO, SharedMeshesMatchTheirDocumentedFacts) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const MeshFact facts[] = {{"fandisk.off", 7229, 14454, 0},       {"plate_holes.STL", 618, 1252, 5},
                            {"fixed_top.ply", 2374, 4772, 7},      {"1002_tray_bottom.STL", 2216, 4520, 23},
                            {"thingi10k-65004.stl", 731, 1466, 2}, {"torus.STL", 4350, 8700, 1},
                            {"3holes.off", 3596, 7200, 3},         {"bunny.off", 3485, 6966, 0},
                            {"armadillo.obj", 43243, 86482, 0}};
  for (const auto& f : facts) {
    SCOPED_TRACE(f.file);
    const Mesh m = read_mesh(test::shared_data() + "/meshes/" + f.file);
    EXPECT_EQ(m.positions.size(), f.vertices);
    EXPECT_EQ(m.triangles.size(), f.faces);
    MeshCheckOptions o;
    o.self_intersections = false;  // not documented for every file
    const MeshCheck r = check_mesh(m, o);
    EXPECT_TRUE(r.closed());
    EXPECT_TRUE(r.manifold());
    EXPECT_TRUE(r.oriented());
    EXPECT_GT(r.signed_volume, 0);
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ((2 - r.euler) / 2, f.genus);
  }
  // fixed_top.ply carries per-face colours (uchar lists with "uchar int" indices).
  const Mesh ft = read_mesh(test::shared_data() + "/meshes/fixed_top.ply");
  EXPECT_TRUE(ft.face_attribute("red"));
}

}  // namespace
}  // namespace voxpress
