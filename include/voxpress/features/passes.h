// voxpress/features/passes.h — the feature layer as one declared table of
// passes, in the order they run, each with the paper section it implements
// (Pressing, Chica et al.) or "beyond the paper", its stage, and its step.
// One driver (features/feature_context.h, run_stage) runs a stage's steps
// in table order over the stage's context, times and counts each, and
// records the trace; adding a pass is one file with its step plus one row.
// A rule is a decision inside a pass: it has a row (so it can be switched
// off and counted) but no step.
//
// Every pass can be switched off on its own (`voxpress press --disable-pass
// NAME`, Python `disable_passes=[...]`): that is the one ablation switch,
// bench/ablation runs it over passes x cases. Switching off a pass that
// others build on switches those off too (`flats` is the whole layer,
// `sharpen` the whole sharpening; `needs` in the table). The per-pass times
// and counts are in `--stats-json` ("passes").
#pragma once

#include <bitset>
#include <cstdint>
#include <string>
#include <vector>

namespace voxpress {

/// Where a pass runs. The feature layer is a fixed sequence of stages:
/// detection (Section 3; once per estimate), the presses, the crease rounds
/// (after the first press), the quadric fit, and the sharpening (Section
/// 5). Within a stage one driver runs the stage's passes in table order.
enum class Stage : uint8_t { detect, press, crease_round, fit, sharpen };

/// The passes and rules, in the table's order (feature_passes()). A rule is
/// a decision inside a pass (it has no step of its own).
enum class Pass : uint8_t {
  // Stage::detect (Section 3)
  flats,                 // votes and greedy growth (off: the whole feature layer)
  stab_refit,            // rule: core planes refit by the sticks they stab (faces near a lattice axis)
  curved_test,           // rule: a flat whose neighbourhood a quadric explains better is refused
  merge,                 // beyond: adjacent flats one plane stabs become one
  junctions,             // flats extended to their sharp edges; junction points
  round_borders,         // rule: a junction chain whose samples allow a resolved fillet is a smooth border
  tangent_borders,       // rule: a would-be junction whose curved side continues the flat is a smooth border
  ring_off_plane,        // rule: the junction test's 2-ring plane leaves out a rim stopped short
  crease_refit,          // rule: planes also keep their creases' samples on their side
  center_planes,         // rule: each plane moves to the centre of its feasible set
  rim_tangent,           // beyond: the rim leaves a tangent curved face (fillets)
  // Stage::press
  free_ends,             // rule (Section 4): slice curves cut at barriers keep open, clamped ends
  // Stage::crease_round
  crease_fit,            // beyond: curved vertices next to a junction placed by the curved side's quadric
  curved_creases,        // beyond: creases between two curved faces placed (and sharpened)
  crease_network,        // rule: ... only where they continue a flat's crease (evidence)
  // Stage::fit
  quadric_fit,           // beyond: curved vertices moved onto their neighbourhood's quadric
  // Stage::sharpen (Section 5)
  snap,                  // beyond: curved bands the flats' solid explains slide onto the flats
  leftovers,             // beyond: curved patches too small for a face (chamfer leftovers) join a flat
  strips,                // rule: ... and so do thin curved strips between flats
  rim_pockets,           // rule: a pocket of a rim joins its flat only where the plane crosses its stick
  round_strips,          // rule: a strip between two flats whose samples allow a resolved fillet stays curved
  inherit_junctions,     // beyond: a curved junction that joined a flat passes the border on
  walls,                 // beyond: the rim of a thin plate gets its own plane (both edges sharpened)
  final_crease,          // beyond: curved vertices next to the final junctions placed again
  past_crease,           // beyond: vertices on the wrong side of a crease change sides
  tangent_planes,        // rule: a curved side's plane is its quadric's tangent plane
  final_curved_creases,  // beyond: creases between curved faces placed again on the final regions
  sharpen,               // Section 5: chamfer edges split (off: the whole sharpening)
  sample_wedges,         // rule: a chamfer's two planes must agree with its sticks' samples
  round_chains,          // beyond (Section 5's chains): a chain whose samples allow a resolved rounding stays round
  moves,                 // Section 5: new vertices moved onto their creases, chains smoothed
  count
};

namespace detail {
struct FeatureContext;  // features/feature_context.h: the stages' state
}

struct PassInfo {
  Pass pass;
  const char* name;     // as --disable-pass spells it
  const char* section;  // "Section 3", "beyond the paper", ...
  const char* what;
  Stage stage;
  /// The pass's step, run by the stage's driver; null for a rule.
  size_t (*run)(detail::FeatureContext&) = nullptr;
  /// Also needed on for the step to run (Pass::count: none beyond its stage's).
  Pass needs = Pass::count;
};

/// Every pass, in running order.
const std::vector<PassInfo>& feature_passes();
/// Name of a pass (feature_passes()[p].name).
const char* pass_name(Pass p);
/// Inverse of pass_name; throws UsageError listing the valid names.
Pass parse_pass(const std::string& name);

/// Which passes run (all by default).
class PassSet {
 public:
  bool on(Pass p) const { return !off_[size_t(p)]; }
  void disable(Pass p) { off_[size_t(p)] = true; }
  void disable(const std::string& name) { disable(parse_pass(name)); }
  /// Names of the disabled passes, in running order.
  std::vector<std::string> disabled() const;

 private:
  std::bitset<size_t(Pass::count)> off_;
};

/// Seconds and a count per pass, for --stats-json (a pass not run stays 0),
/// and the steps run, in order (the driver's trace).
struct PassTimes {
  double seconds[size_t(Pass::count)] = {};
  size_t count[size_t(Pass::count)] = {};
  std::vector<Pass> trace;
  void add(Pass p, double s, size_t n = 0) {
    seconds[size_t(p)] += s;
    count[size_t(p)] += n;
  }
  void add(const PassTimes& other) {
    for (size_t p = 0; p < size_t(Pass::count); ++p) add(Pass(p), other.seconds[p], other.count[p]);
    trace.insert(trace.end(), other.trace.begin(), other.trace.end());
  }
};

/// The passes a stage's driver runs with these switches: on, with what they
/// need, and their stage's gates on (every stage but the press and the fit
/// needs `flats`; the sharpening `sharpen`).
bool runs(const PassInfo& p, const PassSet& on);

}  // namespace voxpress
