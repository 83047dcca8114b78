#!/usr/bin/env python3
"""Derive the constants and polynomial coefficients of `shader-core/src/math.rs`.

Usage:
    python3 shader-core/tools/fit_math.py            # print the generated Rust block
    python3 shader-core/tools/fit_math.py --write    # replace the block in src/math.rs

Requires only `mpmath` (pip install mpmath). Takes about a minute.

Method: every approximation is written as `known(v) + mult(v) * P(v)` where P is a polynomial
with f32 coefficients. P is a weighted minimax fit (Remez exchange on a dense Chebyshev grid,
40-digit arithmetic) of g = (f - known) / mult with weight w = mult / f, so the quantity that is
levelled is the *relative* error of the final function. The coefficients are then rounded to f32
one at a time, lowest order first, re-running the Remez fit of the remaining free coefficients
after each rounding so that the free ones compensate (see `fit`). The printed
"rel err" is the max relative error of the f32-coefficient polynomial evaluated exactly; the
f32 evaluation in Rust adds its own rounding, which `tests/math_accuracy.rs` measures.

Cody-Waite constants: pi/2 is split into six 8-bit pieces (k * piece is exact for |k| < 2^16)
and a 24-bit tail; ln 2 into a 16-bit head (exact for |k| < 2^8) and a 24-bit tail.
"""
import math
import re
import struct
import sys
from pathlib import Path

import mpmath as mp

mp.mp.dps = 40


def f32(x):
    """Round to the nearest f32 (through a double: exact for every value used here)."""
    return struct.unpack('f', struct.pack('f', float(mp.mpf(x))))[0]


def f32_exact(x):
    """Round an mpf to f32 directly (no double rounding) - used for split constants."""
    x = mp.mpf(x)
    if x == 0:
        return 0.0
    e = int(mp.floor(mp.log(abs(x), 2)))
    scale = mp.mpf(2) ** (23 - e)
    return float(mp.nint(x * scale) / scale)


# core::f32::consts that some constants coincide with (clippy's approx_constant wants the name).
STD_CONSTS = {
    'PI': mp.pi, 'FRAC_PI_2': mp.pi / 2, 'FRAC_PI_4': mp.pi / 4, 'FRAC_2_PI': 2 / mp.pi,
    'LN_2': mp.log(2), 'LOG2_E': 1 / mp.log(2), 'FRAC_2_SQRT_PI': 2 / mp.sqrt(mp.pi),
}


def f32_literal(v):
    """The core::f32::consts name of v if it is one, else the shortest decimal that parses back
    to the f32 v (keeps clippy's excessive_precision and approx_constant quiet)."""
    for name, c in STD_CONSTS.items():
        if f32_exact(c) == v:
            return f'core::f32::consts::{name}'
    for digits in range(1, 10):
        text = '%.*g' % (digits, v)
        if f32(float(text)) == v:
            break
    if 'e' in text:
        mant, exp = text.split('e')
        if '.' not in mant:
            mant += '.0'
        return f'{mant}e{int(exp)}'
    return text if '.' in text else text + '.0'


def round_bits(x, nbits):
    """Round an mpf to `nbits` significant bits (nearest)."""
    x = mp.mpf(x)
    e = int(mp.floor(mp.log(abs(x), 2)))
    scale = mp.mpf(2) ** (nbits - 1 - e)
    return mp.nint(x * scale) / scale


