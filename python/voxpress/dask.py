"""Chunked Pressing on Dask: volumes larger than one machine.

    import dask.array as da, voxpress.dask
    from dask.distributed import Client
    client = Client("scheduler:8786")                  # or LocalCluster(), dask-jobqueue, Kubernetes
    mask = da.from_zarr("cells.zarr", component="mask")
    mesh = voxpress.dask.press(mask, chunk=256, spacing=(0.5, 0.5, 2.0))
    mesh.save("cells.ply")

The volume is cut into blocks of `chunk` samples per side (voxpress.chunk_plan).
Each block, read with `halo` more samples on every side, is one Dask task
(voxpress._press_block, run on a worker; with a halo, the block is
extracted once, voxpress._BlockRounds, and pressed in one task per round
of sweeps, then finished) returning its
piece of the surface:
numpy arrays of global stick keys, codes, pressed positions and triangles,
which pickle compactly. Consecutive pieces merge on the workers, up to
split_every at a time (a tree reduction, voxpress._merge), and the caller
turns the few pieces left
into one mesh with exactly the sticks, triangles and order of the
whole-volume run: byte for byte `voxpress press --chunk` on the same
samples (exact mode: the caller smooths it, flats and sharp edges
included). Dask does the scheduling, transfer
and retries; nothing here is a scheduler.
"""
import warnings

import numpy as np
from dask.sizeof import sizeof

from . import _voxpress


def _inside(array, label, threshold):
    """The inside samples as a boolean Dask array (lazy)."""
    if label is not None and threshold is not None:
        raise _voxpress.UsageError("choose one of label and threshold")
    if threshold is not None:
        return array >= threshold
    if label is not None and label not in ("all-nonzero", "nonzero"):
        return array == label
    if array.dtype == bool:
        return array
    return array != 0


def _block(mask, **kw):
    return _voxpress._press_block(np.asarray(mask), **kw)


def _merge(*pieces, **kw):  # a module function pickles by name; the binding itself does not
    return _voxpress._merge(list(pieces), **kw)


def _hold(mask, args):
    """Block i of the halo mode, extracted once: kept on its worker between its rounds."""
    return _voxpress._BlockRounds(np.asarray(mask), args)


def _round(held, state, first, last):
    return held.round(list(state), first, last)


def _finish(held, state, measure):
    return held.finish(list(state), measure)


@sizeof.register(_voxpress._BlockRounds)
def _sizeof_block(held):  # its true size, so that Dask runs a block's rounds where it is held
    return int(held.nbytes)


def _final_residual(*pieces):
    """The whole run's residual at its final t: the max over the blocks' last steps."""
    return max((float(p["residuals"][0]) for p in pieces if len(p["residuals"])), default=0.0)


