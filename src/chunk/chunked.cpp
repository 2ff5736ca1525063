// Chunked Pressing: blocks with a halo, owned sticks and cubes, stitching by
// global stick key. Theory of operation: include/voxpress/chunk/chunked.h.
#include "voxpress/chunk/chunked.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <optional>
#include <queue>
#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>

#include "core/timing.h"
#include "voxpress/core/error.h"
#include "core/parallel.h"
#include "chunk/block.h"

namespace voxpress {

using detail::KeyCodec;
using detail::seconds_since;

namespace {

constexpr int64_t kMinChunk = 8;     // smaller blocks are all halo
constexpr int64_t kMaxHalo = 256;    // samples: the widest halo accepted (27 rounds at 32 already: BENCHMARKS, Chunked)

bool in_core(const Box& core, const std::array<int64_t, 3>& dims, const std::array<int64_t, 3>& g) {
  for (int a = 0; a < 3; ++a) {
    const int64_t c = std::clamp<int64_t>(g[size_t(a)], 0, dims[size_t(a)] - 1);
    if (c < core.lo[size_t(a)] || c >= core.hi[size_t(a)]) return false;
  }
  return true;
}

}  // namespace

ChunkGrid::ChunkGrid(const std::array<int64_t, 3>& d, const ChunkOptions& o) : dims(d), chunk(o.chunk), halo(o.halo) {
  if (chunk < kMinChunk) throw UsageError("--chunk must be at least " + std::to_string(kMinChunk) + " samples");
  if (halo < 0 || halo > kMaxHalo) throw UsageError("the halo must be in [0, " + std::to_string(kMaxHalo) + "] samples");
  for (int a = 0; a < 3; ++a) n_[size_t(a)] = (dims[size_t(a)] + chunk - 1) / chunk;
}

Box ChunkGrid::core(size_t b) const {
  const int64_t idx[3] = {int64_t(b) % n_[0], (int64_t(b) / n_[0]) % n_[1], int64_t(b) / (n_[0] * n_[1])};
  Box box;
  for (int a = 0; a < 3; ++a) {
    box.lo[size_t(a)] = idx[a] * chunk;
    box.hi[size_t(a)] = std::min(dims[size_t(a)], box.lo[size_t(a)] + chunk);
  }
  return box;
}

Box ChunkGrid::with_halo(size_t b) const {
  Box box = core(b);
  const int64_t h = std::max<int64_t>(halo, 1);  // extraction's own reach: the owned cubes' upper samples
  for (int a = 0; a < 3; ++a) {
    box.lo[size_t(a)] = std::max<int64_t>(0, box.lo[size_t(a)] - h);
    box.hi[size_t(a)] = std::min(dims[size_t(a)], box.hi[size_t(a)] + h);
  }
  return box;
}

size_t ChunkGrid::block_of(const std::array<int64_t, 3>& sample) const {
  int64_t idx[3];
  for (int a = 0; a < 3; ++a) idx[a] = std::clamp<int64_t>(sample[size_t(a)], 0, dims[size_t(a)] - 1) / chunk;
  return size_t(idx[0] + n_[0] * (idx[1] + n_[1] * idx[2]));
}

void VolumeSummary::add(const BinaryVolume& v, const Box& where) {
  const auto& d = v.lattice.dims;
  samples += v.lattice.size();
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j) {
      const uint8_t* row = v.inside.data() + v.lattice.linear(0, j, k);
      int64_t first = -1, last = -1, n = 0;
      for (int64_t i = 0; i < d[0]; ++i)
        if (row[i]) {
          if (first < 0) first = i;
          last = i;
          ++n;
        }
      if (n == 0) continue;
      inside += uint64_t(n);
      const int64_t lo[3] = {where.lo[0] + first, where.lo[1] + j, where.lo[2] + k};
      const int64_t hi[3] = {where.lo[0] + last + 1, lo[1] + 1, lo[2] + 1};
      for (int a = 0; a < 3; ++a) {
        bounds.lo[size_t(a)] = std::min(bounds.lo[size_t(a)], lo[a]);
        bounds.hi[size_t(a)] = std::max(bounds.hi[size_t(a)], hi[a]);
      }
    }
}