def remez(g, w, a, b, n, fixed=None, iters=60, grid=2000):
    """Weighted minimax: coefficients c (len n) minimizing max |w(v) (sum c_j v^j - g(v))| on
    [a, b]; `fixed` maps index -> value for coefficients that are held. Returns (coef, max_err)."""
    fixed = dict(fixed or {})
    free = [j for j in range(n) if j not in fixed]
    m = len(free)
    a = mp.mpf(a)
    b = mp.mpf(b)
    pts = [a + (b - a) * (1 - mp.cos(mp.pi * i / (grid - 1))) / 2 for i in range(grid)]
    gv = [g(v) for v in pts]
    wv = [w(v) for v in pts]
    if m == 0:  # everything fixed: just measure the error
        err = []
        for i in range(grid):
            s = mp.mpf(0)
            for j in reversed(range(n)):
                s = s * pts[i] + fixed[j]
            err.append(abs(float(wv[i] * (s - gv[i]))))
        return [mp.mpf(fixed[j]) for j in range(n)], max(err)
    idx = [int(round((grid - 1) * (1 - math.cos(math.pi * i / m)) / 2)) for i in range(m + 1)]
    coef, maxerr = None, None
    for _ in range(iters):
        A = mp.matrix(m + 1, m + 1)
        rhs = mp.matrix(m + 1, 1)
        for r, i in enumerate(idx):
            p = pts[i]
            for c, j in enumerate(free):
                A[r, c] = p ** j
            A[r, m] = (-1) ** r / wv[i]
            rhs[r] = gv[i] - sum(fixed[j] * p ** j for j in fixed)
        sol = mp.lu_solve(A, rhs)
        coef = [None] * n
        for j in fixed:
            coef[j] = mp.mpf(fixed[j])
        for c, j in enumerate(free):
            coef[j] = sol[c]
        err = []
        for i in range(grid):
            p = pts[i]
            s = mp.mpf(0)
            for j in reversed(range(n)):
                s = s * p + coef[j]
            err.append(float(wv[i] * (s - gv[i])))
        segs = []
        start = 0
        for i in range(1, grid + 1):
            if i == grid or (err[i] >= 0) != (err[start] >= 0):
                segs.append(max(range(start, i), key=lambda t: abs(err[t])))
                start = i
        while len(segs) > m + 1:
            if abs(err[segs[0]]) < abs(err[segs[-1]]):
                segs.pop(0)
            else:
                segs.pop()
        maxerr = max(abs(e) for e in err)
        if len(segs) == m + 1:
            idx = segs
        lev = min(abs(err[k]) for k in idx)
        if maxerr - lev < 1e-4 * maxerr:
            break
    return coef, maxerr


def fit(g, w, a, b, n, c0_split=False):
    """Remez fit, then round the coefficients to f32 one at a time, refitting the still-free ones
    after each rounding so they compensate. Three orders are tried and the best result kept:
    lowest order first (best when the interval starts at 0 and c0 dominates the rounding error),
    highest order first (the free basis stays {1, v, ..., v^k}, a Haar system, which keeps the
    exchange well posed on intervals around 0), and plain rounding of the free fit.
    With `c0_split` the constant term is kept as an f32 hi + lo pair (treated as exact).
    Returns (coefficients, c0_lo or None, max weighted error)."""
    free, _ = remez(g, w, a, b, n)
    candidates = [list(free)]
    for order in (list(range(n)), list(reversed(range(1, n)))):
        fixed = {}
        for j in order:
            if j == 0 and c0_split:
                continue
            coef, _ = remez(g, w, a, b, n, fixed)
            fixed[j] = mp.mpf(f32(coef[j]))
        coef, _ = remez(g, w, a, b, n, fixed)
        candidates.append(coef)
    best = None
    for cand in candidates:
        full = {j: mp.mpf(f32(cand[j])) for j in range(1, n)}
        hi = mp.mpf(f32_exact(cand[0]))
        lo = mp.mpf(f32_exact(cand[0] - hi)) if c0_split else None
        full[0] = hi + lo if c0_split else hi
        _, err = remez(g, w, a, b, n, full, grid=6000)
        if best is None or err < best[2]:
            best = ([float(hi)] + [float(full[j]) for j in range(1, n)],
                    float(lo) if c0_split else None, err)
    return best


TINY = mp.mpf('1e-30')


def sq(z):
    return mp.sqrt(max(mp.mpf(z), TINY))


def nz(v):
    v = mp.mpf(v)
    return v if abs(v) > TINY else TINY


OUT = []


