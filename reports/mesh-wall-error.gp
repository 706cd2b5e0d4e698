set terminal pngcairo size 1000,450 noenhanced
set output "mesh-wall-error.png"
$m0 << EOD
0.626525 0.254086 4 "1/60" 0.178578
0.641764 0.155580 3 "1/240" 0.237461
0.820111 0.177751 4 "1/120" 0.230651
1.448870 0.402475 3 "1/480" 0.210388
2.241500 0.254086 5 "1/30" 0.235929
EOD
$m1 << EOD
0.182946 0.111333 4 "1/240" 0.246000
0.229575 0.359680 2 "1/480" 0.220905
0.321058 0.125305 4 "1/120" 0.333666
0.374008 0.234086 5 "1/60" 0.244288
0.585818 0.234086 5 "1/30" 0.236103
EOD
$m2 << EOD
0.097795 0.029159 0 "1/240" 0.018048
0.099689 0.047309 0 "1/480" 0.032345
0.168279 0.032800 0 "1/120" 0.049611
0.211210 0.046589 0 "1/60" 0.041377
2.555300 0.164072 0 "1/30" 0.015361
EOD
$m3 << EOD
0.079671 0.171504 1 "1/480"
0.138011 0.145163 4 "1/60"
0.141537 0.111706 3 "1/120"
0.194528 0.106797 2 "1/240"
0.229254 0.145163 4 "1/30"
EOD
$m4 << EOD
0.092885 0.047309 0 "1/480" 0.032345
0.093527 0.029159 0 "1/240" 0.018048
0.156937 0.032800 0 "1/120" 0.049611
0.213874 0.046589 0 "1/60" 0.041377
2.561650 0.164072 0 "1/30" 0.015361
EOD
$m5 << EOD
0.248640 0.039467 0 "1/480" 0.020089
0.345664 0.032800 0 "1/120" 0.049611
0.348840 0.029159 0 "1/240" 0.018048
0.448238 0.046589 0 "1/60" 0.041377
2.560660 0.208926 0 "1/30" 0.054569
EOD
set title "mesh-wall: tunnelled bodies against step time"
set logscale x
set grid
set key top right
set xlabel "median step time (ms)"
set ylabel "bodies past the wall"
plot $m0 using 1:3 with linespoints lw 2 pt 7 title "gimpact", $m0 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m1 using 1:3 with linespoints lw 2 pt 9 title "gimpact-0", $m1 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m2 using 1:3 with linespoints lw 2 pt 11 title "kolize", $m2 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m3 using 1:3 with linespoints lw 2 pt 13 title "kolize, no CCD", $m3 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m4 using 1:3 with linespoints lw 2 pt 15 title "kolize-all-on", $m4 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m5 using 1:3 with linespoints lw 2 pt 17 title "kolize-margin", $m5 using 1:3:4 with labels font ",8" offset char 0,0.9 notitle
