"""The monitor's per-sample step, compiled (numba), on named state (:mod:`.layout`).

One call of :func:`step` takes one sample of the signals (time, speed reference, wheel speeds,
brake pressures and/or torques) and updates every axle. It allocates nothing, raises nothing
and touches no Python object, so the same function serves the Python object
(:class:`~railadhesion.monitor.AdhesionMonitor`), the log replay (:func:`replay`, a compiled
loop over the samples) and can be compiled as a C function (``numba.cfunc``) for a native
FMU.

What one sample does
--------------------
All helpers compile with numba's ``error_model="numpy"``: no exception path anywhere (a
division by zero gives inf or NaN, which the checks catch), as a C function needs.

1. **Time**: a time that is NaN or not after the previous one is rejected (nothing changes,
   every axle ``unknown`` until ``recovery_time`` after the last good sample); a step longer
   than ``gap_factor`` sample periods is a gap: the filters restart.
2. **Speed reference** v: checked (finite, plausible, not stuck), filtered at the wheel
   cut-off; the deceleration d = -dv/dt (backward difference) at the vehicle cut-off.
3. **Per axle**, causal versions of seed 002 eqs. 10-12 (Allotta, Malvezzi, Toni): wheel
   speed, pressure and torque checked (finite, plausible, not stuck, no step that no torque
   explains); the angular acceleration (backward difference), the pressure, the torque and
   the slip v - omega R filtered at the wheel cut-off (first-order, as the paper's on-board
   filters, the coefficients of :class:`railadhesion.identification.signals.FirstOrderFilter`
   in causal mode); the axle load N = N0 + N1 d (eqs. 11-12, affine in d); the creepage
   (v - omega R)/v and the adhesion in use, eq. 10 with the traction torque tau:
   ``mu = (J omega_dot + c p - tau) / (R N)`` (braking positive;
   :func:`railadhesion.identification.brake_tests.axle_adhesion_law`).
4. **Wheel radius**: learned while the axle coasts (no pressure, no torque) as the ratio of
   the sums of v and omega over the coasting samples after ``coast_settle``; a coasting
   radius away from the learned one is a changed wheel.
5. **Blocks**: the signals are averaged over blocks of ``block_time`` (staggered between the
   axles); a block gives one point of the creep curve, its creep ``1 - R mean(omega) /
   mean(v)`` and its adhesion (eq. 10 with the mean pressure and torque and the angular
   acceleration over the block, ``(omega_last - omega_first)/(t_last - t_first)``), with the
   variances the sensor noise gives them (independent from block to block).
6. **Estimator** (at the end of a block): a bank of extended Kalman filters, one per
   hypothesis of the friction level mu (41 levels 0.02-0.9, 10 % apart, and "no bend"),
   each estimating ln(initial slope) of Fletcher's 2D curve (seed 001 eqs. 8-12 with k_s = 1,
   :func:`railadhesion.models.kernels.fletcher_scalar`) from the blocks; the hypotheses are
   weighted by their residuals (multiple-model adaptive estimation, Magill 1965), with the
   creep noise carried into the adhesion residual through the curve's slope ("effective
   variance", Orear 1982) and exponential forgetting of time constant ``memory``. The
   weights give the available adhesion and its band (quantiles). The residuals are weighed as
   Student-t (4 degrees of freedom) so that one odd block cannot swing the weights, and the
   initial slope is bounded (``max_slope``: no contact is stiffer than Kalker's). A block far off
   the prediction, or whose creep is far from the remembered creeps at the same adhesion
   (``change_z`` standard deviations, ``change_blocks`` blocks in a row), restarts the
   estimate (a change of the rail).
7. **Level** per axle: ``unknown`` with the reason for bad data (and ``recovery_time``
   after), a radius not learned, a low speed, sliding, or data that cannot show the bend;
   else ``normal`` (adhesion in use already above the threshold, or the band above it),
   ``low`` (band below), ``caution`` (band across). A new level is reported once it has held
   ``confirm_time``; ``unknown`` at once.
8. **Brake coefficient**, eq. 14 causally: ``c = (M d - J sum(omega_dot)/R) / (sum(p)/R)``
   with d, the angular accelerations and the pressures filtered alike at the vehicle cut-off,
   averaged over braking (mean pressure >= 0.5 bar, all wheels turning) with a 10 s
   exponential memory (running resistance and gradient neglected, as in the paper;
   :func:`railadhesion.identification.brake_tests.brake_coefficient_law`).
"""

from __future__ import annotations

import math

from numba import njit

from railadhesion import _jit
from railadhesion.identification.brake_tests import axle_adhesion_law, brake_coefficient_law
from railadhesion.models import kernels as _models_kernels
from railadhesion.models import polach as _polach
from railadhesion.models import twod as _twod
from railadhesion.models.kernels import fletcher_scalar, polach_curve_scalar
from railadhesion.monitor import layout

__all__ = ["step", "step_record", "replay", "reset_state", "KERNEL_FINGERPRINT"]

# constants frozen into the compiled code
_UNKNOWN, _NORMAL, _CAUTION, _LOW = layout.UNKNOWN, layout.NORMAL, layout.CAUTION, layout.LOW
_NODES = layout.NODES
_FINITE = layout.FINITE_NODES
_FAMILY = layout.FAMILY
_SHAPES = len(layout.SHAPES)
_NAN = math.nan
_INF = math.inf

# reason codes (layout.REASONS)
R_STARTING, R_LOW, R_ABOVE, R_USED, R_STRADDLE = 0, 1, 2, 3, 4
R_CREEP_SMALL, R_BEND, R_SLIDING = 5, 6, 7
R_SPEED_LOW, R_RADIUS, R_RADIUS_CHANGED, R_LONE, R_JUMP = 10, 11, 12, 13, 14
R_NO_FORCE, R_SIGN, R_UNCONFIRMED = 15, 16, 17
R_TIME_ORDER, R_GAP, R_NAN_SPEED, R_NAN_WHEEL, R_NAN_FORCE = 20, 21, 22, 23, 24
R_STUCK_SPEED, R_STUCK_WHEEL, R_STUCK_PRESSURE = 25, 26, 27
R_BAD_SPEED, R_BAD_WHEEL, R_BAD_PRESSURE, R_BAD_TORQUE, R_BAD_ADHESION = 28, 29, 30, 31, 32
R_TIME_NAN, R_STUCK_TORQUE, R_RECOVERING, R_NUMERICAL = 33, 34, 40, 41

# radius states
_NOMINAL, _LEARNED, _UNCONFIRMED_R = 0, 1, 2

