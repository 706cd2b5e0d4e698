set terminal pngcairo size 1500,450 noenhanced
set output "dynamics-tall-stack.png"
$ccdoff << EOD
0.080300 0.417833 12.000000 13.889870 "1/30 x1"
0.102000 0.049801 0.000000 0.725435 "1/60 x1"
0.158800 0.009291 0.000000 0.268876 "1/60 x2"
0.174800 0.049801 0.000000 0.725435 "1/30 x2"
0.338000 0.002163 0.000000 0.170154 "1/60 x4"
0.398800 0.009291 0.000000 0.268876 "1/30 x4"
0.636800 0.002163 0.000000 0.170154 "1/30 x8"
0.800200 0.000719 0.000000 0.056457 "1/60 x8"
1.280400 0.000719 0.000000 0.056457 "1/30 x16"
EOD
$ccdon << EOD
0.089900 0.417697 12.000000 13.898369 "1/30 x1"
0.100100 0.049801 0.000000 0.725435 "1/60 x1"
0.158600 0.009291 0.000000 0.268876 "1/60 x2"
0.166800 0.049801 0.000000 0.725435 "1/30 x2"
0.321500 0.009291 0.000000 0.268876 "1/30 x4"
0.387600 0.002163 0.000000 0.170154 "1/60 x4"
0.777000 0.002163 0.000000 0.170154 "1/30 x8"
0.831600 0.000719 0.000000 0.056457 "1/60 x8"
1.289300 0.000719 0.000000 0.056457 "1/30 x16"
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
