# Made by `bumpgrad stability`; rerun it to regenerate.
set datafile separator ','
set grid
set key autotitle columnhead
set terminal pngcairo size 900,560 noenhanced
set output 'docs/stability/.creases.tmp.png'
set title 'Turbulence: analytic vs central near creases'
set xlabel 'distance to nearest octave zero crossing (upper bin edge)'
set ylabel 'angle between normals (deg)'
set logscale x
set format x '%.0e'
set logscale y
set format y '%.0e'
data = 'docs/stability/creases.csv'
plot data using 1:($3>0?$3:1/0) with linespoints lw 2 title 'mean angle error', data using 1:($4>0?$4:1/0) with linespoints lw 2 title 'max angle error'
