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

``fletcher_scalar(creep, slope, inverse_mu) -> (adhesion, d_creep, d_slope, d_inverse_mu)``
    Fletcher's (2013) 2D curve with k_s = 1 (eqs. (8)-(12) in closed form, the law of
    :func:`railadhesion.models.twod.fletcher`) as the adhesion coefficient of a creep
    magnitude, parametrised by its initial slope and the inverse of its saturation level
    (``inverse_mu = 0``: the straight line of the limit mu -> inf), with its partial
    derivatives (used by the on-board monitor's estimator).

``polach_curve_scalar(creep, slope, inverse_mu, ratio) -> (adhesion, d_creep, d_slope)``
    Polach's (2005) curve for pure longitudinal creepage and constant friction (A = 1, the
    law of :func:`railadhesion.models.polach.polach_forces`) parametrised the same way, with
    ``ratio = k_S / k_A``.

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
import os

import numba
import numpy as np
from numba import carray, njit, prange
from numba.core import cgutils, types
from numba.extending import intrinsic

from railadhesion.contact.kalker import _AOB_MAX, _AOB_MIN, _C33_GT_ROWS, _G_MIN, _NROW, _ROWS

__all__ = [
    "HEADER_SIZE",
    "exp_scalar",
    "fletcher_scalar",
    "kalker_scalar",
    "pack_wilac",
    "polach_curve_scalar",
    "polach_checked",
    "polach_longitudinal",
    "polach_scalar",
    "wilac_condition_parameters",
    "wilac_scalar",
    "wilac_weights",
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

#: Number of header values of a packed WILAC set (:func:`pack_wilac`).
HEADER_SIZE = 22
#: Below this many contacts the serial kernels are used: thread start-up and, on a busy
#: machine, waiting for a descheduled thread at the end of the parallel loop cost more than
#: the work (measured: 10^4 contacts took 60 ms with 2 threads on a loaded machine, 0.3 ms
#: serially).
_PARALLEL_MIN = 100_000
_PARALLEL_MIN_WILAC = 20_000


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
    """C11, C22, C23 of :func:`kalker_scalar`."""
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
def _contact_forces(creep_x, creep_y, spin, normal_force, speed, data):
    """:func:`polach_scalar` with one contact's fixed data ``data`` = (a, b, G, nu, c11, c22,
    c23, k_A, k_S, mu0, A, B) (:class:`~railadhesion.models.polach.PolachContact`)."""
    return polach_scalar(creep_x, creep_y, spin, normal_force, speed, data[0], data[1], data[2],
                         data[3], data[4], data[5], data[6], data[7], data[8], data[9], data[10],
                         data[11])  # fmt: skip


def contact_kernel():
    """:func:`_contact_forces` for float64 arguments only: other numbers (ints, NumPy
    scalars) are converted by numba's dispatcher instead of compiling new versions."""
    if not _contact_forces.signatures:
        _contact_forces.compile("UniTuple(float64, 2)(float64, float64, float64, float64, "
                                "float64, float64[::1])")  # fmt: skip
        _contact_forces.disable_compile()
    return _contact_forces


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


# Rational approximation of arctan on [0, 0.66] after range reduction (coefficients of
# S. L. Moshier's Cephes library, ``atan.c``): within 1 ulp of libm's atan, and free of calls
# and branches so that loops over it vectorise.
_AT_P = (-8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1,
         -1.228866684490136173410e2, -6.485021904942025371773e1)  # fmt: skip
_AT_Q = (2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2,
         4.853903996359136964868e2, 1.945506571482613964425e2)  # fmt: skip
_AT_MOREBITS = 6.123233995736765886130e-17
_AT_T3P8 = 2.41421356237309504880  # tan(3 pi/8)


# exp(x) = 2^n exp(r), n = round(x/ln 2), r = x - n ln 2 (ln 2 split in two: fdlibm's
# constants, exact products for |n| < 2^11), exp(r) by its Taylor series to r^13 (|r| <= 0.35:
# truncation below 1e-17 relative): within an ulp of libm's exp, vectorisable.
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_LOG2E = 1.4426950408889634
_EXP_C = tuple(1.0 / math.factorial(k) for k in range(14))


@njit(cache=True, error_model="numpy")
def _atan_nonneg(x):
    """arctan(x) for x >= 0 (within an ulp of ``math.atan``), vectorisable."""
    big = x > _AT_T3P8
    mid = x > 0.66
    xr = -1.0 / x if big else ((x - 1.0) / (x + 1.0) if mid else x)
    y0 = _PI / 2.0 if big else (_PI / 4.0 if mid else 0.0)
    extra = _AT_MOREBITS if big else (0.5 * _AT_MOREBITS if mid else 0.0)
    z = xr * xr
    pz = (((_AT_P[0] * z + _AT_P[1]) * z + _AT_P[2]) * z + _AT_P[3]) * z + _AT_P[4]
    qz = ((((z + _AT_Q[0]) * z + _AT_Q[1]) * z + _AT_Q[2]) * z + _AT_Q[3]) * z + _AT_Q[4]
    return y0 + ((xr * (z * pz / qz) + xr) + extra)


# --- batched kernels --------------------------------------------------------------------------
#
# Contacts are processed in chunks of _BATCH. Each stage of a model is one short loop over the
# chunk in a function of its own: few arrays per loop (LLVM then needs few run-time aliasing
# checks), no calls that do not inline, no float -> int64 conversions (AVX2 has none), so that
# every stage compiles to SIMD code (four doubles per instruction). Contacts that need care
# (zero creepage, magnitudes beyond 1e+-150, friction gone, exponents below -700) are flagged
# and recomputed by the scalar code (:func:`_contact_terms`, :func:`_polach_terms`), which
# follows the reference operation by operation. Stages and the scalar code use the same
# operations in the same order, so that results agree to rounding (exp and arctan: within an
# ulp of libm's).

#: Contacts per chunk (the chunk's scratch rows stay in the level-2 cache).
_BATCH = 512
# exp(x) = 2^n exp(r): 2^n is built from n's bits; adding 1.5 2^52 to the float n leaves n in
# the low bits of the sum (|n| < 2^51), which integer SIMD operations then shift into place.
_ROUND_SHIFT = 6755399441055744.0
_ROUND_SHIFT_BITS = 0x4338000000000000
_E2, _E3, _E4, _E5, _E6, _E7 = _EXP_C[2:8]
_E8, _E9, _E10, _E11, _E12, _E13 = _EXP_C[8:14]


@njit(cache=True, error_model="numpy")
def _fill(out, value, m):
    """out[:m] = value (a loop: slice assignment would compile numba's shape-error code)."""
    for k in range(m):
        out[k] = value


@njit(cache=True, error_model="numpy")
def _chunk(arr, const, lo, hi):
    """arr[lo:hi], or the first hi - lo values of ``const`` (arr repeated) if arr has one."""
    if arr.size == 1:
        return const[: hi - lo]
    return arr[lo:hi]


# Allowed ranges of the arguments, as (low, low if closed else NaN, high, high if closed else
# NaN): x is in range if (x > low or x == low_closed) and (x < high or x == high_closed).
_INF = math.inf
_NAN = math.nan
_FINITE = (-_INF, _NAN, _INF, _NAN)
_POSITIVE = (0.0, _NAN, _INF, _NAN)
_NONNEGATIVE = (0.0, 0.0, _INF, _NAN)
_FRACTION = (0.0, _NAN, 1.0, 1.0)  # (0, 1]
_POISSON = (0.0, 0.0, 0.5, 0.5)  # [0, 0.5]


@njit(cache=True, error_model="numpy", inline="always")
def _count_outside(xs, bounds, m):
    """Number of the first m values of xs outside ``bounds`` (see _FINITE; NaN counts)."""
    low, low_closed, high, high_closed = bounds
    nbad = 0
    for k in range(m):
        x = xs[k]
        nbad += 0 if ((x > low) | (x == low_closed)) & ((x < high) | (x == high_closed)) else 1
    return nbad


@njit(cache=True, error_model="numpy", inline="always")
def _spin_factors(ratio, kpsi, tmp, tmp2, m):
    """Polach's K_psi = 1 + 6.3 (1 - exp(-a/b)) (tmp, tmp2: scratch)."""
    for k in range(m):
        tmp[k] = -ratio[k]
    _exp_into(tmp, kpsi, tmp2, m)
    for k in range(m):
        kpsi[k] = 1.0 + 6.3 * (1.0 - kpsi[k])


#: The most distinct (a/b, nu) pairs a chunk remembers before it looks contacts up one by one.
_MEMO = 8


@njit(cache=True, error_model="numpy", inline="always")
def _kalker_memo(ratio, nus, c11, c22, c23, kpsi, m):
    """Kalker's coefficients and K_psi contact by contact, each distinct (a/b, nu) looked up
    once (an a/b that is constant up to rounding takes a few values). Stops at the
    (_MEMO + 1)-th distinct pair; returns (contacts done, False if an a/b was out of range)."""
    memo = np.empty((_MEMO, 6))
    memo[0, 0] = math.nan
    used = 0
    last = 0
    ok = True
    for k in range(m):
        r = ratio[k]
        nk = nus[k]
        j = last
        if not (memo[j, 0] == r and memo[j, 1] == nk):
            j = -1
            for e in range(used):
                if memo[e, 0] == r and memo[e, 1] == nk:
                    j = e
                    break
            if j < 0:
                if used == _MEMO:
                    return k, ok
                j = used
                used += 1
                memo[j, 0] = r
                memo[j, 1] = nk
                if not _AOB_MIN <= r <= _AOB_MAX:
                    ok = False
                    r = 1.0
                memo[j, 2], memo[j, 3], memo[j, 4] = _kalker3(r, nk)
                memo[j, 5] = 1.0 + 6.3 * (1.0 - math.exp(-r))
            last = j
        c11[k] = memo[j, 2]
        c22[k] = memo[j, 3]
        c23[k] = memo[j, 4]
        kpsi[k] = memo[j, 5]
    return m, ok


@njit(cache=True, error_model="numpy", inline="always")
def _kalker_rows(ratio, nus, c11, c22, c23, kpsi, tmp, tmp2, m):
    """Kalker's C11, C22, C23 and Polach's K_psi per contact (tmp, tmp2: scratch); False if
    an a/b is outside Kalker's range. Few distinct (a/b, nu): each looked up once
    (:func:`_kalker_memo`); else contact by contact, K_psi vectorised."""
    done, ok = _kalker_memo(ratio, nus, c11, c22, c23, kpsi, m)
    if done == m:
        return ok
    for k in range(done, m):
        r = ratio[k]
        if not _AOB_MIN <= r <= _AOB_MAX:
            ok = False
            r = 1.0
        c11[k], c22[k], c23[k] = _kalker3(r, nus[k])
    _spin_factors(ratio[done:], kpsi[done:], tmp, tmp2, m - done)
    for k in range(done, m):  # exp(-a/b) below -700: the scalar code
        if not ratio[k] <= 700.0:
            kpsi[k] = 1.0 + 6.3 * (1.0 - math.exp(-ratio[k]))
    return ok


@njit(cache=True, error_model="numpy", inline="always")
def _exp_reduced(x):
    """exp(x) = 2^n exp(r), x clamped to [-700, 700]: (exp(r) by its Taylor series to r^13,
    n + 1.5 2^52) (see :func:`_exp_into` and :func:`exp_scalar`)."""
    x = min(max(x, -700.0), 700.0)
    nn = np.floor(x * _LOG2E + 0.5)
    r = (x - nn * _LN2_HI) - nn * _LN2_LO
    e = _E13 * r + _E12
    e = e * r + _E11
    e = e * r + _E10
    e = e * r + _E9
    e = e * r + _E8
    e = e * r + _E7
    e = e * r + _E6
    e = e * r + _E5
    e = e * r + _E4
    e = e * r + _E3
    e = e * r + _E2
    e = e * r + 1.0
    e = e * r + 1.0
    return e, nn + _ROUND_SHIFT


@njit(cache=True, error_model="numpy", inline="always")
def _exp_parts(x, e, t, m):
    """exp(x) = 2^n exp(r), x clamped to [-700, 700]: e = exp(r) and t = n + 1.5 2^52, for
    m values (:func:`_exp_reduced`; see :func:`_exp_into`)."""
    for k in range(m):
        e[k], t[k] = _exp_reduced(x[k])


@njit(cache=True, error_model="numpy")
def _exp_into(x, out, tmp, m):
    """out = exp(x) (within an ulp of libm's) for x in [-700, 700]; values beyond are those
    of the clamped x (callers flag them or recompute them). ``tmp``: scratch."""
    _exp_parts(x, out, tmp, m)
    bits = tmp.view(np.int64)
    for k in range(m):
        bits[k] = (bits[k] - _ROUND_SHIFT_BITS + 1023) << 52
    for k in range(m):
        out[k] = out[k] * tmp[k]


@njit(cache=True, error_model="numpy")
def _negated_products(fos, xs, out, m):
    for k in range(m):
        out[k] = -fos[k] * xs[k]


@njit(cache=True, error_model="numpy")
def _scale(out, xs, m):
    for k in range(m):
        out[k] = out[k] * xs[k]


# Rows of a chunk's scratch array (``rows``, shape (_POLACH_ROWS, _BATCH)): the contact's
# geometry (filled once, shared by WILAC's conditions), then scratch of one Polach evaluation.
_R_C11, _R_C22, _R_C23, _R_KPSI, _R_SC, _R_ABSYC, _R_S, _R_EPSN, _R_GC3, _R_FLAG0 = range(10)
_R_FLAG, _R_ARG, _R_EXP, _R_TMP, _R_QMU, _R_FOS, _R_E2, _R_FYS = range(10, 18)
_POLACH_ROWS = 18


@njit(cache=True, error_model="numpy", inline="always")
def _contact_rows(xs, ys, ps, as_, bs, gs, nus, rows, m, kalker, spin_free):
    """The creepage geometry of a chunk into ``rows`` (Kalker's coefficients, K_psi, s_C,
    |s_yC|, s, the eps numerator, G c^3 C23, the flags of the norms).

    ``kalker`` = (c11, c22, c23, K_psi) if a/b and nu are the same for every contact (looked
    up once per call), else (0, 0, 0, 0): looked up here. False if an a/b is out of Kalker's
    range.
    """
    c11, c22, c23, kpsi = rows[_R_C11][:m], rows[_R_C22][:m], rows[_R_C23][:m], rows[_R_KPSI][:m]
    scs, absyc, ss = rows[_R_SC][:m], rows[_R_ABSYC][:m], rows[_R_S][:m]
    epsn, gc3, flag0 = rows[_R_EPSN][:m], rows[_R_GC3][:m], rows[_R_FLAG0][:m]
    ok = True
    if kalker[0] > 0.0:
        _fill(c11, kalker[0], m)
        _fill(c22, kalker[1], m)
        _fill(c23, kalker[2], m)
        _fill(kpsi, kalker[3], m)
    else:
        for k in range(m):  # a/b
            gc3[k] = as_[k] / bs[k]
        ok = _kalker_rows(gc3, nus, c11, c22, c23, kpsi, ss, absyc, m)
    # Each stage is one short loop (few arrays: few run-time aliasing checks), compiled to
    # SIMD code; the operations are those of _contact_terms, in its order.
    for k in range(m):  # s_yC (its magnitude) and s_C
        y = ys[k]
        syc = y + ps[k] * as_[k]
        syc = syc if abs(syc) > abs(y) else y
        absyc[k] = abs(syc)
        scs[k] = math.sqrt(xs[k] * xs[k] + syc * syc)
    for k in range(m):  # s
        ss[k] = math.sqrt(xs[k] * xs[k] + ys[k] * ys[k])
    for k in range(m):  # Kalker's coefficient in the creep direction, c_jj
        u = c11[k] * xs[k]
        w = c22[k] * ys[k]
        epsn[k] = math.sqrt(u * u + w * w) / ss[k] if ss[k] > 0.0 else c22[k]
    for k in range(m):  # 1 where a norm is outside (1e-150, 1e150): hypot needed
        m1 = max(abs(xs[k]), absyc[k])
        m2 = max(abs(xs[k]), abs(ys[k]))
        m3 = max(abs(c11[k] * xs[k]), abs(c22[k] * ys[k]))
        fine = (
            ((m1 > 1e-150) & (m1 < 1e150))
            & ((m2 == 0.0) | ((m2 > 1e-150) & (m2 < 1e150)))
            & ((m3 == 0.0) | ((m3 > 1e-150) & (m3 < 1e150)))
        )
        flag0[k] = 0.0 if fine else 1.0
    for k in range(m):  # pi G a b c_jj s_C / 4 (eps times Q mu), in place of c_jj
        epsn[k] = _PI_OVER_4 * gs[k] * as_[k] * bs[k] * epsn[k] * scs[k]
    if not spin_free:
        for k in range(m):  # G c^3 C23, c = sqrt(ab)
            aa = as_[k]
            gc3[k] = gs[k] * aa * bs[k] * math.sqrt(aa * bs[k]) * c23[k]
    return ok


@njit(cache=True, error_model="numpy", inline="always")
def _polach_rows(xs, ys, ps, qs, vs, as_, bs, gs, mus, kas, kss, bas, bbs, rows, ox, oy, m,
                 const_mu, spin_free):  # fmt: skip
    """Polach's forces of a chunk into ox, oy, from the geometry of :func:`_contact_rows`
    in ``rows`` (whose other rows are scratch)."""
    c11, c22, c23, kpsi = rows[_R_C11][:m], rows[_R_C22][:m], rows[_R_C23][:m], rows[_R_KPSI][:m]
    scs, absyc, ss = rows[_R_SC][:m], rows[_R_ABSYC][:m], rows[_R_S][:m]
    epsn, gc3, flag0 = rows[_R_EPSN][:m], rows[_R_GC3][:m], rows[_R_FLAG0][:m]
    flag, arg, expo, tmp = rows[_R_FLAG][:m], rows[_R_ARG][:m], rows[_R_EXP][:m], rows[_R_TMP][:m]
    qmus, fos, e2, fys = rows[_R_QMU][:m], rows[_R_FOS][:m], rows[_R_E2][:m], rows[_R_FYS][:m]
    for k in range(m):
        flag[k] = flag0[k]
    if const_mu:
        for k in range(m):
            qmus[k] = qs[k] * mus[k]
        for k in range(m):  # friction gone (or NaN)
            flag[k] = flag[k] + (0.0 if qmus[k] > 1e-300 else 1.0)
    else:
        for k in range(m):  # exponent of exp(-B w), w = s_C V
            arg[k] = -bbs[k] * (scs[k] * vs[k])
        _exp_into(arg, expo, tmp, m)
        for k in range(m):  # Q mu, mu = mu0 ((1 - A) exp(-B w) + A); mu0 where B = 0 or A = 1
            ba = bas[k]
            mu = mus[k] * ((1.0 - ba) * expo[k] + ba)
            qmus[k] = qs[k] * (mus[k] if (bbs[k] == 0.0) | (ba == 1.0) else mu)
        for k in range(m):  # exponents below -700 (or NaN), friction gone
            fine = (arg[k] >= -700.0) & (qmus[k] > 1e-300)
            flag[k] = flag[k] + (0.0 if fine else 1.0)
    for k in range(m):  # F / s_C of Polach's force law (arctan without calls)
        qmu = qmus[k]
        eps = min(epsn[k] / qmu, _EPS_MAX)
        x = kas[k] * eps
        fos[k] = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + _atan_nonneg(kss[k] * eps)) / scs[k]
    _negated_products(fos, xs, ox, m)
    _negated_products(fos, ys, oy, m)
    if not spin_free:
        for k in range(m):  # 1 + eps_psi^2
            eps_psi = 8.0 / 3.0 * gc3[k] / as_[k] * absyc[k] / (kpsi[k] * qmus[k])
            e2[k] = 1.0 + eps_psi * eps_psi
        for k in range(m):  # Polach's F_yS (0 without spin)
            e = e2[k]
            value = gc3[k] * (ps[k] / scs[k]) * (absyc[k] / e) / e
            fys[k] = value if ps[k] != 0.0 else 0.0
        for k in range(m):
            oy[k] = oy[k] - fys[k]
        for k in range(m):  # the spin cap's factor max(mu Q, |F|)/|(fx, fy)| where it is < 1
            fxk = ox[k]
            fyk = oy[k]
            limit = max(qmus[k], fos[k] * ss[k])
            total = math.sqrt(fxk * fxk + fyk * fyk)
            cap = (fys[k] != 0.0) & (total > limit)
            tmp[k] = limit / total if cap else 1.0
        _scale(ox, tmp, m)
        _scale(oy, tmp, m)
        for k in range(m):  # forces beyond (1e-150, 1e150) where the cap's norm was taken
            mf = max(abs(ox[k]), abs(oy[k]))
            fine = (fys[k] == 0.0) | ((mf > 1e-150) & (mf < 1e150))
            flag[k] = flag[k] + (0.0 if fine else 1.0)
    for k in range(m):  # the careful scalar code where flagged
        if flag[k] != 0.0:
            t = _contact_terms(xs[k], ys[k], ps[k], as_[k], bs[k], gs[k], c11[k], c22[k],
                               c23[k])  # fmt: skip
            ox[k], oy[k] = _polach_terms(xs[k], ys[k], qs[k], vs[k], t[0], t[1], t[2], t[3],
                                         t[4], t[5], t[6], kas[k], kss[k], mus[k], bas[k],
                                         bbs[k])  # fmt: skip


