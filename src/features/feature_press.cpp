// The Pressing pipeline with flats (Section 4, last paragraph): estimate,
// detect, freeze, press, crease rounds; and the region outputs. Theory of
// operation: include/voxpress/features/flats.h.
#include "core/timing.h"
#include "feature_context.h"
#include "feature_tuning.h"
#include "smooth/curve_kernel.h"
#include "smooth/quadric.h"
#include "voxpress/features/flats.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace voxpress {

using detail::seconds_since;

void apply_flats(StickSurface& s, const FlatSegmentation& f) {
  for (size_t v = 0; v < s.stick_count(); ++v) {
    if (f.region[v] < 0) {
      s.t[v] = 0.5;
      continue;
    }
    // seg.t is measured from the inside sample; StickSurface::t from the lower one.
    s.t[v] = s.lower_inside(v) ? f.t[v] : 1 - f.t[v];
  }
}

// What segment() leaves the press: the segmentation, `est` the last
// estimate, `plain` whether it is still the plain press of the surface (no
// flats were frozen in it), with `first` its stats and `options` the first
// estimate's press.
struct detail::FlatRun::Estimates {
  FlatSegmentation seg;
  StickSurface est;
  PressStats first;
  PressOptions options;
  bool plain = true;
};

namespace {

std::vector<uint8_t> frozen_of(const FlatSegmentation& f) {
  std::vector<uint8_t> frozen(f.region.size());
  for (size_t v = 0; v < frozen.size(); ++v) frozen[v] = f.region[v] >= 0;
  return frozen;
}

// The first estimate's press: the final press's schedule (its stages by
// extent, `levels`), so that without flats the estimate is the final press
// at every size (a 256^3 sphere: one 100-sweep press instead of two). Its
// sweeps are fixed: the flats do not depend on po.iterations. Against the
// 2 stages it used to run at every size: the same faces and no spurious
// flat on the CAD part, boxes and fandisk at 256^3, r->t within 2 %
// (docs/BENCHMARKS.md, The flats' estimates).
PressOptions estimate_options(const PressOptions& po, int levels) {
  PressOptions eo = po;
  eo.iterations = detail::kEstimateIterations;
  eo.levels = levels;
  eo.tolerance = 0;
  eo.progress = nullptr;
  eo.free_ends = false;  // see PressOptions::free_ends
  return eo;
}

// The flats of a surface from its estimates (Section 4, last paragraph):
// press a copy, detect, and (beyond the paper) press again with the first
// flats frozen and detect from scratch.
using Segmented = detail::FlatRun::Estimates;

Segmented segment(const StickSurface& s, const SliceCurves& curves, const detail::Layout& layout,
                  const PressOptions& po, const FlatOptions& fo, const detail::Adjacency& graph) {
  const auto t0 = std::chrono::steady_clock::now();
  Segmented g;
  g.est = s;
  g.options = estimate_options(po, press_levels(s, po.levels));
  const PressOptions& eo = g.options;
  g.first = detail::press_on(g.est, layout, eo);
  double t_est = seconds_since(t0);
  // The crease refit serves the final planes only: refitting a first pass's
  // piece of a face (a couple of degrees off) can change the second
  // estimate enough to lose that face.
  FlatOptions early = fo;
  early.passes.disable(Pass::crease_refit);
  FlatSegmentation& seg = g.seg;
  seg = detail::find_flats(s, curves, g.est.t, detail::kDetectionPasses > 1 ? early : fo, graph);
  // Beyond the paper: a second pass. The estimate of a face next to rounded
  // edges is a pillow whose normals spread past the acceptance test (64^3
  // boxes, thin plates). Pressed again with the first pass's flats frozen,
  // their edges are sharp and the faces between them flat, so the second
  // detection (from scratch, on the new estimate) finds the faces the
  // first missed (measured by `build/bench/bench_flats --shape box --res 64
  // --seeds 30`: more faces found beside rounded edges).
  for (int pass = 1; pass < detail::kDetectionPasses && !seg.flats.empty(); ++pass) {
    g.plain = false;
    const auto t1 = std::chrono::steady_clock::now();
    g.est = s;
    apply_flats(g.est, seg);
    PressOptions again = eo;
    again.iterations = detail::kSecondEstimateIterations;
    detail::press_on(g.est, layout, again, frozen_of(seg), seg.barrier);
    t_est += seconds_since(t1);
    const FlatStats before = seg.stats;
    seg = detail::find_flats(s, curves, g.est.t, pass + 1 < detail::kDetectionPasses ? early : fo, graph);
    seg.stats.seconds_detect += before.seconds_detect;
    seg.stats.seconds_junctions += before.seconds_junctions;
    // The seconds and trace of both detections, the last one's counts.
    PassTimes& times = seg.stats.passes;
    for (size_t p = 0; p < size_t(Pass::count); ++p) times.seconds[p] += before.passes.seconds[p];
    times.trace.insert(times.trace.begin(), before.passes.trace.begin(), before.passes.trace.end());
  }
  seg.stats.seconds_estimate = t_est;
  return g;
}

}  // namespace

