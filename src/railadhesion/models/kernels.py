"""Compiled (numba) kernels of Kalker's coefficients, Polach and WILAC, for inner loops.

The NumPy implementations (:func:`railadhesion.models.polach.polach_forces`,
:func:`railadhesion.models.wilac.wilac_forces`, :func:`railadhesion.contact.kalker_coefficients`)
are the readable reference; these kernels compute the same numbers (the test suite holds them
to 1e-12 relative) in compiled loops. Importing this module imports numba; nothing is compiled
until a kernel is first called, and compiled code is cached on disk (``cache=True``), so the
compile cost is paid once per installation, not per process.

Stable API for numba code (the functions below are ``@njit`` and can be called from other
``@njit`` functions, e.g. an ODE right-hand side or a braking integrator; from Python they
work too, at a dispatch cost of a few microseconds):

``kalker_scalar(a_over_b, nu) -> (c11, c22, c23, c33)``
    Kalker's coefficients (same table, interpolation and asymptotes as
    :func:`railadhesion.contact.kalker.kalker_coefficients`).

``polach_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
k_A, k_S, mu0, A, B) -> (fx, fy)``
    Polach's forces [N] (Kalker's signs, rail on wheel) of one contact, exactly the model of
    :func:`railadhesion.models.polach.polach_forces` (spin, k_A/k_S, falling friction, the
    spin cap). Pass the coefficients of ``kalker_scalar(a/b, nu)`` as c11, c22, c23 (look them
    up once per contact shape), or ``c11 <= 0`` (e.g. 0.0) to have them looked up from a/b and
    nu on every call (about 20 ns more).

``wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11,
c22, c23, packed) -> (fx, fy)``
    WILAC's forces [N] of one contact (weights, regressions, Polach per condition with non-zero
    weight, blend), as :func:`railadhesion.models.wilac.wilac_forces`. ``packed`` is the plain
    1-d float64 array of :func:`pack_wilac` (``pack_wilac(params)``, once per parameter set);
    c11 as above.

``polach_checked(...)``, same arguments as ``polach_scalar`` -> (fx, fy, bad)
    With validation: ``bad`` is -1, or the position (0-16) of the first argument out of the
    range of :func:`~railadhesion.models.polach.polach_forces` (forces then NaN).

None of them validates its input (validation is the public functions' job): they assume
finite creepages, positive Q, a, b, G, mu0, k_A, k_S in (0, 1], A, B >= 0, nu in [0, 0.5].

Example, an ODE right-hand side in numba (one wheel braking on one contact)::

    from numba import njit
    from railadhesion.models.kernels import kalker_scalar, polach_scalar

    a, b = 6.3e-3, 12.6e-3
    c11, c22, c23, _ = kalker_scalar(a / b, 0.28)

    @njit
    def rhs(t, y):  # y = (V, omega)
        creep = (y[0] - y[1] * 0.46) / y[0]
        fx, _ = polach_scalar(creep, 0.0, 0.0, 1e5, y[0], a, b, 8.2e10, 0.28,
                              c11, c22, c23, 1.0, 0.4, 0.55, 0.4, 0.6)
        ...

The vectorised kernels (``polach_many``, ``wilac_many``) and the FASTSIM kernel are used by
the public functions; they are not part of the stable API.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from railadhesion.contact.kalker import _AOB_MAX, _AOB_MIN, _C33_GT_ROWS, _G_MIN, _NROW, _ROWS

__all__ = [
    "HEADER_SIZE",
    "kalker_scalar",
    "pack_wilac",
    "polach_checked",
    "polach_scalar",
    "wilac_scalar",
]

# Kalker's table as compile-time constants (numba freezes global arrays into the code).
_KROWS = np.ascontiguousarray(_ROWS, dtype=np.float64)  # (19 rows, 4 coefficients, 3 nu)
_C33_01 = np.ascontiguousarray(_C33_GT_ROWS[0], dtype=np.float64)
_C33_02 = np.ascontiguousarray(_C33_GT_ROWS[1], dtype=np.float64)
_KG_MIN = float(_G_MIN)
_KNROW = int(_NROW)
_PI = math.pi
_TWO_OVER_PI = 2.0 / math.pi
_PI_OVER_4 = math.pi / 4.0
_EPS_MAX = 1e50
_LOG4 = math.log(4.0)
_LOG2 = math.log(2.0)

#: Length of the ``header`` array of :func:`pack_wilac`.
HEADER_SIZE = 22
#: Number of contacts a thread processes in sequence (the Kalker lookup is reused within it
#: while a/b and nu do not change).
_CHUNK = 2048
#: Below this many contacts the serial kernels are used (thread start-up costs more).
_PARALLEL_MIN = 8192


# --- Kalker ---------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _nu_blend(w0, w1, w2, c0, c1, c2):
    return 1.0 / (w0 / c0 + w1 / c1 + w2 / c2)


@njit(cache=True, error_model="numpy")
def _asymptotes(g, nu, le):
    """Kalker's small-g asymptotes (C11, C22, C23, C33), C33 NaN on the b/a branch."""
    if le:
        return (
            _PI**2 / (4.0 * (1.0 - nu)),
            _PI**2 / 4.0,
            _PI * math.sqrt(g) / (3.0 * (1.0 - nu)) * (1.0 + nu * (math.log(16.0 / g) - 5.0)),
            _PI**2 / (16.0 * (1.0 - nu) * g),
        )
    lam = math.log(16.0 / g**2)
    k = 3.0 - _LOG4
    den = (1.0 - nu) * lam + 2.0 * nu
    return (
        2.0 * _PI / ((lam - 2.0 * nu) * g) * (1.0 + k / (lam - 2.0 * nu)),
        (2.0 * _PI / g) * (1.0 + (1.0 - nu) * k / den) / den,
        2.0 * _PI / (3.0 * g**1.5 * ((1.0 - nu) * lam - 2.0 + 4.0 * nu)),
        math.nan,
    )


