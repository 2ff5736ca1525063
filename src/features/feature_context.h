// Private to the feature layer: its driver. The pass table
// (features/passes.cpp, declared in voxpress/features/passes.h) lists every
// pass with its stage and its step (each step defined beside its pass's
// code, declared beside its row); run_stage runs one stage's steps in
// table order over the stage's context, each only when runs() allows it,
// and times, counts and traces each. A step returns its count; what a
// step records itself in `times` (its rules' seconds) is not counted twice.
#pragma once

#include <memory>

#include <vector>

#include "smooth/surface_graph.h"
#include "voxpress/features/flats.h"
#include "voxpress/features/sharpen.h"
#include "voxpress/smooth/pressing.h"

namespace voxpress::flats_impl {
struct FlatsContext;  // flat_detector.h
}
namespace voxpress::sharpen_impl {
struct Sharpener;  // sharpener.h
}

namespace voxpress::detail {

// Stage::crease_round's state (feature_press.cpp): the surface pressed so
// far, its flats, and what the round's placements fix and cut.
struct CreaseRound {
  StickSurface& s;
  FlatSegmentation& seg;
  const FlatOptions& o;
  const Adjacency& graph;
  std::vector<uint8_t> fixed;    // placed by crease_fit, then curved_creases
  std::vector<uint8_t> barrier;  // seg.barrier and the curved creases' vertices
  bool last = false;             // the last round: the one whose counts are reported
};

// Stage::fit's state. `only` (optional): the vertices that may move (a
// label's part of a shared surface, labels/shared_fit.cpp).
struct FitStage {
  StickSurface& s;
  const FlatSegmentation& seg;
  const Adjacency& graph;
  QuadricFitOptions o;
  QuadricFitStats out;
  const std::vector<uint8_t>* only = nullptr;
};

// The state a stage's steps work on: the stage's own (one of the pointers)
// and where the driver writes.
struct FeatureContext {
  const PassSet& on;
  PassTimes& times;
  flats_impl::FlatsContext* detect = nullptr;   // Stage::detect
  CreaseRound* crease = nullptr;                // Stage::crease_round
  FitStage* fit = nullptr;                      // Stage::fit
  sharpen_impl::Sharpener* sharpen = nullptr;   // Stage::sharpen
};

// Runs `stage`'s steps, in table order.
void run_stage(Stage stage, FeatureContext& ctx);

// The public stages on a surface whose adjacency is built once per run
// (smooth/pipeline.cpp): find_flats, fit_creases, fit_curved_creases,
// press_with_flats and sharpen, given that adjacency.
FlatSegmentation find_flats(const StickSurface& surface, const SliceCurves& curves, const std::vector<double>& estimate,
                            const FlatOptions& options, const Adjacency& graph);
size_t fit_creases(StickSurface& surface, const FlatSegmentation& flats, const FlatOptions& options,
                   std::vector<uint8_t>* placed, const Adjacency& graph);
size_t fit_curved_creases(StickSurface& surface, const FlatSegmentation& flats, const FlatOptions& options,
                          std::vector<uint8_t>& fixed, std::vector<uint8_t>* placed, const Adjacency& graph);
FeaturePressStats press_with_flats(StickSurface& surface, const SliceCurves& curves, const PressOptions& options,
                                   const FlatOptions* flat_options, FlatSegmentation* flats, const Adjacency& graph);

// press_with_flats as the pipeline's two steps (smooth/sequence.h): the
// flats (the layout, the estimates, the detection; the flats applied to the
// surface), then the press (the final press, the crease rounds). FlatRun
// carries what the first leaves the second.
struct Layout;
struct FlatRun {
  struct Estimates;  // feature_press.cpp
  std::unique_ptr<Layout> layout;
  std::unique_ptr<Estimates> estimates;
  FlatRun();
  ~FlatRun();
};
void find_flats_of(StickSurface& surface, const SliceCurves& curves, const PressOptions& options,
                   const FlatOptions& flat_options, const Adjacency& graph, FlatRun& run);
FeaturePressStats press_flat_run(StickSurface& surface, FlatRun& run, const PressOptions& options,
                                 const FlatOptions& flat_options, FlatSegmentation* flats, const Adjacency& graph);
SharpenResult sharpen(const StickSurface& surface, const FlatSegmentation& flats, const SharpenOptions& options,
                      const Adjacency& graph);

}  // namespace voxpress::detail
