set terminal pngcairo size 1400,600 noenhanced
set output "sweep.png"
$fA0 << EOD
1.000000 0.219415 "sap-noray"
1.000000 1.321961 "dbvt"
1.000000 1.013447 "sap"
EOD
$fA1 << EOD
617.000000 0.136970 ""
618.000000 0.134535 ""
618.000000 0.132440 ""
618.000000 0.134995 ""
618.000000 0.131399 ""
622.000000 0.131919 ""
EOD
$fA2 << EOD
1.000000 0.288696 ""
1.000000 0.359280 ""
1.000000 0.548847 ""
2.000000 0.226519 ""
2.000000 0.232339 ""
5.000000 0.219806 ""
131.000000 0.316710 ""
EOD
$fA3 << EOD
1.000000 0.253850 ""
1.000000 0.309546 ""
1.000000 0.476502 ""
2.000000 0.227321 ""
2.000000 0.215898 "segment-trees:divisions=1000"
5.000000 0.205128 ""
131.000000 0.280761 ""
EOD
$fA4 << EOD
1.000000 0.449571 ""
3.000000 0.200680 "spatial-hash:factor=1"
8.000000 0.142580 "spatial-hash:factor=2"
8.000000 0.152618 ""
28.000000 0.133012 "spatial-hash:factor=4"
140.000000 0.128634 "spatial-hash:factor=8"
EOD
$frontA << EOD
1.000000 0.219415
2.000000 0.215898
3.000000 0.200680
8.000000 0.142580
28.000000 0.133012
140.000000 0.128634
EOD
$fB0 << EOD
32.000000 0.537838 "sap-noray"
32.000000 1.537589 "sap"
173.000000 2.685470 "dbvt"
EOD
$fB1 << EOD
510160.000000 5.054612 ""
510160.000000 4.962208 ""
510267.000000 5.002564 ""
527642.000000 5.061426 ""
530724.000000 5.160783 ""
532017.000000 5.145835 ""
EOD
$fB2 << EOD
698.000000 0.979874 ""
1496.000000 0.798641 ""
2029.000000 0.771981 ""
3342.000000 0.753555 ""
3342.000000 0.750711 ""
8619.000000 0.979202 ""
137719.000000 5.350923 ""
EOD
$fB3 << EOD
698.000000 0.704573 ""
1496.000000 0.659899 ""
2029.000000 0.703120 ""
3342.000000 0.714231 ""
3342.000000 0.713319 ""
8619.000000 0.999150 ""
137719.000000 4.910621 ""
EOD
$fB4 << EOD
2224.000000 0.877801 ""
5043.000000 0.522859 "spatial-hash:factor=1"
13966.000000 0.537847 ""
13966.000000 0.547186 ""
48282.000000 0.900183 ""
182209.000000 2.256359 ""
EOD
$frontB << EOD
32.000000 0.537838
5043.000000 0.522859
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
     $frontA using 1:2 with lines lw 2 title "Pareto front", 0.016832 with lines dt 2 lc black title "store-only"
set title "scene B (clustered)"
plot $fB0 using 1:2 with points pt 6 ps 1.3 lc 1 title "Bullet", $fB0 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB1 using 1:2 with points pt 8 ps 1.3 lc 2 title "grid", $fB1 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB2 using 1:2 with points pt 10 ps 1.3 lc 3 title "range-tree", $fB2 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB3 using 1:2 with points pt 12 ps 1.3 lc 4 title "segment-trees", $fB3 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB4 using 1:2 with points pt 14 ps 1.3 lc 5 title "spatial-hash", $fB4 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $frontB using 1:2 with lines lw 2 title "Pareto front", 0.016772 with lines dt 2 lc black title "store-only"
unset multiplot
