# Sod shock tube at t = 0.2 (make plots-sod): density, velocity, pressure and
# the viscosity switch of examples/sod_shock.c against the exact Riemann
# solution the program writes (sod_exact.csv), for the nx = 16 and 48 runs.
# Variables: datadir (the --out directory of the study), outdir (PNG output).
set terminal pngcairo size 1200,900 font ",11"
set datafile separator ","
set output outdir."/sod_shock.png"
set multiplot layout 2,2 title "Sod shock tube in 3-D, t = 0.2, gamma = 5/3: SPH particles (|x| <= 0.5) and the exact solution"
set grid
set xrange [-0.5:0.5]
set key top right
run(n) = sprintf("%s/sod_nx%d.csv", datadir, n)
ex = datadir."/sod_exact.csv"
set title "density"
plot run(16) using 1:2 every ::1 with points pt 7 ps 0.2 lc rgb "#ff7f0e" title "nx 16", \
     run(48) using 1:2 every ::1 with points pt 7 ps 0.2 lc rgb "#1f77b4" title "nx 48", \
     ex using 1:2 every ::1 with lines lw 2 lc rgb "black" title "exact"
set title "velocity v_x"
set key top left
plot run(16) using 1:3 every ::1 with points pt 7 ps 0.2 lc rgb "#ff7f0e" title "nx 16", \
     run(48) using 1:3 every ::1 with points pt 7 ps 0.2 lc rgb "#1f77b4" title "nx 48", \
     ex using 1:3 every ::1 with lines lw 2 lc rgb "black" title "exact"
set title "pressure"
set key top right
plot run(16) using 1:4 every ::1 with points pt 7 ps 0.2 lc rgb "#ff7f0e" title "nx 16", \
     run(48) using 1:4 every ::1 with points pt 7 ps 0.2 lc rgb "#1f77b4" title "nx 48", \
     ex using 1:4 every ::1 with lines lw 2 lc rgb "black" title "exact"
set title "viscosity switch alpha"
plot run(16) using 1:6 every ::1 with points pt 7 ps 0.2 lc rgb "#ff7f0e" title "nx 16", \
     run(48) using 1:6 every ::1 with points pt 7 ps 0.2 lc rgb "#1f77b4" title "nx 48"
unset multiplot
