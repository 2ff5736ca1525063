#!/usr/bin/env bash
# scripts/test.sh — sets everything up (apt packages, Node test tools),
# builds in Release and runs the whole test suite. CI runs exactly this.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" --tests
cd "$root/build"
ctest --output-on-failure -j "$(nproc)"
