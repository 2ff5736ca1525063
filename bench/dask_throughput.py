#!/usr/bin/env python3
"""Throughput of voxpress.dask.press (issue 56) on a dask.distributed
LocalCluster: voxels/s and triangles/s for 1 and 2 worker processes of one
thread each (each block task uses its worker's one core), and for one worker
whose tasks use every core; the in-process `press(chunk=)` for reference.
Every run's mesh is compared with the in-process one (same bytes).

    PYTHONPATH=build/python python3 bench/dask_throughput.py [--n 512] [--chunk 128] [--runs 2]
"""
import argparse
import statistics
import time

import numpy as np

import voxpress
import voxpress.dask


def sphere(n):
    i, j, k = np.indices((n, n, n), dtype=np.float32)
    c = n / 2 + np.array([0.31, -0.17, 0.23])
    return (i - c[0]) ** 2 + ((j - c[1]) / 0.9) ** 2 + ((k - c[2]) / 1.1) ** 2 < (0.38 * n) ** 2


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=512)
    ap.add_argument("--chunk", type=int, default=128)
    ap.add_argument("--runs", type=int, default=2)
    args = ap.parse_args()
    import dask.array as da
    import distributed

    mask = sphere(args.n)
    voxels = mask.size
    t0 = time.perf_counter()
    ref = voxpress.press(mask, chunk=args.chunk)
    base = time.perf_counter() - t0
    tri = len(ref.faces)
    rows = [("in-process `press(chunk=)`, all cores", base, True)]
    array = da.from_array(mask, chunks=args.chunk)
    for workers, threads in [(1, 1), (2, 1), (1, 2)]:
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            times, same = [], True
            for _ in range(args.runs):
                t0 = time.perf_counter()
                mesh = voxpress.dask.press(array, chunk=args.chunk, client=client, threads=threads)
                times.append(time.perf_counter() - t0)
                same &= bool(np.array_equal(mesh.vertices, ref.vertices) and np.array_equal(mesh.faces, ref.faces))
        rows.append((f"Dask, {workers} worker process{'es' if workers > 1 else ''}, {threads} thread{'s' if threads > 1 else ''} per task",
                     statistics.median(times), same))
    print(f"{args.n}³ rotated ellipsoid mask, blocks of {args.chunk} (exact mode: workers extract, the caller smooths), {tri} triangles:\n")
    print("| run | time | voxels/s | triangles/s | same bytes |")
    print("|---|---:|---:|---:|---|")
    for name, t, same in rows:
        print(f"| {name} | {t:.1f} s | {voxels / t / 1e6:.0f} M | {tri / t / 1e6:.2f} M | {'yes' if same else 'NO'} |")


if __name__ == "__main__":
    main()
