#!/usr/bin/env bash
# scripts/pictures.sh — regenerates the README's pictures (docs/images/*.png)
# with voxpress's own commands. The CAD part is built in; the medical and
# voxel-art pictures need ../shared/data (skipped with a message without it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" >&2
vp="$root/build/bin/voxpress"
img="$root/docs/images"
shared="$root/../shared/data"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$img"

# A rotated CAD-like part at 128^3: midpoint surface vs Pressing (flats coloured, sharp edges drawn).
"$vp" -q generate cad-part --res 128 --rotate random:7 -o "$work/part.nrrd"
"$vp" -q extract "$work/part.nrrd" -o "$work/part-midpoint.ply"
"$vp" -q press "$work/part.nrrd" -o "$work/part-pressed.ply"
"$vp" render "$work/part-midpoint.ply" "$work/part-pressed.ply" --color regions --size 480x400 -o "$img/cad-part.png"

# A plate 3 cells thick (examples/plate.obj at 64^3): one crease along the middle of its rim without
# the thin walls (--disable-pass walls) vs the rim's own plane and both of its edges.
"$vp" -q voxelize "$root/examples/plate.obj" --res 64 --rotate random:3 -o "$work/plate.nrrd"
"$vp" -q press "$work/plate.nrrd" -o "$work/plate-no-walls.ply" --disable-pass walls
"$vp" -q press "$work/plate.nrrd" -o "$work/plate-walls.ply"
"$vp" render "$work/plate-no-walls.ply" "$work/plate-walls.ply" --color regions --size 480x400 -o "$img/thin-plate.png"

# The same part at 256^3, pressed (432 k triangles) and simplified to 2 % of them (--faces 8644),
# triangle edges drawn: the flats become a few large triangles, every sample still on its side.
"$vp" -q generate cad-part --res 256 --rotate random:7 -o "$work/part256.nrrd"
"$vp" -q press "$work/part256.nrrd" -o "$work/part256.ply"
"$vp" -q press "$work/part256.nrrd" -o "$work/part256-2pc.ply" --faces 8644
"$vp" render "$work/part256.ply" "$work/part256-2pc.ply" --color regions --wireframe --size 480x400 -o "$img/simplified.png"

if [ -d "$shared/medical" ]; then
  # A CT segmentation (TotalSegmentator's aorta, 1.5 mm): input voxels vs Pressing.
  "$vp" render "$shared/medical/totalseg_aorta.nii.gz" "$shared/medical/totalseg_aorta.nii.gz" \
    --method voxels,pressing --view y --size 360x460 -o "$img/aorta.png"
  # TotalSegmentator's 61-label map (3 mm), seen from behind: the shared midpoint surface vs the
  # pressed one (press --labels), every face coloured by the label it bounds.
  "$vp" -q extract "$shared/medical/totalseg_example_seg_fast_force_split.nii.gz" --labels -o "$work/labels-midpoint.ply"
  "$vp" -q press "$shared/medical/totalseg_example_seg_fast_force_split.nii.gz" --labels all -o "$work/organs"
  "$vp" render "$work/labels-midpoint.ply" "$work/organs/interfaces.ply" --color regions --view y --size 420x520 \
    -o "$img/label-map.png"
  # MagicaVoxel's chr_knight: the voxels vs the faired, textured mesh (voxpress voxart).
  "$vp" render "$shared/vox/chr_knight.vox" "$shared/vox/chr_knight.vox" --method voxels,lanczos \
    --size 400x440 -o "$img/voxel-art.png"
else
  echo "pictures: ../shared/data is absent; the medical and voxel-art pictures were not regenerated" >&2
fi
