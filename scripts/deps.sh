#!/usr/bin/env bash
# Installs the Debian packages kolize needs, only those missing. Needs root (or sudo).
set -euo pipefail
packages=(cmake g++ make pkg-config libbullet-dev libeigen3-dev libassimp-dev assimp-testmodels
          libbox2d-dev libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox libgmp-dev
          libfcl-dev)  # FCL: only the narrowphase benchmark compares against it
missing=()
for package in "${packages[@]}"; do
    dpkg -s "$package" >/dev/null 2>&1 || missing+=("$package")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "kolize: installing ${missing[*]}" >&2
    run=()
    [ "$(id -u)" -eq 0 ] || run=(sudo)
    "${run[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${run[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
