set terminal pngcairo size 1200,500 noenhanced
set output "thesis-detection.png"
$sA0 << EOD
250 0.007311
1000 0.030295
3000 0.095612
EOD
$sA1 << EOD
250 0.009574
1000 0.039619
3000 0.124004
EOD
$sA2 << EOD
250 0.008302
1000 0.029774
3000 0.098166
EOD
$sA3 << EOD
250 0.008813
1000 0.034501
3000 0.116933
EOD
$sA4 << EOD
250 0.077896
1000 0.396189
3000 1.486920
EOD
$sA5 << EOD
250 0.060379
1000 0.290372
3000 1.109459
EOD
$sA6 << EOD
250 0.001793
1000 0.007120
3000 0.021452
EOD
$sB0 << EOD
250 0.025838
1000 0.579681
3000 4.480498
EOD
$sB1 << EOD
250 0.010606
1000 0.059718
3000 0.440594
EOD
$sB2 << EOD
250 0.007832
1000 0.043925
3000 0.232125
EOD
$sB3 << EOD
250 0.009755
1000 0.050535
3000 0.240127
EOD
$sB4 << EOD
250 0.123874
1000 0.674352
3000 2.824487
EOD
$sB5 << EOD
250 0.081131
1000 0.419713
3000 1.620529
EOD
$sB6 << EOD
250 0.001803
1000 0.007131
3000 0.021492
EOD
set multiplot layout 1,2 title "kolize-bench, thesis scenes, slow motion: detection time per frame"
set logscale xy
set grid
set key top left
set xlabel "N (objects)"
set ylabel "ms per frame (median)"
set title "scene A (uniform)"
plot $sA0 using 1:2 with linespoints title "grid", \
     $sA1 using 1:2 with linespoints title "spatial-tree", \
     $sA2 using 1:2 with linespoints title "segment-trees", \
     $sA3 using 1:2 with linespoints title "range-tree", \
     $sA4 using 1:2 with linespoints title "dbvt", \
     $sA5 using 1:2 with linespoints title "sap", \
     $sA6 using 1:2 with linespoints title "store-only"
set title "scene B (clustered)"
plot $sB0 using 1:2 with linespoints title "grid", \
     $sB1 using 1:2 with linespoints title "spatial-tree", \
     $sB2 using 1:2 with linespoints title "segment-trees", \
     $sB3 using 1:2 with linespoints title "range-tree", \
     $sB4 using 1:2 with linespoints title "dbvt", \
     $sB5 using 1:2 with linespoints title "sap", \
     $sB6 using 1:2 with linespoints title "store-only"
unset multiplot
