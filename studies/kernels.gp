# kernels.gp - W, dW/dr and d2W/dr2 of every kernel in 2-D and 3-D, at equal h
# and at equal standard deviation (docs/kernels.md, "Plots").
# Run by `make plots`:  gnuplot -e "datadir='build/plots'; outdir='docs/results/plots'" studies/kernels.gp
# Data: studies/kernel_plots.c (columns: r, then W dW/dr d2W/dr2 per kernel).
if (!exists("datadir")) datadir = 'build/plots'
if (!exists("outdir")) outdir = 'docs/results/plots'

names = "cubic Lucy new\\_quartic quintic Wendland\\_C2 Wendland\\_C4 Wendland\\_C6 quartic"
nk = words(names) # the kernels, in the order of SPH_KERNEL_LIST
set linetype 1 lc rgb "#000000" lw 2.5 dt 1
set linetype 2 lc rgb "#e69f00" lw 2.5 dt 2
set linetype 3 lc rgb "#56b4e9" lw 2.5 dt 4
set linetype 4 lc rgb "#009e73" lw 2.5 dt 5
set linetype 5 lc rgb "#d55e00" lw 2.5 dt 1
set linetype 6 lc rgb "#cc79a7" lw 2.5 dt 1
set linetype 7 lc rgb "#0072b2" lw 2.5 dt 1
set linetype 8 lc rgb "#8c510a" lw 2.5 dt 3 # the colour report.gp gives the quartic

set terminal pngcairo size 1800,560 font "Sans,13"
set grid xtics ytics lt 1 lw 1 lc rgb "#d8d8d8"
set xzeroaxis lt -1 lw 1.2 lc rgb "#555555"
set xrange [0:3]
set xlabel "r"

ylabels = "W dW/dr d^2W/dr^2"
do for [dim in "2 3"] {
  do for [mode in "equal_h equal_sigma"] {
    file = sprintf("%s/kernels_%sd_%s.dat", datadir, dim, mode)
    set output sprintf("%s/kernels_%sd_%s.png", outdir, dim, mode)
    if (mode eq "equal_h") {
      what = "all kernels at h = 1 (support: Lucy 1 h, quartic 2.5 h, quintic 3 h, the others 2 h)"
    } else {
      what = "equal standard deviation: h = sigma_{cubic} / sigma_k (the cubic at h = 1)"
    }
    set multiplot layout 1,3 title sprintf("%s-D kernels, %s", dim, what) font "Sans,15"
    do for [p = 1:3] {
      set ylabel word(ylabels, p)
      if (p == 1) { set key top right box opaque } else { unset key }
      plot for [k = 1:nk] file u 1:(column(1 + 3*(k-1) + p)) w l lt k title word(names, k)
    }
    unset multiplot
    set output
  }
}

# The new quartic near the support edge: w(q) < 0 on ((8 + 2 sqrt 76)/15, 2).
set terminal pngcairo size 1200,480 font "Sans,13"
set output sprintf("%s/new_quartic_tail.png", outdir)
set multiplot layout 1,2 title "new quartic (Liu and Liu 2003) near q = 2: dimensionless w(q) and w'(q)" font "Sans,15"
set xrange [1.5:2]
set xlabel "q = r/h"
q0 = (8 + 2*sqrt(76))/15
file = sprintf("%s/new_quartic_tail.dat", datadir)
set arrow 1 from q0, graph 0 to q0, graph 1 nohead dt 3 lc rgb "#888888"
unset key
set ylabel "w(q)"
qm = 1.8
wm = -19.0/12000
set label 1 sprintf("w = 0 at q = %.4f", q0) at q0 + 0.01, graph 0.9
set label 2 sprintf("minimum w(1.8)\n= -19/12000\n= %.6f", wm) at 1.76, graph 0.45
set label 4 "" at qm, wm point pt 7 ps 1.2
set arrow 2 from qm, graph 0 to qm, graph 1 nohead dt 3 lc rgb "#888888"
plot file u 1:2 w l lw 2.5 lc rgb "#56b4e9"
unset label 1
unset label 2
unset label 4
set ylabel "w'(q)"
set label 3 "w' > 0 on (1.8, 2):" at 1.72, graph 0.42
set label 5 "w rises back to 0" at 1.72, graph 0.34
plot file u 1:3 w l lw 2.5 lc rgb "#56b4e9"
unset multiplot
set output
