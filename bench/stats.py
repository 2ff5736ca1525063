#!/usr/bin/env python3
"""bench/stats.py [--passes] FILE.json... — the timings and counts of
`voxpress press|extract --stats-json FILE.json` as Markdown rows
(docs/BENCHMARKS.md): seconds per stage ("seconds"), the flats' own stages
(estimate, detect, junctions, creases), the simplification's seconds and
faces and the collapses inside one plane (with --faces), the stick count, labelled sharp edges and peak memory; with --passes, each feature pass's seconds and count too.
    python3 bench/stats.py --passes out/bench/sphere-2.json out/bench/cad-2.json
"""
import argparse
import json


def row(cells):
    return "| " + " | ".join(str(c) for c in cells) + " |"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="+")
    ap.add_argument("--passes", action="store_true", help="also every feature pass: seconds (count)")
    args = ap.parse_args()
    stats = [(f, flatten(json.load(open(f)))) for f in args.files]
    stages = sorted({k for _, s in stats for k in s.get("seconds", {})}, key=lambda k: (k != "total", k))
    flats = sorted({k for _, s in stats for k in s.get("flats", {}).get("seconds", {})})
    simp = any("simplify" in s for _, s in stats)
    head = ["file", *stages, *("flats: " + k for k in flats), *(["simplify", "faces", "in one plane"] if simp else []),
            "stick count", "sharp edges", "peak MB"]
    print(row(head))
    print(row(["---"] + ["---:"] * (len(head) - 1)))
    for f, s in stats:
        sec, fsec = s.get("seconds", {}), s.get("flats", {}).get("seconds", {})
        peak = s.get("peak_memory_bytes")
        print(row([f, *(f"{sec[k]:.2f}" if k in sec else "" for k in stages),
                   *(f"{fsec[k]:.2f}" if k in fsec else "" for k in flats),
                   *([f"{s['simplify']['seconds']:.2f}" if "simplify" in s else "",
                      s.get("simplify", {}).get("faces", ""), s.get("simplify", {}).get("in_plane", "")] if simp else []),
                   s.get("counts", {}).get("sticks", ""), s.get("sharpen", {}).get("sharp_edges", ""),
                   f"{peak / 2**20:.0f}" if peak else ""]))
    if args.passes:
        for f, s in stats:
            passes = ", ".join(f"{p['name']} {p['seconds']:.2f} s ({p['count']})" for p in s.get("passes", []))
            print(f"\n{f} passes: {passes}")


def flatten(s):
    """A label map's run (`press --labels`) keeps its stages under shared_surface: lifted to the top."""
    sh = s.get("shared_surface")
    if not sh:
        return s
    s = dict(s)
    s["seconds"] = {**s.get("seconds", {}), **sh.get("seconds", {})}
    for k in ("passes", "sharpen", "simplify"):
        if k in sh:
            s[k] = sh[k]
    return s


if __name__ == "__main__":
    main()
