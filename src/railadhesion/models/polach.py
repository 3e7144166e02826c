"""Polach's creep-force model (Polach 1999, 2005), in Kalker's sign convention.

Polach's method gives the tangential wheel-rail forces in closed form from the creepages, the
Hertzian contact ellipse and a friction coefficient. The 2005 extension adds a friction
coefficient falling with slip velocity and two factors reducing the creep stiffness in the
areas of adhesion (``k_A``) and slip (``k_S``); with ``k_A = k_S = 1`` and ``A = 1`` (or
``B = 0``) it is the original 1999 model.

Sign convention (``docs/CONVENTIONS.md``): the forces returned are exerted by the rail on the
wheel and oppose the creepages, as in Kalker's linear theory and CONTACT. Polach's papers
count forces positive along the creepages, so both of his components (spin term included) are
negated here.

References
----------
O. Polach, A fast wheel-rail forces calculation computer code, Vehicle System Dynamics 33
(Suppl.), 1999, 728-739.
O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit, Wear 258,
2005, 992-1000.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from railadhesion._labelled import labelled
from railadhesion._validate import (
    as_float_array,
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.contact.friction import falling_friction_factor, falling_friction_slope
from railadhesion.contact.kalker import (
    AOB_MAX,
    AOB_MIN,
    axis_ratio,
    kalker_law,
    kalker_rows,
    kalker_scalar,
)
from railadhesion.models.parameters import (
    MU0_PLAUSIBLE_MAX,
    PARAMETER_RANGES,
    PolachParameters,
    mu0_message,
    parameter_range_error,
    polach_parameters,
)
from railadhesion.numerics import (
    CHUNK,
    FINITE,
    FRACTION,
    NONNEGATIVE,
    POISSON,
    POSITIVE,
    as_scalars,
    atan_nonneg,
    count_outside,
    exp,
    fill,
    fill_row,
    flatten,
    hypot,
    jitable,
    kernel,
    load_row,
    output_chunk,
    run_chunks,
)
from railadhesion.plausibility import PlausibilityWarning, input_checker, warn

__all__ = [
    "Polach",
    "PolachContact",
    "polach_contact_terms",
    "polach_curve",
    "polach_force",
    "polach_forces",
    "polach_law",
    "polach_longitudinal",
    "polach_longitudinal_at",
    "polach_longitudinal_terms",
]

_TWO_OVER_PI = 2.0 / math.pi
_PI_OVER_4 = math.pi / 4.0
# The gradient eps is clipped here: the term k eps / (1 + (k eps)^2) ~ 1/(k eps) it feeds is
# then below 1e-50 of mu*Q, and squaring it cannot overflow. The spin gradient eps_psi is not
# clipped: F_yS ~ |s_yC| / (1 + eps_psi^2)^2 with eps_psi proportional to |s_yC|, so a clipped
# eps_psi would let F_yS grow without bound at huge creepages; (1 + eps_psi^2) = inf gives 0.
_EPS_MAX = 1e50
_INF = math.inf
# Upper ends of the ranges of mu0, A and B (PolachParameters' PARAMETER_RANGES, all closed):
# polach_forces accepts what a parameter set accepts.
_MU0_MAX = PARAMETER_RANGES["mu0"][1]
_A_MAX = PARAMETER_RANGES["A"][1]
_B_MAX = PARAMETER_RANGES["B"][1]
# the same ranges for the batch loop's count_outside (railadhesion.numerics.FINITE and the like)
_MU0_RANGE = (0.0, math.nan, _MU0_MAX, _MU0_MAX)
_A_RANGE = (0.0, 0.0, _A_MAX, _A_MAX)
_B_RANGE = (0.0, 0.0, _B_MAX, _B_MAX)


# --- the law (plain functions compiled where compiled code calls them) ----------------------


@jitable(inline="always")
def polach_contact_terms(sx, sy, psi, a, b, g, c11, c22, c23):
    """The parameter-independent part of Polach's model for one contact (the formulas of
    :func:`polach_forces`, Notes; shared by WILAC's four conditions):
    (s_C, s, pi G a b c_jj s_C / 4, |s_yC|, K_psi, (8/3) G c^3 C23 |s_yC| / a,
    G c^3 C23 psi / s_C), c = sqrt(ab); the last is 0 without spin or creepage."""
    syc = sy + psi * a
    syc = syc if abs(syc) > abs(sy) else sy
    sc = hypot(sx, syc)
    s = hypot(sx, sy)
    cjj = hypot(c11 * sx, c22 * sy) / s if s > 0.0 else c22
    eps_num = _PI_OVER_4 * g * a * b * cjj * sc
    abs_syc = abs(syc)
    k_psi = 1.0 + 6.3 * (1.0 - exp(-(a / b)))
    gc3c23 = g * a * b * math.sqrt(a * b) * c23
    epsp_num = 8.0 / 3.0 * gc3c23 / a * abs_syc
    fys_pre = gc3c23 * (psi / sc) if (psi != 0.0) & (sc > 0.0) else 0.0
    return sc, s, eps_num, abs_syc, k_psi, epsp_num, fys_pre


@jitable(inline="always")
def polach_force(sx, sy, q, v, sc, s, eps_num, abs_syc, k_psi, epsp_num, fys_pre, k_a, k_s,
                 mu0, big_a, big_b):  # fmt: skip
    """Polach's forces (fx, fy) [N] of one contact from its :func:`polach_contact_terms` and
    one parameter set (k_A, k_S, mu0, A, B): the falling friction at the slip velocity
    s_C V, the force law, the spin term and the spin cap of :func:`polach_forces`, Notes.
    Zero without creepage, or when friction is gone (A = 0 and exp(-B w) underflowed)."""
    qmu = q * (mu0 * falling_friction_factor(sc * v, big_a, big_b))
    eps = min(eps_num / qmu, _EPS_MAX)
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + atan_nonneg(k_s * eps)) / sc
    eps_psi = epsp_num / (k_psi * qmu)
    e2 = 1.0 + eps_psi * eps_psi  # may be inf: then F_yS = 0
    # |psi|/s_C <= 2/a and |s_yC|/e2 is bounded: this order cannot overflow. fys_pre = 0
    # (no spin): F_yS is that zero, and a loop whose spin is 0 drops the spin term and cap
    fys = fys_pre * (abs_syc / e2) / e2 if fys_pre != 0.0 else fys_pre
    fx = -f_over_sc * sx
    fy = -(f_over_sc * sy + fys)
    # spin cap at max(mu Q, |F of the creepage part|): removes only the overshoot of F_yS
    limit = max(qmu, f_over_sc * s)
    total = hypot(fx, fy)
    scale = limit / total if (fys != 0.0) & (total > limit) else 1.0
    active = (sc > 0.0) & (qmu > 0.0)
    return (fx * scale if active else 0.0), (fy * scale if active else 0.0)


@jitable(inline="always")
def polach_law(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23, k_A,
               k_S, mu0, A, B):  # fmt: skip
    """Polach's forces (fx, fy) [N] of one contact, Kalker's signs (:func:`polach_forces`,
    without validation). ``c11 <= 0`` looks Kalker's C11, C22, C23 up from a/b and nu
    (:func:`railadhesion.contact.kalker.kalker_law`); else they are used as given.

    Compiled: :func:`railadhesion.models.kernels.polach_scalar`.
    """
    if not c11 > 0.0:
        c11, c22, c23, _ = kalker_law(a / b, nu)
    t = polach_contact_terms(creep_x, creep_y, spin, a, b, G, c11, c22, c23)
    return polach_force(creep_x, creep_y, normal_force, speed, t[0], t[1], t[2], t[3], t[4],
                        t[5], t[6], k_A, k_S, mu0, A, B)  # fmt: skip


@jitable(inline="always")
def polach_curve(creep, slope, inverse_mu, ratio):
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
    ``F'(x) = (1 - x**2)/(1 + x**2)**2 + ratio/(1 + (ratio x)**2)``. Written for the on-board
    monitor's estimator; compiled: :func:`railadhesion.models.kernels.polach_curve_scalar`.
    Inlined where compiled code calls it (:func:`polach_longitudinal`, whose loops over
    braking axles then vectorise).
    """
    z = math.pi * slope * creep / (2.0 * (1.0 + ratio))
    x = z * inverse_mu
    y = ratio * x
    # g = atan(y)/y, or 1 - y**2/3 near 0: the two quotients as one division (a loop over
    # lanes, vectorised, computes both sides of a select, and divides only once)
    far = y > 1e-6
    t = (atan_nonneg(y) if far else y * y) / (y if far else 3.0)
    g = t if far else 1.0 - t
    xx = x * x
    f = 2.0 / math.pi * z * (1.0 / (1.0 + xx) + ratio * g)
    fp = (1.0 - xx) / ((1.0 + xx) * (1.0 + xx)) + ratio / (1.0 + y * y)
    return f, slope * fp / (1.0 + ratio), creep * fp / (1.0 + ratio)


