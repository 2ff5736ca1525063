// The feature layer's pass table and its driver. Theory of operation:
// include/voxpress/features/passes.h and feature_context.h.
#include "voxpress/features/passes.h"

#include <algorithm>
#include <chrono>

#include "core/timing.h"
#include "feature_context.h"
#include "voxpress/core/error.h"

namespace voxpress {

using detail::seconds_since;

namespace detail {
// The steps, each defined in its pass's file.
size_t flats_step(FeatureContext&);              // find_flats.cpp: votes and greedy growth
size_t merge_step(FeatureContext&);              // find_flats.cpp
size_t junctions_step(FeatureContext&);          // flat_junctions.cpp: extension to the sharp edges
size_t rim_tangent_step(FeatureContext&);        // flat_junctions.cpp
size_t crease_fit_step(FeatureContext&);         // feature_press.cpp
size_t curved_creases_step(FeatureContext&);     // feature_press.cpp
size_t quadric_fit_step(FeatureContext&);        // feature_press.cpp
size_t snap_step(FeatureContext&);               // sharpen_labels.cpp
size_t leftovers_step(FeatureContext&);          // sharpen_labels.cpp
size_t inherit_junctions_step(FeatureContext&);  // sharpen_labels.cpp
size_t walls_step(FeatureContext&);              // sharpen_walls.cpp
size_t final_crease_step(FeatureContext&);       // sharpen_creases.cpp
size_t past_crease_step(FeatureContext&);        // sharpen_creases.cpp
size_t final_curved_creases_step(FeatureContext&);  // sharpen_creases.cpp
size_t sharpen_step(FeatureContext&);            // sharpen_moves.cpp: the chamfers split
size_t round_chains_step(FeatureContext&);       // sharpen_chains.cpp
size_t moves_step(FeatureContext&);              // sharpen.cpp
}  // namespace detail

using detail::FeatureContext;
using S = Stage;

const std::vector<PassInfo>& feature_passes() {
  // Each row: pass, name, section, what, stage, step (none: a rule), needs.
  // Rules follow the pass whose decision they change.
  static const std::vector<PassInfo> passes = {
      // ---- Stage::detect, once per estimate (find_flats)
      {Pass::flats, "flats", "Section 3", "flats by plane voting and greedy growth (off: the whole feature layer)",
       S::detect, detail::flats_step},
      {Pass::stab_refit, "stab-refit", "beyond the paper", "core planes refit by the count of sticks they stab", S::detect},
      {Pass::curved_test, "curved-test", "beyond the paper",
       "a flat is refused when a quadric stabs clearly more of its neighbourhood's sticks", S::detect},
      {Pass::merge, "merge", "beyond the paper (Section 3's refinement)", "adjacent flats one plane stabs merged",
       S::detect, detail::merge_step},
      {Pass::junctions, "junctions", "Section 3", "flats extended to their sharp edges; junction points", S::detect,
       detail::junctions_step},
      {Pass::round_borders, "round-borders", "beyond the paper (Section 3's junctions)",
       "a chain of junctions between two flats, or a flat and a curved side, whose samples allow a fillet the "
       "lattice resolves is a smooth border",
       S::detect},
      {Pass::tangent_borders, "tangent-borders", "beyond the paper (Section 3's junctions)",
       "a would-be junction whose curved side continues the flat is a smooth border", S::detect},
      {Pass::ring_off_plane, "ring-off-plane", "beyond the paper (Section 3's junctions)",
       "the junction test's plane leaves out a rim stopped short of the crease", S::detect},
      {Pass::crease_refit, "crease-refit", "beyond the paper", "planes keep their creases' samples on their side", S::detect},
      {Pass::center_planes, "center-planes", "beyond the paper", "planes centred in their feasible set", S::detect},
      {Pass::rim_tangent, "rim-tangent", "beyond the paper", "a flat's rim gives back a tangent curved face (fillet)",
       S::detect, detail::rim_tangent_step, Pass::junctions},
      // ---- Stage::press (pressing.h)
      {Pass::free_ends, "free-ends", "Section 4, beyond the paper", "slice curves cut at barriers keep open ends", S::press},
      // ---- Stage::crease_round, after the first press (press_with_flats)
      {Pass::crease_fit, "crease-fit", "beyond the paper",
       "curved vertices next to a sharp flat border placed by the curved side's quadric, unless a sample denies the "
       "crease",
       S::crease_round,
       detail::crease_fit_step},
      {Pass::curved_creases, "curved-creases", "beyond the paper",
       "creases between two curved faces placed by both sides' quadrics (and sharpened)", S::crease_round,
       detail::curved_creases_step, Pass::crease_fit},
      {Pass::crease_network, "crease-network", "beyond the paper",
       "a crease between curved faces is kept only where it continues a flat's sharp border (off: wherever found)",
       S::crease_round},
      // ---- Stage::fit
      {Pass::quadric_fit, "quadric-fit", "beyond the paper", "curved vertices moved onto their local quadric", S::fit,
       detail::quadric_fit_step},
      // ---- Stage::sharpen (Sharpener::run)
      {Pass::snap, "snap", "beyond the paper", "curved bands the flats' solid explains slide onto the flats", S::sharpen,
       detail::snap_step},
      {Pass::leftovers, "leftovers", "beyond the paper", "curved patches too small for a face (chamfer leftovers) join a flat",
       S::sharpen, detail::leftovers_step},
      {Pass::strips, "strips", "beyond the paper", "thin curved strips between flats join a flat", S::sharpen},
      {Pass::rim_pockets, "rim-pockets", "beyond the paper",
       "a rim pocket joins its flat only where the plane crosses its stick", S::sharpen},
      {Pass::round_strips, "round-strips", "beyond the paper",
       "a strip between two flats whose samples allow a resolved fillet, unexplained by the flats, stays curved",
       S::sharpen},
      {Pass::inherit_junctions, "inherit-junctions", "beyond the paper",
       "the neighbours of a junction that joined a flat become junctions", S::sharpen, detail::inherit_junctions_step},
      {Pass::walls, "walls", "beyond the paper", "the rim of a thin plate gets its own plane", S::sharpen,
       detail::walls_step},
      {Pass::final_crease, "final-crease", "beyond the paper", "curved vertices at the final junctions placed again",
       S::sharpen, detail::final_crease_step},
      {Pass::past_crease, "past-crease", "beyond the paper", "vertices past their crease change sides", S::sharpen,
       detail::past_crease_step},
      {Pass::tangent_planes, "tangent-planes", "beyond the paper", "a curved side's plane is its quadric's tangent",
       S::sharpen},
      {Pass::final_curved_creases, "final-curved-creases", "beyond the paper",
       "creases between curved faces placed again on the final regions", S::sharpen, detail::final_curved_creases_step,
       Pass::curved_creases},
      {Pass::sharpen, "sharpen", "Section 5", "chamfer edges split (off: the whole sharpening, no sharp edges)",
       S::sharpen, detail::sharpen_step},
      {Pass::sample_wedges, "sample-wedges", "beyond the paper", "a chamfer's two planes agree with its samples",
       S::sharpen},
      {Pass::round_chains, "round-chains", "beyond the paper (Section 5's chains)",
       "a crease chain whose samples allow a fillet the lattice resolves stays round (issue 75)", S::sharpen,
       detail::round_chains_step},
      {Pass::moves, "moves", "Section 5", "new vertices moved onto their creases (checked), the chains smoothed",
       S::sharpen, detail::moves_step},
  };
  return passes;
}

bool runs(const PassInfo& p, const PassSet& on) {
  if (!on.on(p.pass) || (p.needs != Pass::count && !on.on(p.needs))) return false;
  if (p.stage != Stage::press && p.stage != Stage::fit && !on.on(Pass::flats)) return false;
  return p.stage != Stage::sharpen || on.on(Pass::sharpen);
}

namespace detail {

void run_stage(Stage stage, FeatureContext& ctx) {
  for (const PassInfo& p : feature_passes()) {
    if (p.stage != stage || !p.run || !runs(p, ctx.on)) continue;
    double recorded = 0;  // what the step records itself (its rules)
    for (double s : ctx.times.seconds) recorded += s;
    const auto t0 = std::chrono::steady_clock::now();
    const size_t count = p.run(ctx);
    const double seconds = seconds_since(t0);
    double after = 0;
    for (double s : ctx.times.seconds) after += s;
    ctx.times.add(p.pass, std::max(0.0, seconds - (after - recorded)), count);
    ctx.times.trace.push_back(p.pass);
  }
}

}  // namespace detail

const char* pass_name(Pass p) { return feature_passes()[size_t(p)].name; }

Pass parse_pass(const std::string& name) {
  std::string all;
  for (const PassInfo& p : feature_passes()) {
    if (name == p.name) return p.pass;
    all += std::string(all.empty() ? "" : ", ") + p.name;
  }
  throw UsageError("unknown pass '" + name + "' (expected " + all + ")");
}

std::vector<std::string> PassSet::disabled() const {
  std::vector<std::string> names;
  for (const PassInfo& p : feature_passes())
    if (!on(p.pass)) names.push_back(p.name);
  return names;
}

}  // namespace voxpress
