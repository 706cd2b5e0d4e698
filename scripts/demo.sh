#!/usr/bin/env bash
# The README's demo command: installs what is missing, builds, runs the headless comparison
# of every broadphase on the falling-boxes world. Arguments go to kolize-demo (see --help).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build} scripts/build.sh
"${BUILD_DIR:-build}/demos/kolize-demo" "$@"
