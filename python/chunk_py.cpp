// The chunked core for Python: chunk_plan (the blocks and the boxes to read),
// _press_block (one block's piece: numpy arrays of global stick keys, so a
// piece pickles compactly for Dask), _merge (consecutive pieces -> one:
// the tree reduction's step), _stitch (pieces -> Mesh), _BlockRounds and
// _press_rounds (the halo mode's blocks and rounds), and the in-process
// press(..., chunk=) path. voxpress/dask.py maps them over a Dask array's
// blocks; the results are the CLI's `press --chunk`.
#include <pybind11/stl.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <optional>
#include <set>
#include <span>

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
  d["velocity"] = to_numpy(piece.velocity);
  d["residuals"] = to_numpy(piece.residuals);
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
  if (d.contains("velocity")) p.velocity = from_numpy<double>(d, "velocity");
  if (d.contains("residuals")) p.residuals = from_numpy<double>(d, "residuals");
  if (p.code.size() != p.sticks.size() || p.t.size() != p.sticks.size() || p.triangles.size() % 3 ||
      (!p.velocity.empty() && p.velocity.size() != p.sticks.size()))
    throw UsageError("a piece's arrays do not match (sticks, code, t, velocity, triangles)");
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

// press()'s keyword options as the chunked run uses them
// (chunk_surface_options: levels from the inside box `bounds`).
SurfaceOptions chunk_options(const py::kwargs& kw, const py::tuple& bounds) {
  SurfaceOptions o;
  set_options(o, kw);
  if (bounds.size() != 2) throw UsageError("bounds must be (lo, hi): the box of the inside samples");
  VolumeSummary summary;
  summary.bounds = {corner(bounds[0], "bounds lo"), corner(bounds[1], "bounds hi")};
  return chunk_surface_options(o, summary);
}

// One block of a plan, as the Dask task reads it: the whole lattice, the
// grid, the block's samples (its read box, non-zero inside) and the options
// chunk_surface_options gives (levels from the inside box `bounds`).
struct BlockTask {
  Lattice lattice;
  ChunkGrid grid;
  SurfaceOptions so;
  BinaryVolume samples;
  BlockTask(const py::array& mask, const py::handle& shape, size_t block, int64_t chunk, int64_t halo,
            const py::tuple& bounds, const py::object& spacing, const py::object& origin, const py::object& direction,
            const py::kwargs& kw)
      : lattice(whole_lattice(shape, spacing, origin, direction)),
        grid(lattice.dims, ChunkOptions{chunk, halo}),
        so(chunk_options(kw, bounds)) {
    if (block >= grid.count()) throw UsageError("block " + std::to_string(block) + " is not in the plan");
    const Box box = grid.with_halo(block);
    ScalarVolume scalar = to_volume(mask, py::make_tuple(1, 1, 1), py::make_tuple(0, 0, 0), py::none(), "xyz");
    if (scalar.lattice.dims != box.dims())
      throw UsageError("block " + std::to_string(block) + " must be the array's box read = (lo, hi) of chunk_plan");
    Selection nonzero;
    nonzero.kind = Selection::Kind::nonzero;
    samples = select_samples(scalar, nonzero);
    samples.lattice = box_lattice(lattice, box);
    samples.source = "array";
  }
};

// f() on `threads` cores (a Dask worker's share of the machine; 0: all), without the GIL.
template <class F>
auto on_cores(int threads, F&& f) {
  py::gil_scoped_release release;
  if (threads <= 0) return f();
  tbb::task_arena arena(threads);
  return arena.execute([&] { return f(); });
}

// The state a block reads: views of its neighbours' pieces (numpy arrays,
// kept alive in `held` while the round runs).
template <class T>
std::span<const T> view(const py::dict& piece, const char* key, std::vector<py::object>& held) {
  if (!piece.contains(key)) throw UsageError(std::string("a piece lacks '") + key + "' (not from a round?)");
  const auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(piece[key]);
  if (!a) throw UsageError(std::string("a piece's '") + key + "' is not an array");
  held.push_back(a);
  return {a.data(), size_t(a.size())};
}

