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
set lmargin at screen 0.09
set rmargin at screen 0.62
set bmargin at screen 0.09
set tmargin at screen 0.93
set xrange [1:10000]
set yrange [1e-07:100]
set label 1 '1' at screen 0.19562,0.87606 left font ',7' front
set label 2 '16' at screen 0.20647,0.83300 left font ',7' front
set label 3 '2' at screen 0.22093,0.87121 left font ',7' front
set label 4 '3' at screen 0.23869,0.86514 left font ',7' front
set label 5 '64' at screen 0.24458,0.80413 left font ',7' front
set arrow from first 13.35,7.08531 to screen 0.24367,0.80413 nohead lw 0.6 lc rgb '#999999' back
set label 6 '4' at screen 0.25205,0.85690 left font ',7' front
set label 7 '5' at screen 0.26404,0.88569 left font ',7' front
set arrow from first 18.72,9.097 to screen 0.26313,0.88569 nohead lw 0.6 lc rgb '#999999' back
set label 8 '1024' at screen 0.27181,0.79246 left font ',7' front
set arrow from first 21.43,1.84544 to screen 0.27091,0.79246 nohead lw 0.6 lc rgb '#999999' back
set label 9 '64' at screen 0.27195,0.89138 left font ',7' front
set arrow from first 21.48,14.8912 to screen 0.27104,0.89138 nohead lw 0.6 lc rgb '#999999' back
set label 10 '16' at screen 0.27198,0.91751 left font ',7' front
set arrow from first 21.49,19.9472 to screen 0.27107,0.91751 nohead lw 0.6 lc rgb '#999999' back
set label 11 '256' at screen 0.27531,0.74348 left font ',7' front
set arrow from first 22.77,6.49779 to screen 0.27440,0.74348 nohead lw 0.6 lc rgb '#999999' back
set label 12 '1024' at screen 0.27626,0.72103 left font ',7' front
set arrow from first 23.15,1.84544 to screen 0.27535,0.72103 nohead lw 0.6 lc rgb '#999999' back
set label 13 '256' at screen 0.28135,0.83292 left font ',7' front
set label 14 '256' at screen 0.28436,0.70238 left font ',7' front
set arrow from first 26.65,13.7339 to screen 0.28345,0.70238 nohead lw 0.6 lc rgb '#999999' back
set label 15 '1024' at screen 0.28445,0.80928 left font ',7' front
set arrow from first 26.69,5.65558 to screen 0.28354,0.80928 nohead lw 0.6 lc rgb '#999999' back
set label 16 '64' at screen 0.28473,0.87313 left font ',7' front
set label 17 '4096' at screen 0.28475,0.77295 left font ',7' front
set label 18 '0.01' at screen 0.32865,0.87935 left font ',7' front
set arrow from first 57.54,11.0683 to screen 0.32774,0.87935 nohead lw 0.6 lc rgb '#999999' back
set label 19 '0.0001' at screen 0.32872,0.67164 left font ',7' front
set arrow from first 57.61,0.189566 to screen 0.32781,0.67164 nohead lw 0.6 lc rgb '#999999' back
set label 20 '0.001' at screen 0.32893,0.76172 left font ',7' front
set arrow from first 57.82,1.74972 to screen 0.32802,0.76172 nohead lw 0.6 lc rgb '#999999' back
set label 21 '3e-05' at screen 0.35970,0.61883 left font ',7' front
set arrow from first 98.69,0.0515143 to screen 0.35879,0.61883 nohead lw 0.6 lc rgb '#999999' back
set label 22 '0.0001' at screen 0.35984,0.71572 left font ',7' front
set arrow from first 98.93,0.0965561 to screen 0.35893,0.71572 nohead lw 0.6 lc rgb '#999999' back
set label 23 '0.0003' at screen 0.35992,0.75665 left font ',7' front
set arrow from first 99.08,0.264996 to screen 0.35901,0.75665 nohead lw 0.6 lc rgb '#999999' back
set label 24 '0.003' at screen 0.36014,0.80665 left font ',7' front
set arrow from first 99.46,2.61955 to screen 0.35923,0.80665 nohead lw 0.6 lc rgb '#999999' back
set label 25 '0.01' at screen 0.36030,0.82342 left font ',7' front
set arrow from first 99.73,8.01581 to screen 0.35939,0.82342 nohead lw 0.6 lc rgb '#999999' back
set label 26 '0.03' at screen 0.36091,0.88968 left font ',7' front
set arrow from first 100.8,14.2809 to screen 0.36000,0.88968 nohead lw 0.6 lc rgb '#999999' back
set label 27 '1e-06' at screen 0.36103,0.65597 left font ',7' front
set arrow from first 101,0.750301 to screen 0.36012,0.65597 nohead lw 0.6 lc rgb '#999999' back
set label 28 '1e-05' at screen 0.36199,0.63417 left font ',7' front
set arrow from first 102.7,0.0752252 to screen 0.36108,0.63417 nohead lw 0.6 lc rgb '#999999' back
set label 29 '3e-06' at screen 0.36210,0.69035 left font ',7' front
set arrow from first 102.9,0.300765 to screen 0.36119,0.69035 nohead lw 0.6 lc rgb '#999999' back
set label 30 '0.001' at screen 0.36266,0.73344 left font ',7' front
set arrow from first 103.9,0.870872 to screen 0.36175,0.73344 nohead lw 0.6 lc rgb '#999999' back
set label 31 '3e-07' at screen 0.36293,0.78480 left font ',7' front
set arrow from first 104.4,3.09211 to screen 0.36202,0.78480 nohead lw 0.6 lc rgb '#999999' back
set label 32 '0.1' at screen 0.36343,0.87209 left font ',7' front
set label 33 '1e-07' at screen 0.36354,0.84450 left font ',7' front
set arrow from first 105.5,13.4854 to screen 0.36263,0.84450 nohead lw 0.6 lc rgb '#999999' back
set label 34 '1e-05' at screen 0.51418,0.56296 left font ',7' front
set label 35 '3e-05' at screen 0.51430,0.60689 left font ',7' front
set label 36 '0.0001' at screen 0.51508,0.65485 left font ',7' front
set label 37 '0.003' at screen 0.51524,0.79237 left font ',7' front
set label 38 '0.0003' at screen 0.51579,0.69934 left font ',7' front
set label 39 '0.1' at screen 0.51617,0.87209 left font ',7' front
set label 40 '3e-06' at screen 0.51663,0.51239 left font ',7' front
set label 41 '1e-06' at screen 0.51728,0.46950 left font ',7' front
set label 42 '0.001' at screen 0.51739,0.74773 left font ',7' front
set label 43 '0.03' at screen 0.52064,0.84682 left font ',7' front
set arrow from first 1618,14.2809 to screen 0.51974,0.84682 nohead lw 0.6 lc rgb '#999999' back
set label 44 '0.01' at screen 0.52118,0.82342 left font ',7' front
set arrow from first 1633,8.01581 to screen 0.52027,0.82342 nohead lw 0.6 lc rgb '#999999' back
set label 45 '3e-07' at screen 0.52453,0.43002 left font ',7' front
set label 46 '1e-07' at screen 0.52516,0.37733 left font ',7' front
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
  $pareto using 1:2 with steps lw 2 dt 2 lc rgb '#444444' title 'Pareto front'
