// Label volumes shared by the label-map tests: an empty map, a phantom of
// nested and touching solids where three and four labels meet, and an
// assembly of two boxes (flats).
#pragma once

#include <cmath>

#include "voxpress/voxpress.h"

namespace voxpress::test {

inline ScalarVolume label_volume(std::array<int64_t, 3> dims, Vec3 spacing = {1, 1, 1}) {
  ScalarVolume v;
  v.lattice.dims = dims;
  v.lattice.spacing = spacing;
  v.lattice.origin = Vec3(-12.5, 40.25, 7);
  v.type = ScalarType::u8;
  v.bytes.assign(v.lattice.size(), std::byte{0});
  v.source = "test-labels";
  return v;
}

inline void set(ScalarVolume& v, int64_t i, int64_t j, int64_t k, int value) {
  v.bytes[v.lattice.linear(i, j, k)] = std::byte(uint8_t(value));
}
inline int get(const ScalarVolume& v, int64_t i, int64_t j, int64_t k) { return int(v.bytes[v.lattice.linear(i, j, k)]); }

// Nested and touching solids: a box (1) with a sphere (2) pressed against
// it, a sphere (3) nested in the sphere, a slab (4) touching box and sphere
// so that three and four labels meet; rotated, anisotropic spacing.
inline ScalarVolume phantom() {
  ScalarVolume v = label_volume({44, 40, 30}, {1, 1.2, 1.5});
  const double c = std::cos(0.4), s = std::sin(0.4);
  for (int64_t k = 0; k < 30; ++k)
    for (int64_t j = 0; j < 40; ++j)
      for (int64_t i = 0; i < 44; ++i) {
        const double x0 = i - 22.0, y0 = (j - 20.0) * 1.2, z = (k - 15.0) * 1.5;
        const double x = c * x0 - s * y0, y = s * x0 + c * y0;
        int label = 0;
        if (std::abs(x + 8) < 7 && std::abs(y) < 9 && std::abs(z) < 8) label = 1;
        if ((x - 6) * (x - 6) + y * y + z * z < 12 * 12) label = 2;
        if ((x - 7) * (x - 7) + y * y + z * z < 5 * 5) label = 3;
        if (label == 0 && y > 9 && y < 13 && std::abs(z) < 10 && std::abs(x) < 16) label = 4;
        set(v, i, j, k, label);
      }
  return v;
}

inline BinaryVolume whole_mask(const ScalarVolume& v, double value) {
  Selection s;
  s.kind = Selection::Kind::label;
  s.value = value;
  return binarize(v, s);
}

// Three labels in a checkerboard: label (i + j_step * j + k) % 3 + first.
inline ScalarVolume checkerboard3(std::array<int64_t, 3> dims, int64_t j_step = 1, int first = 1) {
  ScalarVolume v = label_volume(dims);
  for (int64_t k = 0; k < dims[2]; ++k)
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i) set(v, i, j, k, int((i + j_step * j + k) % 3) + first);
  return v;
}

// An assembly of two boxes sharing a face (labels 1 and 2), rotated,
// anisotropic; its true surfaces are the two boxes'. Faces of 18-25 cells:
// the detection needs more than the 12-16 of a 40^3 box (none found there).
struct Assembly {
  ScalarVolume volume;
  Mat3 rotation;
  Vec3 centre;
  // Signed distance to box `label` (1 or 2), physical units.
  double distance(int label, const Vec3& p) const {
    const Vec3 q = rotation.transpose() * (p - centre) - 1.6 * Vec3(label == 1 ? -7 : 6, 0, 0);
    const Vec3 h = 1.6 * (label == 1 ? Vec3(7, 8, 7) : Vec3(6, 7, 6));
    const Vec3 d = q.cwiseAbs() - h;
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
};
inline Assembly assembly(int seed) {
  Assembly a;
  a.volume = label_volume({64, 64, 52}, {1, 1, 1.25});
  a.rotation = parse_rotation("random:" + std::to_string(seed));
  a.centre = a.volume.lattice.to_physical(Vec3(31.5, 31.5, 25.5));
  for (int64_t k = 0; k < 52; ++k)
    for (int64_t j = 0; j < 64; ++j)
      for (int64_t i = 0; i < 64; ++i) {
        const Vec3 p = a.volume.lattice.to_physical(Vec3(double(i), double(j), double(k)));
        set(a.volume, i, j, k, a.distance(1, p) < 0 ? 1 : a.distance(2, p) < 0 ? 2 : 0);
      }
  return a;
}

}  // namespace voxpress::test
