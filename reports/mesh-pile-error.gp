set terminal pngcairo size 1000,450 noenhanced
set output "mesh-pile-error.png"
$m0 << EOD
14.694600 0.139599 0 "1/240" 0.015629
15.144100 0.229167 0 "1/480" 0.026922
16.427600 0.150103 0 "1/120" 0.247115
25.085900 0.129209 0 "1/60" 0.179400
29.348600 0.253714 2 "1/30" 0.475337
EOD
$m1 << EOD
14.055500 0.134452 0 "1/480" 0.251970
14.413200 0.093349 0 "1/240" 0.110061
16.902700 0.186919 0 "1/120" 0.148984
24.061500 0.161741 1 "1/60" 0.246993
30.116700 0.156686 0 "1/30" 0.481006
EOD
$m2 << EOD
1.530190 0.282667 0 "1/480" 0.040082
1.871760 0.197758 0 "1/240" 0.021442
2.202030 0.270245 0 "1/120" 0.078329
2.794150 0.271796 0 "1/60" 0.195746
4.036700 0.327124 0 "1/30" 0.338902
EOD
$m3 << EOD
1.427380 0.282667 0 "1/480" 0.040082
1.782650 0.197758 0 "1/240" 0.021442
2.131580 0.270245 0 "1/120" 0.078329
2.646990 0.271796 0 "1/60" 0.195746
3.883360 0.327124 0 "1/30" 0.338902
EOD
$m4 << EOD
5.378920 0.160320 0 "1/240" 0.073071
5.429960 0.183007 0 "1/480" 0.020411
6.238930 0.308177 0 "1/60" 0.220573
6.311130 0.260880 0 "1/120" 0.052249
7.361660 0.375676 0 "1/30" 0.429913
EOD
set title "mesh-pile: penetration (measured exactly) against step time"
set logscale x
set logscale y
set grid
set key top right
set xlabel "median step time (ms)"
set ylabel "largest penetration (m)"
plot $m0 using 1:5 with linespoints lw 2 pt 7 title "gimpact", $m0 using 1:5:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m1 using 1:5 with linespoints lw 2 pt 9 title "gimpact-0", $m1 using 1:5:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m2 using 1:5 with linespoints lw 2 pt 11 title "kolize", $m2 using 1:5:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m3 using 1:5 with linespoints lw 2 pt 13 title "kolize-all-on", $m3 using 1:5:4 with labels font ",8" offset char 0,0.9 notitle, \
     $m4 using 1:5 with linespoints lw 2 pt 15 title "kolize-margin", $m4 using 1:5:4 with labels font ",8" offset char 0,0.9 notitle