@njit(cache=True, error_model="numpy")
def _outside(xs, bounds, lo, m):
    """Number of values out of ``bounds`` among xs[lo:lo + m] (xs of n values) or xs[0] (one
    value, broadcast)."""
    if xs.size == 1:
        lo, m = 0, 1
    return _count_outside(xs[lo:], bounds, m)


@njit(cache=True, error_model="numpy", inline="always")
def _shape_constants(a, b, nu):
    """(c11, c22, c23, K_psi) of a/b and nu if all three are single values (looked up once per
    call), else zeros; and True if a/b is then out of Kalker's range."""
    if a.size == 1 and b.size == 1 and nu.size == 1:
        a0, b0, nu0 = a[0], b[0], nu[0]
        if 0.0 < a0 < math.inf and 0.0 < b0 < math.inf and 0.0 <= nu0 <= 0.5:
            r0 = a0 / b0
            if not _AOB_MIN <= r0 <= _AOB_MAX:
                return (0.0, 0.0, 0.0, 0.0), True
            c11, c22, c23 = _kalker3(r0, nu0)
            return (c11, c22, c23, 1.0 + 6.3 * (1.0 - math.exp(-r0))), False
    return (0.0, 0.0, 0.0, 0.0), False


# --- WILAC ----------------------------------------------------------------------------------


