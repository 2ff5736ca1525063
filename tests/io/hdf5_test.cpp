// HDF5 volumes: round trip of samples and lattice for every type, boxes read
// by hyperslab equal crops of the whole volume (chunked gzip datasets
// included), a dataset chosen by name or by being the only 3-D one, and bad
// files refused with the file named. Files with several datasets, foreign
// types or Fiji-style attributes are written here with the C API.
#include <hdf5.h>

#include <cstring>
#include <fstream>

#include "test_util.h"

namespace voxpress {
namespace {

// A dataset written with the C API, as another tool would: C order (z, y, x).
void write_dataset(hid_t file, const std::string& name, hid_t type, hid_t memory, const std::vector<hsize_t>& dims,
                   const void* data) {
  const hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  const hid_t ds = H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ds, 0);
  H5Dwrite(ds, memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  if (name == "/raw/fiji") {
    const hsize_t three = 3;
    const hid_t as = H5Screate_simple(1, &three, nullptr);
    const hid_t a = H5Acreate2(ds, "element_size_um", H5T_IEEE_F32LE, as, H5P_DEFAULT, H5P_DEFAULT);
    const float f[3] = {2.5f, 0.5f, 0.25f};
    H5Awrite(a, H5T_NATIVE_FLOAT, f);
    H5Aclose(a);
    H5Sclose(as);
  }
  H5Dclose(ds);
  H5Sclose(space);
}

std::string several_datasets(const test::TempDir& dir) {
  const std::string path = dir.path("several.h5");
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t g = H5Gcreate2(f, "/raw", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Gclose(g);
  std::vector<uint16_t> a(4 * 5 * 6);
  for (size_t n = 0; n < a.size(); ++n) a[n] = uint16_t(n * 7 % 1000);
  write_dataset(f, "/raw/fiji", H5T_STD_U16BE, H5T_NATIVE_UINT16, {4, 5, 6}, a.data());  // big-endian on disk: HDF5 converts
  write_dataset(f, "/mask", H5T_NATIVE_UINT8, H5T_NATIVE_UINT8, {3, 3, 3}, std::vector<uint8_t>(27, 1).data());
  write_dataset(f, "/plane", H5T_NATIVE_UINT8, H5T_NATIVE_UINT8, {3, 3}, std::vector<uint8_t>(9, 1).data());
  const hid_t str = H5Tcopy(H5T_C_S1);
  H5Tset_size(str, 4);
  write_dataset(f, "/text", str, str, {2, 2, 2}, std::string(32, 'a').data());
  H5Tclose(str);
  H5Fclose(f);
  return path;
}

TEST(Hdf5, EveryTypeRoundTripsWithItsLatticeAndBoxesMatchCrops) {
  test::TempDir dir;
  for (ScalarType t : {ScalarType::u8, ScalarType::i8, ScalarType::u16, ScalarType::i16, ScalarType::u32,
                       ScalarType::i32, ScalarType::u64, ScalarType::i64, ScalarType::f32, ScalarType::f64}) {
    ScalarVolume v = test::random_scalar_volume(t, {70, 23, 67}, uint64_t(t) + 3, 1, 100);
    v.lattice.spacing = Vec3(0.5, 0.75, 2.0);
    v.lattice.origin = Vec3(-3, 4.25, 10);
    v.lattice.direction = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    for (bool compress : {true, false}) {
      const std::string path = dir.path(std::string("v") + (compress ? "z" : "") + ".h5");
      write_volume(path, v, {.compress = compress});
      const ScalarVolume back = read_volume(path);
      ASSERT_EQ(back.type, t);
      EXPECT_EQ(back.lattice.dims, v.lattice.dims);
      EXPECT_TRUE(back.lattice.spacing == v.lattice.spacing);
      EXPECT_TRUE(back.lattice.origin == v.lattice.origin);
      EXPECT_TRUE(back.lattice.direction == v.lattice.direction);
      EXPECT_TRUE(back.bytes == v.bytes) << scalar_name(t);
      const VolumeFile file(path + ":/volume");
      EXPECT_TRUE(file.streams());
      EXPECT_TRUE(file.header().bytes.empty());
      test::Rng rng{uint64_t(t)};
      for (int n = 0; n < 10; ++n) {  // boxes across the 64^3 chunks of the writer
        Box b;
        for (size_t a = 0; a < 3; ++a) {
          b.lo[a] = rng.range(0, v.lattice.dims[a] - 1);
          b.hi[a] = rng.range(b.lo[a] + 1, v.lattice.dims[a]);
        }
        const ScalarVolume got = file.read(b);
        ASSERT_EQ(got.lattice.dims, b.dims());
        EXPECT_LT((got.lattice.origin - v.lattice.to_physical(Vec3(double(b.lo[0]), double(b.lo[1]), double(b.lo[2])))).norm(), 1e-9);
        const size_t vs = scalar_size(t);
        bool same = true;
        size_t at = 0;
        for (int64_t k = b.lo[2]; k < b.hi[2]; ++k)
          for (int64_t j = b.lo[1]; j < b.hi[1]; ++j)
            for (int64_t i = b.lo[0]; i < b.hi[0]; ++i, at += vs)
              same = same && std::memcmp(got.bytes.data() + at, v.bytes.data() + v.lattice.linear(i, j, k) * vs, vs) == 0;
        EXPECT_TRUE(same) << scalar_name(t) << " box " << n;
      }
    }
  }
}

TEST(Hdf5, DatasetsAreChosenByNameOrAsTheOnlyThreeDimensionalOne) {
  test::TempDir dir;
  const std::string path = several_datasets(dir);
  const ScalarVolume fiji = read_volume(path + ":/raw/fiji");
  EXPECT_EQ(fiji.type, ScalarType::u16);
  EXPECT_EQ(fiji.lattice.dims, (std::array<int64_t, 3>{6, 5, 4}));
  EXPECT_TRUE(fiji.lattice.spacing == Vec3(0.25, 0.5, 2.5));  // element_size_um is (z, y, x)
  EXPECT_DOUBLE_EQ(fiji.value(fiji.lattice.linear(5, 4, 3)), double((4 * 5 * 6 - 1) * 7 % 1000));
  EXPECT_EQ(read_volume(path + ":/mask").lattice.dims, (std::array<int64_t, 3>{3, 3, 3}));
  test::expect_input_error([&] { read_volume(path); }, path, "3-D datasets");  // /mask, /raw/fiji, /text
  test::expect_input_error([&] { read_volume(path + ":/plane"); }, path, "not a 3-D dataset");
  test::expect_input_error([&] { read_volume(path + ":/text"); }, path, "unsupported HDF5 sample type");
  test::expect_input_error([&] { read_volume(path + ":/absent"); }, path, "no dataset /absent");
}

TEST(Hdf5, DamagedFilesAreRefusedNamingTheFile) {
  test::TempDir dir;
  const ScalarVolume v = test::random_scalar_volume(ScalarType::u8, {40, 30, 20}, 5, 1, 2);
  const std::string good = dir.path("good.h5");
  write_volume(good, v);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t keep : {size_t(0), size_t(8), size_t(100), bytes.size() / 2, bytes.size() - 10}) {
    const std::string cut = dir.path("cut" + std::to_string(keep) + ".h5");
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(keep));
    test::expect_input_error([&] { read_volume(cut); }, cut, "");
    test::expect_input_error([&] { VolumeFile f(cut); (void)f.read(Box{{0, 0, 0}, {40, 30, 20}}); }, cut, "");
  }
  test::expect_input_error([&] { read_volume(dir.path("missing.h5")); }, dir.path("missing.h5"), "");
  test::expect_input_error([&] { ReadOptions small; small.max_bytes = 1000; read_volume(good, small); }, good, "");
}

}  // namespace
}  // namespace voxpress
