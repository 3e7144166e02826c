"""Creep curves of the axles of a braking vehicle, compiled (numba) for the braking step.

The step (:mod:`railadhesion.braking.step`) asks the adhesion model three things, through
three functions chosen when the step is compiled by the type of its ``aux`` argument:

``refresh_adhesion(state, settings, tables, aux)``
    every ``refresh_period``: the slowly varying inputs of each axle's curve (its load, the
    track section or water flow at its position, WILAC's weights and Polach parameters);
``evaluate_adhesion(state, settings, tables, aux, speed)``
    μ, dμ/dξ and dμ/dV of every axle at the creepages ``state.curve.creep`` (into
    ``state.curve.mu``, ``.dmu``, ``.dmv``); μ is odd in ξ;
``peak_adhesion(state, settings, tables, aux, speed)``
    the adhesion available (the peak of each axle's curve) into ``state.curve.available``.

``aux`` selects the model family at compile time:

* an integer (0): the built-in models, Polach sets on track sections or WILAC with a
  water-flow profile (``settings.model``). Each axle's curve is a weighted sum of Polach
  curves, evaluated by :func:`railadhesion.models.polach.polach_longitudinal` (the law and
  its analytic slopes; its creepage-independent terms kept per lane, the rest by
  :func:`~railadhesion.models.polach.polach_longitudinal_at`) in one loop over *lanes*, one
  per axle and set of non-zero weight,
  which the compiler vectorises: the law is the plain function, inlined into the loop with
  the curve it calls (a call of its compiled dispatcher in the loop body would keep the
  loop scalar);
* a first-class function ``mu(creep >= 0, speed, wheel load) -> float`` (a user's numba law
  compiled as a C callback): its slopes by the differences of
  :class:`~railadhesion.braking.adhesion.CallableAdhesion`;
* ``None``: any :class:`~railadhesion.braking.adhesion.AxleAdhesion` in Python, called back
  through numba's ``objmode`` (its ``prepare``, ``slopes`` and ``available`` methods);
* a float (:data:`TABLE_AUX`): the table model of Kalker's exact theory
  (:class:`~railadhesion.braking.adhesion.ExactTableAdhesion`): each axle's curve is
  :func:`railadhesion.contact.table.exact_table_law` at its Hertz contact
  (:func:`table_axle_curve`), the table and the law's constants in the settings and tables.

The first two and the last compile to code with no Python in it (a C host can run them); only the
third calls the interpreter.
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from numba import njit, objmode, types
from numba.extending import overload

from railadhesion.braking.records import (
    CURVE,
    LANE_BLOCK,
    MAX_CONDITIONS,
    PEAK_FULL_EVERY,
    PEAK_WINDOW,
    POLACH,
    TABLE,
    WILAC_AXLE_BLOCK,
)
from railadhesion.contact.table import exact_table_law
from railadhesion.models.kernels import wilac_weights_scalar
from railadhesion.models.polach import polach_longitudinal_at, polach_longitudinal_terms
from railadhesion.models.wilac_parameters import (
    wilac_clip,
    wilac_factors,
    wilac_normalise,
    wilac_term,
    wilac_terms,
)

__all__ = ["new_workspace", "build_lanes", "evaluate_lanes", "peak_lanes", "water_flow_at",
           "wilac_axle_parameters", "family_slopes", "family_slope_table", "family_peak",
           "register_python_model", "table_axle_curve", "table_slopes", "table_axle_peak",
           "table_peak",
           "TABLE_AUX",
           "refresh_adhesion", "evaluate_adhesion", "peak_adhesion", "evaluation_tables"]

_GOLDEN = 0.6180339887498949


def new_workspace() -> np.ndarray:
    """A one-element CURVE record array (scratch of the curve functions below)."""
    return np.zeros(1, CURVE)


# ---------------------------------------------------------------------------------------------
# Polach-family curves on lanes


@njit(cache=True, error_model="numpy")
def build_lanes(c, n, kc, weights, params, stiffness):
    """Lanes of every (axle, set) of non-zero weight, axle by axle, into workspace ``c``,
    padded with lanes of weight 0 to a multiple of ``LANE_BLOCK``. Each lane holds the part
    of Polach's curve that depends on its contact and set only
    (:func:`~railadhesion.models.polach.polach_longitudinal_terms`).

    ``weights`` (n, K), ``params`` (n, K, 5) = (k_A, k_S, mu0, A, B), ``stiffness`` (n,) =
    (π/4) G a b C11 / Q per axle.
    """
    j = 0
    for i in range(n):
        c.lane_lo[i] = j
        for k in range(kc):
            w = weights[i, k]
            if w == 0.0:
                continue
            c.lane_axle[j] = i
            c.lane_weight[j] = w
            c.lane_slope[j], c.lane_ratio[j] = polach_longitudinal_terms(
                stiffness[i], params[i, k, 0], params[i, k, 1])
            c.lane_mu0[j] = params[i, k, 2]
            c.lane_a[j] = params[i, k, 3]
            c.lane_b[j] = params[i, k, 4]
            j += 1
        c.lane_hi[i] = j
    last = j - 1
    while j % LANE_BLOCK != 0:  # padding: copies of the last lane with weight 0
        c.lane_axle[j] = c.lane_axle[last]
        c.lane_weight[j] = 0.0
        c.lane_slope[j] = c.lane_slope[last]
        c.lane_ratio[j] = c.lane_ratio[last]
        c.lane_mu0[j] = c.lane_mu0[last]
        c.lane_a[j] = c.lane_a[last]
        c.lane_b[j] = c.lane_b[last]
        j += 1
    c.lane_count = j


@njit(cache=True, error_model="numpy")
def _lane_curves(c, speed):
    """The weighted Polach curve of every lane (the loop the compiler vectorises)."""
    for j in range(c.lane_count):
        m, dm, dv = polach_longitudinal_at(c.lane_creep[j], speed, c.lane_slope[j],
                                           c.lane_ratio[j], c.lane_mu0[j], c.lane_a[j],
                                           c.lane_b[j])
        w = c.lane_weight[j]
        c.lane_mu[j] = w * m
        c.lane_dmu[j] = w * dm
        c.lane_dmv[j] = w * dv


@njit(cache=True, error_model="numpy")
def evaluate_lanes(c, n, speed):
    """μ, dμ/dξ, dμ/dV of every axle at ``c.creep`` (sums over the axle's lanes; μ and
    dμ/dV odd in ξ)."""
    for j in range(c.lane_count):
        c.lane_creep[j] = abs(c.creep[c.lane_axle[j]])
    _lane_curves(c, speed)
    for i in range(n):
        mu = 0.0
        dmu = 0.0
        dmv = 0.0
        for j in range(c.lane_lo[i], c.lane_hi[i]):
            mu += c.lane_mu[j]
            dmu += c.lane_dmu[j]
            dmv += c.lane_dmv[j]
        if c.creep[i] < 0.0:
            mu = -mu
            dmv = -dmv
        c.mu[i] = mu
        c.dmu[i] = dmu
        c.dmv[i] = dmv


@njit(cache=True, error_model="numpy")
def _slope_at(c, n, speed, where):
    """Evaluate at creepages 10^where[i]; returns nothing, results in c.mu, c.dmu."""
    for i in range(n):
        c.creep[i] = 10.0 ** where[i]
    evaluate_lanes(c, n, speed)


@njit(cache=True, error_model="numpy")
def peak_lanes(c, n, speed):
    """Largest μ per axle over creepage 1e-4 … 1 (the adhesion available) into c.available.

    Full search (every ``PEAK_FULL_EVERY``-th call, and whenever tracking fails): a 17-point
    log-spaced grid, then a golden-section search (16 evaluations) in log creepage between the
    neighbours of the best grid point. In between, the peak is tracked from its previous
    position t* (log10 creepage, ``c.peak_t``): the slopes at t* ± ``PEAK_WINDOW`` must
    bracket it (or show it still at an end of the range), and a secant step on dμ/d(log ξ)
    between them, then a second one in the smaller bracket, locate it (4 evaluations instead
    of 33). All axles at once.
    """
    full = c.peak_calls % PEAK_FULL_EVERY == 0
    c.peak_calls += 1
    if not full:
        for i in range(n):
            c.peak_lo[i] = max(c.peak_t[i] - PEAK_WINDOW, -4.0)
            c.peak_hi[i] = min(c.peak_t[i] + PEAK_WINDOW, 0.0)
        _slope_at(c, n, speed, c.peak_lo)
        for i in range(n):
            c.peak_f1[i] = c.mu[i]
            c.peak_x1[i] = c.creep[i] * c.dmu[i]  # dμ/d ln ξ at the lower end
        _slope_at(c, n, speed, c.peak_hi)
        for i in range(n):
            c.peak_f2[i] = c.mu[i]
            c.peak_x2[i] = c.creep[i] * c.dmu[i]
        for i in range(n):
            lo = c.peak_lo[i]
            hi = c.peak_hi[i]
            h_lo = c.peak_x1[i]
            h_hi = c.peak_x2[i]
            if h_lo > 0.0 and h_hi < 0.0:  # bracketed: secant root of the slope
                t = lo + (hi - lo) * h_lo / (h_lo - h_hi)
            elif hi == 0.0 and h_hi >= 0.0 and h_lo >= 0.0:  # still rising at creepage 1
                t = 0.0
            elif lo == -4.0 and h_lo <= 0.0 and h_hi <= 0.0:  # falling from creepage 1e-4
                t = -4.0
            else:
                full = True
                break
            c.peak_t[i] = t
        if not full:
            _slope_at(c, n, speed, c.peak_t)
            for i in range(n):  # a second secant step inside the smaller bracket
                t = c.peak_t[i]
                c.peak_best[i] = max(c.mu[i], c.peak_f1[i], c.peak_f2[i])
                h = c.creep[i] * c.dmu[i]
                if t == 0.0 or t == -4.0:
                    continue
                if h > 0.0:
                    lo, h_lo, hi, h_hi = t, h, c.peak_hi[i], c.peak_x2[i]
                else:
                    lo, h_lo, hi, h_hi = c.peak_lo[i], c.peak_x1[i], t, h
                if h_lo - h_hi > 0.0:
                    c.peak_t[i] = lo + (hi - lo) * h_lo / (h_lo - h_hi)
            _slope_at(c, n, speed, c.peak_t)
            for i in range(n):
                c.available[i] = max(c.mu[i], c.peak_best[i])
            return
    for i in range(n):
        c.peak_best[i] = -1.0
        c.peak_side[i] = 0
    for jg in range(17):
        for i in range(n):
            c.creep[i] = 10.0 ** (-4.0 + 0.25 * jg)
        evaluate_lanes(c, n, speed)
        for i in range(n):
            if c.mu[i] > c.peak_best[i]:
                c.peak_best[i] = c.mu[i]
                c.peak_side[i] = jg
    for i in range(n):
        jb = c.peak_side[i]
        c.peak_t[i] = -4.0 + 0.25 * jb
        lo = -4.0 + 0.25 * max(jb - 1, 0)
        hi = -4.0 + 0.25 * min(jb + 1, 16)
        c.peak_lo[i] = lo
        c.peak_hi[i] = hi
        c.peak_x1[i] = hi - _GOLDEN * (hi - lo)
        c.peak_x2[i] = lo + _GOLDEN * (hi - lo)
    _slope_at(c, n, speed, c.peak_x1)
    for i in range(n):
        c.peak_f1[i] = c.mu[i]
    _slope_at(c, n, speed, c.peak_x2)
    for i in range(n):
        c.peak_f2[i] = c.mu[i]
    for _ in range(14):
        for i in range(n):
            lo = c.peak_lo[i]
            hi = c.peak_hi[i]
            if c.peak_f1[i] > c.peak_f2[i]:
                hi = c.peak_x2[i]
                c.peak_x2[i] = c.peak_x1[i]
                c.peak_f2[i] = c.peak_f1[i]
                c.peak_x1[i] = hi - _GOLDEN * (hi - lo)
                c.creep[i] = 10.0 ** c.peak_x1[i]
                c.peak_side[i] = 1
            else:
                lo = c.peak_x1[i]
                c.peak_x1[i] = c.peak_x2[i]
                c.peak_f1[i] = c.peak_f2[i]
                c.peak_x2[i] = lo + _GOLDEN * (hi - lo)
                c.creep[i] = 10.0 ** c.peak_x2[i]
                c.peak_side[i] = 2
            c.peak_lo[i] = lo
            c.peak_hi[i] = hi
        evaluate_lanes(c, n, speed)
        for i in range(n):
            if c.peak_side[i] == 1:
                c.peak_f1[i] = c.mu[i]
            else:
                c.peak_f2[i] = c.mu[i]
    for i in range(n):
        best = c.peak_best[i]
        f1 = c.peak_f1[i]
        f2 = c.peak_f2[i]
        c.available[i] = max(best, f1, f2)
        if f1 > best and f1 >= f2:  # where the peak is, for the tracking
            c.peak_t[i] = c.peak_x1[i]
        elif f2 > best:
            c.peak_t[i] = c.peak_x2[i]


# ---------------------------------------------------------------------------------------------
# the built-in models' slowly varying inputs


@njit(cache=True, error_model="numpy")
def water_flow_at(x, values, linear, where):
    """Water flow of a profile (:class:`~railadhesion.braking.adhesion.WaterFlowProfile`) at
    one position or time ``where``: linear interpolation (held beyond the ends, as
    ``np.interp``), or steps (``values[k]`` on ``[x[k], x[k+1])``, ``values[0]`` before
    ``x[0]``, as ``np.searchsorted(x, where, "right") - 1``). Written as a bisection: numba's
    ``np.interp`` allocates and may raise, which compiled code for a C host must not."""
    n = x.shape[0]
    lo = 0  # the number of x <= where, by bisection (x is non-decreasing)
    hi = n
    while lo < hi:
        mid = (lo + hi) // 2
        if x[mid] <= where:
            lo = mid + 1
        else:
            hi = mid
    k = lo - 1  # the last index with x[k] <= where, or -1
    if k < 0:
        return values[0]
    if not linear or k == n - 1:
        return values[k]
    return values[k] + (values[k + 1] - values[k]) * ((where - x[k]) / (x[k + 1] - x[k]))


@njit(cache=True, error_model="numpy")
def wilac_axle_parameters(packed, wheel_loads, speed, water, weights, params, scratch,
                          weighted_only=False):
    """WILAC's weights (n, 4) and Polach parameters (n, 4, 5) of every axle, through the
    WILAC laws of :mod:`railadhesion.models.wilac_parameters`.

    The weights: :func:`~railadhesion.models.kernels.wilac_weights_scalar` per axle (an axle
    with the same water flow as the axle before it reuses them). The parameters: Q' and v'
    of each axle and its regression factors (``wilac_normalise``, ``wilac_factors``) into
    the columns of ``scratch`` (8 rows, at least n rounded up to a multiple of
    ``WILAC_AXLE_BLOCK`` columns: the six factors, the factor 1, the sums), then each
    regression term by term for four axles at once (``wilac_terms``, ``wilac_term``,
    ``wilac_clip``; four sums in registers, the factors read from the rows of ``scratch`` by
    their packed indices, where ``wilac_regression`` picks each factor of each term out of a
    tuple through a jump table): the loop differs from ``wilac_regression``'s, the terms,
    their order and the clip do not, and neither do the numbers.

    ``weighted_only``: the parameters of a condition are computed only for the blocks of four
    axles in which an axle gives it a non-zero weight (the others are left as they were: a
    curve of weight 0 is not evaluated, :func:`build_lanes`), e.g. two of the four
    conditions on a dry rail.
    """
    n = wheel_loads.shape[0]
    for a in range(n):
        if a > 0 and water[a] == water[a - 1]:
            for i in range(4):
                weights[a, i] = weights[a - 1, i]
        else:
            w = wilac_weights_scalar(water[a], packed)
            for i in range(4):
                weights[a, i] = w[i]
    padded = (n + WILAC_AXLE_BLOCK - 1) // WILAC_AXLE_BLOCK * WILAC_AXLE_BLOCK
    for a in range(padded):  # padding columns: the last axle's factors (finite)
        qn, vn = wilac_normalise(wheel_loads[min(a, n - 1)], speed, packed)
        (scratch[0, a], scratch[1, a], scratch[2, a], scratch[3, a], scratch[4, a],
         scratch[5, a]) = wilac_factors(qn, vn)
        scratch[6, a] = 1.0
    for i in range(4):
        for j in range(5):
            first, count = wilac_terms(packed, i, j)
            for b in range(0, padded, WILAC_AXLE_BLOCK):  # four sums in registers
                last = min(b + WILAC_AXLE_BLOCK, n)
                if weighted_only:
                    used = False
                    for a in range(b, last):
                        used = used or weights[a, i] != 0.0
                    if not used:
                        continue
                s0 = s1 = s2 = s3 = 0.0
                for t in range(count):
                    p = first + 4 * t
                    c = packed[p]
                    # the rows of the term's three factors, indexed in place (a row view
                    # per factor would be an array built, and reference-counted, per term)
                    fa = int(packed[p + 1])
                    fb = int(packed[p + 2])
                    fc = int(packed[p + 3])
                    s0 = s0 + wilac_term(c, scratch[fa, b], scratch[fb, b], scratch[fc, b])
                    s1 = s1 + wilac_term(
                        c, scratch[fa, b + 1], scratch[fb, b + 1], scratch[fc, b + 1]
                    )
                    s2 = s2 + wilac_term(
                        c, scratch[fa, b + 2], scratch[fb, b + 2], scratch[fc, b + 2]
                    )
                    s3 = s3 + wilac_term(
                        c, scratch[fa, b + 3], scratch[fb, b + 3], scratch[fc, b + 3]
                    )
                scratch[7, b], scratch[7, b + 1], scratch[7, b + 2], scratch[7, b + 3] = (
                    s0, s1, s2, s3)
                for a in range(b, last):
                    params[a, i, j] = wilac_clip(scratch[7, a], packed, j)


@njit(cache=True, error_model="numpy")
def _builtin_refresh(s, st, tables):
    """Contact stiffness per axle, then the Polach set of the section each axle is on, or
    WILAC's parameters at the water flow each axle sees; then the lanes."""
    n = st.n_axles
    k0 = st.contact_k0
    qref = st.contact_reference_load
    for i in range(n):
        wheel = s.wheel_load[i]
        if i > 0 and wheel == s.wheel_load[i - 1]:
            s.stiffness[i] = s.stiffness[i - 1]
        else:  # Hertz semi-axes scale with Q^(1/3): (π/4) G a b C11 / Q ∝ Q^(-1/3)
            s.stiffness[i] = k0 * (wheel / qref) ** (2.0 / 3.0) / wheel
    if st.model == POLACH:
        sets = tables[st.polach_sets_at:st.polach_sets_at + 5 * st.polach_sets_count]
        sections = tables[st.sections_at:st.sections_at + 3 * st.sections_count]
        for i in range(n):
            position = s.distance - st.axle_offset[i]
            k = 0
            for m in range(st.sections_count):
                if sections[3 * m] <= position < sections[3 * m + 1]:
                    k = int(sections[3 * m + 2])
            for j in range(MAX_CONDITIONS):
                s.weights[i, j] = 0.0
            s.weights[i, 0] = 1.0
            for m in range(5):
                s.params[i, 0, m] = sets[5 * k + m]
        build_lanes(s.curve, n, 1, s.weights, s.params, s.stiffness)
        return
    count = st.profile_count
    px = tables[st.profile_at:st.profile_at + count]
    pv = tables[st.profile_at + count:st.profile_at + 2 * count]
    linear = st.profile_linear != 0
    heat = 0.0  # frictional energy per metre dissipated by the axles ahead [J/m]
    for i in range(n):
        where = s.time if st.profile_over_time != 0 else s.distance - st.axle_offset[i]
        w = water_flow_at(px, pv, linear, where)
        if st.recovery_energy > 0.0:
            w = w * math.exp(-heat / st.recovery_energy)
        s.water[i] = w
        heat += s.force[i] * abs(s.creep[i])
    c = s.curve
    wilac_axle_parameters(tables[st.wilac_at:st.wilac_at + st.wilac_count], s.wheel_load[:n],
                          max(s.speed, 0.0), s.water[:n], s.weights[:n], s.params[:n],
                          c.wilac_scratch, True)
    build_lanes(c, n, MAX_CONDITIONS, s.weights, s.params, s.stiffness)


