// Blocks pressed apart in exchange rounds: the whole run's sweeps, block by
// block. Theory of operation: include/voxpress/chunk/chunked.h.
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "chunk/block.h"
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
    r.measured = std::min(levels - 1, (r.last - 1) * levels / cap) == levels - 1;  // iterate()'s stage of its last sweep
    rounds.push_back(r);
    k = r.last;
  }
  return rounds;
}

PressState press_state(const std::vector<SurfacePiece>& pieces) {
  PressState out;
  out.pieces.reserve(pieces.size());
  for (const SurfacePiece& p : pieces) out.pieces.push_back({p.block, p.sticks, p.t, p.velocity});
  return out;
}

// The block's sticks placed for pressing, once: on their own box (as the
// whole run), with the layout's order and families.
struct BlockRounds::Impl {
  detail::BlockSticks bs;
  OwnBox frame;
  SliceCurves curves;  // the layout's families point into it
  detail::Layout layout;
  std::vector<uint8_t> owned;  // layout order
  std::vector<uint32_t> owner;  // stick order: the block that owns it
  PressOptions po;
  SurfaceOptions options;
  const ChunkGrid grid;
  size_t b;
  Impl(const BinaryVolume& samples, const ChunkGrid& g, size_t block, const SurfaceOptions& o)
      : bs(detail::block_sticks(samples, g, block, ExtractOptions{})),
        po(block_press_options(o)),
        options(o),
        grid(g),
        b(block) {
    bs.s = on_own_box(std::move(bs.s), &frame);
    curves = build_slice_curves(bs.s);
    detail::make_layout(bs.s, curves, layout);
    owned.resize(bs.s.stick_count());
    for (size_t i = 0; i < owned.size(); ++i) owned[i] = bs.owned[layout.old_of[i]];
    // Each stick's owner: the block holding its lower sample.
    const detail::KeyCodec codec(grid.dims);
    owner.resize(bs.s.stick_count());
    for (size_t id = 0; id < owner.size(); ++id) owner[id] = uint32_t(grid.block_of(codec.lower(bs.key[id])));
  }
  // t and momentum in layout order from `state` (sticks it does not hold,
  // the block's artificial border: the extraction's t, at rest). Each stick
  // is looked up in its owner's piece; a block's sticks are in whole-run key
  // order (the canonical order of a sub-box), as are a piece's, so the
  // search in each piece only moves forwards.
  void load(const PressState& state, std::vector<double>& t, std::vector<double>& velocity) const {
    const size_t n = bs.s.stick_count();
    std::vector<int32_t> slot(grid.count(), -1);
    for (size_t k = 0; k < state.pieces.size(); ++k) {
      const PressState::Piece& p = state.pieces[k];
      if (p.block >= slot.size() || slot[p.block] >= 0 || p.t.size() != p.sticks.size() ||
          (!p.velocity.empty() && p.velocity.size() != p.sticks.size()))
        throw UsageError("a round's state: a piece is repeated, not of this grid, or its arrays do not match");
      slot[p.block] = int32_t(k);
    }
    std::vector<size_t> from(state.pieces.size(), 0);
    t.resize(n);
    velocity.assign(n, 0.0);
    for (size_t i = 0; i < n; ++i) t[i] = bs.s.t[layout.old_of[i]];
    for (size_t id = 0; id < n; ++id) {
      const int32_t k = slot[owner[id]];
      if (k < 0) continue;
      const PressState::Piece& p = state.pieces[size_t(k)];
      if (from[size_t(k)] < p.sticks.size() && p.sticks[from[size_t(k)]] > bs.key[id]) from[size_t(k)] = 0;  // not in order: search it all
      const auto at = std::lower_bound(p.sticks.begin() + ptrdiff_t(from[size_t(k)]), p.sticks.end(), bs.key[id]);
      if (at == p.sticks.end() || *at != bs.key[id]) continue;
      const size_t j = size_t(at - p.sticks.begin());
      from[size_t(k)] = j;
      t[layout.new_of[id]] = p.t[j];
      if (!p.velocity.empty()) velocity[layout.new_of[id]] = p.velocity[j];
    }
  }
};