@njit(cache=True, error_model="numpy")
def kalker_scalar(a_over_b, nu):
    """Kalker's C11, C22, C23, C33 at a/b and Poisson's ratio nu (no validation).

    Same numbers as :func:`railadhesion.contact.kalker.kalker_coefficients` (Kalker 1990,
    Table E.3, CONTACT's interpolation, corrected asymptotes below g = 0.1); a/b must be in
    [1e-150, 1e150] and nu in [0, 0.5].
    """
    le = a_over_b <= 1.0
    g = a_over_b if le else 1.0 / a_over_b
    w0 = 8.0 * (nu - 0.25) * (nu - 0.5)
    w1 = -16.0 * (nu - 0.5) * nu
    w2 = 8.0 * nu * (nu - 0.25)
    t = g if le else 2.0 - g
    s = (min(max(t, 0.1), 1.9) - 0.1) * 10.0
    sr = math.floor(s + 0.5)
    if abs(s - sr) < 1e-9:
        s = sr
    i = min(int(s), _KNROW - 2)
    f = s - i
    out0 = 0.0
    out1 = 0.0
    out2 = 0.0
    out3 = 0.0
    for k in range(4):
        c0 = _KROWS[i, k, 0] * (1.0 - f) + _KROWS[i + 1, k, 0] * f
        c1 = _KROWS[i, k, 1] * (1.0 - f) + _KROWS[i + 1, k, 1] * f
        c2 = _KROWS[i, k, 2] * (1.0 - f) + _KROWS[i + 1, k, 2] * f
        c = _nu_blend(w0, w1, w2, c0, c1, c2)
        if k == 0:
            out0 = c
        elif k == 1:
            out1 = c
        elif k == 2:
            out2 = c
        else:
            out3 = c
    if g >= _KG_MIN:
        return out0, out1, out2, out3
    a0, a1, a2, a3 = _asymptotes(g, nu, le)
    b0, b1, b2, b3 = _asymptotes(_KG_MIN, nu, le)
    h = g / _KG_MIN
    r0 = a0 * (1.0 + (out0 / b0 - 1.0) * h)
    r1 = a1 * (1.0 + (out1 / b1 - 1.0) * h)
    r2 = a2 * (1.0 + (out2 / b2 - 1.0) * h)
    if le:
        r3 = a3 * (1.0 + (out3 / b3 - 1.0) * h)
    else:
        c33_01 = _nu_blend(w0, w1, w2, _C33_01[0], _C33_01[1], _C33_01[2])
        c33_02 = _nu_blend(w0, w1, w2, _C33_02[0], _C33_02[1], _C33_02[2])
        r3 = c33_01 * (g / _KG_MIN) ** (math.log(c33_02 / c33_01) / _LOG2)
    return r0, r1, r2, r3


