#!/usr/bin/env python3
"""Exact facts about the kernels quoted in docs/kernels.md (needs sympy).

Run: python3 tools/kernel_facts.py

Independent of the header and of tools/gen_kernel_tables.py: every shape is
typed in again from its published form, and everything below is exact
integration and algebra:
  1. per kernel: alpha_d (1/int w dV), sigma/h (eq. (K5)), smoothness C^n
     (continuity of w(|x|) as a function of x, at q = 0, at every knot and at
     the support edge, where w meets the zero function);
  2. Lucy's kernel with (1-q)^3 and with the misprinted (1-q);
  3. the new quartic's factorisation, zero, minimum and rising tail.
"""
import sympy as sp

q = sp.symbols('q', nonnegative=True)
R = sp.Rational

# name, kappa, pieces [(a, b, w(q))] as published (q = r/h)
KERNELS = [
    ('cubic', 2, [(0, 1, R(2, 3) - q**2 + q**3 / 2), (1, 2, (2 - q)**3 / 6)]),
    ('lucy', 1, [(0, 1, (1 + 3 * q) * (1 - q)**3)]),
    ('new_quartic', 2, [(0, 2, R(2, 3) - R(9, 8) * q**2 + R(19, 24) * q**3 - R(5, 32) * q**4)]),
    ('quintic', 3, [(0, 1, (3 - q)**5 - 6 * (2 - q)**5 + 15 * (1 - q)**5),
                    (1, 2, (3 - q)**5 - 6 * (2 - q)**5), (2, 3, (3 - q)**5)]),
    ('wendland_c2', 2, [(0, 2, (1 - q / 2)**4 * (1 + 2 * q))]),
    ('wendland_c4', 2, [(0, 2, (1 - q / 2)**6 * (1 + 3 * q + R(35, 12) * q**2))]),
    ('wendland_c6', 2, [(0, 2, (1 - q / 2)**8 * (1 + 4 * q + R(25, 4) * q**2 + 4 * q**3))]),
    ('wendland_c2_1d', 2, [(0, 2, (1 - q / 2)**3 * (1 + R(3, 2) * q))]),
    ('wendland_c4_1d', 2, [(0, 2, (1 - q / 2)**5 * (1 + R(5, 2) * q + 2 * q**2))]),
    ('wendland_c6_1d', 2, [(0, 2, (1 - q / 2)**7 * (1 + R(7, 2) * q + R(19, 4) * q**2
                                                     + R(21, 8) * q**3))]),
    ('quartic', R(5, 2), [(0, R(1, 2), (R(5, 2) - q)**4 - 5 * (R(3, 2) - q)**4 + 10 * (R(1, 2) - q)**4),
                          (R(1, 2), R(3, 2), (R(5, 2) - q)**4 - 5 * (R(3, 2) - q)**4),
                          (R(3, 2), R(5, 2), (R(5, 2) - q)**4)]),
]
# which shape serves which dimension (2-D/3-D Wendland differ from 1-D)
DIMS = {'wendland_c2': (2, 3), 'wendland_c4': (2, 3), 'wendland_c6': (2, 3),
        'wendland_c2_1d': (1,), 'wendland_c4_1d': (1,), 'wendland_c6_1d': (1,)}
SURFACE = {1: 2, 2: 2 * sp.pi, 3: 4 * sp.pi}  # surface of the unit sphere


def moment(pieces, dim, p):
    """int |x|^p w(|x|) d^dx over the support (h = 1)."""
    return sp.simplify(SURFACE[dim] * sum(sp.integrate(w * q**(dim - 1 + p), (q, a, b))
                                          for a, b, w in pieces))


