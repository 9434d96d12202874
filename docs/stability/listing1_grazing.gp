# Made by `bumpgrad stability`; rerun it to regenerate.
set datafile separator ','
set grid
set key autotitle columnhead
set terminal pngcairo size 900,560 noenhanced
set output 'docs/stability/.listing1_grazing.tmp.png'
set title 'Listing 1 error vs view angle'
set xlabel 'angle between view and normal (deg)'
set ylabel 'angle error (deg)'
set logscale y
set format y '%.0e'
data = 'docs/stability/listing1_grazing.csv'
plot data using 1:2 with linespoints lw 2, data using 1:3 with linespoints lw 2