@njit(cache=True, parallel=True, error_model="numpy")
def kalker_many(a_over_b, nu):
    """C11, C22, C23, C33 of 1-d arrays a/b and nu (each of length n or 1); (4, n) array."""
    n = max(a_over_b.size, nu.size)
    sr = 1 if a_over_b.size > 1 else 0
    sn = 1 if nu.size > 1 else 0
    out = np.empty((4, n))
    for i in prange(n):
        c = kalker_scalar(a_over_b[i * sr], nu[i * sn])
        out[0, i] = c[0]
        out[1, i] = c[1]
        out[2, i] = c[2]
        out[3, i] = c[3]
    return out


# --- Polach ---------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _hyp(x, y):
    """sqrt(x^2 + y^2): the plain formula where it can neither overflow nor lose the larger
    term to underflow (it then agrees with hypot to an ulp), else ``math.hypot``."""
    m = max(abs(x), abs(y))
    if 1e-150 < m < 1e150:
        return math.sqrt(x * x + y * y)
    return math.hypot(x, y)


@njit(cache=True, error_model="numpy")
def _kalker3(a_over_b, nu):
    """C11, C22, C23 of :func:`kalker_scalar` (the same operations, without C33)."""
    le = a_over_b <= 1.0
    g = a_over_b if le else 1.0 / a_over_b
    w0 = 8.0 * (nu - 0.25) * (nu - 0.5)
    w1 = -16.0 * (nu - 0.5) * nu
    w2 = 8.0 * nu * (nu - 0.25)
    t = g if le else 2.0 - g
    s = (min(max(t, 0.1), 1.9) - 0.1) * 10.0
    sr = math.floor(s + 0.5)
    if abs(s - sr) < 1e-9:
        s = sr
    i = min(int(s), _KNROW - 2)
    f = s - i
    e = 1.0 - f
    out0 = _nu_blend(w0, w1, w2, _KROWS[i, 0, 0] * e + _KROWS[i + 1, 0, 0] * f,
                     _KROWS[i, 0, 1] * e + _KROWS[i + 1, 0, 1] * f,
                     _KROWS[i, 0, 2] * e + _KROWS[i + 1, 0, 2] * f)  # fmt: skip
    out1 = _nu_blend(w0, w1, w2, _KROWS[i, 1, 0] * e + _KROWS[i + 1, 1, 0] * f,
                     _KROWS[i, 1, 1] * e + _KROWS[i + 1, 1, 1] * f,
                     _KROWS[i, 1, 2] * e + _KROWS[i + 1, 1, 2] * f)  # fmt: skip
    out2 = _nu_blend(w0, w1, w2, _KROWS[i, 2, 0] * e + _KROWS[i + 1, 2, 0] * f,
                     _KROWS[i, 2, 1] * e + _KROWS[i + 1, 2, 1] * f,
                     _KROWS[i, 2, 2] * e + _KROWS[i + 1, 2, 2] * f)  # fmt: skip
    if g >= _KG_MIN:
        return out0, out1, out2
    c = kalker_scalar(a_over_b, nu)
    return c[0], c[1], c[2]


