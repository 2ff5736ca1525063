#!/usr/bin/env bash
# A plain CMake configure works without Node.js (issue: it used to stop with
# a fatal error): the CLI is then built with a `report` that says it has no
# viewer. Configures a scratch build with node pointed at nothing; does not build it.
set -euo pipefail
src=$1 scratch=$2
rm -rf "$scratch"
cmake -S "$src" -B "$scratch" -DVOXPRESS_NODE=/nonexistent/node -DVOXPRESS_BUILD_TESTS=OFF \
  -DVOXPRESS_BUILD_BENCH=OFF -DVOXPRESS_PYTHON=OFF > "$scratch.log" 2>&1 || { cat "$scratch.log"; exit 1; }
grep -q "its viewer" "$scratch.log"
grep -q "kReportScript = nullptr" "$scratch/apps/voxpress/report_assets.cpp"
rm -rf "$scratch" "$scratch.log"
echo "configured without Node.js; report built without its viewer"
