// Stick surface extraction: the midpoint marching-cubes surface on sticks.
//
// Theory of operation (count, prefix-sum, fill — after VTK's Flying Edges):
//   Index space is padded by one outside sample on every side; a padded
//   sample row (q, r) holds samples p = 0 .. nx+1 (p = i + 1).
//   Pass 1  (rows, parallel): for each padded sample row count its x-sticks
//           (p, p+1), y-sticks (row q+1) and z-sticks (row r+1), and record
//           the first/last position holding a stick (trimming).
//   Scan    exclusive prefix sum of the counts -> each row's first stick id.
//           Stick ids are thus ordered by (r, q, axis, p).
//   Pass 2  (rows, parallel): each row writes its sticks into its own range.
//   Pass 3  (cell rows, parallel): a cell row (q, r) touches the four sample
//           rows (q..q+1, r..r+1); skip it when none of its 12 edge sets holds
//           a stick, else count the triangles of each cell's case.
//   Scan    prefix sum of triangle counts per cell row.
//   Pass 4  (cell rows, parallel): walk the cells again with one running
//           "next stick id" per (row, axis) — the id of every edge follows
//           from the counts without any lookup table or hashing — and write
//           the triangles into the row's range.
// No locks, no welding, no reallocation; the output bytes do not depend on
// the number of threads.
#include "voxpress/extract/sticks.h"

#include "extract/stick_box.h"


#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>

#include "core/timing.h"
#include "voxpress/core/error.h"
#include "voxpress/core/memory_budget.h"
#include "voxpress/extract/cube_cases.h"
#include "core/parallel.h"

namespace voxpress {

using detail::seconds_since;

namespace {

struct RowInfo {
  uint32_t count[3] = {0, 0, 0};  // x, y, z sticks of the row
  int64_t first = std::numeric_limits<int64_t>::max();  // padded position of the first stick
  int64_t last = -1;                                    // ... and of the last
  uint64_t offset = 0;            // id of the row's first stick
};

class Padded {
 public:
  explicit Padded(const BinaryVolume& v)
      : data_(v.inside.data()), nx_(v.lattice.dims[0]), ny_(v.lattice.dims[1]), nz_(v.lattice.dims[2]) {}
  int64_t nx() const { return nx_; }
  int64_t rows_y() const { return ny_ + 2; }
  int64_t rows_z() const { return nz_ + 2; }
  /// Unpadded row data for padded row (q, r), or nullptr for an outside row.
  const uint8_t* row(int64_t q, int64_t r) const {
    if (q < 1 || r < 1 || q > ny_ || r > nz_) return nullptr;
    return data_ + size_t(nx_) * (size_t(q - 1) + size_t(ny_) * size_t(r - 1));
  }
  /// Value at padded position p of a row (0 outside).
  uint8_t at(const uint8_t* row, int64_t p) const { return (row && p >= 1 && p <= nx_) ? row[p - 1] : 0; }