void VolumeSummary::merge(const VolumeSummary& o) {
  inside += o.inside;
  samples += o.samples;
  for (size_t a = 0; a < 3; ++a) {
    bounds.lo[a] = std::min(bounds.lo[a], o.bounds.lo[a]);
    bounds.hi[a] = std::max(bounds.hi[a], o.bounds.hi[a]);
  }
}

BinaryVolume crop(const BinaryVolume& v, const Box& box) {
  BinaryVolume out;
  out.lattice = box_lattice(v.lattice, box);
  out.source = v.source;
  out.inside.resize(box.size());
  const int64_t nx = box.hi[0] - box.lo[0];
  uint8_t* dst = out.inside.data();
  for (int64_t k = box.lo[2]; k < box.hi[2]; ++k)
    for (int64_t j = box.lo[1]; j < box.hi[1]; ++j, dst += nx)
      std::copy_n(v.inside.data() + v.lattice.linear(box.lo[0], j, k), nx, dst);
  return out;
}

SurfaceOptions chunk_surface_options(const SurfaceOptions& options, const VolumeSummary& summary) {
  SurfaceOptions o = options;
  o.passes.disable(Pass::flats);
  o.progress = nullptr;
  o.press.progress = nullptr;
  o.extract.progress = nullptr;
  // press_levels measures the box of the sticks' lower samples: the inside
  // box grown by one below, so one more than the inside box's longest side.
  int64_t extent = 0;
  for (size_t a = 0; a < 3; ++a) extent = std::max(extent, summary.bounds.hi[a] - summary.bounds.lo[a] + 1);
  o.press.levels = press_levels_for_extent(options.press.levels, extent);
  return o;
}

detail::BlockSticks detail::block_sticks(const BinaryVolume& block, const ChunkGrid& grid, size_t b,
                                         const ExtractOptions& eo) {
  const Box read = grid.with_halo(b);
  const auto& dims = grid.dims;
  if (block.lattice.dims != read.dims() || block.inside.size() != read.size())
    throw UsageError("press_block: the samples do not match block " + std::to_string(b) + "'s box with its halo");
  BlockSticks out;
  out.offset = read.lo;
  const uint64_t inside = block.count_inside();
  if (inside == 0) return out;
  bool touches_border = false;
  for (size_t a = 0; a < 3; ++a) touches_border |= read.lo[a] == 0 || read.hi[a] == dims[a];
  if (inside == block.lattice.size() && !touches_border) return out;  // its only sticks are the read box's faces
  out.s = extract_sticks(block, eo);
  const Box core = grid.core(b);
  const size_t n = out.s.stick_count();
  out.key.resize(n);
  out.owned.resize(n);
  detail::parallel_for(n, [&](size_t id) {
    auto l = out.s.lower_index(id);
    for (size_t a = 0; a < 3; ++a) l[a] += read.lo[a];
    out.owned[id] = in_core(core, dims, l);
    for (int64_t& x : l) x += 1;
    out.key[id] = stick_key(dims, l, out.s.axis(id));
  });
  return out;
}

SurfacePiece detail::owned_piece(const BlockSticks& bs, const ChunkGrid& grid, size_t b, bool triangles,
                                 const std::vector<double>* t) {
  SurfacePiece out;
  out.block = b;
  out.blocks = grid.count();
  const StickSurface& s = bs.s;
  const std::vector<double>& ts = t ? *t : s.t;
  for (size_t id = 0; id < s.stick_count(); ++id)
    if (bs.owned[id]) {
      out.sticks.push_back(bs.key[id]);
      out.code.push_back(s.code[id]);
      out.t.push_back(ts[id]);
    }
  if (!triangles) return out;
  // A triangle's cube is the componentwise minimum of its three sticks' lower
  // samples (no cube case has a triangle on one face: tests/chunk).
  const Box core = grid.core(b);
  for (const Triangle& tri : s.triangles) {
    std::array<int64_t, 3> corner{INT64_MAX, INT64_MAX, INT64_MAX};
    for (uint32_t v : tri) {
      const auto l = s.lower_index(v);
      for (size_t a = 0; a < 3; ++a) corner[a] = std::min(corner[a], l[a] + bs.offset[a]);
    }
    if (!in_core(core, grid.dims, corner)) continue;
    for (uint32_t v : tri) out.triangles.push_back(bs.key[v]);
  }
  return out;
}

