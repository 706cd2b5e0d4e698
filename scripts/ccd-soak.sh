#!/usr/bin/env bash
# Differential soak of the robust CCD method against the exact reference (GMP rationals):
# QUERIES seeded degenerate queries (default 1 000 000) from tests/ccd/ccd_families.h, each
# checked in every arithmetic mode (hit must agree, toi <= t* <= toi + toi_tolerance
# exactly), then every query of the shipped data set (and of DATA_DIR, e.g. one written by
# kolize-ccd-record) against the reference and its labels.
#
#   scripts/ccd-soak.sh [QUERIES] [SEED] [DATA_DIR]
#
# SEED defaults to the current time (printed, so a run can be repeated). Runs in chunks of
# 100 000 queries, each under the shared CPU lock (/tmp/kolize-cpu.lock, or KOLIZE_CPU_LOCK), so other jobs can
# interleave. Prints every disagreement with its seed and query index (rerun one with
# `kolize-ccd-soak --seed S --first I --queries 1`), writes the chunks' tables to
# $KOLIZE_BUILD_DIR/ccd-soak/ (default build/ccd-soak/) and exits 1 if anything disagreed.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KOLIZE_BUILD_DIR:-$repo/build}"
queries="${1:-1000000}"
seed="${2:-$(date +%s)}"
data="${3:-}"
lock="${KOLIZE_CPU_LOCK:-/tmp/kolize-cpu.lock}"  # shared CPU lock; another path runs beside it
chunk=100000
out="$build/ccd-soak"
mkdir -p "$out"

if [ ! -f "$build/CMakeCache.txt" ]; then
    flock "$lock" cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKOLIZE_BUILD_TESTS=ON
fi
flock "$lock" cmake --build "$build" -j2 --target kolize-ccd-soak
# A copy: rebuilding the tree during a long soak must not change the program under test.
soak="$out/kolize-ccd-soak.$$"
cp "$build/tests/ccd/kolize-ccd-soak" "$soak"
trap 'rm -f "$soak"' EXIT

echo "ccd soak: $queries queries, seed $seed"
start=$(date +%s)
failed=0
for ((first = 0; first < queries; first += chunk)); do
    n=$((queries - first < chunk ? queries - first : chunk))
    log="$out/seed-$seed-from-$first.txt"
    if ! flock "$lock" "$soak" --seed "$seed" --first "$first" --queries "$n" > "$log"; then
        failed=1
    fi
    grep '^DISAGREEMENT\|^  query\|^  shrunk' "$log" || true
    tail -n 1 "$log"
done
for dir in "$repo/assets/ccd-data/Sample-Queries" ${data:+"$data"}; do
    log="$out/data-$(basename "$dir").txt"
    if ! flock "$lock" "$soak" --data "$dir" > "$log"; then
        failed=1
    fi
    grep '^DISAGREEMENT\|^LABEL' "$log" || true
    tail -n 1 "$log"
done
echo
echo "ccd soak: $queries queries, seed $seed, $(($(date +%s) - start)) s:" \
    "$([ "$failed" = 0 ] && echo "no disagreement" || echo "DISAGREEMENTS (see above)")"
exit "$failed"
