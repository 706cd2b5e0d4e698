set terminal pngcairo size 1200,500 noenhanced
set output "scaling.png"
$sA0 << EOD
1000 0.030396
3000 0.031427
10000 0.034199
EOD
$sA1 << EOD
1000 0.041081
3000 0.042413
10000 0.049975
EOD
$sA2 << EOD
1000 0.031086
3000 0.031163
10000 0.034960
EOD
$sA3 << EOD
1000 0.032138
3000 0.033640
10000 0.041127
EOD
$sA4 << EOD
1000 0.034471
3000 0.037733
10000 0.046244
EOD
$sA5 << EOD
1000 0.427435
3000 0.514849
10000 0.671176
EOD
$sA6 << EOD
1000 0.307096
3000 0.387613
10000 0.522509
EOD
$sA7 << EOD
1000 0.007161
3000 0.007164
10000 0.007120
EOD
$sB0 << EOD
1000 0.588725
3000 1.479335
10000 2.907584
EOD
$sB1 << EOD
1000 0.068943
3000 0.163800
10000 0.429229
EOD
$sB2 << EOD
1000 0.055252
3000 0.150467
10000 0.425731
EOD
$sB3 << EOD
1000 0.047991
3000 0.080643
10000 0.243723
EOD
$sB4 << EOD
1000 0.052348
3000 0.081761
10000 0.217262
EOD
$sB5 << EOD
1000 0.929001
3000 1.229654
10000 2.610546
EOD
$sB6 << EOD
1000 0.417981
3000 1.907304
10000 0.965988
EOD
$sB7 << EOD
1000 0.007141
3000 0.007855
10000 0.007150
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
