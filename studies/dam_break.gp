# Dam-break validation plots (make plots-dambreak): surge front and residual
# column height of examples/dam_break.c against Martin & Moyce (1952).
# Variables: datadir (measurements), simdir (directory holding res<N>/ runs),
# outdir (PNG output), res1 (both columns, with and without the wall-friction
# model: res<res1>/ and res<res1>_nofriction/), res2 (a x 2a only).
# Every curve is the simulation as computed: no shift in time.
set terminal pngcairo size 900,600 font ",11"
set datafile separator ","
set grid

sim(r, n2) = sprintf("%s/res%d/dam_break_n2-%d.csv", simdir, r, n2)
slip(r, n2) = sprintf("%s/res%d_nofriction/dam_break_n2-%d.csv", simdir, r, n2)

set output outdir."/dam_break_front.png"
set title "Surge front: SPH against Martin and Moyce (1952)"
set xlabel "T = n t sqrt(g/a)"
set ylabel "Z = z / a"
set key top left
set xrange [0:3.6]
set yrange [1:5.5]
plot datadir."/mm1952_n2-2_a2.25in_front_table2.csv" using 1:2 with points pt 7 ps 1.2 lc rgb "#1f77b4" title "measured, a x 2a (Table 2)", \
     datadir."/mm1952_n2-1_a2.25in_front.csv" using 1:2 with points pt 5 ps 1.1 lc rgb "#d62728" title "measured, a x a (digitised)", \
     sim(res1, 2) using 2:3 with lines lw 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a", res1), \
     sim(res2, 2) using 2:3 with lines lw 2 dt 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a", res2), \
     slip(res1, 2) using 2:3 with lines lw 1 dt 3 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a, no wall friction", res1), \
     sim(res1, 1) using 2:3 with lines lw 2 lc rgb "#d62728" title sprintf("SPH a x a, %d across a", res1), \
     slip(res1, 1) using 2:3 with lines lw 1 dt 3 lc rgb "#d62728" title sprintf("SPH a x a, %d across a, no wall friction", res1)

set output outdir."/dam_break_height.png"
set title "Residual column height at the back wall: SPH against Martin and Moyce (1952)"
set xlabel "tau = t sqrt(g/a)"
set ylabel "H = eta / (n^2 a)"
set key top right
set xrange [0:3.6]
set yrange [0:1.05]
plot datadir."/mm1952_n2-2_a2.25in_height_table6.csv" using 1:2 with points pt 7 ps 1.2 lc rgb "#1f77b4" title "measured, a x 2a (Table 6)", \
     datadir."/mm1952_n2-1_a2.25in_height.csv" using 1:2 with points pt 5 ps 1.1 lc rgb "#d62728" title "measured, a x a (digitised)", \
     sim(res1, 2) using 1:4 with lines lw 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a", res1), \
     sim(res2, 2) using 1:4 with lines lw 2 dt 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a", res2), \
     slip(res1, 2) using 1:4 with lines lw 1 dt 3 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a, no wall friction", res1), \
     sim(res1, 1) using 1:4 with lines lw 2 lc rgb "#d62728" title sprintf("SPH a x a, %d across a", res1), \
     slip(res1, 1) using 1:4 with lines lw 1 dt 3 lc rgb "#d62728" title sprintf("SPH a x a, %d across a, no wall friction", res1)