PressState state_of(const py::list& pieces, std::vector<py::object>& held) {
  PressState st;
  for (const py::handle& h : pieces) {
    const py::dict d = h.cast<py::dict>();
    if (!d.contains("block")) throw UsageError("a piece lacks 'block' (not from a round?)");
    st.pieces.push_back({d["block"].cast<uint64_t>(), view<uint64_t>(d, "sticks", held), view<double>(d, "t", held),
                         d.contains("velocity") ? view<double>(d, "velocity", held) : std::span<const double>{}});
  }
  return st;
}

py::dict py_press_block(const py::array& mask, const py::handle& shape, size_t block, int64_t chunk, int64_t halo,
                        const py::tuple& bounds, const py::object& spacing, const py::object& origin,
                        const py::object& direction, int threads, const py::kwargs& kw) {
  const BlockTask task(mask, shape, block, chunk, halo, bounds, spacing, origin, direction, kw);
  return to_dict(on_cores(threads, [&] { return press_block(task.samples, task.grid, block); }));
}

// A block of the halo mode between its rounds (voxpress.dask): extracted
// once from its read box; it pickles as what built it (the mask and the
// arguments), so a worker that receives it extracts it again.
class PyBlockRounds {
 public:
  PyBlockRounds(py::array mask, py::dict args) : mask_(std::move(mask)), args_(std::move(args)) {
    const auto get = [&](const char* key, py::object fallback) {
      return args_.contains(key) ? py::reinterpret_borrow<py::object>(args_[key]) : fallback;
    };
    py::kwargs kw;
    for (const auto& [key, value] : args_)
      if (!kNamed.count(key.cast<std::string>())) kw[key] = value;
    for (const char* key : {"shape", "block", "chunk", "halo", "bounds"})
      if (!args_.contains(key)) throw UsageError(std::string("_BlockRounds needs ") + key);
    block_ = args_["block"].cast<size_t>();
    threads_ = get("threads", py::int_(0)).cast<int>();
    const BlockTask task(mask_, args_["shape"], block_, args_["chunk"].cast<int64_t>(), args_["halo"].cast<int64_t>(),
                         args_["bounds"].cast<py::tuple>(), get("spacing", py::make_tuple(1.0, 1.0, 1.0)),
                         get("origin", py::make_tuple(0.0, 0.0, 0.0)), get("direction", py::none()), kw);
    rounds_ = std::make_shared<BlockRounds>(
        on_cores(threads_, [&] { return BlockRounds(task.samples, task.grid, block_, task.so); }));
  }
  py::dict round(const py::list& state, int first, int last) const {
    std::vector<py::object> held;
    const PressState st = state_of(state, held);
    return to_dict(on_cores(threads_, [&] { return rounds_->round(PressRound{first, last}, st); }));
  }
  py::dict finish(const py::list& state, bool measure) const {
    std::vector<py::object> held;
    const PressState st = state_of(state, held);
    return to_dict(on_cores(threads_, [&] { return rounds_->finish(st, measure); }));
  }
  uint64_t nbytes() const { return rounds_->bytes() + uint64_t(mask_.nbytes()); }
  py::tuple state() const { return py::make_tuple(mask_, args_); }

 private:
  static inline const std::set<std::string> kNamed = {"shape",  "block",   "chunk",     "halo",   "bounds",
                                                       "spacing", "origin", "direction", "threads"};
  py::array mask_;
  py::dict args_;
  size_t block_ = 0;
  int threads_ = 0;
  std::shared_ptr<const BlockRounds> rounds_;
};

