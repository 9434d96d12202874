# Made by `bumpgrad stability`; rerun it to regenerate.
set datafile separator ','
set grid
set key autotitle columnhead
set terminal pngcairo size 900,560 noenhanced
set output 'docs/stability/.large_coords.tmp.png'
set title 'Large coordinates: max error vs base'
set xlabel 'base coordinate X'
set ylabel 'max |error| (float: 0 not drawn)'
set logscale x
set format x '%.0e'
set logscale y
set format y '%.0e'
data = 'docs/stability/large_coords.csv'
set key left center
set yrange [1e-18:3]
plot data using 1:($2>0?$2:1/0) with linespoints lw 2 title 'float', data using 1:($4>0?$4:1e-17) with linespoints lw 2 dt 2 title 'double (exact: drawn at 1e-17)'
