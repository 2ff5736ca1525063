// What the legacy (.vtk) and XML (.vtp) readers and writers share (private):
// VTK's type names, raw value coding, and the arrays and cells a reader
// gathers before they become a Mesh.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/volume.h"

namespace voxpress::detail {

/// A type by its legacy ("unsigned_int") or XML ("UInt32") name; InputError otherwise.
ScalarType vtk_type(const std::string& path, const std::string& name, bool xml);
const char* vtk_type_name(ScalarType t, bool xml);
/// `count` values of type t from raw bytes, byte-swapped when `swap`.
std::vector<double> vtk_decode(const std::byte* p, uint64_t count, ScalarType t, bool swap);
/// Appends x as type t to buf, big-endian when `big`.
void vtk_put(std::string& buf, ScalarType t, double x, bool big);

struct VtkArray {
  std::string name;
  ScalarType type = ScalarType::f64;
  int64_t comps = 1;
  std::vector<double> values;
  bool normals = false, colors = false;  ///< marked as the normals / the colours
};
struct VtkCells {
  std::vector<int64_t> offsets{0}, ids;
  size_t count() const { return offsets.size() - 1; }
};
struct VtkData {
  std::vector<double> points;  ///< 3 per point
  VtkCells verts, lines, polys, strips;
  std::vector<VtkArray> point, cell;  ///< cell data: verts, lines, polys, strips in that order
};

/// Cells from a legacy 4.x list ([k, ids...] per cell).
VtkCells vtk_cells_from_list(const std::string& path, const std::vector<double>& list, uint64_t count);
/// Cells from offsets (with or without the leading 0) and connectivity.
VtkCells vtk_cells_from_offsets(const std::string& path, const std::vector<double>& offsets,
                                const std::vector<double>& ids, bool leading_zero);
/// Triangles (polygons fanned, strips unrolled; cell data copied to each),
/// normals, colours and one-component arrays as attributes; validated.
Mesh vtk_to_mesh(const std::string& path, VtkData& data);

}  // namespace voxpress::detail