_C_MEMORY = 10.0  # s: memory of the causal eq. 14 mean
_DOF = 4.0  # degrees of freedom of the Student-t residuals of the estimator (our choice)
_C_MIN_PRESSURE = 0.5e5  # Pa: braking for eq. 14 (as identify_adhesion's window)

# The kernels inline fletcher_scalar and polach_curve_scalar of railadhesion.models.kernels
# (the laws of models/twod.py and models/polach.py), which numba's cache of this file does not
# track: a checksum of those modules and of the layout is compiled in, and a mismatch drops
# this module's cached code (railadhesion._jit.guard_cache).
KERNEL_FINGERPRINT = _jit.source_checksum(_models_kernels, _polach, _twod, layout)


@njit(cache=True, error_model="numpy")
def _compiled_fingerprint():
    return KERNEL_FINGERPRINT


_jit.guard_cache(_compiled_fingerprint, __file__, KERNEL_FINGERPRINT)


@njit(cache=True, inline="always", error_model="numpy")
def _finite(x):
    return x == x and x != _INF and x != -_INF


@njit(cache=True, inline="always", error_model="numpy")
def _others_mean(values, i, n):
    """Mean of the finite ``values`` of the axles other than i and their count; NaN when
    there are none."""
    total = 0.0
    cnt = 0
    for j in range(n):
        if j != i and _finite(values[j]):
            total += values[j]
            cnt += 1
    return (total / cnt if cnt > 0 else _NAN), cnt


@njit(cache=True, inline="always", error_model="numpy")
def _flagged_others_mean(values, flags, i, n):
    """:func:`_others_mean` over the axles with ``flags[j] != 0`` only."""
    total = 0.0
    cnt = 0
    for j in range(n):
        if j != i and flags[j] != 0 and _finite(values[j]):
            total += values[j]
            cnt += 1
    return (total / cnt if cnt > 0 else _NAN), cnt


@njit(cache=True, inline="always", error_model="numpy")
def _stuck(values, since, refs, i, x, t, ref, armed, wait, moved):
    """Stuck detector of one channel of axle i (its last value, since when, and what its
    reference was then): a new reading ``x`` restarts it; an unchanged one is stuck when it
    has held for ``wait`` [s] while its reference ``ref`` moved by more than ``moved``
    (``armed``: the check applies). Returns how long it has held [s], or -1 if not stuck."""
    if x != values[i]:
        values[i] = x
        since[i] = t
        refs[i] = ref
    elif armed and t - since[i] >= wait and abs(ref - refs[i]) > moved:
        return t - since[i]
    return -1.0


@njit(cache=True, inline="always", error_model="numpy")
def _filt(z, x, b0, b1, a1):
    """One sample of the first-order IIR (direct form II transposed): (y, new state)."""
    y = b0 * x + z
    return y, b1 * x - a1 * y


@njit(cache=True, inline="always", error_model="numpy")
def _curve(cfg, j, x, slope):
    """Hypothesis j's curve at creep x >= 0: (adhesion, d/d creep, d/d slope)."""
    if j < _FAMILY:
        f, fx, fs, _ = fletcher_scalar(x, slope, cfg.node_q[j])
        return f, fx, fs
    return polach_curve_scalar(x, slope, cfg.node_q[j], cfg.polach_ratio)


@njit(cache=True, error_model="numpy")
def _slope_through(cfg, j, x, y):
    """ln of the initial slope that puts hypothesis j's curve through (x, y), x, y > 0 (the
    curve's largest slope if it cannot reach y)."""
    q = cfg.node_q[j]
    if q == 0.0:
        return math.log(y / x)
    if j < _FAMILY:  # Fletcher: closed form
        if y * q < 1.0:
            return math.log(3.0 * (1.0 - (1.0 - y * q) ** (1.0 / 3.0)) / (x * q))
        return math.log(3.0 / (x * q))  # saturates at x: the most it can give is mu
    if y * q >= 0.999:  # Polach: below its asymptote only
        return cfg.log_slope_max
    m = math.log(y / x)  # the secant; the curve lies below its tangent: Newton upwards
    for _ in range(30):
        slope = math.exp(m)
        f, _, fs = polach_curve_scalar(x, slope, q, cfg.polach_ratio)
        step = (y - f) / max(fs * slope, 1e-300)
        m += min(step, 2.0)
        if abs(step) < 1e-10 or m > cfg.log_slope_max:
            break
    return m


@njit(cache=True, error_model="numpy")
def _bank_reset(cfg, st, bank, i, x, y):
    """Restart axle i's estimator on the point (x, y): every hypothesis' slope put through it
    (or at the prior for a point at the origin), wide variance, prior weights."""
    for j in range(_NODES):
        m = cfg.log_slope0
        if x > 1e-6 and y > 0.0:
            m = _slope_through(cfg, j, x, y)
        bank[0, i, j] = cfg.node_logprior[j]
        bank[1, i, j] = min(max(m, cfg.log_slope_min), cfg.log_slope_max)
        bank[2, i, j] = cfg.var_slope0
    st.updates[i] = 0
    st.outliers[i] = 0
    st.nis[i] = 1.0


@njit(cache=True, error_model="numpy")
def _temper(cfg, bank, i, factor):
    """Forget: log-weights times ``factor`` (<= 1), slope variances divided by it."""
    for j in range(_NODES):
        bank[0, i, j] *= factor
        bank[2, i, j] = min(bank[2, i, j] / factor, cfg.var_slope0)


@njit(cache=True, error_model="numpy")
def _normalise(cfg, bank, i, totals, w):
    """Per shape: subtract the largest log-weight; put each hypothesis' mixture weight in
    ``w`` (the shapes in their fixed proportions, each normalised: their fit does not choose
    between them) and each shape's sum of exp(log-weight) in ``totals``."""
    for f in range(_SHAPES):
        top = -_INF
        for j in range(f * _FAMILY, (f + 1) * _FAMILY):
            if bank[0, i, j] > top:
                top = bank[0, i, j]
        total = 0.0
        for j in range(f * _FAMILY, (f + 1) * _FAMILY):
            bank[0, i, j] -= top
            e = math.exp(bank[0, i, j])
            w[j] = e
            total += e
        totals[f] = total
        scale = cfg.shape_weight[f] / total
        for j in range(f * _FAMILY, (f + 1) * _FAMILY):
            w[j] *= scale


