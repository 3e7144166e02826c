"""Compiled kernels of the braking simulator (numba, ``cache=True``, ``error_model="numpy"``).

Everything the compiled integrator needs lives in three arrays, so that one call from Python
costs one cheap dispatch:

``buf`` (1-d float64)
    header scalars (state, parameters, counters: the ``*_`` indices of
    :mod:`railadhesion.braking._layout`) followed by the
    per-condition tables (weights and Polach parameters of each axle, refreshed every
    ``refresh_period``) and the constant tables (Polach sets and track sections, the packed
    WILAC set, the water-flow profile, the WSP settings); offsets are in the header.
``work`` (2-d float64, rows of length ``max(n_axles * K, n_axles)``)
    the *lanes* of the creep-curve evaluation (one per axle and blend condition of non-zero
    weight; rows ``LA_*``), then one row per per-axle quantity (rows ``R_*``: state such as
    wheel speeds and pressures, inputs, scratch). Rows are separate memory streams, which
    lets the compiler vectorise the lane loops (AVX2: four lanes per instruction).
``rows`` (2-d float64)
    the history rows written when recording.

The integrator is documented in :mod:`railadhesion.braking.simulator`; the Python reference
path there performs the same operations (tests hold the two together).

Creep curve. A Polach-family curve (Polach 2005, section 2; WILAC blends four sets with the
weights of Trummer et al. 2017, section 5.3) for pure longitudinal creepage s = |ξ| at speed
V, written per set with ``m = μ0[(1 − A) exp(−B s V) + A]`` and ``u = K s`` (K the contact
stiffness over the load, (π/4) G a b C11 / Q) in the rational form

    f = m [k_A u m / (m² + k_A² u²) + atan(k_S u / m)],

which equals Polach's ``μ_k [x/(1 + x²) + atan(y)]`` with ``x = k_A ε``, ``y = k_S ε``,
``ε = u/m`` but needs one division where the textbook form needs three; μ = (2/π) Σ w f,
with the analytic slopes dμ/dξ and dμ/dV. ``exp`` and ``atan`` are evaluated without calls
(range reduction plus polynomial / rational approximation, within an ulp of libm) so that
the lane loop vectorises.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core.extending import intrinsic

from railadhesion._jit import guard_cache, purge_module_cache, source_checksum
from railadhesion.braking._layout import (  # noqa: F401 (numba reads them as constants)
    AVAIL_ON_,
    BAD_COMMAND,
    BAD_DT,
    BAD_TORQUE,
    BAD_VALVE,
    BOGIE_,
    BRAKE_,
    CMD_MAX_,
    D_,
    DAVIS_A_,
    DAVIS_B_,
    DAVIS_C_,
    DEM_P_,
    DEM_RAMP_,
    DEM_T0_,
    DT_CACHE_,
    DV_PREV_,
    E_FILL_,
    E_VENT_,
    ERR_AXLE_,
    ERR_VALUE_,
    FALLBACK_,
    FD_H_,
    FN_ADDR_,
    GRADE_,
    H_PREV_,
    INERTIA_,
    INIT_,
    K0_,
    K_,
    KC_,
    KIND_,
    LA_AX,
    LA_B,
    LA_C0,
    LA_C1,
    LA_E,
    LA_KA,
    LA_KD,
    LA_KS,
    LA_OD,
    LA_OM,
    LA_OV,
    LA_S,
    LA_ST,
    LA_W,
    LINEAR_,
    MASS_,
    MAX_STEP_,
    MEAN_FILL_,
    MEAN_VENT_,
    N_,
    N_PROF_,
    NEWTON_,
    NEWTON_MAX,
    NEWTON_TOL_,
    NEXT_,
    NLANES_,
    NONFINITE,
    NROW_,
    NSEC_,
    O_COND_,
    O_GRID_,
    O_PACKED_,
    O_PROF_,
    O_PROG_,
    O_SCR_,
    O_SEC_,
    O_TABLE_,
    O_WS_,
    OK,
    OVER_TIME_,
    P_MAX_,
    PEAK_FULL_EVERY,
    PEAK_WINDOW,
    PERIOD_,
    QREF_,
    R_AA,
    R_ACC,
    R_ACT,
    R_AVAIL,
    R_BB,
    R_CLAMP,
    R_CMD,
    R_CREEP,
    R_DOMEGA,
    R_EDMU,
    R_EDMV,
    R_EMU,
    R_FORCE,
    R_FORCED,
    R_G,
    R_HI,
    R_LHI,
    R_LLO,
    R_LO,
    R_LOAD,
    R_MU,
    R_OFFSET,
    R_OMEGA,
    R_P1,
    R_PBAR,
    R_PK_BEST,
    R_PK_F1,
    R_PK_F2,
    R_PK_HI,
    R_PK_LO,
    R_PK_N,
    R_PK_T,
    R_PK_X1,
    R_PK_X2,
    R_PRESS,
    R_PREV,
    R_RELEASED,
    R_STATIC,
    R_STIFF,
    R_TMP,
    R_TORQUE,
    R_TRANSFER,
    R_VACT,
    R_VALVE,
    R_VENTED,
    R_VIN,
    R_VSTEP,
    R_W,
    R_WATER,
    R_WDEC,
    R_WHEEL,
    R_WST,
    R_XI,
    RADIUS_,
    RATIO_,
    RECORD_,
    RECOVERY_,
    REF_,
    ROWS_FULL,
    STEPS_,
    STOP_SPEED_,
    STOP_T_,
    STOP_X_,
    STOPPED,
    STOPPED_,
    T_,
    TAU_FILL_,
    TAU_VENT_,
    USER_GRID,
    V_,
    WB_,
    WC_,
    WG_,
    WR_,
    WSP_ON_,
    X_,
)
from railadhesion.braking._layout import fingerprint as _layout_checksum
from railadhesion.models import kernels as _models_kernels
from railadhesion.models.kernels import _factors as _wilac_factors
from railadhesion.models.kernels import _weights as _wilac_weights

_TWO_OVER_PI = 2.0 / math.pi
_PI = math.pi

# ---------------------------------------------------------------------------------------------
# elementary functions without calls (vectorisable)

# exp(x) = 2^k exp(r), k = round(x / ln 2) by the 1.5 * 2^52 shifter, r = x - k ln 2 (ln 2 split
# in two: fdlibm's constants), exp(r) by its Taylor series to r^13 (|r| <= 0.35: truncation
# below 1e-17 relative); 2^k from the shifter's bits.
_SHIFTER = 6755399441055744.0
_LOG2E = 1.4426950408889634
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
(_E0, _E1, _E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9, _E10, _E11, _E12, _E13) = tuple(
    1.0 / math.factorial(k) for k in range(14))
# arctan: Cephes (S. L. Moshier, atan.c) range reduction and rational approximation
_AP0, _AP1, _AP2, _AP3, _AP4 = (-8.750608600031904122785e-1, -1.615753718733365076637e1,
                                -7.500855792314704667340e1, -1.228866684490136173410e2,
                                -6.485021904942025371773e1)
_AQ0, _AQ1, _AQ2, _AQ3, _AQ4 = (2.485846490142306297962e1, 1.650270098316988542046e2,
                                4.328810604912902668951e2, 4.853903996359136964868e2,
                                1.945506571482613964425e2)
_MOREBITS = 6.123233995736765886130e-17
_T3P8 = 2.41421356237309504880  # tan(3 pi / 8)


@njit(cache=True, error_model="numpy")
def _eval_lanes(work, n, nl, v):
    """μ, dμ/dξ and dμ/dV of every axle at its creepage ``work[R_XI]`` and speed ``v``.

    Results go to ``work[R_EMU]``, ``work[R_EDMU]``, ``work[R_EDMV]``.
    """
    for j in range(nl):
        work[LA_S, j] = abs(work[R_XI, int(work[LA_AX, j])])
    for j in range(nl):  # exp(-B s V): polynomial part and the shifter
        x = max(-work[LA_B, j] * work[LA_S, j] * v, -700.0)
        x = x if x <= 700.0 else math.nan  # exp overflows (negative trial speed): NaN, as
        # math.exp's inf gives in the reference, never wrapped exponent bits
        k = x * _LOG2E + _SHIFTER
        kk = k - _SHIFTER
        r = (x - kk * _LN2_HI) - kk * _LN2_LO
        p = _E13 * r + _E12
        p = p * r + _E11
        p = p * r + _E10
        p = p * r + _E9
        p = p * r + _E8
        p = p * r + _E7
        p = p * r + _E6
        p = p * r + _E5
        p = p * r + _E4
        p = p * r + _E3
        p = p * r + _E2
        p = p * r + _E1
        p = p * r + _E0
        work[LA_E, j] = p
        work[LA_KD, j] = k
    bits = work[LA_KD].view(np.int64)
    for j in range(nl):  # 2^k: exponent field from the shifter's low bits
        bits[j] = (bits[j] + 1023) << 52
    for j in range(nl):
        s = work[LA_S, j]
        c1e = work[LA_C1, j] * (work[LA_E, j] * work[LA_KD, j])
        m = c1e + work[LA_C0, j]
        dm = -c1e * work[LA_B, j]  # dm / d(sV)
        st = work[LA_ST, j]
        ka = work[LA_KA, j]
        ks = work[LA_KS, j]
        u = st * s
        au = ka * u
        bu = ks * u
        m2 = m * m
        pa = m2 + au * au
        qa = m2 + bu * bu
        inv = 1.0 / (pa * qa)
        ip = qa * inv
        iq = pa * inv
        big = bu > _T3P8 * m
        mid = bu > 0.66 * m
        num = -m if big else (bu - m if mid else bu)
        den = bu if big else (bu + m if mid else m)
        xr = num / den
        y0 = _PI / 2.0 if big else (_PI / 4.0 if mid else 0.0)
        extra = _MOREBITS if big else (0.5 * _MOREBITS if mid else 0.0)
        z = xr * xr
        pz = (((_AP0 * z + _AP1) * z + _AP2) * z + _AP3) * z + _AP4
        qz = ((((z + _AQ0) * z + _AQ1) * z + _AQ2) * z + _AQ3) * z + _AQ4
        at = y0 + ((xr * (z * pz / qz) + xr) + extra)
        br = au * m * ip + at
        dbr = ka * m2 * (m2 - au * au) * ip * ip + ks * m2 * iq  # d br / d eps
        dmks = dm * v
        w = work[LA_W, j]
        work[LA_OM, j] = w * (m * br)
        work[LA_OD, j] = w * (dmks * br + dbr * (st - u * dmks / m))
        work[LA_OV, j] = w * ((br - (u / m) * dbr) * dm * s)
    for i in range(n):
        a = 0.0
        b = 0.0
        c = 0.0
        for j in range(int(work[R_LLO, i]), int(work[R_LHI, i])):
            a += work[LA_OM, j]
            b += work[LA_OD, j]
            c += work[LA_OV, j]
        a *= _TWO_OVER_PI
        c *= _TWO_OVER_PI
        if work[R_XI, i] < 0.0:
            a = -a
            c = -c
        work[R_EMU, i] = a
        work[R_EDMU, i] = _TWO_OVER_PI * b
        work[R_EDMV, i] = c


@intrinsic
def _call_user(typingctx, address, creep, speed, load):
    """Call the C function ``double f(double, double, double)`` at ``address`` (the user's
    adhesion function compiled as a numba cfunc; its address is data, so the kernels are
    compiled and cached once for every user function)."""
    sig = types.float64(types.int64, types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.DoubleType(), [ir.DoubleType()] * 3)
        pointer = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(pointer, list(args[1:]))

    return sig, codegen


@njit(cache=True, error_model="numpy")
def _eval_user(buf, work, n, v):
    """:func:`_eval_lanes` for a user adhesion function ``μ(creep >= 0, speed, wheel load)``:
    the same differences as ``CallableAdhesion.evaluate`` (central in the creepage, step
    ``buf[FD_H_]``) and ``AxleAdhesion.slopes`` (forward in the speed)."""
    fn = int(buf[FN_ADDR_])
    h = buf[FD_H_]
    hv = 1e-6 * max(v, 1.0)
    for i in range(n):
        xi = work[R_XI, i]
        q = work[R_WHEEL, i]
        s = abs(xi)
        lo = max(s - h, 0.0)
        m = _call_user(fn, s, v, q)
        dmu = (_call_user(fn, s + h, v, q) - _call_user(fn, lo, v, q)) / (s + h - lo)
        m2 = _call_user(fn, s, v + hv, q)
        if xi > 0.0:
            sign = 1.0
        elif xi < 0.0:
            sign = -1.0
        elif xi == 0.0:
            sign = 0.0
        else:
            sign = math.nan
        mu = sign * m
        work[R_EMU, i] = mu
        work[R_EDMU, i] = dmu
        work[R_EDMV, i] = (sign * m2 - mu) / hv


@njit(cache=True, error_model="numpy")
def _curve(buf, work, n, nl, v):
    """μ, dμ/dξ, dμ/dV of every axle at work[R_XI]: the Polach-family lanes or the user's
    function."""
    if buf[KIND_] == 2.0:
        _eval_user(buf, work, n, v)
    else:
        _eval_lanes(work, n, nl, v)


@njit(cache=True, error_model="numpy")
def _peak_user(buf, work, n, v):
    """Adhesion available for a user function: the largest μ over the 64 log-spaced creepages
    of ``AxleAdhesion.available`` (1e-4 … 1)."""
    fn = int(buf[FN_ADDR_])
    og = int(buf[O_GRID_])
    for i in range(n):
        best = -math.inf
        q = work[R_WHEEL, i]
        for j in range(USER_GRID):
            best = max(best, _call_user(fn, buf[og + j], v, q))
        work[R_AVAIL, i] = best


@njit(cache=True, error_model="numpy")
def _build_lanes(work, n, kc, weights, params, stiffness):
    """Lanes of every (axle, condition) of non-zero weight, axle by axle; returns their count.

    ``weights`` (n, K), ``params`` (n, K, 5) = (k_A, k_S, mu0, A, B), ``stiffness`` (n,).
    """
    j = 0
    for i in range(n):
        work[R_LLO, i] = j
        for k in range(kc):
            w = weights[i, k]
            if w == 0.0:
                continue
            mu0 = params[i, k, 2]
            big_a = params[i, k, 3]
            work[LA_AX, j] = i
            work[LA_W, j] = w
            work[LA_C1, j] = mu0 * (1.0 - big_a)
            work[LA_C0, j] = mu0 * big_a
            work[LA_B, j] = params[i, k, 4]
            work[LA_KA, j] = params[i, k, 0]
            work[LA_KS, j] = params[i, k, 1]
            work[LA_ST, j] = stiffness[i]
            j += 1
        work[R_LHI, i] = j
    return j


@njit(cache=True, error_model="numpy")
def family_evaluate(creep, speed, weights, params, stiffness, work):
    """μ, dμ/dξ, dμ/dV per axle (arrays (n,)) of a Polach-family blend; ``work`` from
    :func:`railadhesion.braking._layout.new_work`."""
    n = creep.shape[0]
    nl = _build_lanes(work, n, weights.shape[1], weights, params, stiffness)
    for i in range(n):
        work[R_XI, i] = creep[i]
    _eval_lanes(work, n, nl, speed)
    return work[R_EMU, :n].copy(), work[R_EDMU, :n].copy(), work[R_EDMV, :n].copy()


@njit(cache=True, error_model="numpy")
def _peak_lanes(work, n, nl, speed):
    """Largest μ per axle over creepage 1e-4 … 1 (the adhesion available) into work[R_AVAIL].

    Full search (every ``PEAK_FULL_EVERY``-th call, and whenever tracking fails): a 17-point
    log-spaced grid, then a golden-section search (16 evaluations) in log creepage between the
    neighbours of the best grid point. In between, the peak is tracked from its previous
    position t* (log10 creepage, kept in work[R_PK_T]): the slopes dμ/dξ at t* ± 0.05 must
    bracket it (or show it still at an end of the range), and a secant step on dμ/d(log ξ)
    between them, and a second one in the smaller bracket, locate it (4 evaluations instead of
    33). All axles at once.
    """
    count = work[R_PK_N, 0]
    work[R_PK_N, 0] = count + 1.0
    full = count % PEAK_FULL_EVERY == 0.0
    if not full:
        for i in range(n):  # lower end of the window
            t = work[R_PK_T, i]
            work[R_PK_LO, i] = max(t - PEAK_WINDOW, -4.0)
            work[R_XI, i] = 10.0 ** work[R_PK_LO, i]
        _eval_lanes(work, n, nl, speed)
        for i in range(n):
            work[R_PK_F1, i] = work[R_EMU, i]
            work[R_PK_X1, i] = work[R_XI, i] * work[R_EDMU, i]  # dμ/d ln ξ
            work[R_PK_HI, i] = min(work[R_PK_T, i] + PEAK_WINDOW, 0.0)
            work[R_XI, i] = 10.0 ** work[R_PK_HI, i]
        _eval_lanes(work, n, nl, speed)
        for i in range(n):
            work[R_PK_F2, i] = work[R_EMU, i]
            work[R_PK_X2, i] = work[R_XI, i] * work[R_EDMU, i]
        for i in range(n):
            lo = work[R_PK_LO, i]
            hi = work[R_PK_HI, i]
            h_lo = work[R_PK_X1, i]
            h_hi = work[R_PK_X2, i]
            if h_lo > 0.0 and h_hi < 0.0:  # bracketed: secant root of the slope
                t = lo + (hi - lo) * h_lo / (h_lo - h_hi)
            elif hi == 0.0 and h_hi >= 0.0 and h_lo >= 0.0:  # still rising at creepage 1
                t = 0.0
            elif lo == -4.0 and h_lo <= 0.0 and h_hi <= 0.0:  # falling from creepage 1e-4
                t = -4.0
            else:
                full = True
                break
            work[R_PK_T, i] = t
            work[R_XI, i] = 10.0 ** t
        if not full:
            _eval_lanes(work, n, nl, speed)
            for i in range(n):  # a second secant step inside the smaller bracket
                t = work[R_PK_T, i]
                work[R_PK_BEST, i] = max(work[R_EMU, i], work[R_PK_F1, i], work[R_PK_F2, i])
                h = work[R_XI, i] * work[R_EDMU, i]
                if t == 0.0 or t == -4.0:
                    continue
                if h > 0.0:
                    lo, h_lo, hi, h_hi = t, h, work[R_PK_HI, i], work[R_PK_X2, i]
                else:
                    lo, h_lo, hi, h_hi = work[R_PK_LO, i], work[R_PK_X1, i], t, h
                if h_lo - h_hi > 0.0:
                    t = lo + (hi - lo) * h_lo / (h_lo - h_hi)
                work[R_PK_T, i] = t
                work[R_XI, i] = 10.0 ** t
            _eval_lanes(work, n, nl, speed)
            for i in range(n):
                work[R_AVAIL, i] = max(work[R_EMU, i], work[R_PK_BEST, i])
            return
    g = 0.6180339887498949
    for i in range(n):
        work[R_PK_BEST, i] = -1.0
        work[R_PK_LO, i] = 0.0
    for jg in range(17):
        for i in range(n):
            work[R_XI, i] = 10.0 ** (-4.0 + 0.25 * jg)
        _eval_lanes(work, n, nl, speed)
        for i in range(n):
            if work[R_EMU, i] > work[R_PK_BEST, i]:
                work[R_PK_BEST, i] = work[R_EMU, i]
                work[R_PK_LO, i] = jg
    for i in range(n):
        jb = int(work[R_PK_LO, i])
        work[R_PK_T, i] = -4.0 + 0.25 * jb
        lo = -4.0 + 0.25 * max(jb - 1, 0)
        hi = -4.0 + 0.25 * min(jb + 1, 16)
        work[R_PK_LO, i] = lo
        work[R_PK_HI, i] = hi
        work[R_PK_X1, i] = hi - g * (hi - lo)
        work[R_PK_X2, i] = lo + g * (hi - lo)
    for i in range(n):
        work[R_XI, i] = 10.0 ** work[R_PK_X1, i]
    _eval_lanes(work, n, nl, speed)
    for i in range(n):
        work[R_PK_F1, i] = work[R_EMU, i]
        work[R_XI, i] = 10.0 ** work[R_PK_X2, i]
    _eval_lanes(work, n, nl, speed)
    for i in range(n):
        work[R_PK_F2, i] = work[R_EMU, i]
    for _ in range(14):
        for i in range(n):
            lo = work[R_PK_LO, i]
            hi = work[R_PK_HI, i]
            if work[R_PK_F1, i] > work[R_PK_F2, i]:
                hi = work[R_PK_X2, i]
                work[R_PK_X2, i] = work[R_PK_X1, i]
                work[R_PK_F2, i] = work[R_PK_F1, i]
                work[R_PK_X1, i] = hi - g * (hi - lo)
                work[R_XI, i] = 10.0 ** work[R_PK_X1, i]
                work[R_TMP, i] = 1.0
            else:
                lo = work[R_PK_X1, i]
                work[R_PK_X1, i] = work[R_PK_X2, i]
                work[R_PK_F1, i] = work[R_PK_F2, i]
                work[R_PK_X2, i] = lo + g * (hi - lo)
                work[R_XI, i] = 10.0 ** work[R_PK_X2, i]
                work[R_TMP, i] = 2.0
            work[R_PK_LO, i] = lo
            work[R_PK_HI, i] = hi
        _eval_lanes(work, n, nl, speed)
        for i in range(n):
            if work[R_TMP, i] == 1.0:
                work[R_PK_F1, i] = work[R_EMU, i]
            else:
                work[R_PK_F2, i] = work[R_EMU, i]
    for i in range(n):
        best = work[R_PK_BEST, i]
        f1 = work[R_PK_F1, i]
        f2 = work[R_PK_F2, i]
        work[R_AVAIL, i] = max(best, f1, f2)
        if f1 > best and f1 >= f2:  # where the peak is, for the tracking
            work[R_PK_T, i] = work[R_PK_X1, i]
        elif f2 > best:
            work[R_PK_T, i] = work[R_PK_X2, i]


@njit(cache=True, error_model="numpy")
def family_peak(speed, weights, params, stiffness, work):
    """Adhesion available per axle (see :func:`_peak_lanes`); ``work`` from
    :func:`railadhesion.braking._layout.new_work`."""
    n = weights.shape[0]
    nl = _build_lanes(work, n, weights.shape[1], weights, params, stiffness)
    _peak_lanes(work, n, nl, speed)
    return work[R_AVAIL, :n].copy()


@njit(cache=True, error_model="numpy")
def wilac_table(packed, program, loads, speed, water, weights, params, scratch, acc):
    """Fill WILAC's blending weights (n, 4) and Polach parameters (n, 4, 5) per axle.

    ``packed`` is :func:`railadhesion.models.kernels.pack_wilac` (layout documented there),
    ``program`` its :func:`railadhesion.braking._layout.wilac_program`, ``scratch`` (7) and
    ``acc`` (M, the number of monomials) work arrays. The weights (erf transitions, Trummer
    et al. §5.3) and the normalised factors of Q' and v' (clamped into the calibrated ranges,
    §5.2) are the WILAC kernel's own functions; each regression is the sum of its terms
    (coefficient times monomial of the factors, in four interleaved partial sums), clipped to
    the physical bounds. An axle with the same load (or water flow) as the axle before it (the
    two axles of a bogie) reuses its results.
    """
    n = loads.shape[0]
    nmono = int(program[0])
    for a in range(n):
        if a > 0 and water[a] == water[a - 1]:
            for i in range(4):
                weights[a, i] = weights[a - 1, i]
        else:
            f = _wilac_weights(water[a], packed)
            for i in range(4):
                weights[a, i] = f[i]
        if a > 0 and loads[a] == loads[a - 1]:
            for i in range(4):
                for j in range(5):
                    params[a, i, j] = params[a - 1, i, j]
            continue
        _wilac_factors(loads[a], speed, packed, scratch)
        for m in range(nmono):
            acc[m] = (scratch[int(program[1 + 3 * m])] * scratch[int(program[2 + 3 * m])]
                      * scratch[int(program[3 + 3 * m])])
        p = 1 + 3 * nmono
        for r in range(20):
            count = int(program[p])
            p += 1
            t0 = 0.0  # four partial sums (terms k = 0, 1, 2, 3 mod 4): short add chains
            t1 = 0.0
            t2 = 0.0
            t3 = 0.0
            k = 0
            while k + 4 <= count:
                t0 += program[p] * acc[int(program[p + 1])]
                t1 += program[p + 2] * acc[int(program[p + 3])]
                t2 += program[p + 4] * acc[int(program[p + 5])]
                t3 += program[p + 6] * acc[int(program[p + 7])]
                p += 8
                k += 4
            if k < count:
                t0 += program[p] * acc[int(program[p + 1])]
                p += 2
            if k + 1 < count:
                t1 += program[p] * acc[int(program[p + 1])]
                p += 2
            if k + 2 < count:
                t2 += program[p] * acc[int(program[p + 1])]
                p += 2
            j = r % 5
            params[a, r // 5, j] = min(max((t0 + t1) + (t2 + t3), packed[12 + 2 * j]),
                                       packed[13 + 2 * j])


# ---------------------------------------------------------------------------------------------
# one step of the integrator (see the simulator module docstring)


@njit(cache=True, error_model="numpy")
def _water(x, values, over_time, linear, position, time):
    q = time if over_time else position
    if linear:
        return np.interp(q, x, values)
    idx = np.searchsorted(x, q, side="right") - 1
    if idx < 0:
        return values[0]
    if idx > values.size - 1:
        idx = values.size - 1
    return values[idx]


@njit(cache=True, error_model="numpy")
def _refresh(buf, work):
    """Slowly varying inputs of the adhesion model: loads, stiffness, water, parameters, lanes."""
    n = int(buf[N_])
    kc = int(buf[KC_])
    d = buf[D_]
    oc = int(buf[O_COND_])
    weights = buf[oc:oc + n * kc].reshape((n, kc))
    params = buf[oc + n * kc:oc + 6 * n * kc].reshape((n, kc, 5))
    k0 = buf[K0_]
    qref = buf[QREF_]
    for i in range(n):
        load = max(work[R_STATIC, i] + work[R_TRANSFER, i] * d, 0.0)
        work[R_LOAD, i] = load
        wheel = 0.5 * load
        work[R_WHEEL, i] = wheel
        if i > 0 and load == work[R_LOAD, i - 1]:
            work[R_STIFF, i] = work[R_STIFF, i - 1]
        else:
            work[R_STIFF, i] = k0 * (wheel / qref) ** (2.0 / 3.0) / wheel
    if buf[KIND_] == 2.0:  # a user function: nothing to prepare but the wheel loads
        if buf[AVAIL_ON_] != 0.0:
            _peak_user(buf, work, n, max(buf[V_], 0.0))
        return
    if buf[KIND_] == 0.0:  # Polach sets on sections
        o_sec = int(buf[O_SEC_])
        o_tab = int(buf[O_TABLE_])
        for i in range(n):
            pos = buf[X_] - work[R_OFFSET, i]
            k = 0
            for s in range(int(buf[NSEC_])):
                if pos >= buf[o_sec + 3 * s] and pos < buf[o_sec + 3 * s + 1]:
                    k = int(buf[o_sec + 3 * s + 2])
            for j in range(kc):
                weights[i, j] = 0.0
                for m in range(5):
                    params[i, j, m] = buf[o_tab + 5 * j + m]
            weights[i, k] = 1.0
    else:  # WILAC
        o_prof = int(buf[O_PROF_])
        npr = int(buf[N_PROF_])
        px = buf[o_prof:o_prof + npr]
        pv = buf[o_prof + npr:o_prof + 2 * npr]
        over_time = buf[OVER_TIME_] != 0.0
        linear = buf[LINEAR_] != 0.0
        recovery = buf[RECOVERY_]
        heat = 0.0
        for i in range(n):
            w = _water(px, pv, over_time, linear, buf[X_] - work[R_OFFSET, i], buf[T_])
            if recovery > 0.0:
                w = w * math.exp(-heat / recovery)
            work[R_WATER, i] = w
            heat += work[R_FORCE, i] * abs(work[R_CREEP, i])
        o_pk = int(buf[O_PACKED_])
        o_prog = int(buf[O_PROG_])
        o_scr = int(buf[O_SCR_])
        wilac_table(buf[o_pk:o_prog], buf[o_prog:o_scr], work[R_WHEEL, :n], max(buf[V_], 0.0),
                    work[R_WATER, :n], weights, params, buf[o_scr:], work[R_ACC])
    nl = _build_lanes(work, n, kc, weights, params, work[R_STIFF, :n])
    buf[NLANES_] = nl
    if buf[AVAIL_ON_] != 0.0:
        _peak_lanes(work, n, nl, buf[V_])


@njit(cache=True, error_model="numpy")
def _newton(buf, work, n, nl, v0, dt, external, r_pred):
    """Backward Euler by Newton on the (n + 1) arrow system (wheels and train), from the
    extrapolated previous step; active set for wheels at rest. Returns the new train speed
    (> 0) or -1.0 if the safeguarded solve must take over.

    On success ``work[R_W]`` holds the wheel speeds and ``work[R_EMU]`` the adhesion used
    (linearised at the last iterate: consistent with the accepted update).
    """
    radius = buf[RADIUS_]
    inertia = buf[INERTIA_]
    brake = buf[BRAKE_]
    mass = buf[MASS_]
    tol = buf[NEWTON_TOL_]
    j_dt = inertia / dt
    m_dt = mass / dt
    v = v0 + r_pred * buf[DV_PREV_]
    for i in range(n):
        w0 = work[R_OMEGA, i]
        if w0 == 0.0:
            work[R_CLAMP, i] = 1.0
            work[R_W, i] = 0.0
        else:
            work[R_CLAMP, i] = 0.0
            wp = w0 + r_pred * work[R_DOMEGA, i]
            work[R_W, i] = wp if wp > 0.0 else w0
    for _ in range(NEWTON_MAX):
        buf[NEWTON_] += 1.0
        if not v > 1e-6:
            return -1.0
        iv = 1.0 / v  # v > 1e-6: no floor needed
        iv2 = iv * iv
        for i in range(n):
            work[R_XI, i] = (v - work[R_W, i] * radius) * iv
        _curve(buf, work, n, nl, v)
        h = m_dt * (v - v0) + external
        dd = m_dt
        s_acc = 0.0
        rhs = 0.0
        for i in range(n):
            nl_i = work[R_LOAD, i]
            mu = work[R_EMU, i]
            dmu = work[R_EDMU, i]
            dmv = work[R_EDMV, i]
            if not (math.isfinite(mu) and math.isfinite(dmu) and math.isfinite(dmv)):
                return -1.0
            h += nl_i * mu
            dsdv = work[R_W, i] * radius * iv2
            dd += nl_i * (dmu * dsdv + dmv)
            if work[R_CLAMP, i] != 0.0:
                continue
            rn = radius * nl_i
            g = (j_dt * (work[R_W, i] - work[R_OMEGA, i]) - rn * mu + brake * work[R_PBAR, i]
                 - work[R_TORQUE, i])
            a = j_dt + rn * dmu * radius * iv
            b = -rn * (dmu * dsdv + dmv)
            c = -nl_i * dmu * radius * iv
            if not a > 0.0:
                return -1.0
            ia = 1.0 / a
            work[R_G, i] = g
            work[R_AA, i] = ia
            work[R_BB, i] = b
            s_acc += c * b * ia
            rhs += c * g * ia
        schur = dd - s_acc
        if not schur > 0.0:
            return -1.0
        dv = (-h + rhs) / schur
        err = abs(dv)
        changed = False
        for i in range(n):
            if work[R_CLAMP, i] != 0.0:
                work[R_TMP, i] = 0.0
                static = (-j_dt * work[R_OMEGA, i] - radius * work[R_LOAD, i] * work[R_EMU, i]
                          + brake * work[R_PBAR, i] - work[R_TORQUE, i])
                if static < 0.0:  # brake friction cannot hold the wheel: it turns
                    work[R_CLAMP, i] = 0.0
                    changed = True
                continue
            dw = (-work[R_G, i] - work[R_BB, i] * dv) * work[R_AA, i]
            work[R_TMP, i] = dw
            err = max(err, abs(dw) * radius)
            if work[R_W, i] + dw <= 0.0:  # the wheel stops within the step
                work[R_CLAMP, i] = 1.0
                changed = True
        if not changed and err <= tol * v:
            for i in range(n):  # adhesion used, linearised at this iterate
                dw = work[R_TMP, i]
                dxi = -radius * dw * iv + work[R_W, i] * radius * iv2 * dv
                work[R_EMU, i] = (work[R_EMU, i] + work[R_EDMU, i] * dxi
                                  + work[R_EDMV, i] * dv)
                work[R_W, i] = work[R_W, i] + dw
            return v + dv
        v = v + dv
        for i in range(n):
            if work[R_CLAMP, i] != 0.0:
                work[R_W, i] = 0.0
            else:
                work[R_W, i] = max(work[R_W, i] + work[R_TMP, i], 0.0)
    return -1.0


@njit(cache=True, error_model="numpy")
def _solve_wheels(buf, work, n, nl, v, dt, tol):
    """Safeguarded Newton per wheel (bisection inside a bracket) for a trial train speed v;
    the same algorithm as ``BrakingSimulator._solve_wheels_python``. ``work[R_W]`` is the
    guess on entry and the wheel speeds on exit, ``work[R_EMU]`` their μ. Returns the first
    axle with a non-finite μ, or -1."""
    radius = buf[RADIUS_]
    inertia = buf[INERTIA_]
    brake = buf[BRAKE_]
    vr = max(v, 1e-6)
    for i in range(n):
        work[R_XI, i] = 1.0
    _curve(buf, work, n, nl, v)
    for i in range(n):
        if not (math.isfinite(work[R_EMU, i]) and math.isfinite(work[R_EDMU, i])):
            return i
    for i in range(n):
        rn = radius * work[R_LOAD, i]
        locked = (-inertia * work[R_OMEGA, i] / dt - rn * work[R_EMU, i]
                  + brake * work[R_PBAR, i] - work[R_TORQUE, i]) >= 0.0
        work[R_CLAMP, i] = 1.0 if locked else 0.0
        work[R_ACT, i] = 0.0 if locked else 1.0
        work[R_LO, i] = 0.0
        hi = work[R_OMEGA, i] + dt * (rn * 2.0 + max(work[R_TORQUE, i], 0.0)) / inertia + 1e-9
        work[R_HI, i] = hi
        work[R_W, i] = min(max(work[R_W, i], 0.0), hi)
    for _ in range(100):
        for i in range(n):
            work[R_XI, i] = (v - work[R_W, i] * radius) / vr
        _curve(buf, work, n, nl, v)
        for i in range(n):
            if not (math.isfinite(work[R_EMU, i]) and math.isfinite(work[R_EDMU, i])):
                return i
        any_active = False
        for i in range(n):
            rn = radius * work[R_LOAD, i]
            w = work[R_W, i]
            g = (inertia * (w - work[R_OMEGA, i]) / dt - rn * work[R_EMU, i]
                 + brake * work[R_PBAR, i] - work[R_TORQUE, i])
            dg = inertia / dt + rn * work[R_EDMU, i] * radius / vr
            step = g / dg
            converged = dg > 0.0 and abs(step) * radius < tol
            if g < 0.0:
                work[R_LO, i] = w
            else:
                work[R_HI, i] = w
            lo = work[R_LO, i]
            hi = work[R_HI, i]
            new = w - step
            if not (dg > 0.0) or not (new > lo) or not (new < hi):
                new = 0.5 * (lo + hi)
            if converged:
                new = w - step
            done = converged or (hi - lo) * radius < tol
            if work[R_ACT, i] != 0.0:
                work[R_W, i] = new
                if done:
                    work[R_ACT, i] = 0.0
                else:
                    any_active = True
        if not any_active:
            break
    for i in range(n):
        if work[R_CLAMP, i] != 0.0:
            work[R_W, i] = 0.0
        work[R_XI, i] = (v - work[R_W, i] * radius) / vr
    _curve(buf, work, n, nl, v)
    for i in range(n):
        if not (math.isfinite(work[R_EMU, i]) and math.isfinite(work[R_EDMU, i])):
            return i
    return -1


@njit(cache=True, error_model="numpy")
def _safeguarded(buf, work, n, nl, v0, dt, external):
    """Backward Euler by the nested safeguarded solve (secant steps on the train speed around
    :func:`_solve_wheels`, to 1e-10 m/s); the same algorithm as
    ``BrakingSimulator._safeguarded_python``. Returns (v, failed axle or -1)."""
    tol = 1e-10
    mass = buf[MASS_]
    v = v0 - dt * buf[D_]
    for i in range(n):
        work[R_W, i] = work[R_OMEGA, i]
    v_prev = v
    r_prev = 0.0
    for it in range(30):
        bad = _solve_wheels(buf, work, n, nl, v, dt, tol)
        if bad >= 0:
            buf[ERR_VALUE_] = work[R_XI, bad]
            return v, bad
        total = 0.0
        for i in range(n):
            total += work[R_EMU, i] * work[R_LOAD, i]
        v_new = v0 - dt * (total + external) / mass
        r = v_new - v
        if abs(r) < tol:
            v = v_new
            break
        if it == 0 or r == r_prev:
            v_next = v_new
        else:
            v_next = v - r * (v - v_prev) / (r - r_prev)
        v_prev = v
        r_prev = r
        v = v_next
    return v, -1


@njit(cache=True, error_model="numpy")
def _advance(buf, work, rows, dt):
    """One step of length dt with the valves in work[R_VALVE] and commands in work[R_CMD].

    Returns OK, STOPPED (the train has stopped in this step) or NONFINITE (buf[ERR_AXLE_]
    names the axle, buf[ERR_VALUE_] its creepage).
    """
    n = int(buf[N_])
    radius = buf[RADIUS_]
    inertia = buf[INERTIA_]
    brake = buf[BRAKE_]
    mass = buf[MASS_]
    if buf[T_] >= buf[NEXT_] - 1e-12:
        _refresh(buf, work)
        period = buf[PERIOD_]
        buf[NEXT_] = (math.floor(buf[T_] / period + 1e-9) + 1) * period
    nl = int(buf[NLANES_])
    v0 = buf[V_]
    d0 = buf[D_]
    for i in range(n):
        work[R_LOAD, i] = max(work[R_STATIC, i] + work[R_TRANSFER, i] * d0, 0.0)
    # brake cylinders: exact first-order lag over the step, exact mean pressure
    if dt != buf[DT_CACHE_]:
        buf[DT_CACHE_] = dt
        e = math.exp(-dt / buf[TAU_FILL_])
        buf[E_FILL_] = e
        buf[MEAN_FILL_] = (buf[TAU_FILL_] / dt) * (1.0 - e)
        e = math.exp(-dt / buf[TAU_VENT_])
        buf[E_VENT_] = e
        buf[MEAN_VENT_] = (buf[TAU_VENT_] / dt) * (1.0 - e)
    p_max = buf[P_MAX_]
    cmd_max = 0.0
    for i in range(n):
        p0 = work[R_PRESS, i]
        cmd = work[R_CMD, i]
        cmd_max = max(cmd_max, cmd)
        valve = work[R_VALVE, i]
        if valve == 2.0:
            target = 0.0
        elif valve == 1.0:
            target = p0
        else:
            target = min(max(cmd, 0.0), p_max)
        if target > p0:
            e = buf[E_FILL_]
            mean = buf[MEAN_FILL_]
        else:
            e = buf[E_VENT_]
            mean = buf[MEAN_VENT_]
        p1 = target + (p0 - target) * e
        work[R_P1, i] = p1
        work[R_PBAR, i] = target + (p0 - target) * mean
        work[R_VSTEP, i] = p0 - p1 if valve == 2.0 else 0.0
    buf[CMD_MAX_] = cmd_max
    resistance = 0.0
    if v0 > 0.0:
        resistance = buf[DAVIS_A_] + buf[DAVIS_B_] * v0 + buf[DAVIS_C_] * v0 * v0
    external = resistance + buf[GRADE_]
    h_prev = buf[H_PREV_]
    r_pred = dt / h_prev if h_prev > 0.0 else 0.0
    v = _newton(buf, work, n, nl, v0, dt, external, r_pred)
    if v < 0.0:
        buf[FALLBACK_] += 1.0
        v, bad = _safeguarded(buf, work, n, nl, v0, dt, external)
        if bad >= 0:
            buf[ERR_AXLE_] = bad
            return NONFINITE
    # bookkeeping
    grade = buf[GRADE_]
    wb = 0.0
    wc = 0.0
    for i in range(n):
        wb += (brake * work[R_PBAR, i] - work[R_TORQUE, i]) * work[R_W, i] * dt
        wc += work[R_EMU, i] * work[R_LOAD, i] * (v - work[R_W, i] * radius) * dt
    buf[WB_] += wb
    buf[WC_] += wc
    buf[WR_] += resistance * v * dt + 0.0
    buf[WG_] += grade * v * dt
    vr = max(v, 1e-6)
    ke = 0.5 * mass * v * v
    for i in range(n):
        w = work[R_W, i]
        work[R_DOMEGA, i] = w - work[R_OMEGA, i]
        work[R_VENTED, i] += work[R_VSTEP, i]
        work[R_OMEGA, i] = w
        work[R_PRESS, i] = work[R_P1, i]
        work[R_MU, i] = work[R_EMU, i]
        work[R_FORCE, i] = work[R_EMU, i] * work[R_LOAD, i]
        work[R_CREEP, i] = (v - w * radius) / vr
        ke += 0.5 * inertia * w * w
    buf[DV_PREV_] = v - v0
    buf[H_PREV_] = dt
    buf[D_] = (v0 - v) / dt
    buf[X_] += 0.5 * (v0 + v) * dt
    buf[T_] += dt
    buf[V_] = v
    buf[STEPS_] += 1.0
    status = OK
    if v <= buf[STOP_SPEED_]:
        d = buf[D_]
        if v > 0 and d > 0:
            buf[STOP_X_] = buf[X_] + v * v / (2 * d)
            buf[STOP_T_] = buf[T_] + v / d
        else:
            buf[STOP_X_] = buf[X_]
            buf[STOP_T_] = buf[T_]
        buf[STOPPED_] = 1.0
        status = STOPPED
    if buf[RECORD_] != 0.0:
        r = rows[int(buf[NROW_])]
        r[0] = buf[T_]
        r[1] = buf[X_]
        r[2] = v
        r[3] = buf[D_]
        for i in range(n):
            r[4 + i] = work[R_OMEGA, i]
            r[4 + n + i] = work[R_PRESS, i]
            r[4 + 2 * n + i] = work[R_VALVE, i]
            r[4 + 3 * n + i] = work[R_CREEP, i]
            r[4 + 4 * n + i] = work[R_FORCE, i]
            r[4 + 5 * n + i] = work[R_LOAD, i]
            r[4 + 6 * n + i] = work[R_MU, i]
            r[4 + 7 * n + i] = work[R_AVAIL, i]
        b = 4 + 8 * n
        r[b] = cmd_max
        r[b + 1] = ke
        r[b + 2] = buf[WB_]
        r[b + 3] = buf[WC_]
        r[b + 4] = buf[WR_] + buf[WG_]
        buf[NROW_] += 1.0
    return status


@njit(cache=True, error_model="numpy")
def _set_valves(buf, work, n):
    """Group the new valve states in work[R_TMP] per bogie if so configured, count vent
    actions and make them the valve states."""
    if buf[BOGIE_] != 0.0:
        half = n // 2
        m1 = 0.0
        m2 = 0.0
        for i in range(half):
            m1 = max(m1, work[R_TMP, i])
            m2 = max(m2, work[R_TMP, half + i])
        for i in range(half):
            work[R_TMP, i] = m1
            work[R_TMP, half + i] = m2
    for i in range(n):
        new = work[R_TMP, i]
        if new == 2.0 and work[R_VALVE, i] != 2.0:
            work[R_VACT, i] += 1.0
        work[R_VALVE, i] = new


@njit(cache=True, error_model="numpy")
def step(buf, work, rows, dt):
    """The stepping API: advance by dt (split into equal sub-steps <= max_step) with the inputs
    in work[R_CMD] (commanded pressure per axle), work[R_VIN] (valve state per axle) and
    work[R_TORQUE] (traction torque per axle [N m], positive driving the wheel forward).

    Returns OK, STOPPED (the train is at rest: nothing happens), NONFINITE, BAD_DT,
    BAD_COMMAND, BAD_VALVE or BAD_TORQUE (buf[ERR_AXLE_] and buf[ERR_VALUE_] say which
    input), or
    ROWS_FULL (nothing done: the caller provides a new rows block and calls again).
    """
    if not (dt > 0.0 and dt < math.inf):
        return BAD_DT
    if buf[STOPPED_] != 0.0:
        return STOPPED
    n = int(buf[N_])
    for i in range(n):
        c = work[R_CMD, i]
        if not (c >= 0.0 and c < math.inf):
            buf[ERR_AXLE_] = i
            buf[ERR_VALUE_] = c
            return BAD_COMMAND
        s = work[R_VIN, i]
        if not (s == 0.0 or s == 1.0 or s == 2.0):
            buf[ERR_AXLE_] = i
            buf[ERR_VALUE_] = s
            return BAD_VALVE
        q = work[R_TORQUE, i]
        if not (q > -math.inf and q < math.inf):
            buf[ERR_AXLE_] = i
            buf[ERR_VALUE_] = q
            return BAD_TORQUE
    nsub = max(1, int(math.ceil(dt / buf[MAX_STEP_] - 1e-9)))
    if buf[RECORD_] != 0.0 and buf[NROW_] + nsub > rows.shape[0]:
        return ROWS_FULL
    for i in range(n):
        work[R_TMP, i] = work[R_VIN, i]
    _set_valves(buf, work, n)
    h = dt / nsub
    for _ in range(nsub):
        status = _advance(buf, work, rows, h)
        if status != OK:
            return status
    return OK


@njit(cache=True, error_model="numpy")
def step_free(buf, work, dt):
    """:func:`step` without recording (``buf[RECORD_]`` must be 0): one array less to pass."""
    return step(buf, work, work, dt)


@njit(cache=True, error_model="numpy")
def _wsp(buf, work, n, t):
    """WheelSlideProtection.__call__ (settings in buf, state in work); valves into R_TMP."""
    ws = int(buf[O_WS_])
    period = buf[ws]
    radius = buf[RADIUS_]
    umax = -math.inf
    for i in range(n):
        umax = max(umax, work[R_OMEGA, i] * radius)
    if buf[INIT_] == 0.0:
        for i in range(n):
            work[R_PREV, i] = work[R_OMEGA, i] * radius
        buf[REF_] = umax
        buf[INIT_] = 1.0
    alpha = period / (buf[ws + 11] + period)
    for i in range(n):
        u = work[R_OMEGA, i] * radius
        raw = (work[R_PREV, i] - u) / period
        work[R_WDEC, i] += alpha * (raw - work[R_WDEC, i])
        work[R_PREV, i] = u
    ref = buf[REF_]
    rate = buf[ws + 1]
    if umax < ref - max(buf[ws + 2] * ref, buf[ws + 3]):
        rate = buf[ws + 14]
    v_ref = max(umax, ref - rate * period)
    buf[REF_] = v_ref
    hold = max(buf[ws + 2] * v_ref, buf[ws + 3])
    vent = max(buf[ws + 4] * v_ref, buf[ws + 5])
    reapply = max(buf[ws + 6] * v_ref, buf[ws + 7])
    for i in range(n):
        slip = v_ref - work[R_OMEGA, i] * radius
        a = work[R_WDEC, i]
        st = work[R_WST, i]
        new = st
        want_vent = slip > vent or a > buf[ws + 9]
        want_hold = slip > hold or a > buf[ws + 8]
        if st == 0.0:
            new = 2.0 if want_vent else (1.0 if want_hold else 0.0)
        elif st == 2.0:
            if -a > buf[ws + 10]:
                new = 1.0
        else:
            accelerating = -a > buf[ws + 10]
            if want_vent and not accelerating:
                new = 2.0
            elif slip < reapply and not accelerating and a < buf[ws + 8]:
                new = 0.0
        if t < work[R_FORCED, i]:
            new = 0.0
        elif new != 0.0:
            if math.isnan(work[R_RELEASED, i]):
                work[R_RELEASED, i] = t
            elif t - work[R_RELEASED, i] >= buf[ws + 12] - 1e-12:
                new = 0.0
                work[R_FORCED, i] = t + buf[ws + 13]
        if new == 0.0:
            work[R_RELEASED, i] = math.nan
        work[R_WST, i] = new
        work[R_TMP, i] = new


@njit(cache=True, error_model="numpy")
def run(buf, work, rows, dt, k_end):
    """Steps k = buf[K_] … k_end - 1 of simulate() with the brake demand in buf and, if on,
    the default WSP; stops early when ``rows`` is full. Returns OK (k_end reached or rows
    full), STOPPED or NONFINITE."""
    n = int(buf[N_])
    ratio = int(buf[RATIO_])
    wsp_on = buf[WSP_ON_] != 0.0
    k = int(buf[K_])
    while k < k_end and buf[NROW_] < rows.shape[0]:
        t = k * dt
        cmd = 0.0
        if t >= buf[DEM_T0_]:
            if buf[DEM_RAMP_] <= 0.0:
                cmd = buf[DEM_P_]
            else:
                cmd = buf[DEM_P_] * min(1.0, (t - buf[DEM_T0_]) / buf[DEM_RAMP_])
        if wsp_on and k % ratio == 0:
            _wsp(buf, work, n, t)
            _set_valves(buf, work, n)
        for i in range(n):
            work[R_CMD, i] = cmd
        status = _advance(buf, work, rows, dt)
        k += 1
        buf[K_] = k
        if status != OK:
            return status
    return OK


@njit(cache=True, error_model="numpy")
def available(buf, work):
    """The adhesion available per axle at the current conditions (into work[R_AVAIL])."""
    n = int(buf[N_])
    if buf[KIND_] == 2.0:
        _peak_user(buf, work, n, max(buf[V_], 0.0))
    else:
        _peak_lanes(work, n, int(buf[NLANES_]), buf[V_])


# --------------------------------------------------------------------------------------------
# Stale-cache guard: numba keys its cache on this file alone, but the kernels freeze the
# constants of ``_layout.py`` at compile time and inline njit helpers of
# ``railadhesion.models.kernels``. A checksum of both is compiled in too; if the cached value
# differs from the current one, every cache entry of this module is dropped (before any other
# kernel is loaded) so that the kernels compile afresh (railadhesion._jit.guard_cache).

_LAYOUT_FINGERPRINT = _layout_checksum() ^ source_checksum(_models_kernels)


@njit(cache=True)
def _compiled_layout_fingerprint():
    return _LAYOUT_FINGERPRINT


def purge_stale_cache(cache_dir, compiled: int, current: int) -> list:
    """Delete this module's numba cache files in ``cache_dir`` if ``compiled`` (the checksum
    the cached code was built with) differs from ``current``; return the deleted paths."""
    return purge_module_cache(cache_dir, Path(__file__).stem, compiled, current)


guard_cache(_compiled_layout_fingerprint, __file__, _LAYOUT_FINGERPRINT)
