// The chunked core for Python: chunk_plan (the blocks and the boxes to read),
// _press_block (one block's piece: numpy arrays of global stick keys, so a
// piece pickles compactly for Dask), _merge (consecutive pieces -> one:
// the tree reduction's step), _stitch (pieces -> Mesh), and the
// in-process press(..., chunk=) path. voxpress/dask.py maps _press_block
// over a Dask array's blocks; the results are the CLI's `press --chunk`.
#include <pybind11/stl.h>
#include <tbb/task_arena.h>

#include <cstring>

#include "py_common.h"

namespace voxpress::python {
namespace {

using Corner = std::array<int64_t, 3>;

Corner corner(const py::handle& o, const char* what) {
  const auto v = o.cast<std::vector<int64_t>>();
  if (v.size() != 3) throw UsageError(std::string(what) + " must have 3 values");
  return {v[0], v[1], v[2]};
}

template <class T>
py::array_t<T> to_numpy(const std::vector<T>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

template <class T>
std::vector<T> from_numpy(const py::dict& piece, const char* key) {
  if (!piece.contains(key)) throw UsageError(std::string("a piece lacks '") + key + "' (not from _press_block?)");
  const auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(piece[key]);
  if (!a) throw UsageError(std::string("a piece's '") + key + "' is not an array");
  return std::vector<T>(a.data(), a.data() + a.size());
}

// A piece as Dask moves it: numpy arrays (pickled compactly) and counts.
py::dict to_dict(const SurfacePiece& piece) {
  py::dict d;
  d["block"] = piece.block;
  d["count"] = piece.count;
  d["blocks"] = piece.blocks;
  d["sticks"] = to_numpy(piece.sticks);
  d["code"] = to_numpy(piece.code);
  d["t"] = to_numpy(piece.t);
  d["triangles"] = to_numpy(piece.triangles);
  d["iterations"] = piece.press.iterations;
  return d;
}

SurfacePiece from_dict(const py::dict& d) {
  for (const char* key : {"block", "count", "blocks"})
    if (!d.contains(key)) throw UsageError(std::string("a piece lacks '") + key + "' (not from _press_block?)");
  SurfacePiece p;
  p.block = d["block"].cast<uint64_t>();
  p.count = d["count"].cast<uint64_t>();
  p.blocks = d["blocks"].cast<uint64_t>();
  p.sticks = from_numpy<uint64_t>(d, "sticks");
  p.code = from_numpy<uint8_t>(d, "code");
  p.t = from_numpy<double>(d, "t");
  p.triangles = from_numpy<uint64_t>(d, "triangles");
  if (d.contains("iterations")) p.press.iterations = d["iterations"].cast<int>();
  if (p.code.size() != p.sticks.size() || p.t.size() != p.sticks.size() || p.triangles.size() % 3)
    throw UsageError("a piece's arrays do not match (sticks, code, t, triangles)");
  return p;
}

// The whole volume's lattice from shape, spacing, origin, direction.
Lattice whole_lattice(const py::handle& shape, const py::object& spacing, const py::object& origin,
                      const py::object& direction) {
  return to_lattice(corner(shape, "shape"), spacing, origin, direction);
}

py::list py_chunk_plan(const py::handle& shape, int64_t chunk, int64_t halo) {
  const ChunkGrid grid(corner(shape, "shape"), ChunkOptions{chunk, halo});
  py::list out;
  for (size_t b = 0; b < grid.count(); ++b) {
    const Box core = grid.core(b), read = grid.with_halo(b);
    py::dict d;
    d["block"] = b;
    d["core"] = py::make_tuple(py::cast(core.lo), py::cast(core.hi));
    d["read"] = py::make_tuple(py::cast(read.lo), py::cast(read.hi));
    out.append(d);
  }
  return out;
}

py::dict py_press_block(const py::array& mask, const py::handle& shape, size_t block, int64_t chunk, int64_t halo,
                        const py::tuple& bounds, const py::object& spacing, const py::object& origin,
                        const py::object& direction, int threads, const py::kwargs& kw) {
  SurfaceOptions o;
  set_options(o, kw);
  const Lattice lattice = whole_lattice(shape, spacing, origin, direction);
  const ChunkGrid grid(lattice.dims, ChunkOptions{chunk, halo});
  if (block >= grid.count()) throw UsageError("block " + std::to_string(block) + " is not in the plan");
  if (bounds.size() != 2) throw UsageError("bounds must be (lo, hi): the box of the inside samples");
  VolumeSummary summary;
  summary.bounds = {corner(bounds[0], "bounds lo"), corner(bounds[1], "bounds hi")};
  const Box box = grid.with_halo(block);
  ScalarVolume scalar = to_volume(mask, py::make_tuple(1, 1, 1), py::make_tuple(0, 0, 0), py::none(), "xyz");
  if (scalar.lattice.dims != box.dims())
    throw UsageError("block " + std::to_string(block) + " must be the array's box read = (lo, hi) of chunk_plan");
  SurfacePiece piece;
  {
    py::gil_scoped_release release;
    Selection nonzero;
    nonzero.kind = Selection::Kind::nonzero;
    BinaryVolume b = select_samples(scalar, nonzero);
    b.lattice = box_lattice(lattice, box);
    b.source = "array";
    const SurfaceOptions so = chunk_surface_options(o, summary);
    const SurfaceOptions* pressed = halo > 0 ? &so : nullptr;  // halo 0: extraction only (exact mode)
    if (threads > 0) {  // a Dask worker's share of the machine
      tbb::task_arena arena(threads);
      arena.execute([&] { piece = press_block(b, grid, block, pressed); });
    } else {
      piece = press_block(b, grid, block, pressed);
    }
  }
  return to_dict(piece);
}

py::dict py_merge(const py::list& pieces, const py::handle& shape) {
  std::vector<SurfacePiece> ps;
  for (const py::handle& h : pieces) ps.push_back(from_dict(h.cast<py::dict>()));
  SurfacePiece out;
  {
    py::gil_scoped_release release;
    out = merge_pieces(ps, corner(shape, "shape"));
  }
  return to_dict(out);
}

PyMesh py_stitch(const py::list& pieces, const py::handle& shape, const py::object& spacing, const py::object& origin,
                 const py::object& direction, bool smooth, const py::kwargs& kw) {
  SurfaceOptions o;
  set_options(o, kw);
  const Lattice lattice = whole_lattice(shape, spacing, origin, direction);
  std::vector<SurfacePiece> ps;
  for (const py::handle& h : pieces) {
    ps.push_back(from_dict(h.cast<py::dict>()));
  }
  const uint64_t blocks = ps.empty() ? 0 : ps[0].blocks;
  PyMesh out;
  int iterations = 0;
  size_t flats = 0;
  {
    py::gil_scoped_release release;  // no Python object is touched in here
    StickSurface s = stitch(lattice, ps);
    ps = {};
    if (smooth) {  // the exact mode: the pieces' sticks are the whole volume's, smoothed here at once
      require_float32_room(lattice, o, "array");
      SurfaceResult r = smooth_sticks(std::move(s), o);
      out.mesh = std::move(r.mesh);
      iterations = r.press.iterations;
      flats = r.flats.flats.size();
    } else {
      out.mesh = to_mesh(s);
    }
  }
  if (smooth) {
    out.stats["iterations"] = iterations;
    out.stats["flats"] = flats;
  }
  out.stats["method"] = "pressing";
  out.stats["blocks"] = blocks;
  out.stats["vertices"] = out.mesh.vertex_count();
  out.stats["triangles"] = out.mesh.face_count();
  return out;
}

}  // namespace

PyMesh press_chunked_volume(const ScalarVolume& scalar, const Selection& sel, const SurfaceOptions& o,
                            const ChunkOptions& chunks) {
  PyMesh out;
  ChunkedStats st;
  SurfaceResult r;
  {
    py::gil_scoped_release release;
    const BinaryVolume volume = binarize(scalar, sel);
    r = press_chunked(volume.lattice, "array", [&](const Box& box) { return crop(volume, box); }, o, chunks, &st);
  }
  out.mesh = std::move(r.mesh);
  out.stats["method"] = std::string(method_name(o.method));
  out.stats["blocks"] = st.blocks;
  out.stats["sticks"] = st.sticks;
  out.stats["vertices"] = out.mesh.vertex_count();
  out.stats["triangles"] = out.mesh.face_count();
  out.stats["iterations"] = r.press.iterations;
  out.stats["flats"] = r.flats.flats.size();
  out.stats["sharp_edges"] = out.mesh.edges.size();
  out.stats["keeps_classification"] = keeps_classification(o.method);
  out.stats["seconds_blocks"] = st.seconds_blocks;
  out.stats["seconds_stitch"] = st.seconds_stitch;
  return out;
}

void bind_chunks(py::module_& m) {
  m.def("chunk_plan", &py_chunk_plan, py::arg("shape"), py::kw_only(), py::arg("chunk") = 256, py::arg("halo") = 0,
        "The blocks of a volume: [{block, core: (lo, hi), read: (lo, hi)}], x fastest.");
  m.def("_press_block", &py_press_block, py::arg("mask"), py::kw_only(), py::arg("shape"), py::arg("block"),
        py::arg("chunk"), py::arg("halo"), py::arg("bounds"), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
        py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::arg("direction") = py::none(), py::arg("threads") = 0,
        "One block's piece (voxpress.dask): mask is the block's read box, non-zero inside; threads 0: all cores.");
  m.def("_merge", &py_merge, py::arg("pieces"), py::kw_only(), py::arg("shape"),
        "One piece of consecutive ones (each one's blocks follow the one before): a step of voxpress.dask's tree "
        "reduction.");
  m.def("_stitch", &py_stitch, py::arg("pieces"), py::kw_only(), py::arg("shape"),
        py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0), py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0),
        py::arg("direction") = py::none(), py::arg("smooth") = false,
        "The mesh of every block's piece (any order); smooth: the pieces were only extracted (halo 0), "
        "smooth the stitched sticks with the options (press()'s).");
}

}  // namespace voxpress::python