@njit(cache=True, error_model="numpy")
def _contact_terms(sx, sy, psi, a, b, g, c11, c22, c23):
    """Parameter-independent part of Polach's model for one contact (shared by WILAC's four
    conditions). Same operations, in the same order, as the NumPy reference."""
    syc = sy + psi * a
    if not abs(syc) > abs(sy):
        syc = sy
    sc = _hyp(sx, syc)
    s = _hyp(sx, sy)
    cjj = _hyp(c11 * sx, c22 * sy) / s if s > 0.0 else c22
    eps_num = _PI_OVER_4 * g * a * b * cjj * sc
    abs_syc = abs(syc)
    k_psi = 1.0
    epsp_num = 0.0
    fys_pre = 0.0
    if psi != 0.0 and sc > 0.0:
        k_psi = 1.0 + 6.3 * (1.0 - math.exp(-(a / b)))
        gc3c23 = g * a * b * math.sqrt(a * b) * c23
        epsp_num = 8.0 / 3.0 * gc3c23 / a * abs_syc
        fys_pre = gc3c23 * (psi / sc)
    return sc, s, eps_num, abs_syc, k_psi, epsp_num, fys_pre


@njit(cache=True, error_model="numpy")
def _polach_terms(sx, sy, q, v, sc, s, eps_num, abs_syc, k_psi, epsp_num, fys_pre,
                  k_a, k_s, mu0, big_a, big_b):  # fmt: skip
    """Polach's forces from :func:`_contact_terms` and one parameter set."""
    if sc == 0.0:
        return 0.0, 0.0
    if big_b == 0.0 or big_a == 1.0:  # constant friction (to an ulp of the general formula)
        mu = mu0
    else:
        mu = mu0 * ((1.0 - big_a) * math.exp(-big_b * (sc * v)) + big_a)
    qmu = q * mu
    if not qmu > 0.0:  # A = 0 and exp(-B w) underflowed: no friction left, no force
        return 0.0, 0.0
    eps = min(eps_num / qmu, _EPS_MAX)
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + math.atan(k_s * eps)) / sc
    fys = 0.0
    if fys_pre != 0.0:
        eps_psi = epsp_num / (k_psi * qmu)
        e2 = 1.0 + eps_psi * eps_psi  # may be inf: then F_yS = 0
        fys = fys_pre * (abs_syc / e2) / e2
    fx = -f_over_sc * sx
    fy = -(f_over_sc * sy + fys)
    if fys != 0.0:  # spin cap: max(mu Q, |F of the creepage part|)
        limit = max(qmu, f_over_sc * s)
        total = _hyp(fx, fy)
        if total > limit:
            scale = limit / total
            fx = fx * scale
            fy = fy * scale
    return fx, fy


@njit(cache=True, error_model="numpy")
def polach_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
                  k_A, k_S, mu0, A, B):  # fmt: skip
    """Polach's forces (fx, fy) [N] of one contact; see the module docstring (no validation).

    Kalker's sign convention: the forces of the rail on the wheel oppose the creepages.
    ``c11 <= 0`` looks C11, C22, C23 up from a/b and nu.
    """
    if not c11 > 0.0:
        c11, c22, c23 = _kalker3(a / b, nu)
    t = _contact_terms(creep_x, creep_y, spin, a, b, G, c11, c22, c23)
    return _polach_terms(creep_x, creep_y, normal_force, speed, t[0], t[1], t[2], t[3], t[4],
                         t[5], t[6], k_A, k_S, mu0, A, B)  # fmt: skip