 private:
  const uint8_t* data_;
  int64_t nx_, ny_, nz_;
};

// Number of differing positions between two rows of length n (null = zeros).
uint32_t count_diff(const uint8_t* a, const uint8_t* b, int64_t n) {
  uint32_t c = 0;
  if (a && b) {
    for (int64_t i = 0; i < n; ++i) c += uint32_t(a[i] ^ b[i]);
  } else if (a || b) {
    const uint8_t* x = a ? a : b;
    for (int64_t i = 0; i < n; ++i) c += x[i];
  }
  return c;
}

uint32_t count_x(const uint8_t* a, int64_t n) {
  if (!a) return 0;
  uint32_t c = uint32_t(a[0]) + uint32_t(a[n - 1]);
  for (int64_t i = 0; i + 1 < n; ++i) c += uint32_t(a[i] ^ a[i + 1]);
  return c;
}

void row_pass(const Padded& pv, int64_t q, int64_t r, RowInfo& info) {
  const int64_t nx = pv.nx();
  const uint8_t* a = pv.row(q, r);
  const uint8_t* b = q + 1 < pv.rows_y() ? pv.row(q + 1, r) : nullptr;
  const uint8_t* c = r + 1 < pv.rows_z() ? pv.row(q, r + 1) : nullptr;
  info.count[0] = count_x(a, nx);
  info.count[1] = count_diff(a, b, nx);
  info.count[2] = count_diff(a, c, nx);
  if (info.count[0] + info.count[1] + info.count[2] == 0) return;
  auto has_stick = [&](int64_t p) {  // any stick starting at padded position p
    const uint8_t v = pv.at(a, p);
    return v != pv.at(a, p + 1) || v != pv.at(b, p) || v != pv.at(c, p);
  };
  int64_t p = 0;
  while (!has_stick(p)) ++p;
  info.first = p;
  p = nx;
  while (!has_stick(p)) --p;
  info.last = p;
}

template <class F>
void parallel_rows(int64_t rows, F&& f) {
  detail::parallel_ranges(size_t(rows), 16, [&](detail::IndexRange range) {
    for (size_t row = range.begin(); row < range.end(); ++row) f(int64_t(row));
  });
}

std::vector<RowInfo> classify_rows(const Padded& pv, ProgressCounter* progress) {
  const int64_t rows = pv.rows_y() * pv.rows_z();
  std::vector<RowInfo> info(static_cast<size_t>(rows));
  detail::parallel_for(int64_t(0), pv.rows_z(), [&](int64_t r) {
    for (int64_t q = 0; q < pv.rows_y(); ++q) row_pass(pv, q, r, info[size_t(r * pv.rows_y() + q)]);
    if (progress) progress->add(1);
  });
  return info;
}

}  // namespace

std::array<int64_t, 3> StickSurface::lower_index(size_t s) const {
  const uint64_t l = lower[s];
  const uint64_t px = uint64_t(padded[0]), py = uint64_t(padded[1]);
  return {int64_t(l % px) - 1, int64_t((l / px) % py) - 1, int64_t(l / (px * py)) - 1};
}

namespace {

// The sticks re-indexed on lattice `to`, whose sample 0 is their sample
// `at` (same sticks, order and t; only the index frame moves).
StickSurface moved_to(StickSurface s, const Lattice& to, const std::array<int64_t, 3>& at) {
  const uint64_t ox = uint64_t(s.padded[0]), oy = uint64_t(s.padded[1]);
  s.lattice = to;
  for (size_t a = 0; a < 3; ++a) s.padded[a] = to.dims[a] + 2;
  const uint64_t px = uint64_t(s.padded[0]), py = uint64_t(s.padded[1]);
  detail::parallel_for(s.stick_count(), [&](size_t i) {
    const uint64_t l = s.lower[i];
    const uint64_t x = uint64_t(int64_t(l % ox) - at[0]), y = uint64_t(int64_t((l / ox) % oy) - at[1]),
                   z = uint64_t(int64_t(l / (ox * oy)) - at[2]);
    s.lower[i] = x + px * (y + py * z);
  });
  return s;
}

}  // namespace

StickSurface on_own_box(StickSurface s, OwnBox* frame) {
  const size_t n = s.stick_count();
  if (frame) *frame = {s.lattice, {0, 0, 0}};
  if (n == 0) return s;
  const detail::IndexBox<3> box = detail::stick_box<3>(n, [&](size_t i) { return s.lower_index(i); });
  Lattice own = s.lattice;
  own.origin = s.lattice.to_physical(Vec3(double(box[0]), double(box[1]), double(box[2])));
  for (size_t a = 0; a < 3; ++a) own.dims[a] = box[a + 3] + 2 - box[a];  // a stick's upper sample lies one past its lower one
  if (frame) frame->lo = {box[0], box[1], box[2]};
  return moved_to(std::move(s), own, {box[0], box[1], box[2]});
}

StickSurface off_own_box(StickSurface s, const OwnBox& frame) {
  return moved_to(std::move(s), frame.lattice, {-frame.lo[0], -frame.lo[1], -frame.lo[2]});
}

Vec3 StickSurface::index_position(size_t s) const {
  const auto i = lower_index(s);
  Vec3 p{double(i[0]), double(i[1]), double(i[2])};
  p[axis(s)] += t[s];
  return p;
}

std::array<Vec3, 2> StickSurface::sample_points(size_t s) const {
  const auto i = lower_index(s);
  const Vec3 a{double(i[0]), double(i[1]), double(i[2])};
  Vec3 b = a;
  b[axis(s)] += 1;
  return {a, b};
}

uint64_t stick_key(const std::array<int64_t, 3>& dims, const std::array<int64_t, 3>& pl, int axis) {
  const uint64_t px = uint64_t(dims[0] + 2), py = uint64_t(dims[1] + 2);
  return ((uint64_t(pl[2]) * py + uint64_t(pl[1])) * 3 + uint64_t(axis)) * px + uint64_t(pl[0]);
}

namespace {

// Scan: each row's first stick id; the total.
uint64_t number_sticks(std::vector<RowInfo>& info) {
  uint64_t total = 0;
  for (RowInfo& r : info) {
    r.offset = total;
    total += uint64_t(r.count[0]) + r.count[1] + r.count[2];
  }
  return total;
}

// Refuses (LimitError) a surface of `total` sticks that would not fit the
// memory limit, with its figures.
void check_budget(const BinaryVolume& volume, const ExtractOptions& options, uint64_t total) {
  if (total >= std::numeric_limits<uint32_t>::max())
    throw LimitError(volume.source, std::to_string(total) + " sticks exceed the 2^32 - 1 vertex limit of one mesh");
  // Triangles are about twice the vertices (each vertex has ~6 incident
  // triangles, each triangle 3 vertices); 17 bytes per stick, 12 per triangle.
  const uint64_t surface = total * (17 + 2 * 12), later = total * options.later_bytes_per_stick;
  const uint64_t estimate = options.held_bytes + volume.inside.size() + surface + later + kRunBytesFixed;
  if (!options.max_bytes || estimate <= options.max_bytes) return;
  const bool small = options.max_bytes < (16u << 20);  // KiB below 16 MiB, so that no figure reads 0
  auto size = [&](uint64_t b) { return std::to_string(small ? b >> 10 : b >> 20); };
  const std::string unit = small ? " KiB" : " MiB";
  throw LimitError(volume.source, "this needs about " + size(estimate) + unit + " (volume " +
                                      size(volume.inside.size()) + ", surface " + size(surface) + ", its smoothing " +
                                      size(later) + " for " + std::to_string(total) + " sticks, the run " +
                                      size(kRunBytesFixed) +
                                      (options.held_bytes ? ", held before " + size(options.held_bytes) : "") +
                                      "), above the memory limit of " + size(options.max_bytes) + unit);
}

// Pass 2: each row writes its sticks into its own range.
void fill_sticks(const Padded& pv, const std::vector<RowInfo>& info, StickSurface& out) {
  const int64_t ny2 = pv.rows_y(), nz2 = pv.rows_z();
  const uint64_t px = uint64_t(out.padded[0]), py = uint64_t(out.padded[1]);
  parallel_rows(ny2 * nz2, [&](int64_t row) {
    const RowInfo& ri = info[size_t(row)];
    if (ri.last < 0) return;
    const int64_t q = row % ny2, r = row / ny2;
    const uint8_t* a = pv.row(q, r);
    const uint8_t* b = q + 1 < ny2 ? pv.row(q + 1, r) : nullptr;
    const uint8_t* c = r + 1 < nz2 ? pv.row(q, r + 1) : nullptr;
    uint64_t id[3] = {ri.offset, ri.offset + ri.count[0], ri.offset + ri.count[0] + ri.count[1]};
    const uint64_t base = px * (uint64_t(q) + py * uint64_t(r));
    for (int64_t p = ri.first; p <= ri.last; ++p) {
      const uint8_t v = pv.at(a, p);
      const uint8_t nb[3] = {pv.at(a, p + 1), pv.at(b, p), pv.at(c, p)};
      for (int axis = 0; axis < 3; ++axis)
        if (v != nb[axis]) {
          out.lower[id[axis]] = base + uint64_t(p);
          out.code[id[axis]] = uint8_t(axis | (v << 2));
          ++id[axis];
        }
    }
  });
}

struct CellRow {
  int64_t p0 = 0, p1 = -1;  // cell range to visit
  uint64_t offset = 0, count = 0;
};

// The cell rows (q, r) of the padded volume: each touches the four sample
// rows (q..q+1, r..r+1).
class CellRows {
 public:
  CellRows(const Padded& pv, const std::vector<RowInfo>& info) : pv_(pv), info_(info) {}

