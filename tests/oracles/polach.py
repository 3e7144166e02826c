"""NumPy oracle of Polach's creep-force model (Polach 1999, 2005; the formulas and this
package's conventions, the spin cap included, are in the docstring of
:func:`railadhesion.models.polach.polach_forces`): arrays with NumPy, and one contact with the
``math`` module. Kalker's coefficients from the NumPy oracle :mod:`oracles.kalker`.
"""

from __future__ import annotations

import math

import numpy as np

from oracles.kalker import kalker_coefficients

_TWO_OVER_PI = 2.0 / math.pi
_PI_OVER_4 = math.pi / 4.0
_EPS_MAX = 1e50


def polach_forces(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu):
    """Polach's (fx, fy) of valid inputs (any shapes, broadcast), Kalker's signs: NumPy, no
    Python loops. Arguments in the order of the package's ``_ARG_NAMES`` (positional)."""
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu = (
        np.asarray(x, dtype=float) for x in (sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a,
                                             big_b, g, nu))
    a_over_b = a / b
    c11, c22, c23, _ = kalker_coefficients(a_over_b, nu)

    syc = sy + psi * a
    syc = np.where(np.abs(syc) > np.abs(sy), syc, sy)
    sc = np.hypot(sx, syc)
    moving = sc > 0.0
    sc_safe = np.where(moving, sc, 1.0)
    s = np.hypot(sx, sy)
    has_s = s > 0.0
    cjj = np.where(has_s, np.hypot(c11 * sx, c22 * sy) / np.where(has_s, s, 1.0), c22)

    mu = mu0 * ((1.0 - big_a) * np.exp(-big_b * (sc * v)) + big_a)
    qmu = q * mu
    # qmu == 0 only if A = 0 and exp(-B w) underflowed: no friction left, no force
    active = moving & (qmu > 0.0)
    qmu = np.where(qmu > 0.0, qmu, 1.0)
    k_psi = 1.0 + 6.3 * (1.0 - np.exp(-a_over_b))
    gc3c23 = g * a * b * np.sqrt(a * b) * c23
    abs_syc = np.abs(syc)
    with np.errstate(over="ignore"):  # huge gradients become inf (eps is then clipped)
        eps = np.minimum(_PI_OVER_4 * g * a * b * cjj * sc / qmu, _EPS_MAX)
        eps_psi = (8.0 / 3.0) * gc3c23 / a * abs_syc / (k_psi * qmu)
        e2 = 1.0 + eps_psi * eps_psi  # inf gives F_yS = 0
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + np.arctan(k_s * eps)) / sc_safe
    fys = gc3c23 * (psi / sc_safe) * (abs_syc / e2) / e2  # same order as the scalar path

    fx = np.where(active, -f_over_sc * sx, 0.0)
    fy = np.where(active, -(f_over_sc * sy + fys), 0.0)
    total = np.hypot(fx, fy)
    # spin cap at max(mu Q, |F|) where F_yS != 0 (see Notes); divide only where it applies
    # (limit/total of a tiny force would overflow)
    limit = np.maximum(qmu, f_over_sc * np.hypot(sx, sy))
    over = (total > limit) & (fys != 0.0) & active
    scale = np.where(over, limit / np.where(over, total, 1.0), 1.0)
    fx, fy = fx * scale, fy * scale
    if fx.ndim == 0:
        return np.float64(fx), np.float64(fy)
    # the five parameters may not reach fx (e.g. spin-only shapes): broadcast both fully
    shape = np.broadcast_shapes(fx.shape, fy.shape)
    if fx.shape != shape:
        fx = np.broadcast_to(fx, shape).copy()
    if fy.shape != shape:
        fy = np.broadcast_to(fy, shape).copy()
    return fx, fy


def polach_scalar(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu):
    """:func:`polach_forces` of one contact of valid floats, with the ``math`` module."""
    a_over_b = a / b
    c11, c22, c23 = (float(c) for c in kalker_coefficients(a_over_b, float(nu))[:3])
    syc = sy + psi * a
    if not abs(syc) > abs(sy):
        syc = sy
    sc = math.hypot(sx, syc)
    if sc == 0.0:  # then psi == 0 too: no creepage, no force
        return np.float64(0.0), np.float64(0.0)
    s = math.hypot(sx, sy)
    cjj = math.hypot(c11 * sx, c22 * sy) / s if s > 0.0 else c22
    mu = mu0 * ((1.0 - big_a) * math.exp(-big_b * sc * v) + big_a)
    qmu = q * mu
    if qmu == 0.0:  # A = 0 and exp(-B w) underflowed: no friction left, no force
        return np.float64(0.0), np.float64(0.0)
    eps = min(_PI_OVER_4 * g * a * b * cjj * sc / qmu, _EPS_MAX)
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + math.atan(k_s * eps)) / sc
    k_psi = 1.0 + 6.3 * (1.0 - math.exp(-a_over_b))
    gc3c23 = g * a * b * math.sqrt(a * b) * c23
    eps_psi = 8.0 / 3.0 * gc3c23 / a * abs(syc) / (k_psi * qmu)
    e2 = 1.0 + eps_psi * eps_psi  # may be inf (float overflow): then F_yS = 0
    # |psi|/s_C <= 2/a and |s_yC|/e2 is bounded: this order cannot overflow (a product
    # psi*|s_yC| first would, for huge creepages, and give inf*0 = NaN after the cap)
    fys = gc3c23 * (psi / sc) * (abs(syc) / e2) / e2
    fx, fy = -f_over_sc * sx, -(f_over_sc * sy + fys)
    if fys != 0.0:  # spin cap (see Notes): removes only the overshoot the spin term adds
        limit = max(qmu, f_over_sc * math.hypot(sx, sy))
        total = math.hypot(fx, fy)
        if total > limit:
            fx, fy = fx * (limit / total), fy * (limit / total)
    return np.float64(fx), np.float64(fy)
