#!/usr/bin/env bash
# scripts/setup.sh [--tests] — installs what voxpress needs on Debian 12 (only
# the packages that are missing) and builds it in Release under build/
# (library, CLI, benchmarks, tests and the Python module in build/python;
# with --tests, everything but the benchmarks).
# The report viewer's packages (three.js, meshoptimizer, esbuild) come from
# npm (web/package-lock.json); --tests also installs the Node packages and
# the Chromium the test suite uses.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
with_tests=0
[ "${1:-}" = "--tests" ] && with_tests=1

packages=(build-essential cmake ninja-build pkg-config
          libeigen3-dev libtbb-dev zlib1g-dev libtiff-dev libpng-dev libnifti2-dev
          libhdf5-dev libpugixml-dev libtinygltf-dev libtinyobjloader-dev libcli11-dev nlohmann-json3-dev
          libgtest-dev libgmock-dev libbenchmark-dev libmeshoptimizer-dev nodejs
          python3-dev pybind11-dev python3-numpy)
[ $with_tests = 1 ] && packages+=(python3-pytest python3-nibabel python3-dask python3-distributed python3-zarr chromium
                                  clang libclang-rt-14-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm ships inside nodesource's nodejs; Debian's nodejs needs the npm package.
if ! command -v npm >/dev/null 2>&1; then missing+=(npm); fi
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "setup: installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

if [ ! -f "$root/web/node_modules/.package-lock.json" ] ||
   [ "$root/web/package-lock.json" -nt "$root/web/node_modules/.package-lock.json" ]; then
  (cd "$root/web" && npm ci --no-audit --no-fund --loglevel=error >&2)
fi
if [ $with_tests = 1 ]; then
  (cd "$root/tests/js" && npm ci --no-audit --no-fund --loglevel=error >&2) ||
    echo "setup: npm ci failed; the glTF validator and browser tests will be skipped" >&2
fi

# The test command skips the benchmark programs (no test uses them; CI time).
bench=ON; [ $with_tests = 1 ] && bench=OFF
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVOXPRESS_BUILD_BENCH=$bench \
  ${VOXPRESS_CMAKE_ARGS:-} >/dev/null
cmake --build "$root/build" -j "$(nproc)" >&2