# ---------------------------------------------------------------------------------------------
# a user's compiled law mu(creep >= 0, speed, wheel load)


@njit(cache=True, error_model="numpy")
def _user_evaluate(s, st, fn, speed):
    """The differences of CallableAdhesion: central in the creepage (step
    ``settings.creep_step``), forward in the speed (1e-6 of it, at least 1e-6 m/s)."""
    c = s.curve
    h = st.creep_step
    hv = 1e-6 * max(speed, 1.0)
    for i in range(st.n_axles):
        xi = c.creep[i]
        q = s.wheel_load[i]
        a = abs(xi)
        lo = max(a - h, 0.0)
        m = fn(a, speed, q)
        dmu = (fn(a + h, speed, q) - fn(lo, speed, q)) / (a + h - lo)
        m2 = fn(a, speed + hv, q)
        sign = np.sign(xi)
        mu = sign * m
        c.mu[i] = mu
        c.dmu[i] = dmu
        c.dmv[i] = (sign * m2 - mu) / hv


@njit(cache=True, error_model="numpy")
def _user_peak(s, st, tables, fn, speed):
    """The largest μ over the log-spaced grid of ``AxleAdhesion.available``."""
    c = s.curve
    grid = tables[st.grid_at:st.grid_at + st.grid_count]
    for i in range(st.n_axles):
        best = -math.inf
        for j in range(grid.size):
            best = max(best, fn(grid[j], speed, s.wheel_load[i]))
        c.available[i] = best


