#!/usr/bin/env bash
# Continuous collision detection report: builds kolize-ccd-bench, records the primitive
# queries of kolize's own mesh CCD runs (kolize-ccd-record, when assimp is built), runs the
# bench over the CCD data set and the recorded queries (colliding and non-colliding
# separately) with the tolerance sweep, and plots errors against run time; then runs the
# discrete-substeps-against-continuous tunneling demo and plots it too.
#
#   scripts/ccd-report.sh [DATA_DIR] [OUT_DIR]
#
# DATA_DIR defaults to the bench's own default (../shared/ccd-data/Sample-Queries when
# present, else assets/ccd-data/Sample-Queries); OUT_DIR defaults to build/ccd-report.
# Writes OUT_DIR/table.txt (the printed table and sweep), table.csv (one row per folder,
# method, data set and kind), sweep.csv and sweep.png; mesh-queries/ (the recorded queries);
# tunneling.txt, tunneling.csv and tunneling.png; mesh.txt (mesh-mesh CCD with and without
# culling, if assimp is built). Every build and run holds the shared CPU lock
# /tmp/kolize-cpu.lock. Needs cmake, a C++17 compiler and gnuplot (Debian: gnuplot-nox).
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KOLIZE_BUILD_DIR:-$repo/build}"
data="${1:-}"
out="${2:-$build/ccd-report}"
mkdir -p "$out"

lock=/tmp/kolize-cpu.lock
if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKOLIZE_WITH_BOX2D=OFF
fi
# One job: the machines this runs on are shared.
flock "$lock" nice -n 10 cmake --build "$build" -j1 --target kolize-ccd-bench \
    kolize-ccd-tunneling-demo

# Queries of kolize's own mesh CCD (Wuson against Wuson, the thin wall), if assimp is built.
recorded=()
if flock "$lock" nice -n 10 cmake --build "$build" -j1 --target kolize-ccd-record 2>/dev/null &&
    [ -f /usr/share/assimp/models/PLY/Wuson.ply ]; then
    flock "$lock" "$build/demos/ccd/kolize-ccd-record" --out "$out/mesh-queries" \
        | tee "$out/record.txt"
    recorded=("$out/mesh-queries")
fi

bench="$build/demos/ccd/kolize-ccd-bench"
# The bench resolves its default data folder relative to the working directory.
default_data="$(cd "$repo" && [ -d ../shared/ccd-data/Sample-Queries ] &&
    echo ../shared/ccd-data/Sample-Queries || echo assets/ccd-data/Sample-Queries)"
(cd "$repo" && flock "$lock" "$bench" "${data:-$default_data}" "${recorded[@]}" \
    --csv "$out/table.csv" --sweep "$out/sweep.csv") | tee "$out/table.txt"

# One data file per method: mean_us, false positives, false negatives, tolerance.
for method in cubic robust-search; do
    awk -F, -v m="$method" '$1 == m && $3 == "both" { print $7, $6, $5, $2 }' \
        "$out/sweep.csv" > "$out/sweep-$method.dat"
done

gnuplot <<GNUPLOT
set terminal pngcairo size 1200,500 noenhanced
set output "$out/sweep.png"
set multiplot layout 1,2 title "CCD tolerance sweep 1e-8 ... 1e-1, all queries, one point per tolerance: errors against run time (robust-search is exact at every tolerance)"
set logscale xy
set grid
set key top left
set xlabel "mean time per query (us)"
set ylabel "false positives + 1"
set title "False positives (robust: always 0)"
plot "$out/sweep-cubic.dat" using 1:(\$2+1) with linespoints title "cubic (thesis)", \
     "$out/sweep-robust-search.dat" using 1:(\$2+1) with linespoints title "robust-search"
set ylabel "false negatives + 1"
set title "False negatives (robust: always 0)"
set yrange [0.8:*]
plot "$out/sweep-cubic.dat" using 1:(\$3+1) with linespoints title "cubic (thesis)", \
     "$out/sweep-robust-search.dat" using 1:(\$3+1) with linespoints title "robust-search"
unset multiplot
GNUPLOT
flock "$lock" "$build/demos/ccd/kolize-ccd-tunneling-demo" --csv "$out/tunneling.csv" \
    | tee "$out/tunneling.txt"
# Per method: missed fraction over all speeds against mean time per step.
awk -F, 'NR > 1 { k = $1 == "continuous" ? "continuous" : "discrete-" $2; n[k] += $4;
                   miss[k] += $5; us[k] += $6; c[k]++ }
         END { for (k in n) print us[k] / c[k], miss[k] / n[k], k }' \
    "$out/tunneling.csv" | sort -n > "$out/tunneling-summary.dat"
for m in 1 2 4 8 16; do
    awk -F, -v m="$m" '$1 == "discrete" && $2 == m { print $3, $5 / $4 }' \
        "$out/tunneling.csv" > "$out/tunneling-discrete-$m.dat"
done
awk -F, '$1 == "continuous" { print $3, $5 / $4 }' "$out/tunneling.csv" \
    > "$out/tunneling-continuous.dat"

gnuplot <<GNUPLOT
set terminal pngcairo size 1200,500 noenhanced
set output "$out/tunneling.png"
set multiplot layout 1,2 title "Cube fired at a thin plate: discrete substeps against continuous collision detection"
set grid
set key top left
set logscale x
set xlabel "speed (distance per step; cube edge 0.2, plate 0.01)"
set ylabel "missed fraction"
set yrange [-0.02:1.02]
set title "Missed collisions by speed"
plot for [m in "1 2 4 8 16"] "$out/tunneling-discrete-".m.".dat" using 1:2 with linespoints title "discrete, ".m." substeps", \
     "$out/tunneling-continuous.dat" using 1:2 with linespoints lw 2 title "continuous (meshCcd)"
set xlabel "mean time per step (us)"
set title "Error against run time (all speeds)"
plot "$out/tunneling-summary.dat" using 1:2 with points pt 7 notitle, \
     "$out/tunneling-summary.dat" using 1:2:3 with labels offset char 0,1 notitle
unset multiplot
GNUPLOT
# Mesh against mesh, with and without the thesis's culling (needs assimp and its models).
if [ -x "$build/demos/ccd/kolize-ccd-mesh-demo" ] ||
    flock "$lock" nice -n 10 cmake --build "$build" -j1 --target kolize-ccd-mesh-demo 2>/dev/null; then
    for model in /usr/share/assimp/models/PLY/cube.ply \
        /usr/share/assimp/models/STL/sphereWithHole.stl \
        /usr/share/assimp/models/PLY/Wuson.ply; do
        [ -f "$model" ] && flock "$lock" "$build/demos/ccd/kolize-ccd-mesh-demo" "$model"
    done | tee "$out/mesh.txt"
fi
echo "wrote $out/{table.txt,table.csv,sweep.csv,sweep.png,mesh-queries/,tunneling.txt,tunneling.csv,tunneling.png,mesh.txt}"