@jitable(inline="always")
def polach_longitudinal(creep, speed, stiffness, k_A, k_S, mu0, A, B):  # noqa: N803
    """Polach's adhesion coefficient for pure longitudinal creepage, with its two slopes.

    The model of :func:`polach_forces` with no lateral creepage and no spin, for a contact
    whose geometry and load are fixed (a braking axle): with s = ``creep`` >= 0, V =
    ``speed`` and ``stiffness`` K = (pi/4) G a b C11 / Q [-], the friction falls with the slip
    velocity, mu_k = mu0 (:func:`~railadhesion.contact.friction.falling_friction_factor` at
    w = s V), and the force is the curve of :func:`polach_curve` at mu_k (Polach 2005, Wear
    258, eqs. for F with k_A, k_S; initial slope (2/pi)(k_A + k_S) K). Returns
    ``(mu, dmu/ds, dmu/dV)``: the slopes by the chain rule through mu_k, with
    d(F/Q)/d mu_k = (F/Q - s d(F/Q)/ds|mu_k) / mu_k (F/Q is mu_k times a function of K s /
    mu_k). No friction left (A = 0 and exp(-B w) underflowed) gives (0, 0, 0), as
    :func:`polach_law` gives no force. Call-free (vectorises when inlined in a loop).
    """
    slope, ratio = polach_longitudinal_terms(stiffness, k_A, k_S)
    return polach_longitudinal_at(creep, speed, slope, ratio, mu0, A, B)


@jitable(inline="always")
def polach_longitudinal_terms(stiffness, k_A, k_S):  # noqa: N803
    """The part of :func:`polach_longitudinal` that depends on the contact and the parameter
    set only, not on the creepage or the speed: ``(slope, ratio)``, the curve's initial slope
    (2/pi)(k_A + k_S) K and k_S / k_A (computed once per contact and set by a caller that
    evaluates the curve at many creepages, then :func:`polach_longitudinal_at`)."""
    return _TWO_OVER_PI * (k_A + k_S) * stiffness, k_S / k_A


@jitable(inline="always")
def polach_longitudinal_at(creep, speed, slope, ratio, mu0, A, B):  # noqa: N803
    """:func:`polach_longitudinal` from its :func:`polach_longitudinal_terms` ``slope`` and
    ``ratio``: ``(mu, dmu/ds, dmu/dV)``, the same numbers. Call-free."""
    w = creep * speed
    mu_k = mu0 * falling_friction_factor(w, A, B)
    dmu_k = mu0 * falling_friction_slope(w, A, B)  # d mu_k / d w
    friction = mu_k > 0.0
    mu_k = mu_k if friction else 1.0  # zeros below
    f, df_ds, _ = polach_curve(creep, slope, 1.0 / mu_k, ratio)
    df_dmu = (f - creep * df_ds) / mu_k
    if not friction:
        return 0.0, 0.0, 0.0
    return f, df_ds + df_dmu * dmu_k * speed, df_dmu * dmu_k * creep


# --- compiled entry points (numba, built on first use) ---------------------------------------

#: Compiled :func:`~railadhesion.models.polach.polach_law`: (fx, fy) of one contact, no
#: validation (its numba dispatcher, for numba code:
#: :func:`railadhesion.models.kernels.polach_scalar`).
polach_scalar = kernel(polach_law)


