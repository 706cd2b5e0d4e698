#!/usr/bin/env bash
# Continuous collision detection report: builds kolize-ccd-bench, runs it over the CCD
# data set with the tolerance sweep, and plots errors against run time.
#
#   scripts/ccd-report.sh [DATA_DIR] [OUT_DIR]
#
# DATA_DIR defaults to the bench's own default (../shared/ccd-data/Sample-Queries when
# present, else assets/ccd-data/Sample-Queries); OUT_DIR defaults to build/ccd-report.
# Writes OUT_DIR/table.txt (the printed table and sweep), table.csv (one row per method,
# data set and kind), sweep.csv and sweep.png. Needs cmake, a C++17 compiler and gnuplot
# (Debian: gnuplot-nox).
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KOLIZE_BUILD_DIR:-$repo/build}"
data="${1:-}"
out="${2:-$build/ccd-report}"
mkdir -p "$out"

if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKOLIZE_WITH_BOX2D=OFF
fi
# One job: the machines this runs on are shared.
nice -n 10 cmake --build "$build" -j1 --target kolize-ccd-bench

bench="$build/demos/ccd/kolize-ccd-bench"
# The bench resolves its default data folder relative to the working directory.
(cd "$repo" && "$bench" ${data:+"$data"} --csv "$out/table.csv" --sweep "$out/sweep.csv") \
    | tee "$out/table.txt"

# One data file per method: mean_us, false positives, false negatives, tolerance.
for method in cubic robust; do
    awk -F, -v m="$method" '$1 == m && $3 == "both" { print $7, $6, $5, $2 }' \
        "$out/sweep.csv" > "$out/sweep-$method.dat"
done

gnuplot <<GNUPLOT
set terminal pngcairo size 1200,500 noenhanced
set output "$out/sweep.png"
set multiplot layout 1,2 title "CCD tolerance sweep 1e-8 ... 1e-1 over all queries: error against run time (one point per tolerance; robust: larger tolerance = faster)"
set logscale xy
set grid
set key top left
set xlabel "mean time per query (us)"
set ylabel "false positives + 1"
set title "False positives"
plot "$out/sweep-cubic.dat" using 1:(\$2+1) with linespoints title "cubic (thesis)", \
     "$out/sweep-robust.dat" using 1:(\$2+1) with linespoints title "robust"
set ylabel "false negatives + 1"
set title "False negatives (robust: always 0)"
set yrange [0.8:*]
plot "$out/sweep-cubic.dat" using 1:(\$3+1) with linespoints title "cubic (thesis)", \
     "$out/sweep-robust.dat" using 1:(\$3+1) with linespoints title "robust"
unset multiplot
GNUPLOT
echo "wrote $out/table.txt $out/table.csv $out/sweep.csv $out/sweep.png"
