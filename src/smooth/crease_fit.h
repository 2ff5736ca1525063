// Private helper of fit_creases (press time) and of sharpen's final crease fit:
// where the sticks near a sharp flat/curved border leave the piecewise solid
// of the flat's half-space and the curved side's quadric (index space).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "voxpress/core/types.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/smooth/flats.h"

namespace voxpress::detail {

struct CreaseFit {
  int rings;              // the zone: curved vertices up to this many rings (over curved vertices) from a junction
  int fit_rings;          // the quadric's points: curved vertices beyond the zone, within rings + fit_rings of the vertex
  double residual;        // largest RMS residual of a trusted fit (cells)
  double margin;          // t kept in [margin, 1 - margin]
  double max_move = 1;    // farthest a vertex may move along its stick (cells; 1: no limit)
};

// The zone's new stick parameters (from the inside sample, 0, to the outside
// one, 1), in vertex order: sticks = the surface whose sticks the vertices
// lie on, region = flat id or -1 per vertex, junction = junction flags, x =
// positions (index space), off / adj = the vertex adjacency. A junction is
// a curved vertex with a junction flag and a flat neighbour; each zone
// vertex takes the flat of the junction it was reached from.
std::vector<std::pair<uint32_t, double>> crease_targets(const StickSurface& sticks, const std::vector<Flat>& flats,
                                                        const std::vector<int32_t>& region,
                                                        const std::vector<uint8_t>& junction,
                                                        const std::vector<Vec3>& x, const std::vector<uint32_t>& off,
                                                        const std::vector<uint32_t>& adj, const CreaseFit& c);

}  // namespace voxpress::detail
