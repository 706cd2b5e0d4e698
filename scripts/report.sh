#!/usr/bin/env bash
# The whole measurement report: installs what is missing, builds the float build (build/)
# and a double-precision build with the demos (build-double/), then runs kolize-report,
# which writes reports/REPORT.md with its plots and CSV (reports/data/).
#
#   scripts/report.sh [--quick] [--out DIR]
#
# --quick: small N and few frames (minutes; what CI runs). Other arguments go to
# kolize-report (--help lists them). Builds use one job at low priority: the machines this
# runs on are shared, and the benchmarks time better on a quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
jobs=${JOBS:-1}
# Configure only a build folder that has none yet (CI's earlier steps configured both).
[ -f build/CMakeCache.txt ] ||
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DKOLIZE_BUILD_TESTS=ON >/dev/null
nice -n 10 cmake --build build -j"$jobs" --target kolize-report
[ -f build-double/CMakeCache.txt ] ||
    cmake -S . -B build-double -DCMAKE_BUILD_TYPE=Release -DKOLIZE_DOUBLE_PRECISION=ON \
        -DKOLIZE_BUILD_TESTS=OFF >/dev/null
nice -n 10 cmake --build build-double -j"$jobs" --target kolize-demo
build/demos/report/kolize-report --double-demo build-double/demos/kolize-demo "$@"
