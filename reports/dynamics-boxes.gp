set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-boxes.png"
$ccdoff << EOD
5.963500 0.522545 0.000000 9.978365 "1/60 x1"
7.571500 1.241010 1.000000 12.987722 "1/30 x1"
13.345200 0.185415 0.000000 1.997970 "1/60 x2"
13.779400 0.522545 0.000000 9.978365 "1/30 x2"
20.083700 0.104391 0.000000 1.111814 "1/60 x4"
34.257300 0.185415 0.000000 1.997970 "1/30 x4"
35.847100 0.038327 0.000000 0.276262 "1/60 x8"
51.182600 0.104391 0.000000 1.111814 "1/30 x8"
86.945300 0.038327 0.000000 0.276262 "1/30 x16"
EOD
$ccdon << EOD
7.805300 0.977430 0.000000 12.935075 "1/30 x1"
9.834900 0.522545 0.000000 9.978365 "1/60 x1"
14.350600 0.185415 0.000000 1.997970 "1/60 x2"
19.062600 0.522545 0.000000 9.978365 "1/30 x2"
31.073100 0.104391 0.000000 1.111814 "1/60 x4"
34.000600 0.185415 0.000000 1.997970 "1/30 x4"
37.497600 0.038327 0.000000 0.276262 "1/60 x8"
45.684800 0.104391 0.000000 1.111814 "1/30 x8"
75.641400 0.038327 0.000000 0.276262 "1/30 x16"
EOD
set multiplot layout 1,3 title "boxes: error against ms per step (labels: time step x substeps)"
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
