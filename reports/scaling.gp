set terminal pngcairo size 1200,500 noenhanced
set output "scaling.png"
$sA0 << EOD
1000 0.044925
3000 0.048689
10000 0.052141
30000 0.068611
100000 0.088194
EOD
$sA1 << EOD
1000 0.057018
3000 0.064706
10000 0.068985
30000 0.088374
100000 0.112079
EOD
$sA2 << EOD
1000 0.048843
3000 0.052459
10000 0.059945
30000 0.067714
100000 0.093832
EOD
$sA3 << EOD
1000 0.068930
3000 0.076388
10000 0.106616
30000 0.168698
100000 0.341516
EOD
$sA4 << EOD
1000 0.063100
3000 0.080178
10000 0.129551
30000 0.188633
100000 0.226020
EOD
$sA5 << EOD
1000 0.352687
3000 0.462568
10000 0.619822
30000 1.069114
100000 1.754912
EOD
$sA6 << EOD
1000 0.265903
3000 0.340474
10000 0.514133
30000 1.256986
EOD
$sA7 << EOD
1000 0.006101
3000 0.006065
10000 0.006115
30000 0.005796
100000 0.006646
EOD
$sB0 << EOD
1000 0.619201
3000 1.742600
10000 2.487609
30000 4.195276
100000 8.097722
EOD
$sB1 << EOD
1000 0.079470
3000 0.189685
10000 0.471519
30000 1.399682
100000 5.459407
EOD
$sB2 << EOD
1000 0.075313
3000 0.188033
10000 0.459498
30000 1.417113
100000 4.382587
EOD
$sB3 << EOD
1000 0.118404
3000 0.246600
10000 0.647288
30000 1.861990
100000 9.477844
EOD
$sB4 << EOD
1000 0.153591
3000 0.258983
10000 0.529587
30000 1.275521
100000 5.810446
EOD
$sB5 << EOD
1000 0.653606
3000 0.924790
10000 1.733317
30000 6.637572
100000 40.797490
EOD
$sB6 << EOD
1000 0.392483
3000 0.533393
10000 0.873478
30000 2.094122
EOD
$sB7 << EOD
1000 0.006012
3000 0.006045
10000 0.005758
30000 0.005943
100000 0.006560
EOD
set multiplot layout 1,2 title "kolize-bench, slow motion: time per object per frame against N"
set logscale xy
set grid
set key top left
set xlabel "N (objects)"
set ylabel "µs per object per frame"
set title "scene A (uniform)"
plot $sA0 using 1:2 with linespoints title "grid", \
     $sA1 using 1:2 with linespoints title "spatial-tree", \
     $sA2 using 1:2 with linespoints title "spatial-hash", \
     $sA3 using 1:2 with linespoints title "segment-trees", \
     $sA4 using 1:2 with linespoints title "range-tree", \
     $sA5 using 1:2 with linespoints title "dbvt", \
     $sA6 using 1:2 with linespoints title "sap", \
     $sA7 using 1:2 with linespoints title "store-only"
set title "scene B (clustered)"
plot $sB0 using 1:2 with linespoints title "grid", \
     $sB1 using 1:2 with linespoints title "spatial-tree", \
     $sB2 using 1:2 with linespoints title "spatial-hash", \
     $sB3 using 1:2 with linespoints title "segment-trees", \
     $sB4 using 1:2 with linespoints title "range-tree", \
     $sB5 using 1:2 with linespoints title "dbvt", \
     $sB6 using 1:2 with linespoints title "sap", \
     $sB7 using 1:2 with linespoints title "store-only"
unset multiplot
