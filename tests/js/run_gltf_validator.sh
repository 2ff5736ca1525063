#!/usr/bin/env bash
# ctest wrapper: writes GLB and glTF files with the CLI (volumes and voxel
# art, with embedded textures; a label map's scene of organs) and validates them.
# Exit 77 (skipped) only when node or the validator package is unavailable.
set -euo pipefail
cli=$1; here=$(cd "$(dirname "$0")" && pwd)
if ! command -v node >/dev/null; then echo "SKIPPED: node is not installed"; exit 77; fi
if [ ! -d "$here/node_modules/gltf-validator" ]; then
  echo "SKIPPED: gltf-validator is not installed (scripts/setup.sh runs npm ci in tests/js)"; exit 77
fi
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$cli" -q generate cad-part --res 48 --rotate random:1 -o "$work/part.nrrd"
"$cli" -q extract "$work/part.nrrd" -o "$work/part.glb"
"$cli" -q extract "$work/part.nrrd" -o "$work/part.gltf"
node "$here/make_vox.mjs" "$work/ball.vox"
"$cli" -q voxart "$work/ball.vox" -o "$work/ball.glb"
"$cli" -q voxart "$work/ball.vox" -o "$work/ball_low.gltf" --faces 300 --fairing pressing
files=("$work/part.glb" "$work/part.gltf" "$work/ball.glb" "$work/ball_low.gltf")
# Voxel art from ../shared/data when present (skipped otherwise).
shared="$here/../../../shared/data"
if [ -d "$shared/vox" ]; then
  "$cli" -q voxart "$shared/vox/chr_knight.vox" -o "$work/knight.glb"
  "$cli" -q voxart "$shared/vxl/hmec.vxl" -o "$work/hmec.glb" --faces 4000
  files+=("$work/knight.glb" "$work/hmec.glb")
  # A label map's organs as one scene, a coloured node per label.
  "$cli" -q press "$shared/medical/totalseg_example_seg_fast_force_split.nii.gz" --labels 1,2,3,5 --format glb -o "$work/organs"
  files+=("$work/organs/all_labels.glb")
else
  echo "../shared/data is absent: shared voxel art not validated"
fi
node "$here/validate_gltf.mjs" "${files[@]}"
