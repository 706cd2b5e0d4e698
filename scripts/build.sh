#!/usr/bin/env bash
# Configures and builds kolize in BUILD_DIR (default build/) as Release with tests and demos.
# Extra arguments go to cmake's configure step, e.g. -DKOLIZE_DOUBLE_PRECISION=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
"scripts/deps.sh"
build_dir=${BUILD_DIR:-build}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} -DKOLIZE_BUILD_TESTS=ON "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
