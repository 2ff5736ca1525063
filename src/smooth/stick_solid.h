// Private: where a stick leaves a solid bounded by a plane or a quadric,
// the one crossing primitive of the feature layer and the quadric fit.
//
// Convention everywhere: t runs along the stick from its inside sample
// (t = 0) to its outside sample (t = 1); a surface's solid is below it
// (a plane's half-space n . p < c, a quadric's z < h). StickSurface stores t
// from the lower sample instead (StickSurface::lower_inside converts).
#pragma once

#include <cmath>
#include <limits>

#include "quadric.h"
#include "surface_graph.h"

namespace voxpress::detail {

// Where the segment in -> out leaves the half-space below P: its crossing
// (not clamped: outside [0, 1] when both samples are on one side) when it
// runs outwards through the plane; +inf when the whole line lies below a
// plane it does not climb (it never leaves), -inf when it lies wholly above
// one (it is never in); NaN when it enters the half-space on its way out.
// `leave_heights` takes the two samples' heights over the plane when the
// caller has them.
inline double leave_heights(double hi, double ho) {
  if (ho > hi) return -hi / (ho - hi);
  if (hi < 0) return INFINITY;
  if (ho > 0) return -INFINITY;
  return std::numeric_limits<double>::quiet_NaN();
}
inline double leave(const Plane& P, const Vec3& in, const Vec3& out) {
  return leave_heights(P.n.dot(in) - P.c, P.n.dot(out) - P.c);
}

// The same for a quadric: the exit nearest `near` within the stick's
// extension [-1, 2]; a line that never crosses it is inside (+inf) or
// outside (-inf) all along; NaN when the samples straddle it without an
// outward crossing there.
inline double leave(const Quadric& Q, const Vec3& in, const Vec3& out, double near) {
  const double t = Q.exit(in, out, near, -1, 2);
  if (!std::isnan(t)) return t;
  const double gi = Q.height_above(in), go = Q.height_above(out);
  if (gi < 0 && go < 0) return INFINITY;
  if (gi > 0 && go > 0) return -INFINITY;
  return t;
}

// Whether P stabs the stick with the margin: its crossing when it lies in
// [margin, 1 - margin] (so the inside sample is below the plane and the
// outside one above), NaN otherwise.
inline double stab(const Plane& P, const Vec3& in, const Vec3& out, double margin) {
  const double t = leave(P, in, out);
  return t >= margin && t <= 1 - margin ? t : std::numeric_limits<double>::quiet_NaN();
}

// The same for a quadric: its exit nearest `near` within the margins.
inline double stab(const Quadric& Q, const Vec3& in, const Vec3& out, double near, double margin) {
  return Q.exit(in, out, near, margin, 1 - margin);
}

}  // namespace voxpress::detail