SurfacePiece press_block(const BinaryVolume& block, const ChunkGrid& grid, size_t b) {
  const detail::BlockSticks bs = detail::block_sticks(block, grid, b, ExtractOptions{});
  return detail::owned_piece(bs, grid, b, true);
}

namespace {

// A triangle's cube (padded linear index of its lower corner): the
// componentwise minimum of its sticks' lower samples, the order key of the
// whole run's triangles.
uint64_t cube_of(const KeyCodec& codec, const uint64_t* tri) {
  uint64_t c[3] = {UINT64_MAX, UINT64_MAX, UINT64_MAX};
  for (int v = 0; v < 3; ++v) {
    const auto d = codec.decode(tri[v]);
    for (int a = 0; a < 3; ++a) c[a] = std::min(c[a], d[size_t(a)]);
  }
  return c[0] + codec.px * (c[1] + codec.py * c[2]);
}

}  // namespace

SurfacePiece merge_pieces(const std::vector<SurfacePiece>& pieces, const std::array<int64_t, 3>& dims) {
  if (pieces.empty()) throw UsageError("merge_pieces: no piece");
  for (size_t i = 1; i < pieces.size(); ++i)
    if (pieces[i].blocks != pieces[0].blocks || pieces[i].block != pieces[i - 1].block + pieces[i - 1].count)
      throw UsageError("merge_pieces: the pieces are not consecutive blocks of one grid");
  if (pieces.back().block + pieces.back().count > pieces[0].blocks)
    throw UsageError("merge_pieces: the pieces are not consecutive blocks of one grid");
  const KeyCodec codec(dims);
  SurfacePiece out;
  out.block = pieces[0].block;
  out.blocks = pieces[0].blocks;
  out.count = 0;
  size_t n = 0, m = 0;
  for (const SurfacePiece& p : pieces) {
    out.count += p.count;
    n += p.sticks.size();
    m += p.triangles.size();
    if (p.press.iterations > out.press.iterations) out.press = p.press;
  }
  // k-way merges by key (sticks) and by cube (triangles: a cube's triangles
  // all come from one block, so each piece's order within a cube is kept).
  using Head = std::pair<uint64_t, size_t>;  // (key, piece)
  std::priority_queue<Head, std::vector<Head>, std::greater<>> heap;
  std::vector<size_t> at(pieces.size(), 0);
  out.sticks.reserve(n);
  out.code.reserve(n);
  out.t.reserve(n);
  for (size_t p = 0; p < pieces.size(); ++p)
    if (!pieces[p].sticks.empty()) heap.push({pieces[p].sticks[0], p});
  while (!heap.empty()) {
    const auto [key, p] = heap.top();
    heap.pop();
    const size_t i = at[p]++;
    out.sticks.push_back(key);
    out.code.push_back(pieces[p].code[i]);
    out.t.push_back(pieces[p].t[i]);
    if (at[p] < pieces[p].sticks.size()) heap.push({pieces[p].sticks[at[p]], p});
  }
  out.triangles.reserve(m);
  std::fill(at.begin(), at.end(), 0);
  for (size_t p = 0; p < pieces.size(); ++p)
    if (!pieces[p].triangles.empty()) heap.push({cube_of(codec, pieces[p].triangles.data()), p});
  while (!heap.empty()) {
    const size_t p = heap.top().second;
    heap.pop();
    const uint64_t* t = pieces[p].triangles.data() + at[p];
    out.triangles.insert(out.triangles.end(), t, t + 3);
    at[p] += 3;
    if (at[p] < pieces[p].triangles.size()) heap.push({cube_of(codec, pieces[p].triangles.data() + at[p]), p});
  }
  return out;
}

