// The voxpress Python module (pybind11): numpy masks in, meshes out, over
// the same library calls as the CLI (smooth_surface, read_volume, check_*,
// evaluate), so results and error messages are the CLI's. The GIL is
// released while the library works.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>

#include "voxpress/eval/metrics.h"
#include "voxpress/eval/truth.h"
#include "voxpress/voxpress.h"

#include "py_common.h"

using namespace voxpress;

namespace voxpress::python {

ScalarType scalar_type(const py::dtype& d) {
  const char kind = d.kind();
  const size_t size = size_t(d.itemsize());
  if (kind == 'b') return ScalarType::u8;
  if (kind == 'u') {
    if (size == 1) return ScalarType::u8;
    if (size == 2) return ScalarType::u16;
    if (size == 4) return ScalarType::u32;
    if (size == 8) return ScalarType::u64;
  }
  if (kind == 'i') {
    if (size == 1) return ScalarType::i8;
    if (size == 2) return ScalarType::i16;
    if (size == 4) return ScalarType::i32;
    if (size == 8) return ScalarType::i64;
  }
  if (kind == 'f') {
    if (size == 4) return ScalarType::f32;
    if (size == 8) return ScalarType::f64;
  }
  throw UsageError("mask dtype " + std::string(py::str(static_cast<const py::handle&>(d))) + " is not supported (bool, integer or float32/64)");
}

Vec3 vec3(const py::object& o, const char* what) {
  // A string is a sequence too (of characters): refuse it by name.
  std::vector<double> v;
  if (py::isinstance<py::str>(o) || !py::isinstance<py::sequence>(o))
    throw UsageError(std::string(what) + " must be a sequence of 3 numbers, not " +
                     std::string(py::str(py::type::of(o).attr("__name__"))));
  try {
    v = o.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw UsageError(std::string(what) + " must be a sequence of 3 numbers");
  }
  if (v.size() != 3) throw UsageError(std::string(what) + " must have 3 values");
  return {v[0], v[1], v[2]};
}

Lattice to_lattice(const std::array<int64_t, 3>& dims, const py::object& spacing, const py::object& origin,
                   const py::object& direction) {
  Lattice l;
  l.dims = dims;
  l.spacing = vec3(spacing, "spacing");
  l.origin = vec3(origin, "origin");
  if (!direction.is_none()) {
    const auto m = direction.cast<std::vector<std::vector<double>>>();
    if (m.size() != 3 || m[0].size() != 3 || m[1].size() != 3 || m[2].size() != 3)
      throw UsageError("direction must be a 3x3 matrix (columns: the physical directions of the array axes)");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) l.direction(r, c) = m[size_t(r)][size_t(c)];
  }
  l.validate();
  return l;
}

// The array as a ScalarVolume on its lattice: x fastest, whatever its
// memory order. axes "xyz": a[i, j, k]; "zyx": a[k, j, i] (SimpleITK).
ScalarVolume to_volume(const py::array& a, const py::object& spacing, const py::object& origin,
                       const py::object& direction, const std::string& axes) {
  if (a.ndim() != 3) throw UsageError("the mask must be a 3-D array (got " + std::to_string(a.ndim()) + " dimensions)");
  if (axes != "xyz" && axes != "zyx") throw UsageError("axes must be 'xyz' or 'zyx' (got '" + axes + "')");
  ScalarVolume v;
  v.type = scalar_type(a.dtype());
  v.source = "array";
  const bool zyx = axes == "zyx";
  std::array<py::ssize_t, 3> stride{};
  for (int d = 0; d < 3; ++d) {
    const int src = zyx ? 2 - d : d;
    v.lattice.dims[size_t(d)] = int64_t(a.shape(src));
    stride[size_t(d)] = a.strides(src);
  }
  v.lattice = to_lattice(v.lattice.dims, spacing, origin, direction);
  const size_t item = size_t(a.itemsize());
  v.bytes.resize(size_t(v.lattice.size()) * item);
  const auto* src = static_cast<const std::byte*>(a.data());
  const int64_t nx = v.lattice.dims[0], ny = v.lattice.dims[1], nz = v.lattice.dims[2];
  std::byte* out = v.bytes.data();
  if (stride[0] == py::ssize_t(item) && stride[1] == py::ssize_t(item) * nx && stride[2] == py::ssize_t(item) * nx * ny) {
    std::memcpy(out, src, v.bytes.size());  // already x fastest and contiguous (Fortran order, or zyx C order)
  } else {
    // Gather in x-fastest order: a y row per task, in 32 x 32 (z, x) tiles
    // so that both the source's fast axis and the output's stay in cache
    // (a C-ordered [i, j, k] array is a transpose of x and z).
    auto gather = [&](auto tag) {
      using T = decltype(tag);
      T* dst = reinterpret_cast<T*>(out);
      constexpr int64_t kTile = 32;
      tbb::parallel_for(int64_t(0), ny, [&](int64_t j) {
        for (int64_t k0 = 0; k0 < nz; k0 += kTile)
          for (int64_t i0 = 0; i0 < nx; i0 += kTile)
            for (int64_t k = k0; k < std::min(nz, k0 + kTile); ++k) {
              T* row = dst + (k * ny + j) * nx;
              const std::byte* p = src + j * stride[1] + k * stride[2];
              for (int64_t i = i0; i < std::min(nx, i0 + kTile); ++i) std::memcpy(row + i, p + i * stride[0], sizeof(T));
            }
      });
    };
    switch (item) {
      case 1: gather(uint8_t{}); break;
      case 2: gather(uint16_t{}); break;
      case 4: gather(uint32_t{}); break;
      default: gather(uint64_t{}); break;
    }
  }
  return v;
}