# ---------------------------------------------------------------------------------------------
# the table model of Kalker's exact theory

#: ``aux`` of the table model's family (its type, a float, selects it; the value is unused).
TABLE_AUX = float(TABLE)


@njit(cache=True, error_model="numpy")
def _table_mu(s, speed, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
              inv_step):
    """μ = −Fx/Q of :func:`railadhesion.contact.table.exact_table_law` at longitudinal
    creepage ``s`` (no lateral creep, no spin): the braking adhesion of a wheel of load Q."""
    fx = exact_table_law(s, 0.0, 0.0, q, a, b, mu0, g, nu, speed, ratio, decay, tab, dims,
                         strides, origin, inv_step)[0]
    return -fx / q


@njit(cache=True, error_model="numpy")
def table_axle_curve(creep, speed, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides,
                     origin, inv_step):
    """μ, dμ/dξ, dμ/dV of one wheel by the table model of Kalker's exact theory
    (:func:`railadhesion.contact.table.exact_table_law`, Kalker 1990 ch. 5 tabulated):
    pure longitudinal creepage ``creep`` (braking: ξ > 0 gives μ > 0), train speed [m/s]
    (the falling friction's slip velocity is V|ξ|), wheel load ``q`` [N], Hertz semi-axes
    ``a``, ``b`` [m], friction μ0, A, B [s/m], G [Pa], ν; the table as
    :func:`railadhesion.contact.table.exact_table_arrays` gives it.

    μ is the law at |ξ| with the sign of ξ (odd, 0 at ξ = 0); dμ/dξ a central difference
    (step 1e-9 + 1e-5 |ξ|; across ξ = 0, where the law is odd, its slope is continuous and,
    with falling friction, its curvature jumps: error below 1e-5 relative), dμ/dV a forward
    difference (step 1e-6 of the speed, at least 1e-6 m/s; 0 for Coulomb friction). An
    unloaded wheel (q = 0) has no adhesion: (0, 0, 0)."""
    if q == 0.0:
        return 0.0, 0.0, 0.0
    v = max(speed, 0.0)
    x = abs(creep)
    m = _table_mu(x, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
                  inv_step)
    h = 1e-9 + 1e-5 * x
    hi = _table_mu(x + h, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
                   inv_step)
    lo = _table_mu(x - h, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
                   inv_step)
    dmu = (hi - lo) / (2.0 * h)
    dmv = 0.0
    if ratio != 1.0 and decay != 0.0:
        hv = 1e-6 * max(v, 1.0)
        dmv = (_table_mu(x, v + hv, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides,
                         origin, inv_step) - m) / hv
    sign = np.sign(creep)
    return sign * m, dmu, sign * dmv


