#!/usr/bin/env python3
"""Generate the per-kernel coefficient tables of sph_kernel.h (section 2).

Run: python3 tools/gen_kernel_tables.py > /tmp/tables.h   (needs sympy)
and paste the output between the GENERATED markers of sph_kernel.h.

Every shape w(q) (support [0, kappa)) is cut into pieces of width 1/2. On
each piece it is written as three exact polynomials in the local variable
u = q - c (c = the piece's expansion point):
  w(q), w'(q) (divided by q at run time) or, on the piece that holds q = 0,
  w'(q)/q expanded so that no division happens there, and w''(q).
c = 0 on the innermost piece, c = kappa on the outermost (so w = t^m P(t),
t = kappa - q, keeps its sign and relative accuracy up to the edge), and for
the middle pieces the end point or mid point with the smallest cancellation
ratio sum|c_i u^i| / |sum c_i u^i|. All coefficients are exact rationals.
Normalisation constants alpha_d are computed by exact integration.

A second representation (sph__nshapes, used by the operator pair loops, which
evaluate every piece and select by comparisons) keeps the NATURAL pieces
(cubic 2, quintic 3, the others 1), each in product form
  value = (b - q)^m P(q - e),
b = the piece's right end, m = the multiplicity of the root q = b (so the
value keeps its sign and relative accuracy up to the edge), P expanded about
the end or mid point e with the smallest cancellation ratio (e = 0 favoured on
the piece holding 0, so w(0) is exact). For F the piece
holding q = 0 stores w'(q)/q (q divided out exactly), the others w'(q).
"""
import sympy as sp

q, u, r = sp.symbols('q u r')
R = sp.Rational
WIDTH = R(1, 2)

# name, C identifier, pieces [(a, b, w(q))], kappa, dims, literature
SHAPES = [
    ('cubic spline (M4), Monaghan & Lattanzio 1985', 'cubic',
     [(0, 1, R(2, 3) - q**2 + q**3 / 2), (1, 2, (2 - q)**3 / 6)], 2, (1, 2, 3)),
    ('Lucy quartic, Lucy 1977', 'lucy',
     [(0, 1, (1 + 3 * q) * (1 - q)**3)], 1, (1, 2, 3)),
    ('new quartic, Liu & Liu 2003', 'new_quartic',
     [(0, 2, R(2, 3) - R(9, 8) * q**2 + R(19, 24) * q**3 - R(5, 32) * q**4)], 2, (1, 2, 3)),
    ('quintic spline (M6), Morris 1996', 'quintic',
     [(0, 1, (3 - q)**5 - 6 * (2 - q)**5 + 15 * (1 - q)**5),
      (1, 2, (3 - q)**5 - 6 * (2 - q)**5), (2, 3, (3 - q)**5)], 3, (1, 2, 3)),
    ('Wendland C2 (2-D/3-D), Wendland 1995', 'wendland_c2',
     [(0, 2, (1 - q / 2)**4 * (1 + 2 * q))], 2, (2, 3)),
    ('Wendland C4 (2-D/3-D), Wendland 1995', 'wendland_c4',
     [(0, 2, (1 - q / 2)**6 * (1 + 3 * q + R(35, 12) * q**2))], 2, (2, 3)),
    ('Wendland C6 (2-D/3-D), Wendland 1995', 'wendland_c6',
     [(0, 2, (1 - q / 2)**8 * (1 + 4 * q + R(25, 4) * q**2 + 4 * q**3))], 2, (2, 3)),
    ('Wendland C2 (1-D), Wendland 1995', 'wendland_c2_1d',
     [(0, 2, (1 - q / 2)**3 * (1 + R(3, 2) * q))], 2, (1,)),
    ('Wendland C4 (1-D), Wendland 1995', 'wendland_c4_1d',
     [(0, 2, (1 - q / 2)**5 * (1 + R(5, 2) * q + 2 * q**2))], 2, (1,)),
    ('Wendland C6 (1-D), Wendland 1995', 'wendland_c6_1d',
     [(0, 2, (1 - q / 2)**7 * (1 + R(7, 2) * q + R(19, 4) * q**2 + R(21, 8) * q**3))], 2, (1,)),
]


def piece_at(pieces, x):
    for a, b, p in pieces:
        if a <= x < b:
            return p
    raise ValueError(x)


def polys(p, c, inner):
    w = sp.expand(p.subs(q, u + c))
    d1 = sp.cancel(sp.diff(p, q) / q) if inner else sp.diff(p, q)
    g = sp.expand(d1.subs(q, u + c))
    d2 = sp.expand(sp.diff(p, q, 2).subs(q, u + c))
    return [sp.Poly(x, u).all_coeffs()[::-1] for x in (w, g, d2)]