Selection selection(const py::object& label, const py::object& threshold) {
  if (!label.is_none() && !threshold.is_none()) throw UsageError("choose one of label and threshold");
  Selection s;
  if (!label.is_none()) s = parse_label_selection(py::str(label));
  if (!threshold.is_none()) {
    s.kind = Selection::Kind::threshold;
    s.value = threshold.cast<double>();
  }
  return s;
}

// A keyword's value as T, or the library's UsageError naming it: nan, 10**30
// or a string raised pybind11's bare cast RuntimeError (issue 73).
template <class T>
T option(const std::string& k, const py::handle& value) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw UsageError(k + "= must be " +
                     (std::is_same_v<T, int> ? "a whole number from 0 to 2147483647"
                      : std::is_same_v<T, bool> ? "True or False"
                                                : "a number") +
                     ", not " + std::string(py::repr(value)));
  }
}

void set_options(SurfaceOptions& o, const py::kwargs& kw) {
  for (const auto& [key, value] : kw) {
    const std::string k = py::str(key);
    if (k == "iterations") o.overrides.iterations = option<int>(k, value);
    else if (k == "tolerance") o.overrides.tolerance = option<double>(k, value);
    else if (k == "flats") {
      if (!value.cast<bool>()) o.passes.disable(Pass::flats);
    } else if (k == "sharpen") {
      if (!value.cast<bool>()) o.passes.disable(Pass::sharpen);
    } else if (k == "disable_passes") {
      for (const auto& name : value.cast<std::vector<std::string>>()) o.passes.disable(name);
    }
    else if (k == "min_flat_area") o.flat.min_area = option<double>(k, value);
    else if (k == "junction_angle") o.flat.junction_angle = option<double>(k, value);
    else if (k == "sharp_angle") o.sharp.sharp_angle = option<double>(k, value);
    else if (k == "color_regions") o.color_regions = option<bool>(k, value);
    else if (k == "fit_rings") o.fit.rings = option<int>(k, value);
    else if (k == "lambda_") o.overrides.lambda = option<double>(k, value);
    else if (k == "mu") o.overrides.mu = option<double>(k, value);
    else if (k == "faces") o.simplify.faces = option<uint64_t>(k, value);
    else if (k == "max_error") o.simplify.max_error = option<double>(k, value);
    else
      throw py::type_error("press() got an unknown option '" + k +
                           "' (iterations, tolerance, flats, sharpen, min_flat_area, junction_angle, sharp_angle, "
                           "disable_passes, color_regions, fit_rings, lambda_, mu, faces, max_error)");
  }
}

}  // namespace voxpress::python