@njit(cache=True, error_model="numpy")
def table_slopes(creep, speed, loads, a, b, mu0, ratio, decay, g, nu, tab, dims, strides,
                 origin, inv_step, mu, dmu, dmv):
    """:func:`table_axle_curve` of every axle (arrays over axles ``creep``, ``loads``, ``a``,
    ``b``) into ``mu``, ``dmu``, ``dmv``."""
    for i in range(creep.shape[0]):
        mu[i], dmu[i], dmv[i] = table_axle_curve(creep[i], speed, loads[i], a[i], b[i], mu0,
                                                 ratio, decay, g, nu, tab, dims, strides,
                                                 origin, inv_step)


@njit(cache=True, error_model="numpy")
def table_axle_peak(speed, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
                    inv_step):
    """The adhesion available to one wheel: the largest μ of the table model's curve
    (:func:`table_axle_curve`'s law, without the slopes) over creepages 1e-4 … 1, searched as
    :func:`peak_lanes` does in full: a 17-point log-spaced grid, then a golden-section search
    (14 steps) in log creepage between the neighbours of the best grid point (33 lookups).
    An unloaded wheel (q = 0) has none."""
    if q == 0.0:
        return 0.0
    v = max(speed, 0.0)
    best = -math.inf
    jb = 0
    for j in range(17):
        m = _table_mu(10.0 ** (-4.0 + 0.25 * j), v, q, a, b, mu0, ratio, decay, g, nu, tab,
                      dims, strides, origin, inv_step)
        if m > best:
            best = m
            jb = j
    lo = -4.0 + 0.25 * max(jb - 1, 0)
    hi = -4.0 + 0.25 * min(jb + 1, 16)
    x1 = hi - _GOLDEN * (hi - lo)
    x2 = lo + _GOLDEN * (hi - lo)
    f1 = _table_mu(10.0 ** x1, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides,
                   origin, inv_step)
    f2 = _table_mu(10.0 ** x2, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims, strides,
                   origin, inv_step)
    for _ in range(14):
        if f1 > f2:
            hi = x2
            x2 = x1
            f2 = f1
            x1 = hi - _GOLDEN * (hi - lo)
            f1 = _table_mu(10.0 ** x1, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims,
                           strides, origin, inv_step)
        else:
            lo = x1
            x1 = x2
            f1 = f2
            x2 = lo + _GOLDEN * (hi - lo)
            f2 = _table_mu(10.0 ** x2, v, q, a, b, mu0, ratio, decay, g, nu, tab, dims,
                           strides, origin, inv_step)
    return max(best, f1, f2)