@jitable
def polach_bad_input(sx, sy, psi, q, v, a, b, g, nu, k_a, k_s, mu0, big_a, big_b):
    """Position (in :func:`polach_law`'s argument order) of the first argument outside the
    range :func:`polach_forces` accepts, 17 for an a/b outside Kalker's range, or -1."""
    if not math.isfinite(sx):
        return 0
    if not math.isfinite(sy):
        return 1
    if not math.isfinite(psi):
        return 2
    if not 0.0 < q < _INF:
        return 3
    if not 0.0 <= v < _INF:
        return 4
    if not 0.0 < a < _INF:
        return 5
    if not 0.0 < b < _INF:
        return 6
    if not 0.0 < g < _INF:
        return 7
    if not 0.0 <= nu <= 0.5:
        return 8
    if not 0.0 < k_a <= 1.0:
        return 12
    if not 0.0 < k_s <= 1.0:
        return 13
    if not 0.0 < mu0 <= _MU0_MAX:
        return 14
    if not 0.0 <= big_a <= _A_MAX:
        return 15
    if not 0.0 <= big_b <= _B_MAX:
        return 16
    if not AOB_MIN <= a / b <= AOB_MAX:
        return 17
    return -1


@kernel
def polach_checked(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
                   k_A, k_S, mu0, A, B):  # fmt: skip
    """:func:`~railadhesion.models.polach.polach_law` with validation: (fx, fy, bad), ``bad``
    = -1 if every argument is in range, else
    :func:`~railadhesion.models.polach.polach_bad_input` (the forces are then NaN)."""
    bad = polach_bad_input(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, k_A, k_S,
                           mu0, A, B)  # fmt: skip
    if bad >= 0:
        return math.nan, math.nan, bad
    fx, fy = polach_law(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
                        k_A, k_S, mu0, A, B)  # fmt: skip
    return fx, fy, -1


# compiled for float64 arguments only: other numbers (ints, NumPy scalars) are converted by
# numba's dispatcher instead of compiling new versions
@kernel(signature="UniTuple(float64, 2)(float64, float64, float64, float64, float64, "
        "float64[::1])")  # fmt: skip
def _contact_forces(creep_x, creep_y, spin, normal_force, speed, data):
    """:func:`polach_law` with one contact's fixed data ``data`` = (a, b, G, nu, c11, c22, c23,
    k_A, k_S, mu0, A, B) (:class:`PolachContact`)."""
    return polach_law(creep_x, creep_y, spin, normal_force, speed, data[0], data[1], data[2],
                      data[3], data[4], data[5], data[6], data[7], data[8], data[9], data[10],
                      data[11])  # fmt: skip


# Rows of the chunk buffer of the batch loops of Polach and WILAC (rows of CHUNK values): the
# contact's inputs, a/b and Kalker's coefficients first (ROW_X to ROW_C23, shared by both
# loops), then each model's own rows. One buffer, rows a constant CHUNK apart: the loop over a
# chunk reads one array at known distances and writes few, which LLVM vectorises with few
# run-time aliasing checks (a loop reading many arrays needs a check per pair and is not
# vectorised).
ROW_X, ROW_Y, ROW_PSI, ROW_Q, ROW_V, ROW_A, ROW_B, ROW_G, ROW_NU = range(9)
ROW_RATIO, ROW_C11, ROW_C22, ROW_C23 = range(9, 13)
CONTACT_ROWS = 13
_MU0, _KA, _KS, _BA, _BB = range(CONTACT_ROWS, CONTACT_ROWS + 5)
_ROWS = CONTACT_ROWS + 5
# the rows of the driver's 14 inputs, in their order
_INPUT_ROWS = (ROW_X, ROW_Y, ROW_PSI, ROW_Q, ROW_V, ROW_A, ROW_B, ROW_G, ROW_NU, _MU0, _KA, _KS,
               _BA, _BB)  # fmt: skip
#: From this many contacts the batch loop runs on ``numba.get_num_threads()`` threads
#: (below, thread start-up and waiting for a descheduled thread cost more than the work).
PARALLEL_MIN = 100_000


@jitable
def polach_count_bad(sx, sy, psi, q, v, a, b, g, nu, lo, m):
    """Number of values of the contact inputs of :func:`polach_forces` outside their ranges
    among contacts lo to lo + m (arrays of n values, or of one value for every contact)."""
    return (count_outside(sx, FINITE, lo, m) + count_outside(sy, FINITE, lo, m)
            + count_outside(psi, FINITE, lo, m) + count_outside(q, POSITIVE, lo, m)
            + count_outside(v, NONNEGATIVE, lo, m) + count_outside(a, POSITIVE, lo, m)
            + count_outside(b, POSITIVE, lo, m) + count_outside(g, POSITIVE, lo, m)
            + count_outside(nu, POISSON, lo, m))  # fmt: skip


@jitable
def polach_fixed_shape(a, b, nu, buf, c11_row, count):
    """If a, b and nu hold one value each: Kalker's C11, C22, C23 looked up once, into the
    rows ``c11_row`` to ``c11_row + 2`` (``count`` values each); returns (fixed, ok), ``ok``
    False if that a/b is outside Kalker's range."""
    if not (a.size == 1 and b.size == 1 and nu.size == 1):
        return False, True
    r = a[0] / b[0]
    ok = AOB_MIN <= r <= AOB_MAX and 0.0 <= nu[0] <= 0.5
    c11, c22, c23, _ = kalker_law(r if ok else 1.0, nu[0] if ok else 0.25)
    fill(buf[c11_row * CHUNK :], c11, count)
    fill(buf[(c11_row + 1) * CHUNK :], c22, count)
    fill(buf[(c11_row + 2) * CHUNK :], c23, count)
    return True, ok


@jitable
def chunk_coefficients(buf, fixed, m):
    """Kalker's coefficients of a chunk's contacts into rows ROW_C11 to ROW_C23 (unless
    ``fixed``: then filled once per call by :func:`polach_fixed_shape`); False if an a/b is
    outside Kalker's range."""
    if fixed:
        return True
    for k in range(m):
        buf[ROW_RATIO * CHUNK + k] = buf[ROW_A * CHUNK + k] / buf[ROW_B * CHUNK + k]
    return kalker_rows(buf, ROW_RATIO, ROW_NU, ROW_C11, CHUNK, m)