@njit(cache=True, error_model="numpy")
def polach_checked(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
                   k_A, k_S, mu0, A, B):  # fmt: skip
    """:func:`polach_scalar` with validation: returns (fx, fy, bad), ``bad`` = -1 if every
    argument is in range, else the position of the first bad argument (forces NaN)."""
    bad = _first_bad(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, k_A, k_S, mu0,
                     A, B)  # fmt: skip
    if bad >= 0:
        return math.nan, math.nan, bad
    fx, fy = polach_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22,
                           c23, k_A, k_S, mu0, A, B)  # fmt: skip
    return fx, fy, -1


@njit(cache=True, error_model="numpy")
def _first_bad(sx, sy, psi, q, v, a, b, g, nu, k_a, k_s, mu0, big_a, big_b):
    """Position (in polach_scalar's argument order) of the first out-of-range argument, 17
    for an a/b out of Kalker's range, or -1."""
    if not math.isfinite(sx):
        return 0
    if not math.isfinite(sy):
        return 1
    if not math.isfinite(psi):
        return 2
    if not 0.0 < q < math.inf:
        return 3
    if not 0.0 <= v < math.inf:
        return 4
    if not 0.0 < a < math.inf:
        return 5
    if not 0.0 < b < math.inf:
        return 6
    if not 0.0 < g < math.inf:
        return 7
    if not 0.0 <= nu <= 0.5:
        return 8
    if not 0.0 < k_a <= 1.0:
        return 12
    if not 0.0 < k_s <= 1.0:
        return 13
    if not 0.0 < mu0 < math.inf:
        return 14
    if not 0.0 <= big_a < math.inf:
        return 15
    if not 0.0 <= big_b < math.inf:
        return 16
    r = a / b
    if not _AOB_MIN <= r <= _AOB_MAX:
        return 17
    return -1


@njit(cache=True, error_model="numpy")
def _bad_polach(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu):
    """True if any argument is outside the range of polach_forces (NaN fails every test)."""
    if not (math.isfinite(sx) and math.isfinite(sy) and math.isfinite(psi)):
        return True
    if not (0.0 < q < math.inf and 0.0 < a < math.inf and 0.0 < b < math.inf):
        return True
    if not (0.0 < mu0 < math.inf and 0.0 < g < math.inf):
        return True
    if not (0.0 < k_a <= 1.0 and 0.0 < k_s <= 1.0 and 0.0 <= nu <= 0.5):
        return True
    if not (0.0 <= v < math.inf and 0.0 <= big_a < math.inf and 0.0 <= big_b < math.inf):
        return True
    r = a / b
    return not (_AOB_MIN <= r <= _AOB_MAX)


def _polach_many_py(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu, n):
    """Polach over n contacts; every argument a 1-d float64 array of length n or 1.

    Returns (fx, fy, ok); ``ok`` False if an argument is out of range (the caller then runs
    the reference validation to raise the error naming it).
    """
    fx = np.empty(n)
    fy = np.empty(n)
    s0 = 1 if sx.size > 1 else 0
    s1 = 1 if sy.size > 1 else 0
    s2 = 1 if psi.size > 1 else 0
    s3 = 1 if q.size > 1 else 0
    s4 = 1 if v.size > 1 else 0
    s5 = 1 if a.size > 1 else 0
    s6 = 1 if b.size > 1 else 0
    s7 = 1 if mu0.size > 1 else 0
    s8 = 1 if k_a.size > 1 else 0
    s9 = 1 if k_s.size > 1 else 0
    s10 = 1 if big_a.size > 1 else 0
    s11 = 1 if big_b.size > 1 else 0
    s12 = 1 if g.size > 1 else 0
    s13 = 1 if nu.size > 1 else 0
    nchunk = (n + _CHUNK - 1) // _CHUNK
    bad = np.zeros(nchunk, dtype=np.uint8)
    for c in prange(nchunk):
        lo = c * _CHUNK
        hi = min(lo + _CHUNK, n)
        last_r = -1.0
        last_nu = -1.0
        c11 = c22 = c23 = 0.0
        for i in range(lo, hi):
            xa = a[i * s5]
            xb = b[i * s6]
            xnu = nu[i * s13]
            xq = q[i * s3]
            xv = v[i * s4]
            xsx = sx[i * s0]
            xsy = sy[i * s1]
            xpsi = psi[i * s2]
            xg = g[i * s12]
            p_mu0 = mu0[i * s7]
            p_ka = k_a[i * s8]
            p_ks = k_s[i * s9]
            p_a = big_a[i * s10]
            p_b = big_b[i * s11]
            if _bad_polach(xsx, xsy, xpsi, xq, xv, xa, xb, p_mu0, p_ka, p_ks, p_a, p_b, xg,
                           xnu):  # fmt: skip
                bad[c] = 1
                fx[i] = math.nan
                fy[i] = math.nan
                continue
            r = xa / xb
            if r != last_r or xnu != last_nu:
                c11, c22, c23 = _kalker3(r, xnu)
                last_r = r
                last_nu = xnu
            t = _contact_terms(xsx, xsy, xpsi, xa, xb, xg, c11, c22, c23)
            fxi, fyi = _polach_terms(xsx, xsy, xq, xv, t[0], t[1], t[2], t[3], t[4], t[5],
                                     t[6], p_ka, p_ks, p_mu0, p_a, p_b)  # fmt: skip
            fx[i] = fxi
            fy[i] = fyi
    return fx, fy, bad.sum() == 0


