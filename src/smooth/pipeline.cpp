// The volume-to-surface pipeline behind `voxpress press`. Theory of
// operation: include/voxpress/smooth/pipeline.h.
#include "voxpress/smooth/pipeline.h"

#include <chrono>

#include "core/clearance.h"
#include "core/timing.h"
#include "features/feature_context.h"
#include "io/io_util.h"
#include "smooth/sequence.h"

namespace voxpress {

using detail::seconds_since;

namespace {

struct Named {
  Method method;
  const char* name;
};
constexpr Named kMethods[] = {{Method::pressing, "pressing"},   {Method::cesn, "cesn"},
                              {Method::diamond, "diamond"},     {Method::cell_edge, "cell-edge"},
                              {Method::cell_size, "cell-size"}, {Method::taubin, "taubin"},
                              {Method::laplacian, "laplacian"}};

}  // namespace

const char* method_name(Method m) {
  for (const Named& n : kMethods)
    if (n.method == m) return n.name;
  return "?";
}

Method parse_method(const std::string& name) {
  std::string all;
  for (const Named& n : kMethods) {
    if (name == n.name) return n.method;
    all += std::string(all.empty() ? "" : ", ") + n.name;
  }
  throw UsageError("unknown method '" + name + "' (expected " + all + ")");
}

void MethodOverrides::apply(PressOptions& o) const {
  if (iterations) o.iterations = *iterations;
  if (tolerance) o.tolerance = *tolerance;
}

void MethodOverrides::apply(SurfaceNetOptions& o) const {
  if (iterations) o.max_iterations = *iterations;
  if (tolerance) o.threshold = *tolerance;
}

void MethodOverrides::apply(ConstrainedOptions& o) const {
  if (iterations) o.max_iterations = *iterations;
  if (tolerance) o.threshold = *tolerance;
}

void MethodOverrides::apply(FairOptions& o) const {
  if (iterations) o.iterations = *iterations;
  if (lambda) o.lambda = *lambda;
  if (mu) o.mu = *mu;
}

bool keeps_classification(Method m) {
  return m == Method::pressing || m == Method::diamond || m == Method::cell_edge;
}

namespace {
// value in [lo, hi] (NaN never is); `name` as the CLI and Python spell it.
void in_range(double value, double lo, double hi, const char* name) {
  if (!(value >= lo && value <= hi))
    throw UsageError(std::string(name) + " must be in [" + detail::format_double(lo) + ", " +
                     detail::format_double(hi) + "], not " + detail::format_double(value));
}
// Iteration caps and ring counts beyond these only burn time (a ring count
// of 12 already spans a whole small part).
constexpr double kMaxIterations = 1e6, kMaxRings = 12;
// Bytes per stick of the stages after extraction, at their peak (measured:
// docs/RELIABILITY.md, Resource limits).
constexpr uint64_t kFeatureBytesPerStick = 420, kPressBytesPerStick = 250, kOtherBytesPerStick = 320;
// The simplifier's share on top (positions twice, quadrics, face lists,
// grid, heap): `press --faces 8644` of the 256^3 CAD part peaked 154 MB
// above `press` for 216,121 sticks (713 B), rounded up.
constexpr uint64_t kSimplifyBytesPerStick = 768;
}  // namespace

uint64_t bytes_per_stick(const SurfaceOptions& o) {
  // Peak resident bytes per stick beyond the volume and the bare surface,
  // measured with /usr/bin/time on spheres and CAD parts at 256^3 and 512^3
  // (docs/RELIABILITY.md, Resource limits), rounded up.
  const uint64_t simplify = o.simplify.faces || o.simplify.max_error > 0 ? kSimplifyBytesPerStick : 0;
  if (o.method != Method::pressing) return kOtherBytesPerStick + simplify;
  return (o.passes.on(Pass::flats) ? kFeatureBytesPerStick : kPressBytesPerStick) + simplify;
}

void validate(const SurfaceOptions& o) {
  const MethodOverrides& ov = o.overrides;
  if ((ov.lambda || ov.mu) && o.method != Method::taubin && o.method != Method::laplacian)
    throw UsageError("lambda and mu apply to taubin and laplacian only");
  if (ov.iterations) in_range(*ov.iterations, 0, kMaxIterations, "iterations");
  if (ov.tolerance) in_range(*ov.tolerance, 0, 1, "tolerance");
  if (ov.lambda) in_range(*ov.lambda, -10, 10, "lambda");
  if (ov.mu) in_range(*ov.mu, -10, 10, "mu");
  const PressOptions& p = o.press;
  in_range(p.iterations, 0, kMaxIterations, "iterations");
  in_range(o.simplify.max_error, 0, 1e300, "max_error");
  if (!o.simplify.soft_keys.empty()) throw UsageError("simplify.soft_keys is voxel art's; a volume's surface keeps its borders");
  in_range(p.tolerance, 0, 1, "tolerance");
  in_range(p.step, 1e-6, 2, "step");
  in_range(p.arc_length, 1e-3, 16, "arc_length");
  in_range(p.margin, 1e-4, 0.49, "margin");
  in_range(p.levels, 0, 16, "levels");
  in_range(p.momentum, 0, 0.99, "momentum");
  in_range(p.circle_correction, 0, 90, "circle_correction");
  in_range(o.fit.rings, 0, kMaxRings, "fit_rings");
  in_range(o.fit.residual, 0, 10, "fit_residual");
  in_range(o.fit.stab_eps, 0, 1, "fit_stab_eps");
  in_range(o.flat.min_area, 0, 1e12, "min_flat_area");
  in_range(o.flat.junction_angle, 0, 180, "junction_angle");
  in_range(o.flat.margin, 1e-4, 0.49, "flat margin");
  in_range(o.sharp.sharp_angle, 0, 180, "sharp_angle");
  in_range(o.sharp.margin, 1e-4, 0.49, "sharpen margin");
}

void require_float32_room(const Lattice& lattice, const SurfaceOptions& o, const std::string& source) {
  // The output keeps the guarantee in float32 only if its rounding (delta / 4)
  // stays well inside the clearance the pressing margin gives every sample
  // (margin / sqrt(3)): a lattice far from the origin for its spacing cannot.
  // The rounding is judged per axis (issue 73: spacing 0.01, 1, 100 was refused).
  if (const double rounding = detail::float32_rounding(lattice); 4 * rounding > o.press.margin)
    throw InputError(source, "its coordinates are too large for its spacing to be stored in float32 with "
                             "every sample on its side (rounding " + detail::format_double(rounding) +
                             " cells; move the origin closer to the volume)");
}

namespace {

// A binary volume's steps of the pipeline's sequence (smooth/sequence.h),
// on its sticks' own box, with the surface's adjacency built once for
// every stage of the run.
struct BinarySteps {
  StickSurface& s;
  const OwnBox& frame;
  const SurfaceOptions& o;
  SurfaceResult& r;
  const detail::Adjacency graph;
  PressOptions po;
  FlatOptions fo;
  SliceCurves curves;
  detail::FlatRun run;

