// The Mesh class of the Python module: arrays out without copies, the
// regions, label pairs and sharp edges, saving, and Mesh.simplify (private
// to python/).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "py_common.h"

namespace voxpress::python {

namespace {

py::array_t<int32_t> int_rows(const std::vector<std::array<uint32_t, 3>>& rows) {
  py::array_t<int32_t> a({py::ssize_t(rows.size()), py::ssize_t(3)});
  auto m = a.mutable_unchecked<2>();
  for (size_t r = 0; r < rows.size(); ++r)
    for (int c = 0; c < 3; ++c) m(py::ssize_t(r), c) = int32_t(rows[r][size_t(c)]);
  return a;
}

}  // namespace

py::dict simplify_stats(const SimplifyStats& st) {
  py::dict d;
  d["faces_before"] = st.faces_before;
  d["faces"] = st.faces_after;
  d["vertices"] = st.vertices_after;
  d["collapses"] = st.collapses;
  d["error"] = st.error;
  d["seconds"] = st.seconds;
  return d;
}

void bind_mesh(py::module_& m) {
  py::class_<PyMesh>(m, "Mesh", "A triangle mesh in physical units, triangles counter-clockwise seen from outside.")
      .def_property_readonly("vertices", [](py::object self) {
        PyMesh& pm = self.cast<PyMesh&>();
        return py::array_t<double>({py::ssize_t(pm.mesh.vertex_count()), py::ssize_t(3)},
                                   {py::ssize_t(sizeof(Vec3)), py::ssize_t(sizeof(double))},
                                   pm.mesh.positions.empty() ? nullptr : pm.mesh.positions[0].data(), self);
      }, "N x 3 float64 view of the positions (no copy)")
      .def_property_readonly("faces", [](const PyMesh& pm) { return int_rows(pm.mesh.triangles); }, "M x 3 int32")
      .def_property_readonly("regions", [](const PyMesh& pm) -> py::object {
        const MeshAttribute* a = pm.mesh.face_attribute("region");
        if (!a) return py::none();
        py::array_t<int32_t> r(py::ssize_t(a->values.size()));
        for (size_t i = 0; i < a->values.size(); ++i) r.mutable_at(py::ssize_t(i)) = int32_t(a->values[i]);
        return r;
      }, "per face: flat id, -1 curved (None without flats)")
      .def_property_readonly("label_pairs", [](const PyMesh& pm) -> py::object {
        const MeshAttribute* a = pm.mesh.face_attribute("label_in");
        const MeshAttribute* b = pm.mesh.face_attribute("label_out");
        if (!a || !b) return py::none();
        py::array_t<int64_t> r({py::ssize_t(a->values.size()), py::ssize_t(2)});
        auto w = r.mutable_unchecked<2>();
        for (size_t i = 0; i < a->values.size(); ++i) w(py::ssize_t(i), 0) = int64_t(a->values[i]), w(py::ssize_t(i), 1) = int64_t(b->values[i]);
        return r;
      }, "per face of a shared surface: (inside, outside) labels, the normal pointing from the first to the second "
         "(None otherwise)")
      .def_property_readonly("sharp_edges", [](const PyMesh& pm) {
        py::array_t<int32_t> a({py::ssize_t(pm.mesh.edges.size()), py::ssize_t(2)});
        auto w = a.mutable_unchecked<2>();
        for (size_t i = 0; i < pm.mesh.edges.size(); ++i)
          for (int c = 0; c < 2; ++c) w(py::ssize_t(i), c) = int32_t(pm.mesh.edges[i][size_t(c)]);
        return a;
      }, "K x 2 int32 vertex pairs of the sharp feature curves")
      .def_readonly("stats", &PyMesh::stats, "what the call did: method, counts, iterations, seconds")
      .def("simplify", [](const PyMesh& pm, uint64_t faces, double max_error) {
        PyMesh out;
        out.mesh = pm.mesh;
        out.lattice = pm.lattice;
        SimplifyOptions o;
        o.faces = faces;
        o.max_error = max_error;
        o.lattice = pm.lattice ? &*pm.lattice : nullptr;
        if (!(max_error >= 0) || !std::isfinite(max_error)) throw UsageError("max_error must be finite and >= 0");
        SimplifyStats st;
        {
          py::gil_scoped_release release;
          st = simplify(out.mesh, o);
        }
        out.stats = py::dict(pm.stats);
        out.stats["vertices"] = out.mesh.vertex_count();
        out.stats["triangles"] = out.mesh.face_count();
        out.stats["sharp_edges"] = out.mesh.edges.size();
        out.stats["simplify"] = simplify_stats(st);
        return out;
      }, py::kw_only(), py::arg("faces") = 0, py::arg("max_error") = 0.0,
         "A simplified copy (see voxpress/__init__.pyi)")
      .def("save", [](const PyMesh& pm, const std::string& path, bool ascii) {
        MeshWriteOptions o;
        o.ascii = ascii;
        py::gil_scoped_release release;
        write_mesh(path, pm.mesh, o);
      }, py::arg("path"), py::arg("ascii") = false, "Writes .ply .obj .stl .off .glb .gltf (atomically)")
      .def("__repr__", [](const PyMesh& pm) {
        return "Mesh(" + std::to_string(pm.mesh.vertex_count()) + " vertices, " + std::to_string(pm.mesh.face_count()) +
               " triangles)";
      });
}

}  // namespace voxpress::python