#: Offset of the term counts, and of the regressions, in a packed WILAC set.
_COUNTS = HEADER_SIZE + 1
_TERMS = _COUNTS + 20
_U1, _U2, _U3 = np.uint64(1), np.uint64(2), np.uint64(3)


def pack_wilac(params):
    """Pack a :class:`~railadhesion.models.wilac.WilacParameters` into one float64 array.

    Returns
    -------
    numpy.ndarray, shape (43 + 80 T,)
        ``packed[0:22]``: ``[Q_ref, v_ref, Q_low, Q_high, v_low, v_high, m1, s1, m2, s2,
        m3, s3, k_A_low, k_A_high, k_S_low, k_S_high, mu0_low, mu0_high, A_low, A_high,
        B_low, B_high]``, i.e. the normalisation, the calibrated ranges (Q and v are clamped
        into them), the three erf transitions (midpoint, width) [µl/s] and the clipping bounds
        of the five Polach parameters; ``packed[22]``: T, the largest number of terms of any
        regression; ``packed[23:43]``: the number of terms of each regression, (4, 5) in C
        order; ``packed[43:]``: the regressions, an array of shape (4, 5, T, 4) in C order:
        for condition i (dry, damp2, damp1, wet), parameter j (k_A, k_S, mu0, A, B) and term
        k, ``(coefficient, f1, f2, f3)`` with the factor indices f into
        ``(Q', v', 1/Q', 1/v', exp(Q'), exp(v'), 1)`` stored as floats (6, the factor 1, for
        none); unused terms are zero.

    Examples
    --------
    >>> from railadhesion.models.wilac import default_wilac_parameters
    >>> packed = pack_wilac(default_wilac_parameters())
    >>> packed.dtype, (packed.size - 43) % 80, packed[6:12].tolist()
    (dtype('float64'), 0, [15.0, 5.0, 30.0, 3.0, 50.0, 7.0])
    """
    from railadhesion.models.wilac import PHYSICAL_BOUNDS, POLACH_PARAMETER_NAMES, WILAC_CONDITIONS

    plan = params._scalar_plan
    nterm = max(len(plan[c][j][0]) for c in WILAC_CONDITIONS for j in range(5))
    regression = np.zeros((4, 5, nterm, 4))
    counts = np.zeros((4, 5))
    for i, cond in enumerate(WILAC_CONDITIONS):
        for j in range(5):
            counts[i, j] = len(plan[cond][j][0])
            for k, (idx, coef) in enumerate(plan[cond][j][0]):
                regression[i, j, k] = (coef, 6.0, 6.0, 6.0)
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
    return np.concatenate([header, counts.ravel(), regression.ravel()])