_polach_many_par = njit(cache=True, parallel=True, error_model="numpy")(_polach_many_py)
_polach_many_ser = njit(cache=True, error_model="numpy")(_polach_many_py)


def polach_many(args, n):
    """Run the Polach kernel on 1-d float64 arrays (length n or 1); serial for small n."""
    kernel = _polach_many_par if n >= _PARALLEL_MIN else _polach_many_ser
    return kernel(*args, n)


# --- WILAC ----------------------------------------------------------------------------------


def pack_wilac(params):
    """Pack a :class:`~railadhesion.models.wilac.WilacParameters` into one float64 array.

    Returns
    -------
    numpy.ndarray, shape (23 + 80 T,)
        ``packed[0:22]``: ``[Q_ref, v_ref, Q_low, Q_high, v_low, v_high, m1, s1, m2, s2,
        m3, s3, k_A_low, k_A_high, k_S_low, k_S_high, mu0_low, mu0_high, A_low, A_high,
        B_low, B_high]``, i.e. the normalisation, the calibrated ranges (Q and v are clamped
        into them), the three erf transitions (midpoint, width) [µl/s] and the clipping bounds
        of the five Polach parameters; ``packed[22]``: T, the largest number of terms of any
        regression; ``packed[23:]``: the regressions, an array of shape (4, 5, T, 4) in C
        order: for condition i (dry, damp2, damp1, wet), parameter j (k_A, k_S, mu0, A, B)
        and term k, ``(coefficient, f1, f2, f3)`` with the factor indices f into
        ``(Q', v', 1/Q', 1/v', exp(Q'), exp(v'))`` stored as floats, -1 for none; unused terms
        have coefficient 0.

    Examples
    --------
    >>> from railadhesion.models.wilac import default_wilac_parameters
    >>> packed = pack_wilac(default_wilac_parameters())
    >>> packed.dtype, (packed.size - 23) % 80, packed[6:12].tolist()
    (dtype('float64'), 0, [15.0, 5.0, 30.0, 3.0, 50.0, 7.0])
    """
    from railadhesion.models.wilac import PHYSICAL_BOUNDS, POLACH_PARAMETER_NAMES, WILAC_CONDITIONS

    plan = params._scalar_plan
    nterm = max(len(plan[c][j][0]) for c in WILAC_CONDITIONS for j in range(5))
    regression = np.zeros((4, 5, nterm, 4))
    regression[..., 1:] = -1.0
    for i, cond in enumerate(WILAC_CONDITIONS):
        for j in range(5):
            for k, (idx, coef) in enumerate(plan[cond][j][0]):
                regression[i, j, k, 0] = coef
                for m, f in enumerate(idx):
                    regression[i, j, k, 1 + m] = f
    header = np.empty(HEADER_SIZE + 1)
    header[0] = params.normal_force_ref
    header[1] = params.speed_ref
    header[2:4] = params.normal_force_range
    header[4:6] = params.speed_range
    header[6:12] = np.ravel([(t.midpoint, t.width) for t in params.transitions])
    header[12:22] = np.ravel([PHYSICAL_BOUNDS[p] for p in POLACH_PARAMETER_NAMES])
    header[22] = nterm
    return np.concatenate([header, regression.ravel()])