namespace {

using namespace voxpress::python;

PyMesh py_press(const py::object& mask_like, const py::object& spacing, const py::object& origin, const py::object& direction,
             const std::string& method, const std::string& axes, const py::object& label, const py::object& threshold,
             const py::kwargs& kw) {
  SurfaceOptions o;
  o.method = parse_method(method);
  py::kwargs rest;  // chunk= and halo= choose the chunked run; the others are SurfaceOptions
  std::optional<ChunkOptions> chunks;
  for (const auto& [key, value] : kw) {
    const std::string k = py::str(key);
    if (k == "chunk" && !value.is_none()) {
      if (!chunks) chunks = ChunkOptions{};
      chunks->chunk = value.cast<int64_t>();
    } else if (k == "halo") {
      if (!chunks) chunks = ChunkOptions{};
      chunks->halo = value.cast<int64_t>();
    } else if (k != "chunk") {
      rest[key] = value;
    }
  }
  if (chunks && !kw.contains("chunk")) throw UsageError("halo= needs chunk=");
  set_options(o, rest);
  const Selection sel = selection(label, threshold);
  // ArrayLike: nested lists and anything numpy.asarray takes.
  const py::array mask = py::module_::import("numpy").attr("asarray")(mask_like);
  ScalarVolume scalar = to_volume(mask, spacing, origin, direction, axes);
  const Lattice lattice = scalar.lattice;
  if (chunks) return press_chunked_volume(scalar, sel, o, *chunks);  // as press --chunk [--halo]
  SurfaceResult r;
  double seconds_binarize = 0;
  {
    py::gil_scoped_release release;
    const auto t0 = std::chrono::steady_clock::now();
    const BinaryVolume volume = binarize(scalar, sel);
    seconds_binarize = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    scalar = {};
    r = smooth_surface(volume, o);
  }
  PyMesh out;
  out.mesh = std::move(r.mesh);
  out.lattice = lattice;
  if (o.simplify.faces || o.simplify.max_error) out.stats["simplify"] = simplify_stats(r.simplify);
  const bool pressing = o.method == Method::pressing;
  out.stats["method"] = method;
  out.stats["sticks"] = r.extract.sticks;
  out.stats["vertices"] = out.mesh.vertex_count();
  out.stats["triangles"] = out.mesh.face_count();
  out.stats["iterations"] = pressing ? r.press.iterations : o.method == Method::cesn ? r.net.iterations : r.smooth.iterations;
  if (pressing) out.stats["residual"] = r.press.residual;  // max |T(t) - t| reached, a fraction of the stick
  out.stats["flats"] = r.flats.flats.size();
  out.stats["sharp_edges"] = out.mesh.edges.size();
  out.stats["keeps_classification"] = keeps_classification(o.method);
  out.stats["seconds_binarize"] = seconds_binarize;
  out.stats["seconds_extract"] = r.seconds_extract;
  out.stats["seconds_smooth"] = r.seconds_smooth;
  return out;
}

}  // namespace