@njit(cache=True, error_model="numpy")
def table_peak(speed, loads, a, b, mu0, ratio, decay, g, nu, tab, dims, strides, origin,
               inv_step, out):
    """:func:`table_axle_peak` of every axle (arrays over axles ``loads``, ``a``, ``b``)
    into ``out``."""
    for i in range(loads.shape[0]):
        out[i] = table_axle_peak(speed, loads[i], a[i], b[i], mu0, ratio, decay, g, nu, tab,
                                 dims, strides, origin, inv_step)


@njit(cache=True, error_model="numpy")
def _table_refresh(s, st):
    """Hertz semi-axes of every axle at its wheel load (a, b ∝ Q^(1/3)), into
    ``s.params[i, 0, 0:2]``."""
    for i in range(st.n_axles):
        f = (s.wheel_load[i] / st.contact_reference_load) ** (1.0 / 3.0)
        s.params[i, 0, 0] = st.table_a0 * f
        s.params[i, 0, 1] = st.table_b0 * f


@njit(cache=True, error_model="numpy")
def _table_evaluate(s, st, tables, speed):
    c = s.curve
    tab = tables[st.table_at:st.table_at + st.table_count]
    for i in range(st.n_axles):
        c.mu[i], c.dmu[i], c.dmv[i] = table_axle_curve(
            c.creep[i], speed, s.wheel_load[i], s.params[i, 0, 0], s.params[i, 0, 1],
            st.table_mu, st.table_ratio, st.table_decay, st.table_shear_modulus,
            st.table_poisson, tab, st.table_dims, st.table_strides, st.table_origin,
            st.table_inv_step)