@njit(cache=True, error_model="numpy")
def _regression_value(packed, nterm, i, j, fac, lo, hi):
    """Value of regression (condition i, parameter j) of a packed set, clipped to [lo, hi]."""
    total = 0.0
    base = HEADER_SIZE + 1 + (i * 5 + j) * nterm * 4
    for k in range(nterm):
        p = base + 4 * k
        value = packed[p]
        if value == 0.0:
            continue
        for m in range(3):
            f = int(packed[p + 1 + m])
            if f >= 0:
                value = value * fac[f]
        total = total + value
    return min(max(total, lo), hi)


@njit(cache=True, error_model="numpy")
def _wilac_contact(sx, sy, psi, q, v, a, b, w, g, c11, c22, c23, header):
    """WILAC forces of one validated contact with known Kalker coefficients."""
    e1 = 0.5 * (math.erf((w - header[6]) / header[7]) + 1.0)
    e2 = 0.5 * (math.erf((w - header[8]) / header[9]) + 1.0)
    e3 = 0.5 * (math.erf((w - header[10]) / header[11]) + 1.0)
    weights = (1.0 - e1, e1 - e2, e2 - e3, e3)
    qn = min(max(q, header[2]), header[3]) / header[0]
    vn = min(max(v, header[4]), header[5]) / header[1]
    fac = (qn, vn, 1.0 / qn, 1.0 / vn, math.exp(qn), math.exp(vn))
    nterm = int(header[HEADER_SIZE])
    t = _contact_terms(sx, sy, psi, a, b, g, c11, c22, c23)
    fx = 0.0
    fy = 0.0
    for i in range(4):
        f = weights[i]
        if f == 0.0:
            continue
        k_a = _regression_value(header, nterm, i, 0, fac, header[12], header[13])
        k_s = _regression_value(header, nterm, i, 1, fac, header[14], header[15])
        mu0 = _regression_value(header, nterm, i, 2, fac, header[16], header[17])
        big_a = _regression_value(header, nterm, i, 3, fac, header[18], header[19])
        big_b = _regression_value(header, nterm, i, 4, fac, header[20], header[21])
        fxi, fyi = _polach_terms(sx, sy, q, v, t[0], t[1], t[2], t[3], t[4], t[5], t[6],
                                 k_a, k_s, mu0, big_a, big_b)  # fmt: skip
        fx = fx + f * fxi
        fy = fy + f * fyi
    return fx, fy


@njit(cache=True, error_model="numpy")
def wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11, c22,
                 c23, packed):  # fmt: skip
    """WILAC forces (fx, fy) [N] of one contact; see the module docstring (no validation).

    ``packed`` comes from :func:`pack_wilac`; ``c11 <= 0`` looks the Kalker coefficients up
    from a/b and nu.
    """
    if not c11 > 0.0:
        c11, c22, c23 = _kalker3(a / b, nu)
    return _wilac_contact(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G,
                          c11, c22, c23, packed)  # fmt: skip


