set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-tall-stack.png"
$ccdoff << EOD
0.304900 0.056072 0.000000 1.292135 "1/60 x1"
0.577800 0.027160 0.000000 0.908320 "1/60 x2"
1.105800 0.010262 0.000000 0.091107 "1/60 x4"
EOD
$ccdon << EOD
0.302400 0.056072 0.000000 1.292135 "1/60 x1"
0.571000 0.027160 0.000000 0.908320 "1/60 x2"
1.110200 0.010262 0.000000 0.091107 "1/60 x4"
EOD
set multiplot layout 1,3 title "tall-stack: error against ms per step (labels: time step x substeps)"
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
