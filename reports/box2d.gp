set terminal pngcairo size 1200,500 noenhanced
set output "box2d.png"
$sA0 << EOD
1000 0.085952
3000 0.108017
10000 0.185098
EOD
$sA1 << EOD
1000 0.123640
3000 0.147890
10000 0.230819
EOD
$sA2 << EOD
1000 0.088107
3000 0.111039
10000 0.196332
EOD
$sA3 << EOD
1000 0.124109
3000 0.159763
10000 0.196255
EOD
$sA4 << EOD
1000 0.155342
3000 0.195593
10000 0.206152
EOD
$sA5 << EOD
1000 6.465460
3000 31.558571
10000 104.243281
EOD
$sB0 << EOD
1000 1.594185
3000 1.797764
10000 1.341276
EOD
$sB1 << EOD
1000 0.767086
3000 1.458179
10000 1.419347
EOD
$sB2 << EOD
1000 0.761096
3000 1.452772
10000 1.413057
EOD
$sB3 << EOD
1000 0.527742
3000 0.935345
10000 0.935054
EOD
$sB4 << EOD
1000 0.548169
3000 0.887998
10000 0.926963
EOD
$sB5 << EOD
1000 7.943200
3000 18.417760
10000 20.954409
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
