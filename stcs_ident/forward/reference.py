"""Closed-form reference frequencies (Hz) of cables, for tables and tests.

- :func:`taut_string`: f_n = (n / 2l) √(H/m).
- :func:`beam_pinned`: the pinned–pinned tensioned beam ("beam theory", BT),
  f_n = (n / 2l) √(H/m) √(1 + n²π² EI /(H l²)).
- :func:`beam_clamped_asymptotic`: f_n ≈ f_n^string (1 + 2/ξ + (4 + n²π²/2)/ξ²),
  ξ = l √(H/EI).
- :func:`beam_clamped`: exact roots of the clamped–clamped tensioned beam,
  Δ = 2pq(1 − cosh pL cos qL) + (p² − q²) sinh pL sin qL = 0.
- :func:`beam_clamped_no_tension`: β_n l from cos βl cosh βl = 1.
- :func:`irvine`: Irvine's shallow sagging string (EI → 0, no attachments).
- :func:`string_point_mass`: a taut string with one point mass.

Frequencies are returned as numpy arrays over ``modes`` (1-based).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


def _modes(modes):
    n = np.atleast_1d(np.asarray(modes))
    if n.ndim != 1 or np.any(n < 1) or np.any(n != np.round(n)):
        raise ValueError("`modes` must be a 1-D sequence of integers >= 1")
    return n.astype(float)


def taut_string(length, mass_per_length, tension, modes):
    """Taut string: f_n = (n / 2l) √(H/m)."""
    n = _modes(modes)
    return n / (2 * length) * math.sqrt(tension / mass_per_length)


def beam_pinned(length, mass_per_length, tension, EI, modes):
    """Pinned–pinned tensioned beam: f_n = f_n^string √(1 + n²π² EI /(H l²))."""
    n = _modes(modes)
    return taut_string(length, mass_per_length, tension, n) * np.sqrt(
        1 + n * n * math.pi**2 * EI / (tension * length**2)
    )


def beam_clamped_asymptotic(length, mass_per_length, tension, EI, modes):
    """Clamped tensioned beam, asymptotic in ξ = l √(H/EI) (large ξ)."""
    n = _modes(modes)
    xi = length * math.sqrt(tension / EI)
    return taut_string(length, mass_per_length, tension, n) * (1 + 2 / xi + (4 + n * n * math.pi**2 / 2) / xi**2)


def _clamped_delta(omega, length, mass_per_length, tension, EI):
    """Δ(ω) / cosh(pL): same sign and roots as Δ, without overflow."""
    a = tension / (2 * EI)
    root = math.sqrt(a * a + mass_per_length * omega * omega / EI)
    p = math.sqrt(a + root)
    q = math.sqrt(mass_per_length * omega * omega / EI / (a + root))
    pL, qL = p * length, q * length
    sech = 2 * math.exp(-pL) / (1 + math.exp(-2 * pL))
    return 2 * p * q * (sech - math.cos(qL)) + (p * p - q * q) * math.tanh(pL) * math.sin(qL)


def beam_clamped(length, mass_per_length, tension, EI, modes):
    """Clamped–clamped tensioned beam: roots of Δ(ω), one in each interval
    qL ∈ (nπ, (n+1)π); found by Brent's method on that interval."""
    n = _modes(modes).astype(int)
    out = []
    for k in n:
        # ω as a function of qL: m ω² = EI q² (q² + H/EI)
        def omega_of(qL):
            q = qL / length
            return math.sqrt(EI * q * q * (q * q + tension / EI) / mass_per_length)

        lo, hi = omega_of(k * math.pi * (1 + 1e-12)), omega_of((k + 1) * math.pi * (1 - 1e-12))
        root = brentq(_clamped_delta, lo, hi, args=(length, mass_per_length, tension, EI), xtol=1e-300, rtol=1e-15)
        out.append(root / (2 * math.pi))
    return np.array(out)


def beam_clamped_no_tension(length, mass_per_length, EI, modes):
    """Clamped–clamped beam without tension: cos βl cosh βl = 1,
    ω = β² √(EI/m)."""
    n = _modes(modes).astype(int)
    out = []
    for k in n:
        # cos x − sech x = 0 has one root in ((k + ½)π − ½, (k + ½)π + ½)
        g = lambda x: math.cos(x) - 2 * math.exp(-x) / (1 + math.exp(-2 * x))
        x = brentq(g, (k + 0.5) * math.pi - 0.5, (k + 0.5) * math.pi + 0.5, xtol=1e-300, rtol=1e-15)
        out.append((x / length) ** 2 * math.sqrt(EI / mass_per_length) / (2 * math.pi))
    return np.array(out)


def irvine(length, mass_per_length, tension, lambda2, modes):
    """Irvine's sagging string (EI → 0, no attachments), all in-plane modes
    in ascending order: antisymmetric ω̄ = 2kπ and symmetric roots of
    tan(ω̄/2) = ω̄/2 − (4/λ²)(ω̄/2)³, ω̄ = ω l √(m/H)."""
    n = _modes(modes).astype(int)
    count = int(n.max())
    sym = []
    for k in range(count + 1):
        # in ω̄/2 ∈ ((k − ½)π, (k + ½)π) the function below rises from −∞ to +∞
        def g(x):
            return math.tan(x) - x + 4.0 / lambda2 * x**3 if lambda2 > 0 else -math.cos(x)

        lo = max((k - 0.5) * math.pi, 0.0) + 1e-12
        hi = (k + 0.5) * math.pi - 1e-12
        if lambda2 == 0:
            sym.append(2 * (k + 0.5) * math.pi)
            continue
        if g(lo) < 0 < g(hi):
            sym.append(2 * brentq(g, lo, hi, xtol=1e-300, rtol=1e-15))
    anti = [2 * k * math.pi for k in range(1, count + 1)]
    wbar = np.sort(np.array(sym + anti))[: count]
    f = wbar / (length * math.sqrt(mass_per_length / tension)) / (2 * math.pi)
    return f[n - 1]


def string_point_mass(length, mass_per_length, tension, mass, position, modes):
    """Taut string with one point mass M at x = a: H q [cot(qa) + cot(qb)] = M ω²,
    q = ω √(m/H), b = l − a; antisymmetric-like roots where sin(qa) = sin(qb) = 0
    are included through the product form
    H q sin(ql) − M ω² sin(qa) sin(qb) = 0."""
    n = _modes(modes).astype(int)
    c = math.sqrt(tension / mass_per_length)
    a, b = position, length - position

    def g(q):
        return tension * q * np.sin(q * length) - mass * (q * c) ** 2 * np.sin(q * a) * np.sin(q * b)

    # scan finely in q, then refine each sign change
    qmax = (n.max() + 1) * math.pi / length
    grid = np.linspace(1e-9, qmax, 20000 * int(n.max() + 1))
    vals = g(grid)
    roots = []
    for i in np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0):
        roots.append(brentq(g, grid[i], grid[i + 1], xtol=1e-300, rtol=1e-15))
    roots = np.array(roots)
    return roots[n - 1] * c / (2 * math.pi)
