#!/usr/bin/env bash
# ctest wrapper: writes GLB and glTF files with the CLI and validates them.
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
node "$here/validate_gltf.mjs" "$work/part.glb" "$work/part.gltf"
