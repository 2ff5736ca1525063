// VTK polygon data (.vtk legacy, .vtp XML): what voxpress writes reads back
// whole; the variants other writers produce (legacy 3.0-5.1, inline ascii and
// base64, zlib blocks, several pieces, quads and strips) read as documented;
// broken files are refused with one line naming the file.
#include <zlib.h>

#include "test_util.h"

namespace voxpress {
namespace {

Mesh attributed_mesh() {
  test::Rng rng(5);
  const BinaryVolume v = test::random_blobs(rng, {9, 10, 8}, 2);
  Mesh m = to_mesh(extract_sticks(v));
  for (auto& p : m.positions) p = p * 0.61 + Vec3(-120.3, 45.000001, 1e3);
  m.normals = vertex_normals(m);
  m.colors.resize(m.positions.size());
  for (size_t i = 0; i < m.colors.size(); ++i) m.colors[i] = {uint8_t(i), uint8_t(3 * i), 9, 200};
  MeshAttribute region{"region", ScalarType::i32, {}};
  for (size_t i = 0; i < m.positions.size(); ++i) region.values.push_back(double(int(i % 7) - 2));
  region.values[3] = 100000;  // ASCII writes it whole: other readers refuse "1e+05" for an integer
  m.vertex_attributes.push_back(region);
  MeshAttribute in{"label_in", ScalarType::u32, {}}, quality{"quality", ScalarType::f32, {}};
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    in.values.push_back(double(f % 61 + 1));
    quality.values.push_back(double(float(0.1 * double(f))));
  }
  m.face_attributes = {in, quality};
  return m;
}

TEST(VtkIO, LegacyAndXmlRoundTripKeepEverything) {
  test::TempDir tmp;
  const Mesh m = attributed_mesh();
  for (const std::string name : {"b.vtk", "a.vtk", "m.vtp"}) {
    SCOPED_TRACE(name);
    MeshWriteOptions o;
    o.ascii = name == "a.vtk";
    o.space = Space::RAS;
    write_mesh(tmp.path(name), m, o);
    const Mesh r = read_mesh(tmp.path(name));
    ASSERT_EQ(r.triangles, m.triangles);
    ASSERT_EQ(r.positions, m.positions) << "doubles, exactly (ASCII: shortest round-trip text)";
    EXPECT_EQ(r.colors, m.colors);
    ASSERT_EQ(r.normals.size(), m.normals.size());
    for (size_t v = 0; v < m.normals.size(); ++v) ASSERT_LT((r.normals[v] - m.normals[v]).norm(), 1e-6);
    ASSERT_TRUE(r.vertex_attribute("region"));
    EXPECT_EQ(r.vertex_attribute("region")->values, m.vertex_attributes[0].values);
    EXPECT_EQ(r.vertex_attribute("region")->type, ScalarType::i32);
    for (const MeshAttribute& a : m.face_attributes) {
      ASSERT_TRUE(r.face_attribute(a.name)) << a.name;
      EXPECT_EQ(r.face_attribute(a.name)->values, a.values);
      EXPECT_EQ(r.face_attribute(a.name)->type, a.type);
    }
    // The frame, where 3D Slicer looks for it.
    const std::string text = test::read_file(tmp.path(name));
    EXPECT_NE(text.find(name.ends_with(".vtp") ? "Name=\"SPACE\"" : "SPACE=RAS"), std::string::npos);
  }
  for (const std::string name : {"a.vtk", "a.ply"}) {
    MeshWriteOptions o;
    o.ascii = true;
    write_mesh(tmp.path(name), m, o);
    const std::string text = test::read_file(tmp.path(name));
    EXPECT_NE(text.find(" 100000"), std::string::npos) << name;
    EXPECT_EQ(text.find("e+05"), std::string::npos) << name;
  }
  // PLY and STL carry the frame too (a comment, the header).
  MeshWriteOptions o;
  o.space = Space::LPS;
  write_mesh(tmp.path("m.ply"), m, o);
  write_mesh(tmp.path("m.stl"), m, o);
  EXPECT_NE(test::read_file(tmp.path("m.ply")).find("comment SPACE=LPS\n"), std::string::npos);
  EXPECT_NE(test::read_file(tmp.path("m.stl")).substr(0, 80).find("SPACE=LPS"), std::string::npos);
}

std::string base64(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t n = (uint32_t(uint8_t(bytes[i])) << 16) | (i + 1 < bytes.size() ? uint32_t(uint8_t(bytes[i + 1])) << 8 : 0) |
                       (i + 2 < bytes.size() ? uint32_t(uint8_t(bytes[i + 2])) : 0);
    out += k[(n >> 18) & 63];
    out += k[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[n & 63] : '=';
  }
  return out;
}
// Half the sum of the triangles' cross products: the area vector.
Vec3 area_vector(const Mesh& m) {
  Vec3 s = Vec3::Zero();
  for (const Triangle& t : m.triangles)
    s += (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]) / 2;
  return s;
}

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

