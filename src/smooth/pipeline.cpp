// The volume-to-surface pipeline behind `voxpress press`. Theory of
// operation: include/voxpress/smooth/pipeline.h.
#include "voxpress/smooth/pipeline.h"

#include <chrono>

#include "core/timing.h"

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

SurfaceResult smooth_surface(const BinaryVolume& volume, const SurfaceOptions& o) {
  const MethodOverrides& ov = o.overrides;
  if ((ov.lambda || ov.mu) && o.method != Method::taubin && o.method != Method::laplacian)
    throw UsageError("lambda and mu apply to taubin and laplacian only");
  require_mixed(volume);
  SurfaceResult r;
  auto t0 = std::chrono::steady_clock::now();
  ExtractOptions eo = o.extract;
  if (o.progress) eo.progress = o.progress;
  StickSurface surface = extract_sticks(volume, eo, &r.extract);
  r.seconds_extract = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  switch (o.method) {
    case Method::pressing: {
      PressOptions po = o.press;
      FlatOptions fo = o.flat;
      if (o.progress) po.progress = fo.progress = o.progress;
      ov.apply(po);
      const SliceCurves curves = build_slice_curves(surface);
      r.press = press_with_flats(surface, curves, po, o.flats ? &fo : nullptr, &r.flats).press;
      QuadricFitOptions qo = o.fit;
      qo.margin = po.margin;
      r.fit = fit_local_quadrics(surface, r.flats.region, r.flats.junction, qo);
      if (o.flats && o.sharpen) {
        SharpenOptions so = o.sharp;
        so.colors = o.color_regions;
        SharpenResult sr = sharpen(surface, r.flats, so);
        r.mesh = std::move(sr.mesh);
        r.sharpen = sr.stats;
      } else {
        r.mesh = to_mesh(surface);
        if (o.flats) add_region_attributes(r.mesh, r.flats, o.color_regions);
      }
      break;
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
  return r;
}

}  // namespace voxpress