  BinarySteps(StickSurface& own, const OwnBox& box, const SurfaceOptions& options, SurfaceResult& result)
      : s(own), frame(box), o(options), r(result), graph(own.stick_count(), own.triangles), po(o.press), fo(o.flat) {
    fo.passes = o.passes;
    if (o.progress) po.progress = fo.progress = o.progress;
    po.free_ends = po.free_ends && o.passes.on(Pass::free_ends);
    o.overrides.apply(po);
    curves = build_slice_curves(s);
  }
  void flats() { detail::find_flats_of(s, curves, po, fo, graph, run); }
  void press() {
    const FeaturePressStats fs = run.layout ? detail::press_flat_run(s, run, po, fo, &r.flats, graph)
                                            : detail::press_with_flats(s, curves, po, nullptr, &r.flats, graph);
    r.press = fs.press;
    r.pass_times = fs.passes;
  }
  void fit() {
    detail::FitStage fit{s, r.flats, graph, o.fit, {}};
    fit.o.margin = po.margin;
    detail::FeatureContext fc{o.passes, r.pass_times};
    fc.fit = &fit;
    detail::run_stage(Stage::fit, fc);
    r.fit = fit.out;
  }
  void sharpen() {
    SharpenOptions so = o.sharp;
    so.colors = o.color_regions;
    so.passes = o.passes;
    SharpenResult sr = detail::sharpen(s, r.flats, so, graph);
    r.mesh = std::move(sr.mesh);
    r.sharpen = sr.stats;
    r.pass_times.add(sr.stats.passes);
  }
  void output(bool sharpened) {
    if (sharpened) return;
    r.mesh = to_mesh(off_own_box(std::move(s), frame));  // written from the caller's lattice (s is not used after)
    if (o.passes.on(Pass::flats)) add_region_attributes(r.mesh, r.flats, o.color_regions);
  }
  void simplify() { simplify_result(frame.lattice, o, r); }  // the caller's lattice, as Mesh::simplify has it
};

}  // namespace

void press_stick_surface(StickSurface& sticks, const SurfaceOptions& o, SurfaceResult& r) {
  // Translation-free (issue 74, item 2): every stage on the sticks' own
  // box, so a shifted, padded or cropped volume gives the same t, and the
  // sticks come back on their lattice (the chunked path's blocks too).
  OwnBox frame;
  StickSurface surface = on_own_box(std::move(sticks), &frame);
  BinarySteps steps(surface, frame, o, r);
  detail::run_sequence(steps, o.passes, false, detail::Through::fit);
  sticks = off_own_box(std::move(surface), frame);
}

SurfaceResult smooth_surface(const BinaryVolume& volume, const SurfaceOptions& o) {
  validate(o);
  require_mixed(volume);
  require_float32_room(volume.lattice, o, volume.source);
  SurfaceResult r;
  auto t0 = std::chrono::steady_clock::now();
  ExtractOptions eo = o.extract;
  if (o.progress) eo.progress = o.progress;
  eo.later_bytes_per_stick = std::max(eo.later_bytes_per_stick, bytes_per_stick(o));
  StickSurface surface = extract_sticks(volume, eo, &r.extract);
  r.seconds_extract = seconds_since(t0);
  return smooth_sticks(std::move(surface), o, std::move(r));
}

SurfaceResult smooth_sticks(StickSurface surface, const SurfaceOptions& o, SurfaceResult r) {
  const MethodOverrides& ov = o.overrides;
  validate(o);
  const auto t0 = std::chrono::steady_clock::now();
  const Lattice lattice = surface.lattice;
  switch (o.method) {
    case Method::pressing: {
      OwnBox frame;  // as press_stick_surface
      StickSurface own = on_own_box(std::move(surface), &frame);
      BinarySteps steps(own, frame, o, r);
      detail::run_sequence(steps, o.passes, o.simplify.faces != 0 || o.simplify.max_error != 0);
      r.seconds_smooth = seconds_since(t0) - r.simplify.seconds;
      return r;
    }
    case Method::cesn: {
      SurfaceNetOptions so;
      ov.apply(so);
      so.progress = o.progress;
      r.mesh = constrained_surface_net(surface, so, &r.net);
      break;
    }
    case Method::taubin:
    case Method::laplacian: {
      FairOptions fo = fair_defaults(o.method == Method::taubin ? FairOptions::Kind::taubin : FairOptions::Kind::laplacian);
      ov.apply(fo);
      fo.progress = o.progress;
      r.mesh = to_mesh(surface);
      r.smooth = fair(r.mesh, fo);
      break;
    }
    case Method::diamond:
    case Method::cell_edge:
    case Method::cell_size: {
      ConstrainedOptions co;
      co.constraint = o.method == Method::diamond     ? MeshConstraint::diamond
                      : o.method == Method::cell_edge ? MeshConstraint::cell_edge
                                                      : MeshConstraint::cell_size;
      ov.apply(co);
      co.progress = o.progress;
      LatticeMesh lm = lattice_mesh(surface);
      r.smooth = constrained_smooth(lm, co);
      r.mesh = std::move(lm.mesh);
      break;
    }
  }
  r.seconds_smooth = seconds_since(t0);
  simplify_result(lattice, o, r);  // the caller's, as Mesh::simplify has it
  return r;
}

void simplify_result(const Lattice& lattice, const SurfaceOptions& o, SurfaceResult& r) {
  if (o.simplify.faces == 0 && o.simplify.max_error == 0) return;
  SimplifyOptions so = o.simplify;
  so.lattice = &lattice;
  if (o.progress) so.progress = o.progress;
  r.simplify = simplify(r.mesh, so);
}

}  // namespace voxpress