@njit(cache=True, error_model="numpy")
def _table_peak(s, st, tables, speed):
    c = s.curve
    tab = tables[st.table_at:st.table_at + st.table_count]
    for i in range(st.n_axles):
        c.available[i] = table_axle_peak(
            speed, s.wheel_load[i], s.params[i, 0, 0], s.params[i, 0, 1], st.table_mu,
            st.table_ratio, st.table_decay, st.table_shear_modulus, st.table_poisson, tab,
            st.table_dims, st.table_strides, st.table_origin, st.table_inv_step)


# ---------------------------------------------------------------------------------------------
# any model in Python (objmode call-backs)

_PYTHON_MODELS: dict[int, object] = {}
_NEXT_KEY = [1]


def register_python_model(model, owner) -> int:
    """Make ``model`` (an AxleAdhesion) reachable from compiled code while ``owner`` lives;
    returns its key (``settings.python_key``)."""
    key = _NEXT_KEY[0]
    _NEXT_KEY[0] += 1
    _PYTHON_MODELS[key] = model
    weakref.finalize(owner, _PYTHON_MODELS.pop, key, None)
    return key


def _python_prepare(key, speed, distance, time, wheel_loads, offsets, forces, creeps):
    heat = np.cumsum(forces * np.abs(creeps))
    dissipation = np.concatenate([[0.0], heat[:-1]])
    _PYTHON_MODELS[key].prepare(speed, wheel_loads.copy(), distance - offsets, time,
                                dissipation)


