"""NumPy oracle of the 2D creep-force models: Carter (1926; Johnson 1985, chapter 8) and
Fletcher's elastic foundation (2013, eqs. (8)-(12)), written with NumPy from the formulas in
the docstrings of :mod:`railadhesion.models.twod` (valid inputs, broadcast)."""

from __future__ import annotations

import numpy as np


def _ratio_or_inf(num, den):
    """num/den for num, den >= 0: 0 where num == 0, inf where only den == 0."""
    shape = np.broadcast_shapes(num.shape, den.shape)
    out = np.divide(num, den, out=np.zeros(shape), where=den > 0)
    return np.where((den <= 0) & (num > 0), np.inf, out)


def _inputs(*args):
    return (np.asarray(x, dtype=float) for x in args)


def carter(creep, normal_load, half_width, radius, mu):
    """(traction, stick, slip, stick_half_width) of Carter's model."""
    xi, load, a, r, m = _inputs(creep, normal_load, half_width, radius, mu)
    kappa = np.minimum(_ratio_or_inf(np.abs(xi) * r, m * a), 1.0)
    total = 2.0 * kappa - kappa * kappa
    s = 2.0 * kappa - 1.0
    slip_frac = (np.arcsin(s) + s * np.sqrt(1.0 - s * s) + 0.5 * np.pi) / np.pi
    scale = np.sign(-xi) * m * load
    traction = scale * total
    slip = scale * slip_frac
    stick = traction - slip
    stick_half_width = a * (1.0 - kappa) * np.ones_like(traction)
    return traction, stick, slip, stick_half_width


def fletcher(creep, normal_load, half_width, radius, mu, k_a=1.0, k_s=1.0):
    """(traction, stick, slip, stick_half_width) of Fletcher's model."""
    xi, load, a, r, m, ka, ks = _inputs(creep, normal_load, half_width, radius, mu, k_a, k_s)
    mag = np.abs(xi)
    # eq. (8): c = max(a - 2 k_a xi R / (3 k_s mu), 0)
    shift = _ratio_or_inf(2.0 * ka * mag * r, 3.0 * ks * m)
    c = np.maximum(a - shift, 0.0)
    u = c / a
    # eq. (9): Q_A / P = 2 k_a c^2 xi R / a^3
    stick_frac = 2.0 * ka * u * u * mag * r / a
    # eq. (11): Q_S / P = 3/2 mu k_s (a - c)/a - 1/4 mu k_s (a^3 - (2c - a)^3)/a^3
    w = 2.0 * u - 1.0
    slip_frac = m * ks * (1.5 * (1.0 - u) - 0.25 * (1.0 - w * w * w))
    scale = np.sign(-xi) * load
    stick = scale * stick_frac
    slip = scale * slip_frac
    traction = stick + slip  # eq. (12)
    c = c * np.ones_like(traction)
    return traction, stick, slip, c
