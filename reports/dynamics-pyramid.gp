set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-pyramid.png"
$ccdoff << EOD
7.531300 0.003618 0.000000 0.007010 "1/60 x1"
8.306600 0.014515 0.000000 0.029921 "1/30 x1"
16.328000 0.003497 0.000000 0.007010 "1/30 x2"
17.243500 0.000858 0.000000 0.001839 "1/60 x2"
33.141700 0.000211 0.000000 0.000980 "1/60 x4"
43.904300 0.000831 0.000000 0.001839 "1/30 x4"
71.771300 0.000046 0.000000 0.000611 "1/60 x8"
78.694700 0.000179 0.000000 0.000980 "1/30 x8"
141.939600 0.000045 0.000000 0.000611 "1/30 x16"
EOD
$ccdon << EOD
7.978400 0.014515 0.000000 0.029921 "1/30 x1"
8.062900 0.003618 0.000000 0.007010 "1/60 x1"
17.786500 0.003497 0.000000 0.007010 "1/30 x2"
21.609500 0.000858 0.000000 0.001839 "1/60 x2"
32.565800 0.000211 0.000000 0.000980 "1/60 x4"
34.328300 0.000831 0.000000 0.001839 "1/30 x4"
69.890500 0.000046 0.000000 0.000611 "1/60 x8"
77.153700 0.000179 0.000000 0.000980 "1/30 x8"
133.022400 0.000045 0.000000 0.000611 "1/30 x16"
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