@njit(cache=True, error_model="numpy")
def _factors(q, v, packed, fac):
    """Fill ``fac`` (7) with Q', v', 1/Q', 1/v', exp(Q'), exp(v'), 1 (inputs clamped)."""
    qn = min(max(q, packed[2]), packed[3]) / packed[0]
    vn = min(max(v, packed[4]), packed[5]) / packed[1]
    fac[0] = qn
    fac[1] = vn
    fac[2] = 1.0 / qn
    fac[3] = 1.0 / vn
    fac[4] = math.exp(qn)
    fac[5] = math.exp(vn)
    fac[6] = 1.0


@njit(cache=True, error_model="numpy")
def _condition_parameters(packed, i, fac, out):
    """The five clipped Polach parameters of condition i into out[5 i : 5 i + 5]."""
    nterm = int(packed[HEADER_SIZE])
    for j in range(5):
        base = _TERMS + (i * 5 + j) * nterm * 4
        terms = packed[base : base + 4 * int(packed[_COUNTS + i * 5 + j])]
        total = 0.0
        # unsigned positions, and factor indices masked into 0-7 (they are 0-6): the compiler
        # then knows them non-negative and leaves out the negative-index wraparound code
        for k in range(terms.size // 4):
            p = np.uint64(4 * k)
            total = total + terms[p] * fac[int(terms[p + _U1]) & 7] * fac[
                int(terms[p + _U2]) & 7] * fac[int(terms[p + _U3]) & 7]  # fmt: skip
        out[5 * i + j] = min(max(total, packed[12 + 2 * j]), packed[13 + 2 * j])


@njit(cache=True, error_model="numpy")
def _weights(w, packed):
    e1 = 0.5 * (math.erf((w - packed[6]) / packed[7]) + 1.0)
    e2 = 0.5 * (math.erf((w - packed[8]) / packed[9]) + 1.0)
    e3 = 0.5 * (math.erf((w - packed[10]) / packed[11]) + 1.0)
    return 1.0 - e1, e1 - e2, e2 - e3, e3


@njit(cache=True, error_model="numpy")
def _wilac_blend(sx, sy, q, v, t, weights, pars):
    """Blend of the Polach forces of the conditions with non-zero weight (``pars`` holds
    their parameters, (k_A, k_S, mu0, A, B) per condition)."""
    fx = 0.0
    fy = 0.0
    for i in range(4):
        f = weights[i]
        if f == 0.0:
            continue
        b = 5 * i
        fxi, fyi = _polach_terms(sx, sy, q, v, t[0], t[1], t[2], t[3], t[4], t[5], t[6],
                                 pars[b], pars[b + 1], pars[b + 2], pars[b + 3],
                                 pars[b + 4])  # fmt: skip
        fx = fx + f * fxi
        fy = fy + f * fyi
    return fx, fy


@intrinsic
def _stack_doubles(typingctx, n):
    """A pointer to ``n`` float64 (a compile-time constant) on the calling function's stack:
    scratch space without a heap allocation, so that the scalar laws need no numba runtime and
    can be compiled ahead of time (:mod:`railadhesion.export.native`)."""
    if not isinstance(n, types.IntegerLiteral):
        return None
    size = n.literal_value

    def codegen(context, builder, signature, args):
        return cgutils.alloca_once(builder, context.get_value_type(types.float64), size=size)

    return types.CPointer(types.float64)(n), codegen


@njit(cache=True, error_model="numpy")
def wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11, c22,
                 c23, packed):  # fmt: skip
    """WILAC forces (fx, fy) [N] of one contact; see the module docstring (no validation).

    ``packed`` comes from :func:`pack_wilac`; ``c11 <= 0`` looks the Kalker coefficients up
    from a/b and nu.
    """
    if not c11 > 0.0:
        c11, c22, c23 = _kalker3(a / b, nu)
    weights = _weights(water_flow, packed)
    scratch = carray(_stack_doubles(27), 27)  # on the stack: the factors, then the parameters
    fac = scratch[:7]
    pars = scratch[7:]
    _factors(normal_force, speed, packed, fac)
    for i in range(4):
        if weights[i] != 0.0:
            _condition_parameters(packed, i, fac, pars)
    t = _contact_terms(creep_x, creep_y, spin, a, b, G, c11, c22, c23)
    return _wilac_blend(creep_x, creep_y, normal_force, speed, t, weights, pars)


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


