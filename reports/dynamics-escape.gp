set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-escape.png"
$ccdoff << EOD
0.107600 0.544408 0.000000 530.624573 "1/60 x1"
0.182900 0.051396 0.000000 530.616821 "1/60 x2"
0.337100 0.000000 0.000000 530.612915 "1/60 x4"
EOD
$ccdon << EOD
0.215000 0.544408 0.000000 101.984917 "1/60 x1"
0.345000 0.199762 0.000000 188.483521 "1/60 x2"
0.621900 0.107256 0.000000 260.765503 "1/60 x4"
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