def cond(coeffs, a, b, c):
    worst = 0.0
    vals = []
    for j in range(201):
        x = float(a) + (float(b) - float(a)) * j / 200
        uu = x - float(c)
        v = sum(float(ci) * uu**i for i, ci in enumerate(coeffs))
        s = sum(abs(float(ci) * uu**i) for i, ci in enumerate(coeffs))
        vals.append((v, s))
    mx = max(abs(v) for v, _ in vals)
    for v, s in vals:
        if abs(v) > 0.02 * mx:
            worst = max(worst, s / abs(v))
    return worst


def cfrac(x):
    x = sp.Rational(x)
    if x == 0:
        return '0'
    if x.q == 1:
        return 'SPH__Q(%d, 1)' % x.p
    return 'SPH__Q(%d, %d)' % (x.p, x.q)


def shape_table(pieces, kappa):
    n = int(sp.Rational(kappa) / WIDTH)
    rows = []
    for k in range(n):
        a, b = WIDTH * k, WIDTH * (k + 1)
        p = piece_at(pieces, a)
        if a == 0:
            cands = [0]
        elif b == kappa:
            cands = [sp.Rational(kappa)]
        else:
            cands = [b, a, (a + b) / 2]
        best = None
        for c in cands:
            cs = polys(p, c, a == 0)
            score = max(cond(cs[0], a, b, c), cond(cs[1], a, b, c))
            if best is None or score < best[0] - 1e-9:
                best = (score, c, cs)
        rows.append((a, b, best[1], a == 0, best[2]))
    deg = max(len(x) for row in rows for x in row[4]) - 1
    return rows, deg


NPMAX = 6  # coefficients per product-form polynomial (quintic: degree 5)


def product_form(expr, a, b, root):
    """expr = (root - q)^m P(q - e) on [a, b): returns m, e, coefficients of P."""
    m, rest = 0, sp.expand(expr)
    while rest != 0 and rest.subs(q, root) == 0:
        rest = sp.cancel(rest / (root - q))
        m += 1
    best = None
    for e in (a, b, (a + b) / 2):
        cs = sp.Poly(sp.expand(rest.subs(q, u + e)), u).all_coeffs()[::-1]
        score = cond(cs, a, b, e) if any(c != 0 for c in cs[1:]) else 1.0
        if a == 0 and e == 0:
            score /= 4  # favoured: w(0) is then b^m P(0), exact, as in the table rows
        if best is None or score < best[0] - 1e-9:
            best = (score, e, cs)
    assert len(best[2]) <= NPMAX
    return m, best[1], best[2]


# The new quartic is one polynomial, but (2 - q)^2 P(q - e) cannot be both
# exact at q = 0 (e = 0: the self term equals that of the table rows) and
# accurate in its small negative lobe near q = 2 (e = 2): split at 1.
SPLIT = {'new_quartic': [(0, 1), (1, 2)]}  # the root q = b stays that of the whole piece


def natural_table(ident, pieces):
    whole = [(sp.Rational(a), sp.Rational(b), sp.Rational(b), p) for a, b, p in pieces]
    if ident in SPLIT:
        whole = [(sp.Rational(a), sp.Rational(b), sp.Rational(pieces[0][1]), piece_at(pieces, a))
                 for a, b in SPLIT[ident]]
    rows = []
    for a, b, root, p in whole:
        g = sp.diff(p, q)
        if a == 0:
            g = sp.cancel(g / q)
        rows.append((a, root, product_form(p, a, b, root), product_form(g, a, b, root)))
    return rows


def pform(b, form):
    m, e, cs = form
    vals = [cfrac(x) for x in cs] + ['0'] * (NPMAX - len(cs))
    return '{ %s, %s, %d, %d, { %s } }' % (cfrac(b), cfrac(e), m, len(cs) - 1, ', '.join(vals))


def alpha(pieces, d):
    vol = {1: 2, 2: 2 * sp.pi * r, 3: 4 * sp.pi * r**2}[d]
    tot = sum(sp.integrate(p.subs(q, r) * vol, (r, a, b)) for a, b, p in pieces)
    m2 = sum(sp.integrate(p.subs(q, r) * r**2 * vol, (r, a, b)) for a, b, p in pieces)
    return sp.nsimplify(1 / tot), sp.sqrt(sp.simplify(m2 / tot / d))


KERNELS = [  # enum order of sph_kernel: shape per dimension 1, 2, 3
    ('cubic', ('cubic', 'cubic', 'cubic')),
    ('lucy', ('lucy', 'lucy', 'lucy')),
    ('new_quartic', ('new_quartic', 'new_quartic', 'new_quartic')),
    ('quintic', ('quintic', 'quintic', 'quintic')),
    ('wendland_c2', ('wendland_c2_1d', 'wendland_c2', 'wendland_c2')),
    ('wendland_c4', ('wendland_c4_1d', 'wendland_c4', 'wendland_c4')),
    ('wendland_c6', ('wendland_c6_1d', 'wendland_c6', 'wendland_c6')),
]


