set terminal pngcairo size 1400,600 noenhanced
set output "sweep.png"
$fA0 << EOD
1.000000 0.055493 "sap-noray"
1.000000 0.307668 "sap"
1.000000 0.426143 "dbvt"
EOD
$fA1 << EOD
140.000000 0.030175 ""
140.000000 0.030346 ""
148.000000 0.030014 ""
171.000000 0.030926 ""
171.000000 0.030345 ""
174.000000 0.030435 ""
EOD
$fA2 << EOD
1.000000 0.118016 ""
1.000000 0.057044 ""
1.000000 0.042663 ""
1.000000 0.034651 ""
1.000000 0.024206 ""
1.000000 0.034782 ""
10.000000 0.018537 ""
EOD
$fA3 << EOD
1.000000 0.022394 "segment-trees:divisions=500"
1.000000 0.130234 ""
1.000000 0.046249 ""
1.000000 0.036925 ""
1.000000 0.030886 ""
1.000000 0.031147 ""
10.000000 0.016985 "segment-trees:divisions=100"
EOD
$fA4 << EOD
1.000000 0.027290 ""
1.000000 0.030365 ""
1.000000 0.043515 ""
1.000000 0.093799 ""
1.000000 0.030816 ""
13.000000 0.025838 ""
EOD
$frontA << EOD
1.000000 0.022394
10.000000 0.016985
EOD
$fB0 << EOD
4.000000 0.099087 "sap-noray"
4.000000 0.418853 "sap"
20.000000 0.901630 "dbvt"
EOD
$fB1 << EOD
74628.000000 0.514014 ""
78632.000000 0.562997 ""
81854.000000 0.586852 ""
81854.000000 0.582235 ""
82647.000000 0.600943 ""
82948.000000 0.601514 ""
EOD
$fB2 << EOD
43.000000 0.213978 ""
119.000000 0.083644 ""
166.000000 0.066809 ""
271.000000 0.050505 ""
271.000000 0.052578 ""
758.000000 0.040720 ""
13684.000000 0.114530 ""
EOD
$fB3 << EOD
43.000000 0.163903 ""
119.000000 0.060801 "segment-trees:divisions=2000"
166.000000 0.055302 "segment-trees:divisions=1500"
271.000000 0.045107 ""
271.000000 0.044686 "segment-trees:divisions=1000"
758.000000 0.037927 "segment-trees:divisions=500"
13684.000000 0.164194 ""
EOD
$fB4 << EOD
195.000000 0.122963 ""
472.000000 0.062493 ""
1311.000000 0.050705 ""
1311.000000 0.054801 ""
4905.000000 0.077295 ""
18018.000000 0.167449 ""
EOD
$frontB << EOD
4.000000 0.099087
119.000000 0.060801
166.000000 0.055302
271.000000 0.044686
758.000000 0.037927
EOD
set multiplot layout 1,2 title "Error against run time, N = 1000 (x: rejected candidates for kolize, extra pairs for Bullet's)"
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
     $frontA using 1:2 with lines lw 2 title "Pareto front", 0.007140 with lines dt 2 lc black title "store-only"
set title "scene B (clustered)"
plot $fB0 using 1:2 with points pt 6 ps 1.3 lc 1 title "Bullet", $fB0 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB1 using 1:2 with points pt 8 ps 1.3 lc 2 title "grid", $fB1 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB2 using 1:2 with points pt 10 ps 1.3 lc 3 title "range-tree", $fB2 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB3 using 1:2 with points pt 12 ps 1.3 lc 4 title "segment-trees", $fB3 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $fB4 using 1:2 with points pt 14 ps 1.3 lc 5 title "spatial-hash", $fB4 using 1:2:3 with labels font ",8" offset char 0,0.9 notitle, \
     $frontB using 1:2 with lines lw 2 title "Pareto front", 0.007120 with lines dt 2 lc black title "store-only"
unset multiplot
