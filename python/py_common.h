// What the module's binding files share (private to python/).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>

#include "voxpress/voxpress.h"

namespace py = pybind11;

namespace voxpress::python {

/// A mesh and the statistics of the call that made it.
struct PyMesh {
  Mesh mesh;
  py::dict stats;
  /// The volume's lattice when the mesh was made from one (press): its
  /// samples keep their side when the mesh is simplified.
  std::optional<Lattice> lattice;
};
/// stats["simplify"] of a simplified mesh.
py::dict simplify_stats(const SimplifyStats& st);

/// A lattice of `dims` from press()'s spacing, origin and direction
/// arguments (validated: UsageError naming the bad one).
Lattice to_lattice(const std::array<int64_t, 3>& dims, const py::object& spacing, const py::object& origin,
                   const py::object& direction);
/// The array as a ScalarVolume on its lattice, x fastest whatever its memory
/// order; axes "xyz": a[i, j, k], "zyx": a[k, j, i].
ScalarVolume to_volume(const py::array& a, const py::object& spacing, const py::object& origin,
                       const py::object& direction, const std::string& axes);
/// label= / threshold= as a Selection (automatic when both are None).
Selection selection(const py::object& label, const py::object& threshold);
/// press()'s keyword options (iterations, tolerance, flats, ...).
void set_options(SurfaceOptions& o, const py::kwargs& kw);

/// press_labels()'s result: {label: Mesh}, and with `interfaces` (and a
/// shared surface) the tuple ({label: Mesh}, the interfaces' Mesh).
py::object labels_result(const std::vector<LabelInfo>& chosen, std::vector<Mesh> meshes, const std::vector<size_t>& flats,
                         bool keeps, const SharedLabels* shared, bool interfaces);
/// The chosen labels' closed meshes and flat counts, cut from the shared surface.
void cut_labels(const SharedLabels& r, const std::vector<LabelInfo>& chosen, std::vector<Mesh>& meshes,
                std::vector<size_t>& flats);
/// UsageError for the sharpening options, which the shared surface has not.
void check_shared_options(const py::kwargs& kw);
/// labels=: None (every label) or the values.
std::vector<double> label_values(const py::object& labels);
/// The Mesh class (mesh_py.cpp).
void bind_mesh(py::module_& m);
/// chunk_plan, _press_block, _stitch, _label_block, _press_label_blocks (chunk_py.cpp).
void bind_chunks(py::module_& m);
/// press(..., chunk=N): press_chunked on the in-memory volume.
PyMesh press_chunked_volume(const ScalarVolume& scalar, const Selection& sel, const SurfaceOptions& o,
                            const ChunkOptions& chunks);

}  // namespace voxpress::python