def main():
    out = []
    meta = {}
    off = 0
    out.append('/* ---- GENERATED by tools/gen_kernel_tables.py: do not edit by hand ---- */')
    out.append('/* Per piece [a, b): c, den0, den1, then w, g, w2 as deg+1 coefficients each')
    out.append('   (lowest power first) in u = q - c; F = alpha h^-(d+2) g(u) / (den0 + den1 q),')
    out.append('   W = alpha h^-d w(u), d2W/dr2 = alpha h^-(d+2) w2(u). The last row of each')
    out.append('   shape is the zero row used for q >= kappa (and for NaN q).            */')
    out.append('SPH__TABLE sph_real sph__coef[] = {')
    for title, ident, pieces, kappa, dims in SHAPES:
        rows, deg = shape_table(pieces, kappa)
        stride = 3 + 3 * (deg + 1)
        out.append('    /* %s, kappa = %s, degree %d */' % (title, kappa, deg))
        for a, b, p in pieces:
            out.append('    /*   w = %s  on [%s, %s) */' % (sp.sstr(sp.factor(p)), a, b))
        for a, b, c, inner, cs in rows:
            head = [cfrac(c), '1' if inner else '0', '0' if inner else '1']
            out.append('    /* [%s, %s) c = %s */ %s,' % (a, b, c, ', '.join(head)))
            for lab, poly in zip(('w  ', 'g  ', 'w2 '), cs):
                vals = [cfrac(x) for x in poly] + ['0'] * (deg + 1 - len(poly))
                out.append('        /* %s */ %s,' % (lab, ', '.join(vals)))
        out.append('    /* zero row */ 0, 1, 0, ' + ', '.join(['0'] * (3 * (deg + 1))) + ',')
        meta[ident] = (kappa, len(rows), deg, off, {d: alpha(pieces, d) for d in dims})
        off += stride * (len(rows) + 1)
    out[-1] = out[-1].rstrip(',')
    out.append('};')
    out.append('')
    out.append('SPH__TABLE sph__shape sph__shapes[] = {')
    out.append('    /* kappa, 1/width, pieces, degree, offset into sph__coef */')
    names = [x[1] for x in SHAPES]
    for i, ident in enumerate(names):
        kappa, n, deg, o, al = meta[ident]
        out.append('    { SPH__Q(%s, 1), SPH__Q(%d, 1), %d, %d, %d }%s /* %d %s */'
                   % (kappa, int(1 / WIDTH), n, deg, o, ',' if i + 1 < len(names) else ' ', i, ident))
    out.append('};')
    out.append('')
    out.append('/* Per kernel and dimension 1..3: shape index, alpha_d (exact integration of')
    out.append('   the shape, correctly rounded) and sigma_d / h, sigma_d^2 = int |x|^2 W d^dx / d. */')
    out.append('SPH__TABLE sph__kdim sph__kdims[SPH_KERNEL_COUNT][3] = {')
    for ki, (kname, sh) in enumerate(KERNELS):
        cells = []
        for d in (1, 2, 3):
            kappa, n, deg, o, al = meta[sh[d - 1]]
            a, s = al[d]
            cells.append('        { %d, SPH__C(%s), SPH__C(%s) }%s /* %dD: alpha = %s, sigma/h = %s */'
                         % (names.index(sh[d - 1]), sp.N(a, 21), sp.N(s, 21), ',' if d < 3 else ' ',
                            d, sp.sstr(a), sp.sstr(s)))
        out.append('    { /* %s */' % kname)
        out += cells
        out.append('    }%s' % (',' if ki + 1 < len(KERNELS) else ''))
    out.append('};')
    out.append('')
    out.append('/* The natural pieces in product form, per shape (same order as sph__shapes):')
    out.append('   pieces, kappa, left ends, then per piece the forms of w and g,')
    out.append('   { b, e, m, degree, P } means (b - q)^m P(q - e); W = w, F from g, where g')
    out.append('   is w\'(q)/q on the piece holding 0 and w\'(q) (to divide by q) elsewhere. */')
    out.append('SPH__TABLE sph__nshape sph__nshapes[] = {')
    for i, (title, ident, pieces, kappa, dims) in enumerate(SHAPES):
        rows = natural_table(ident, pieces)
        lo = [cfrac(a) for a, _, _, _ in rows] + ['0'] * (3 - len(rows))
        out.append('    { %d, SPH__Q(%s, 1), { %s }, { /* %s */' % (len(rows), kappa, ', '.join(lo), ident))
        for a, b, fw, fg in rows:
            out.append('        { %s,' % pform(b, fw))
            out.append('          %s },' % pform(b, fg))
        out[-1] = out[-1].rstrip(',')
        out.append('    } }%s' % (',' if i + 1 < len(SHAPES) else ''))
    out.append('};')
    out.append('/* ---- end of GENERATED tables ---- */')
    print('\n'.join(out))


if __name__ == '__main__':
    main()