# Rows of WILAC's chunk scratch after Polach's (_POLACH_ROWS): the four weights, the seven
# regression factors (Q', v', 1/Q', 1/v', exp(Q'), exp(v'), 1), one condition's five Polach
# parameters and its forces.
_R_WEIGHT = _POLACH_ROWS
_R_FACTOR = _R_WEIGHT + 4
_R_PARAM = _R_FACTOR + 7
_R_CX = _R_PARAM + 5
_R_CY = _R_CX + 1
_WILAC_ROWS = _R_CY + 1

@njit(cache=True, error_model="numpy", inline="always")
def _weight_rows(ws, packed, rows, m):
    """The four weights of :func:`_weights` per contact (recomputed only when w changes)."""
    w0, w1, w2, w3 = rows[_R_WEIGHT][:m], rows[_R_WEIGHT + 1][:m], rows[_R_WEIGHT + 2][:m], \
        rows[_R_WEIGHT + 3][:m]
    last = math.nan
    f0 = f1 = f2 = f3 = 0.0
    for k in range(m):
        wk = ws[k]
        if wk != last:
            f0, f1, f2, f3 = _weights(wk, packed)
            last = wk
        w0[k] = f0
        w1[k] = f1
        w2[k] = f2
        w3[k] = f3


@njit(cache=True, error_model="numpy", inline="always")
def _factor_rows(qs, vs, packed, rows, m):
    """The regression factors of :func:`_factors` per contact."""
    qn, vn = rows[_R_FACTOR][:m], rows[_R_FACTOR + 1][:m]
    q_low, q_high, q_ref, v_low, v_high, v_ref = (packed[2], packed[3], packed[0], packed[4],
                                                  packed[5], packed[1])  # fmt: skip
    for k in range(m):  # Q', v': clamped, normalised
        qn[k] = min(max(qs[k], q_low), q_high) / q_ref
        vn[k] = min(max(vs[k], v_low), v_high) / v_ref
    iq, iv = rows[_R_FACTOR + 2][:m], rows[_R_FACTOR + 3][:m]
    for k in range(m):
        iq[k] = 1.0 / qn[k]
        iv[k] = 1.0 / vn[k]
    eq, ev = rows[_R_FACTOR + 4][:m], rows[_R_FACTOR + 5][:m]
    _exp_into(qn, eq, rows[_R_TMP], m)
    _exp_into(vn, ev, rows[_R_TMP], m)
    for k in range(m):  # beyond [-700, 700] (a parameter set of huge ranges): libm's exp
        if not (qn[k] <= 700.0 and vn[k] <= 700.0):
            eq[k] = math.exp(qn[k])
            ev[k] = math.exp(vn[k])
    _fill(rows[_R_FACTOR + 6], 1.0, m)


@njit(cache=True, error_model="numpy", inline="always")
def _add_term(out, coef, f1, f2, f3, m):
    """out += coef f1 f2 f3 (in this order, as :func:`_condition_parameters`)."""
    for k in range(m):
        out[k] = out[k] + coef * f1[k] * f2[k] * f3[k]


@njit(cache=True, error_model="numpy", inline="always")
def _clip(out, low, high, m):
    for k in range(m):
        out[k] = min(max(out[k], low), high)


@njit(cache=True, error_model="numpy", inline="always")
def _regression_row(packed, i, j, rows, out, m):
    """Polach parameter j of condition i per contact, as :func:`_condition_parameters` (the
    same terms in the same order)."""
    nterm = int(packed[HEADER_SIZE])
    base = _TERMS + (i * 5 + j) * nterm * 4
    _fill(out, 0.0, m)
    for t in range(int(packed[_COUNTS + i * 5 + j])):
        p = base + 4 * t
        _add_term(out, packed[p], rows[_R_FACTOR + int(packed[p + 1])],
                  rows[_R_FACTOR + int(packed[p + 2])], rows[_R_FACTOR + int(packed[p + 3])],
                  m)  # fmt: skip
    _clip(out, packed[12 + 2 * j], packed[13 + 2 * j], m)


@njit(cache=True, error_model="numpy", inline="always")
def _count_nonzero(xs, m):
    count = 0
    for k in range(m):
        count += 1 if xs[k] != 0.0 else 0
    return count