FlatSegmentation segment_flats(const StickSurface& s, const SliceCurves& curves, const PressOptions& po,
                               const FlatOptions& fo) {
  detail::Layout layout;
  detail::make_layout(s, curves, layout);
  return segment(s, curves, layout, po, fo, detail::Adjacency(s.stick_count(), s.triangles)).seg;
}

FeaturePressStats press_with_flats(StickSurface& s, const SliceCurves& curves, const PressOptions& po,
                                   const FlatOptions* fo, FlatSegmentation* out) {
  return detail::press_with_flats(s, curves, po, fo, out,
                                  fo ? detail::Adjacency(s.stick_count(), s.triangles) : detail::Adjacency());
}

// The pipeline's flats step (smooth/sequence.h): the layout, the estimates
// and the detection (segment), the flats applied to the surface.
detail::FlatRun::FlatRun() = default;
detail::FlatRun::~FlatRun() = default;

void detail::find_flats_of(StickSurface& s, const SliceCurves& curves, const PressOptions& po, const FlatOptions& fo,
                           const Adjacency& graph, FlatRun& run) {
  run.layout = std::make_unique<Layout>();
  detail::make_layout(s, curves, *run.layout);
  run.estimates = std::make_unique<FlatRun::Estimates>();
  *run.estimates = segment(s, curves, *run.layout, po, fo, graph);
  apply_flats(s, run.estimates->seg);
}

// The pipeline's press step after find_flats_of: the final press with the
// flats frozen, then the crease rounds; the segmentation ends in `out`.
FeaturePressStats detail::press_flat_run(StickSurface& s, FlatRun& run, const PressOptions& po, const FlatOptions& fo,
                                         FlatSegmentation* out, const Adjacency& graph) {
  FeaturePressStats st;
  const Layout& layout = *run.layout;
  Segmented& g = *run.estimates;
  FlatSegmentation& seg = g.seg;
  const PressStats& first_estimate = g.first;
  const StickSurface& est = g.est;
  const bool est_is_plain = g.plain;
  const PressOptions& eo = g.options;
  // Beyond the paper: the vertices near sharp flat/curved borders placed
  // by the curved side's fit (fit_creases), and those of creases between
  // two curved faces by both sides' fits (fit_curved_creases), then the rest pressed again
  // around them; the iterations are shared out so the cost is unchanged.
  // Each round re-presses a fifth of the iterations (fewer past 4 rounds, so
  // the first press keeps a share).
  const bool creases = fo.passes.on(Pass::crease_fit) && seg.stats.junctions > 0;
  const int rest = creases ? po.iterations / std::max(5, detail::kCreaseRounds + 1) : 0;
  PressOptions first = po;
  first.iterations = po.iterations - detail::kCreaseRounds * rest;
  // No flat: the final press would be the estimate again (same start, no
  // frozen vertex, no barrier) when it runs the same schedule and the
  // estimate never came within its tolerance (where it would have stopped).
  if (seg.flats.empty() && est_is_plain && first.iterations == eo.iterations &&
      first_estimate.least_residual > po.tolerance) {
    s.t = est.t;
    st.press = first_estimate;
    st.press.seconds = 0;  // already counted: flats.seconds_estimate
  } else {
    st.press = detail::press_on(s, layout, first, frozen_of(seg), seg.barrier);
  }
  for (int round = 0; creases && round < detail::kCreaseRounds; ++round) {
    const auto t2 = std::chrono::steady_clock::now();
    detail::CreaseRound cr{s, seg, fo, graph, {}, seg.barrier, round + 1 == detail::kCreaseRounds};
    cr.barrier.resize(s.stick_count(), 0);
    detail::FeatureContext fc{fo.passes, st.passes};
    fc.crease = &cr;
    detail::run_stage(Stage::crease_round, fc);
    seg.stats.seconds_creases += seconds_since(t2);
    cr.fixed.resize(s.stick_count(), 0);
    for (size_t v = 0; v < cr.fixed.size(); ++v) cr.fixed[v] |= seg.region[v] >= 0;
    PressOptions again = po;
    again.iterations = rest;
    again.levels = 1;  // the fine stage goes on
    const PressStats ps = detail::press_on(s, layout, again, cr.fixed, cr.barrier);
    st.press.iterations += ps.iterations;
    st.press.seconds += ps.seconds;
    st.press.residual = ps.residual;
  }
  st.flats = seg.stats;
  // The detection's steps were timed by its driver; `flats` also takes the
  // estimates and the detection's output (sizes, barriers), and counts the
  // final flats. The crease rounds come after the detection in the trace.
  double sub = 0;
  for (size_t p = 0; p < size_t(Pass::count); ++p) sub += seg.stats.passes.seconds[p];
  PassTimes all = seg.stats.passes;
  all.add(st.passes);
  st.passes = std::move(all);
  if (po.free_ends) st.passes.count[size_t(Pass::free_ends)] = seg.stats.barriers;  // the curves' cut points
  st.passes.add(Pass::flats, seg.stats.seconds_estimate + seg.stats.seconds_detect + seg.stats.seconds_junctions - sub,
                seg.flats.size());
  if (out) *out = std::move(seg);
  return st;
}