def const(name, value, comment=''):
    v = float(value)
    assert f32(v) == v, (name, v)
    lit = f32_literal(v)
    OUT.append(f'const {name}: f32 = {lit};' + (f' // {comment}' if comment else ''))


def poly(prefix, g, w, a, b, n, what, c0_split=False):
    coef, lo, err = fit(g, w, a, b, n, c0_split)
    OUT.append('')
    OUT.append(f'// {what}: rel err {err:.3e} (2^{math.log2(err):.1f}) on [{float(a):.6g}, {float(b):.6g}]')
    for j, c in enumerate(coef):
        const(f'{prefix}{j}', c)
    if lo is not None:
        const(f'{prefix}0_LO', lo, f'{prefix}0 + {prefix}0_LO is the constant term')
    print(f'{prefix}: n={n} rel err 2^{math.log2(err):.2f}', file=sys.stderr)


def main():
    pi = mp.pi
    OUT.append('// ---- Cody-Waite splits ----')
    # pi/2 = C1 + ... + C6 (8 significant bits each) + C7 (24 bits); remainder < 2^-70.
    rem = pi / 2
    for i in range(1, 7):
        c = round_bits(rem, 8)
        const(f'PIO2_C{i}', c, '8 significant bits')
        rem = rem - c
    c7 = f32_exact(rem)
    const('PIO2_C7', c7, f'remainder after C7: {float(rem - c7):.3e}')
    # short split for |x| < 8 (|k| <= 5, 3 bits): two 21-bit pieces (k * piece exact) + 24-bit tail
    s1 = round_bits(pi / 2, 21)
    s2 = round_bits(pi / 2 - s1, 21)
    s3 = f32_exact(pi / 2 - s1 - s2)
    const('PIO2_S1', s1, '21 significant bits: k * S1 exact for |k| < 8')
    const('PIO2_S2', s2, '21 significant bits')
    const('PIO2_S3', s3, f'remainder after S3: {float(pi / 2 - s1 - s2 - s3):.3e}')
    const('FRAC_2_PI', f32_exact(2 / pi))
    # pi/2, pi, pi/4 as hi + lo (24 + 24 bits).
    for name, v in (('PIO2', pi / 2), ('PI', pi), ('PIO4', pi / 4)):
        hi = f32_exact(v)
        const(f'{name}_HI', hi)
        const(f'{name}_LO', f32_exact(v - hi))
    ln2 = mp.log(2)
    l1 = round_bits(ln2, 16)
    const('LN2_C1', l1, '16 significant bits: k * C1 exact for |k| < 256')
    const('LN2_C2', f32_exact(ln2 - l1))
    hi = f32_exact(ln2)
    const('LN2_HI', hi)
    const('LN2_LO', f32_exact(ln2 - hi))
    const('LOG2_E', f32_exact(1 / ln2))
    hi = f32_exact(1 / ln2)
    const('INV_LN2_HI', hi)
    const('INV_LN2_LO', f32_exact(1 / ln2 - hi))
    hi = f32_exact(2 / mp.sqrt(pi))
    const('FRAC_2_SQRTPI', hi)
    const('FRAC_2_SQRTPI_LO', f32_exact(2 / mp.sqrt(pi) - hi))
    # Bits 1..224 after the binary point of 2/pi, for the Payne-Hanek reduction of huge arguments.
    with mp.workdps(120):
        bits = int(mp.floor((2 / mp.pi) * mp.mpf(2) ** 224))
    for j in range(7):
        word = (bits >> (32 * (6 - j))) & 0xFFFFFFFF
        OUT.append(f'const TWO_OVER_PI_W{j}: u32 = 0x{word >> 16:04x}_{word & 0xFFFF:04x}; // bits {32 * j + 1}..{32 * j + 32}')

    OUT.append('')
    OUT.append('// ---- polynomials (generated) ----')
    R = mp.mpf('0.8')  # |r| after pi/2 reduction, pi/4 plus the rounding slack of k
    poly('SIN_S', lambda z: (mp.sin(sq(z)) - sq(z)) / sq(z) ** 3,
         lambda z: sq(z) ** 3 / mp.sin(sq(z)), 0, R * R, 4,
         'sin(r) = r + r^3 S(r^2)')
    poly('COS_C', lambda z: (mp.cos(sq(z)) - 1 + z / 2) / z ** 2,
         lambda z: z ** 2 / mp.cos(sq(z)), R * R * 1e-6, R * R, 3,
         'cos(r) = 1 - r^2/2 + r^4 C(r^2)')
    E = mp.mpf('0.34675')  # ln2/2 plus slack
    poly('EXP_E', lambda r: (mp.expm1(nz(r)) - nz(r)) / nz(r) ** 2,
         lambda r: nz(r) ** 2 / abs(mp.expm1(nz(r))), -E, E, 6,
         'expm1(r) = r + r^2 E(r), e^r = 1 + expm1(r)')
    Z = mp.mpf('0.02944')  # s^2, s = f/(2+f), f in [sqrt(1/2)-1, sqrt(2)-1]
    poly('LOG_R', lambda z: (2 * mp.atanh(sq(z)) - 2 * sq(z)) / sq(z) ** 3,
         lambda z: sq(z) ** 3 / (2 * mp.atanh(sq(z))), 0, Z, 4,
         'log1p(f) = 2s + s^3 R(s^2), s = f / (2 + f)')
    poly('ATAN_A', lambda z: (mp.atan(sq(z)) - sq(z)) / sq(z) ** 3,
         lambda z: sq(z) ** 3 / mp.atan(sq(z)), 0, 1, 10,
         'atan(t) = t + t^3 A(t^2), t in [0, 1]')
    poly('ASIN_B', lambda z: (mp.asin(sq(z)) - sq(z)) / sq(z) ** 3,
         lambda z: sq(z) ** 3 / mp.asin(sq(z)), 0, mp.mpf('0.25'), 6,
         'asin(x) = x + x^3 B(x^2), |x| <= 1/2')
    poly('ERF_P', lambda z: mp.erf(sq(z)) / sq(z) - 1,
         lambda z: sq(z) / mp.erf(sq(z)), 0, mp.mpf('0.390625'), 6,
         'erf(x) = x + x P(x^2), |x| <= 0.625')
    # erfc(x) = exp(-x^2) F(x), F = erfc(x) exp(x^2), piecewise in v = x - c (exact by Sterbenz).
    F = lambda x: mp.erfc(x) * mp.exp(x * x)
    pieces = [('ERFC_A', '0.5', '1.0', 8), ('ERFC_B', '1.0', '1.5', 8), ('ERFC_C', '1.5', '2.25', 8),
              ('ERFC_D', '2.25', '3.5', 9), ('ERFC_E', '3.5', '6.0', 10), ('ERFC_F', '6.0', '10.0625', 10)]
    for prefix, a, b, n in pieces:
        a = mp.mpf(a)
        b = mp.mpf(b)
        c = mp.mpf(f32((a + b) / 2))
        assert 3 * a >= b
        const(f'{prefix}_MID', c, f'x in [{float(a)}, {float(b)})')
        poly(prefix, lambda v, c=c: F(v + c), lambda v, c=c: 1 / F(v + c), a - c, b - c, n,
             f'F(x) = erfc(x) exp(x^2) = P(x - {float(c)})', c0_split=True)

    text = '\n'.join(OUT) + '\n\n'  # blank line: keeps rustfmt from indenting the end marker
    if '--write' in sys.argv:
        path = Path(__file__).resolve().parent.parent / 'src' / 'math.rs'
        src = path.read_text()
        begin = '// BEGIN GENERATED by tools/fit_math.py\n'
        end = '// END GENERATED\n'
        i = src.index(begin) + len(begin)
        j = src.index(end)
        path.write_text(src[:i] + text + src[j:])
        print(f'wrote {path}', file=sys.stderr)
    else:
        sys.stdout.write(text)


if __name__ == '__main__':
    main()