@njit(cache=True, error_model="numpy", inline="always")
def _blend(ox, oy, weights, cx, cy, m):
    """(ox, oy) += weight * (cx, cy) where the weight is not zero."""
    for k in range(m):
        f = weights[k]
        ox[k] = ox[k] + (f * cx[k] if f != 0.0 else 0.0)
        oy[k] = oy[k] + (f * cy[k] if f != 0.0 else 0.0)


# --- batched drivers --------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", inline="always")
def _batch_outside(sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a, big_b, w, lo, m):
    """Number of arguments out of the ranges of polach_forces and wilac_forces among contacts
    lo to lo + m."""
    return (_outside(sx, _FINITE, lo, m) + _outside(sy, _FINITE, lo, m)
            + _outside(psi, _FINITE, lo, m) + _outside(q, _POSITIVE, lo, m)
            + _outside(v, _NONNEGATIVE, lo, m) + _outside(a, _POSITIVE, lo, m)
            + _outside(b, _POSITIVE, lo, m) + _outside(g, _POSITIVE, lo, m)
            + _outside(nu, _POISSON, lo, m) + _outside(mu0, _POSITIVE, lo, m)
            + _outside(k_a, _FRACTION, lo, m) + _outside(k_s, _FRACTION, lo, m)
            + _outside(big_a, _NONNEGATIVE, lo, m) + _outside(big_b, _NONNEGATIVE, lo, m)
            + _outside(w, _NONNEGATIVE, lo, m))  # fmt: skip


@njit(cache=True, error_model="numpy", nogil=True)
def _batch_chunks(sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a, big_b, w, packed, fx,
                  fy, first, last, wilac):  # fmt: skip
    """Polach's (``wilac`` False) or WILAC's forces of chunks first to last - 1 (of _BATCH
    contacts) into fx, fy (length n). The other arguments are 1-d float64 arrays of length n
    or 1 (broadcast); Polach ignores w and packed, WILAC the five Polach parameters (pass
    valid single values). One function for both models: the shared stages are compiled once.

    Returns the number of chunks with an argument out of range (their forces are NaN; the
    caller then runs the reference validation to raise the error naming it).

    WILAC, per chunk: the contact geometry once (shared by the conditions), the weights, the
    regression factors, then for each condition whose weight is not zero somewhere in the
    chunk its five parameters (vectorised regressions) and Polach's forces (the stages of
    :func:`_polach_rows`), blended. With single values of Q and v the parameters are computed
    once; with a single w, conditions of zero weight are skipped for the whole call.
    """
    n = fx.size
    m0 = max(min(_BATCH, n), 1)
    # arguments of one value, repeated over a chunk
    single = np.empty((15, m0))
    for j, x in enumerate((sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a, big_b, w)):
        _fill(single[j], x[0], m0)
    k_sx, k_sy, k_psi_, k_q, k_v = single[0], single[1], single[2], single[3], single[4]
    k_a_, k_b, k_g, k_nu, k_mu0 = single[5], single[6], single[7], single[8], single[9]
    k_ka, k_ks, k_ba, k_bb, k_w = single[10], single[11], single[12], single[13], single[14]
    kalker, shape_bad = _shape_constants(a, b, nu)
    spin_free = psi.size == 1 and psi[0] == 0.0
    const_mu = big_a.size == 1 and big_b.size == 1 and (big_b[0] == 0.0 or big_a[0] == 1.0)
    const_qv = q.size == 1 and v.size == 1
    pars = np.zeros(20)  # WILAC's parameters of single Q and v
    if wilac and const_qv:
        fac = np.empty(7)
        _factors(q[0], v[0], packed, fac)
        for i in range(4):
            _condition_parameters(packed, i, fac, pars)
    rows = np.empty((_WILAC_ROWS if wilac else _POLACH_ROWS, _BATCH))
    nbad = 0
    for c in range(first, last):
        lo = c * _BATCH
        hi = min(lo + _BATCH, n)
        m = hi - lo
        xs = _chunk(sx, k_sx, lo, hi)
        ys = _chunk(sy, k_sy, lo, hi)
        ps = _chunk(psi, k_psi_, lo, hi)
        qs = _chunk(q, k_q, lo, hi)
        vs = _chunk(v, k_v, lo, hi)
        as_ = _chunk(a, k_a_, lo, hi)
        bs = _chunk(b, k_b, lo, hi)
        gs = _chunk(g, k_g, lo, hi)
        nus = _chunk(nu, k_nu, lo, hi)
        ox = fx[lo:hi]
        oy = fy[lo:hi]
        bad = shape_bad or _batch_outside(sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a,
                                          big_b, w, lo, m) > 0  # fmt: skip
        bad = bad or not _contact_rows(xs, ys, ps, as_, bs, gs, nus, rows, m, kalker, spin_free)
        if bad:
            nbad += 1
            _fill(ox, math.nan, m)
            _fill(oy, math.nan, m)
            continue
        if wilac:
            _weight_rows(_chunk(w, k_w, lo, hi), packed, rows, m)
            if not const_qv:
                _factor_rows(qs, vs, packed, rows, m)
            _fill(ox, 0.0, m)
            _fill(oy, 0.0, m)
        # Polach's forces once (Polach), or per condition (WILAC): one call site, so that
        # the stages are compiled once
        for i in range(4 if wilac else 1):
            if wilac:
                if _count_nonzero(rows[_R_WEIGHT + i], m) == 0:
                    continue
                for j in range(5):
                    if const_qv:
                        _fill(rows[_R_PARAM + j], pars[5 * i + j], m)
                    else:
                        _regression_row(packed, i, j, rows, rows[_R_PARAM + j], m)
                kas, kss, mus = rows[_R_PARAM], rows[_R_PARAM + 1], rows[_R_PARAM + 2]
                bas, bbs = rows[_R_PARAM + 3], rows[_R_PARAM + 4]
                cx, cy = rows[_R_CX], rows[_R_CY]
                cmu = const_qv and (pars[5 * i + 4] == 0.0 or pars[5 * i + 3] == 1.0)
            else:
                kas, kss, mus = _chunk(k_a, k_ka, lo, hi), _chunk(k_s, k_ks, lo, hi), _chunk(
                    mu0, k_mu0, lo, hi)  # fmt: skip
                bas, bbs = _chunk(big_a, k_ba, lo, hi), _chunk(big_b, k_bb, lo, hi)
                cx, cy = ox, oy
                cmu = const_mu
            _polach_rows(xs, ys, ps, qs, vs, as_, bs, gs, mus, kas, kss, bas, bbs, rows, cx, cy,
                         m, cmu, spin_free)  # fmt: skip
            if wilac:
                _blend(ox, oy, rows[_R_WEIGHT + i], cx, cy, m)
    return nbad


def _read_only(x):
    """A read-only view of x (the kernels are compiled for read-only inputs only)."""
    if x.flags.writeable:
        x = x.view()
        x.flags.writeable = False
    return x


_ONE = _read_only(np.ones(1))
_ZERO = _read_only(np.zeros(1))