FeaturePressStats detail::press_with_flats(StickSurface& s, const SliceCurves& curves, const PressOptions& po,
                                           const FlatOptions* fo, FlatSegmentation* out, const Adjacency& graph) {
  if (!fo) {
    FeaturePressStats st;
    st.press = press(s, curves, po);
    if (out) {
      *out = FlatSegmentation{};
      out->region.assign(s.stick_count(), -1);
    }
    return st;
  }
  FlatRun run;
  find_flats_of(s, curves, po, *fo, graph, run);
  return press_flat_run(s, run, po, *fo, out, graph);
}

namespace detail {

size_t crease_fit_step(FeatureContext& c) {
  CreaseRound& r = *c.crease;
  r.seg.stats.crease_vertices = fit_creases(r.s, r.seg, r.o, &r.fixed, r.graph);
  return r.last ? r.seg.stats.crease_vertices : 0;
}

size_t curved_creases_step(FeatureContext& c) {
  // The curved crease vertices cut the slice curves too (barriers), so
  // neither side's bilaplacian reaches across them.
  CreaseRound& r = *c.crease;
  r.seg.stats.curved_crease_vertices = fit_curved_creases(r.s, r.seg, r.o, r.fixed, &r.barrier, r.graph);
  return r.last ? r.seg.stats.curved_crease_vertices : 0;
}

size_t quadric_fit_step(FeatureContext& c) {
  FitStage& f = *c.fit;
  f.out = fit_local_quadrics(f.s, f.seg.region, f.seg.junction, f.o, f.only, f.graph);
  return f.out.moved;
}

}  // namespace detail

void add_region_attributes(Mesh& mesh, const FlatSegmentation& f, bool colors) {
  const size_t n = mesh.vertex_count();
  if (f.region.size() != n) throw std::invalid_argument("add_region_attributes: segmentation does not match the mesh");
  MeshAttribute region{"region", ScalarType::i32, std::vector<double>(n)};
  MeshAttribute junction{"junction", ScalarType::u8, std::vector<double>(n)};
  for (size_t v = 0; v < n; ++v) {
    region.values[v] = f.region[v];
    junction.values[v] = f.junction.empty() ? 0 : f.junction[v];
  }
  mesh.vertex_attributes.push_back(std::move(region));
  mesh.vertex_attributes.push_back(std::move(junction));
  if (!colors) return;
  mesh.colors.resize(n);
  for (size_t v = 0; v < n; ++v) mesh.colors[v] = region_color(f.region[v], !f.junction.empty() && f.junction[v]);
}

std::array<uint8_t, 4> region_color(int32_t region, bool junction) {
  if (junction) return {255, 140, 0, 255};
  if (region < 0) return {170, 170, 170, 255};
  // Golden-angle hues: neighbouring ids get distant colours.
  const double h = std::fmod(double(region) * 137.50776, 360.0) / 60.0;
  const double x = 1 - std::abs(std::fmod(h, 2.0) - 1);
  double rgb[3] = {0, 0, 0};
  const int sector = int(h);
  const int order[6][2] = {{0, 1}, {1, 0}, {1, 2}, {2, 1}, {2, 0}, {0, 2}};  // HSV sectors: (full, rising)
  rgb[order[sector][0]] = 1;
  rgb[order[sector][1]] = x;
  for (double& c : rgb) c = 0.25 + 0.65 * c;
  return {uint8_t(255 * rgb[0]), uint8_t(255 * rgb[1]), uint8_t(255 * rgb[2]), 255};
}


}  // namespace voxpress
