#!/usr/bin/env python3
"""Out-of-core `press --chunk` (issue 56): a 1024^3 mask (the CAD part,
rotated) as a raw NRRD, meshed block by block from disk (exact, and with
blocks pressed apart) against the in-memory whole-volume run (default
options) and the chunked run of the same samples gzip-compressed (read
whole). Prints a markdown table: wall time,
peak RSS of the process, triangles, max / RMS vertex difference to the
whole run.

    VOXPRESS_CLI=build/bin/voxpress PYTHONPATH=build/python \
        python3 bench/chunk_out_of_core.py [--res 1024] [--chunk 256] [--threads 2]

Needs ~1 GB of disk per copy of the volume (in a temporary folder) and, for
the in-memory run, several GB of RAM.
"""
import argparse
import filecmp
import os
import pathlib
import shutil
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from chunk_seams import read_ply, run  # noqa: E402


def write_raw_nrrd(path, data, lattice):
    """The volume as a raw (uncompressed) NRRD with its geometry."""
    d = np.asarray(lattice.direction) * np.asarray(lattice.spacing)[None, :]
    dirs = " ".join("(" + ",".join(repr(float(x)) for x in d[:, a]) + ")" for a in range(3))
    o = ",".join(repr(float(x)) for x in lattice.origin)
    with open(path, "wb") as f:
        f.write(f"NRRD0004\ntype: uint8\ndimension: 3\nspace dimension: 3\n"
                f"sizes: {data.shape[0]} {data.shape[1]} {data.shape[2]}\nspace directions: {dirs}\n"
                f"space origin: ({o})\nencoding: raw\n\n".encode())
        # read_volume's array is [i, j, k] over x-fastest bytes: its transpose is C-contiguous.
        f.write(np.ascontiguousarray(data.astype(np.uint8, copy=False).T).tobytes())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=int, default=1024)
    ap.add_argument("--chunk", type=int, default=256)
    ap.add_argument("--threads", default="2")
    ap.add_argument("--skip-whole", action="store_true", help="no in-memory run (too little RAM)")
    args = ap.parse_args()
    import voxpress

    tmp = pathlib.Path(tempfile.mkdtemp(prefix="voxpress_ooc_"))
    try:
        gz, raw, h5 = tmp / "part.nrrd", tmp / "part_raw.nrrd", tmp / "part.h5"
        for path in (gz, h5):
            _, s, _ = run(["-q", "generate", "cad-part", "--res", str(args.res), "--rotate", "random:1", "-o", str(path)])
            print(f"generated {path.name} ({args.res}^3, {path.stat().st_size >> 20} MB) in {s:.0f} s", file=sys.stderr)
        data, lattice = voxpress.read_volume(str(gz))
        write_raw_nrrd(raw, data, lattice)
        shape = data.shape
        del data
        rows = []
        c = str(args.chunk)
        runs = [("`--chunk " + c + "`, raw NRRD streamed", raw, ["--chunk", c]),
                ("`--chunk " + c + "`, HDF5 (64^3 chunks, gzip) streamed", h5, ["--chunk", c]),
                ("`--chunk " + c + "`, gzip NRRD read whole", gz, ["--chunk", c])]
        if not args.skip_whole:
            runs.insert(0, ("whole volume in memory", raw, []))
        ref = None
        for name, path, extra in runs:
            out = tmp / "out.ply"
            _, s, rss = run(["-q", "--threads", args.threads, "press", str(path), *extra, "-o", str(out)])
            v, f = read_ply(out)
            if ref is None:
                ref = (v, f)
                shutil.copy(out, tmp / "ref.ply")
                diff = "", ""
            elif filecmp.cmp(out, tmp / "ref.ply", shallow=False):
                diff = "0 (same bytes)", "0"
            elif ref[1].shape == f.shape and (ref[1] == f).all():
                d = np.linalg.norm(ref[0] - v, axis=1)
                diff = f"{d.max():.2g}", f"{np.sqrt((d ** 2).mean()):.2g}"
            else:
                diff = "different topology", ""
            rows.append(f"| {name} | {s:.1f} s | {rss / 1024:.2f} GiB | {len(f)} | {diff[0]} | {diff[1]} |")
            print(rows[-1], file=sys.stderr, flush=True)
        print(f"CAD part {shape[0]}x{shape[1]}x{shape[2]} (rotated random:1), {args.threads} threads:\n")
        print("| run | time | peak RSS | triangles | max diff | RMS diff |")
        print("|---|---:|---:|---:|---:|---:|")
        print("\n".join(rows))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
