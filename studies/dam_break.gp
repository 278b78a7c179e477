# Dam-break validation plots (make plots-dambreak): surge front and residual
# column height of examples/dam_break.c against Martin & Moyce (1952).
# Variables: datadir (measurements), simdir (directory holding res<N>/ runs),
# outdir (PNG output), res1 (both columns, with and without the wall-friction
# model: res<res1>/ and res<res1>_nofriction/), res2 (a x 2a only), probe
# (the folder of the Buchner run in simdir).
# dam_break_front.png: the simulation as computed; dam_break_front_delayed.png:
# delayed by the protocol's fitted delay of each run (column T_delayed).
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

set output outdir."/dam_break_front_delayed.png"
set title "Surge front, each run delayed by its fitted delay (T >= 0.84 fitted)"
set xlabel "T = n t sqrt(g/a)"
set ylabel "Z = z / a"
set key top left
set xrange [0:3.6]
set yrange [1:5.5]
plot datadir."/mm1952_n2-2_a2.25in_front_table2.csv" using 1:2 with points pt 7 ps 1.2 lc rgb "#1f77b4" title "measured, a x 2a (Table 2)", \
     datadir."/mm1952_n2-1_a2.25in_front.csv" using 1:2 with points pt 5 ps 1.1 lc rgb "#d62728" title "measured, a x a (digitised)", \
     sim(res1, 2) using 8:3 with lines lw 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a, delayed", res1), \
     sim(res2, 2) using 8:3 with lines lw 2 dt 2 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a, delayed", res2), \
     slip(res1, 2) using 8:3 with lines lw 1 dt 3 lc rgb "#1f77b4" title sprintf("SPH a x 2a, %d across a, no wall friction, delayed", res1), \
     sim(res1, 1) using 8:3 with lines lw 2 lc rgb "#d62728" title sprintf("SPH a x a, %d across a, delayed", res1), \
     slip(res1, 1) using 8:3 with lines lw 1 dt 3 lc rgb "#d62728" title sprintf("SPH a x a, %d across a, no wall friction, delayed", res1)

set output outdir."/dam_break_probe.png"
set title "Pressure at P1 on the far wall: SPH against Buchner (2002)"
set xlabel "t sqrt(g/H)"
set ylabel "p / (rho g H)"
set key top left
set xrange [0:7.2]
set yrange [-0.5:1.5]
pfile(s) = datadir."/buchner2002_P1_pressure_digitised.csv"
plot pfile(0) using 2:(strcol(1) eq "pysph" ? $3 : NaN) with points pt 7 ps 0.6 lc rgb "#2ca02c" title "measured (PySPH digitisation)", \
     pfile(0) using 2:(strcol(1) eq "trixi_P1" ? $3 : NaN) with points pt 5 ps 0.6 lc rgb "#9467bd" title "measured (TrixiParticles.jl digitisation)", \
     pfile(0) using 2:(strcol(1) eq "jaxsph" ? $3 : NaN) with points pt 9 ps 0.6 lc rgb "#8c564b" title "measured (JAX-SPH digitisation)", \
     simdir."/".probe."/buchner_P1.csv" using 1:2 with lines lw 1.5 lc rgb "#1f77b4" title "SPH (bins of 0.02)"