def smoothness(pieces):
    """Largest n with w(|x|) in C^n: derivatives matched at knots and edge,
    odd derivatives zero at the origin."""
    knots = [(pieces[i][2], pieces[i + 1][2], pieces[i][1]) for i in range(len(pieces) - 1)]
    knots.append((pieces[-1][2], sp.Integer(0), pieces[-1][1]))
    n = 0
    while n < 12:
        m = n + 1
        d0 = sp.diff(pieces[0][2], q, m).subs(q, 0)
        if m % 2 == 1 and d0 != 0:
            break
        if any(sp.simplify(sp.diff(l, q, m).subs(q, x) - sp.diff(r, q, m).subs(q, x)) != 0
               for l, r, x in knots):
            break
        n = m
    return n


def main():
    print('1. Normalisation alpha_d = 1 / int w dV, sigma/h (eq. (K5)), smoothness\n')
    for name, kappa, pieces in KERNELS:
        dims = DIMS.get(name, (1, 2, 3))
        print('%s: kappa = %s, C^%d' % (name, kappa, smoothness(pieces)))
        for a, b, w in pieces:
            print('    w = %s  on [%s, %s)' % (sp.factor(w), a, b))
        for d in dims:
            m0 = moment(pieces, d, 0)
            alpha = sp.nsimplify(1 / m0, [sp.pi])
            sigma = sp.sqrt(sp.nsimplify(moment(pieces, d, 2) * alpha / d))
            print('    %d-D: alpha = %-14s = %.17g   sigma/h = %-18s = %.17g'
                  % (d, alpha, float(alpha), sp.simplify(sigma), float(sigma)))
    print()

    print("2. Lucy: published (1+3q)(1-q)^3 against the slide's (1+3q)(1-q)\n")
    listed = {1: R(5, 4), 2: 5 / sp.pi, 3: 105 / (16 * sp.pi)}
    for label, w in (('(1+3q)(1-q)^3', (1 + 3 * q) * (1 - q)**3), ('(1+3q)(1-q)', (1 + 3 * q) * (1 - q))):
        for d in (1, 2, 3):
            m0 = moment([(0, 1, w)], d, 0)
            print("    %-14s %d-D: int w dV = %-10s  alpha needed = %-12s  listed alpha x int = %s"
                  % (label, d, m0, sp.simplify(1 / m0), sp.simplify(listed[d] * m0)))
        print("    %-14s w(1) = %s, w'(1) = %s, w''(1) = %s" % (
            label, w.subs(q, 1), sp.diff(w, q).subs(q, 1), sp.diff(w, q, 2).subs(q, 1)))
    print()

    print('3. New quartic near the support edge\n')
    w = KERNELS[2][2][0][2]
    print('    w = %s = (2-q)^2 (1/6 + q/6 - 5q^2/32): %s' % (
        sp.factor(w), sp.expand((2 - q)**2 * (R(1, 6) + q / 6 - R(5, 32) * q**2) - w) == 0))
    zeros = sorted(sp.solve(w, q), key=float)
    print('    zeros of w: %s = %s' % (zeros, [float(z) for z in zeros]))
    crit = sorted(sp.solve(sp.diff(w, q), q), key=float)
    print("    zeros of w': %s" % crit)
    qm = R(9, 5)
    print('    minimum on (0, 2): w(%s) = %s = %.10g, w(%s)/w(0) = %s' % (
        qm, w.subs(q, qm), float(w.subs(q, qm)), qm, w.subs(q, qm) / w.subs(q, 0)))
    print("    w'(1.9) = %s > 0: w rises on (9/5, 2)" % sp.diff(w, q).subs(q, R(19, 10)))
    print("    w''(2) = %s (so W'' jumps at the support edge)" % sp.diff(w, q, 2).subs(q, 2))
    for d in (1, 2, 3):
        alpha = 1 / moment([(0, 2, w)], d, 0)
        neg = sp.simplify(alpha * SURFACE[d] * sp.integrate(w * q**(d - 1), (q, zeros[-2], 2)))
        print('    %d-D: mass in the negative tail int_{w<0} W dV = %.6g' % (d, float(neg)))


if __name__ == '__main__':
    main()