namespace voxpress::python {

py::object labels_result(const std::vector<LabelInfo>& chosen, std::vector<Mesh> meshes, const std::vector<size_t>& flats,
                         bool keeps, const SharedLabels* shared, bool interfaces) {
  py::dict out;
  for (size_t i = 0; i < chosen.size(); ++i) {
    PyMesh m;
    m.mesh = std::move(meshes[i]);
    m.stats["label"] = chosen[i].value;
    m.stats["samples"] = chosen[i].samples;
    m.stats["vertices"] = m.mesh.vertex_count();
    m.stats["triangles"] = m.mesh.face_count();
    m.stats["flats"] = flats[i];
    m.stats["shared"] = shared != nullptr;
    m.stats["keeps_classification"] = keeps;
    const double v = chosen[i].value;
    if (v == std::floor(v) && std::abs(v) < 9e15)
      out[py::int_(int64_t(v))] = std::move(m);
    else
      out[py::float_(v)] = std::move(m);
  }
  if (!interfaces || !shared) return out;
  const SharedPressStats& ps = shared->press;
  PyMesh all;
  all.mesh = interfaces_mesh(shared->surface);
  all.stats["junction_curves"] = ps.junction_curves;
  all.stats["residual"] = ps.interfaces.residual;  // the shared press's, as press()'s
  all.stats["cubes_pinned"] = ps.cubes_pinned;
  all.stats["cubes_reset"] = ps.cubes_reset;
  all.stats["flats"] = shared->flats ? shared->flats->flats.size() : 0;
  all.stats["flat_vertices"] = ps.flat_vertices;
  all.stats["fitted_vertices"] = shared->fit.moved;
  all.stats["crease_vertices"] = shared->sharpen.inserted;
  all.stats["seconds"] = ps.seconds + shared->fit.seconds + shared->sharpen.seconds;
  return py::make_tuple(out, all);
}

void cut_labels(const SharedLabels& r, const std::vector<LabelInfo>& chosen, std::vector<Mesh>& meshes,
                std::vector<size_t>& flats) {
  const SharedSurface& s = r.surface;
  for (const LabelInfo& l : chosen) {
    const auto it = std::find(s.labels.begin(), s.labels.end(), uint32_t(l.value));
    meshes.push_back(label_mesh(s, uint32_t(it - s.labels.begin())));
    flats.push_back(r.flats ? r.flats->flats_of(l.value) : 0);
  }
}

void check_shared_options(const py::kwargs& kw) {
  for (const char* k : {"color_regions", "fit_rings"})
    if (kw.contains(k))
      throw UsageError(std::string(k) + "= applies to separate=True only (the shared surface has no region colours or quadric fit)");
}

std::vector<double> label_values(const py::object& labels) {
  std::vector<double> values;  // empty: every label
  // "all" as on the command line; any other string was a bare cast error (issue 73).
  if (py::isinstance<py::str>(labels)) {
    if (labels.cast<std::string>() == "all") return values;
    throw UsageError("labels= must be 'all' or a sequence of label values, not " + std::string(py::repr(labels)));
  }
  if (!labels.is_none()) {
    for (const py::handle& h : labels) values.push_back(option<double>("labels", h));
    if (values.empty()) throw UsageError("labels= selects no label");
  }
  return values;
}

}  // namespace voxpress::python

