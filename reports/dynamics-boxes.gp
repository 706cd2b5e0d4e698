set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-boxes.png"
$ccdoff << EOD
5.877300 0.522545 0.000000 9.978365 "1/60 x1"
7.937600 1.241010 1.000000 12.987722 "1/30 x1"
13.668000 0.522545 0.000000 9.978365 "1/30 x2"
14.876200 0.185415 0.000000 1.997970 "1/60 x2"
18.147200 0.104391 0.000000 1.111814 "1/60 x4"
23.489100 0.185415 0.000000 1.997970 "1/30 x4"
33.572600 0.104391 0.000000 1.111814 "1/30 x8"
42.840800 0.038327 0.000000 0.276262 "1/60 x8"
83.928400 0.038327 0.000000 0.276262 "1/30 x16"
EOD
$ccdon << EOD
5.379800 0.522545 0.000000 9.978365 "1/60 x1"
6.574500 0.977430 0.000000 12.935075 "1/30 x1"
11.312800 0.185415 0.000000 1.997970 "1/60 x2"
17.299600 0.522545 0.000000 9.978365 "1/30 x2"
18.906100 0.104391 0.000000 1.111814 "1/60 x4"
31.578700 0.185415 0.000000 1.997970 "1/30 x4"
32.874800 0.104391 0.000000 1.111814 "1/30 x8"
42.739600 0.038327 0.000000 0.276262 "1/60 x8"
66.500700 0.038327 0.000000 0.276262 "1/30 x16"
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
