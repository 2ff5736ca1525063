// Flats of a shared surface: each label's binary detection mapped onto the
// shared stick vertices. Theory of operation: include/voxpress/labels/shared_flats.h.
#include "voxpress/labels/shared_flats.h"


#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/timing.h"
#include "shared_sticks.h"
#include "voxpress/labels/labels.h"
#include "core/parallel.h"

namespace voxpress {
namespace {

// One label's flats, as (shared vertex, t, barrier, its flat) entries.
struct LabelFlats {
  std::vector<Flat> flats;
  struct Entry {
    uint32_t vertex;
    double t;
    uint8_t barrier;
    int32_t flat;
  };
  std::vector<Entry> entries;
};

}  // namespace

size_t SharedFlats::flats_of(double value) const {
  return size_t(std::count(flat_label.begin(), flat_label.end(), uint32_t(value)));
}

SharedFlats find_shared_flats(const LabelMasks& masks, const SharedSurface& s, const std::vector<LabelInfo>& labels,
                              const PressOptions& press, const FlatOptions& options, Progress* progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = s.mesh.positions.size();
  SharedFlats out;
  out.t.assign(n, std::numeric_limits<double>::quiet_NaN());
  out.barrier.assign(n, 0);
  out.region.assign(n, -1);
  const detail::SharedSticks sticks(s);

  std::vector<LabelFlats> per(labels.size());
  out.segmentations.resize(labels.size());
  FlatOptions fo = options;
  fo.progress = nullptr;
  PressOptions po = press;
  po.progress = nullptr;
  if (progress) progress->begin("flats per label", labels.size());
  std::atomic<uint64_t> done{0};
  detail::parallel_for(labels.size(), [&](size_t i) {
    const LabelInfo& label = labels[i];
    const BinaryVolume mask = masks(label);
    const std::array<int64_t, 3> lo = detail::mask_origin(label.lo);
    StickSurface surface = extract_sticks(mask);
    const SliceCurves curves = build_slice_curves(surface);
    // Only the flats' vertices are kept: their t (on their planes) and
    // barriers; the final press of the label's own surface would be unused.
    FlatSegmentation seg = segment_flats(surface, curves, po, fo);
    apply_flats(surface, seg);
    LabelFlats& lf = per[i];
    lf.flats = seg.flats;
    const bool has_flats = !seg.flats.empty();
    if (has_flats) out.segmentations[i] = std::move(seg);
    const FlatSegmentation& kept = has_flats ? out.segmentations[i] : seg;
    for (size_t k = 0; k < surface.stick_count(); ++k) {
      if (kept.region[k] < 0) continue;
      const uint32_t v = sticks.find(surface, k, lo);
      if (v == UINT32_MAX) continue;  // cannot happen: a label's sticks are shared sticks
      // surface.t: from the lower sample, as the shared surface (seg.t is from the inside one).
      lf.entries.push_back({v, surface.t[k], kept.barrier[k], kept.region[k]});
    }
    if (progress) progress->update(++done);
  });
  if (progress) progress->end();
  // Labels in value order: the first to freeze a vertex gives its t.
  for (size_t i = 0; i < per.size(); ++i) {
    const int32_t base = int32_t(out.flats.size());
    for (const Flat& f : per[i].flats) {
      out.flats.push_back(f);
      out.flat_label.push_back(uint32_t(labels[i].value));
    }
    for (const auto& e : per[i].entries) {
      out.barrier[e.vertex] |= e.barrier;
      if (out.region[e.vertex] >= 0) continue;
      out.region[e.vertex] = base + e.flat;
      out.t[e.vertex] = e.t;
      ++out.frozen;
    }
  }
  out.seconds = detail::seconds_since(t0);
  return out;
}

}  // namespace voxpress