@jitable(inline="always")
def chunk_contact_terms(buf, k):
    """:func:`polach_contact_terms` of contact k of a chunk buffer."""
    return polach_contact_terms(
        buf[ROW_X * CHUNK + k], buf[ROW_Y * CHUNK + k], buf[ROW_PSI * CHUNK + k],
        buf[ROW_A * CHUNK + k], buf[ROW_B * CHUNK + k], buf[ROW_G * CHUNK + k],
        buf[ROW_C11 * CHUNK + k], buf[ROW_C22 * CHUNK + k], buf[ROW_C23 * CHUNK + k])  # fmt: skip


@jitable
def row_same(buf, row, m):
    """True if the first m values of row ``row`` of a chunk buffer are all equal
    (vectorised)."""
    base = row * CHUNK
    first = buf[base]
    ndiff = 0
    for k in range(m):
        ndiff += 0 if buf[base + k] == first else 1
    return ndiff == 0


@jitable
def chunk_same_shape(buf, m):
    """True if a chunk's contacts share one a, b, G and nu (rows ROW_A, ROW_B, ROW_G,
    ROW_NU)."""
    return (row_same(buf, ROW_A, m) and row_same(buf, ROW_B, m) and row_same(buf, ROW_G, m)
            and row_same(buf, ROW_NU, m))  # fmt: skip


@jitable
def chunk_shape_coefficients(buf):
    """Kalker's coefficients of a chunk whose contacts share one a, b and nu
    (:func:`chunk_same_shape`): looked up once, into the first value of rows ROW_C11 to
    ROW_C23; False if a/b is outside Kalker's range (as :func:`chunk_coefficients`)."""
    r = buf[ROW_A * CHUNK] / buf[ROW_B * CHUNK]
    ok = AOB_MIN <= r <= AOB_MAX
    c11, c22, c23, _ = kalker_law(r if ok else 1.0, buf[ROW_NU * CHUNK])
    buf[ROW_C11 * CHUNK] = c11
    buf[ROW_C22 * CHUNK] = c22
    buf[ROW_C23 * CHUNK] = c23
    return ok


@jitable(inline="always")
def _chunk_force(buf, k, t):
    """:func:`polach_force` of contact k of a chunk buffer (its creepages, Q, V and Polach
    parameters in their rows), given its contact terms ``t`` (:func:`polach_contact_terms`)."""
    return polach_force(
        buf[ROW_X * CHUNK + k], buf[ROW_Y * CHUNK + k], buf[ROW_Q * CHUNK + k],
        buf[ROW_V * CHUNK + k], t[0], t[1], t[2], t[3], t[4], t[5], t[6],
        buf[_KA * CHUNK + k], buf[_KS * CHUNK + k], buf[_MU0 * CHUNK + k],
        buf[_BA * CHUNK + k], buf[_BB * CHUNK + k])  # fmt: skip


@jitable
def _polach_rows(buf, ox, oy, m):
    """:func:`polach_law` of the m contacts of a chunk buffer (Kalker's coefficients in their
    rows) into ox, oy: the law inlined in one loop, vectorised."""
    for k in range(m):
        t = chunk_contact_terms(buf, k)
        ox[k], oy[k] = _chunk_force(buf, k, t)


@jitable
def _polach_rows_spinless(buf, ox, oy, m):
    """:func:`_polach_rows` of a chunk without spin (psi = 0 for every contact): the same
    law with psi = 0, whose spin term and spin cap then fold away."""
    for k in range(m):
        t = polach_contact_terms(
            buf[ROW_X * CHUNK + k], buf[ROW_Y * CHUNK + k], 0.0, buf[ROW_A * CHUNK + k],
            buf[ROW_B * CHUNK + k], buf[ROW_G * CHUNK + k], buf[ROW_C11 * CHUNK + k],
            buf[ROW_C22 * CHUNK + k], buf[ROW_C23 * CHUNK + k])  # fmt: skip
        ox[k], oy[k] = _chunk_force(buf, k, t)


@jitable
def _polach_same_shape(buf, ox, oy, m, a, b, g, c11, c22, c23):
    """:func:`_polach_rows` for a chunk whose contacts share a, b, G and Kalker's
    coefficients (given as numbers): the same law, the same operations; LLVM computes the
    parts that depend on the shape alone (K_psi with its exp, G c^3 C23, ...) once."""
    for k in range(m):
        t = polach_contact_terms(buf[ROW_X * CHUNK + k], buf[ROW_Y * CHUNK + k],
                                 buf[ROW_PSI * CHUNK + k], a, b, g, c11, c22, c23)  # fmt: skip
        ox[k], oy[k] = _chunk_force(buf, k, t)


@kernel(nogil=True)
def _polach_chunks(sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a, big_b, fx, fy, first,
                   last):  # fmt: skip
    """:func:`polach_law` of the contacts of chunks ``first`` to ``last - 1`` (of CHUNK
    contacts) into fx, fy (length n); the other arguments are 1-d float64 arrays of length n
    or 1 (one value for every contact). Validates in the same pass; returns the number of
    chunks with an argument out of range (their forces are NaN)."""
    n = fx.size
    count = min(CHUNK, n)
    buf = np.empty(_ROWS * CHUNK)
    inputs = (sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a, big_b)
    for j in range(14):
        fill_row(buf, _INPUT_ROWS[j], inputs[j], count)
    fixed, shape_ok = polach_fixed_shape(a, b, nu, buf, ROW_C11, count)
    spinless = psi.size == 1 and psi[0] == 0.0
    nbad = 0
    for c in range(first, last):
        lo = c * CHUNK
        m = min(CHUNK, n - lo)
        bad = polach_count_bad(sx, sy, psi, q, v, a, b, g, nu, lo, m) + (
            count_outside(mu0, _MU0_RANGE, lo, m) + count_outside(k_a, FRACTION, lo, m)
            + count_outside(k_s, FRACTION, lo, m) + count_outside(big_a, _A_RANGE, lo, m)
            + count_outside(big_b, _B_RANGE, lo, m))  # fmt: skip
        for j in range(14):
            load_row(buf, _INPUT_ROWS[j], inputs[j], lo, m)
        # one shape (a, b, G, nu) over the chunk: Kalker's coefficients looked up once and
        # the loop with the shape as constants (what depends on it alone is hoisted)
        same = chunk_same_shape(buf, m)
        if same and not fixed:
            coefficients_ok = chunk_shape_coefficients(buf)
        else:
            coefficients_ok = same or chunk_coefficients(buf, fixed, m)
        ok = coefficients_ok and bad == 0 and shape_ok
        ox, oy = output_chunk(fx, fy, lo, m, ok)  # views: the loops write the outputs directly
        if not ok:
            nbad += 1
        elif same:
            _polach_same_shape(buf, ox, oy, m, buf[ROW_A * CHUNK], buf[ROW_B * CHUNK],
                               buf[ROW_G * CHUNK], buf[ROW_C11 * CHUNK], buf[ROW_C22 * CHUNK],
                               buf[ROW_C23 * CHUNK])  # fmt: skip
        elif spinless:
            _polach_rows_spinless(buf, ox, oy, m)
        else:
            _polach_rows(buf, ox, oy, m)
    return nbad