py::list py_press_rounds(const py::handle& shape, int64_t halo, const py::tuple& bounds, const py::object& spacing,
                         const py::object& origin, const py::object& direction, const py::kwargs& kw) {
  const Lattice lattice = whole_lattice(shape, spacing, origin, direction);
  py::list out;
  for (const PressRound& r : press_rounds(lattice, chunk_options(kw, bounds), halo))
    out.append(py::make_tuple(r.first, r.last, r.measured));
  return out;
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

// A label-map block's part of the table and piece of the shared surface
// (voxpress.dask.press_labels), as numpy arrays that pickle compactly.
py::dict py_label_block(const py::array& block_samples, const py::handle& shape, size_t block, int64_t chunk,
                        int threads) {
  const Corner dims = corner(shape, "shape");
  const ChunkGrid grid(dims, ChunkOptions{chunk, 0});
  if (block >= grid.count()) throw UsageError("block " + std::to_string(block) + " is not in the plan");
  const Box read = grid.with_halo(block), core = grid.core(block);
  ScalarVolume v = to_volume(block_samples, py::make_tuple(1, 1, 1), py::make_tuple(0, 0, 0), py::none(), "xyz");
  v.source = "array";
  if (v.lattice.dims != read.dims())
    throw UsageError("block " + std::to_string(block) + " must be the array's box read = (lo, hi) of chunk_plan");
  LabelTable t;
  SharedPiece piece;
  {
    py::gil_scoped_release release;
    auto run = [&] {
      t = label_table_part(v, read, core, dims);
      piece = extract_shared_piece(v, read, core, dims);
    };
    if (threads > 0) {
      tbb::task_arena arena(threads);
      arena.execute(run);
    } else {
      run();
    }
  }
  std::vector<double> value, a, b;
  std::vector<uint64_t> samples, sticks, apex_keys;
  std::vector<int64_t> box;
  for (const LabelInfo& l : t.labels) {
    value.push_back(l.value);
    samples.push_back(l.samples);
    box.insert(box.end(), l.lo.begin(), l.lo.end());
    box.insert(box.end(), l.hi.begin(), l.hi.end());
  }
  for (const LabelContact& c : t.contacts) a.push_back(c.a), b.push_back(c.b), sticks.push_back(c.sticks);
  std::vector<uint64_t> keys;
  std::vector<uint32_t> values;
  std::vector<double> apex_pos;
  for (size_t i = 0; i < piece.cube.size(); ++i) {
    keys.insert(keys.end(), piece.keys[i].begin(), piece.keys[i].end());
    values.insert(values.end(), piece.values[i].begin(), piece.values[i].end());
  }
  for (const auto& [key, x] : piece.apexes) {
    apex_keys.push_back(key);
    apex_pos.insert(apex_pos.end(), {x.x(), x.y(), x.z()});
  }
  py::dict d;
  d["block"] = block;
  d["value"] = to_numpy(value);
  d["samples"] = to_numpy(samples);
  d["box"] = to_numpy(box);
  d["a"] = to_numpy(a);
  d["b"] = to_numpy(b);
  d["sticks"] = to_numpy(sticks);
  d["cube"] = to_numpy(piece.cube);
  d["keys"] = to_numpy(keys);
  d["values"] = to_numpy(values);
  d["apex_keys"] = to_numpy(apex_keys);
  d["apex_pos"] = to_numpy(apex_pos);
  d["underivable"] = piece.underivable;
  d["underivable_cube"] = piece.underivable_cube;
  return d;
}

std::pair<LabelTable, SharedPiece> label_block_from_dict(const py::dict& d) {
  LabelTable t;
  const auto value = from_numpy<double>(d, "value"), a = from_numpy<double>(d, "a"), b = from_numpy<double>(d, "b");
  const auto samples = from_numpy<uint64_t>(d, "samples"), sticks = from_numpy<uint64_t>(d, "sticks");
  const auto box = from_numpy<int64_t>(d, "box");
  if (samples.size() != value.size() || box.size() != 6 * value.size() || b.size() != a.size() ||
      sticks.size() != a.size())
    throw UsageError("a label block's table arrays do not match (not from _label_block?)");
  for (size_t i = 0; i < value.size(); ++i) {
    LabelInfo l;
    l.value = value[i];
    l.samples = samples[i];
    for (size_t k = 0; k < 3; ++k) l.lo[k] = box[6 * i + k], l.hi[k] = box[6 * i + 3 + k];
    t.labels.push_back(l);
  }
  for (size_t i = 0; i < a.size(); ++i) t.contacts.push_back({a[i], b[i], sticks[i]});
  SharedPiece p;
  p.cube = from_numpy<uint64_t>(d, "cube");
  const auto keys = from_numpy<uint64_t>(d, "keys"), apex_keys = from_numpy<uint64_t>(d, "apex_keys");
  const auto values = from_numpy<uint32_t>(d, "values");
  const auto apex_pos = from_numpy<double>(d, "apex_pos");
  if (keys.size() != 3 * p.cube.size() || values.size() != 2 * p.cube.size() || apex_pos.size() != 3 * apex_keys.size())
    throw UsageError("a label block's surface arrays do not match (not from _label_block?)");
  for (size_t i = 0; i < p.cube.size(); ++i) {
    p.keys.push_back({keys[3 * i], keys[3 * i + 1], keys[3 * i + 2]});
    p.values.push_back({values[2 * i], values[2 * i + 1]});
  }
  for (size_t i = 0; i < apex_keys.size(); ++i)
    p.apexes.push_back({apex_keys[i], Vec3(apex_pos[3 * i], apex_pos[3 * i + 1], apex_pos[3 * i + 2])});
  if (d.contains("underivable")) p.underivable = d["underivable"].cast<std::string>();
  if (d.contains("underivable_cube")) p.underivable_cube = d["underivable_cube"].cast<uint64_t>();
  return {std::move(t), std::move(p)};
}

// Every block's part, merged and pressed as `press --labels --chunk`: the
// table, the assembled shared surface, each label's flats on the mask of its
// box (read(lo, hi) returns the label map's samples of that box).
py::object py_press_label_blocks(const py::list& blocks, const py::handle& shape, const py::object& labels,
                                 const py::function& read, const py::object& spacing, const py::object& origin,
                                 const py::object& direction, bool interfaces, const py::kwargs& kw) {
  SurfaceOptions o;
  set_options(o, kw);
  check_shared_options(kw);
  const Lattice lattice = whole_lattice(shape, spacing, origin, direction);
  std::vector<LabelTable> parts;
  std::vector<SharedPiece> pieces;
  for (const py::handle& h : blocks) {
    auto [t, p] = label_block_from_dict(h.cast<py::dict>());
    parts.push_back(std::move(t));
    pieces.push_back(std::move(p));
  }
  ScalarVolume header;
  header.lattice = lattice;
  header.source = "array";
  const std::vector<double> values = label_values(labels);
  // The label map's samples of a box, from Python (the GIL taken for it:
  // flats run labels on several threads).
  const BoxRead box_read = [&read](const Box& box) {
    py::gil_scoped_acquire gil;
    const py::array a = py::module_::import("numpy").attr("asarray")(read(py::cast(box.lo), py::cast(box.hi)));
    ScalarVolume v = to_volume(a, py::make_tuple(1, 1, 1), py::make_tuple(0, 0, 0), py::none(), "xyz");
    v.source = "array";
    return v;
  };
  std::vector<LabelInfo> chosen;
  std::vector<Mesh> meshes;
  std::vector<size_t> flats;
  std::optional<SharedLabels> r;
  {
    py::gil_scoped_release release;
    const LabelTable table = merge_label_tables(parts, header);
    chosen = select_labels(table, values, "array");
    SharedSurface surface = assemble_shared_surface(lattice, std::move(pieces), "array");
    r = press_shared_labels(std::move(surface), masks_read(lattice, "array", box_read), table, o, "array");
    cut_labels(*r, chosen, meshes, flats);
  }
  return labels_result(chosen, std::move(meshes), flats, true, &*r, interfaces);
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
  out.lattice = scalar.lattice;
  if (o.simplify.faces || o.simplify.max_error) out.stats["simplify"] = simplify_stats(r.simplify);
  out.stats["method"] = std::string(method_name(o.method));
  out.stats["blocks"] = st.blocks;
  out.stats["sticks"] = st.sticks;
  out.stats["vertices"] = out.mesh.vertex_count();
  out.stats["triangles"] = out.mesh.face_count();
  out.stats["iterations"] = r.press.iterations;
  if (o.method == Method::pressing) out.stats["residual"] = r.press.residual;  // as press()'s, the halo mode's too
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
        "One block's piece, extracted (voxpress.dask): mask is the block's read box, non-zero inside; threads 0: all "
        "cores.");
  m.def("_press_rounds", &py_press_rounds, py::arg("shape"), py::kw_only(), py::arg("halo"), py::arg("bounds"),
        py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0), py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0),
        py::arg("direction") = py::none(),
        "The halo mode's rounds [(first, last, measured)]: sweeps of the whole run between exchanges "
        "(press_rounds); measured: the round holds sweeps of the last stage.");
  py::class_<PyBlockRounds>(m, "_BlockRounds",
                            "One block of the halo mode, extracted once from its read box (mask) and pressed round "
                            "after round (voxpress.dask); args: shape, block, chunk, halo, bounds, spacing, origin, "
                            "direction, threads and press()'s options. Pickles as (mask, args).")
      .def(py::init<py::array, py::dict>(), py::arg("mask"), py::arg("args"))
      .def("round", &PyBlockRounds::round, py::arg("state"), py::arg("first"), py::arg("last"),
           "Sweeps [first, last) from the state of the pieces of the last round around the block: its piece.")
      .def("finish", &PyBlockRounds::finish, py::arg("state"), py::arg("measure") = true,
           "The last step after the rounds: the residual at the final t, the quadric fit, the block's piece.")
      .def_property_readonly("nbytes", &PyBlockRounds::nbytes, "Memory held (what Dask's sizeof reports).")
      .def(py::pickle([](const PyBlockRounds& b) { return b.state(); },
                      [](const py::tuple& s) {
                        if (s.size() != 2) throw UsageError("_BlockRounds: a bad pickle");
                        return PyBlockRounds(s[0].cast<py::array>(), s[1].cast<py::dict>());
                      }));
  m.def("_merge", &py_merge, py::arg("pieces"), py::kw_only(), py::arg("shape"),
        "One piece of consecutive ones (each one's blocks follow the one before): a step of voxpress.dask's tree "
        "reduction.");
  m.def("_stitch", &py_stitch, py::arg("pieces"), py::kw_only(), py::arg("shape"),
        py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0), py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0),
        py::arg("direction") = py::none(), py::arg("smooth") = false,
        "The mesh of every block's piece (any order); smooth: the pieces were only extracted (halo 0), "
        "smooth the stitched sticks with the options (press()'s).");
  m.def("_label_block", &py_label_block, py::arg("samples"), py::kw_only(), py::arg("shape"), py::arg("block"),
        py::arg("chunk"), py::arg("threads") = 0,
        "One label-map block's table part and shared-surface piece (voxpress.dask.press_labels); samples is the "
        "block's read box of chunk_plan.");
  m.def("_press_label_blocks", &py_press_label_blocks, py::arg("blocks"), py::kw_only(), py::arg("shape"),
        py::arg("labels") = py::none(), py::arg("read"), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
        py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::arg("direction") = py::none(),
        py::arg("interfaces") = false,
        "press_labels() of every block's _label_block: {label: Mesh} (and the interfaces with interfaces=True); "
        "read(lo, hi) returns the label map's samples of a box, for each label's flats.");
}

}  // namespace voxpress::python
