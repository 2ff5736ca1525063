// Regression tests for the inputs bench/fuzz found (docs/RELIABILITY.md):
// each is the minimized finding, written out as the file it was, and must now
// be refused with one InputError line naming the file.
#include <string>
#include <vector>

#include "test_util.h"
#include "voxpress/voxart/voxel_art.h"

namespace voxpress {
namespace {

struct Finding {
  const char* name;  ///< file name (its extension picks the reader)
  std::string bytes;
  const char* what;  ///< expected in the message
};

void read_any(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".ply" || ext == ".obj" || ext == ".stl" || ext == ".off" || ext == ".vtk" || ext == ".vtp")
    (void)read_mesh(path);
  else if (ext == ".vox" || ext == ".vxl")
    (void)read_voxel_art(path);
  else if (ext == ".png" || ext == ".pgm" || ext == ".pbm" || ext == ".ppm")
    (void)read_image(path);
  else
    (void)read_volume(path);
}

std::string from_hex(const std::string& hex) {
  std::string out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2) out.push_back(char(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

std::vector<Finding> findings() {
  using namespace std::string_literals;
  return {
      // UBSan: NaN converted to an integer sample type (nrrd.cpp, text encoding).
      {"nan-text-sample.nrrd", "NRRD0004\ntype: uint\ndimension: 3\nsizes: 2 1 1\nencoding: text\n\n-nan float\n",
       "does not fit the declared voxel type"},
      {"big-text-sample.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: text\n\n1 256\n",
       "does not fit the declared voxel type"},
      // UBSan: a NaN list length converted to an integer (ply.cpp); the
      // finding was a binary file with a float list count.
      {"nan-list-length.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list float int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\nnan 0 1 2\n",
       "invalid vertex count"},
      {"nan-vertex-list.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "property list float int extra\nend_header\n0 0 0 nan\n",
       "invalid list length"},
      // Stack overflow inside nifti_clib (nifti_convert_n2hdr2nim writes
      // dim[dim[0] + 1 ..] = 1): a gzipped NIfTI-2 header whose dim[0] is
      // 0x5b5b5b5b5b5b5b5b. The finding's exact bytes.
      {"bad-dim0.nii.gz", from_hex(
           "1f8b080000000000000393616260c8d33662e08e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e"
           "8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e"
           "8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8e8ee592e2626110606066800016280de33341294602347ef0c19e5c5a01e600307880263f"
           "3801716182171c40e5aa38403803000b7356f750020000"),
       "dim[0]"},
      // Timeout: an element without properties and a count of 6.6e8 looped
      // over empty records (0.6 s in Release, over 10 s under ASan); with
      // 2^63, as here, it would never end (a regression hangs until ctest's
      // timeout fails it).
      {"empty-elements.ply",
       "ply\nformat binary_little_endian 1.0\nelement junk 9223372036854775807\nelement edge 9223372036854775807\n"
       "end_header\n",
       "no vertex element"},
      // UBSan: a DimSize beyond int64 converted to an integer (metaimage.cpp).
      {"huge-dimsize.mha",
       "ObjectType = Image\nNDims = 3\nDimSize = 3 5 46666666666666666666666666\nElementType = MET_CHAR\n"
       "ElementDataFile = LOCAL\n",
       "DimSize"},
      // Out of memory: a 277-byte tiled TIFF whose tile size made the reader
      // allocate 1.7 GB before reading a byte of it. The finding's exact bytes.
      {"huge-tile.tif", from_hex(
           "49492a0034000000789cb3f68e08170ce013d0540bd38d65b315d18fb20cd6e1b48ae764b0e1e54e9137138f48010080ee0706001100"
           "fe00040001000000020000000001030001000000076a0000010103000100000005000000020103000100000008000000030103000100"
           "0000b28000000601030001000000010000000e0102003200000016010000110104000100000008000000171103000100000001000000"
           "16010300010000009224000017010400010000232b0000001a01050001000000060100001b010000000200000e0009001c0103000100"
           "0000010000002801030001000000010000002901030100000000000025004301030001000000ffffffffffffffffffff72010000b76d"
           "5b8e8e8e010501"),
       "larger than the image"},
      // UBSan: a cell list's index of 4.4e20 (and a strip's of 5.6e73)
      // converted to an integer (vtk.cpp, legacy cell lists). Minimized.
      {"huge-cell-index.vtk",
       "# vtk DataFile Version 3.0\nstrip\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n0 0 0 1 0 0 0 1 0 1 1 0\n"
       "LINES 1 3\n2 444444444444444444444 3\n",
       "bad index"},
      {"huge-strip-index.vtk",
       "# vtk DataFile Version 3.0\nstrip\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n0 0 0 1 0 0 0 1 0 1 1 0\n"
       "TRIANGLE_STRIPS 1 5\n4 0 55555555555555555555555555555555555555555555555555555555555555555555555555 2 3\n",
       "bad index"},
  };
}

TEST(FuzzRegressions, EveryFindingIsRefusedWithOneLineNamingTheFile) {
  test::TempDir tmp;
  for (const Finding& f : findings()) {
    SCOPED_TRACE(f.name);
    const std::string path = tmp.path(f.name);
    test::write_file(path, f.bytes);
    try {
      read_any(path);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(f.name), std::string::npos) << msg;
      EXPECT_NE(msg.find(f.what), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

// Detached data that is not a regular file (a pipe, a device) could block
// or never end: refused by name before anything is read.
TEST(Hardening, DetachedDataMustBeARegularFile) {
  test::TempDir tmp;
  const std::pair<const char*, std::string> headers[] = {
      {"stdin.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: /dev/stdin\n\n"},
      {"zero.mhd", "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                   "ElementDataFile = /dev/zero\n"},
  };
  for (const auto& [name, text] : headers) {
    test::write_file(tmp.path(name), text);
    try {
      (void)read_volume(tmp.path(name));
      ADD_FAILURE() << name << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace voxpress