@njit(cache=True, error_model="numpy")
def _quantile(cfg, w, prob):
    """Quantile ``prob`` of the friction level in the mixture (weights ``w``): the weight of
    level j (both shapes) spread evenly over its cell in ln(mu) (half a node step either side),
    the "no bend" hypotheses' weight at +inf."""
    acc = 0.0
    half = 0.5 * cfg.node_step
    for j in range(_FINITE):
        wj = 0.0
        for f in range(_SHAPES):
            wj += w[f * _FAMILY + j]
        if acc + wj >= prob and wj > 0.0:
            frac = (prob - acc) / wj
            return math.exp(math.log(cfg.node_mu[j]) - half + frac * cfg.node_step)
        acc += wj
    return _INF


@njit(cache=True, error_model="numpy")
def _shape_median(cfg, w, f):
    """Median of the friction level under shape f alone (inf if the "no bend" hypothesis
    holds half its weight)."""
    acc = 0.0
    half = 0.5 * cfg.node_step
    share = cfg.shape_weight[f]
    for j in range(_FINITE):
        wj = w[f * _FAMILY + j] / share
        if acc + wj >= 0.5 and wj > 0.0:
            return math.exp(math.log(cfg.node_mu[j]) - half + (0.5 - acc) / wj * cfg.node_step)
        acc += wj
    return _INF


@njit(cache=True, error_model="numpy")
def _node_residual(cfg, bank, i, j, x, y, var_x, var_y, scale, res):
    """Hypothesis j against the block (x, y): the point of its curve closest to the block in
    the metric of the block's noise (a Gauss-Newton step from the measured creep), and the
    residual there. Writes (residual, d y/d ln S, variance) into ``res`` [3 j .. 3 j + 2].

    Linearising the curve at that point rather than at the measured creep keeps the residual
    of a block far from a steep curve large (the orthogonal distance: errors-in-variables with
    the creep noise carried through the local slope, Orear 1982)."""
    slope = math.exp(bank[1, i, j])
    vx = scale * var_x
    vy = scale * var_y
    f, fx, _ = _curve(cfg, j, x, slope)
    xs = max(x + vx * fx * (y - f) / (vy + fx * fx * vx), 0.0)  # one Gauss-Newton step
    f, fx, fs = _curve(cfg, j, xs, slope)
    h = fs * slope
    res[3 * j] = y - f - fx * (x - xs)
    res[3 * j + 1] = h
    res[3 * j + 2] = vy + fx * fx * vx + h * h * bank[2, i, j]


@njit(cache=True, error_model="numpy")
def _ring_push(cfg, st, i, x, y, ylo):
    k = st.ring_pos[i]
    st.ring_x[i, k] = x
    st.ring_y[i, k] = y
    st.ring_ylo[i, k] = ylo
    st.ring_pos[i] = (k + 1) % cfg.ring_len
    if st.ring_n[i] < cfg.ring_len:
        st.ring_n[i] += 1


@njit(cache=True, error_model="numpy")
def _shift_at_equal_force(cfg, st, i, x, y):
    """Creep of the new point minus the mean creep of the remembered points at about the same
    adhesion (within 15 %), NaN if fewer than 3 such points."""
    tol = 0.15 * max(abs(y), 0.01)
    acc = 0.0
    cnt = 0
    for k in range(st.ring_n[i]):
        if abs(st.ring_y[i, k] - y) <= tol:
            acc += st.ring_x[i, k]
            cnt += 1
    if cnt < 3:
        return _NAN
    return x - acc / cnt


@njit(cache=True, error_model="numpy")
def _creep_jump(cfg, st, i, x, y, sd_x, sd_y):
    """How many standard deviations the new block's creep lies from the remembered blocks at
    about the same adhesion (within 10 % or 2 sd of it; at least 5 of them; the block is not
    among them yet): 0 if there are too few. A creep that jumps while the force stays is a
    change of the curve (or of the wheel), whatever the curve."""
    tol = max(0.1 * abs(y), 2.0 * sd_y)
    acc = 0.0
    acc2 = 0.0
    cnt = 0
    for k in range(st.ring_n[i]):
        if abs(st.ring_y[i, k] - y) <= tol:
            xk = st.ring_x[i, k]
            acc += xk
            acc2 += xk * xk
            cnt += 1
    if cnt < 5:
        return 0.0
    mean = acc / cnt
    spread = math.sqrt(max(acc2 / cnt - mean * mean, 0.0))
    return abs(x - mean) / max(spread, 1.5 * sd_x)


@njit(cache=True, error_model="numpy")
def _lone_confirmed(cfg, st, i, t):
    """True if another axle restarted its estimate within the time the rail change takes to
    travel between them (plus ``lone_window``)."""
    v = max(st.v_f, 1.0)
    for j in range(cfg.n_axles):
        if j == i or not (st.changed_at[j] == st.changed_at[j]):
            continue
        window = abs(cfg.offset[i] - cfg.offset[j]) / v + cfg.lone_window
        if abs(st.changed_at[j] - t) <= window:
            return True
    return False


@njit(cache=True, error_model="numpy")
def _mark_bad(cfg, st, i, t, code, v1, v2):
    """Bad data on axle i: its block is spoilt, the axle is unknown until ``recovery_time``
    after now (the reason and its values kept for the report)."""
    st.b_ok[i] = 0
    st.recover_until[i] = t + cfg.recovery_time
    st.recover_code[i] = code
    st.recover_v1[i] = v1
    st.recover_v2[i] = v2


@njit(cache=True, error_model="numpy")
def _report(cfg, st, out, i, t, level, code, v1, v2):
    """Report axle i's level: ``unknown`` at once, any other level once it has held
    ``confirm_time`` (meanwhile the previous level and reason stay)."""
    if level == _UNKNOWN or level == st.level[i]:
        if level != st.level[i]:
            st.level[i] = level
            st.level_since[i] = t
        st.pending[i] = -1
    else:
        if st.pending[i] != level:
            st.pending[i] = level
            st.pending_since[i] = t
        if t - st.pending_since[i] >= cfg.confirm_time:
            st.level[i] = level
            st.level_since[i] = t
            st.pending[i] = -1
        else:
            out.level[i] = st.level[i]
            out.level_since[i] = st.level_since[i]
            return
    out.level[i] = level
    out.level_since[i] = st.level_since[i]
    out.reason[i] = code
    out.reason_v1[i] = v1
    out.reason_v2[i] = v2


