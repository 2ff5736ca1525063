// Westwood .vxl reader (Tiberian Sun / Red Alert 2), with the .hva beside it.
//
// Layout (all little-endian): an 802-byte header ("Voxel Animation\0",
// palette count, section count, tailer count, body size, remap range, a
// 256 x RGB palette), one 28-byte header per section (name), the body, then
// one 92-byte tailer per section: offsets of its span-start table, span-end
// table and span data (relative to the body), a scale ("det"), a 3 x 4
// transform, the section's bounding box (min, max) and its size in voxels
// plus the normals mode. Each (x, y) column of a section is a list of spans:
// skip count, voxel count, that many (colour, normal) pairs, the count again.
//
// Placement: voxel corner v of a section sits at min + v * (max - min) / size
// in the section's frame (the voxels may be anisotropic); the section's
// 3 x 4 matrix (the .hva's for the chosen frame when a .hva with the same
// stem exists, the tailer's otherwise) maps that frame to the model's, its
// translation scaled by det, as the game's renderer does.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "../io/io_util.h"
#include "byte_cursor.h"
#include "voxel_art_formats.h"
#include "voxpress/io/volume_io.h"

namespace voxpress::detail {
namespace {

constexpr size_t kHeader = 802, kSectionHeader = 28, kTailer = 92;

std::string section_name(const std::string& raw) {
  const auto nul = raw.find('\0');
  return trim(nul == std::string::npos ? raw : raw.substr(0, nul));
}

using Matrix34 = std::array<float, 12>;  // row-major 3 x 4

// The .hva beside `path` (same stem, .hva or .HVA), frame `frame`: section
// name -> matrix. Empty when there is no .hva.
std::vector<std::pair<std::string, Matrix34>> read_hva(const std::string& vxl_path, int64_t frame,
                                                       std::vector<std::string>& notes) {
  std::filesystem::path p(vxl_path);
  std::string hva;
  for (const char* ext : {".hva", ".HVA", ".Hva"}) {
    auto q = p;
    q.replace_extension(ext);
    if (std::filesystem::is_regular_file(q)) {
      hva = q.string();
      break;
    }
  }
  if (hva.empty()) {
    notes.push_back("no .hva beside the file: sections placed by their own transforms");
    return {};
  }
  const uint64_t fs = file_size(hva);
  if (fs > (64u << 20)) throw InputError(hva, "file is too large for an .hva (" + std::to_string(fs) + " bytes)");
  const auto data = read_range(hva, 0, fs);
  ByteCursor c(hva, data, 0, data.size());
  c.skip(16, "header");
  const uint32_t frames = c.u32("header"), sections = c.u32("header");
  if (frames == 0 || sections == 0 || sections > 4096) throw InputError(hva, "header declares " + std::to_string(frames) +
                                                                          " frames of " + std::to_string(sections) + " sections");
  if (uint64_t(sections) * 16 + uint64_t(frames) * sections * 48 > c.left())
    throw InputError(hva, "truncated: " + std::to_string(frames) + " frames x " + std::to_string(sections) +
                              " sections do not fit in " + std::to_string(fs) + " bytes");
  if (frame < 0 || uint64_t(frame) >= frames)
    throw UsageError(hva + ": --frame " + std::to_string(frame) + " but the animation has " + std::to_string(frames) + " frame(s)");
  std::vector<std::pair<std::string, Matrix34>> out(sections);
  for (auto& s : out) s.first = section_name(c.text(16, "section names"));
  c.skip(size_t(frame) * sections * 48, "frames");
  for (auto& s : out)
    for (float& v : s.second) {
      v = c.f32("frame matrices");
      // A NaN reached the atlas as "a texture chart would exceed 10^9 texels", no file named (issue 73).
      if (!std::isfinite(v))
        throw InputError(hva, "section '" + s.first + "' frame " + std::to_string(frame) + ": the matrix holds " +
                                  format_double(v) + ", not a finite number");
    }
  notes.push_back("placed by " + std::filesystem::path(hva).filename().string() + " frame " + std::to_string(frame) +
                  " of " + std::to_string(frames));
  return out;
}

}  // namespace

VoxelArt read_vxl(const std::string& path, const VoxelArtReadOptions& options) {
  const uint64_t cap = options.max_bytes ? options.max_bytes : default_memory_limit();
  const auto data = read_whole_file(path, cap, "reading the .vxl file");
  const uint64_t fs = data.size();
  ByteCursor c(path, data, 0, data.size());
  if (data.size() < 16 || c.text(15, "header") != "Voxel Animation")
    throw InputError(path, "not a Westwood voxel file (no 'Voxel Animation' magic)");
  c.seek(16, "header");
  c.u32("header");  // palette count
  const uint32_t n = c.u32("header"), n_tailers = c.u32("header"), body_size = c.u32("header");
  if (n == 0 || n != n_tailers || n > 4096)
    throw InputError(path, "header declares " + std::to_string(n) + " sections and " + std::to_string(n_tailers) + " tailers");
  c.skip(2, "header");  // remap range
  std::array<std::array<uint8_t, 3>, 256> palette;
  for (auto& col : palette)
    for (auto& b : col) b = c.u8("palette");
  const uint64_t body = kHeader + uint64_t(n) * kSectionHeader, tailers = body + body_size;
  if (tailers + uint64_t(n) * kTailer > fs)
    throw InputError(path, "truncated: " + std::to_string(n) + " sections and a " + std::to_string(body_size) +
                               "-byte body need " + std::to_string(tailers + uint64_t(n) * kTailer) + " bytes, the file has " +
                               std::to_string(fs));
  VoxelArt art;
  art.source = path;
  art.format = "vxl";
  art.notes.push_back(std::to_string(n) + " section(s)");
  const auto hva = read_hva(path, options.frame, art.notes);
  uint64_t total_cells = 0;
  for (uint32_t s = 0; s < n; ++s) {
    ByteCursor h(path, data, kHeader + s * kSectionHeader, kHeader + (s + 1) * kSectionHeader);
    const std::string name = section_name(h.text(16, "section header"));
    ByteCursor t(path, data, tailers + s * kTailer, tailers + (s + 1) * kTailer);
    const uint32_t start_off = t.u32("section tailer"), end_off = t.u32("section tailer"), data_off = t.u32("section tailer");
    const float det = t.f32("section tailer");
    Matrix34 m;
    for (float& v : m) v = t.f32("section tailer");
    Vec3 lo, hi;
    for (int a = 0; a < 3; ++a) lo[a] = t.f32("section tailer");
    for (int a = 0; a < 3; ++a) hi[a] = t.f32("section tailer");
    ColorGrid g;
    for (auto& d : g.dims) d = t.u8("section tailer");
    g.name = name;
    const std::string where = "section '" + name + "'";
    if (g.dims[0] == 0 || g.dims[1] == 0 || g.dims[2] == 0) throw InputError(path, where + " has size zero");
    const uint64_t columns = uint64_t(g.dims[0]) * uint64_t(g.dims[1]);
    for (uint32_t off : {start_off, end_off})
      if (uint64_t(off) + columns * 4 > body_size) throw InputError(path, where + ": span table lies outside the body");
    if (data_off > body_size) throw InputError(path, where + ": span data lies outside the body");
    if (!std::isfinite(det) || !lo.allFinite() || !hi.allFinite() ||
        !std::all_of(m.begin(), m.end(), [](float v) { return std::isfinite(v); }))
      throw InputError(path, where + ": transform or bounds are not finite");
    const uint64_t cells = uint64_t(g.dims[0]) * uint64_t(g.dims[1]) * uint64_t(g.dims[2]);
    total_cells += cells;
    check_limit(path, total_cells * kVoxartBytesPerCell, cap, "the voxel grids (" + std::to_string(kVoxartBytesPerCell) + " bytes per cell)");
    g.voxels.assign(cells, Rgba{0, 0, 0, 0});
    ByteCursor starts(path, data, body + start_off, body + start_off + columns * 4);
    ByteCursor ends(path, data, body + end_off, body + end_off + columns * 4);
    for (uint64_t col = 0; col < columns; ++col) {
      const uint32_t a = starts.u32("span table"), b = ends.u32("span table");
      if (a == 0xffffffffu) continue;  // empty column
      if (b == 0xffffffffu || b < a || uint64_t(data_off) + b >= body_size)
        throw InputError(path, where + ": column " + std::to_string(col) + " has a bad span range");
      ByteCursor span(path, data, body + data_off + a, body + data_off + b + 1);
      const int64_t x = int64_t(col % uint64_t(g.dims[0])), y = int64_t(col / uint64_t(g.dims[0]));
      int64_t z = 0;
      while (z < g.dims[2] && span.left() > 0) {
        z += span.u8("span");
        const uint8_t count = span.u8("span");
        if (z + count > g.dims[2]) throw InputError(path, where + ": a span runs past the column height " + std::to_string(g.dims[2]));
        for (uint8_t k = 0; k < count; ++k, ++z) {
          const uint8_t colour = span.u8("span");
          span.u8("span");  // normal index (the mesh computes its own normals)
          const auto& p = palette[colour];
          g.voxels[g.index(x, y, z)] = {p[0], p[1], p[2], 255};
        }
        span.u8("span");  // the count, repeated
      }
    }
    // Place the section.
    const Matrix34* place = &m;
    for (const auto& [hname, hm] : hva)
      if (hname == name) place = &hm;
    if (!hva.empty() && place == &m && s < hva.size()) place = &hva[s].second;  // unnamed: by order
    Mat3 r;
    Vec3 tr;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = (*place)[size_t(4 * i + j)];
      tr[i] = double((*place)[size_t(4 * i + 3)]) * double(det);
    }
    Vec3 step;
    for (int a = 0; a < 3; ++a) {
      step[a] = (hi[a] - lo[a]) / double(g.dims[size_t(a)]);
      if (!(std::abs(step[a]) > 1e-9)) step[a] = 1;  // degenerate bounds: unit voxels
    }
    g.linear = r * step.asDiagonal();
    g.offset = r * lo + tr;
    if (std::abs(g.linear.determinant()) < 1e-12) throw InputError(path, where + ": its transform is singular");
    if (g.count() > 0) art.parts.push_back(std::move(g));
  }
  if (art.parts.empty()) throw InputError(path, "the model is empty (no voxel in any section)");
  return art;
}

}  // namespace voxpress::detail