@labelled(units=("N", "N"))
def polach_forces(
    creep_long,
    creep_lat,
    spin,
    normal_force,
    speed,
    a,
    b,
    *,
    mu0,
    k_A=1.0,
    k_S=1.0,
    A=1.0,
    B=0.0,
    shear_modulus=8.2e10,
    poisson=0.28,
):
    """Tangential creep forces of Polach's model (1999, extended 2005), Kalker's signs.

    Parameters
    ----------
    creep_long : array_like
        Longitudinal creepage xi = (V - omega R)/V [-]; braking > 0, traction < 0. Finite.
    creep_lat : array_like
        Lateral creepage eta [-]. Finite.
    spin : array_like
        Spin creepage phi [rad/m]. Finite.
    normal_force : array_like
        Normal force Q [N], > 0.
    speed : array_like
        Rolling speed V [m/s], >= 0. Enters only through the slip velocity w = s_C V of the
        falling friction law.
    a : array_like
        Contact semi-axis **in the rolling direction** x [m], > 0 (whether or not it is the
        longer one).
    b : array_like
        Lateral contact semi-axis [m], > 0.
    mu0 : array_like
        Maximum friction coefficient mu0 [-], in (0, 1.5] (the range of
        :class:`~railadhesion.models.parameters.PolachParameters`; a value in percent is an
        error saying so). Above 1, no wheel-rail value: a
        :class:`~railadhesion.plausibility.PlausibilityWarning`.
    k_A : array_like, optional
        Stiffness reduction factor in the area of adhesion [-], in (0, 1] (Polach 2005:
        k_S <= k_A <= 1).
    k_S : array_like, optional
        Stiffness reduction factor in the area of slip [-], in (0, 1]. Polach recommends
        k_S <= k_A; k_S > k_A is accepted and evaluated as published (see Notes, Bounds).
    A : array_like, optional
        mu_inf/mu0 [-], in [0, 10]. ``A = 1`` gives constant friction.
    B : array_like, optional
        Exponential friction decrease rate [s/m], in [0, 100]. ``B = 0`` gives constant
        friction.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa], > 0.
    poisson : array_like, optional
        Combined Poisson's ratio nu [-], in [0, 0.5].

    All arguments broadcast against each other, the five model parameters included (so a
    model such as WILAC can pass one parameter set per contact).

    Returns
    -------
    fx, fy : numpy.float64 or ndarray
        Longitudinal and lateral forces exerted by the rail on the wheel [N] (they oppose the
        creepages: ``fx < 0`` in braking). Scalars for scalar input, else arrays of the
        broadcast shape. Zero creepage gives exactly zero force.

    Raises
    ------
    ValueError
        If an argument is not finite or outside its range; the message names it.

    Notes
    -----
    With s_x = xi, s_y = eta, psi = phi, s = sqrt(s_x^2 + s_y^2) (Polach 1999, 2005; the
    formulas below are those of Polach 2005, section 2, which restates the 1999 model):

    * spin-corrected lateral creepage: s_yC = s_y + psi a if abs(s_y + psi a) > abs(s_y), else
      s_y; s_C = sqrt(s_x^2 + s_yC^2);
    * friction falling with the slip velocity w = s_C V:
      mu = mu0 [(1 - A) exp(-B w) + A];
    * Kalker's coefficient in the creep direction c_jj = sqrt((C11 s_x/s)^2 + (C22 s_y/s)^2),
      contact stiffness C = (3/8)(G/a) c_jj and gradient of the tangential stress
      eps = (2/3) C pi a^2 b s_C / (Q mu) = pi G a b c_jj s_C / (4 Q mu);
    * force (2005 extension):
      F = (2 Q mu / pi) [k_A eps / (1 + (k_A eps)^2) + arctan(k_S eps)]
      (the 1999 model is k_A = k_S = 1; some public codes write ``1 + k_A eps^2``, wrongly);
    * spin: K_psi = 1 + 6.3 (1 - exp(-a/b)),
      eps_psi = (8/3) G b sqrt(ab) C23 abs(s_yC) / (K_psi Q mu),
      delta = (eps_psi^2 - 1)/(eps_psi^2 + 1),
      K_M = abs(eps_psi) (delta^3/3 - delta^2/2 + 1/6) - (1/3) sqrt((1 - delta^2)^3),
      F_yS = -(9/16) a Q mu K_M K_psi psi / s_C;
    * in Polach's signs F_x = F s_x/s_C, F_y = F s_y/s_C + F_yS; returned here:
      ``fx = -F s_x/s_C``, ``fy = -(F s_y/s_C + F_yS)``.

    C11, C22, C23 come from :func:`railadhesion.contact.kalker.kalker_coefficients` at a/b.

    Implementation: the law is :func:`polach_law` (:func:`polach_contact_terms`,
    :func:`polach_force`), compiled (numba, on first use, cached on disk) and looped over the
    contacts by :mod:`railadhesion.models.kernels`, validating in the same pass; the Kalker
    lookup is done once per call when a/b and nu are constant. The tests hold it to an
    independent NumPy oracle (``tests/oracles/polach.py``) at 1e-12 relative. For repeated
    calls on one contact see :class:`PolachContact`; from numba code,
    :func:`railadhesion.models.kernels.polach_scalar`.

    Implementation detail [derived here]: substituting delta, Polach's K_M simplifies
    exactly to K_M = -(2/3) eps_psi / (1 + eps_psi^2)^2, hence
    F_yS = G c^3 C23 psi (abs(s_yC) / s_C) / (1 + eps_psi^2)^2 with c = sqrt(ab). This form is
    evaluated (no cancellation at large eps_psi, no 0/0). At small pure spin it is exactly
    Kalker's linear term, so ``fy -> -G c^3 C23 phi``; likewise ``fx -> -G c^2 C11 xi`` at small
    xi when k_A = k_S = 1. In general the initial slope is (k_A + k_S)/2 times Kalker's.

    **Which semi-axis is a.** In Polach's papers a is the half-axis of the contact ellipse in
    the longitudinal (rolling) direction and b the lateral one (variable list of the FORTRAN
    code of Polach 1999: "semiaxis a of the contact ellipse (in longitudinal direction)");
    this is also our convention (``docs/CONVENTIONS.md``), so ``a`` is passed through as is.
    Some later papers (e.g. Trummer et al., WILAC) call a the "semi-major" axis; that is only
    true when the contact is longer in the rolling direction (a/b > 1), which is often not
    the case on wheel treads (CONTACT's Eurosprinter case has a/b = 0.5). The choice
    matters: eps is symmetric in a and b, but s_yC, K_psi, eps_psi, F_yS and the Kalker
    coefficients are not.

    Bounds: with k_S <= k_A the bracket of F is at most pi/2, so |F| <= mu Q <=
    mu0 Q max(1, A). With k_S > k_A (which Polach 2005 excludes, k_S <= k_A <= 1, but a
    fitted or regressed set may reach) the published model itself exceeds mu Q: the bracket
    reaches up to pi/2 + 1/2, so |F| <= (1 + 1/pi) mu Q (e.g. a/b = 0.5, k_A = 0.1, k_S = 1,
    pure longitudinal creep: |F|/(mu Q) = 1.19, 1.23, 1.09 at 1, 3, 10 % on the Eurosprinter
    contact at Q = 100 kN, mu = 0.3). This is returned as published, unchanged.

    **The spin cap.** When the spin opposes the lateral creepage on long contacts (a/b > 1),
    the spin term F_yS, which k_A and k_S do not reduce, can push |(fx, fy)| above mu Q (up
    to about 1.6 mu Q with k_A = 0.3, k_S = 0.1 at a/b = 5). A tangential force above the
    friction limit is not physical, so **where the spin term is non-zero this implementation
    caps |(fx, fy)| at max(mu Q, |F|)** (mu at the current slip velocity, F the force of the
    creepage part above), scaling both components: it removes only the overshoot the spin
    term adds. Without spin the cap never acts, whatever k_A and k_S.

    **Known limit with spin reinforcing the lateral creep.** When psi a has the sign of s_y,
    s_yC = s_y + psi a and F_yS is added along F_y, but Polach's F_yS falls with eps_psi like
    1/(1 + eps_psi^2)^2 while the exact theory keeps a spin contribution: the lateral force
    is then underestimated. On the Eurosprinter contact (a/b = 0.5, Q = 106.7 kN, mu = 0.33)
    at eta = 0.01, psi a = 0.01, Polach gives Fy = -0.51 mu Q where FASTSIM (40 x 40 strips)
    gives -0.83 mu Q with blended flexibilities (-0.72 mu Q with Kalker's original ones);
    without the spin both give -1.00 mu Q. Use FASTSIM or CONTACT where large spin matters.

    References
    ----------
    O. Polach, A fast wheel-rail forces calculation computer code, Vehicle System Dynamics 33
    (Suppl.), 1999, 728-739.
    O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit,
    Wear 258, 2005, 992-1000.

    Examples
    --------
    CONTACT's Eurosprinter case (a = 6.304 mm, b = 12.61 mm, Q = 106.7 kN, V = 10 m/s,
    G = 82 GPa, nu = 0.28), Coulomb friction 0.33, braking creepage 2 per mille:

    >>> fx, fy = polach_forces(2e-3, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3, mu0=0.33)
    >>> round(float(fx / (0.33 * 106.7e3)), 4), float(fy)
    (-0.8434, -0.0)

    Arrays and parameter arrays broadcast; the dry and wet sets of Polach (2005) at 5 %
    traction creepage:

    >>> import numpy as np
    >>> fx, fy = polach_forces(-0.05, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3,
    ...                        mu0=np.array([0.55, 0.3]), k_A=np.array([1.0, 0.3]),
    ...                        k_S=np.array([0.4, 0.1]), A=0.4, B=np.array([0.6, 0.2]))
    >>> np.round(fx / 106.7e3, 4)
    array([0.4416, 0.2465])
    """
    args = (
        creep_long, creep_lat, spin, normal_force, speed, a, b,
        mu0, k_A, k_S, A, B, shear_modulus, poisson,
    )  # fmt: skip
    scalars = as_scalars(args)
    if scalars is None:
        out = _polach_array(*args)
        _PLAUSIBLE(args)  # implausible inputs warn (docs/checks.md); errors were raised above
        _check_mu0(mu0)
        return out
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu = scalars
    fx, fy, bad = polach_checked.dispatcher(
        sx, sy, psi, q, v, a, b, g, nu, 0.0, 0.0, 0.0, k_a, k_s, mu0, big_a, big_b
    )
    if bad >= 0:
        check_polach_inputs(*scalars)  # raises the error naming the argument
        raise AssertionError("polach kernel flagged an input the checks accept")
    _PLAUSIBLE(scalars)  # implausible inputs warn (docs/checks.md)
    if mu0 > MU0_PLAUSIBLE_MAX:
        _check_mu0(mu0)
    return np.float64(fx), np.float64(fy)