StickSurface stitch(const Lattice& lattice, const std::vector<SurfacePiece>& pieces) {
  const auto& dims = lattice.dims;
  const KeyCodec codec(dims);
  StickSurface out;
  out.lattice = lattice;
  out.padded = {dims[0] + 2, dims[1] + 2, dims[2] + 2};

  std::vector<uint8_t> seen(pieces.empty() ? 0 : pieces[0].blocks, 0);
  size_t covered = 0;
  for (const SurfacePiece& p : pieces) {
    if (p.blocks != seen.size() || p.count < 1 || p.block >= seen.size() || p.count > seen.size() - p.block)
      throw UsageError("stitch: the pieces are not each block of one grid exactly once");
    for (uint64_t b = p.block; b < p.block + p.count; ++b)
      if (seen[b]++) throw UsageError("stitch: the pieces are not each block of one grid exactly once");
    covered += p.count;
  }
  if (covered != seen.size()) throw UsageError("stitch: " + std::to_string(seen.size() - covered) + " of the grid's " +
                                               std::to_string(seen.size()) + " blocks are missing");

  // Sticks: (key, piece, index) sorted by key; keys are unique.
  size_t n = 0, m = 0;
  for (const SurfacePiece& p : pieces) n += p.sticks.size(), m += p.triangles.size() / 3;
  if (n >= UINT32_MAX) throw LimitError("", std::to_string(n) + " sticks exceed the 2^32 - 1 vertex limit of one mesh");
  struct Ref {
    uint64_t key;
    uint32_t piece, index;
    bool operator<(const Ref& o) const { return key < o.key; }
  };
  std::vector<Ref> refs;
  refs.reserve(n);
  for (size_t p = 0; p < pieces.size(); ++p)
    for (size_t i = 0; i < pieces[p].sticks.size(); ++i) refs.push_back({pieces[p].sticks[i], uint32_t(p), uint32_t(i)});
  tbb::parallel_sort(refs.begin(), refs.end());
  for (size_t i = 1; i < refs.size(); ++i)
    if (refs[i].key == refs[i - 1].key) throw std::logic_error("stitch: a stick is owned by two pieces");
  out.lower.resize(n);
  out.code.resize(n);
  out.t.resize(n);
  std::vector<uint64_t> keys(n);
  detail::parallel_ranges(n, 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const Ref& ref = refs[i];
      const auto d = codec.decode(ref.key);
      keys[i] = ref.key;
      out.lower[i] = d[0] + codec.px * (d[1] + codec.py * d[2]);
      out.code[i] = pieces[ref.piece].code[ref.index];
      out.t[i] = pieces[ref.piece].t[ref.index];
    }
  });
  refs = {};

  // Triangles in whole-run order: by cube (padded lower corner, z, y, x
  // outer to inner), then in the cube's own order. A cube's triangles all
  // come from one piece, consecutive, so (cube, position in the
  // concatenation) is a strict total order.
  struct Tri {
    uint64_t cube, at;
    bool operator<(const Tri& o) const { return cube != o.cube ? cube < o.cube : at < o.at; }
  };
  std::vector<Tri> order(m);
  std::vector<const uint64_t*> first(m);
  {
    size_t w = 0;
    for (const SurfacePiece& p : pieces)
      for (size_t i = 0; i + 2 < p.triangles.size(); i += 3, ++w) first[w] = p.triangles.data() + i;
  }
  detail::parallel_ranges(m, 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i) order[i] = {cube_of(codec, first[i]), i};
  });
  tbb::parallel_sort(order.begin(), order.end());
  out.triangles.resize(m);
  std::atomic<bool> missing{false};
  detail::parallel_ranges(m, 1 << 14, [&](detail::IndexRange r) {
    for (size_t i = r.begin(); i < r.end(); ++i)
      for (int v = 0; v < 3; ++v) {
        const uint64_t key = first[order[i].at][v];
        const auto it = std::lower_bound(keys.begin(), keys.end(), key);
        if (it == keys.end() || *it != key) {
          missing = true;
          continue;
        }
        out.triangles[i][size_t(v)] = uint32_t(it - keys.begin());
      }
  });
  if (missing) throw std::logic_error("stitch: a triangle names a stick no piece owns");
  return out;
}

