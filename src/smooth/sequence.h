// The Pressing pipeline's one sequence of stages (private), written once
// for a binary volume's sticks (pipeline.cpp) and a label map's shared
// surface (labels/shared_labels.cpp): each surface kind gives its steps,
// and which of them run, in which order, is decided here.
#pragma once

#include "voxpress/features/passes.h"

namespace voxpress::detail {

/// How far a run goes: the whole pipeline, or its stick stages only (the
/// chunked path's blocks, whose mesh is stitched from their sticks).
enum class Through : uint8_t { fit, all };

/// flats (Section 3: the estimates and the detection; the feature layer's
/// Stage::detect) -> press (Section 4; a binary surface then runs its
/// crease rounds) -> fit (Stage::fit) -> sharpen (Section 5; Stage::sharpen)
/// -> output (the mesh of a surface left unsharpened) -> simplify (checked
/// collapses). `Steps` has one member function per stage.
template <class Steps>
void run_sequence(Steps& s, const PassSet& on, bool simplify, Through through = Through::all) {
  const bool features = on.on(Pass::flats);
  if (features) s.flats();
  s.press();
  s.fit();
  if (through == Through::fit) return;
  const bool sharpen = features && on.on(Pass::sharpen);
  if (sharpen) s.sharpen();
  s.output(sharpen);
  if (simplify) s.simplify();
}

}  // namespace voxpress::detail