  // The 12 edge sets of cell row (q, r): x-sticks of the 4 rows, y-sticks of
  // rows (q, r), (q, r+1) and z-sticks of rows (q, r), (q+1, r). False when
  // none holds a stick, else the cell range to visit in cr.
  bool prepare(int64_t q, int64_t r, CellRow& cr) const {
    const RowInfo* R[2][2] = {{&at(q, r), &at(q, r + 1)}, {&at(q + 1, r), &at(q + 1, r + 1)}};
    int64_t first = std::numeric_limits<int64_t>::max(), last = -1;
    uint64_t n = 0;
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) {
        n += R[y][z]->count[0];
        first = std::min(first, R[y][z]->first);
        last = std::max(last, R[y][z]->last);
      }
    n += R[0][0]->count[1] + R[0][1]->count[1] + R[0][0]->count[2] + R[1][0]->count[2];
    if (n == 0) return false;
    cr.p0 = std::max<int64_t>(0, first - 1);
    cr.p1 = std::min<int64_t>(pv_.nx(), last);
    return true;
  }

  // Walks the cells p0..p1 of a cell row. The four sample rows are copied
  // into zero-padded scratch rows, and each x position becomes a nibble
  // col = r00 | r10 << 1 | r01 << 2 | r11 << 3 (bit y + 2 z); a cell's cube
  // case interleaves the nibbles at p and p + 1, and the stick flags the id
  // counters need are XORs of their bits: visit(p, case, col p, col p + 1).
  template <class Visit>
  void walk(int64_t q, int64_t r, const CellRow& cr, Visit&& visit) const {
    thread_local std::vector<uint8_t> scratch;
    const int64_t p0 = cr.p0, p1 = cr.p1, nx = pv_.nx();
    scratch.assign(size_t(p1 - p0 + 2), 0);
    // Plain locals: uint8_t stores may alias anything, so keep loop bounds
    // and pointers out of memory the compiler would have to reload.
    uint8_t* const cols = scratch.data();  // cols[p - p0] for p in [p0, p1 + 1]
    const int64_t a = std::max<int64_t>(p0, 1), b = std::min<int64_t>(p1 + 1, nx);
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z)
        if (const uint8_t* row = pv_.row(q + y, r + z)) {
          const int bit = y + 2 * z;
          for (int64_t p = a; p <= b; ++p) cols[p - p0] = uint8_t(cols[p - p0] | (row[p - 1] << bit));
        }
    auto spread = [](unsigned c) { return (c & 1u) | ((c & 2u) << 1) | ((c & 4u) << 2) | ((c & 8u) << 3); };
    for (int64_t p = p0; p <= p1; ++p) {
      const unsigned c0 = cols[p - p0], c1 = cols[p - p0 + 1];
      visit(p, spread(c0) | (spread(c1) << 1), c0, c1);
    }
  }

