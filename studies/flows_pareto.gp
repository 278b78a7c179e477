# studies/flows_pareto.gp - the plots of docs/results/flows.md from the CSV files that
# studies/flows_vs_runtime.c writes into dir; the PNGs go beside them.
# Run by `make report-flows` / `make plots-report-flows`:
#   gnuplot -e "dir='docs/results/flows'" studies/flows_pareto.gp
#   pareto_gresho.png  L1 of v_phi against CPU seconds, every kernel x neighbour number x n
#   pareto_sod.png     L1 of rho, v_x and P against CPU seconds, three panels
# Colour: kernel; symbol: the neighbour rung c; a line joins the resolutions of one
# kernel and rung; the black staircase is the Pareto front.
if (!exists("dir")) dir = 'docs/results/flows'
pts = dir . '/points.csv'

set datafile separator ","
# the kernels in the order of the CSV (every kernel the study ran, however many)
kernels = system(sprintf("awk -F, 'NR > 1 && !seen[$2]++ {printf \"%%s \", $2}' %s", pts))
nk = words(kernels)
rungs = "1.0 1.3 1.6"
rpt = "7 5 9"
set linetype 1 lc rgb "#000000" lw 1.5
set linetype 2 lc rgb "#e69f00" lw 1.5
set linetype 3 lc rgb "#56b4e9" lw 1.5
set linetype 4 lc rgb "#009e73" lw 1.5
set linetype 5 lc rgb "#d55e00" lw 1.5
set linetype 6 lc rgb "#cc79a7" lw 1.5
set linetype 7 lc rgb "#0072b2" lw 1.5
set linetype 8 lc rgb "#a65628" lw 1.5
set linetype 9 lc rgb "#f0e442" lw 1.5
set linetype cycle 9

set grid xtics ytics mxtics mytics lt 1 lw 1 lc rgb "#e0e0e0"
set logscale xy
set format x "%g"
set format y "%g"
set xtics ()
set ytics ()
do for [e=-4:4] { set xtics add (1 * 10.0**e, 2 * 10.0**e, 5 * 10.0**e); set ytics add (1 * 10.0**e, 2 * 10.0**e, 3 * 10.0**e, 5 * 10.0**e) }
set xlabel "CPU seconds of the run (one thread)"
set key outside right top Left reverse samplen 1.5 spacing 1.1

do for [fl in "gresho sod"] {
  if (fl eq "gresho") {
    set terminal pngcairo size 1200,700 font "Sans,12" noenhanced
    set output dir . '/pareto_gresho.png'
    set title "Gresho-Chan vortex, 2-D: L1 of v_phi at t = 1 against CPU time (n = 32, 64, 128)"
    set ylabel "L1 v_phi"
    plot for [k=1:nk] for [c=1:3] pts using ((strcol(1) eq fl && strcol(2) eq word(kernels, k) && \
           sprintf("%.1f", $3) eq word(rungs, c) && $13 == 1) ? $9 : 1/0):10 \
           with linespoints lt k pt (word(rpt, c) + 0) ps 1.2 notitle, \
         for [k=1:nk] keyentry with points lt k pt 7 title word(kernels, k), \
         for [c=1:3] keyentry with points lc rgb "#808080" pt (word(rpt, c) + 0) title "c = " . word(rungs, c), \
         dir . '/front_gresho.csv' using 1:2 every ::1 with steps lc rgb "#000000" lw 2 title "front", \
         '' using 1:2 every ::1 with points pt 6 ps 2.2 lc rgb "#000000" notitle
  } else {
    set terminal pngcairo size 1800,650 font "Sans,12" noenhanced
    set output dir . '/pareto_sod.png'
    set multiplot layout 1,3 title "Sod shock tube, 3-D: L1 at t = 0.2 against CPU time (nx = 16, 24, 32)"
    do for [q=1:3] {
      col = 9 + q
      qn = word("rho v_x P", q)
      set title "L1 " . qn
      set ylabel "L1 " . qn
      if (q == 3) { set key } else { unset key }
      plot for [k=1:nk] for [c=1:2] pts using ((strcol(1) eq fl && strcol(2) eq word(kernels, k) && \
             sprintf("%.1f", $3) eq word(rungs, c) && $13 == 1) ? $9 : 1/0):col \
             with linespoints lt k pt (word(rpt, c) + 0) ps 1.2 notitle, \
           for [k=1:nk] keyentry with points lt k pt 7 title word(kernels, k), \
           for [c=1:2] keyentry with points lc rgb "#808080" pt (word(rpt, c) + 0) title "c = " . word(rungs, c), \
           dir . '/front_sod_' . qn . '.csv' using 1:2 every ::1 with steps lc rgb "#000000" lw 2 title "front", \
           '' using 1:2 every ::1 with points pt 6 ps 2.2 lc rgb "#000000" notitle
    }
    unset multiplot
  }
}
