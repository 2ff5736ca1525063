#!/usr/bin/env python3
"""Python call overhead: voxpress.press on a 128^3 mask, wall time of the
call versus the C++ API calls it makes (binarize + smooth_surface, timed
inside). The difference is what the binding adds: argument checks, the
mask copy into x-fastest order and building the Mesh. Both memory orders.

    PYTHONPATH=build/python python3 bench/python_overhead.py [--runs 5]
"""
import argparse
import statistics
import time

import numpy as np

import voxpress

ap = argparse.ArgumentParser()
ap.add_argument("--runs", type=int, default=5)
args = ap.parse_args()

n = 128
i, j, k = np.indices((n, n, n), dtype=np.float32)
mask = (i - 63.7) ** 2 + (j - 64.2) ** 2 + (k - 63.9) ** 2 < 55.0 ** 2
for order, m in [("C", mask), ("Fortran", np.asfortranarray(mask))]:
    for method in ["pressing", "diamond"]:
        wall, inner = [], []
        for _ in range(args.runs):
            t0 = time.perf_counter()
            mesh = voxpress.press(m, method=method)
            wall.append(time.perf_counter() - t0)
            s = mesh.stats
            inner.append(s["seconds_binarize"] + s["seconds_extract"] + s["seconds_smooth"])
        w, c = statistics.median(wall), statistics.median(inner)
        print(f"{method:9s} {order:7s} 128^3 sphere, {mesh.stats['vertices']} vertices: call {w * 1e3:.1f} ms, "
              f"C++ calls {c * 1e3:.1f} ms, overhead {(w - c) * 1e3:.1f} ms ({100 * (w - c) / c:.1f} %)")
