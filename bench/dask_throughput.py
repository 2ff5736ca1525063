#!/usr/bin/env python3
"""Throughput of voxpress.dask.press (issue 56) on a dask.distributed
LocalCluster: voxels/s and triangles/s for 1 and 2 worker processes of one
thread each (each block task uses its worker's one core), in both modes
(exact: the workers extract, the caller smooths the whole surface; halo:
the workers press their blocks too); the in-process `press(chunk=)` of
the same mode for reference, whether Dask's mesh has its bytes, and the
seconds the tasks computed and waited for transfers, summed over the
workers (Dask's task stream).

    PYTHONPATH=build/python python3 bench/dask_throughput.py [--n 512] [--chunk 128] [--runs 1]
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


def busy(stream):
    """The tasks' compute and transfer seconds, summed over the workers (the last run's task stream)."""
    spent = {"compute": 0.0, "transfer": 0.0}
    for task in stream:
        for part in task["startstops"]:
            if part["action"] in spent:
                spent[part["action"]] += part["stop"] - part["start"]
    return f"{spent['compute']:.1f} / {spent['transfer']:.1f} s"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=512)
    ap.add_argument("--chunk", type=int, default=128)
    ap.add_argument("--runs", type=int, default=1)
    args = ap.parse_args()
    import dask.array as da
    import distributed

    mask = sphere(args.n)
    voxels = mask.size
    array = da.from_array(mask, chunks=args.chunk)
    print(f"{args.n}³ rotated ellipsoid mask, blocks of {args.chunk}:\n")
    print("| mode | run | time | voxels/s | triangles/s | same bytes as in-process | tasks' compute / transfer |")
    print("|---|---|---:|---:|---:|---|---:|")
    for mode, halo in [("exact (workers extract, the caller smooths)", 0), ("halo 32 (workers press)", 32)]:
        t0 = time.perf_counter()
        ref = voxpress.press(mask, chunk=args.chunk, halo=halo)
        base = time.perf_counter() - t0
        tri = len(ref.faces)
        rows = [("in-process `press(chunk=)`, all cores", base, True, "")]
        for workers in [1, 2]:
            with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                          dashboard_address=None) as cluster, distributed.Client(cluster) as client:
                times, same = [], True
                for _ in range(args.runs):
                    with distributed.get_task_stream(client) as stream:
                        t0 = time.perf_counter()
                        mesh = voxpress.dask.press(array, chunk=args.chunk, halo=halo, client=client, threads=1)
                        times.append(time.perf_counter() - t0)
                    same &= bool(np.array_equal(mesh.vertices, ref.vertices) and np.array_equal(mesh.faces, ref.faces))
            rows.append((f"Dask, {workers} worker process{'es' if workers > 1 else ''} of 1 thread",
                         statistics.median(times), same, busy(stream.data)))
        for name, t, same, work in rows:
            print(f"| {mode} | {name} | {t:.1f} s | {voxels / t / 1e6:.1f} M | {tri / t / 1e6:.3f} M | "
                  f"{'yes' if same else 'NO'} | {work} |", flush=True)


if __name__ == "__main__":
    main()