TEST(VtkIO, OtherWritersVariantsRead) {
  test::TempDir tmp;
  // Legacy 5.1 (VTK 9's default): OFFSETS / CONNECTIVITY, a quad fanned into
  // two triangles that both keep its cell value, METADATA blocks.
  test::write_file(tmp.path("q.vtk"),
                   "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\nPOINTS 5 float\n"
                   "0 0 0 1 0 0 1 1 0 0 1 0 0.5 0.5 1\nMETADATA\nINFORMATION 0\n\n"
                   "POLYGONS 3 7\nOFFSETS vtktypeint64\n0 4 7\nCONNECTIVITY vtktypeint64\n0 1 2 3 0 1 4\n"
                   "CELL_DATA 2\nSCALARS part int 1\nLOOKUP_TABLE default\n7 9\n"
                   "POINT_DATA 5\nFIELD FieldData 1\nheat 1 5 double\n1 2 3 4 5\n");
  const Mesh q = read_mesh(tmp.path("q.vtk"));
  ASSERT_EQ(q.triangles.size(), 3u);
  EXPECT_EQ(q.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(q.triangles[1], (Triangle{0, 2, 3}));
  ASSERT_TRUE(q.face_attribute("part"));
  EXPECT_EQ(q.face_attribute("part")->values, (std::vector<double>{7, 7, 9}));
  ASSERT_TRUE(q.vertex_attribute("heat"));
  EXPECT_EQ(q.vertex_attribute("heat")->values[4], 5.0);
  // Legacy 3.0 with a triangle strip (alternate triangles flipped back) and
  // a line before the polygons (cell data counts it first).
  test::write_file(tmp.path("s.vtk"),
                   "# vtk DataFile Version 3.0\nstrip\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n"
                   "0 0 0 1 0 0 0 1 0 1 1 0\nLINES 1 3\n2 0 3\nTRIANGLE_STRIPS 1 5\n4 0 1 2 3\n"
                   "CELL_DATA 2\nSCALARS id unsigned_char\nLOOKUP_TABLE default\n1 2\n");
  const Mesh s = read_mesh(tmp.path("s.vtk"));
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(s.triangles[1], (Triangle{2, 1, 3}));
  EXPECT_EQ(s.face_attribute("id")->values, (std::vector<double>{2, 2}));
  EXPECT_NEAR(area_vector(s).z(), 1.0, 1e-12) << "both triangles face +z";

  // XML: two pieces inline (ascii, then base64 with a UInt32 header encoded
  // with its data), Int64 connectivity; the second piece's indices are its own.
  const std::vector<float> pts = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint32_t> head = {uint32_t(pts.size() * 4)};
  const std::string piece2 = base64(bytes_of(head) + bytes_of(pts));
  test::write_file(tmp.path("p.vtp"),
                   "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
                   "<Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" "
                   "format=\"ascii\">0 0 1 1 0 1 0 1 1</DataArray></Points><Polys>"
                   "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2</DataArray>"
                   "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">3</DataArray></Polys>"
                   "<CellData><DataArray type=\"Int32\" Name=\"organ\" format=\"ascii\">4</DataArray></CellData></Piece>\n"
                   "<Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" "
                   "format=\"binary\">" + piece2 + "</DataArray></Points><Polys>"
                   "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 2 1</DataArray>"
                   "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">3</DataArray></Polys>"
                   "<CellData><DataArray type=\"Int32\" Name=\"organ\" format=\"ascii\">5</DataArray></CellData></Piece>\n"
                   "</PolyData>\n</VTKFile>\n");
  const Mesh p = read_mesh(tmp.path("p.vtp"));
  ASSERT_EQ(p.positions.size(), 6u);
  EXPECT_EQ(p.positions[4], Vec3(1, 0, 0));
  ASSERT_EQ(p.triangles.size(), 2u);
  EXPECT_EQ(p.triangles[1], (Triangle{3, 5, 4}));
  EXPECT_EQ(p.face_attribute("organ")->values, (std::vector<double>{4, 5}));

  // XML: zlib blocks in raw appended data (what 3D Slicer writes), UInt64 header.
  auto zblock = [](const std::string& raw) {
    uLongf n = compressBound(uLong(raw.size()));
    std::string z(n, '\0');
    compress2(reinterpret_cast<Bytef*>(z.data()), &n, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 6);
    z.resize(n);
    const std::vector<uint64_t> h = {1, raw.size(), raw.size(), z.size()};
    return bytes_of(h) + z;
  };
  const std::vector<double> quad = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0};
  const std::string a = zblock(bytes_of(quad)), c = zblock(bytes_of(std::vector<int32_t>{0, 1, 2, 3})),
                    o = zblock(bytes_of(std::vector<int32_t>{4}));
  test::write_file(tmp.path("z.vtp"),
                   "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
                   "compressor=\"vtkZLibDataCompressor\"><PolyData><Piece NumberOfPoints=\"4\" NumberOfPolys=\"1\">"
                   "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points>"
                   "<Polys><DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\" offset=\"" + std::to_string(a.size()) +
                   "\"/><DataArray type=\"Int32\" Name=\"offsets\" format=\"appended\" offset=\"" +
                   std::to_string(a.size() + c.size()) + "\"/></Polys></Piece></PolyData>\n<AppendedData encoding=\"raw\">\n_" +
                   a + c + o + "\n</AppendedData></VTKFile>\n");
  const Mesh z = read_mesh(tmp.path("z.vtp"));
  ASSERT_EQ(z.triangles.size(), 2u);
  EXPECT_EQ(z.positions[2], Vec3(2, 2, 0));
  EXPECT_NEAR(area_vector(z).z(), 4.0, 1e-12);
}

