# studies/report.gp - the plots of docs/results/report.md from the CSV files that
# studies/error_vs_runtime.c writes into dir; the PNGs go beside them.
# Run by `make report` / `make plots-report`:  gnuplot -e "dir='docs/results/report'" studies/report.gp
#   pareto_<operator>.png  L2 error against time per particle, every kernel x h x scheme of
#                          the Pareto scan, perturbed 10 % lattice, sine field; the front as a staircase
#   sweep_<A|B>_<d>d.png   L2 error of the difference and corrected gradient and the Laplacian
#                          along sweep A (against h) and sweep B (against dx/h), kernels at equal sigma h
if (!exists("dir")) dir = 'docs/results/report'

set datafile separator ","
names = "cubic Lucy new\\_quartic quintic Wendland\\_C2 Wendland\\_C4 Wendland\\_C6 quartic"
nk = words(names) # the kernels, in the order of SPH_KERNEL_LIST
arrs = "lattice perturbed10 perturbed30 surface"
set linetype 1 lc rgb "#000000" lw 2 pt 7 ps 1.3
set linetype 2 lc rgb "#e69f00" lw 2 pt 7 ps 1.3
set linetype 3 lc rgb "#56b4e9" lw 2 pt 7 ps 1.3
set linetype 4 lc rgb "#009e73" lw 2 pt 7 ps 1.3
set linetype 5 lc rgb "#d55e00" lw 2 pt 7 ps 1.3
set linetype 6 lc rgb "#cc79a7" lw 2 pt 7 ps 1.3
set linetype 7 lc rgb "#0072b2" lw 2 pt 7 ps 1.3
set linetype 8 lc rgb "#8c510a" lw 2 pt 7 ps 1.3 # brown: grey (#808080) marks the schemes in the legend
# point type per scheme (operator row id of the CSV): plain operators and
# difference = filled circle, standard = square, symmetric = triangle,
# corrected = diamond, pressure = inverted triangle
ptype(op) = op == 2 ? 5 : op == 4 ? 9 : (op == 5 || op == 8) ? 13 : op == 6 ? 11 : 7
schemes = "plain/difference standard symmetric corrected pressure"
spts = "7 5 9 13 11"

set terminal pngcairo size 1500,620 font "Sans,12"
set grid xtics ytics mxtics mytics lt 1 lw 1 lc rgb "#e0e0e0"
set logscale xy
set format y "10^{%T}"
set key outside right top Left reverse samplen 1.5 spacing 1.1

do for [g in "density interpolation gradient divergence laplacian"] {
  set output sprintf("%s/pareto_%s.png", dir, g)
  set multiplot layout 1,2 title sprintf("%s: L2 error against time per particle (perturbed 10 %%, sine field); black staircase: Pareto front", g)
  do for [dim=2:3] {
    set title sprintf("%d-D", dim)
    set xlabel "time per particle (ns)"
    set ylabel "L2 error"
    blk = (dim - 2) * 4 + 1
    if (dim == 2) { unset key } else { set key }
    # legend: colour = kernel (filled circles), shape = scheme (grey); the
    # data points themselves take their shape from the scheme (pt variable)
    plot for [k=0:nk-1] sprintf("%s/pareto_%s.csv", dir, g) \
           using (($1 == dim && strcol(2) eq "perturbed10" && $4 == k) ? $8 : 1/0):9:(ptype($7)) \
           every ::1 with points lt k+1 pt variable notitle, \
         for [k=0:nk-1] keyentry with points lt k+1 pt 7 title word(names, k+1), \
         for [s=1:words(schemes)] keyentry with points pt (word(spts, s) + 0) ps 1.3 lc rgb "#808080" title word(schemes, s), \
         sprintf("%s/pareto_front_%s.csv", dir, g) index blk using 8:9 with steps lc rgb "#000000" lw 1.5 title "front", \
         "" index blk using 8:9 with points pt 6 ps 2.2 lc rgb "#000000" notitle
  }
  unset multiplot
}

set terminal pngcairo size 1800,1150 font "Sans,12"
# each panel fits its own data (a sweep B spans well under a decade in dx/h and
# often in the error): ranges fixed at the data plus a margin, x tics at 1, 2
# and 5 of every decade, the error on a log axis when it spans a factor of 5 or
# more, otherwise on a linear one (a log axis inside one decade has no labels)
set autoscale fix
set offsets graph 0.04, graph 0.04, graph 0.08, graph 0.08
set format x "%g"
set xtics ()
do for [e=-8:3] { set xtics add (1 * 10.0**e, 2 * 10.0**e, 5 * 10.0**e) }
opname(o) = o == 0 ? "difference gradient" : o == 1 ? "corrected gradient" : "Laplacian"
do for [sw in "A B"] {
  do for [dim=2:3] {
    set output sprintf("%s/sweep_%s_%dd.png", dir, sw, dim)
    # the default run has no perturbed30 sweeps in 3-D (--full has): plot the arrangements with data
    stats sprintf("%s/sweep_%s.csv", dir, sw) index ((dim - 2) * 4 + 2) * 3 * nk using 9:10 nooutput
    na = exists("STATS_records") ? (STATS_records > 0 ? 4 : 3) : 3
    if (sw eq "A") {
      set multiplot layout 3,na title sprintf("sweep A, %d-D: h -> 0 at fixed dx/h (h = 1.3 dx for the cubic, kernels at equal sigma h), sine field", dim)
    } else {
      set multiplot layout 3,na title sprintf("sweep B, %d-D: dx/h -> 0 at fixed h, kernels at equal sigma h, sine field", dim)
    }
    do for [o=0:2] {
      do for [ai=0:na-1] {
        a = (na == 4 || ai < 2) ? ai : 3
        set title sprintf("%s, %s", opname(o), word(arrs, a+1))
        set xlabel (sw eq "A" ? "h" : "dx / h")
        set ylabel "L2 error"
        if (o == 0 && ai == na - 1) { set key } else { unset key }
        base = ((dim - 2) * 4 + a) * 3 * nk + o * nk
        stats sprintf("%s/sweep_%s.csv", dir, sw) index base:base+nk-1 using 10 nooutput
        if (STATS_min > 0 && STATS_max / STATS_min >= 5) {
          set logscale y; set format y "%g"; set ytics ()
          do for [e=-8:3] { set ytics add (1 * 10.0**e, 2 * 10.0**e, 5 * 10.0**e) }
        } else {
          unset logscale y; set format y "%.3g"; set ytics autofreq
        }
        plot for [k=0:nk-1] sprintf("%s/sweep_%s.csv", dir, sw) index base+k \
             using (sw eq "A" ? $8 : $9):10 with linespoints lt k+1 title word(names, k+1)
      }
    }
    unset multiplot
  }
}
