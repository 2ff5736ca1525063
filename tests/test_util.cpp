#include "test_util.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <sys/resource.h>
#include <sys/wait.h>

namespace voxpress::test {

namespace fs = std::filesystem;

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

std::string le32(int32_t v) {
  std::string s(4, '\0');
  for (int b = 0; b < 4; ++b) s[size_t(b)] = char((uint32_t(v) >> (8 * b)) & 0xff);
  return s;
}

std::string vox_chunk(const std::string& id, const std::string& content, const std::string& children) {
  return id + le32(int32_t(content.size())) + le32(int32_t(children.size())) + content + children;
}

std::string vox_dict(const std::vector<std::pair<std::string, std::string>>& entries) {
  std::string s = le32(int32_t(entries.size()));
  for (const auto& [k, v] : entries) s += le32(int32_t(k.size())) + k + le32(int32_t(v.size())) + v;
  return s;
}

std::string vox_model(std::array<int, 3> size, const std::vector<std::array<uint8_t, 4>>& voxels) {
  std::string xyzi = le32(int32_t(voxels.size()));
  for (const auto& v : voxels) xyzi += std::string(reinterpret_cast<const char*>(v.data()), 4);
  return vox_chunk("SIZE", le32(size[0]) + le32(size[1]) + le32(size[2])) + vox_chunk("XYZI", xyzi);
}

std::string vox_file(const std::string& main_children, int32_t version) {
  return "VOX " + le32(version) + vox_chunk("MAIN", "", main_children);
}

std::string f32(float v) {
  uint32_t b;
  std::memcpy(&b, &v, 4);
  return le32(int32_t(b));
}

// One section of size (2, 1, 3), voxels at (0, 0, 0) colour 5 and (1, 0, 1),
// (1, 0, 2) colour 9; bounds (0..4, 0..1, 0..6) make the voxels 2 x 1 x 2
// units; det 0.5 scales the translation (2, 0, 0).
std::string vxl_file() {
  const std::string col0 = std::string{char(0), char(1), char(5), char(0), char(1)};  // skip 0, 1 voxel
  const std::string col1 = std::string{char(1), char(2), char(9), char(0), char(9), char(0), char(2)};  // skip 1, 2
  const std::string body = le32(0) + le32(int32_t(col0.size())) +  // span starts
                           le32(int32_t(col0.size()) - 1) + le32(int32_t(col0.size() + col1.size()) - 1) +  // ends
                           col0 + col1;
  std::string palette(768, '\0');
  palette[15] = char(200);  // colour 5 = (200, 0, 0)
  palette[27] = char(10);   // colour 9 = (10, 20, 30)
  palette[28] = char(20);
  palette[29] = char(30);
  const std::string header = std::string("Voxel Animation") + '\0' + le32(1) + le32(1) + le32(1) +
                             le32(int32_t(body.size())) + std::string{char(16), char(31)} + palette;
  const std::string section = std::string("Body") + std::string(12, '\0') + le32(0) + le32(1) + le32(0);
  std::string tailer = le32(0) + le32(8) + le32(16) + f32(0.5f);
  const float m[12] = {1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 0};
  for (float v : m) tailer += f32(v);
  for (float v : {0.f, 0.f, 0.f, 4.f, 1.f, 6.f}) tailer += f32(v);
  tailer += std::string{char(2), char(1), char(3), char(2)};
  return header + section + body + tailer;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "voxpress";
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.') c = '_';
  dir_ = fs::temp_directory_path() / ("voxpress-test-" + std::to_string(::getpid()) + "-" +
                                      std::to_string(counter++) + "-" + name);
  fs::remove_all(dir_);
  fs::create_directories(dir_);
}

TempDir::~TempDir() {
  std::error_code ec;
  // bench/fuzz seeds its corpora with the files the tests write.
  if (const char* keep = std::getenv("VOXPRESS_KEEP_TEST_FILES"); keep && *keep) {
    const std::string prefix = dir_.filename().string().substr(dir_.filename().string().find('-', 14) + 1);
    for (const auto& e : fs::recursive_directory_iterator(dir_, ec))
      if (e.is_regular_file(ec) && e.file_size(ec) <= (256u << 10))
        fs::copy_file(e.path(), fs::path(keep) / (prefix + "-" + e.path().filename().string()),
                      fs::copy_options::overwrite_existing, ec);
  }
  fs::remove_all(dir_, ec);
}

std::vector<std::string> TempDir::files() const {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string shared_data() {
  if (const char* env = std::getenv("VOXPRESS_SHARED_DATA"); env && *env) return fs::exists(env) ? env : "";
  const fs::path p = fs::path(VOXPRESS_SOURCE_DIR) / ".." / "shared" / "data";
  return fs::exists(p / "README.md") ? fs::canonical(p).string() : "";
}

VoxelizedModel voxelized_shared_model(const std::string& file, int64_t res, int seed) {
  return voxelized_model(read_mesh(shared_data() + "/meshes/" + file), file, res, seed);
}

VoxelizedModel voxelized_model(const Mesh& model, const std::string& name, int64_t res, int seed) {
  VoxelizeOptions vo;
  vo.res = res;
  vo.rotation = parse_rotation("random:" + std::to_string(seed));
  Voxelized v = voxelize(model, vo);
  Mesh phys = model;
  for (Vec3& p : phys.positions) p = v.placement.translation + v.placement.linear * p;
  VoxelizedModel out;
  out.physical = phys;
  out.truth = mesh_truth(std::move(phys), name);
  out.volume = std::move(v.volume);
  return out;
}

uint64_t Rng::next() {
  uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

BinaryVolume make_volume(int64_t nx, int64_t ny, int64_t nz) {
  BinaryVolume v;
  v.lattice.dims = {nx, ny, nz};
  v.inside.assign(size_t(nx * ny * nz), 0);
  v.source = "test volume";
  return v;
}

BinaryVolume random_noise(Rng& rng, std::array<int64_t, 3> d, double density) {
  BinaryVolume v = make_volume(d[0], d[1], d[2]);
  for (auto& x : v.inside) x = rng.uniform() < density ? 1 : 0;
  return v;
}

BinaryVolume random_blobs(Rng& rng, std::array<int64_t, 3> d, int blobs) {
  BinaryVolume v = make_volume(d[0], d[1], d[2]);
  for (int b = 0; b < blobs; ++b) {
    const Vec3 c(rng.uniform() * double(d[0]), rng.uniform() * double(d[1]), rng.uniform() * double(d[2]));
    const double r = 1 + rng.uniform() * double(std::min({d[0], d[1], d[2]})) / 3;
    for (int64_t k = 0; k < d[2]; ++k)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i)
          if ((Vec3(double(i), double(j), double(k)) - c).norm() <= r) v.inside[v.lattice.linear(i, j, k)] = 1;
  }
  return v;
}

namespace {

// The lattice of reframed().
Lattice reframed_lattice(const Lattice& l, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
  Lattice out = l;
  for (size_t a = 0; a < 3; ++a) out.dims[a] = l.dims[a] + lo[a] + hi[a];
  out.origin = l.to_physical(Vec3(-double(lo[0]), -double(lo[1]), -double(lo[2])));
  return out;
}

// For each sample of `out` (reframed_lattice(l, lo, ...)) within `l`:
// put(its linear index in out, get(its linear index in l)).
template <class Get, class Put>
void copy_reframed(const Lattice& l, const Lattice& out, const std::array<int64_t, 3>& lo, Get get, Put put) {
  for (int64_t k = 0; k < out.dims[2]; ++k)
    for (int64_t j = 0; j < out.dims[1]; ++j)
      for (int64_t i = 0; i < out.dims[0]; ++i) {
        const int64_t x = i - lo[0], y = j - lo[1], z = k - lo[2];
        if (x >= 0 && y >= 0 && z >= 0 && x < l.dims[0] && y < l.dims[1] && z < l.dims[2])
          put(out.linear(i, j, k), get(l.linear(x, y, z)));
      }
}

// lo, hi of reframed() that crop to the box of the samples where `in` holds.
template <class In>
std::array<std::array<int64_t, 3>, 2> crop_of(const Lattice& l, In in) {
  std::array<int64_t, 3> mn{INT64_MAX, INT64_MAX, INT64_MAX}, mx{-1, -1, -1};
  for (int64_t k = 0; k < l.dims[2]; ++k)
    for (int64_t j = 0; j < l.dims[1]; ++j)
      for (int64_t i = 0; i < l.dims[0]; ++i)
        if (in(l.linear(i, j, k))) {
          const std::array<int64_t, 3> x{i, j, k};
          for (size_t a = 0; a < 3; ++a) mn[a] = std::min(mn[a], x[a]), mx[a] = std::max(mx[a], x[a]);
        }
  return {{{-mn[0], -mn[1], -mn[2]}, {mx[0] + 1 - l.dims[0], mx[1] + 1 - l.dims[1], mx[2] + 1 - l.dims[2]}}};
}

}  // namespace

BinaryVolume reframed(const BinaryVolume& v, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
  BinaryVolume p;
  p.source = v.source;
  p.lattice = reframed_lattice(v.lattice, lo, hi);
  p.inside.assign(p.lattice.size(), 0);
  copy_reframed(v.lattice, p.lattice, lo, [&](uint64_t n) { return v.inside[n]; },
                [&](uint64_t n, uint8_t x) { p.inside[n] = x; });
  return p;
}

ScalarVolume reframed(const ScalarVolume& v, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
  ScalarVolume p;
  p.source = v.source;
  p.type = ScalarType::u8;
  p.lattice = reframed_lattice(v.lattice, lo, hi);
  p.bytes.assign(p.lattice.size(), std::byte{0});
  copy_reframed(v.lattice, p.lattice, lo, [&](uint64_t n) { return v.value(n * uint64_t(v.components)); },
                [&](uint64_t n, double x) {
                  if (!(x >= 0 && x < 256)) throw std::invalid_argument("reframed: a value beyond 0..255");
                  p.bytes[n] = std::byte(uint8_t(x));
                });
  return p;
}

BinaryVolume cropped(const BinaryVolume& v) {
  const auto [lo, hi] = crop_of(v.lattice, [&](uint64_t n) { return v.inside[n] != 0; });
  return reframed(v, lo, hi);
}

ScalarVolume cropped(const ScalarVolume& v) {
  const auto [lo, hi] = crop_of(v.lattice, [&](uint64_t n) { return v.value(n * uint64_t(v.components)) != 0; });
  return reframed(v, lo, hi);
}

BinaryVolume checkerboard(std::array<int64_t, 3> d, int period_axes) {
  BinaryVolume v = make_volume(d[0], d[1], d[2]);
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const int64_t s = ((period_axes & 1) ? i : 0) + ((period_axes & 2) ? j : 0) + ((period_axes & 4) ? k : 0);
        v.inside[v.lattice.linear(i, j, k)] = s % 2 == 0 ? 1 : 0;
      }
  return v;
}

BinaryVolume far_anisotropic_part(int64_t res) {
  GenerateOptions g;
  g.res = res;
  g.rotation = parse_rotation("random:3");
  BinaryVolume v = generate_shape(ShapeKind::cad_part, g).volume;
  v.lattice.spacing = Vec3(0.7, 0.7, 1.9);
  v.lattice.origin = Vec3(-2500.25, 1800.5, 3100.75);
  return v;
}

Mesh rounded_to_float32(Mesh m) {
  for (Vec3& p : m.positions) p = p.cast<float>().cast<double>();
  return m;
}

void expect_guarantees(const Mesh& m, const BinaryVolume& v) {
  const Mesh f = rounded_to_float32(m);
#if defined(__SANITIZE_ADDRESS__)
  // Under the sanitizers (memory safety, CI's second part) the float32 pass
  // would run the same checking code again on other numbers; the Release
  // suite runs it.
  const std::vector<const Mesh*> meshes{&m};
#else
  const std::vector<const Mesh*> meshes{&m, &f};
#endif
  for (const Mesh* mesh : meshes) {
    SCOPED_TRACE(mesh == &m ? "double" : "float32");
    const MeshCheck mc = check_mesh(*mesh);
    EXPECT_TRUE(mc.ok()) << (mc.problems.empty() ? "" : mc.problems[0]);
    EXPECT_EQ(check_classification(*mesh, v).violations, 0u);
  }
}

ScalarVolume random_scalar_volume(ScalarType type, std::array<int64_t, 3> dims, uint64_t seed, int64_t components,
                                  int64_t max_value) {
  ScalarVolume v;
  v.type = type;
  v.components = components;
  v.lattice.dims = dims;
  v.lattice.spacing = Vec3(0.7, 1.25, 2.5);
  v.lattice.origin = Vec3(-12.5, 3.25, 100);
  v.lattice.direction = Eigen::AngleAxisd(0.3, Vec3(1, 2, 2).normalized()).toRotationMatrix();
  v.lattice.space = Space::LPS;
  v.bytes.resize(v.value_count() * scalar_size(type));
  Rng rng(seed);
  v.visit([&](auto values) {
    using T = typename decltype(values)::value_type;
    T* p = const_cast<T*>(values.data());
    for (size_t i = 0; i < values.size(); ++i) p[i] = T(rng.range(0, max_value));
  });
  return v;
}

void write_raw_volume(const std::string& path, const ScalarVolume& v) {
  WriteVolumeOptions raw;
  raw.compress = false;
  write_volume(path, v, raw);
}

std::vector<Case> property_volumes() {
  std::vector<Case> out;
  Rng rng(2024);
  // Every single-cell configuration (all 256 cube cases, touching the border).
  for (unsigned mask = 1; mask < 256; ++mask) {
    BinaryVolume v = make_volume(2, 2, 2);
    for (int c = 0; c < 8; ++c) v.inside[size_t((c & 1) + 2 * ((c >> 1) & 1) + 4 * ((c >> 2) & 1))] = (mask >> c) & 1;
    out.push_back({"cube case " + std::to_string(mask), v});
  }
  // Random noise at several densities and sizes.
  for (double density : {0.1, 0.3, 0.5, 0.7, 0.9})
    for (int s = 0; s < 16; ++s) {
      const std::array<int64_t, 3> d{rng.range(3, 12), rng.range(3, 12), rng.range(3, 12)};
      out.push_back({"noise " + std::to_string(density) + " #" + std::to_string(s), random_noise(rng, d, density)});
    }
  // Random blobs (smooth-ish organic unions).
  for (int s = 0; s < 20; ++s) {
    const std::array<int64_t, 3> d{rng.range(8, 20), rng.range(8, 20), rng.range(8, 20)};
    out.push_back({"blobs #" + std::to_string(s), random_blobs(rng, d, int(rng.range(1, 6)))});
  }
  // Checkerboards: 3D (corner contacts everywhere), 2D and 1D stripes.
  for (int axes = 1; axes < 8; ++axes) out.push_back({"checkerboard " + std::to_string(axes), checkerboard({7, 6, 5}, axes)});
  // Single voxels, including in corners and on the border, and 1-sample volumes.
  out.push_back({"1x1x1 inside", [] { auto v = make_volume(1, 1, 1); v.inside[0] = 1; return v; }()});
  for (int s = 0; s < 10; ++s) {
    BinaryVolume v = make_volume(4, 5, 3);
    v.inside[size_t(rng.range(0, int64_t(v.inside.size()) - 1))] = 1;
    out.push_back({"single voxel #" + std::to_string(s), v});
  }
  // Pairs touching only along an edge or at a corner (non-manifold voxel configurations).
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        if (std::abs(dx) + std::abs(dy) + std::abs(dz) < 2) continue;
        BinaryVolume v = make_volume(5, 5, 5);
        v.inside[v.lattice.linear(2, 2, 2)] = 1;
        v.inside[v.lattice.linear(2 + dx, 2 + dy, 2 + dz)] = 1;
        out.push_back({"diagonal pair " + std::to_string(dx) + "," + std::to_string(dy) + "," + std::to_string(dz), v});
      }
  // Noise whose border layer is inside (surface closes around the grid).
  for (int s = 0; s < 10; ++s) {
    BinaryVolume v = random_noise(rng, {6, 7, 8}, 0.5);
    for (int64_t k = 0; k < 8; ++k)
      for (int64_t j = 0; j < 7; ++j)
        for (int64_t i = 0; i < 6; ++i)
          if (i == 0 || j == 0 || k == 0 || i == 5 || j == 6 || k == 7) v.inside[v.lattice.linear(i, j, k)] = 1;
    out.push_back({"border noise #" + std::to_string(s), v});
  }
  // Thin structures: 1-sample-thick planes and lines.
  for (int s = 0; s < 6; ++s) {
    BinaryVolume v = make_volume(1 + s, 6, 1);
    for (auto& x : v.inside) x = rng.uniform() < 0.6 ? 1 : 0;
    out.push_back({"flat sheet #" + std::to_string(s), v});
  }
  // Generated shapes at random rotations. Under the sanitizers (10-20x
  // slower) the two smaller seeds only: the larger ones run the same code on
  // more samples, and they run in the Release suite.
#ifdef VOXPRESS_SANITIZED
  constexpr int kSeeds = 2;
#else
  constexpr int kSeeds = 4;
#endif
  for (ShapeKind k : all_shapes())
    for (int seed = 0; seed < kSeeds; ++seed) {
      GenerateOptions o;
      o.res = 20 + 6 * seed;
      o.rotation = parse_rotation("random:" + std::to_string(seed * 31 + 7));
      out.push_back({std::string(shape_name(k)) + " seed " + std::to_string(seed), generate_shape(k, o).volume});
    }
  return out;
}

int run_cli(const std::string& args, std::string* output) {
  const std::string cmd = std::string(VOXPRESS_CLI) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return -1;
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = ::pclose(p);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

CliRun run_cli_measured(const std::string& args, uint64_t address_space_limit) {
  std::vector<std::string> words = {VOXPRESS_CLI};
  std::istringstream fields(args);
  for (std::string w; fields >> w;) words.push_back(w);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  int fds[2];
  CliRun r;
  if (::pipe(fds) != 0) return r;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fds[1], 1);
    ::dup2(fds[1], 2);
    ::close(fds[0]);
    ::close(fds[1]);
    if (address_space_limit) {
      const rlimit lim{address_space_limit, address_space_limit};
      ::setrlimit(RLIMIT_AS, &lim);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  char buf[4096];
  ssize_t n;
  while ((n = ::read(fds[0], buf, sizeof buf)) > 0) r.output.append(buf, size_t(n));
  ::close(fds[0]);
  int status = 0;
  rusage usage{};
  if (pid < 0 || ::wait4(pid, &status, 0, &usage) != pid) return r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.peak_kib = usage.ru_maxrss;
  return r;
}

}  // namespace voxpress::test
