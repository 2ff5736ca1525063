// press_shared_labels: what `press --labels` runs by default, the stages
// of smooth_surface on a label map's shared surface (extraction, each
// label's flats, the shared press, the quadric fit, the sharpening, the
// simplification), each in its own file. Contract: labels/shared_press.h.
#include <chrono>
#include <string>

#include "core/timing.h"
#include "voxpress/core/error.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_press.h"
#include "smooth/sequence.h"
#include "voxpress/smooth/pipeline.h"

namespace voxpress {

namespace {

// A label map's steps of the pipeline's sequence (smooth/sequence.h) on its
// shared surface: each label's flats, the shared press (no crease rounds:
// a shared vertex belongs to two labels' sides), each label's fit and
// sharpening, one simplification.
struct SharedSteps {
  SharedLabels& r;
  const LabelMasks& masks;
  const LabelTable& table;
  const SurfaceOptions& o;
  PressOptions po;

  void flats() {
    FlatOptions fo = o.flat;
    fo.passes = o.passes;
    r.flats = find_shared_flats(masks, r.surface, table.labels, po, fo, o.progress);
  }
  void press() { r.press = press_shared(r.surface, po, r.flats ? &*r.flats : nullptr); }
  void fit() {
    QuadricFitOptions fit = o.fit;
    fit.margin = po.margin;
    r.fit = fit_shared_quadrics(r.surface, masks, table.labels, r.flats ? &*r.flats : nullptr, fit, o.passes);
  }
  void sharpen() {
    SharpenOptions so = o.sharp;
    so.passes = o.passes;
    r.sharpen = sharpen_shared(r.surface, *r.flats, masks, table.labels, so);
  }
  void output(bool) {}  // the shared surface is the output, sharpened or not
  void simplify() { r.simplify = simplify_shared(r.surface, o.simplify); }
};

}  // namespace

SharedLabels press_shared_labels(const ScalarVolume& volume, const LabelTable& table, const SurfaceOptions& o) {
  require_float32_room(volume.lattice, o, volume.source);  // before the extraction's cost
  const auto t0 = std::chrono::steady_clock::now();
  SharedSurface surface = extract_shared_surface(volume);
  const double seconds = detail::seconds_since(t0);
  SharedLabels r = press_shared_labels(std::move(surface), masks_in(volume), table, o, volume.source);
  r.seconds_extract = seconds;
  return r;
}

SharedLabels press_shared_labels(SharedSurface surface, const LabelMasks& masks, const LabelTable& table,
                                 const SurfaceOptions& o, const std::string& source) {
  require_float32_room(surface.lattice, o, source);
  // The shared press's peak, measured whole-process: 0.77 GiB for 3.3 M
  // interface triangles, 2.45 GiB for 11.1 M (bench/chunk_labels.py):
  // about 240 bytes per triangle; 256 leaves room.
  // Simplifying adds about 190 bytes a triangle (the 61-label map at 1.5 mm:
  // 692 MB peak for 1.6 M triangles with --faces): 256 more.
  constexpr uint64_t kBytesPerTriangle = 256, kSimplifyBytesPerTriangle = 256;
  const bool simplifying = o.simplify.faces || o.simplify.max_error > 0;
  const uint64_t need = uint64_t(surface.mesh.triangles.size()) * (kBytesPerTriangle + (simplifying ? kSimplifyBytesPerTriangle : 0)),
                 cap = o.extract.max_bytes;
  if (cap && need > cap)
    throw LimitError(source, "pressing the shared surface of " + std::to_string(surface.mesh.triangles.size()) +
                                 " triangles needs about " + std::to_string(need >> 20) + " MiB, above the memory limit of " +
                                 std::to_string(cap >> 20) + " MiB");
  SharedLabels r;
  r.surface = std::move(surface);
  SharedSteps steps{r, masks, table, o, o.press};
  o.overrides.apply(steps.po);
  detail::run_sequence(steps, o.passes, o.simplify.faces != 0 || o.simplify.max_error != 0);
  if (r.flats)
    for (const FlatSegmentation& seg : r.flats->segmentations) r.passes.add(seg.stats.passes);
  r.passes.add(r.fit.passes);
  r.passes.add(r.sharpen.passes);
  return r;
}

}  // namespace voxpress