def _python_slopes(key, creep, speed, mu, dmu, dmv):
    out = _PYTHON_MODELS[key].slopes(creep.copy(), speed)
    mu[:], dmu[:], dmv[:] = (np.asarray(x, float) for x in out)


def _python_available(key, speed, available):
    available[:] = _PYTHON_MODELS[key].available(speed)


@njit(cache=True)
def _python_refresh(s, st):
    n = st.n_axles
    key = st.python_key
    speed = s.speed
    distance = s.distance
    time = s.time
    loads = s.wheel_load[:n]
    offsets = st.axle_offset[:n]
    forces = s.force[:n]
    creeps = s.creep[:n]
    with objmode():
        _python_prepare(key, speed, distance, time, loads, offsets, forces, creeps)


@njit(cache=True)
def _python_evaluate(s, st, speed):
    n = st.n_axles
    c = s.curve
    key = st.python_key
    creep = c.creep[:n]
    mu = c.mu[:n]
    dmu = c.dmu[:n]
    dmv = c.dmv[:n]
    with objmode():
        _python_slopes(key, creep, speed, mu, dmu, dmv)


@njit(cache=True)
def _python_peak(s, st, speed):
    key = st.python_key
    available = s.curve.available[:st.n_axles]
    with objmode():
        _python_available(key, speed, available)


# ---------------------------------------------------------------------------------------------
# the three questions of the step, one implementation per model family (chosen by aux's type)


def refresh_adhesion(s, st, tables, aux):
    """Refresh the curves' slowly varying inputs (see the module docstring)."""
    raise NotImplementedError("compiled code only")


