// Volume readers and writers: round trips, hand-written variants, bad input
// and the real files of ../shared/data.
#include <nifti2_io.h>
#include <zlib.h>

#include <fstream>

#include "test_util.h"

namespace voxpress {
namespace {

namespace fs = std::filesystem;

std::string gzip(const std::string& s) {
  z_stream zs{};
  deflateInit2(&zs, 6, Z_DEFLATED, 16 + 15, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&zs, uLong(s.size())) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(s.data()));
  zs.avail_in = uInt(s.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = uInt(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

ScalarVolume random_volume(ScalarType type, std::array<int64_t, 3> dims, uint64_t seed) {
  return test::random_scalar_volume(type, dims, seed);
}

void expect_same_lattice(const Lattice& a, const Lattice& b, double tol = 1e-9) {
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_LT((a.spacing - b.spacing).norm(), tol);
  EXPECT_LT((a.origin - b.origin).norm(), tol);
  EXPECT_LT((a.direction - b.direction).norm(), tol);
}

using test::expect_input_error;

TEST(VolumeIO, RoundTripEveryWriterAndType) {
  test::TempDir tmp;
  const std::vector<ScalarType> types = {ScalarType::u8,  ScalarType::i8,  ScalarType::u16, ScalarType::i16,
                                         ScalarType::u32, ScalarType::i32, ScalarType::f32, ScalarType::f64};
  for (ScalarType t : types) {
    const ScalarVolume v = random_volume(t, {7, 5, 4}, uint64_t(t) + 1);
    for (const std::string name : {"a.nrrd", "b.nrrd", "c.mha", "d.mha", "e.nii", "f.nii.gz", "g.tif"}) {
      SCOPED_TRACE(name + std::string(" ") + scalar_name(t));
      const std::string path = tmp.path(std::string(scalar_name(t)) + name);
      WriteVolumeOptions wo;
      wo.compress = name[0] != 'b' && name[0] != 'd';
      write_volume(path, v, wo);
      const ScalarVolume r = read_volume(path);
      EXPECT_EQ(r.type, v.type);
      EXPECT_EQ(r.bytes, v.bytes);
      if (name[0] == 'g') {  // TIFF keeps the spacing only (float resolution)
        EXPECT_EQ(r.lattice.dims, v.lattice.dims);
        EXPECT_LT((r.lattice.spacing - v.lattice.spacing).norm(), 1e-5);
      } else if (name[0] == 'e' || name[0] == 'f') {
        // NIfTI stores RAS: the same physical points, mirrored in x and y.
        EXPECT_EQ(r.lattice.space, Space::RAS);
        const Mat3 lps_to_ras = Vec3(-1, -1, 1).asDiagonal();
        for (const Vec3& ijk : {Vec3(0, 0, 0), Vec3(6, 4, 3), Vec3(2.5, 1, 0.5)})
          EXPECT_LT((r.lattice.to_physical(ijk) - lps_to_ras * v.lattice.to_physical(ijk)).norm(), 1e-5);
      } else {
        expect_same_lattice(r.lattice, v.lattice);
        EXPECT_EQ(r.lattice.space, Space::LPS);
      }
    }
  }
}

TEST(VolumeIO, ReadsNifti2WithSformAndScaling) {
  // Written at the format level (nifti_2_header), so the test does not depend
  // on any writer: 540-byte header, 4 extension bytes, int16 data.
  test::TempDir tmp;
  nifti_2_header h;
  std::memset(&h, 0, sizeof h);
  static_assert(sizeof(nifti_2_header) == 540);
  h.sizeof_hdr = 540;
  std::memcpy(h.magic, "n+2\0\r\n\032\n", 8);
  h.datatype = DT_INT16;
  h.bitpix = 16;
  const int64_t dims[8] = {3, 4, 3, 2, 1, 1, 1, 1};
  std::copy(dims, dims + 8, h.dim);
  for (double& p : h.pixdim) p = 1;
  h.vox_offset = 544;
  h.scl_slope = 0.5;
  h.scl_inter = 1;
  h.sform_code = NIFTI_XFORM_SCANNER_ANAT;
  const double rows[3][4] = {{0, -2, 0, 10}, {1.5, 0, 0, -20}, {0, 0, 3, 5}};
  std::copy(rows[0], rows[0] + 4, h.srow_x);
  std::copy(rows[1], rows[1] + 4, h.srow_y);
  std::copy(rows[2], rows[2] + 4, h.srow_z);
  std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
  bytes.append(4, '\0');
  for (int16_t i = 0; i < 24; ++i) bytes.append(reinterpret_cast<const char*>(&i), 2);
  test::write_file(tmp.path("v2.nii"), bytes);
  test::write_file(tmp.path("v2.nii.gz"), gzip(bytes));
  for (const std::string name : {"v2.nii", "v2.nii.gz"}) {
    SCOPED_TRACE(name);
    const ScalarVolume v = read_volume(tmp.path(name));
    EXPECT_EQ(v.lattice.dims, (std::array<int64_t, 3>{4, 3, 2}));
    EXPECT_EQ(v.lattice.space, Space::RAS);
    EXPECT_LT((v.lattice.to_physical(Vec3(1, 2, 1)) - Vec3(10 - 4, -20 + 1.5, 5 + 3)).norm(), 1e-9);
    EXPECT_EQ(v.type, ScalarType::f32);  // scaled
    EXPECT_EQ(v.value(7), 0.5 * 7 + 1);
  }
  // Truncated NIfTI-2 payload.
  test::write_file(tmp.path("short2.nii"), bytes.substr(0, bytes.size() - 10));
  expect_input_error([&] { read_volume(tmp.path("short2.nii")); }, "short2.nii", "truncated");
}

TEST(VolumeIO, NrrdVariants) {
  test::TempDir tmp;
  // Big-endian int16 raw with "spacings" and no space.
  std::string data;
  for (int16_t x : {1, -2, 300, 4, 5, 6, 7, 8}) {
    data.push_back(char((x >> 8) & 0xff));
    data.push_back(char(x & 0xff));
  }
  test::write_file(tmp.path("be.nrrd"),
                   "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nspacings: 0.5 2 -3\n"
                   "endian: big\nencoding: raw\n\n" +
                       data);
  ScalarVolume v = read_volume(tmp.path("be.nrrd"));
  EXPECT_EQ(v.value(2), 300);
  EXPECT_EQ(v.value(1), -2);
  EXPECT_EQ(v.lattice.spacing, Vec3(0.5, 2, 3));
  EXPECT_EQ(v.lattice.direction(2, 2), -1);
  // Detached header with a data file, and with a LIST of files.
  test::write_file(tmp.path("vol.raw"), std::string("\x01\x00\x01\x00\x00\x01\x00\x01", 8));
  test::write_file(tmp.path("det.nhdr"),
                   "NRRD0005\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                   "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1)\ndata file: vol.raw\n");
  v = read_volume(tmp.path("det.nhdr"));
  EXPECT_EQ(v.lattice.space, Space::RAS);
  EXPECT_EQ(binarize(v).count_inside(), 4u);
  test::write_file(tmp.path("s0.raw"), std::string("\x01\x00\x01\x00", 4));
  test::write_file(tmp.path("s1.raw"), std::string("\x00\x01\x00\x01", 4));
  test::write_file(tmp.path("list.nhdr"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                   "data file: LIST\ns0.raw\ns1.raw\n");
  v = read_volume(tmp.path("list.nhdr"));
  EXPECT_EQ(v.value(4), 0);
  EXPECT_EQ(v.value(5), 1);
  // Text encoding and gzip members concatenated.
  test::write_file(tmp.path("txt.nrrd"),
                   "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\nencoding: text\n\n1.5 -2\n");
  v = read_volume(tmp.path("txt.nrrd"));
  EXPECT_EQ(v.value(0), 1.5);
  test::write_file(tmp.path("multi.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 1 1\nencoding: gzip\n\n" +
                                               gzip(std::string("\x01\x02", 2)) + gzip(std::string("\x03\x04", 2)));
  v = read_volume(tmp.path("multi.nrrd"));
  EXPECT_EQ(v.value(3), 4);
  // LAS space becomes RAS (x mirrored).
  test::write_file(tmp.path("las.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n"
                   "space: left-anterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
                   "space origin: (10,20,30)\n\n" +
                       std::string(1, '\1'));
  v = read_volume(tmp.path("las.nrrd"));
  EXPECT_EQ(v.lattice.space, Space::RAS);
  EXPECT_EQ(v.lattice.origin, Vec3(-10, 20, 30));
  EXPECT_EQ(v.lattice.direction(0, 0), -1);
  // Unsupported encoding gets a clear message.
  test::write_file(tmp.path("bz.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\nxx");
  expect_input_error([&] { read_volume(tmp.path("bz.nrrd")); }, "bz.nrrd", "bzip2");
}

TEST(VolumeIO, SlicerSegmentations) {
  test::TempDir tmp;
  const std::string keys =
      "Segment0_ID:=Segment_1\nSegment0_Name:=liver\nSegment0_LabelValue:=1\nSegment0_Layer:=0\n"
      "Segment1_ID:=Segment_2\nSegment1_Name:=tumour\nSegment1_LabelValue:=1\nSegment1_Layer:=1\n"
      "Segment2_ID:=Segment_3\nSegment2_Name:=vessel\nSegment2_LabelValue:=2\nSegment2_Layer:=1\n";
  // 4-D layered file: 2 layers first (list axis), then 2 x 1 x 1 samples.
  test::write_file(tmp.path("layers.seg.nrrd"),
                   "NRRD0004\ntype: unsigned char\ndimension: 4\nspace: left-posterior-superior\nsizes: 2 2 1 1\n"
                   "space directions: none (1,0,0) (0,1,0) (0,0,1)\nkinds: list domain domain domain\n"
                   "encoding: raw\nspace origin: (0,0,0)\n" +
                       keys + "\n" + std::string("\x01\x02\x00\x01", 4));
  const ScalarVolume v = read_volume(tmp.path("layers.seg.nrrd"));
  EXPECT_EQ(v.components, 2);
  ASSERT_EQ(v.segments.size(), 3u);
  EXPECT_EQ(v.segments[1].name, "tumour");
  Selection s;
  s.kind = Selection::Kind::segment;
  s.segment = "liver";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{1, 0}));
  s.segment = "vessel";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{1, 0}));
  s.segment = "tumour";
  EXPECT_EQ(binarize(v, s).inside, (std::vector<uint8_t>{0, 1}));
  // Writing keeps the segments.
  write_volume(tmp.path("copy.seg.nrrd"), v);
  EXPECT_EQ(read_volume(tmp.path("copy.seg.nrrd")).segments.size(), 3u);
}

TEST(VolumeIO, TiffFolderSortsSlicesNaturally) {
  test::TempDir tmp;
  fs::create_directories(tmp.path("stack"));
  for (int z = 0; z < 12; ++z) {
    ScalarVolume slice;
    slice.type = ScalarType::u16;
    slice.lattice.dims = {3, 2, 1};
    slice.lattice.spacing = Vec3(0.5, 0.5, 1);
    slice.bytes.resize(12);
    const uint16_t val = uint16_t(z * 10);
    for (int i = 0; i < 6; ++i) std::memcpy(slice.bytes.data() + 2 * i, &val, 2);
    write_volume(tmp.path("stack/slice" + std::to_string(z) + ".tif"), slice);
  }
  const ScalarVolume v = read_volume(tmp.path("stack"));
  EXPECT_EQ(v.lattice.dims, (std::array<int64_t, 3>{3, 2, 12}));
  for (int z = 0; z < 12; ++z) EXPECT_EQ(v.value(uint64_t(z) * 6), z * 10) << "slice" << z << " out of order";
  EXPECT_NEAR(v.lattice.spacing.x(), 0.5, 1e-6);
}

TEST(VolumeIO, RawWithExplicitLayout) {
  test::TempDir tmp;
  std::string bytes = "HEAD";
  for (uint16_t x : {0, 1, 0, 1, 1, 1}) bytes.append(reinterpret_cast<const char*>(&x), 2);
  test::write_file(tmp.path("v.raw"), bytes);
  ReadOptions o;
  o.raw = RawLayout{{3, 2, 1}, ScalarType::u16, Vec3(1, 2, 3), Vec3(0, 0, 0), false, 4};
  const ScalarVolume v = read_volume(tmp.path("v.raw"), o);
  EXPECT_EQ(binarize(v).count_inside(), 4u);
  EXPECT_EQ(v.lattice.spacing, Vec3(1, 2, 3));
  o.raw->dims = {4, 2, 1};
  expect_input_error([&] { read_volume(tmp.path("v.raw"), o); }, "v.raw", "truncated");
  o.raw->dims = {2, 2, 1};
  expect_input_error([&] { read_volume(tmp.path("v.raw"), o); }, "v.raw", "does not match");
  EXPECT_THROW(read_volume(tmp.path("v.raw")), UsageError);  // layout missing
}

TEST(VolumeIO, BadInputsGetOneLineErrorsNamingTheFile) {
  test::TempDir tmp;
  expect_input_error([&] { read_volume(tmp.path("missing.nrrd")); }, "missing.nrrd", "no such file");
  test::write_file(tmp.path("thing.xyz"), "abc");
  expect_input_error([&] { read_volume(tmp.path("thing.xyz")); }, "thing.xyz", "unknown volume format");
  test::write_file(tmp.path("notnrrd.nrrd"), "hello\n");
  expect_input_error([&] { read_volume(tmp.path("notnrrd.nrrd")); }, "notnrrd.nrrd", "not a NRRD");
  // Truncated payloads.
  const ScalarVolume v = random_volume(ScalarType::u16, {10, 10, 10}, 3);
  for (const std::string name : {"t.nrrd", "u.nrrd", "t.nii", "t.nii.gz", "t.mha"}) {
    WriteVolumeOptions wo;
    wo.compress = name[0] != 'u';
    write_volume(tmp.path(name), v, wo);
    const auto size = fs::file_size(tmp.path(name));
    fs::resize_file(tmp.path(name), size - 300);
    SCOPED_TRACE(name);
    expect_input_error([&] { read_volume(tmp.path(name)); }, name, "truncated");
  }
  // Header dimensions that do not match the data.
  test::write_file(tmp.path("big.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + std::string(12, '\1'));
  expect_input_error([&] { read_volume(tmp.path("big.nrrd")); }, "big.nrrd", "does not match");
  test::write_file(tmp.path("gzbig.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n" +
                                               gzip(std::string(12, '\1')));
  expect_input_error([&] { read_volume(tmp.path("gzbig.nrrd")); }, "gzbig.nrrd", "more than");
  // Absurd dimensions are refused before allocating (a gzip bomb in the making).
  test::write_file(tmp.path("bomb.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100000 100000 100000\n"
                   "encoding: gzip\n\n" +
                       gzip(std::string(1000, '\0')));
  try {
    read_volume(tmp.path("bomb.nrrd"));
    FAIL();
  } catch (const LimitError& e) {
    EXPECT_NE(std::string(e.what()).find("bomb.nrrd"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("memory limit"), std::string::npos);
  }
  ReadOptions small;
  small.max_bytes = 1000;
  EXPECT_THROW(read_volume(tmp.path("t.nrrd"), small), LimitError);
  test::write_file(tmp.path("over.nrrd"),
                   "NRRD0004\ntype: double\ndimension: 3\nsizes: 4294967296 4294967296 4294967296\n"
                   "encoding: raw\n\n");
  EXPECT_THROW(read_volume(tmp.path("over.nrrd")), LimitError);
  test::write_file(tmp.path("neg.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 -2 2\nencoding: raw\n\n");
  expect_input_error([&] { read_volume(tmp.path("neg.nrrd")); }, "neg.nrrd", "invalid dimension");
  test::write_file(tmp.path("junk.nii"), std::string(400, 'x'));
  expect_input_error([&] { read_volume(tmp.path("junk.nii")); }, "junk.nii", "NIfTI");
  test::write_file(tmp.path("junk.tif"), std::string(400, 'x'));
  expect_input_error([&] { read_volume(tmp.path("junk.tif")); }, "junk.tif", "TIFF");
  // Text encoding with more values than declared; a detached header whose
  // data file is missing names the header (and the missing file).
  test::write_file(tmp.path("more.nrrd"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: text\n\n1 0 1\n");
  expect_input_error([&] { read_volume(tmp.path("more.nrrd")); }, "more.nrrd", "more than the 2 values");
  test::write_file(tmp.path("lost.nhdr"),
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: raw\ndata file: lost.raw\n");
  expect_input_error([&] { read_volume(tmp.path("lost.nhdr")); }, "lost.nhdr", "lost.raw does not exist");
  // A multi-page TIFF cut anywhere (a page's data, its directory, a value
  // stored past it such as XResolution, the link to the next page) is an
  // error, never fewer slices or a default spacing (libtiff reads what it
  // reaches without a word).
  {
    const ScalarVolume stack = random_volume(ScalarType::u8, {9, 7, 12}, 4);
    write_volume(tmp.path("whole.tif"), stack);
    const std::string bytes = test::read_file(tmp.path("whole.tif"));
    ASSERT_EQ(read_volume(tmp.path("whole.tif")).lattice.dims[2], 12);
    size_t refused = 0, tried = 0;
    for (size_t cut = 8; cut < bytes.size(); cut += cut < bytes.size() - 64 ? 13 : 1) {
      test::write_file(tmp.path("cut.tif"), bytes.substr(0, cut));
      ++tried;
      try {
        read_volume(tmp.path("cut.tif"));
        ADD_FAILURE() << "a TIFF cut at " << cut << " of " << bytes.size() << " bytes was read";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("cut.tif"), std::string::npos);
        ++refused;
      }
    }
    EXPECT_EQ(refused, tried);
  }
  // No temporary or partial output is left by a failed write.
  EXPECT_THROW(write_volume(tmp.path("nowhere/x.nrrd"), v), InputError);
  EXPECT_THROW(write_volume(tmp.path("x.vtk"), v), UsageError);
}

// ---------------------------------------------------------------- real files
struct MedicalFact {
  const char* file;
  std::array<int64_t, 3> dims;
  Vec3 spacing;
  uint64_t inside;  // foreground voxels per ../shared/data/README.md (0: multi-label)
  Space space;
};

TEST(VolumeIO, SharedMedicalVolumesMatchTheirDocumentedFacts) {
  VOXPRESS_REQUIRE_SHARED_DATA();
  const MedicalFact facts[] = {
      {"BallBinary30x30x30.nrrd", {30, 30, 30}, Vec3(1, 1, 1), 14328, Space::LPS},
      {"pyradiomics_brain1_label.nrrd", {256, 256, 25}, Vec3(0.78125, 0.78125, 6.5), 4137, Space::LPS},
      {"pyradiomics_lung2_label.nrrd", {512, 512, 61}, Vec3(0.6269531, 0.6269531, 5.0), 24644, Space::LPS},
      {"elastix_3DCT_lung_baseline_mask.mha", {115, 157, 129}, Vec3(1.366, 1.366, 2.5), 721043, Space::LPS},
      {"totalseg_aorta.nii.gz", {120, 126, 164}, Vec3(1.5, 1.5, 1.5), 72810, Space::RAS},
      {"totalseg_heart.nii.gz", {233, 167, 191}, Vec3(1.5, 1.5, 1.5), 198176, Space::RAS},
      {"totalseg_example_seg_dicom.nii.gz", {512, 512, 20}, Vec3(0.9765625, 0.9765625, 2.0), 0, Space::RAS},
      {"totalseg_example_seg_fast_force_split.nii.gz", {122, 101, 112}, Vec3(3, 3, 3), 0, Space::RAS},
  };
  for (const auto& f : facts) {
    SCOPED_TRACE(f.file);
    const std::string path = test::shared_data() + "/medical/" + f.file;
    const ScalarVolume v = read_volume(path);
    EXPECT_EQ(v.lattice.dims, f.dims);
    EXPECT_LT((v.lattice.spacing - f.spacing).norm(), 1e-5);
    EXPECT_EQ(v.lattice.space, f.space);
    if (f.inside) {
      const BinaryVolume b = binarize(v);
      EXPECT_EQ(b.count_inside(), f.inside);
      // The midpoint surface of every real mask is valid and separates its samples.
      const Mesh m = to_mesh(extract_sticks(b));
      const MeshCheck r = check_mesh(m);
      EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0]);
      EXPECT_GT(r.signed_volume, 0);
      EXPECT_EQ(check_classification(m, b).violations, 0u);
    } else {
      EXPECT_THROW(binarize(v), InputError);  // multi-label: a choice is required
    }
  }
  // Orientation facts: brain1's y axis points to -y; the seg_dicom file is LAS (x to -x in RAS).
  const ScalarVolume brain = read_volume(test::shared_data() + "/medical/pyradiomics_brain1_label.nrrd");
  EXPECT_LT(brain.lattice.direction(1, 1), 0);
  EXPECT_NEAR(brain.lattice.origin.y(), 99.609375, 1e-6);
  const ScalarVolume dicom = read_volume(test::shared_data() + "/medical/totalseg_example_seg_dicom.nii.gz");
  EXPECT_LT(dicom.lattice.direction(0, 0), 0);
  // 61 labels of the TotalSegmentator map, and the label values listed in the README.
  const ScalarVolume split = read_volume(test::shared_data() + "/medical/totalseg_example_seg_fast_force_split.nii.gz");
  const auto hist = value_histogram(split);
  ASSERT_TRUE(hist);
  EXPECT_EQ(hist->size(), 62u);  // 61 labels + background
  uint64_t fg = 0;
  for (auto& [value, n] : *hist) fg += value != 0 ? n : 0;
  EXPECT_EQ(fg, 345988u);
}

}  // namespace
}  // namespace voxpress