BlockRounds::BlockRounds(const BinaryVolume& samples, const ChunkGrid& grid, size_t b, const SurfaceOptions& options)
    : impl_(std::make_unique<Impl>(samples, grid, b, options)) {}
BlockRounds::~BlockRounds() = default;
BlockRounds::BlockRounds(BlockRounds&&) noexcept = default;

uint64_t BlockRounds::bytes() const {
  const Impl& m = *impl_;
  const auto of = [](const auto& v) { return uint64_t(v.size() * sizeof(v[0])); };
  uint64_t out = of(m.bs.s.lower) + of(m.bs.s.code) + of(m.bs.s.t) + of(m.bs.s.triangles) + of(m.bs.key) +
                 of(m.bs.owned) + of(m.owned) + of(m.owner) + of(m.layout.old_of) + of(m.layout.new_of);
  for (int a = 0; a < 3; ++a) out += of(m.curves.ids[a]) + of(m.curves.offsets[a]) + of(m.layout.ids[a]);
  for (const detail::Family& f : m.layout.families) out += sizeof(f) + of(f.base) + of(f.mov) + of(f.dst) + of(f.spans);
  return out;
}

SurfacePiece BlockRounds::round(const PressRound& round, const PressState& state) const {
  const Impl& m = *impl_;
  std::vector<double> t, velocity;
  m.load(state, t, velocity);
  detail::SweepWindow window{round.first, round.last, &velocity, &m.owned, {}};
  PressStats st;
  if (!t.empty())
    st = detail::iterate(t, m.layout.families, 2, {}, {}, m.po, press_levels_for_extent(m.po.levels, m.layout.extent),
                         &window);
  // The owned sticks' t and momentum, in the piece's order (stick order).
  std::vector<double> t_of(t.size()), v_of(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    t_of[m.layout.old_of[i]] = t[i];
    v_of[m.layout.old_of[i]] = velocity.empty() ? 0 : velocity[i];
  }
  SurfacePiece out = detail::owned_piece(m.bs, m.grid, m.b, false, &t_of);
  for (size_t id = 0; id < v_of.size(); ++id)
    if (m.bs.owned[id]) out.velocity.push_back(v_of[id]);
  out.residuals = std::move(window.residuals);
  if (out.residuals.empty()) out.residuals.assign(size_t(std::max(round.last - round.first, 0)), std::nan(""));
  out.press = st;
  return out;
}

SurfacePiece BlockRounds::finish(const PressState& state, bool measure) const {
  const Impl& m = *impl_;
  std::vector<double> t, velocity;
  m.load(state, t, velocity);
  double residual = 0;
  if (measure && !t.empty()) residual = detail::residual_at(t, m.layout.families, 2, m.po, &m.owned);
  detail::BlockSticks bs = m.bs;  // the fit moves them: the last step's own copy
  for (size_t i = 0; i < t.size(); ++i) bs.s.t[m.layout.old_of[i]] = t[i];
  if (m.options.passes.on(Pass::quadric_fit) && bs.s.stick_count() > 0) {
    // The whole run's fit without flats (smooth/pipeline.cpp): no region, no
    // junction; only the owned sticks move (their piece), so only the sites
    // they read are fitted.
    QuadricFitOptions fo = m.options.fit;
    fo.margin = m.po.margin;
    fit_local_quadrics(bs.s, std::vector<int32_t>(bs.s.stick_count(), -1), {}, fo, &m.bs.owned);
  }
  bs.s = off_own_box(std::move(bs.s), m.frame);
  SurfacePiece out = detail::owned_piece(bs, m.grid, m.b, true);
  if (measure) out.residuals.assign(1, residual);
  return out;
}

}  // namespace voxpress