#: Tasks per thread of a parallel call (handed out one by one: a thread that gets ahead, or
#: one that a busy machine holds up, is balanced by the others).
_TASKS_PER_THREAD = 4
_POOL: dict = {}


def _thread_pool(nthreads: int):
    """The process's pool of kernel threads: created on first use, anew with more threads
    if asked, and anew in a forked child (whose copy of the pool has no threads)."""
    from concurrent.futures import ThreadPoolExecutor

    key = (os.getpid(), nthreads)
    pool = _POOL.get("pool")
    if _POOL.get("key") != key or pool is None:
        if pool is not None and _POOL["key"][0] == key[0]:
            pool.shutdown(wait=False)
        pool = ThreadPoolExecutor(max_workers=nthreads, thread_name_prefix="railadhesion-kernel")
        _POOL.update(pool=pool, key=key)
    return pool


def _run_batch(contact, params, w, packed, n, wilac, parallel_min):
    """Allocate the outputs and run the batch kernel; returns (fx, fy, ok).

    From ``parallel_min`` contacts on, the chunks are split into tasks run by
    ``numba.get_num_threads()`` threads: the kernel releases the GIL, so plain Python threads
    run it in parallel, and no second, parallel compilation of it is needed (numba's
    ``parallel=True`` would compile the whole kernel again, about 15 s on a cold cache).

    The outputs are allocated here, by NumPy: its allocations of large arrays are reused from
    call to call (and use transparent huge pages), where arrays allocated inside numba code
    are fresh pages every call (a page fault every 4 KiB: about 9 ns a contact for the two
    outputs, measured).
    """
    fx = np.empty(n)
    fy = np.empty(n)
    nchunk = (n + _BATCH - 1) // _BATCH
    nthreads = numba.get_num_threads() if n >= parallel_min else 1
    if nthreads <= 1 or nchunk < 2:
        nbad = _batch_chunks(*contact, *params, w, packed, fx, fy, 0, nchunk, wilac)
        return fx, fy, nbad == 0
    ntask = min(nchunk, _TASKS_PER_THREAD * nthreads)
    bounds = [nchunk * t // ntask for t in range(ntask + 1)]
    pool = _thread_pool(nthreads)
    tasks = [pool.submit(_batch_chunks, *contact, *params, w, packed, fx, fy, bounds[t],
                         bounds[t + 1], wilac) for t in range(ntask)]  # fmt: skip
    nbad = sum(task.result() for task in tasks)
    return fx, fy, nbad == 0


def polach_many(args, n):
    """Polach's forces of n contacts: ``args`` are the 14 arguments of polach_forces (order
    of its signature) as read-only 1-d float64 arrays of length n or 1 (:func:`flatten_args`);
    returns (fx, fy, ok), ``ok`` False if an argument is out of range. Serial below
    _PARALLEL_MIN contacts."""
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu = args
    return _run_batch((sx, sy, psi, q, v, a, b, g, nu), (mu0, k_a, k_s, big_a, big_b), _ZERO,
                      _ZERO, n, False, _PARALLEL_MIN)  # fmt: skip


def wilac_many(args, packed, n):
    """WILAC's forces of n contacts: ``args`` are the 10 arrays of wilac_forces (creepages,
    Q, V, a, b, w, G, nu) of length n or 1, ``packed`` from :func:`pack_wilac`; returns
    (fx, fy, ok). Serial below _PARALLEL_MIN_WILAC contacts."""
    sx, sy, psi, q, v, a, b, w, g, nu = args
    return _run_batch((sx, sy, psi, q, v, a, b, g, nu), (_ONE, _ONE, _ONE, _ZERO, _ZERO), w,
                      _read_only(packed), n, True, _PARALLEL_MIN_WILAC)  # fmt: skip


# --- Fletcher's 2D curve (scalar) ----------------------------------------------------------


@njit(cache=True, error_model="numpy")
def fletcher_scalar(creep, slope, inverse_mu):
    """Fletcher's (2013) 2D creep curve with k_s = 1 and its partial derivatives.

    ``creep`` >= 0 is the creep magnitude xi [-], ``slope`` > 0 the initial slope
    d(Q/P)/d xi = 2 k_a R / a [-], ``inverse_mu`` >= 0 the inverse 1/mu of the friction
    coefficient (the saturation level of the curve); 0 gives the limit mu -> inf, the straight
    line ``slope * creep``. Returns ``(Q/P, d/d creep, d/d slope, d/d inverse_mu)``.

    Fletcher's eqs. (8)-(12) (Proc. IMechE Part J 227(6) (2013) 529-537) reduce to
    ``Q/P = mu (1 - (c/a)**3)`` with ``c/a = max(1 - x/mu, 0)`` and ``x = 2 k_a xi R/(3 a)
    = slope * xi / 3`` (:func:`railadhesion.models.twod.fletcher`, its Notes). Written with
    u = 1 - x q (q = 1/mu): ``Q/P = x (3 - 3 x q + x**2 q**2)`` while u > 0 (finite at q = 0),
    ``1/q`` at and beyond full slip (u <= 0); d/d xi = slope u**2, d/d slope = xi u**2,
    d/d q = -x**2 (3 - 2 x q) before full slip, 0, 0, -1/q**2 beyond.
    """
    x = slope * creep / 3.0
    u = 1.0 - x * inverse_mu
    if u > 0.0:
        uu = u * u
        return (x * (3.0 - 3.0 * x * inverse_mu + x * x * inverse_mu * inverse_mu),
                slope * uu, creep * uu, -x * x * (3.0 - 2.0 * x * inverse_mu))
    return 1.0 / inverse_mu, 0.0, 0.0, -1.0 / (inverse_mu * inverse_mu)


@njit(cache=True, error_model="numpy")
def polach_curve_scalar(creep, slope, inverse_mu, ratio):
    """Polach's (2005) adhesion-creep curve without falling friction, and two derivatives.

    ``creep`` >= 0 the creep magnitude [-], ``slope`` > 0 the initial slope d(F/Q)/d creep,
    ``inverse_mu`` >= 0 the inverse of the friction coefficient mu (the curve's asymptote; 0
    gives the straight line), ``ratio`` = k_S / k_A > 0. Returns ``(F/Q, d/d creep,
    d/d slope)``.

    Polach (Wear 258 (2005) 992-1000; ``docs`` MODELS §3) for pure longitudinal creepage,
    A = 1 (no falling friction): ``F/Q = (2 mu/pi) (k_A eps/(1 + (k_A eps)**2) +
    arctan(k_S eps))`` with ``eps = K creep / mu`` (K = (pi/4) G a b C11 / Q), whose initial
    slope is ``slope = (2/pi)(k_A + k_S) K``. With ``x = k_A eps = pi slope creep q /
    (2 (1 + ratio))``: ``F/Q = (2/pi) z (1/(1 + x**2) + ratio atan(ratio x)/(ratio x))``,
    ``z = x / q``, finite at q = 0 (the line ``slope * creep``); d/d creep =
    ``slope F'(x)/(1 + ratio)`` and d/d slope = ``creep F'(x)/(1 + ratio)`` with
    ``F'(x) = (1 - x**2)/(1 + x**2)**2 + ratio/(1 + (ratio x)**2)``.
    """
    z = math.pi * slope * creep / (2.0 * (1.0 + ratio))
    x = z * inverse_mu
    y = ratio * x
    g = math.atan(y) / y if y > 1e-6 else 1.0 - y * y / 3.0
    xx = x * x
    f = 2.0 / math.pi * z * (1.0 / (1.0 + xx) + ratio * g)
    fp = (1.0 - xx) / ((1.0 + xx) * (1.0 + xx)) + ratio / (1.0 + y * y)
    return f, slope * fp / (1.0 + ratio), creep * fp / (1.0 + ratio)


# --- helpers for the public functions ---------------------------------------------------------


def flatten_args(arrays):
    """Broadcast float64 arrays to one shape; return (shape, n, 1-d arrays of length n or 1).

    Arrays of one element stay of length 1 and arrays of the full shape are raveled (no copy
    if contiguous); only partly broadcast arrays are materialised. The 1-d arrays returned are
    read-only views, whatever the inputs: the kernels then see one type for every call (numba
    compiles a kernel anew for each combination of writeable and read-only arguments).
    """
    shape = None
    for x in arrays:  # the common case: the arrays that are not 0-d all have one shape
        if x.ndim:
            if shape is None:
                shape = x.shape
            elif x.shape != shape:
                shape = np.broadcast_shapes(*(y.shape for y in arrays))
                break
    if shape is None:
        shape = ()
    n = math.prod(shape)
    flat = []
    for x in arrays:
        if x.size == 1:
            x = x.reshape(1)
        elif x.shape == shape:
            x = np.ascontiguousarray(x).reshape(-1)
        else:
            x = np.ascontiguousarray(np.broadcast_to(x, shape)).reshape(-1)
        x.flags.writeable = False  # a view: the caller's array is untouched
        flat.append(x)
    return shape, n, flat


# --- for implicit integrators (the braking step) ----------------------------------------------
#
# An implicit integrator of a braking wheelset (railadhesion.braking.step) needs, for one
# contact whose geometry and load are fixed over a step, Polach's adhesion coefficient as a
# function of the longitudinal creepage and of the speed, with both slopes (Newton's method),
# for many (axle, blended set) lanes in one loop that the compiler vectorises. polach_scalar
# cannot serve: forces only, every contact term recomputed, and the slopes by differences
# would take three calls of it per lane (about 15 times the cost; measured for the report of
# this change).
# A libm call in the loop stops its vectorisation: the exponential is exp_scalar, the scalar
# form of the batch kernels' call-free exponential.


@njit(cache=True, error_model="numpy", inline="always")
def exp_scalar(x):
    """exp(x) for one value, call-free (vectorises when inlined in a loop): the reduction and
    polynomial of the batch kernels' exponential (:func:`_exp_reduced`) and its exponent
    assembly, x clamped to [-700, 700]; within an ulp of libm's exp."""
    e, t = _exp_reduced(x)
    bits = (np.float64(t).view(np.int64) - _ROUND_SHIFT_BITS + 1023) << 52
    return e * np.int64(bits).view(np.float64)


@njit(cache=True, error_model="numpy", inline="always")
def polach_longitudinal(creep, speed, stiffness, k_A, k_S, mu0, A, B):  # noqa: N803
    """Polach's adhesion coefficient for pure longitudinal creepage, with its slopes.

    Polach (2005, Wear 258, eqs. 11-13 with the reduction factors and the falling friction
    of section 2), the same model as :func:`polach_scalar` with no lateral creepage and no
    spin, for a contact whose geometry and load are fixed: with s = ``creep`` >= 0 and
    V = ``speed``,

    * friction falling with the slip velocity, ``mu_k = mu0 [(1 - A) exp(-B s V) + A]``;
    * gradient of the tangential stress, ``eps = K s / mu_k`` with ``stiffness`` K =
      (pi/4) G a b C11 / Q [-] (per unit creepage);
    * ``mu = (2/pi) mu_k [k_A eps / (1 + (k_A eps)^2) + arctan(k_S eps)]`` = -F_x/Q.

    Returns ``(mu, dmu/ds, dmu/dV)``, the slopes analytic. A contact with no friction left
    (A = 0 and exp(-B s V) underflowed) gives (0, 0, 0), as :func:`polach_scalar` gives no
    force. Scalars in and out, no allocation, no branch, no call (exp and arctan call-free):
    vectorises when inlined in a loop over contacts.
    """
    decay = exp_scalar(-B * (creep * speed))
    mu_k = mu0 * ((1.0 - A) * decay + A)
    friction = mu_k > 0.0
    mu_k = mu_k if friction else 1.0  # no friction left: zeros below
    dmu_k = -mu0 * (1.0 - A) * B * decay  # d mu_k / d(s V)
    inv = 1.0 / mu_k
    eps = min(stiffness * creep * inv, _EPS_MAX)
    x = k_A * eps
    y = k_S * eps
    ix = 1.0 / (1.0 + x * x)
    bracket = x * ix + _atan_nonneg(y)
    dbracket = k_A * (1.0 - x * x) * ix * ix + k_S / (1.0 + y * y)  # d bracket / d eps
    deps = (stiffness - eps * dmu_k * speed) * inv  # d eps / d s
    mu = _TWO_OVER_PI * mu_k * bracket
    dmu_ds = _TWO_OVER_PI * (dmu_k * speed * bracket + mu_k * dbracket * deps)
    dmu_dv = _TWO_OVER_PI * (bracket - eps * dbracket) * dmu_k * creep
    if not friction:
        mu = dmu_ds = dmu_dv = 0.0
    return mu, dmu_ds, dmu_dv


@njit(cache=True, error_model="numpy")
def wilac_weights(water_flow, packed):
    """WILAC's blending weights (dry, damp 2, damp 1, wet) at a water flow [ul/s] (the erf
    transitions of Trummer et al. 2017, section 5.3; the function the WILAC kernel uses)."""
    return _weights(water_flow, packed)


@njit(cache=True, error_model="numpy")
def wilac_condition_parameters(normal_force, speed, packed, factors, out):
    """WILAC's Polach parameters (k_A, k_S, mu0, A, B) of the four conditions at a wheel load
    [N] and speed [m/s] into ``out`` (20 values, condition by condition): the regressions of
    Trummer et al. 2017 section 5.2 with Q' and v' clamped into the calibrated ranges and the
    results into their physical bounds, by the WILAC kernel's own functions. ``factors``:
    scratch of 7 values."""
    _factors(normal_force, speed, packed, factors)
    for i in range(4):
        _condition_parameters(packed, i, factors, out)
