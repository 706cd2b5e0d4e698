#!/usr/bin/env bash
# Soak run of the differential fuzzer (tests/fuzz): every kolize broadphase, at least
# 1 000 000 operations each (OPERATIONS, default 1000000), in both filter modes, each run in
# its own process so that a crash is counted, not fatal. Prints a table (operations,
# searches, queries, mismatches, crashes) and the seed and shrunk program of any failure.
#   scripts/soak.sh                 # uses build/ (scripts/test.sh builds it)
#   BUILD_DIR=build-sanitize scripts/soak.sh   # the ASan + UBSan build
set -uo pipefail
cd "$(dirname "$0")/.."
build="${BUILD_DIR:-build}"
fuzz="$build/tests/kolize-fuzz"
operations="${OPERATIONS:-1000000}"
seed="${SEED:-1}"
if [ ! -x "$fuzz" ]; then
    echo "soak: $fuzz is missing; build first (scripts/test.sh, or BUILD_DIR=... scripts/test.sh)" >&2
    exit 2
fi
names="grid spatial-tree spatial-hash segment-trees range-tree sweep auto brute-force"
echo "| broadphase | filters | operations | searches | queries | mismatches | crashes |"
echo "|---|---|--:|--:|--:|--:|--:|"
status=0
for name in $names; do
    for mode in when-added every-frame; do
        flag=""
        [ "$mode" = every-frame ] && flag="--every-frame"
        out="$(mktemp)"
        "$fuzz" --broadphase "$name" --operations "$operations" --seed "$seed" $flag >"$out" 2>&1
        code=$?
        line="$(head -n 1 "$out")"
        ops="$(echo "$line" | awk '{print $3}')"
        searches="$(echo "$line" | awk '{print $5}')"
        queries="$(echo "$line" | awk '{print $7}')"
        mismatches="$(echo "$line" | awk '{print $9}')"
        crashes=0
        if [ "$code" -gt 1 ]; then
            crashes=1
            status=1
        elif [ "$code" -eq 1 ]; then
            status=1
        fi
        echo "| $name | $mode | ${ops:-?} | ${searches:-?} | ${queries:-?} | ${mismatches:-?} | $crashes |"
        if [ "$code" -ne 0 ]; then
            sed 's/^/    /' "$out" >&2
        fi
        rm -f "$out"
    done
done
exit $status
