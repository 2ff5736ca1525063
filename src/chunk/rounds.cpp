// Blocks pressed apart in exchange rounds: the whole run's sweeps, block by
// block. Theory of operation: include/voxpress/chunk/chunked.h.
#include <tbb/parallel_sort.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "chunk/block.h"
#include "core/parallel.h"
#include "smooth/curve_kernel.h"
#include "voxpress/core/error.h"

namespace voxpress {

namespace {

// The pressing options a block runs: the whole run's (BinarySteps in
// smooth/pipeline.cpp does the same for the whole surface).
PressOptions block_press_options(const SurfaceOptions& o) {
  PressOptions po = o.press;
  po.free_ends = po.free_ends && o.passes.on(Pass::free_ends);
  o.overrides.apply(po);
  po.progress = nullptr;
  return po;
}

// Samples that one sweep at `scale` reaches: a vertex moves from the
// positions within twice the arc length d * scale along its curves (d is
// at most the longest physical cell side), plus the two curve segments its
// virtual neighbours are interpolated on (each within a lattice square: at
// most its diagonal); physical lengths become samples through the shortest
// a unit index step can be (the index-to-physical map's smallest singular
// value: the smallest spacing unless the lattice is sheared); one more for
// rounding.
int64_t sweep_reach(const Lattice& lattice, const PressOptions& po, int scale) {
  const Mat3 M = lattice.index_to_physical_matrix();
  const Eigen::SelfAdjointEigenSolver<Mat3> es(M.transpose() * M, Eigen::EigenvaluesOnly);  // singular values squared
  const double smax = std::sqrt(es.eigenvalues().maxCoeff()), smin = std::sqrt(es.eigenvalues().minCoeff());
  const double reach = (2 * scale * po.arc_length * smax + 2 * std::numbers::sqrt2 * smax) / smin;
  return int64_t(std::ceil(reach)) + 1;
}

// The block's sticks placed for pressing: on their own box (as the whole
// run), in the layout's order, with t and momentum from `state` (sticks
// it does not hold, the block's artificial border: the extraction's, at
// rest).
struct BlockPress {
  detail::BlockSticks bs;
  OwnBox frame;
  SliceCurves curves;  // the layout's families point into it
  detail::Layout layout;
  std::vector<double> t, velocity;
  std::vector<uint8_t> owned;  // layout order
  BlockPress(const BinaryVolume& samples, const ChunkGrid& grid, size_t b, const PressState& state)
      : bs(detail::block_sticks(samples, grid, b, ExtractOptions{})) {
    const size_t n = bs.s.stick_count();
    // Where each stick is in the state (SIZE_MAX: not there). A block's
    // sticks are in whole-run key order (the canonical order of a sub-box),
    // so one forward search finds them all.
    std::vector<size_t> at(n, SIZE_MAX);
    const bool sorted = std::is_sorted(bs.key.begin(), bs.key.end());
    auto from = state.sticks.begin();
    for (size_t i = 0; i < n; ++i) {
      from = std::lower_bound(sorted ? from : state.sticks.begin(), state.sticks.end(), bs.key[i]);
      if (from == state.sticks.end() || *from != bs.key[i]) continue;
      at[i] = size_t(from - state.sticks.begin());
      bs.s.t[i] = state.t[at[i]];
    }
    bs.s = on_own_box(std::move(bs.s), &frame);
    curves = build_slice_curves(bs.s);
    detail::make_layout(bs.s, curves, layout);
    t.resize(n);
    velocity.assign(n, 0.0);
    owned.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t old = layout.old_of[i];
      t[i] = bs.s.t[old];
      owned[i] = bs.owned[old];
      if (at[old] != SIZE_MAX && !state.velocity.empty()) velocity[i] = state.velocity[at[old]];
    }
  }
  // t back on the sticks, `also` run on them while they are on their own
  // box, and the sticks back on their lattice.
  template <class Also = void (*)(StickSurface&)>
  void put_back(Also also = [](StickSurface&) {}) {
    for (size_t i = 0; i < t.size(); ++i) bs.s.t[layout.old_of[i]] = t[i];
    also(bs.s);
    bs.s = off_own_box(std::move(bs.s), frame);
  }
};

}  // namespace

std::vector<PressRound> press_rounds(const Lattice& lattice, const SurfaceOptions& options, int64_t halo) {
  const PressOptions po = block_press_options(options);
  const int cap = std::max(po.iterations, 0), levels = std::max(po.levels, 1);
  // A round's sweeps reach at most the halo less the block's artificial
  // border (one sample) and one for the owned sticks' own samples.
  const int64_t room = halo - 2;
  const int64_t widest = sweep_reach(lattice, po, 1 << (levels - 1));
  if (cap > 0 && widest > room)
    throw UsageError("--halo " + std::to_string(halo) + " is narrower than one sweep of the coarsest pressing stage: use " +
                     std::to_string(widest + 2) + " samples or more");
  std::vector<PressRound> rounds;
  for (int k = 0; k < cap;) {
    PressRound r{k, k};
    for (int64_t used = 0; r.last < cap;) {
      const int stage = std::min(levels - 1, r.last * levels / cap);
      const int64_t step = sweep_reach(lattice, po, 1 << (levels - 1 - stage));
      if (used + step > room) break;
      used += step;
      ++r.last;
    }
    rounds.push_back(r);
    k = r.last;
  }
  return rounds;
}

