# Figure 2 of Woop 2010 on this machine, from `bench_kernels --csv`:
#   build/bench_kernels --csv > kernels.csv
#   gnuplot -e "csv='kernels.csv'; out='docs/kernels_fig2.svg'" bench/plot_kernels.gp
if (!exists("csv")) csv = 'kernels.csv'
if (!exists("out")) out = 'docs/kernels_fig2.svg'
set terminal svg size 720,480 dynamic font "Helvetica,13"
set output out
set datafile separator ","
set key top left
set logscale xy
set xrange [0.8:1300]
set xlabel "occluded samples per triangle (32x32 buffer)"
set ylabel "cycles per triangle (TSC, median)"
set grid
set title "Micro-rasterization kernels: cost against triangle size"
sel(k) = (strcol(1) eq k) ? $3 : NaN
plot csv using 2:(sel("hierarchical")) skip 1 with linespoints lw 2 pt 5 title "Hierarchical", \
     csv using 2:(sel("bounds")) skip 1 with linespoints lw 2 pt 9 title "Bounds", \
     csv using 2:(sel("scanline")) skip 1 with linespoints lw 2 pt 7 title "Scanline (scalar)", \
     csv using 2:(sel("scanline_simd")) skip 1 with linespoints lw 2 pt 13 title "Scanline (AVX-512)", \
     csv using 2:(sel("scanline_avx2")) skip 1 with linespoints lw 2 pt 11 title "Scanline (AVX2)"
