set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-pyramid.png"
$ccdoff << EOD
7.001800 0.003618 0.000000 0.007010 "1/60 x1"
7.404100 0.014515 0.000000 0.029921 "1/30 x1"
15.080500 0.003497 0.000000 0.007010 "1/30 x2"
17.918400 0.000858 0.000000 0.001839 "1/60 x2"
30.259500 0.000211 0.000000 0.000980 "1/60 x4"
30.497500 0.000831 0.000000 0.001839 "1/30 x4"
57.164400 0.000179 0.000000 0.000980 "1/30 x8"
79.690400 0.000046 0.000000 0.000611 "1/60 x8"
121.522500 0.000045 0.000000 0.000611 "1/30 x16"
EOD
$ccdon << EOD
6.807600 0.014515 0.000000 0.029921 "1/30 x1"
7.614100 0.003618 0.000000 0.007010 "1/60 x1"
15.252100 0.003497 0.000000 0.007010 "1/30 x2"
15.299600 0.000858 0.000000 0.001839 "1/60 x2"
34.414900 0.000831 0.000000 0.001839 "1/30 x4"
41.239000 0.000211 0.000000 0.000980 "1/60 x4"
70.182100 0.000179 0.000000 0.000980 "1/30 x8"
73.396800 0.000046 0.000000 0.000611 "1/60 x8"
153.837500 0.000045 0.000000 0.000611 "1/30 x16"
EOD
set multiplot layout 1,3 title "pyramid: error against ms per step (labels: time step x substeps)"
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
