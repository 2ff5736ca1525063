#!/usr/bin/env bash
# scripts/demo.sh — sets everything up and runs the main job on a built-in
# example: a randomly rotated CAD-like part, sampled exactly at 128^3, turned
# into its midpoint (stick) surface and its Pressing surface (flats found by
# plane voting and frozen on their planes; also without flats), checked and
# evaluated against the exact part; a binary image's contours pressed in 2D.
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
"$vp" extract "$out/part.nrrd" -o "$out/part-midpoint.ply"
"$vp" press "$out/part.nrrd" -o "$out/part-pressed.ply" --color-regions --stats-json "$out/press.json"
"$vp" -q press "$out/part.nrrd" -o "$out/part-noflats.ply" --no-flats
"$vp" -q press "$out/part.nrrd" -o "$out/part-pressed.glb"
"$vp" check "$out/part-pressed.ply" --volume "$out/part.nrrd"
echo "== distance to the exact part: midpoint surface, Pressing without flats, Pressing"
"$vp" eval "$out/part-midpoint.ply" --volume "$out/part.nrrd" --samples 100000 --json "$out/eval-midpoint.json"
"$vp" eval "$out/part-noflats.ply" --volume "$out/part.nrrd" --samples 100000 --json "$out/eval-noflats.json"
"$vp" eval "$out/part-pressed.ply" --volume "$out/part.nrrd" --samples 100000 --json "$out/eval-pressed.json"
echo "== without the volume: the midpoint STL smoothed inside Bade's diamonds, then checked against the volume"
"$vp" -q extract "$out/part.nrrd" -o "$out/part-midpoint.stl"
"$vp" smooth-mesh "$out/part-midpoint.stl" -o "$out/part-diamond.ply" --constraint diamond
"$vp" check "$out/part-diamond.ply" --volume "$out/part.nrrd"
echo "== pictures: a PNG drawn without a GPU, and the interactive report (open it in a browser)"
"$vp" render "$out/part-midpoint.ply" "$out/part-pressed.ply" --color regions --size 480x400 -o "$out/part.png"
"$vp" report "$out/part.nrrd" -o "$out/report.html" --methods midpoint,pressing,cesn --stats-json "$out/report.json"
echo "== 2D: the contours of a small binary image, pressed"
"$vp" press2d "$root/examples/shapes.pbm" -o "$out/shapes.svg" --midpoint
echo "== wrote $out/: part.nrrd, part-midpoint.ply, part-noflats.ply, part-pressed.ply/.glb (vertex colours = flats), part-diamond.ply, part.png, report.html, press.json, report.json, eval-*.json, shapes.svg"