namespace {

// Every label of a label map: {value: Mesh}, as `press --labels` computes it.
// {label: Mesh}: by default cut from one pressed shared surface (touching
// labels share their interface vertex for vertex); separate=True, or a
// baseline method, meshes each label alone. interfaces=True also returns
// the shared surface, each interface once, with its label pairs.
py::object py_press_labels(const py::object& array_like, const py::object& labels, const py::object& spacing,
                           const py::object& origin, const py::object& direction, const std::string& method,
                           const std::string& axes, bool separate, bool interfaces, const py::kwargs& kw) {
  SurfaceOptions o;
  o.method = parse_method(method);
  set_options(o, kw);
  const bool shared = !separate && o.method == Method::pressing;
  if (shared) check_shared_options(kw);
  if (interfaces && !shared) throw UsageError("interfaces=True needs the shared surface (method='pressing', separate=False)");
  const py::array array = py::module_::import("numpy").attr("asarray")(array_like);
  const ScalarVolume scalar = to_volume(array, spacing, origin, direction, axes);
  const std::vector<double> values = label_values(labels);
  std::vector<LabelInfo> chosen;
  std::vector<Mesh> meshes;
  std::vector<size_t> flats;
  std::optional<SharedLabels> r;
  {
    py::gil_scoped_release release;
    const LabelTable table = label_table(scalar);
    chosen = select_labels(table, values, scalar.source);
    if (shared && !table.layered) {
      r = press_shared_labels(scalar, table, o);
      cut_labels(*r, chosen, meshes, flats);
    } else {
      for (LabelSurface& ls : press_labels(scalar, chosen, o)) {
        meshes.push_back(std::move(ls.result.mesh));
        flats.push_back(ls.result.flats.flats.size());
      }
    }
  }
  return labels_result(chosen, std::move(meshes), flats, keeps_classification(o.method), r ? &*r : nullptr,
                       interfaces);
}

// A volume argument of check/evaluate: a file path, or a mask array on a lattice.
BinaryVolume binary_argument(const py::object& volume, const py::dict& lattice, ScalarVolume* scalar_out) {
  const py::object none = py::none();
  auto get = [&](const char* k, py::object d) { return lattice.contains(k) ? py::object(lattice[k]) : d; };
  ScalarVolume s = py::isinstance<py::array>(volume)
                       ? to_volume(volume.cast<py::array>(), get("spacing", py::make_tuple(1, 1, 1)),
                                   get("origin", py::make_tuple(0, 0, 0)), get("direction", none),
                                   get("axes", py::str("xyz")).cast<std::string>())
                       : read_volume(volume.cast<std::string>());
  BinaryVolume b = binarize(s, selection(get("label", none), get("threshold", none)));
  if (scalar_out) *scalar_out = std::move(s);
  return b;
}

py::dict py_check(const PyMesh& m, const py::object& volume, const py::kwargs& kw) {
  for (const auto& item : kw) {
    const std::string k = py::str(item.first);
    if (k != "spacing" && k != "origin" && k != "direction" && k != "axes" && k != "label" && k != "threshold")
      throw py::type_error("check() got an unknown option '" + k +
                           "' (spacing, origin, direction, axes, label, threshold)");
  }
  py::dict lattice(kw);
  std::optional<BinaryVolume> b;
  if (!volume.is_none()) b = binary_argument(volume, lattice, nullptr);
  MeshCheck c;
  std::optional<ClassificationReport> cr;
  {
    py::gil_scoped_release release;
    c = check_mesh(m.mesh);
    if (b) cr = check_classification(m.mesh, *b);
  }
  py::dict d;
  d["ok"] = c.ok() && (!cr || cr->violations == 0);
  d["closed"] = c.closed();
  d["manifold"] = c.manifold();
  d["oriented"] = c.oriented();
  d["degenerate_faces"] = c.degenerate_faces;
  d["self_intersections"] = c.self_intersections;
  d["components"] = c.components;
  d["euler"] = c.euler;
  d["volume"] = c.signed_volume;
  d["area"] = c.area;
  d["problems"] = c.problems;
  if (cr) {
    d["samples"] = cr->samples;
    d["classification_violations"] = cr->violations;
  }
  return d;
}

py::dict py_evaluate(const PyMesh& m, const std::string& truth, const py::object& volume, size_t samples,
                     bool quadrature) {
  ScalarVolume scalar;
  std::optional<BinaryVolume> b;
  if (!volume.is_none()) b = binary_argument(volume, py::dict(), &scalar);
  EvalReport e;
  {
    py::gil_scoped_release release;
    const auto t = resolve_truth(truth, b ? &scalar : nullptr);
    EvalOptions o;
    o.samples = samples;
    o.quadrature = quadrature;
    if (b) o.volume = &*b;
    e = voxpress::evaluate(m.mesh, *t, o);
  }
  auto distances = [](const DistanceStats& s) {
    py::dict d;
    d["rms"] = s.rms;
    d["mean"] = s.mean;
    d["max"] = s.max;
    return d;
  };
  py::dict d;
  d["truth"] = e.truth;
  d["result_to_truth"] = distances(e.result_to_truth);
  d["truth_to_result"] = distances(e.truth_to_result);
  d["hausdorff"] = e.hausdorff;
  if (e.result_to_truth_rule_rms) d["result_to_truth_rule_rms"] = *e.result_to_truth_rule_rms;
  if (e.result_to_truth_rule_rms_vox) d["result_to_truth_rule_rms_vox"] = *e.result_to_truth_rule_rms_vox;
  d["normal_error_deg"] = e.normal_error_deg;
  d["volume_ratio"] = e.volume_ratio;
  if (b) {
    d["result_to_truth_vox"] = distances(e.result_to_truth_vox);
    d["truth_to_result_vox"] = distances(e.truth_to_result_vox);
    d["classification_violations"] = e.classification_violations.value_or(0);
    d["stick_rms_vox"] = e.stick_rms_vox ? py::object(py::float_(*e.stick_rms_vox)) : py::object(py::none());
  }
  if (e.sharp_edge_hausdorff) d["sharp_edge_hausdorff"] = *e.sharp_edge_hausdorff;
  if (e.sharp_recall) d["sharp_recall"] = *e.sharp_recall;
  if (e.sharp_precision) d["sharp_precision"] = *e.sharp_precision;
  d["mesh_ok"] = e.mesh.ok();
  return d;
}

}  // namespace

