set terminal pngcairo size 1200,500 noenhanced
set output "scaling.png"
$sA0 << EOD
1000 0.047731
3000 0.054852
10000 0.059762
30000 0.074837
100000 0.126212
EOD
$sA1 << EOD
1000 0.065468
3000 0.071757
10000 0.082872
30000 0.102991
100000 0.218972
EOD
$sA2 << EOD
1000 0.056554
3000 0.059442
10000 0.067813
30000 0.072471
100000 0.132981
EOD
$sA3 << EOD
1000 0.052708
3000 0.058200
10000 0.072557
30000 0.077237
100000 0.149882
EOD
$sA4 << EOD
1000 0.054261
3000 0.064656
10000 0.078108
30000 0.086477
100000 0.166828
EOD
$sA5 << EOD
1000 0.387015
3000 0.496731
10000 0.748903
30000 1.257636
100000 2.537054
EOD
$sA6 << EOD
1000 0.309419
3000 0.381560
10000 0.551185
30000 1.224815
EOD
$sA7 << EOD
1000 0.007901
3000 0.008316
10000 0.008259
30000 0.007216
100000 0.009392
EOD
$sB0 << EOD
1000 0.774041
3000 1.895233
10000 3.120247
30000 5.164337
100000 12.461076
EOD
$sB1 << EOD
1000 0.095612
3000 0.228890
10000 0.881737
30000 2.086940
100000 7.961221
EOD
$sB2 << EOD
1000 0.093148
3000 0.221085
10000 0.841512
30000 1.979857
100000 9.161380
EOD
$sB3 << EOD
1000 0.072318
3000 0.138509
10000 0.412608
30000 1.086967
100000 5.980194
EOD
$sB4 << EOD
1000 0.086308
3000 0.137147
10000 0.451205
30000 1.035683
100000 5.554411
EOD
$sB5 << EOD
1000 0.725408
3000 1.058032
10000 3.920668
30000 10.307508
100000 47.189646
EOD
$sB6 << EOD
1000 0.441356
3000 0.627593
10000 1.485284
30000 2.506810
EOD
$sB7 << EOD
1000 0.007812
3000 0.008302
10000 0.007210
30000 0.008225
100000 0.009909
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
