#!/usr/bin/env bash
# The sweep core of two commits on the same recorded pair streams (core work only: update,
# maintain, drainChanges), alternating, median of R rounds:
#   scripts/sweep-ab.sh REV_A REV_B [ROUNDS] STREAM...
# Record a stream with: build/demos/kolize-demo --scene S --broadphase sweep --frames 300
#   --record FILE. Needs the float build (scripts/build.sh) for the stream reader.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 3 ]; then
    echo "usage: scripts/sweep-ab.sh REV_A REV_B [ROUNDS] STREAM..." >&2
    exit 2
fi
a=$1
b=$2
shift 2
rounds=9
if [[ $1 =~ ^[0-9]+$ ]]; then
    rounds=$1
    shift
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
header=broadphase/include/kolize/broadphase/sweep_and_prune.h
axis=broadphase/include/kolize/broadphase/sweep_axis.h  # from ad648a5 on: the axis passes
rename() {  # distinct names for the two versions in one program
    sed -e "s/SweepAndPrune/Sweep$1/g; s/sweep_detail/sweep_detail_$1/g; s/SweepSettings/SweepSettings$1/g" \
        -e "s|kolize/broadphase/sweep_axis.h|sweep_axis_$1.h|"
}
for side in A B; do
    rev=$a
    [ "$side" = B ] && rev=$b
    git show "$rev:$header" | rename "$side" > "$work/$side.h"
    if git cat-file -e "$rev:$axis" 2> /dev/null; then
        git show "$rev:$axis" | rename "$side" > "$work/sweep_axis_$side.h"
    fi
done
build=${BUILD_DIR:-build}
g++ -O2 -std=c++17 -DNDEBUG -I"$work" -Ibroadphase/include -Iengine/include -I/usr/include/bullet \
    scripts/sweep-ab/sweep_ab.cpp -o "$work/sweep_ab" "$build/engine/libkolize_engine.a" \
    "$build/broadphase/libkolize_broadphase.a" -lBulletDynamics -lBulletCollision -lLinearMath
echo "A = $a, B = $b, $rounds rounds"
"$work/sweep_ab" "$rounds" "$@"