PYBIND11_MODULE(_voxpress, m) {
  m.doc() = "voxpress: smooth, accurate solids from binary voxel volumes (C++ core).";
  m.attr("__version__") = kVersion;

  bind_chunks(m);
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", error.ptr());
  static py::exception<UsageError> usage_error(m, "UsageError", error.ptr());
  static py::exception<LimitError> limit_error(m, "LimitError", input_error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const LimitError& e) {
      limit_error(e.what());
    } catch (const InputError& e) {
      input_error(e.what());
    } catch (const UsageError& e) {
      usage_error(e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });

  py::class_<Lattice>(m, "Lattice", "The sampling grid: physical = origin + direction @ diag(spacing) @ (i, j, k).")
      .def_property_readonly("dims", [](const Lattice& l) { return py::make_tuple(l.dims[0], l.dims[1], l.dims[2]); })
      .def_property_readonly("spacing", [](const Lattice& l) { return py::make_tuple(l.spacing.x(), l.spacing.y(), l.spacing.z()); })
      .def_property_readonly("origin", [](const Lattice& l) { return py::make_tuple(l.origin.x(), l.origin.y(), l.origin.z()); })
      .def_property_readonly("direction", [](const Lattice& l) {
        py::array_t<double> d({3, 3});
        auto w = d.mutable_unchecked<2>();
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) w(r, c) = l.direction(r, c);
        return d;
      }, "3x3 array; column a is the physical direction of index axis a")
      .def_property_readonly("space", [](const Lattice& l) { return std::string(space_name(l.space)); })
      .def("__repr__", [](const Lattice& l) {
        return "Lattice(dims=(" + std::to_string(l.dims[0]) + ", " + std::to_string(l.dims[1]) + ", " +
               std::to_string(l.dims[2]) + "), spacing=(" + std::to_string(l.spacing.x()) + ", " +
               std::to_string(l.spacing.y()) + ", " + std::to_string(l.spacing.z()) + "))";
      });

  bind_mesh(m);

  m.def("press", &py_press, py::arg("mask"), py::kw_only(), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
        py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::arg("direction") = py::none(),
        py::arg("method") = "pressing", py::arg("axes") = "xyz", py::arg("label") = py::none(),
        py::arg("threshold") = py::none(),
        "The smooth surface of a mask (see voxpress/__init__.pyi).");
  m.def("press_labels", &py_press_labels, py::arg("array"), py::kw_only(), py::arg("labels") = py::none(),
        py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0), py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0),
        py::arg("direction") = py::none(), py::arg("method") = "pressing", py::arg("axes") = "xyz",
        py::arg("separate") = false, py::arg("interfaces") = false,
        "Every label's smooth surface: {label: Mesh}, or ({label: Mesh}, shared Mesh) with interfaces=True "
        "(see voxpress/__init__.pyi).");
  m.def("read_volume", [](const std::string& path) {
        ScalarVolume* v = nullptr;
        {
          py::gil_scoped_release release;
          v = new ScalarVolume(read_volume(path));
        }
        py::capsule owner(v, [](void* p) { delete static_cast<ScalarVolume*>(p); });
        const size_t item = scalar_size(v->type);
        static const char* kFormat[] = {"B", "b", "H", "h", "I", "i", "Q", "q", "f", "d"};
        const auto& d = v->lattice.dims;
        std::vector<py::ssize_t> shape{d[0], d[1], d[2]};
        std::vector<py::ssize_t> strides{py::ssize_t(item), py::ssize_t(item) * d[0], py::ssize_t(item) * d[0] * d[1]};
        if (v->components > 1) {
          shape.push_back(v->components);
          for (auto& s : strides) s *= v->components;
          strides.push_back(py::ssize_t(item));
        }
        const py::dtype dt(kFormat[size_t(v->type)]);
        py::array a(dt, shape, strides, v->bytes.data(), owner);
        return py::make_tuple(a, v->lattice);
      }, py::arg("path"), "(array indexed [i, j, k] without copying, Lattice)");
  m.def("read_mesh", [](const std::string& path) {
        PyMesh pm;
        py::gil_scoped_release release;
        pm.mesh = read_mesh(path);
        return pm;
      }, py::arg("path"), "Reads .ply .obj .stl .off");
  m.def("check", &py_check, py::arg("mesh"), py::arg("volume") = py::none(),
        "Closed, manifold, oriented, self-intersections; with a volume, every sample on its side.");
  m.def("evaluate", &py_evaluate, py::arg("mesh"), py::kw_only(), py::arg("truth") = "", py::arg("volume") = py::none(),
        py::arg("samples") = 200000, py::arg("quadrature") = false,
        "Distances to the true surface (as `voxpress eval`; quadrature: also the 7-point rule's result -> truth "
        "RMS).");
}
