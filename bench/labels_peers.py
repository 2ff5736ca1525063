#!/usr/bin/env python3
"""`press --labels all` against 3D Slicer's per-segment closed-surface export
on a label map upsampled with smooth label boundaries (issue 74).

The upsampled maps: each label's indicator on its box (grown by 3 samples),
smoothed by a Gaussian of 0.75 sample (the widest that keeps every label of
the example), interpolated linearly to the finer
lattice (cell-centred, so the physical extent is kept), then the arg-max
over the labels and the background. Written once as NRRD next to the
output and reused.

Slicer's export, per segment: the segment's box padded by one sample,
vtkDiscreteFlyingEdges3D + vtkWindowedSincPolyDataFilter (20 iterations,
pass band 0.01: Slicer's defaults); its seconds are the filters' alone.
voxpress: the whole process of `voxpress press --labels all`.

  PYTHONPATH=build/python /usr/bin/python3 bench/labels_peers.py --factors 1,2,4
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np
from scipy import ndimage

import voxpress
from peers import slicer_filters  # exits with a message without python3-vtk9


def boxes(labels):
    """{value: (lo, hi)} inclusive index boxes of every non-zero label."""
    out = {}
    for value, sl in enumerate(ndimage.find_objects(labels), start=0):
        if sl is not None and value + 1 != 0:
            out[value + 1] = (np.array([s.start for s in sl]), np.array([s.stop - 1 for s in sl]))
    return out


def upsample(labels, factor):
    """The arg-max of every label's smoothed, linearly interpolated indicator."""
    shape = np.array(labels.shape)
    fine = shape * factor
    best = np.full(tuple(fine), -1.0, dtype=np.float32)
    out = np.zeros(tuple(fine), dtype=labels.dtype)
    grow = 3
    for value, (lo, hi) in [(0, (np.zeros(3, int), shape - 1))] + sorted(boxes(labels).items()):
        lo = np.maximum(lo - grow, 0)
        hi = np.minimum(hi + grow, shape - 1)
        box = tuple(slice(a, b + 1) for a, b in zip(lo, hi))
        ind = ndimage.gaussian_filter((labels[box] == value).astype(np.float32), 0.75, mode="nearest")
        up = ndimage.zoom(ind, factor, order=1, mode="nearest", grid_mode=True)
        fbox = tuple(slice(a * factor, (b + 1) * factor) for a, b in zip(lo, hi))
        view = best[fbox]
        win = up > view
        view[win] = up[win]
        out[fbox][win] = value
    return out


def write_nrrd(path, array, spacing, origin):
    with open(path, "wb") as f:
        f.write(("NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\n"
                 f"sizes: {array.shape[0]} {array.shape[1]} {array.shape[2]}\n"
                 f"space directions: ({spacing[0]!r},0,0) (0,{spacing[1]!r},0) (0,0,{spacing[2]!r})\n"
                 f"space origin: ({origin[0]!r},{origin[1]!r},{origin[2]!r})\n"
                 "encoding: raw\nendian: little\n\n").encode())
        f.write(np.asfortranarray(array.astype(np.uint8)).tobytes(order="F"))


def slicer_segments(labels):
    """Seconds of Slicer's default export of every segment (filters only)."""
    seconds = 0.0
    triangles = 0
    for value, (lo, hi) in sorted(boxes(labels).items()):
        box = tuple(slice(a, b + 1) for a, b in zip(lo, hi))
        m = labels[box] == value
        padded = np.zeros(tuple(np.array(m.shape) + 2), dtype=np.uint8)
        padded[1:-1, 1:-1, 1:-1] = m
        poly, t = slicer_filters(padded)
        seconds += t
        triangles += poly.GetNumberOfPolys()
    return seconds, triangles


def voxpress_press(cli, path, out_dir, extra):
    t0 = time.perf_counter()
    r = subprocess.run([cli, "-q", "press", path, "--labels", "all", "-o", out_dir] + extra,
                       capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"bench/labels_peers.py: voxpress press {path}: {r.stderr.strip()}")
    return seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--map", default="../shared/data/medical/totalseg_example_seg_fast_force_split.nii.gz")
    p.add_argument("--factors", default="1,2,4")
    p.add_argument("--cli", default="build/bin/voxpress")
    p.add_argument("--out", default="out/bench/labels-peers")
    p.add_argument("--variants", default="default,--no-flats --no-sharpen",
                   help="comma-separated voxpress flag sets ('default': none)")
    a = p.parse_args()
    if not os.path.exists(a.map):
        sys.exit(f"bench/labels_peers.py: {a.map}: not found (needs ../shared/data)")
    os.makedirs(a.out, exist_ok=True)
    labels, lattice = voxpress.read_volume(a.map)
    labels = np.ascontiguousarray(labels)
    spacing = np.array(lattice.spacing)
    origin = np.array(lattice.origin)
    if not np.allclose(np.abs(np.array(lattice.direction)), np.eye(3)):
        sys.exit("bench/labels_peers.py: an oblique lattice; this script writes axis-aligned maps")
    variants = [v.strip() for v in a.variants.split(",")]
    print(f"| map | samples | labels | Slicer per segment: s / triangles | "
          + " | ".join(f"voxpress {v}: s (× Slicer)" for v in variants) + " |")
    print("|---|---|---:|---:|" + "---:|" * len(variants))
    for factor in [int(f) for f in a.factors.split(",")]:
        path = os.path.join(a.out, f"map-x{factor}.nrrd")
        if factor == 1:
            fine = labels
        else:
            fine = upsample(labels, factor)
        if not os.path.exists(path):
            # Cell-centred: the fine lattice covers the same physical box (identity or flipped axes).
            d = np.diag(np.array(lattice.direction))
            write_nrrd(path, fine, spacing / factor, origin + d * spacing * (-0.5 + 0.5 / factor))
        slicer_s, slicer_tris = slicer_segments(fine)
        cells = []
        for v in variants:
            extra = [] if v == "default" else v.split()
            s = voxpress_press(a.cli, path, os.path.join(a.out, f"x{factor}-{v.replace(' ', '')}"), extra)
            cells.append(f"{s:.1f} ({s / slicer_s:.1f}×)")
        mm = "×".join(f"{x:g}" for x in spacing / factor)
        print(f"| ×{factor} ({mm} mm) | {'×'.join(map(str, fine.shape))} | {len(np.unique(fine)) - 1} | "
              f"{slicer_s:.1f} / {slicer_tris} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