  const RowInfo& at(int64_t q, int64_t r) const { return info_[size_t(r * pv_.rows_y() + q)]; }

 private:
  const Padded& pv_;
  const std::vector<RowInfo>& info_;
};

// Pass 3 and its scan: each cell row's triangle count and first triangle;
// the total.
uint64_t count_triangles(const CellRows& rows, int64_t cell_rows_y, int64_t cell_rows_z, std::vector<CellRow>& cells,
                         const ExtractOptions& options) {
  const CubeCase* const table = &cube_case(0);
  ProgressCounter progress(options.progress, "triangles", uint64_t(cell_rows_z));
  detail::parallel_for(int64_t(0), cell_rows_z, [&](int64_t r) {
    for (int64_t q = 0; q < cell_rows_y; ++q) {
      CellRow& cr = cells[size_t(r * cell_rows_y + q)];
      if (!rows.prepare(q, r, cr)) continue;
      rows.walk(q, r, cr, [&](int64_t, unsigned mask, unsigned, unsigned) { cr.count += table[mask].count; });
    }
    progress.add(1);
  });
  uint64_t ntri = 0;
  for (CellRow& cr : cells) {
    cr.offset = ntri;
    ntri += cr.count;
  }
  return ntri;
}

// Pass 4: walk the cells again with one running "next stick id" per (row,
// axis), writing each cell row's triangles into its range.
void fill_triangles(const CellRows& rows, int64_t cell_rows_y, const std::vector<CellRow>& cells, StickSurface& out) {
  const CubeCase* const table = &cube_case(0);
  parallel_rows(int64_t(cells.size()), [&](int64_t idx) {
    const CellRow& cr = cells[size_t(idx)];
    if (cr.count == 0) return;
    const int64_t q = idx % cell_rows_y, r = idx / cell_rows_y;
    const RowInfo* R[2][2] = {{&rows.at(q, r), &rows.at(q, r + 1)}, {&rows.at(q + 1, r), &rows.at(q + 1, r + 1)}};
    // Running id of the next stick at or after position p, per (row, axis):
    // x-sticks of the four rows (index y + 2 z), y-sticks of rows z = 0, 1,
    // z-sticks of rows y = 0, 1.
    uint64_t xn[4], yn[2], zn[2];
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) xn[y + 2 * z] = R[y][z]->offset;
    for (int z = 0; z < 2; ++z) yn[z] = R[0][z]->offset + R[0][z]->count[0];
    for (int y = 0; y < 2; ++y) zn[y] = R[y][0]->offset + R[y][0]->count[0] + R[y][0]->count[1];
    uint64_t w = cr.offset;
    rows.walk(q, r, cr, [&](int64_t, unsigned mask, unsigned c0, unsigned c1) {
      const unsigned xs = c0 ^ c1;                     // bit y + 2 z: x-stick at p in row (y, z)
      const unsigned ys = (c0 ^ (c0 >> 1)) & 0b0101u;  // bit 2 z: y-stick at p in row z
      const unsigned zs = (c0 ^ (c0 >> 2)) & 0b0011u;  // bit y: z-stick at p in row y
      const CubeCase& cc = table[mask];
      for (int k = 0; k < cc.count; ++k) {
        Triangle t;
        for (int v = 0; v < 3; ++v) {
          const int e = cc.triangles[size_t(k)][size_t(v)];
          const int lo = e & 1, hi = (e >> 1) & 1;
          uint64_t id;
          switch (e >> 2) {
            case 0: id = xn[lo + 2 * hi]; break;                          // x edge in row (y = lo, z = hi)
            case 1: id = yn[hi] + (lo ? (ys >> (2 * hi)) & 1u : 0u); break;  // y edge at x = lo, row z = hi
            default: id = zn[hi] + (lo ? (zs >> hi) & 1u : 0u); break;       // z edge at x = lo, row y = hi
          }
          t[size_t(v)] = uint32_t(id);
        }
        out.triangles[w++] = t;
      }
      for (int b = 0; b < 4; ++b) xn[b] += (xs >> b) & 1u;
      yn[0] += ys & 1u;
      yn[1] += (ys >> 2) & 1u;
      zn[0] += zs & 1u;
      zn[1] += (zs >> 1) & 1u;
    });
  });
}

}  // namespace