def evaluate_adhesion(s, st, tables, aux, speed):
    """μ, dμ/dξ, dμ/dV of every axle at s.curve.creep (see the module docstring)."""
    raise NotImplementedError("compiled code only")


def peak_adhesion(s, st, tables, aux, speed):
    """The adhesion available of every axle into s.curve.available."""
    raise NotImplementedError("compiled code only")


def _implementations(aux):
    """The compiled :func:`refresh_adhesion`, :func:`evaluate_adhesion` and
    :func:`peak_adhesion` of the adhesion family that the numba type of ``aux`` selects: an
    integer the built-in models, None a model in Python, a float the table model, anything
    else a user law."""
    if isinstance(aux, types.Integer):
        return (lambda s, st, tables, aux: _builtin_refresh(s, st, tables),
                lambda s, st, tables, aux, speed: evaluate_lanes(s.curve, st.n_axles, speed),
                lambda s, st, tables, aux, speed: peak_lanes(s.curve, st.n_axles, speed))
    if isinstance(aux, types.NoneType):
        return (lambda s, st, tables, aux: _python_refresh(s, st),
                lambda s, st, tables, aux, speed: _python_evaluate(s, st, speed),
                lambda s, st, tables, aux, speed: _python_peak(s, st, speed))
    if isinstance(aux, types.Float):
        return (lambda s, st, tables, aux: _table_refresh(s, st),
                lambda s, st, tables, aux, speed: _table_evaluate(s, st, tables, speed),
                lambda s, st, tables, aux, speed: _table_peak(s, st, tables, speed))
    return (lambda s, st, tables, aux: None,  # a user law needs only the wheel loads
            lambda s, st, tables, aux, speed: _user_evaluate(s, st, aux, speed),
            lambda s, st, tables, aux, speed: _user_peak(s, st, tables, aux, speed))


def evaluation_tables(tables, aux):
    """The tables that :func:`evaluate_adhesion` of the family ``aux`` reads: ``tables`` for
    the table model, None for the others (their curves need no table)."""
    raise NotImplementedError("compiled code only")


@overload(evaluation_tables, jit_options={"error_model": "numpy"})
def _evaluation_tables(tables, aux):
    if isinstance(aux, types.Float):
        return lambda tables, aux: tables
    return lambda tables, aux: None


@overload(refresh_adhesion, jit_options={"error_model": "numpy"})
def _refresh_adhesion(s, st, tables, aux):
    return _implementations(aux)[0]


@overload(evaluate_adhesion, jit_options={"error_model": "numpy"})
def _evaluate_adhesion(s, st, tables, aux, speed):
    return _implementations(aux)[1]


@overload(peak_adhesion, jit_options={"error_model": "numpy"})
def _peak_adhesion(s, st, tables, aux, speed):
    return _implementations(aux)[2]


# ---------------------------------------------------------------------------------------------
# for the Python-facing models (PolachAdhesion, WilacAdhesion): the same functions on arrays


@njit(cache=True, error_model="numpy")
def family_slopes(creep, speed, weights, params, stiffness, workspace, mu, dmu, dmv):
    """μ, dμ/dξ, dμ/dV per axle (into mu, dmu, dmv) of a Polach-family blend: ``weights``
    (n, K), ``params`` (n, K, 5), ``stiffness`` (n,); ``workspace`` from
    :func:`new_workspace`."""
    c = workspace[0]
    n = creep.shape[0]
    build_lanes(c, n, weights.shape[1], weights, params, stiffness)
    for i in range(n):
        c.creep[i] = creep[i]
    evaluate_lanes(c, n, speed)
    for i in range(n):
        mu[i] = c.mu[i]
        dmu[i] = c.dmu[i]
        dmv[i] = c.dmv[i]


@njit(cache=True, error_model="numpy")
def family_slope_table(creeps, speed, weights, params, stiffness, workspace, out):
    """dμ/dξ of every axle (columns of ``out``) at each of ``creeps`` (rows)."""
    c = workspace[0]
    n = weights.shape[0]
    build_lanes(c, n, weights.shape[1], weights, params, stiffness)
    for j in range(creeps.shape[0]):
        for i in range(n):
            c.creep[i] = creeps[j]
        evaluate_lanes(c, n, speed)
        for i in range(n):
            out[j, i] = c.dmu[i]


@njit(cache=True, error_model="numpy")
def family_peak(speed, weights, params, stiffness, workspace, out):
    """The adhesion available per axle (:func:`peak_lanes`) into ``out``."""
    c = workspace[0]
    n = weights.shape[0]
    build_lanes(c, n, weights.shape[1], weights, params, stiffness)
    peak_lanes(c, n, speed)
    for i in range(n):
        out[i] = c.available[i]
