// The feature layer's pass table. Theory of operation:
// include/voxpress/features/passes.h.
#include "voxpress/features/passes.h"

#include "voxpress/core/error.h"

namespace voxpress {

const std::vector<PassInfo>& feature_passes() {
  static const std::vector<PassInfo> passes = {
      {Pass::flats, "flats", "Section 3",
       "flats by plane voting and greedy growth, junctions and barriers (off: the whole feature layer)"},
      {Pass::stab_refit, "stab-refit", "beyond the paper", "core planes refit by the count of sticks they stab"},
      {Pass::curved_test, "curved-test", "beyond the paper",
       "a flat is refused when a quadric stabs clearly more of its neighbourhood's sticks"},
      {Pass::merge, "merge", "beyond the paper (Section 3's refinement)", "adjacent flats one plane stabs merged"},
      {Pass::tangent_borders, "tangent-borders", "beyond the paper (Section 3's junctions)",
       "a would-be junction whose curved side continues the flat is a smooth border"},
      {Pass::ring_off_plane, "ring-off-plane", "beyond the paper (Section 3's junctions)",
       "the junction test's plane leaves out a rim stopped short of the crease"},
      {Pass::rim_tangent, "rim-tangent", "beyond the paper", "a flat's rim gives back a tangent curved face (fillet)"},
      {Pass::crease_refit, "crease-refit", "beyond the paper", "planes keep their creases' samples on their side"},
      {Pass::center_planes, "center-planes", "beyond the paper", "planes centred in their feasible set"},
      {Pass::crease_fit, "crease-fit", "beyond the paper",
       "curved vertices next to a sharp flat border placed by the curved side's quadric"},
      {Pass::curved_creases, "curved-creases", "beyond the paper",
       "creases between two curved faces placed by both sides' quadrics and sharpened"},
      {Pass::crease_network, "crease-network", "beyond the paper",
       "a crease between curved faces is kept only where it continues a flat's sharp border (off: wherever found)"},
      {Pass::free_ends, "free-ends", "Section 4, beyond the paper", "slice curves cut at barriers keep open ends"},
      {Pass::quadric_fit, "quadric-fit", "beyond the paper", "curved vertices moved onto their local quadric"},
      {Pass::sharpen, "sharpen", "Section 5", "chamfers split and moved onto the creases (off: no sharp edges)"},
      {Pass::snap, "snap", "beyond the paper", "curved bands the flats' solid explains slide onto the flats"},
      {Pass::strips, "strips", "beyond the paper", "thin curved strips between flats join a flat"},
      {Pass::rim_pockets, "rim-pockets", "beyond the paper",
       "a rim pocket joins its flat only where the plane crosses its stick"},
      {Pass::walls, "walls", "beyond the paper", "the rim of a thin plate gets its own plane"},
      {Pass::tangent_planes, "tangent-planes", "beyond the paper", "a curved side's plane is its quadric's tangent"},
      {Pass::final_crease, "final-crease", "beyond the paper", "curved vertices at the final junctions placed again"},
      {Pass::past_crease, "past-crease", "beyond the paper", "vertices past their crease change sides"},
      {Pass::inherit_junctions, "inherit-junctions", "beyond the paper",
       "the neighbours of a junction that joined a flat become junctions"},
      {Pass::sample_wedges, "sample-wedges", "beyond the paper", "a chamfer's two planes agree with its samples"},
      {Pass::round_chains, "round-chains", "beyond the paper (Section 5's chains)",
       "a crease chain whose samples allow a fillet the lattice resolves stays round (issue 75)"},
  };
  return passes;
}

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
