#!/usr/bin/env python3
"""bench/peers.py: voxpress against 3D Slicer's default closed-surface
pipeline, on the same volumes, evaluated against the same truth.

Slicer's default (vtkBinaryLabelmapToClosedSurfaceConversionRule, smoothing
factor 0.5): vtkDiscreteFlyingEdges3D, then vtkWindowedSincPolyDataFilter
with 20 iterations and pass band 10^(-4 * 0.5) = 0.01 (normalized
coordinates, non-manifold smoothing on, boundary and feature-edge smoothing
off), through Debian's VTK 9.1 Python (python3-vtk9). voxpress runs as its
own process (`press`, whole process: read, press, write); the Slicer time is
the two filters alone, in this process. Every result is evaluated by
`voxpress eval` against the volume's recorded truth, in voxels.

    PYTHONPATH=build/python /usr/bin/python3 bench/peers.py \\
        --cases bunny.off,armadillo.obj,cad-part --seeds 1,2 --res 128

Volumes are generated (sphere, torus, box, cylinder, cad-part) or voxelized
from ../shared/data/meshes (any other case name), with random rotations.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

try:
    import vtk
    from vtk.util import numpy_support
except ImportError:
    sys.exit("bench/peers.py: needs VTK's Python module (apt install python3-vtk9)")
import voxpress

GENERATED = {"sphere", "torus", "box", "cylinder", "cad-part"}


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"bench/peers.py: {' '.join(cmd)}: {r.stderr.strip()}")


def slicer_filters(padded, origin=(0, 0, 0)):
    """Slicer's two filters on a padded uint8 mask (index space): (vtkPolyData, seconds of the filters)."""
    image = vtk.vtkImageData()
    image.SetDimensions(*padded.shape)
    image.SetOrigin(*origin)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(padded.ravel(order="F"), deep=True))
    t0 = time.perf_counter()
    fe = vtk.vtkDiscreteFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, 1)
    fe.ComputeGradientsOff()
    fe.ComputeNormalsOff()
    fe.ComputeScalarsOff()
    smoother = vtk.vtkWindowedSincPolyDataFilter()
    smoother.SetInputConnection(fe.GetOutputPort())
    smoother.SetNumberOfIterations(20)
    smoother.SetPassBand(0.01)
    smoother.BoundarySmoothingOff()
    smoother.FeatureEdgeSmoothingOff()
    smoother.NonManifoldSmoothingOn()
    smoother.NormalizeCoordinatesOn()
    smoother.Update()
    return smoother.GetOutput(), time.perf_counter() - t0


def slicer_default(volume_path, out_path):
    """Slicer's default labelmap -> closed surface; returns the filters' seconds."""
    mask, lattice = voxpress.read_volume(volume_path)
    nx, ny, nz = mask.shape
    # One voxel of background around the mask (as Slicer pads), index space.
    padded = np.zeros((nx + 2, ny + 2, nz + 2), dtype=np.uint8)
    padded[1:-1, 1:-1, 1:-1] = mask != 0
    poly, seconds = slicer_filters(padded, origin=(-1, -1, -1))
    idx = numpy_support.vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    tris = numpy_support.vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    # index -> physical: origin + direction diag(spacing) (i, j, k)
    M = np.asarray(lattice.direction) @ np.diag(lattice.spacing)
    pts = idx @ M.T + np.asarray(lattice.origin)
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    if np.einsum("ij,ij->i", a, np.cross(b, c)).sum() < 0:  # inward: flip
        tris = tris[:, ::-1]
    with open(out_path, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\n"
                "property double x\nproperty double y\nproperty double z\n"
                f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n")
        np.savetxt(f, pts, fmt="%.17g")
        np.savetxt(f, np.hstack([np.full((len(tris), 1), 3), tris]), fmt="%d")
    return seconds


def evaluate(cli, mesh, volume, tmp):
    out = os.path.join(tmp, "eval.json")
    run([cli, "-q", "eval", mesh, "--volume", volume, "--json", out])
    d = json.load(open(out))
    return d["voxels"]["result_to_truth"]["rms"], d["normal_error_deg"], d.get("labelled_sharp_edges", 0), \
        d["classification_violations"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="bunny.off,armadillo.obj,sphere,torus,cad-part,fandisk.off")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--cli", default="build/bin/voxpress")
    ap.add_argument("--data", default="../shared/data")
    a = ap.parse_args()
    methods = [("Slicer default", None), ("voxpress", []), ("voxpress, layer off", ["--disable-pass", "flats"])]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for case in a.cases.split(","):
            model = os.path.join(a.data, "meshes", case)
            if case not in GENERATED and not os.path.exists(model):
                print(f"skipping {case}: {model} not found", file=sys.stderr)
                continue
            for seed in a.seeds.split(","):
                vol = os.path.join(tmp, "v.nrrd")
                rot = ["--res", str(a.res), "--rotate", f"random:{seed}"]
                run([a.cli, "-q", "generate", case, "-o", vol] + rot if case in GENERATED else
                    [a.cli, "-q", "voxelize", model, "-o", vol] + rot)
                for name, args in methods:
                    out = os.path.join(tmp, "r.ply")
                    if args is None:
                        seconds = slicer_default(vol, out)
                    else:
                        t0 = time.perf_counter()
                        run([a.cli, "-q", "press", vol, "-o", out] + args)
                        seconds = time.perf_counter() - t0
                    rows.setdefault((case, name), []).append(evaluate(a.cli, out, vol, tmp) + (seconds,))
    print(f"res {a.res}, seeds {a.seeds}: r->t RMS (vox) / mean normal error (deg) / labelled sharp edges / "
          "violations / seconds, means over the seeds (Slicer: its two filters; voxpress: the whole process)\n")
    print("| case | " + " | ".join(m for m, _ in methods) + " | voxpress time / Slicer's |")
    print("|---|" + "---|" * (len(methods) + 1))
    for case in dict.fromkeys(c for c, _ in rows):
        cells, seconds = [], []
        for name, _ in methods:
            m = np.mean(np.array(rows[(case, name)], dtype=float), axis=0)
            cells.append(f"{m[0]:.4f} / {m[1]:.2f}° / {m[2]:.0f} / {m[3]:.0f} / {m[4]:.2f} s")
            seconds.append(m[4])
        print(f"| {case} | " + " | ".join(cells) + f" | {seconds[1] / seconds[0]:.0f}× |")


if __name__ == "__main__":
    main()
