set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-boxes.png"
$ccdoff << EOD
0.074500 0.041667 0.000000 0.019904 "1/60 x1"
0.117500 0.021674 0.000000 0.013164 "1/60 x2"
0.208600 0.005208 0.000000 0.013558 "1/60 x4"
EOD
$ccdon << EOD
0.078100 0.041667 0.000000 0.019904 "1/60 x1"
0.120000 0.021674 0.000000 0.013164 "1/60 x2"
0.206900 0.005208 0.000000 0.013558 "1/60 x4"
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
