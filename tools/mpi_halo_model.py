#!/usr/bin/env python3
"""Halo fraction and exchange cost of a domain-decomposed SPH run (docs/mpi.md,
"What the halo costs at scale"): N particles on a cubic lattice (n = N^(1/3)
per side), P ranks, search radius R = w dx (w = kappa h / dx layers).

  slabs: halo per rank H = 2 w n^2 (valid while a slab is w layers thick: P <= n / w),
         fraction 2 w P / n; 2 messages per exchange
  cubes: P = p^3 cubes of m = n / p layers, H = (m + 2 w)^3 - m^3,
         fraction (1 + 2 w / m)^3 - 1 (about 6 w P^(1/3) / n); 26 messages
  exchange time t_ex = k alpha + H B / beta (k messages of latency alpha, H B bytes at beta)
  compute time  t_c  = (N / P) c / T (c: seconds per particle and step on one core, T cores per rank)

Every parameter is an option; the defaults are the assumptions the page states.
Prints a Markdown table."""
import argparse


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--w", type=float, default=2.6, help="search radius in lattice spacings, kappa h / dx (2.6: Wendland C2, h = 1.3 dx)")
    ap.add_argument("--bytes", type=float, default=104, help="bytes per halo particle per step (B)")
    ap.add_argument("--alpha", type=float, default=2e-6, help="message latency, s")
    ap.add_argument("--beta", type=float, default=10e9, help="bandwidth per rank, bytes/s")
    ap.add_argument("--c", type=float, default=3e-6, help="compute per particle and step on one core, s")
    ap.add_argument("--cores", type=int, default=32, help="cores (OpenMP threads) per rank")
    a = ap.parse_args()
    rows = [(1e6, 8), (1e6, 64), (1e7, 64), (1e8, 64), (1e8, 512), (1e9, 512), (1e9, 4096)]
    print("| particles N | ranks P | slabs: halo / locals | cubes: halo / locals | cubes: halo per rank "
          "| message per rank and step | exchange t_ex | compute t_c | t_ex / t_c |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for N, P in rows:
        n = N ** (1 / 3)
        slab = "%.1f %%" % (100 * 2 * a.w * P / n) if n / P >= a.w else "- (P > n / w = %d)" % int(n / a.w)
        m = n / round(P ** (1 / 3))
        H = (m + 2 * a.w) ** 3 - m ** 3
        t_ex = 26 * a.alpha + H * a.bytes / a.beta
        t_c = N / P * a.c / a.cores
        print("| %.0e | %d | %s | %.1f %% | %.3g | %.3g MB | %.3g ms | %.3g ms | %.2f |"
              % (N, P, slab, 100 * H / m ** 3, H, H * a.bytes / 1e6, 1e3 * t_ex, 1e3 * t_c, t_ex / t_c))
    print()
    print("w = %g, B = %g bytes, alpha = %g s, beta = %g bytes/s, c = %g s, %d cores per rank"
          % (a.w, a.bytes, a.alpha, a.beta, a.c, a.cores))


if __name__ == "__main__":
    main()