@njit(cache=True, error_model="numpy")
def _decide(cfg, st, i, w, sd_x, sd_y):
    """The estimator's verdict for axle i from its weights and the remembered data: their
    range, and how much they moved along the curve (``sd_x``, ``sd_y``: a block's creep and
    adhesion noise)."""
    lo = _quantile(cfg, w, cfg.q_low)
    hi = _quantile(cfg, w, cfg.q_high)
    # the estimate: the shapes' medians in their fixed proportions (the mixture's own median
    # would sit at the edge of one shape's mass when the two disagree)
    med = 0.0
    for f in range(_SHAPES):
        if cfg.shape_weight[f] > 0.0:
            med += cfg.shape_weight[f] * _shape_median(cfg, w, f)
    med = min(max(med, lo), hi)
    st.est[i] = med
    st.est_lo[i] = lo
    st.est_hi[i] = hi
    xmax = 0.0
    ymax = 0.0
    used = -_INF
    ysum = 0.0
    ysum2 = 0.0
    xsum = 0.0
    xsum2 = 0.0
    m = st.ring_n[i]
    for k in range(m):
        y = st.ring_y[i, k]
        x = st.ring_x[i, k]
        xmax = max(xmax, x)
        ymax = max(ymax, y)
        used = max(used, st.ring_ylo[i, k])
        ysum += y
        ysum2 += y * y
        xsum += x
        xsum2 += x * x
    mm = max(m, 1)
    ymean = ysum / mm
    yspread = math.sqrt(max(ysum2 / mm - ymean * ymean, 0.0))
    xmean = xsum / mm
    xspread = math.sqrt(max(xsum2 / mm - xmean * xmean, 0.0))
    # moved along the curve: the force, or the creep, varied beyond its noise
    moved = (yspread >= max(cfg.min_variation * ymean, 3.0 * sd_y)
             or xspread >= max(cfg.min_variation * xmean, 3.0 * sd_x))
    thr = cfg.threshold
    if used >= thr:
        verdict, code, v1, v2 = _NORMAL, R_USED, used, _NAN
    elif xmax < cfg.min_creep or ymax < cfg.min_adhesion:
        verdict, code, v1, v2 = _UNKNOWN, R_CREEP_SMALL, xmax, ymax
    elif not moved:
        # one point of the curve (its noise only), whatever the weights say
        verdict, code, v1, v2 = _UNKNOWN, R_BEND, xmax, max(used, 0.0)
    elif lo >= thr:
        verdict, code, v1, v2 = _NORMAL, R_ABOVE, med, lo
    elif hi == _INF:
        verdict, code, v1, v2 = _UNKNOWN, R_BEND, xmax, max(lo, used, 0.0)
    elif hi < thr:
        verdict, code, v1, v2 = _LOW, R_LOW, med, hi
    else:
        verdict, code, v1, v2 = _CAUTION, R_STRADDLE, med, lo
    _set_verdict(st, i, verdict, code, v1, v2)


@njit(cache=True, inline="always", error_model="numpy")
def _set_verdict(st, i, verdict, code, v1, v2):
    """Keep the estimator's verdict on axle i: its level, reason code and the reason's values
    (reported once the level has held, :func:`_report`)."""
    st.verdict[i] = verdict
    st.verdict_code[i] = code
    st.verdict_v1[i] = v1
    st.verdict_v2[i] = v2


@njit(cache=True, error_model="numpy")
def _estimate(cfg, st, bank, out, i, t, x, mu, var_x, var_mu):
    """One block (creep x, adhesion mu, their variances) into axle i's estimator."""
    sgn = 1.0 if mu >= 0.0 else -1.0
    if abs(mu) < 3.0 * math.sqrt(var_mu):
        sgn = 1.0 if x >= 0.0 else -1.0
    xs = sgn * x
    ys = sgn * mu
    sd_x = math.sqrt(var_x)
    sd_y = math.sqrt(var_mu)
    out.block_creep[i] = x
    out.block_adhesion[i] = mu
    if st.radius_state[i] != _LEARNED:
        return  # the creep is not known well enough (the level says why)
    if xs < -max(4.0 * sd_x, 2e-4) and ys > 4.0 * sd_y:
        _mark_bad(cfg, st, i, t, R_SIGN, x, mu)
        st.sign_blocks[i] += 1
        if st.sign_blocks[i] * cfg.block_time >= 1.0 and cfg.learn_radius != 0:
            st.radius_state[i] = _UNCONFIRMED_R  # a lasting creep offset: radius to relearn
        return
    st.sign_blocks[i] = 0
    if xs > cfg.max_fit_creep:
        st.sliding[i] = 1
        st.slide_creep[i] = xs
        return
    st.sliding[i] = 0
    ylo = ys - 2.0 * sd_y
    xe = max(xs, 0.0)
    totals = st.totals
    w = st.weights[i]
    if ys < 4.0 * sd_y:
        # no force to speak of: the point says nothing about the curve beyond the origin (and
        # its creep, pure noise, would pull every slope towards zero); it counts for the data
        # range only
        _ring_push(cfg, st, i, xs, ys, ylo)
        if st.updates[i] > 0:
            _normalise(cfg, bank, i, totals, w)
            _decide(cfg, st, i, w, sd_x, sd_y)
        return
    if st.updates[i] == 0:
        _bank_reset(cfg, st, bank, i, xe, ys)
    # forgetting, then the residual of every hypothesis
    _temper(cfg, bank, i, cfg.forget)
    for j in range(_NODES):
        bank[2, i, j] = min(bank[2, i, j] + cfg.slope_walk, cfg.var_slope0)
    _normalise(cfg, bank, i, totals, w)
    scale = max(st.nis[i], 1.0)
    res = st.scratch[i]
    for j in range(_NODES):
        _node_residual(cfg, bank, i, j, xe, ys, var_x, var_mu, scale, res)
    # change test: the block's likelihood under the mixture of hypotheses, as a distance
    like = 0.0
    for j in range(_NODES):
        e = res[3 * j]
        like += w[j] * math.exp(-0.5 * e * e / res[3 * j + 2])
    dist2 = -2.0 * math.log(max(like, 1e-300))
    if not _finite(dist2):
        dist2 = 0.0
    jump = _creep_jump(cfg, st, i, xs, ys, sd_x, sd_y)
    if (dist2 > cfg.change_z * cfg.change_z or jump > cfg.change_z) and st.updates[i] > 0:
        st.outliers[i] += 1
        if st.outliers[i] < cfg.change_blocks:
            # one block off: held (not remembered, so that it cannot blur the test of the
            # next one) until the next tells whether the rail changed
            st.held[i, 0] = xs
            st.held[i, 1] = ys
            st.held[i, 2] = ylo
            return
        # a change of the rail (or of the wheel): restart on this block
        shift = _shift_at_equal_force(cfg, st, i, xs, ys)
        st.changed_at[i] = t
        if shift == shift and abs(shift) >= cfg.lone_shift:
            st.shift[i] = shift
            if _lone_confirmed(cfg, st, i, t):
                st.lone_pending[i] = 0
            else:
                reach = 0.0
                for j in range(cfg.n_axles):
                    reach = max(reach, abs(cfg.offset[i] - cfg.offset[j]))
                st.lone_pending[i] = 1
                st.lone_deadline[i] = t + reach / max(st.v_f, 1.0) + cfg.lone_window
        # the remembered points belong to the old rail: keep the blocks of the new one
        st.ring_n[i] = 0
        st.ring_pos[i] = 0
        if cfg.change_blocks > 1:
            _ring_push(cfg, st, i, st.held[i, 0], st.held[i, 1], st.held[i, 2])
        _ring_push(cfg, st, i, xs, ys, ylo)
        _bank_reset(cfg, st, bank, i, xe, ys)
        _normalise(cfg, bank, i, totals, w)
        scale = 1.0
        for j in range(_NODES):
            _node_residual(cfg, bank, i, j, xe, ys, var_x, var_mu, scale, res)
    else:
        st.outliers[i] = 0
        _ring_push(cfg, st, i, xs, ys, ylo)
        # adaptive noise scale: the mean squared standardised residual of the best hypotheses
        st.nis[i] = min(max(0.95 * st.nis[i] + 0.05 * min(dist2, 100.0), 1.0), 100.0)
    # update every hypothesis: EKF on ln(slope), log-weight by its residual; Student-t
    # residuals (``_DOF`` degrees of freedom) so that one odd block cannot swing the weights
    # (the EKF's measurement variance scaled by the same weight: a robust Kalman update)
    ok = True
    for j in range(_NODES):
        e = res[3 * j]
        h = res[3 * j + 1]
        s = res[3 * j + 2]
        p = bank[2, i, j]
        z2 = e * e / s
        robust = (_DOF + 1.0) / (_DOF + z2)
        s_eff = h * h * p + (s - h * h * p) / robust
        k = p * h / s_eff
        m = bank[1, i, j] + k * e
        bank[1, i, j] = min(max(m, cfg.log_slope_min), cfg.log_slope_max)
        bank[2, i, j] = max(p - k * h * p, 1e-12)
        bank[0, i, j] += -0.5 * (_DOF + 1.0) * math.log1p(z2 / _DOF)
        if not (_finite(bank[0, i, j]) and _finite(bank[1, i, j])):
            ok = False
    if not ok:
        _bank_reset(cfg, st, bank, i, xe, ys)
        _mark_bad(cfg, st, i, t, R_NUMERICAL, _NAN, _NAN)
    st.updates[i] += 1
    _normalise(cfg, bank, i, totals, w)
    _decide(cfg, st, i, w, sd_x, sd_y)


