# Made by `bumpgrad stability`; rerun it to regenerate.
set datafile separator ','
set grid
set key autotitle columnhead
set terminal pngcairo size 900,560 noenhanced
set output 'docs/stability/.inward.tmp.png'
set title 'Inward-pointing normals vs amplitude'
set xlabel 'amplitude'
set ylabel 'fraction of samples with dot(perturbed n, n) <= 0'
set logscale x
set format x '%.0e'
data = 'docs/stability/inward.csv'
set key left top
set yrange [-0.03:*]
plot data using 1:2 with linespoints lw 2 title 'additive, n - grad h', data using 1:4 with linespoints lw 2 title 'additive with Perlin sign, n + grad h', data using 1:3 with linespoints lw 3 dt 2 pt 7 title 'surface gradient (eq. 4): always 0'
