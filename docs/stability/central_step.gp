# Made by `bumpgrad stability`; rerun it to regenerate.
set datafile separator ','
set grid
set key autotitle columnhead
set terminal pngcairo size 900,560 noenhanced
set output 'docs/stability/.central_step.tmp.png'
set title 'float32 central differences: error vs step'
set xlabel 'step h (noise units)'
set ylabel 'gradient error'
set logscale x
set format x '%.0e'
set logscale y
set format y '%.0e'
data = 'docs/stability/central_step.csv'
plot data using 1:2 with linespoints lw 2 title 'fBm gradient error, mean', data using 1:3 with linespoints lw 2 title 'fBm gradient error, p99'