uint64_t count_sticks(const BinaryVolume& volume) {
  std::vector<RowInfo> info = classify_rows(Padded(volume), nullptr);
  return number_sticks(info);
}

StickSurface extract_sticks(const BinaryVolume& volume, const ExtractOptions& options, ExtractStats* stats) {
  const auto& dims = volume.lattice.dims;
  if (volume.inside.size() != volume.lattice.size())
    throw UsageError("extract_sticks: volume data does not match its lattice");
  const Padded pv(volume);
  StickSurface out;
  out.lattice = volume.lattice;
  out.padded = {dims[0] + 2, dims[1] + 2, dims[2] + 2};

  // ---- Passes 1-2: sticks.
  auto t0 = std::chrono::steady_clock::now();
  std::vector<RowInfo> info;
  {
    ProgressCounter progress(options.progress, "sticks", uint64_t(pv.rows_z()));
    info = classify_rows(pv, options.progress ? &progress : nullptr);
  }
  const uint64_t total = number_sticks(info);
  check_budget(volume, options, total);
  out.lower.resize(total);
  out.code.resize(total);
  out.t.assign(total, 0.5);
  fill_sticks(pv, info, out);
  const double seconds_sticks = seconds_since(t0);

  // ---- Passes 3-4: triangles.
  t0 = std::chrono::steady_clock::now();
  const int64_t cell_rows_y = dims[1] + 1, cell_rows_z = dims[2] + 1;
  const CellRows rows(pv, info);
  std::vector<CellRow> cells(size_t(cell_rows_y * cell_rows_z));
  const uint64_t ntri = count_triangles(rows, cell_rows_y, cell_rows_z, cells, options);
  out.triangles.resize(ntri);
  fill_triangles(rows, cell_rows_y, cells, out);
  if (stats) {
    stats->samples = volume.lattice.size();
    stats->sticks = total;
    stats->triangles = ntri;
    stats->seconds_sticks = seconds_sticks;
    stats->seconds_triangles = seconds_since(t0);
  }
  return out;
}

Mesh to_mesh(const StickSurface& s) {
  Mesh m;
  m.positions.resize(s.stick_count());
  const Mat3 M = s.lattice.index_to_physical_matrix();
  const Vec3 o = s.lattice.origin;
  detail::parallel_ranges(s.stick_count(), 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i) m.positions[i] = o + M * s.index_position(i);
  });
  m.triangles = s.triangles;
  if (s.lattice.flips_orientation())
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

void require_mixed(const BinaryVolume& volume) {
  const uint64_t inside = volume.count_inside();
  if (inside == 0)
    throw InputError(volume.source, "the volume is empty: no sample is inside (check --label / --threshold)");
  if (inside == volume.lattice.size())
    throw InputError(volume.source,
                     "the volume is full: every sample is inside, so the only surface is the grid's bounding box "
                     "(check --label / --threshold)");
}

}  // namespace voxpress
