#!/usr/bin/env python3
"""Prints the Taylor coefficients (in z = phi^2) used by odometry/src/error_model.cpp.

Every function is an integral over u in [0, 1] of products of cos(phi u), sin(phi u),
X^(u) = int_u^1 cos(phi t) dt and Y^(u) = int_u^1 sin(phi t) dt. Their series in phi are
polynomials in u, integrated exactly with rational arithmetic; each list stops at the first
coefficient below 1e-18 of the leading one (|phi| < 1 in the code). Standard library only.
"""
from fractions import Fraction as F
from math import factorial

N = 40  # highest power of phi kept


def mul(a, b):
    r = {}
    for p1, pa in a.items():
        for p2, pb in b.items():
            if p1 + p2 > N:
                continue
            d = r.setdefault(p1 + p2, {})
            for q1, c1 in pa.items():
                for q2, c2 in pb.items():
                    d[q1 + q2] = d.get(q1 + q2, 0) + c1 * c2
    return r


def integrate(a):  # int_0^1 du of a series {phi power: {u power: coefficient}}
    out = {}
    for p, poly in a.items():
        v = sum(c / (q + 1) for q, c in poly.items())
        if v != 0:
            out[p] = v
    return out


cos_s, sin_s, xh, yh = {}, {}, {}, {}
for k in range(N // 2 + 1):
    sign = (-1) ** k
    cos_s[2 * k] = {2 * k: F(sign, factorial(2 * k))}
    xh[2 * k] = {0: F(sign, factorial(2 * k + 1)), 2 * k + 1: F(-sign, factorial(2 * k + 1))}
    if 2 * k + 1 <= N:
        sin_s[2 * k + 1] = {2 * k + 1: F(sign, factorial(2 * k + 1))}
        yh[2 * k + 1] = {0: F(sign, factorial(2 * k + 2)), 2 * k + 2: F(-sign, factorial(2 * k + 2))}


def shifted(series, off):
    return {p - off: v for p, v in series.items()}


functions = {
    "kSinc (I_c)": integrate(cos_s),
    "kH ((1 - cos)/phi^2 = I_s/phi)": shifted(integrate(sin_s), 1),
    "kG1 (I_ss/phi^2)": shifted(integrate(mul(sin_s, sin_s)), 2),
    "kG2 (J_y/phi)": shifted(integrate(yh), 1),
    "kG3 (J_xx)": integrate(mul(xh, xh)),
    "kG4 (J_yy/phi^2)": shifted(integrate(mul(yh, yh)), 2),
    "kG5 (J_xy/phi)": shifted(integrate(mul(xh, yh)), 1),
}
for name, d in functions.items():
    lead = abs(float(d[0]))
    coeffs = []
    for p in sorted(d):
        assert p % 2 == 0
        coeffs.append(d[p])
        if abs(float(d[p])) < 1e-18 * lead:
            break
    print(name + ": " + ", ".join(repr(float(c)) for c in coeffs))
