set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-escape.png"
$ccdoff << EOD
0.232000 1.252002 0.000000 2220.166992 "1/60 x1"
0.290200 1.252002 0.000000 2220.320312 "1/30 x1"
0.470100 0.330617 0.000000 2220.166992 "1/30 x2"
0.474200 0.701545 0.000000 2220.096436 "1/60 x2"
0.849800 0.293855 0.000000 2220.052246 "1/60 x4"
0.912100 0.029776 0.000000 2220.096436 "1/30 x4"
1.711000 0.293855 0.000000 2220.052246 "1/30 x8"
2.523300 0.115872 0.000000 2220.093750 "1/60 x8"
3.754600 0.027104 0.000000 2220.093750 "1/30 x16"
EOD
$ccdon << EOD
0.501000 1.252002 0.000000 1914.916138 "1/60 x1"
0.575500 1.252002 0.000000 2226.448730 "1/30 x1"
1.030300 0.840191 0.000000 1787.216431 "1/60 x2"
1.405600 0.491318 0.000000 1914.916138 "1/30 x2"
1.948800 0.154714 0.000000 1531.899170 "1/60 x4"
2.712500 0.404510 0.000000 1787.216431 "1/30 x4"
3.332400 0.000000 0.000000 1531.899170 "1/30 x8"
4.358300 0.115872 0.000000 1713.589233 "1/60 x8"
6.343400 0.000000 0.000000 1713.589233 "1/30 x16"
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