def polach_forces_quiet(creep_long, creep_lat, spin, normal_force, speed, a, b, *, mu0,
                       k_A=1.0, k_S=1.0, A=1.0, B=0.0, shear_modulus=8.2e10,
                       poisson=0.28):  # fmt: skip
    """:func:`polach_forces` (the same law, Polach 2005, and the same errors for impossible
    inputs) without its plausibility warnings: for a caller that checked its inputs once
    (a fit, whose optimiser evaluates the model hundreds of times and would warn each time;
    :func:`railadhesion.calibration.fitting.fit_polach`). Returns arrays (or NumPy scalars
    for scalar inputs), unlabelled."""
    return _polach_array(creep_long, creep_lat, spin, normal_force, speed, a, b, mu0, k_A,
                         k_S, A, B, shear_modulus, poisson)  # fmt: skip


def _bad(name: str, rng: str, value) -> ValueError:
    return ValueError(f"{name} must be in {rng}, got {float(value)!r}")


_ARG_NAMES = (
    "creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b",
    "mu0", "k_A", "k_S", "A", "B", "shear_modulus", "poisson",
)  # fmt: skip
#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(_ARG_NAMES)


def _check_mu0(mu0) -> str | None:
    """Warn (:class:`~railadhesion.plausibility.PlausibilityWarning`) for :func:`mu0_message`;
    returns the message or None."""
    text = mu0_message(mu0)
    return None if text is None else warn(text, PlausibilityWarning)


