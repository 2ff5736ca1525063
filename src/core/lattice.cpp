#include "voxpress/core/lattice.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "voxpress/core/error.h"

namespace voxpress {

const char* space_name(Space s) {
  switch (s) {
    case Space::LPS: return "LPS";
    case Space::RAS: return "RAS";
    default: return "unknown";
  }
}

uint64_t Lattice::size() const { return uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]); }

Mat3 Lattice::index_to_physical_matrix() const { return direction * spacing.asDiagonal(); }

Vec3 Lattice::to_physical(const Vec3& ijk) const { return origin + index_to_physical_matrix() * ijk; }

Vec3 Lattice::to_index(const Vec3& p) const { return index_to_physical_matrix().inverse() * (p - origin); }

bool Lattice::flips_orientation() const { return index_to_physical_matrix().determinant() < 0; }

void Lattice::validate() const {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1)
      throw UsageError("invalid dimension along axis " + std::to_string(a) + ": " + std::to_string(dims[a]));
    // Physical units from picometres to megametres in millimetres: beyond,
    // areas and volumes overflow or lose all precision.
    if (!(spacing[a] >= 1e-12 && spacing[a] <= 1e12))
      throw UsageError("lattice spacing along axis " + std::to_string(a) + " must be in [1e-12, 1e12], not " +
                       (std::ostringstream() << spacing[a]).str());
    if (!(std::abs(origin[a]) <= 1e15)) throw UsageError("lattice origin must be finite and within 1e15");
  }
  if (!direction.allFinite() || std::abs(index_to_physical_matrix().determinant()) < 1e-300)
    throw UsageError("lattice direction matrix is singular or not finite");
}

Lattice box_lattice(const Lattice& volume, const Box& box) {
  Lattice l = volume;
  l.dims = box.dims();
  l.origin = volume.to_physical(Vec3(double(box.lo[0]), double(box.lo[1]), double(box.lo[2])));
  return l;
}

}  // namespace voxpress