PressState press_state(const std::vector<SurfacePiece>& pieces, const ChunkGrid* grid, size_t b) {
  struct Ref {
    uint64_t key;
    uint32_t piece, index;
  };
  // A key's lower sample (stick_key: padded x fastest, then the axis, y, z).
  const Box read = grid ? grid->with_halo(b) : Box{};
  const uint64_t px = grid ? uint64_t(grid->dims[0] + 2) : 1, py = grid ? uint64_t(grid->dims[1] + 2) : 1;
  const auto wanted = [&](uint64_t key) {
    if (!grid) return true;
    const uint64_t row = key / px / 3;
    const int64_t l[3] = {int64_t(key % px) - 1, int64_t(row % py) - 1, int64_t(row / py) - 1};
    for (int a = 0; a < 3; ++a)
      if (l[a] < read.lo[size_t(a)] - 1 || l[a] >= read.hi[size_t(a)]) return false;
    return true;
  };
  std::vector<Ref> refs;
  for (size_t p = 0; p < pieces.size(); ++p)
    for (size_t i = 0; i < pieces[p].sticks.size(); ++i)
      if (wanted(pieces[p].sticks[i])) refs.push_back({pieces[p].sticks[i], uint32_t(p), uint32_t(i)});
  tbb::parallel_sort(refs.begin(), refs.end(), [](const Ref& x, const Ref& y) { return x.key < y.key; });
  PressState out;
  out.sticks.resize(refs.size());
  out.t.resize(refs.size());
  out.velocity.resize(refs.size());
  detail::parallel_for(refs.size(), [&](size_t i) {
    const SurfacePiece& p = pieces[refs[i].piece];
    out.sticks[i] = refs[i].key;
    out.t[i] = p.t[refs[i].index];
    out.velocity[i] = p.velocity.empty() ? 0 : p.velocity[refs[i].index];
  });
  for (size_t i = 1; i < out.sticks.size(); ++i)
    if (out.sticks[i] == out.sticks[i - 1]) throw std::logic_error("press_state: a stick is owned by two pieces");
  return out;
}

SurfacePiece press_block_round(const BinaryVolume& samples, const ChunkGrid& grid, size_t b,
                               const SurfaceOptions& options, const PressRound& round, const PressState& state) {
  BlockPress bp(samples, grid, b, state);
  const PressOptions po = block_press_options(options);
  detail::SweepWindow window{round.first, round.last, &bp.velocity, &bp.owned, {}};
  PressStats st;
  if (!bp.t.empty())
    st = detail::iterate(bp.t, bp.layout.families, 2, {}, {}, po, press_levels_for_extent(po.levels, bp.layout.extent),
                         &window);
  bp.put_back();
  SurfacePiece out = detail::owned_piece(bp.bs, grid, b, false);
  // The owned sticks' momentum, in the piece's order (stick order).
  std::vector<double> by_stick(bp.t.size());
  for (size_t i = 0; i < bp.t.size(); ++i) by_stick[bp.layout.old_of[i]] = bp.velocity.empty() ? 0 : bp.velocity[i];
  for (size_t id = 0; id < by_stick.size(); ++id)
    if (bp.bs.owned[id]) out.velocity.push_back(by_stick[id]);
  out.residuals = std::move(window.residuals);
  if (out.residuals.empty()) out.residuals.assign(size_t(std::max(round.last - round.first, 0)), std::nan(""));
  out.press = st;
  return out;
}

SurfacePiece finish_block(const BinaryVolume& samples, const ChunkGrid& grid, size_t b, const SurfaceOptions& options,
                          const PressState& state, bool measure) {
  BlockPress bp(samples, grid, b, state);
  const PressOptions po = block_press_options(options);
  double residual = 0;
  if (measure && !bp.t.empty()) residual = detail::residual_at(bp.t, bp.layout.families, 2, po, &bp.owned);
  bp.put_back([&](StickSurface& s) {
    if (!options.passes.on(Pass::quadric_fit) || s.stick_count() == 0) return;
    // The whole run's fit without flats (smooth/pipeline.cpp): no region, no junction.
    QuadricFitOptions fo = options.fit;
    fo.margin = po.margin;
    fit_local_quadrics(s, std::vector<int32_t>(s.stick_count(), -1), {}, fo);
  });
  SurfacePiece out = detail::owned_piece(bp.bs, grid, b, true);
  if (measure) out.residuals.assign(1, residual);
  return out;
}

}  // namespace voxpress