def _sweep_residuals(*pieces):
    """The whole run's residual per sweep of a round: the max over its blocks (NaN before the last stage)."""
    rows = [p["residuals"] for p in pieces if len(p["residuals"])]
    if not rows:
        return np.zeros(0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN columns: sweeps before the last stage
        return np.nanmax(np.vstack(rows), axis=0)


def _halo_tasks(plan, inside, rounds, measure, common, options):
    """The halo mode's graph: each block extracted once (_hold), one task per
    block per round reading the pieces of the blocks whose core meets its
    read box from the round before, then each block's last step; and per
    round that holds sweeps of the last stage, the residual per sweep. The
    rounds' tasks are one graph layer (thousands of tasks: built as a dict,
    not one Delayed call each)."""
    import dask
    from dask.base import tokenize
    from dask.delayed import Delayed
    from dask.highlevelgraph import HighLevelGraph

    def meets(core, read):
        return all(core[0][a] < read[1][a] and read[0][a] < core[1][a] for a in range(3))

    around = [[c["block"] for c in plan if meets(c["core"], b["read"])] for b in plan]
    hold = dask.delayed(_hold, pure=True)
    held = []
    for b in plan:
        (x0, y0, z0), (x1, y1, z1) = b["read"]
        held.append(hold(inside[x0:x1, y0:y1, z0:z1], dict(block=b["block"], **common, **options)))
    name = "voxpress-rounds-" + tokenize([h.key for h in held], rounds, measure)
    layer, last, residuals = {}, None, []

    def state(i):  # the pieces around block i from the round before (none before the first)
        return [] if last is None else [last[c] for c in around[i]]

    for r, (first, end, measured) in enumerate(rounds):
        keys = [f"{name}-{r}-{i}" for i in range(len(plan))]
        for i, key in enumerate(keys):
            layer[key] = (_round, held[i].key, state(i), first, end)
        last = keys
        if measured:
            layer[f"{name}-residuals-{r}"] = (_sweep_residuals, *keys)
            residuals.append((r, f"{name}-residuals-{r}"))
    done = [f"{name}-finish-{i}" for i in range(len(plan))]
    for i, key in enumerate(done):
        layer[key] = (_finish, held[i].key, state(i), measure)
    graph = HighLevelGraph.from_collections(name, layer, dependencies=held)
    return [Delayed(k, graph, layer=name) for k in done], [(r, Delayed(k, graph, layer=name)) for r, k in residuals]


def _merged(tasks, split_every, shape):
    """Tree reduction: up to split_every consecutive pieces merge on a worker
    (a k-way merge in whole-run order), level after level, until the caller
    has at most split_every of them to stitch."""
    import dask

    merge = dask.delayed(_merge, pure=True)
    while len(tasks) > split_every:
        tasks = [merge(*tasks[i:i + split_every], shape=shape) for i in range(0, len(tasks), split_every)]
    return tasks


def press(array, *, chunk=256, halo=0, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None,
          label=None, threshold=None, client=None, threads=0, split_every=16, **options):
    """The smooth surface of a Dask, Zarr or numpy array, block by block on Dask; returns a Mesh.

    array: indexed array[i, j, k] (x first); a zarr array is wrapped with
    dask.array.from_zarr. Inside: non-zero samples (a bool mask as is);
    label=N takes array == N, threshold=T array >= T. spacing, origin,
    direction and the options (iterations, flats, sharpen, ...) are press()'s.
    halo=0 (exact): the workers extract their blocks' sticks and the caller
    smooths the stitched surface: `voxpress press` byte for byte, flats and
    sharp edges included; the caller holds the surface, never the volume.
    halo=H: the workers press their blocks too, reading H samples around
    them, in rounds that exchange the blocks' borders (`press --chunk N
    --halo H`): each worker holds its blocks' surfaces (with their halos),
    the caller only the stitched mesh; Pressing only
    (flats off); the whole run's surface up to rounding (stats iterations
    and residual as press()'s); the wider the halo, the fewer the rounds
    (docs/BENCHMARKS.md, Chunked). client: a dask.distributed Client; None
    uses Dask's current scheduler (a Client you created, else threads).
    threads: cores one block task uses (0: all its machine's; set it to the
    worker's threads when several workers share a machine). split_every:
    the tree reduction's fan-in (pieces merged per task, and at most what
    the caller receives).
    """
    import dask
    import dask.array as da

    if not isinstance(array, da.Array):
        if type(array).__module__.startswith("zarr"):
            array = da.from_zarr(array)
        else:
            array = da.from_array(np.asarray(array), chunks=chunk)
    if int(split_every) < 2:
        raise _voxpress.UsageError(f"split_every must be at least 2 (got {split_every})")
    split_every = int(split_every)
    if array.ndim != 3:
        raise _voxpress.UsageError(f"the array must be 3-D (got {array.ndim} dimensions)")
    shape = tuple(int(n) for n in array.shape)
    inside = _inside(array, label, threshold)
    # Inside count and box: three 1-D projections, one pass over the blocks.
    counts = [inside.sum(axis=tuple(a for a in range(3) if a != axis)) for axis in range(3)]
    counts = client.gather(client.compute(counts)) if client is not None else dask.compute(*counts)
    total = int(counts[0].sum())
    if total == 0:
        raise _voxpress.InputError("array: the volume is empty: no sample is inside (check label / threshold)")
    if total == int(np.prod(shape)):
        raise _voxpress.InputError("array: the volume is full: every sample is inside, so the only surface is the "
                                   "grid's bounding box (check label / threshold)")
    lo = [int(np.flatnonzero(c)[0]) for c in counts]
    hi = [int(np.flatnonzero(c)[-1]) + 1 for c in counts]
    options = {k: v for k, v in options.items() if v is not None}
    plan = _voxpress.chunk_plan(shape, chunk=chunk, halo=halo)
    common = dict(shape=shape, chunk=chunk, halo=halo, bounds=(lo, hi), spacing=spacing, origin=origin,
                  direction=direction, threads=threads)

    def compute(*graphs):
        return list(client.gather(client.compute(list(graphs)))) if client is not None else list(dask.compute(*graphs))

    pressed = {}
    if halo:
        # Rounds of sweeps between exchanges (voxpress/chunk/chunked.h): the
        # whole run's surface. Where the whole run would stop (the first
        # sweep of its last stage whose residual is within the tolerance),
        # the graph is built again up to that sweep.
        # One block has no artificial border (its box is the volume's): one round, as in-process.
        reach = halo if len(plan) > 1 else 2 ** 31 - 1
        rounds = [tuple(r) for r in _voxpress._press_rounds(shape, halo=reach, bounds=(lo, hi), spacing=spacing,
                                                            origin=origin, direction=direction, **options)]
        tolerance = options.get("tolerance", 1e-4)
        done, measured = _halo_tasks(plan, inside, rounds, True, common, options)
        tasks = _merged(done, split_every, shape)
        out = compute(*tasks, dask.delayed(_final_residual, pure=True)(*done), *[d for _, d in measured])
        pieces, final, rows = out[:len(tasks)], out[len(tasks)], out[len(tasks) + 1:]
        sweep = [(rounds[r][0] + k, v) for (r, _), row in zip(measured, rows) for k, v in enumerate(row)
                 if not np.isnan(v)]
        stop = next(((k, v) for k, v in sweep if v <= tolerance), None)
        if stop is not None:
            cut = [(a, min(b, stop[0]), m) for a, b, m in rounds if a < stop[0]]
            pieces = compute(*_merged(_halo_tasks(plan, inside, cut, False, common, options)[0], split_every, shape))
            pressed = {"iterations": stop[0], "residual": stop[1]}
        else:
            pressed = {"iterations": rounds[-1][1] if rounds else 0, "residual": final}
    else:
        block = dask.delayed(_block, pure=True)
        tasks = []
        for b in plan:
            (x0, y0, z0), (x1, y1, z1) = b["read"]
            tasks.append(block(inside[x0:x1, y0:y1, z0:z1], block=b["block"], **common))
        pieces = compute(*_merged(tasks, split_every, shape))
    mesh = _voxpress._stitch(pieces, shape=shape, spacing=spacing, origin=origin, direction=direction,
                             smooth=not halo, **(options if not halo else {}))
    for key, value in pressed.items():
        mesh.stats[key] = value
    return mesh


def _label_block(samples, **kw):
    return _voxpress._label_block(np.asarray(samples), **kw)


def _labels_arg(labels):
    # None and a string go to press_labels's own reading ("all" as on the
    # command line, another string a UsageError); list("all") split it into
    # characters (issue 73).
    return labels if labels is None or isinstance(labels, str) else list(labels)


def press_labels(array, labels=None, *, chunk=256, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None,
                 client=None, threads=0, interfaces=False, **options):
    """Every label of a label map, block by block on Dask: voxpress.press_labels's result, byte for byte.

    array: an integer label map (Dask, Zarr or numpy; array[i, j, k]),
    0 the background. Each block (chunk samples per side, read with one
    sample around it) is one task (voxpress._label_block on a worker)
    returning its part of the label table and its piece of the shared
    surface (global vertex keys: numpy arrays that pickle compactly). The
    caller assembles the whole shared surface (`press --labels --chunk`),
    reads each label's box from the array itself for its flats (Dask's
    local threads: the caller must reach the array's storage; flats=False
    skips that), presses it and cuts {label: Mesh} from it; interfaces=True also
    returns the shared surface with its label pairs. The caller holds the
    surface, never the volume. labels, spacing, origin, direction and the
    options are voxpress.press_labels's; client and threads as in press().
    """
    import dask
    import dask.array as da

    if not isinstance(array, da.Array):
        if type(array).__module__.startswith("zarr"):
            array = da.from_zarr(array)
        else:
            array = da.from_array(np.asarray(array), chunks=chunk)
    if array.ndim != 3:
        raise _voxpress.UsageError(f"the array must be 3-D (got {array.ndim} dimensions)")
    shape = tuple(int(n) for n in array.shape)
    block = dask.delayed(_label_block, pure=True)
    tasks = []
    for b in _voxpress.chunk_plan(shape, chunk=chunk):
        (x0, y0, z0), (x1, y1, z1) = b["read"]
        tasks.append(block(array[x0:x1, y0:y1, z0:z1], shape=shape, block=b["block"], chunk=chunk, threads=threads))
    parts = client.gather(client.compute(tasks)) if client is not None else list(dask.compute(*tasks))

    def read(lo, hi):  # a label's box, for its flats: read by the caller (one small box per label, no round trip)
        with warnings.catch_warnings():  # Dask warns of local threads while a Client is active: meant here
            warnings.simplefilter("ignore", UserWarning)
            return np.asarray(array[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]].compute(scheduler="threads"))

    if "disable_passes" in options and options["disable_passes"] is not None:
        options["disable_passes"] = list(options["disable_passes"])
    return _voxpress._press_label_blocks(parts, shape=shape, labels=_labels_arg(labels), read=read,
                                         spacing=spacing, origin=origin, direction=direction, interfaces=interfaces,
                                         **{k: v for k, v in options.items() if v is not None})
