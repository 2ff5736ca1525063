#!/usr/bin/env bash
# scripts/demo.sh — sets everything up and runs the main job on a built-in
# example: a randomly rotated CAD-like part, sampled exactly at 128^3, turned
# into its midpoint (stick) surface, checked, and written as PLY and GLB.
# Outputs go to out/demo/. No download, no ../shared.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
vp="$root/build/bin/voxpress"
out="$root/out/demo"
mkdir -p "$out"
echo "== voxpress demo: a rotated CAD-like part at 128^3"
"$vp" generate cad-part --res 128 --rotate random:7 -o "$out/part.nrrd"
"$vp" info "$out/part.nrrd"
"$vp" extract "$out/part.nrrd" -o "$out/part-midpoint.ply" --stats-json "$out/extract.json"
"$vp" -q extract "$out/part.nrrd" -o "$out/part-midpoint.glb"
"$vp" check "$out/part-midpoint.ply" --volume "$out/part.nrrd"
echo "== wrote $out/part.nrrd, part-midpoint.ply, part-midpoint.glb and extract.json"
