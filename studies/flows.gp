# studies/flows.gp - validation plots of examples/taylor_green.c and
# examples/heat_conduction.c (make plots-flows). datadir: the CSVs of their
# --study runs; outdir: where the PNGs go.
set datafile separator ","
set grid
# the Taylor-Green plots carry six curves that fill the axes: their legend
# goes below the axes, in two columns, where it covers none of them
set terminal pngcairo size 800,680 font ",11"
set key below maxrows 3 width -2

set output outdir.'/taylor_green_energy.png'
set title "Taylor-Green vortex, Re = 100: kinetic energy (Wendland C2)"
set xlabel "t U / L"
set ylabel "E(t) / E(0)"
set logscale y
plot datadir.'/tg_48_wendland_c2_pressure_lattice_tvf.csv' every 8 using 1:3 with lines lw 2 lc rgb "black" title "exact exp(-16 pi^2 nu t)", \
     datadir.'/tg_24_wendland_c2_pressure_lattice_tvf.csv' every 4 using 1:2 with points pt 6 title "24^2 moving, transport velocity", \
     datadir.'/tg_48_wendland_c2_pressure_lattice_tvf.csv' every 8 using 1:2 with points pt 7 ps 0.6 title "48^2 moving, transport velocity", \
     datadir.'/tg_32_wendland_c2_pressure_perturbed_tvf.csv' every 6 using 1:2 with points pt 8 title "32^2 moving, perturbed start", \
     datadir.'/tg_48_wendland_c2_pressure_lattice.csv' every 8 using 1:2 with points pt 4 ps 0.6 title "48^2 fixed", \
     datadir.'/tg_32_wendland_c2_pressure_lattice_plain.csv' every 6 using 1:2 with lines lw 2 dt 2 title "32^2 moving, plain + shifting"
unset logscale y

set output outdir.'/taylor_green_l2.png'
set title "Taylor-Green vortex: relative L2 velocity error"
set ylabel "||v - v_{exact}|| / ||v_{exact}||"
set logscale y
plot datadir.'/tg_24_wendland_c2_pressure_lattice_tvf.csv' using 1:4 with lines lw 2 title "24^2 moving (transport velocity)", \
     datadir.'/tg_32_wendland_c2_pressure_lattice_tvf.csv' using 1:4 with lines lw 2 title "32^2 moving", \
     datadir.'/tg_48_wendland_c2_pressure_lattice_tvf.csv' using 1:4 with lines lw 2 title "48^2 moving", \
     datadir.'/tg_32_wendland_c2_corrected_lattice_tvf.csv' using 1:4 with lines lw 2 title "32^2 moving, corrected", \
     datadir.'/tg_48_wendland_c2_pressure_lattice.csv' using 1:4 with lines lw 2 title "48^2 fixed", \
     datadir.'/tg_32_wendland_c2_pressure_lattice_plain.csv' using 1:4 with lines lw 2 dt 2 title "32^2 moving, plain + shifting"
unset logscale y

set terminal pngcairo size 800,560 font ",11"
set key default
set output outdir.'/heat_two_layer.png'
set title "Two layers, k = 1 | 100: steady temperature (Wendland C2, mirror walls)"
set xlabel "x"
set ylabel "T"
set key bottom right
plot datadir.'/heat_two_layer_40_wendland_c2_mirror.csv' using 1:3 with lines lw 2 lc rgb "black" title "exact (flux continuity)", \
     datadir.'/heat_two_layer_20_wendland_c2_mirror.csv' using 1:2 with points pt 6 title "20 across", \
     datadir.'/heat_two_layer_40_wendland_c2_mirror.csv' using 1:2 with points pt 7 ps 0.7 title "40 across", \
     datadir.'/heat_two_layer_20_wendland_c2_fixed.csv' using 1:2 with points pt 4 title "20 across, fixed walls"

set output outdir.'/heat_single.png'
set title "Single layer, k = 1: temperature at t = 0.1 from T = 0"
set key top left
plot datadir.'/heat_single_40_wendland_c2_mirror.csv' using 1:3 with lines lw 2 lc rgb "black" title "Fourier series", \
     datadir.'/heat_single_20_wendland_c2_mirror.csv' using 1:2 with points pt 6 title "20 across", \
     datadir.'/heat_single_40_wendland_c2_mirror.csv' using 1:2 with points pt 7 ps 0.7 title "40 across", \
     datadir.'/heat_single_20_wendland_c2_fixed.csv' using 1:2 with points pt 4 title "20 across, fixed walls"
