set terminal pngcairo size 1200,500 noenhanced
set output "box2d.png"
$sA0 << EOD
1000 0.115181
3000 0.111253
EOD
$sA1 << EOD
1000 0.141438
3000 0.127589
EOD
$sA2 << EOD
1000 0.106101
3000 0.133237
EOD
$sA3 << EOD
1000 0.122762
3000 0.128231
EOD
$sA4 << EOD
1000 0.159447
3000 0.168046
EOD
$sA5 << EOD
1000 6.627502
3000 19.208234
EOD
$sB0 << EOD
1000 1.508151
3000 1.336957
EOD
$sB1 << EOD
1000 0.656649
3000 1.039589
EOD
$sB2 << EOD
1000 0.718407
3000 1.052897
EOD
$sB3 << EOD
1000 0.448243
3000 0.655272
EOD
$sB4 << EOD
1000 0.505715
3000 0.649524
EOD
$sB5 << EOD
1000 6.782769
3000 13.274831
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