@njit(cache=True, error_model="numpy")
def _start(cfg, st, bank, t):
    """First sample (or after a reset): zero state, nominal radii, staggered blocks."""
    n = cfg.n_axles
    st.started = 1
    st.v_ok = 0
    st.eq14_started = 0
    st.v_value = _NAN
    st.v_since = t
    st.c_value = cfg.brake_coefficient
    st.c_sum = 0.0
    st.c_weight = 0.0
    st.c_time = 0.0
    st.d_f = 0.0
    st.v_f = _NAN
    st.vehicle_level = _UNKNOWN
    st.vehicle_since = t
    for i in range(n):
        st.radius[i] = cfg.radius
        st.radius_state[i] = _LEARNED if cfg.learn_radius == 0 else _NOMINAL
        st.radius_sigma[i] = 0.0 if cfg.learn_radius == 0 else cfg.radius_tolerance
        st.filters_on[i] = 0
        st.w_ok[i] = 0
        st.w_value[i] = _NAN
        st.p_value[i] = _NAN
        st.tau_value[i] = _NAN
        st.w_since[i] = t
        st.p_since[i] = t
        st.tau_since[i] = t
        st.recover_until[i] = -_INF
        st.recover_code[i] = 0
        st.coasting[i] = 0
        st.outliers[i] = 0
        st.shift[i] = _NAN
        st.sign_blocks[i] = 0
        st.b_t0[i] = t - i * cfg.block_time / n
        st.b_n[i] = 0
        st.b_ok[i] = 1
        st.ring_n[i] = 0
        st.ring_pos[i] = 0
        st.changed_at[i] = _NAN
        st.lone_pending[i] = 0
        st.est[i] = _NAN
        st.est_lo[i] = _NAN
        st.est_hi[i] = _NAN
        _set_verdict(st, i, _UNKNOWN, R_STARTING, _NAN, _NAN)
        st.level[i] = _UNKNOWN
        st.level_since[i] = t
        st.pending[i] = -1
        st.sliding[i] = 0
        _bank_reset(cfg, st, bank, i, 0.0, 0.0)


@njit(cache=True, error_model="numpy")
def reset_state(config, state, bank):
    """Clear the state: the next sample starts afresh (radii to be learned again)."""
    st = state[0]
    st.started = 0
    st.samples = 0
    st.rejected = 0
    for i in range(config[0].n_axles):
        _bank_reset(config[0], st, bank, i, 0.0, 0.0)


@njit(cache=True, error_model="numpy")
def _reject(cfg, st, out, t, code):
    """A sample that cannot be placed in time: nothing changes but the axles go unknown."""
    st.rejected += 1
    out.status = 1
    for i in range(cfg.n_axles):
        if st.started != 0:
            _mark_bad(cfg, st, i, st.t_last, code, t, st.t_last)
        _report(cfg, st, out, i, st.t_last, _UNKNOWN, code, t, st.t_last)
        out.creep[i] = _NAN
        out.adhesion_used[i] = _NAN
    _vehicle_level(cfg, st, out, st.t_last)


@njit(cache=True, error_model="numpy")
def _vehicle_level(cfg, st, out, t):
    """The most severe level of the axles (low, caution, normal), unknown if none has one."""
    best = _UNKNOWN
    for i in range(cfg.n_axles):
        lv = st.level[i]
        if lv == _LOW:
            best = _LOW
        elif lv == _CAUTION and best != _LOW:
            best = _CAUTION
        elif lv == _NORMAL and best == _UNKNOWN:
            best = _NORMAL
    if best != st.vehicle_level:
        st.vehicle_level = best
        st.vehicle_since = t
    out.vehicle_level = best
    out.vehicle_since = st.vehicle_since


@njit(cache=True, error_model="numpy")
def step(config, inputs, state, outputs, bank):
    """Process one sample (``inputs``); update ``state``, ``bank`` and ``outputs``.

    All arguments are the one-element record arrays of :mod:`railadhesion.monitor.layout`
    (``bank`` the (3, MAX_AXLES, NODES) float array). Returns 0, or 1 when the sample was
    rejected (its time is NaN or not after the previous sample's).
    """
    return step_record(config[0], inputs[0], state[0], outputs[0], bank)