namespace {

// The halo mode (press_rounds): every block runs each round from the state
// the last one left, then its final step. The whole run stops at the first
// sweep of the last stage whose residual (max over all sticks) is within
// the tolerance, before applying it: the round holding that sweep is run
// again up to it. Returns the whole run's PressStats (iterations, residual).
template <class BlockOf>
PressStats press_in_rounds(const Lattice& lattice, const ChunkGrid& grid, const SurfaceOptions& so, BlockOf block_of,
                           std::vector<SurfacePiece>& pieces, Progress* progress_sink, int& round_count) {
  // One block has no artificial border (its box is the volume's): one round.
  const std::vector<PressRound> rounds = press_rounds(lattice, so, grid.count() == 1 ? INT32_MAX : grid.halo);
  const size_t nb = grid.count();
  ProgressCounter progress(progress_sink, "rounds", uint64_t((rounds.size() + 2) * nb));
  PressStats st;
  st.levels = so.press.levels;
  PressOptions po = so.press;  // the tolerance as the blocks run it (the overrides applied)
  so.overrides.apply(po);
  // Each block read and extracted once (as a Dask worker keeps it), while
  // the kept blocks fit in half the memory cap (the rest: the stitched
  // surface); a block beyond it is read and extracted again every round.
  // The same bytes either way.
  std::vector<std::optional<BlockRounds>> blocks(nb);
  const uint64_t budget = so.extract.max_bytes ? so.extract.max_bytes / 2 : UINT64_MAX;
  std::atomic<uint64_t> kept{0};
  const auto each_block = [&](auto&& f) {
    detail::parallel_ranges(nb, 1, [&](detail::IndexRange range) {
      for (size_t b = range.begin(); b < range.end(); ++b) {
        f(b);
        progress.add(1);
      }
    });
  };
  each_block([&](size_t b) {
    BlockRounds block(block_of(b), grid, b, so);
    const uint64_t bytes = block.bytes();
    if (kept.fetch_add(bytes) + bytes <= budget)
      blocks[b].emplace(std::move(block));
    else
      kept.fetch_sub(bytes);
  });
  const auto with_block = [&](size_t b, auto&& f) {
    if (blocks[b]) return f(*blocks[b]);
    return f(BlockRounds(block_of(b), grid, b, so));  // not kept: read for this call
  };
  const auto run_round = [&](const PressRound& r, const PressState& state) {
    each_block([&](size_t b) { pieces[b] = with_block(b, [&](const BlockRounds& k) { return k.round(r, state); }); });
  };
  std::vector<SurfacePiece> last(nb);  // the pieces the state views (pieces: the round's, swapped)
  PressState state;
  bool stopped = false, any = false;
  round_count = 0;
  for (const PressRound& r : rounds) {
    run_round(r, state);
    ++round_count;
    // The whole run's residual per sweep: the max over the blocks (NaN before the last stage).
    int stop = -1;
    for (int k = 0; k < r.last - r.first && stop < 0; ++k) {
      double res = std::nan("");
      for (const SurfacePiece& p : pieces)
        if (size_t(k) < p.residuals.size() && !std::isnan(p.residuals[size_t(k)]))
          res = std::isnan(res) ? p.residuals[size_t(k)] : std::max(res, p.residuals[size_t(k)]);
      if (std::isnan(res)) continue;
      st.residual = res;
      st.least_residual = any ? std::min(st.least_residual, res) : res;
      any = true;
      if (res <= po.tolerance) stop = r.first + k;
    }
    if (stop >= 0) {  // the whole run stops before sweep `stop`: this round again, up to it
      if (stop > r.first) run_round({r.first, stop}, state), ++round_count;
      st.iterations = stop;
      stopped = true;
    } else {
      st.iterations = r.last;
    }
    if (!stopped || st.iterations > r.first) {  // stopped at the round's start: the state before it
      std::swap(last, pieces);
      state = press_state(last);
    }
    if (stopped) break;
  }
  each_block([&](size_t b) { pieces[b] = with_block(b, [&](const BlockRounds& k) { return k.finish(state, !stopped); }); });
  if (!stopped) {  // the cap ended it: the residual at the final t
    double res = 0;
    for (const SurfacePiece& p : pieces)
      if (!p.residuals.empty()) res = std::max(res, p.residuals[0]);
    st.residual = res;
    st.least_residual = any ? std::min(st.least_residual, res) : res;
  }
  return st;
}

}  // namespace

