// voxpress/features/passes.h — the feature layer as a declared list of
// passes, in the order they run, each with the paper section it implements
// (Pressing, Chica et al.) or "beyond the paper".
//
// Every pass can be switched off on its own (`voxpress press --disable-pass
// NAME`, Python `disable_passes=[...]`): that is the one ablation switch,
// bench/ablation runs it over passes x cases. Switching off a pass that
// others build on switches those off too (`flats` is the whole layer,
// `sharpen` everything after the press). The per-pass times and counts are
// in `--stats-json` ("passes").
#pragma once

#include <bitset>
#include <cstdint>
#include <string>
#include <vector>

namespace voxpress {

enum class Pass : uint8_t {
  flats,              // Section 3: estimate, plane voting, greedy growth, refinement, junctions
  stab_refit,         // beyond: core planes refit by the sticks they stab (faces near a lattice axis)
  curved_test,        // beyond: a flat whose neighbourhood a quadric explains better is refused
  merge,              // beyond: adjacent flats one plane stabs become one
  tangent_borders,    // beyond: a would-be junction whose curved side continues the flat is a smooth border
  ring_off_plane,     // beyond: the junction test's 2-ring plane leaves out a rim stopped short
  rim_tangent,        // beyond: the rim leaves a tangent curved face (fillets)
  crease_refit,       // beyond: planes also keep their creases' samples on their side
  center_planes,      // beyond: each plane moves to the centre of its feasible set
  crease_fit,         // beyond: curved vertices next to a junction placed by the curved side's quadric
  curved_creases,     // beyond: creases between two curved faces placed and sharpened
  crease_network,     // beyond: ... only where they continue a flat's crease (evidence)
  free_ends,          // beyond (Section 4): slice curves cut at barriers keep open, clamped ends
  quadric_fit,        // beyond: curved vertices moved onto their neighbourhood's quadric after pressing
  sharpen,            // Section 5: chamfer edges split, new vertices moved onto the creases
  snap,               // beyond: curved bands the flats' solid explains slide onto the flats
  strips,             // beyond: thin curved strips between flats join a flat
  rim_pockets,        // beyond: a pocket of a rim joins its flat only where the plane crosses its stick
  walls,              // beyond: the rim of a thin plate gets its own plane (both edges sharpened)
  tangent_planes,     // beyond: a curved side's plane is its quadric's tangent plane
  final_crease,       // beyond: curved vertices next to the final junctions placed again
  past_crease,        // beyond: vertices on the wrong side of a crease change sides
  inherit_junctions,  // beyond: a curved junction that joined a flat passes the border on
  sample_wedges,      // beyond: a chamfer's two planes must agree with its sticks' samples
  round_chains,       // beyond (Section 5's chains): a chain whose samples allow a resolved rounding stays round
  count
};

struct PassInfo {
  Pass pass;
  const char* name;     // as --disable-pass spells it
  const char* section;  // "Section 3", "beyond the paper", ...
  const char* what;
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

/// Seconds and a count per pass, for --stats-json (a pass not run stays 0).
struct PassTimes {
  double seconds[size_t(Pass::count)] = {};
  size_t count[size_t(Pass::count)] = {};
  void add(Pass p, double s, size_t n = 0) {
    seconds[size_t(p)] += s;
    count[size_t(p)] += n;
  }
  void add(const PassTimes& other) {
    for (size_t p = 0; p < size_t(Pass::count); ++p) add(Pass(p), other.seconds[p], other.count[p]);
  }
};

}  // namespace voxpress