@njit(cache=True, error_model="numpy")
def step_record(cfg, inp, st, out, bank):
    """:func:`step` on the records themselves (not one-element arrays): for a caller holding
    them inside a record of its own, e.g. a native FMU's state."""
    n = cfg.n_axles
    t = inp.time
    out.time = t
    out.status = 0
    if not _finite(t):
        _reject(cfg, st, out, t, R_TIME_NAN)
        return 1
    if st.started != 0 and not (t > st.t_last):
        _reject(cfg, st, out, t, R_TIME_ORDER)
        return 1
    if st.started == 0:
        _start(cfg, st, bank, t)
        dt = 0.0
    else:
        dt = t - st.t_last
    st.t_last = t
    st.samples += 1
    b0f, b1f, a1f = cfg.fast_b0, cfg.fast_b1, cfg.fast_a1
    b0s, b1s, a1s = cfg.slow_b0, cfg.slow_b1, cfg.slow_a1
    if dt > cfg.gap_time:  # a gap: restart the filters, forget in proportion
        factor = cfg.forget ** (dt / cfg.block_time)
        for i in range(n):
            _mark_bad(cfg, st, i, t, R_GAP, dt, _NAN)
            st.filters_on[i] = 0
            st.w_ok[i] = 0
            st.b_t0[i] = t - i * cfg.block_time / n
            st.b_n[i] = 0
            st.coasting[i] = 0
            _temper(cfg, bank, i, factor)
        st.v_ok = 0
        st.eq14_started = 0
        st.v_value = _NAN
    # -- speed reference --------------------------------------------------------------------
    v = inp.train_speed
    v_code = 0
    v_stuck = _NAN
    if v != v:
        v_code = R_NAN_SPEED
    elif not (-0.5 <= v <= 200.0):  # inf included
        v_code = R_BAD_SPEED
    wref = 0.0
    nref = 0
    for i in range(n):
        w = inp.wheel_speed[i]
        if _finite(w):
            wref += w * st.radius[i]
            nref += 1
    wref = wref / nref if nref > 0 else _NAN
    if v_code == 0:
        if v != st.v_value:
            st.v_value = v
            st.v_since = t
            st.v_wref = wref
        elif (t - st.v_since >= cfg.stuck_time and nref > 0 and st.v_wref == st.v_wref
              and abs(wref - st.v_wref) > max(0.05, 6.0 * cfg.sig_w * cfg.radius)):
            v_code = R_STUCK_SPEED
            v_stuck = t - st.v_since
    if v_code == 0:
        if st.v_ok == 0:
            st.z_v = (1.0 - b0f) * v
            st.v_f = v
            d0 = st.d_f if _finite(st.d_f) else 0.0
            st.z_d = (1.0 - b0s) * d0
            st.d_f = d0
            st.v_ok = 1
        else:
            d_raw = -(v - st.v_last) / (t - st.tv_last)
            st.v_f, st.z_v = _filt(st.z_v, v, b0f, b1f, a1f)
            st.d_f, st.z_d = _filt(st.z_d, d_raw, b0s, b1s, a1s)
        st.v_last = v
        st.tv_last = t
    out.train_speed = st.v_f if st.v_ok != 0 else _NAN
    out.deceleration = st.d_f
    c_used = cfg.brake_coefficient
    if cfg.use_identified_c != 0 and st.c_time >= cfg.c_min_time:
        c_used = st.c_value
    out.brake_coefficient = c_used
    out.brake_coefficient_identified = st.c_value if st.c_time > 0.0 else _NAN
    jsum = 0.0
    psum = 0.0
    all_good = v_code == 0
    # -- per axle ---------------------------------------------------------------------------
    for i in range(n):
        r = st.radius[i]
        hp = cfg.has_pressure[i] != 0
        ht = cfg.has_torque[i] != 0
        w = inp.wheel_speed[i]
        p = inp.brake_pressure[i] if hp else 0.0
        tau = inp.torque[i] if ht else 0.0
        load = max(cfg.load_static[i] + cfg.load_transfer[i] * st.d_f, 1.0)
        out.normal_load[i] = load
        out.radius[i] = r
        code = v_code
        v1 = v
        v2 = v_stuck
        if code == 0:
            if w != w:
                code = R_NAN_WHEEL
            elif not (-0.5 <= w and w * r <= 1.5 * v + 2.0):  # inf included
                code, v1 = R_BAD_WHEEL, w
            elif hp and p != p:
                code = R_NAN_FORCE
            elif hp and not (-0.5e5 <= p <= cfg.max_pressure):
                code, v1, v2 = R_BAD_PRESSURE, p, cfg.max_pressure
            elif ht and tau != tau:
                code = R_NAN_FORCE
            elif ht and not (abs(tau) <= cfg.max_torque):
                code, v1, v2 = R_BAD_TORQUE, tau, cfg.max_torque
        if code == 0:  # a wheel speed that does not move while the train speed does
            stuck = _stuck(st.w_value, st.w_since, st.w_vref, i, w, t, v, w > 0.0,
                           cfg.stuck_time, max(0.05, 6.0 * cfg.sig_v))
            if stuck >= 0.0:
                code, v1, v2 = R_STUCK_WHEEL, w, stuck
        if code == 0 and hp and n > 1:  # a pressure that does not move while the others do
            others, cnt = _others_mean(inp.brake_pressure, i, n)
            stuck = _stuck(st.p_value, st.p_since, st.p_oref, i, p, t, others, cnt > 0,
                           cfg.stuck_pressure_time, 1e4)
            if stuck >= 0.0:
                code, v1, v2 = R_STUCK_PRESSURE, p, stuck
        if code == 0 and ht and n > 1:  # the same for a torque: the others' mean moved by
            # 4 sigma_tau (about 5 standard deviations of a change of a three-axle mean);
            # exactly 0 is an unpowered or idle axle, not a stuck one
            others, cnt = _flagged_others_mean(inp.torque, cfg.has_torque, i, n)
            stuck = _stuck(st.tau_value, st.tau_since, st.tau_oref, i, tau, t, others,
                           tau != 0.0 and cnt > 0, cfg.stuck_pressure_time,
                           max(4.0 * cfg.sig_tau, 1.0))
            if stuck >= 0.0:
                code, v1, v2 = R_STUCK_TORQUE, tau, stuck
        if code == 0 and st.w_ok[i] != 0 and st.filters_on[i] != 0:
            # a step of the wheel speed that no torque can give (wheel diameter or sensor)
            dtw = t - st.tw_last[i]
            acc = (w - st.w_last[i]) / dtw
            drive = (tau - cfg.brake_coefficient * max(p, 0.0)) / cfg.inertia
            bound = cfg.max_physical_adhesion * r * load / cfg.inertia
            noise = 8.0 * 1.4142135623730951 * cfg.sig_w / dtw
            if abs(acc - drive) > bound + noise:
                code, v1 = R_JUMP, w - st.w_last[i]
        if code != 0:
            all_good = False
            _mark_bad(cfg, st, i, t, code, v1, v2)
            if code == R_JUMP:
                st.w_last[i] = w  # the new level is the reference from now on
                st.tw_last[i] = t
                st.filters_on[i] = 0
                if cfg.learn_radius != 0:
                    st.radius_state[i] = _UNCONFIRMED_R
            out.creep[i] = _NAN
            out.adhesion_used[i] = _NAN
            _report(cfg, st, out, i, t, _UNKNOWN, code, v1, v2)
            st.coasting[i] = 0
            continue
        # -- good sample: filters (causal, seed 002's cut-offs) -----------------------------
        slip = v - w * r
        if st.filters_on[i] == 0 or st.w_ok[i] == 0:
            wd_raw = 0.0
            if st.w_ok[i] != 0:
                wd_raw = (w - st.w_last[i]) / (t - st.tw_last[i])
            st.wd_f[i] = wd_raw
            st.z_wd[i] = (1.0 - b0f) * wd_raw
            st.p_f[i] = p
            st.z_p[i] = (1.0 - b0f) * p
            st.tau_f[i] = tau
            st.z_tau[i] = (1.0 - b0f) * tau
            st.slip_f[i] = slip
            st.z_slip[i] = (1.0 - b0f) * slip
            st.filters_on[i] = 1
        else:
            wd_raw = (w - st.w_last[i]) / (t - st.tw_last[i])
            st.wd_f[i], st.z_wd[i] = _filt(st.z_wd[i], wd_raw, b0f, b1f, a1f)
            st.p_f[i], st.z_p[i] = _filt(st.z_p[i], p, b0f, b1f, a1f)
            st.tau_f[i], st.z_tau[i] = _filt(st.z_tau[i], tau, b0f, b1f, a1f)
            st.slip_f[i], st.z_slip[i] = _filt(st.z_slip[i], slip, b0f, b1f, a1f)
        st.wd_raw[i] = wd_raw
        st.w_last[i] = w
        st.tw_last[i] = t
        st.w_ok[i] = 1
        jsum += wd_raw
        psum += p
        fast = st.v_f >= cfg.min_speed
        creep = st.slip_f[i] / st.v_f if fast else _NAN
        force = hp or ht
        mu = _NAN
        if force:  # eq. 10 of seed 002 with the traction torque
            mu = axle_adhesion_law(cfg.inertia, st.wd_f[i], c_used, st.p_f[i], st.tau_f[i], r,
                                   load)
            if not (abs(mu) <= 1.5):
                out.creep[i] = creep
                out.adhesion_used[i] = _NAN
                all_good = False
                _mark_bad(cfg, st, i, t, R_BAD_ADHESION, mu, _NAN)
                _report(cfg, st, out, i, t, _UNKNOWN, R_BAD_ADHESION, mu, _NAN)
                continue
        out.creep[i] = creep
        out.adhesion_used[i] = mu
        # -- wheel radius, learned while coasting -------------------------------------------
        if cfg.learn_radius != 0:
            coast = (force and v >= cfg.min_speed and (not hp or st.p_f[i] < cfg.coast_pressure)
                     and (not ht or abs(st.tau_f[i]) < cfg.coast_torque))
            if coast:
                if st.coasting[i] == 0:
                    st.coasting[i] = 1
                    st.coast_t0[i] = t
                    st.coast_sv[i] = 0.0
                    st.coast_sw[i] = 0.0
                    st.coast_n[i] = 0.0
                    st.coast_used[i] = 0.0
                if t - st.coast_t0[i] >= cfg.coast_settle:
                    st.coast_sv[i] += v
                    st.coast_sw[i] += w
                    st.coast_n[i] += 1.0
                    if (t - st.coast_t0[i] >= cfg.coast_settle + cfg.coast_time
                            and st.coast_n[i] >= 10.0 and st.coast_sw[i] > 0.0):
                        r_new = st.coast_sv[i] / st.coast_sw[i]
                        vbar = st.coast_sv[i] / st.coast_n[i]
                        sig = (math.sqrt(cfg.sig_v ** 2 + (r_new * cfg.sig_w) ** 2)
                               / (vbar * math.sqrt(st.coast_n[i])))
                        if st.coast_used[i] == 0.0:  # first look of this coasting period
                            st.coast_used[i] = 1.0
                            change = r_new / r - 1.0
                            if (st.radius_state[i] == _LEARNED
                                    and abs(change) > max(cfg.radius_change, 5.0 * sig)):
                                _mark_bad(cfg, st, i, t, R_RADIUS_CHANGED, change, _NAN)
                                _bank_reset(cfg, st, bank, i, 0.0, 0.0)
                                st.ring_n[i] = 0
                                st.ring_pos[i] = 0
                        moved = abs(r_new / r - 1.0) > 1e-5
                        st.radius[i] = r_new
                        st.radius_sigma[i] = sig
                        if sig <= cfg.radius_precision:
                            if st.radius_state[i] != _LEARNED:
                                _bank_reset(cfg, st, bank, i, 0.0, 0.0)
                                st.ring_n[i] = 0
                                st.ring_pos[i] = 0
                            st.radius_state[i] = _LEARNED
                        if moved:  # the slip filter restarts on the new radius
                            st.slip_f[i] = v - w * r_new
                            st.z_slip[i] = (1.0 - b0f) * st.slip_f[i]
            else:
                st.coasting[i] = 0
        # -- blocks of the estimator --------------------------------------------------------
        if st.b_n[i] == 0:
            st.b_w_first[i] = w
            st.b_t_first[i] = t
            st.b_sv[i] = 0.0
            st.b_sw[i] = 0.0
            st.b_sp[i] = 0.0
            st.b_stau[i] = 0.0
            st.b_sn[i] = 0.0
        st.b_n[i] += 1
        st.b_sv[i] += v
        st.b_sw[i] += w
        st.b_sp[i] += p
        st.b_stau[i] += tau
        st.b_sn[i] += load
        st.b_w_end[i] = w
        st.b_t_end[i] = t
        if v < cfg.min_speed:
            st.b_ok[i] = 0
        if t >= st.b_t0[i] + cfg.block_time:
            m = st.b_n[i]
            span = st.b_t_end[i] - st.b_t_first[i]
            if st.b_ok[i] != 0 and m >= 3 and force and span > 0.0:
                vbar = st.b_sv[i] / m
                nbar = st.b_sn[i] / m
                x = 1.0 - r * (st.b_sw[i] / m) / vbar
                wdot = (st.b_w_end[i] - st.b_w_first[i]) / span
                mu_b = axle_adhesion_law(cfg.inertia, wdot, c_used, st.b_sp[i] / m,
                                         st.b_stau[i] / m, r, nbar)
                var_x = (cfg.sig_v ** 2 + (r * cfg.sig_w) ** 2) / (m * vbar * vbar)
                g = cfg.inertia / (r * nbar * span)
                var_mu = (2.0 * (cfg.sig_w * g) ** 2
                          + ((c_used * cfg.sig_p) ** 2 + cfg.sig_tau ** 2) / (r * nbar) ** 2 / m
                          + cfg.sig_model ** 2)
                _estimate(cfg, st, bank, out, i, t, x, mu_b, var_x, var_mu)
            st.b_n[i] = 0
            st.b_ok[i] = 1
            st.b_t0[i] += cfg.block_time
            if t - st.b_t0[i] > cfg.block_time:
                st.b_t0[i] = t
        # -- level ---------------------------------------------------------------------------
        if st.lone_pending[i] != 0:
            if _lone_confirmed(cfg, st, i, st.changed_at[i]):
                st.lone_pending[i] = 0
            elif t > st.lone_deadline[i]:
                st.lone_pending[i] = 0
                if cfg.learn_radius != 0:
                    st.radius_state[i] = _UNCONFIRMED_R
                _mark_bad(cfg, st, i, t, R_LONE, st.shift[i], _NAN)
        if t < st.recover_until[i]:
            cause = st.recover_code[i]
            if (cause == R_RADIUS_CHANGED or cause == R_LONE or cause == R_SIGN
                    or cause == R_JUMP):
                _report(cfg, st, out, i, t, _UNKNOWN, cause, st.recover_v1[i],
                        st.recover_v2[i])
            else:
                _report(cfg, st, out, i, t, _UNKNOWN, R_RECOVERING, float(cause),
                        st.recover_until[i])
        elif not force:
            _report(cfg, st, out, i, t, _UNKNOWN, R_NO_FORCE, _NAN, _NAN)
        elif not fast:
            _report(cfg, st, out, i, t, _UNKNOWN, R_SPEED_LOW, st.v_f, cfg.min_speed)
        elif st.radius_state[i] != _LEARNED:
            need = cfg.coast_settle + cfg.coast_time
            if st.radius_state[i] == _NOMINAL:
                _report(cfg, st, out, i, t, _UNKNOWN, R_RADIUS, cfg.radius_tolerance, need)
            else:
                _report(cfg, st, out, i, t, _UNKNOWN, R_UNCONFIRMED, _NAN, need)
        elif st.sliding[i] != 0:
            _report(cfg, st, out, i, t, _UNKNOWN, R_SLIDING, st.slide_creep[i], _NAN)
        elif st.updates[i] == 0:
            _report(cfg, st, out, i, t, _UNKNOWN, R_STARTING, _NAN, _NAN)
        else:
            _report(cfg, st, out, i, t, st.verdict[i], st.verdict_code[i], st.verdict_v1[i],
                    st.verdict_v2[i])
    # -- outputs of the estimator, eq. 14 ---------------------------------------------------
    for i in range(n):
        out.estimate[i] = st.est[i]
        out.lower[i] = st.est_lo[i]
        out.upper[i] = st.est_hi[i]
        out.changed_at[i] = st.changed_at[i]
        if not (cfg.has_pressure[i] != 0 and cfg.has_torque[i] == 0):
            all_good = False
    if all_good and st.v_ok != 0:
        if st.eq14_started == 0:
            st.z_jsum = (1.0 - b0s) * jsum
            st.jsum_f = jsum
            st.z_psum = (1.0 - b0s) * psum
            st.psum_f = psum
            st.eq14_started = 1
        else:
            st.jsum_f, st.z_jsum = _filt(st.z_jsum, jsum, b0s, b1s, a1s)
            st.psum_f, st.z_psum = _filt(st.z_psum, psum, b0s, b1s, a1s)
        turning = True
        for i in range(n):
            if inp.wheel_speed[i] * st.radius[i] < 0.5 * v:
                turning = False
        if (turning and st.psum_f / n >= _C_MIN_PRESSURE and st.v_f >= cfg.min_speed
                and dt > 0.0):
            c_k = brake_coefficient_law(cfg.mass, st.d_f, 0.0, cfg.inertia, st.jsum_f, st.psum_f,
                                        cfg.radius)
            if _finite(c_k):
                decay = math.exp(-dt / _C_MEMORY)
                st.c_sum = st.c_sum * decay + c_k * dt
                st.c_weight = st.c_weight * decay + dt
                st.c_time += dt
                st.c_value = st.c_sum / st.c_weight
    else:
        st.eq14_started = 0
    _vehicle_level(cfg, st, out, t)
    return 0