def _polach_array(*args):
    """Array path of :func:`polach_forces`: the compiled batch kernel, validated in the same
    pass; if any argument is out of range, :func:`_check_inputs` raises the error naming it."""
    arrays = [as_float_array(x, name) for x, name in zip(args, _ARG_NAMES, strict=True)]
    shape, n, flat = flatten(arrays)
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu = flat
    fx = np.empty(n)  # allocated by NumPy: its large arrays are reused from call to call
    fy = np.empty(n)
    nbad = run_chunks(_polach_chunks, (sx, sy, psi, q, v, a, b, g, nu, mu0, k_a, k_s, big_a,
                                       big_b, fx, fy), -(-n // CHUNK), n >= PARALLEL_MIN)
    if sum(nbad):
        check_polach_inputs(*arrays)
        raise AssertionError("polach kernel flagged an input the checks accept")
    if not shape:
        return np.float64(fx[0]), np.float64(fy[0])
    return fx.reshape(shape), fy.reshape(shape)


def check_polach_inputs(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu,
                        contact=True):  # fmt: skip
    """Raise the ``ValueError`` naming the first argument of :func:`polach_forces` (in the
    order of its signature) outside its range; ``contact=False`` checks only the five model
    parameters. The compiled paths validate in the same pass and call this to raise."""
    if contact:
        check_finite(sx, "creep_long")
        check_finite(sy, "creep_lat")
        check_finite(psi, "spin")
        check_positive(q, "normal_force")
        check_nonnegative(v, "speed")
        check_positive(a, "a")
        check_positive(b, "b")
    _check_parameter(mu0, "mu0")
    check_range(k_a, "k_A", 0.0, 1.0, closed="right")
    check_range(k_s, "k_S", 0.0, 1.0, closed="right")
    _check_parameter(big_a, "A")
    _check_parameter(big_b, "B")
    if contact:
        check_positive(g, "shear_modulus")
        check_range(nu, "poisson", 0.0, 0.5)
        axis_ratio(np.asarray(a, float), np.asarray(b, float))


def _check_parameter(value, name: str) -> None:
    """Raise the error of :class:`PolachParameters` (:func:`parameter_range_error`) if a value
    of ``value`` (a number or an array) is outside the range of parameter ``name``."""
    arr = as_float_array(value, name).ravel()
    low, high, low_closed, _ = PARAMETER_RANGES[name]
    with np.errstate(invalid="ignore"):
        ok = ((arr >= low) if low_closed else (arr > low)) & (arr <= high)
    if not np.all(ok):
        raise parameter_range_error(name, float(arr[np.argmin(ok)]))


@dataclass(frozen=True)
class Polach:
    """Polach's creep-force model with one parameter set (object layer, no physics of its own).

    Parameters
    ----------
    params : PolachParameters or str
        Parameter set, or the name of a built-in set
        (:data:`railadhesion.models.parameters.POLACH_PARAMETER_SETS`).
    shear_modulus : float, optional
        Combined shear modulus G [Pa], > 0.
    poisson : float, optional
        Combined Poisson's ratio nu [-], in [0, 0.5].

    Examples
    --------
    >>> model = Polach("polach2005_wet")
    >>> fx, fy = model.forces(-0.02, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3)
    >>> round(float(fx), 1)
    22666.4
    >>> round(float(model.adhesion(-0.02, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3)), 4)
    0.2124
    """

    params: PolachParameters
    shear_modulus: float = 8.2e10
    poisson: float = 0.28

    def __post_init__(self) -> None:
        params = self.params
        if isinstance(params, str):
            params = polach_parameters(params)
        if not isinstance(params, PolachParameters):
            raise ValueError(
                f"params must be a PolachParameters or the name of a built-in set, "
                f"got {type(params).__name__}"
            )
        object.__setattr__(self, "params", params)
        g = float(check_positive(self.shear_modulus, "shear_modulus"))
        nu = float(check_range(self.poisson, "poisson", 0.0, 0.5))
        object.__setattr__(self, "shear_modulus", g)
        object.__setattr__(self, "poisson", nu)

    def forces(self, creep_long, creep_lat, spin, normal_force, speed, a, b):
        """Forces (fx, fy) [N] exerted by the rail on the wheel; see :func:`polach_forces`."""
        p = self.params
        return polach_forces(
            creep_long, creep_lat, spin, normal_force, speed, a, b,
            mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )  # fmt: skip

    def adhesion(self, creep_long, creep_lat, spin, normal_force, speed, a, b):
        """Adhesion coefficient sqrt(fx^2 + fy^2)/Q [-] (:func:`railadhesion.adhesion`)."""
        from railadhesion.contact.traction import adhesion

        fx, fy = self.forces(creep_long, creep_lat, spin, normal_force, speed, a, b)
        return adhesion(fx, fy, normal_force)

    def contact(self, normal_force, speed, a, b) -> PolachContact:
        """A :class:`PolachContact` of this model on one contact (fast repeated calls)."""
        p = self.params
        return PolachContact(
            normal_force, speed, a, b, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )  # fmt: skip


class PolachContact:
    """One contact's fixed data, for fast repeated calls of Polach's model in inner loops.

    Holds the parameter set, G, nu, the semi-axes and their Kalker coefficients (looked up
    once); :meth:`forces` then evaluates :func:`polach_forces` for new creepages (and
    optionally a new speed or normal force) through the compiled scalar kernel
    (:func:`railadhesion.models.kernels.polach_scalar`, compiled for float64 arguments only:
    ints and NumPy scalars are converted), and returns
    Python floats. The same numbers as :func:`polach_forces` with scalar arguments. Building
    one imports numba (the kernel is loaded from numba's cache, or compiled once).

    Parameters
    ----------
    normal_force : float
        Normal force Q [N], > 0 (default for :meth:`forces`).
    speed : float
        Rolling speed V [m/s], >= 0 (default for :meth:`forces`).
    a, b : float
        Contact semi-axes in the rolling and lateral directions [m], > 0.
    mu0, k_A, k_S, A, B, shear_modulus, poisson : float
        As :func:`polach_forces` (validated once, here).

    Examples
    --------
    An ODE right-hand side (one wheel braking: state V, omega):

    >>> contact = PolachContact(1e5, 20.0, 6.3e-3, 12.6e-3, mu0=0.55, k_S=0.4, A=0.4, B=0.6)
    >>> def rhs(t, y, mass=8000.0, inertia=100.0, radius=0.46, torque=9e3):
    ...     speed, omega = y  # braking creepage > 0 gives fx < 0
    ...     fx, _ = contact.forces((speed - omega * radius) / speed, speed=speed)
    ...     return [fx / mass, (-torque - fx * radius) / inertia]
    >>> from scipy.integrate import solve_ivp
    >>> sol = solve_ivp(rhs, (0.0, 0.1), [20.0, 20.0 / 0.46 * 0.99], max_step=1e-3)
    >>> bool(sol.success)
    True
    >>> fx, fy = contact.forces(0.01)
    >>> fx == float(polach_forces(0.01, 0.0, 0.0, 1e5, 20.0, 6.3e-3, 12.6e-3, mu0=0.55,
    ...                           k_S=0.4, A=0.4, B=0.6)[0])
    True

    For compiled inner loops (numba) use
    :func:`railadhesion.models.kernels.polach_scalar` instead.
    """

    __slots__ = (
        "normal_force", "speed", "a", "b", "mu0", "k_A", "k_S", "A", "B", "shear_modulus",
        "poisson", "c11", "c22", "c23", "_data", "_kernel",
    )  # fmt: skip

    def __init__(self, normal_force, speed, a, b, *, mu0, k_A=1.0, k_S=1.0, A=1.0, B=0.0,
                 shear_modulus=8.2e10, poisson=0.28):  # fmt: skip
        values = (0.0, 0.0, 0.0, normal_force, speed, a, b, mu0, k_A, k_S, A, B,
                  shear_modulus, poisson)  # fmt: skip
        scalars = as_scalars(values)
        if scalars is None:
            raise ValueError("PolachContact holds one contact: every argument must be a scalar")
        check_polach_inputs(*scalars)  # validates every argument, errors name it
        _PLAUSIBLE(scalars)  # implausible inputs warn (docs/checks.md), once per contact
        _check_mu0(scalars[7])
        (_, _, _, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu) = (float(x) for x in scalars)
        self.normal_force, self.speed, self.a, self.b = q, v, a, b
        self.mu0, self.k_A, self.k_S, self.A, self.B = mu0, k_a, k_s, big_a, big_b
        self.shear_modulus, self.poisson = g, nu
        self.c11, self.c22, self.c23 = kalker_scalar(a / b, nu)[:3]
        object.__setattr__(self, "_kernel", _contact_forces.dispatcher)
        self._refresh()

    def _refresh(self) -> None:
        """The fixed data in the order of :func:`railadhesion.models.kernels.polach_scalar`."""
        object.__setattr__(self, "_data", np.array([
            self.a, self.b, self.shear_modulus, self.poisson, self.c11, self.c22, self.c23,
            self.k_A, self.k_S, self.mu0, self.A, self.B,
        ]))  # fmt: skip

    _INPUTS = ("normal_force", "speed", "a", "b", "mu0", "k_A", "k_S", "A", "B",
               "shear_modulus", "poisson")  # fmt: skip

    def __setattr__(self, name, value) -> None:
        if not hasattr(self, "_data"):  # being built by __init__
            object.__setattr__(self, name, value)
            return
        if name not in self._INPUTS:
            raise AttributeError(f"PolachContact.{name} is derived from the contact's inputs "
                                 f"({', '.join(self._INPUTS)}): set those")  # fmt: skip
        # a changed input: validated and everything derived from it (Kalker's coefficients,
        # the kernel's data) recomputed, as by the constructor
        values = {k: getattr(self, k) for k in self._INPUTS}
        values[name] = value
        q, v, a, b = (values.pop(k) for k in ("normal_force", "speed", "a", "b"))
        fresh = PolachContact(q, v, a, b, **values)
        for k in self.__slots__:
            object.__setattr__(self, k, getattr(fresh, k))

    def __repr__(self) -> str:
        return (f"PolachContact(normal_force={self.normal_force!r}, speed={self.speed!r}, "
                f"a={self.a!r}, b={self.b!r}, mu0={self.mu0!r}, k_A={self.k_A!r}, "
                f"k_S={self.k_S!r}, A={self.A!r}, B={self.B!r})")  # fmt: skip

    def forces(self, creep_long, creep_lat=0.0, spin=0.0, speed=None, normal_force=None):
        """Forces (fx, fy) [N] of the rail on the wheel, as Python floats.

        ``speed`` and ``normal_force`` default to the values given at construction. Raises
        ``ValueError`` for non-finite creepages or an out-of-range speed or normal force.
        """
        sx, sy, psi = creep_long, creep_lat, spin
        if (sx - sx) + (sy - sy) + (psi - psi) != 0.0:  # NaN or inf in a creepage
            for name, val in (("creep_long", sx), ("creep_lat", sy), ("spin", psi)):
                if not math.isfinite(val):
                    raise ValueError(f"{name} must be finite (no NaN or inf), got {val!r}")
        if normal_force is None:
            normal_force = self.normal_force
        elif not 0.0 < normal_force < _INF:
            raise _bad("normal_force", "(0, inf)", normal_force)
        if speed is None:
            speed = self.speed
        elif not 0.0 <= speed < _INF:
            raise _bad("speed", "[0, inf)", speed)
        return self._kernel(sx, sy, psi, normal_force, speed, self._data)
