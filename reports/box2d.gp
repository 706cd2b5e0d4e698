set terminal pngcairo size 1200,500 noenhanced
set output "box2d.png"
$sA0 << EOD
1000 0.125229
3000 0.125629
10000 0.145736
EOD
$sA1 << EOD
1000 0.146802
3000 0.146217
10000 0.170437
EOD
$sA2 << EOD
1000 0.108524
3000 0.113260
10000 0.136646
EOD
$sA3 << EOD
1000 0.142285
3000 0.140876
10000 0.152810
EOD
$sA4 << EOD
1000 0.175785
3000 0.180264
10000 0.175625
EOD
$sA5 << EOD
1000 6.830435
3000 24.212464
10000 81.376654
EOD
$sB0 << EOD
1000 1.226798
3000 1.434844
10000 2.146904
EOD
$sB1 << EOD
1000 0.486051
3000 1.133713
10000 2.383235
EOD
$sB2 << EOD
1000 0.580532
3000 1.202631
10000 2.470630
EOD
$sB3 << EOD
1000 0.424015
3000 0.700885
10000 1.102179
EOD
$sB4 << EOD
1000 0.450784
3000 0.709252
10000 1.036404
EOD
$sB5 << EOD
1000 7.680063
3000 15.871636
10000 25.104787
EOD
set multiplot layout 1,2 title "kolize-bench-2d, slow motion: frame time / Box2D's"
set logscale xy
set grid
set key top left
set xlabel "N"
set ylabel "frame time / Box2D's"
set title "scene A (uniform)"
plot 1 with lines dt 2 lc black title "Box2D", \
     $sA0 using 1:2 with linespoints title "grid", \
     $sA1 using 1:2 with linespoints title "spatial-tree", \
     $sA2 using 1:2 with linespoints title "spatial-hash", \
     $sA3 using 1:2 with linespoints title "segment-trees", \
     $sA4 using 1:2 with linespoints title "range-tree", \
     $sA5 using 1:2 with linespoints title "brute-force"
set title "scene B (clustered)"
plot 1 with lines dt 2 lc black title "Box2D", \
     $sB0 using 1:2 with linespoints title "grid", \
     $sB1 using 1:2 with linespoints title "spatial-tree", \
     $sB2 using 1:2 with linespoints title "spatial-hash", \
     $sB3 using 1:2 with linespoints title "segment-trees", \
     $sB4 using 1:2 with linespoints title "range-tree", \
     $sB5 using 1:2 with linespoints title "brute-force"
unset multiplot
