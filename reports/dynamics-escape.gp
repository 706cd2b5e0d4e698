set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-escape.png"
$ccdoff << EOD
0.244000 1.252002 0.000000 2220.166992 "1/60 x1"
0.275300 1.252002 0.000000 2220.320312 "1/30 x1"
0.435000 0.701545 0.000000 2220.096436 "1/60 x2"
0.445800 0.330617 0.000000 2220.166992 "1/30 x2"
0.790900 0.293855 0.000000 2220.052246 "1/60 x4"
0.991500 0.029776 0.000000 2220.096436 "1/30 x4"
1.480100 0.293855 0.000000 2220.052246 "1/30 x8"
2.066000 0.115872 0.000000 2220.093750 "1/60 x8"
3.255200 0.027104 0.000000 2220.093750 "1/30 x16"
EOD
$ccdon << EOD
0.550600 1.252002 0.000000 2226.448730 "1/30 x1"
0.569300 1.252002 0.000000 1914.916138 "1/60 x1"
0.896800 0.840191 0.000000 1787.216431 "1/60 x2"
0.932300 0.491318 0.000000 1914.916138 "1/30 x2"
1.776100 0.154714 0.000000 1531.899170 "1/60 x4"
1.986500 0.404510 0.000000 1787.216431 "1/30 x4"
3.350600 0.000000 0.000000 1531.899170 "1/30 x8"
4.010600 0.115872 0.000000 1713.589233 "1/60 x8"
5.701400 0.000000 0.000000 1713.589233 "1/30 x16"
EOD
set multiplot layout 1,3 title "escape: error against ms per step (labels: time step x substeps)"
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
