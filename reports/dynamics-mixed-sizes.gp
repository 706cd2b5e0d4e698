set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-mixed-sizes.png"
$ccdoff << EOD
0.517100 0.497330 0.000000 0.322906 "1/30 x1"
0.608700 0.232765 0.000000 0.156189 "1/60 x1"
0.865100 0.122314 0.000000 0.072968 "1/60 x2"
1.034300 0.204887 0.000000 0.156189 "1/30 x2"
1.479200 0.048958 0.000000 0.241709 "1/60 x4"
2.129600 0.122314 0.000000 0.072968 "1/30 x4"
2.789300 0.021538 0.000000 0.241709 "1/30 x8"
3.682100 0.015167 0.000000 0.359367 "1/60 x8"
5.472800 0.015167 0.000000 0.359367 "1/30 x16"
EOD
$ccdon << EOD
1.077000 0.497330 0.000000 0.322906 "1/30 x1"
1.335500 0.232765 0.000000 0.156189 "1/60 x1"
1.881400 0.122314 0.000000 0.072968 "1/60 x2"
2.072200 0.204887 0.000000 0.156189 "1/30 x2"
4.376800 0.122314 0.000000 0.072968 "1/30 x4"
4.671800 0.048958 0.000000 0.241709 "1/60 x4"
6.219300 0.021538 0.000000 0.241709 "1/30 x8"
9.198300 0.015167 0.000000 0.359367 "1/60 x8"
12.548400 0.015167 0.000000 0.359367 "1/30 x16"
EOD
set multiplot layout 1,3 title "mixed-sizes: error against ms per step (labels: time step x substeps)"
set logscale x
set grid
set key top right
set xlabel "ms per step"
set title "max penetration (m)"
set ylabel "max penetration (m)"
plot $ccdoff using 1:2 with points pt 7 title "CCD off", $ccdoff using 1:2:5 with labels font ",7" offset char 0,0.8 notitle, \
     $ccdon using 1:2 with points pt 7 title "CCD on", $ccdon using 1:2:5 with labels font ",7" offset char 0,0.8 notitle
set title "escaped bodies"
set ylabel "escaped bodies"
plot $ccdoff using 1:3 with points pt 7 title "CCD off", $ccdoff using 1:3:5 with labels font ",7" offset char 0,0.8 notitle, \
     $ccdon using 1:3 with points pt 7 title "CCD on", $ccdon using 1:3:5 with labels font ",7" offset char 0,0.8 notitle
set title "drift max (m)"
set ylabel "drift max (m)"
plot $ccdoff using 1:4 with points pt 7 title "CCD off", $ccdoff using 1:4:5 with labels font ",7" offset char 0,0.8 notitle, \
     $ccdon using 1:4 with points pt 7 title "CCD on", $ccdon using 1:4:5 with labels font ",7" offset char 0,0.8 notitle
unset multiplot