@njit(cache=True, error_model="numpy")
def replay(config, inputs, state, outputs, bank, time, speed, wheel, pressure, torque,
           o_status, o_vehicle, o_creep, o_used, o_est, o_lo, o_hi, o_level, o_reason,
           o_v1, o_v2):
    """:func:`step` over every sample of a log (arrays of n samples; per-axle arrays (n, N)),
    writing the outputs of each sample into the ``o_*`` arrays."""
    inp = inputs[0]
    out = outputs[0]
    n_ax = config[0].n_axles
    for k in range(time.size):
        inp.time = time[k]
        inp.train_speed = speed[k]
        for i in range(n_ax):
            inp.wheel_speed[i] = wheel[k, i]
            inp.brake_pressure[i] = pressure[k, i]
            inp.torque[i] = torque[k, i]
        o_status[k] = step(config, inputs, state, outputs, bank)
        o_vehicle[k] = out.vehicle_level
        for i in range(n_ax):
            o_creep[k, i] = out.creep[i]
            o_used[k, i] = out.adhesion_used[i]
            o_est[k, i] = out.estimate[i]
            o_lo[k, i] = out.lower[i]
            o_hi[k, i] = out.upper[i]
            o_level[k, i] = out.level[i]
            o_reason[k, i] = out.reason[i]
            o_v1[k, i] = out.reason_v1[i]
            o_v2[k, i] = out.reason_v2[i]
    return time.size


