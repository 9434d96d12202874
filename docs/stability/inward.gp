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
plot data using 1:2 with linespoints lw 2, data using 1:4 with linespoints lw 2, data using 1:3 with linespoints lw 2