TEST(VtkIO, BrokenFilesGetOneLineErrorsNamingTheFile) {
  test::TempDir tmp;
  const Mesh m = attributed_mesh();
  auto expect_refused = [&](const std::string& name, const std::string& bytes, const std::string& says) {
    SCOPED_TRACE(name + ": " + says);
    test::write_file(tmp.path(name), bytes);
    try {
      read_mesh(tmp.path(name));
      ADD_FAILURE() << "read";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find(says), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  for (const std::string name : {"w.vtk", "w.vtp"}) {
    write_mesh(tmp.path(name), m);
    const std::string bytes = test::read_file(tmp.path(name));
    for (size_t cut : {size_t(10), size_t(60), bytes.size() / 3, bytes.size() / 2, bytes.size() - 40})
      expect_refused("cut_" + name, bytes.substr(0, cut), "");
  }
  const std::string head = "# vtk DataFile Version 4.2\nt\nASCII\n";
  expect_refused("img.vtk", head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n", "not POLYDATA");
  expect_refused("big.vtk", head + "DATASET POLYDATA\nPOINTS 4000000000 double\n0 0 0\n", "");
  expect_refused("idx.vtk", head + "DATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 9\n", "vertex 9");
  expect_refused("nan.vtk", head + "DATASET POLYDATA\nPOINTS 3 float\n0 nan 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\n", "");
  expect_refused("list.vtk", head + "DATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n7 0 1 2\n", "cell 0");
  expect_refused("none.vtk", "hello\n", "not a legacy VTK file");
  expect_refused("img.vtp", "<VTKFile type=\"ImageData\"><ImageData/></VTKFile>", "not PolyData");
  expect_refused("lz4.vtp", "<VTKFile type=\"PolyData\" compressor=\"vtkLZ4DataCompressor\"><PolyData/></VTKFile>", "compressor");
  expect_refused("xml.vtp", "<VTKFile type=\"PolyData\"><PolyData><Piece", "malformed XML");
  expect_refused("empty.vtp", "<VTKFile type=\"PolyData\"><PolyData/></VTKFile>", "no polygons");
}

}  // namespace
}  // namespace voxpress
