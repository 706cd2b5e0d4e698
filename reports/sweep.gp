set terminal pngcairo size 1400,600 noenhanced
set output "sweep.png"
$fA0 << EOD
1.000000 0.201760 "sap-noray"
1.000000 1.350958 "dbvt"
1.000000 1.007818 "sap"
EOD
$fA1 << EOD
617.000000 0.154870 ""
618.000000 0.155571 ""
618.000000 0.116453 ""
618.000000 0.117946 ""
618.000000 0.166617 ""
622.000000 0.114360 ""
EOD
$fA2 << EOD
1.000000 0.185917 ""
1.000000 0.230853 ""
1.000000 0.510849 ""
2.000000 0.152337 ""
2.000000 0.154870 ""
5.000000 0.121040 ""
131.000000 0.096083 ""
EOD
$fA3 << EOD
1.000000 0.156893 "segment-trees:divisions=1500"
1.000000 0.180799 ""
1.000000 0.364342 ""
2.000000 0.130364 "segment-trees"
2.000000 0.133008 ""
5.000000 0.107610 "segment-trees:divisions=500"
131.000000 0.091796 "segment-trees:divisions=100"
EOD
$fA4 << EOD
1.000000 0.347907 ""
3.000000 0.170774 ""
8.000000 0.121571 ""
8.000000 0.125246 ""
28.000000 0.113349 ""
140.000000 0.112367 ""
EOD
$frontA << EOD
1.000000 0.156893
2.000000 0.130364
5.000000 0.107610
131.000000 0.091796
EOD
$fB0 << EOD
32.000000 0.476999 "sap-noray"
32.000000 1.575581 "sap"
173.000000 2.701905 "dbvt"
EOD
$fB1 << EOD
510160.000000 4.584614 ""
510160.000000 5.690166 ""
510267.000000 4.793434 ""
527642.000000 5.125978 ""
530724.000000 4.754596 ""
532017.000000 5.053580 ""
EOD
$fB2 << EOD
698.000000 0.939876 ""
1496.000000 0.408277 ""
2029.000000 0.343731 ""
3342.000000 0.297843 ""
3342.000000 0.301818 ""
8619.000000 0.315509 ""
137719.000000 1.308214 ""
EOD
$fB3 << EOD
698.000000 0.753589 ""
1496.000000 0.370090 "segment-trees:divisions=2000"
2029.000000 0.322058 "segment-trees:divisions=1500"
3342.000000 0.305023 ""
3342.000000 0.295670 "segment-trees:divisions=1000"
8619.000000 0.300056 ""
137719.000000 1.338108 ""
EOD
$fB4 << EOD
2224.000000 0.839137 ""
5043.000000 0.514935 ""
13966.000000 0.510439 ""
13966.000000 0.499553 ""
48282.000000 0.875471 ""
182209.000000 2.097998 ""
EOD
$frontB << EOD
32.000000 0.476999
1496.000000 0.370090
2029.000000 0.322058
3342.000000 0.295670
EOD
set multiplot layout 1,2 title "Error against run time, N = 3000 (x: rejected candidates for kolize, extra pairs for Bullet's)"
set logscale xy
set grid
set key top right
set xlabel "rejected or extra pairs + 1 (last frame)"
set ylabel "ms per frame"
set title "scene A (uniform)"
plot $fA0 using 1:2 with points pt 6 ps 1.3 lc 1 title "Bullet", $fA0 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fA1 using 1:2 with points pt 8 ps 1.3 lc 2 title "grid", $fA1 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fA2 using 1:2 with points pt 10 ps 1.3 lc 3 title "range-tree", $fA2 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fA3 using 1:2 with points pt 12 ps 1.3 lc 4 title "segment-trees", $fA3 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fA4 using 1:2 with points pt 14 ps 1.3 lc 5 title "spatial-hash", $fA4 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $frontA using 1:2 with lines lw 2 title "Pareto front", 0.021442 with lines dt 2 lc black title "store-only"
set title "scene B (clustered)"
plot $fB0 using 1:2 with points pt 6 ps 1.3 lc 1 title "Bullet", $fB0 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB1 using 1:2 with points pt 8 ps 1.3 lc 2 title "grid", $fB1 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB2 using 1:2 with points pt 10 ps 1.3 lc 3 title "range-tree", $fB2 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB3 using 1:2 with points pt 12 ps 1.3 lc 4 title "segment-trees", $fB3 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB4 using 1:2 with points pt 14 ps 1.3 lc 5 title "spatial-hash", $fB4 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $frontB using 1:2 with lines lw 2 title "Pareto front", 0.021422 with lines dt 2 lc black title "store-only"
unset multiplot
