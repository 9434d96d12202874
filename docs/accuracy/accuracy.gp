# Made by `bumpgrad accuracy`; rerun it to regenerate. Reads accuracy.csv.
$pareto << EOD
5.701,20.6496
6.884,7.13792
13.35,7.08531
21.43,1.84544
26.83,1.62263
28.54,9.84181e-06
436.2,1e-07
EOD
set datafile separator ','
set logscale xy
set grid
set format y '%.0e'
set xlabel 'time per sample (ns, one thread)'
set ylabel 'mean angle error of n (degrees; exact drawn at 1e-7)'
set title 'bumpgrad: speed against accuracy of the perturbed normal'
set key outside right top
e(c) = (column(c) > 1e-7 ? column(c) : 1e-7)
sel(m, p) = (strcol(1) eq m && strcol(3) eq p)
lab = '(strcol(1)." ".strcol(2))'
set terminal pngcairo size 1100,700 noenhanced
set output 'docs/accuracy/.accuracy.tmp.png'
plot \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('analytic','float32') ? $4 : 1/0):(e(5)) with points pt 7 ps 1.6 lc rgb '#d62728' title 'analytic f32', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('analytic','float64') ? $4 : 1/0):(e(5)) with points pt 5 ps 1.4 lc rgb '#8c564b' title 'analytic f64 (reference)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('central','float32') ? $4 : 1/0):(e(5)) with linespoints pt 9 lc rgb '#1f77b4' title 'central f32 (h sweep)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('central','float64') ? $4 : 1/0):(e(5)) with linespoints pt 11 lc rgb '#17becf' title 'central f64 (h sweep)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('forward','float32') ? $4 : 1/0):(e(5)) with points pt 13 lc rgb '#9467bd' title 'forward f32', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('listing1','float32') ? $4 : 1/0):(e(5)) with linespoints pt 6 lc rgb '#2ca02c' title 'Listing 1 (pixel density)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('truncated','float32') ? $4 : 1/0):(e(5)) with linespoints pt 4 lc rgb '#ff7f0e' title 'fewer octaves', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('fixed-octaves','float32') ? $4 : 1/0):(e(5)) with linespoints pt 8 lc rgb '#7f7f7f' title 'all 6 octaves vs pixel average', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('footprint','float32') ? $4 : 1/0):(e(5)) with linespoints pt 3 ps 1.4 lc rgb '#e377c2' title 'footprint-aware vs pixel average', \
  'docs/accuracy/accuracy.csv' every ::1 using 4:(e(5)):(strcol(2)) with labels offset 0.8,0.5 font ',7' notitle, \
  $pareto using 1:2 with steps lw 2 dt 2 lc rgb '#444444' title 'Pareto front'
set terminal svg size 1100,700 noenhanced
set output 'docs/accuracy/.accuracy.tmp.svg'
plot \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('analytic','float32') ? $4 : 1/0):(e(5)) with points pt 7 ps 1.6 lc rgb '#d62728' title 'analytic f32', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('analytic','float64') ? $4 : 1/0):(e(5)) with points pt 5 ps 1.4 lc rgb '#8c564b' title 'analytic f64 (reference)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('central','float32') ? $4 : 1/0):(e(5)) with linespoints pt 9 lc rgb '#1f77b4' title 'central f32 (h sweep)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('central','float64') ? $4 : 1/0):(e(5)) with linespoints pt 11 lc rgb '#17becf' title 'central f64 (h sweep)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('forward','float32') ? $4 : 1/0):(e(5)) with points pt 13 lc rgb '#9467bd' title 'forward f32', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('listing1','float32') ? $4 : 1/0):(e(5)) with linespoints pt 6 lc rgb '#2ca02c' title 'Listing 1 (pixel density)', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('truncated','float32') ? $4 : 1/0):(e(5)) with linespoints pt 4 lc rgb '#ff7f0e' title 'fewer octaves', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('fixed-octaves','float32') ? $4 : 1/0):(e(5)) with linespoints pt 8 lc rgb '#7f7f7f' title 'all 6 octaves vs pixel average', \
  'docs/accuracy/accuracy.csv' every ::1 using (sel('footprint','float32') ? $4 : 1/0):(e(5)) with linespoints pt 3 ps 1.4 lc rgb '#e377c2' title 'footprint-aware vs pixel average', \
  'docs/accuracy/accuracy.csv' every ::1 using 4:(e(5)):(strcol(2)) with labels offset 0.8,0.5 font ',7' notitle, \
  $pareto using 1:2 with steps lw 2 dt 2 lc rgb '#444444' title 'Pareto front'