@njit(cache=True, error_model="numpy")
def wilac_checked(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11,
                  c22, c23, packed):  # fmt: skip
    """:func:`wilac_scalar` with validation: (fx, fy, ok); ``ok`` False if an argument is out of
    range (forces NaN)."""
    bad = _first_bad(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, 1.0, 1.0, 1.0,
                     0.0, 0.0)  # fmt: skip
    if bad >= 0 or not 0.0 <= water_flow < math.inf:
        return math.nan, math.nan, False
    fx, fy = wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu,
                          c11, c22, c23, packed)  # fmt: skip
    return fx, fy, True


def _wilac_many_py(sx, sy, psi, q, v, a, b, w, g, nu, packed, n):
    """WILAC over n contacts (1-d float64 arrays of length n or 1); returns (fx, fy, ok)."""
    fx = np.empty(n)
    fy = np.empty(n)
    s0 = 1 if sx.size > 1 else 0
    s1 = 1 if sy.size > 1 else 0
    s2 = 1 if psi.size > 1 else 0
    s3 = 1 if q.size > 1 else 0
    s4 = 1 if v.size > 1 else 0
    s5 = 1 if a.size > 1 else 0
    s6 = 1 if b.size > 1 else 0
    s7 = 1 if w.size > 1 else 0
    s8 = 1 if g.size > 1 else 0
    s9 = 1 if nu.size > 1 else 0
    nchunk = (n + _CHUNK - 1) // _CHUNK
    bad = np.zeros(nchunk, dtype=np.uint8)
    for c in prange(nchunk):
        lo = c * _CHUNK
        hi = min(lo + _CHUNK, n)
        last_r = -1.0
        last_nu = -1.0
        c11 = c22 = c23 = 0.0
        for i in range(lo, hi):
            xa = a[i * s5]
            xb = b[i * s6]
            xnu = nu[i * s9]
            xq = q[i * s3]
            xv = v[i * s4]
            xw = w[i * s7]
            xsx = sx[i * s0]
            xsy = sy[i * s1]
            xpsi = psi[i * s2]
            xg = g[i * s8]
            if _bad_polach(xsx, xsy, xpsi, xq, xv, xa, xb, 1.0, 1.0, 1.0, 0.0, 0.0, xg,
                           xnu) or not (0.0 <= xw < math.inf):  # fmt: skip
                bad[c] = 1
                fx[i] = math.nan
                fy[i] = math.nan
                continue
            r = xa / xb
            if r != last_r or xnu != last_nu:
                c11, c22, c23 = _kalker3(r, xnu)
                last_r = r
                last_nu = xnu
            fxi, fyi = _wilac_contact(xsx, xsy, xpsi, xq, xv, xa, xb, xw, xg, c11, c22, c23,
                                      packed)  # fmt: skip
            fx[i] = fxi
            fy[i] = fyi
    return fx, fy, bad.sum() == 0


_wilac_many_par = njit(cache=True, parallel=True, error_model="numpy")(_wilac_many_py)
_wilac_many_ser = njit(cache=True, error_model="numpy")(_wilac_many_py)


def wilac_many(args, packed, n):
    """Run the WILAC kernel on 1-d float64 arrays (length n or 1); serial for small n."""
    kernel = _wilac_many_par if n >= _PARALLEL_MIN else _wilac_many_ser
    return kernel(*args, packed, n)


# --- helpers for the public functions ---------------------------------------------------------


def flatten_args(arrays):
    """Broadcast float64 arrays to one shape; return (shape, n, 1-d arrays of length n or 1).

    Arrays of one element stay of length 1 and arrays of the full shape are raveled (no copy
    if contiguous); only partly broadcast arrays are materialised.
    """
    shape = np.broadcast_shapes(*(x.shape for x in arrays))
    n = math.prod(shape)
    flat = []
    for x in arrays:
        if x.size == 1:
            flat.append(x.reshape(1))
        elif x.shape == shape:
            flat.append(np.ascontiguousarray(x).reshape(-1))
        else:
            flat.append(np.ascontiguousarray(np.broadcast_to(x, shape)).reshape(-1))
    return shape, n, flat
