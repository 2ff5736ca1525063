#!/usr/bin/env python3
"""Seams of the chunked run (issues 56, 74): `press --chunk C [--halo H]`
against the whole-volume `press --no-flats` of the same volume, per block
size, in the exact mode (no halo: must be the same bytes) and per halo width
(blocks pressed apart in exchange rounds: the same surface up to rounding).
Prints one markdown row per run: the rounds, topology the same (faces
identical), max and RMS vertex distance in cells, `--check` (closed,
manifold, oriented, no self-intersection, 0 violations), wall time and peak
RSS of the process; a halo narrower than one sweep is refused (its row
says so).

    VOXPRESS_CLI=build/bin/voxpress PYTHONPATH=build/python \
        python3 bench/chunk_seams.py [--chunks 64,128] [--halos 16,32] [--threads 2] [--inputs sphere,cad-part,heart,heart512]

Inputs: a rotated sphere and the CAD part generated at 256^3, totalseg_heart
from ../shared/data as it is (`heart`) and tiled (mirrored, so the copies
join) to 512^3 (`heart512`, not in the default: about 46 rounds of 512
blocks); the heart is skipped with a message where ../shared is absent.
"""
import argparse
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np

root = pathlib.Path(__file__).resolve().parent.parent
cli = os.environ.get("VOXPRESS_CLI", str(root / "build/bin/voxpress"))
heart = root.parent / "shared/data/medical/totalseg_heart.nii.gz"


def run(args, refusable=False):
    """Runs the CLI under /usr/bin/time; returns (stdout+stderr, seconds, peak RSS MB); with
    `refusable`, a usage refusal returns (its message, None, None)."""
    p = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M", cli, *args], capture_output=True, text=True)
    out = p.stdout + p.stderr
    if p.returncode == 2 and refusable:
        return out.strip().splitlines()[0], None, None
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(args)}\n{out}")
    m = re.search(r"TIME ([0-9.]+) ([0-9]+)", out)
    return out, float(m.group(1)), int(m.group(2)) / 1024


def read_ply(path):
    """Vertices (float64 x, y, z) and triangles of a binary little-endian PLY
    as voxpress writes it, whatever other per-vertex and per-face properties
    (region, junction, colours) it carries."""
    b = pathlib.Path(path).read_bytes()
    i = b.index(b"end_header\n") + len(b"end_header\n")
    kinds = {"double": "<f8", "float": "<f4", "uchar": "u1", "char": "i1", "ushort": "<u2", "short": "<i2",
             "uint": "<u4", "int": "<i4"}
    elements, current = [], None
    for line in b[:i].decode().split("\n"):
        w = line.split()
        if w[:1] == ["element"]:
            current = [w[1], int(w[2]), []]
            elements.append(current)
        elif w[:1] == ["property"] and w[1] == "list":  # the face's vertex list: uchar count, 3 int indices
            current[2] += [("n", kinds[w[2]]), ("i", kinds[w[3]], 3)]
        elif w[:1] == ["property"]:
            current[2].append((w[2], kinds[w[1]]))
    out, offset = {}, i
    for name, count, fields in elements:
        dt = np.dtype(fields)
        out[name] = np.frombuffer(b, dtype=dt, count=count, offset=offset)
        offset += count * dt.itemsize
    v = out["vertex"]
    return np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64), out["face"]["i"]


def write_nrrd(path, mask):
    """A raw uint8 NRRD of a [i, j, k] mask (x fastest on disk)."""
    with open(path, "wb") as f:
        f.write(f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: {mask.shape[0]} {mask.shape[1]} {mask.shape[2]}\n"
                "encoding: raw\nendian: little\n\n".encode())
        f.write(np.ascontiguousarray(mask.astype(np.uint8).transpose(2, 1, 0)).tobytes())


def tiled_heart(path, n):
    import voxpress
    a, _ = voxpress.read_volume(str(heart))
    m = a != 0
    lo = np.argwhere(m).min(0)
    hi = np.argwhere(m).max(0) + 1
    m = m[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    reps = [-(-n // s) + 1 for s in m.shape]
    t = np.pad(m, [(0, (r - 1) * s) for r, s in zip(reps, m.shape)], mode="symmetric")[:n - 2, :n - 2, :n - 2]
    write_nrrd(path, np.pad(t, 1))  # one empty sample around: a closed solid


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--chunks", default="64,128")
    ap.add_argument("--halos", default="16,32")
    ap.add_argument("--threads", default="2")
    ap.add_argument("--inputs", default="sphere,cad-part,heart")
    args = ap.parse_args()
    wanted = args.inputs.split(",")
    chunks = [int(c) for c in args.chunks.split(",")]
    halos = [int(h) for h in args.halos.split(",") if h]
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="voxpress_seams_"))
    inputs = []
    for shape in [s for s in ["sphere", "cad-part"] if s in wanted]:
        p = tmp / f"{shape}.nrrd"
        run(["-q", "generate", shape, "--res", "256", "--rotate", "random:1", "-o", str(p)])
        inputs.append((f"{shape} 256³ (rotated)", p))
    for key in [k for k in ["heart", "heart512"] if k in wanted]:
        if not heart.exists():
            print(f"skipping {key}: {heart} is absent", file=sys.stderr)
        elif key == "heart":  # the real mask as it is (1.5 mm, 233 x 167 x 191)
            inputs.append(("totalseg_heart (real mask)", heart))
        else:
            p = tmp / "heart512.nrrd"
            tiled_heart(p, 512)
            inputs.append(("totalseg_heart tiled to 512³", p))
    print("| input | run | rounds | time | peak RSS | topology | max diff | RMS diff | check |")
    print("|---|---|---:|---:|---:|---|---:|---:|---|")
    for name, p in inputs:
        whole = tmp / "whole.ply"
        _, s, rss = run(["-q", "--threads", args.threads, "press", str(p), "--no-flats", "-o", str(whole)])
        wv, wf = read_ply(whole)
        print(f"| {name} | whole, `--no-flats` | | {s:.1f} s | {rss:.0f} MB | {len(wf)} faces | | | |", flush=True)
        for c in chunks:
            for h in [0] + halos:  # 0: the exact mode (no --halo)
                out = tmp / "chunk.ply"
                halo = ["--halo", str(h)] if h else ["--no-flats"]
                # --check throws (non-zero exit, run() stops) unless every check passes.
                stats = tmp / "chunk.json"
                msg, s, rss = run(["--threads", args.threads, "press", str(p), "--chunk", str(c), *halo,
                                   "--check", "--stats-json", str(stats), "-o", str(out)], refusable=bool(h))
                if s is None:
                    print(f"| {name} | `--chunk {c} {' '.join(halo)}` | refused: {msg} | | | | | | |", flush=True)
                    continue
                rounds = json.loads(stats.read_text())["chunks"].get("rounds", 0) if h else ""
                cv, cf = read_ply(out)
                same = wf.shape == cf.shape and bool((wf == cf).all())
                d = np.linalg.norm(wv - cv, axis=1) if same else np.array([np.nan])
                print(f"| {name} | `--chunk {c} {' '.join(halo)}` | {rounds} | {s:.1f} s | {rss:.0f} MB | "
                      f"{'same' if same else 'DIFFERENT'} | {d.max():.2g} | {np.sqrt((d ** 2).mean()):.2g} | passes |",
                      flush=True)


if __name__ == "__main__":
    main()
