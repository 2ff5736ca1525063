#!/usr/bin/env python3
"""A label map block by block (`press --labels --chunk`, issue 56 item 4):
the 61-label TotalSegmentator map tiled N x N x N (each copy's labels
renumbered, one background sample between copies: N^3 x 61 labels), written
as a raw NRRD, meshed in memory and streamed block by block. Prints a
markdown table: wall time, peak RSS, labels, triangles of the interfaces,
and whether every output file is the same bytes as the in-memory run's.

    VOXPRESS_CLI=build/bin/voxpress PYTHONPATH=build/python \
        python3 bench/chunk_labels.py [--tiles 2] [--chunk 128] [--threads 2] [--dask]

--dask adds voxpress.press_labels in process and voxpress.dask.press_labels
on a LocalCluster of 1 and 2 worker processes (one thread each): time and
whether every label's mesh has the in-process bytes.
"""
import argparse
import filecmp
import json
import os
import pathlib
import shutil
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from chunk_seams import run  # noqa: E402

MAP = pathlib.Path(__file__).resolve().parents[2] / "shared/data/medical/totalseg_example_seg_fast_force_split.nii.gz"


def write_raw_nrrd(path, data, spacing, origin):
    """uint16 [i, j, k] samples as a raw NRRD (axis-aligned, RAS like the map)."""
    s = [float(x) for x in spacing]
    dirs = f"({s[0]},0,0) (0,{s[1]},0) (0,0,{s[2]})"
    o = ",".join(repr(float(x)) for x in origin)
    with open(path, "wb") as f:
        f.write(f"NRRD0004\ntype: uint16\nendian: little\ndimension: 3\nspace: right-anterior-superior\n"
                f"sizes: {data.shape[0]} {data.shape[1]} {data.shape[2]}\nspace directions: {dirs}\n"
                f"space origin: ({o})\nencoding: raw\n\n".encode())
        f.write(np.ascontiguousarray(data.astype("<u2").T).tobytes())


def dask_rows(tiled, lattice, args):
    """In-process press_labels against voxpress.dask.press_labels on worker processes."""
    import time

    import dask.array as da
    import distributed
    import voxpress
    import voxpress.dask

    kw = dict(spacing=tuple(lattice.spacing), origin=tuple(lattice.origin))
    t = time.perf_counter()
    ref = voxpress.press_labels(tiled, **kw)
    rows = [f"| in-process `press_labels`, all cores | {time.perf_counter() - t:.1f} s | |"]
    for workers in (1, 2):
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            array = da.from_array(tiled, chunks=args.chunk)
            t = time.perf_counter()
            got = voxpress.dask.press_labels(array, chunk=args.chunk, client=client, threads=1, **kw)
            s = time.perf_counter() - t
        same = sorted(got) == sorted(ref) and all(
            (got[k].vertices == ref[k].vertices).all() and (got[k].faces == ref[k].faces).all() for k in ref)
        rows.append(f"| `voxpress.dask.press_labels`, {workers} worker process(es) of 1 thread | {s:.1f} s | "
                    f"{'yes' if same else 'NO'} |")
        print(rows[-1], file=sys.stderr, flush=True)
    print(f"\nDask, blocks of {args.chunk}:\n")
    print("| run | time | same bytes as in-process |")
    print("|---|---:|---|")
    print("\n".join(rows))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tiles", type=int, default=2)
    ap.add_argument("--chunk", type=int, default=128)
    ap.add_argument("--threads", default="2")
    ap.add_argument("--dask", action="store_true")
    args = ap.parse_args()
    if not MAP.exists():
        sys.exit(f"{MAP} is absent (../shared/data)")
    import voxpress

    data, lattice = voxpress.read_volume(str(MAP))
    base = np.asarray(data).astype(np.uint16)
    n = args.tiles
    d = np.array(base.shape)
    tiled = np.zeros(tuple(n * (d + 1)), dtype=np.uint16)
    step = int(base.max()) + 1
    for t, (a, b, c) in enumerate(np.ndindex(n, n, n)):
        tile = np.where(base > 0, base + np.uint16(t * step), 0)
        tiled[a * (d[0] + 1):a * (d[0] + 1) + d[0], b * (d[1] + 1):b * (d[1] + 1) + d[1],
              c * (d[2] + 1):c * (d[2] + 1) + d[2]] = tile
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="voxpress_labels_"))
    try:
        raw = tmp / "map.nrrd"
        write_raw_nrrd(raw, tiled, lattice.spacing, lattice.origin)
        labels = len(np.unique(tiled)) - 1
        rows, ref = [], None
        for name, extra in [("whole volume in memory", []), (f"`--chunk {args.chunk}`, raw NRRD streamed",
                                                              ["--chunk", args.chunk]),
                            (f"`--chunk {args.chunk} --no-flats`, raw NRRD streamed",
                             ["--chunk", args.chunk, "--no-flats"])]:
            out = tmp / ("out%d" % len(rows))
            _, s, rss = run(["-q", "--threads", args.threads, "press", str(raw), "--labels", "all",
                             *map(str, extra), "-o", str(out)])
            tri = json.loads((out / "labels.json").read_text())["interfaces"]["triangles"]
            if ref is None:
                ref, same = out, ""
            elif "--no-flats" in extra:
                same = "n/a (no flats)"
            else:
                names = sorted(os.listdir(ref))
                same = "yes, all %d files" % len(names) if names == sorted(os.listdir(out)) and all(
                    filecmp.cmp(ref / f, out / f, shallow=False) for f in names) else "NO"
            rows.append(f"| {name} | {s:.1f} s | {rss / 1024:.2f} GiB | {labels} | {tri} | {same} |")
            print(rows[-1], file=sys.stderr, flush=True)
        print(f"61-label map tiled {n}x{n}x{n}: {tiled.shape[0]}x{tiled.shape[1]}x{tiled.shape[2]} uint16, "
              f"{labels} labels, {args.threads} threads:\n")
        print("| run | time | peak RSS | labels | interface triangles | same bytes as in memory |")
        print("|---|---:|---:|---:|---:|---|")
        print("\n".join(rows))
        if args.dask:
            dask_rows(tiled, lattice, args)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