SurfaceResult press_chunked(const Lattice& lattice, const std::string& source, const BlockReader& read,
                            const SurfaceOptions& options, const ChunkOptions& chunks, ChunkedStats* stats) {
  const bool exact = chunks.halo == 0;
  if (!exact && options.method != Method::pressing)
    throw UsageError("blocks pressed on their own (a halo) run --method pressing only");
  validate(options);
  require_float32_room(lattice, options, source);
  const ChunkGrid grid(lattice.dims, chunks);
  ChunkedStats st;
  st.blocks = grid.count();

  auto t0 = std::chrono::steady_clock::now();
  VolumeSummary summary;
  {
    std::mutex mu;
    ProgressCounter progress(options.progress, "summary", grid.count());
    detail::parallel_ranges(grid.count(), 1, [&](detail::IndexRange r) {
      for (size_t b = r.begin(); b < r.end(); ++b) {
        const Box core = grid.core(b);
        VolumeSummary part;
        part.add(read(core), core);
        std::lock_guard lock(mu);
        summary.merge(part);  // sums and min / max: order-independent
        progress.add(1);
      }
    });
  }
  if (summary.inside == 0)
    throw InputError(source, "the volume is empty: no sample is inside (check --label / --threshold)");
  if (summary.inside == lattice.size())
    throw InputError(source, "the volume is full: every sample is inside, so the only surface is the grid's bounding "
                             "box (check --label / --threshold)");
  st.inside = summary.inside;
  st.seconds_summary = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  const SurfaceOptions so = chunk_surface_options(options, summary);
  const auto block_of = [&](size_t b) {
    const Box box = grid.with_halo(b);
    BinaryVolume block = read(box);
    if (block.lattice.dims != box.dims() || block.inside.size() != box.size())
      throw std::logic_error("press_chunked: the reader returned the wrong box");
    block.lattice = box_lattice(lattice, box);
    block.source = source;
    return block;
  };
  std::vector<SurfacePiece> pieces(grid.count());
  PressStats pressed;
  if (exact) {
    ProgressCounter progress(options.progress, "blocks", grid.count());
    detail::parallel_ranges(grid.count(), 1, [&](detail::IndexRange r) {
      for (size_t b = r.begin(); b < r.end(); ++b) {
        pieces[b] = press_block(block_of(b), grid, b);
        progress.add(1);
      }
    });
  } else {
    st.levels = so.press.levels;
    pressed = press_in_rounds(lattice, grid, so, block_of, pieces, options.progress, st.rounds);
  }
  for (const SurfacePiece& p : pieces) st.pressed += !p.sticks.empty();
  st.max_iterations = pressed.iterations;
  st.seconds_blocks = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  StickSurface surface = stitch(lattice, pieces);
  pieces = {};
  st.sticks = surface.stick_count();
  st.triangles = surface.triangles.size();
  st.seconds_stitch = seconds_since(t0);
  SurfaceResult r;
  r.extract.samples = lattice.size();
  r.extract.sticks = st.sticks;
  r.extract.triangles = st.triangles;
  r.seconds_extract = st.seconds_summary + st.seconds_blocks + st.seconds_stitch;
  if (exact) {
    // The cap smooth_surface's extraction checks, for the stitched surface
    // and its smoothing (the volume itself is never held).
    const uint64_t need = st.sticks * (17 + 2 * 12 + bytes_per_stick(options)), cap = options.extract.max_bytes;
    if (cap && need > cap)
      throw LimitError(source, "smoothing the stitched surface of " + std::to_string(st.sticks) + " sticks needs about " +
                                   std::to_string(need >> 20) + " MiB, above the memory limit of " +
                                   std::to_string(cap >> 20) + " MiB");
    // The whole volume's sticks, exactly: the rest of smooth_surface on them.
    r = smooth_sticks(std::move(surface), options, std::move(r));
    st.levels = r.press.levels;
    st.max_iterations = r.press.iterations;
  } else {
    r.mesh = to_mesh(surface);
    r.press = pressed;
    simplify_result(lattice, options, r);
  }
  if (stats) *stats = st;
  return r;
}

}  // namespace voxpress
