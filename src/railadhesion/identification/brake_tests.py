"""Adhesion identification from braking-test logs (Allotta, Malvezzi and Toni, seed 002).

The pipeline of the paper's §5, end to end:

1. derivatives by finite differences, filtered (:mod:`railadhesion.identification.signals`):
   vehicle deceleration at 0.5 Hz, angular accelerations at 2 Hz;
2. brake coefficient per sample, eq. 14,
   ``c = (M_tot d - F_res(v) - sum J w_dot_i / R) / (sum p_i / R)``, its mean over a window
   of steady braking (the paper takes the mean, Fig. 6);
3. normal loads with the body's pitch load transfer, eqs. 11-12 (from the
   :class:`~railadhesion.braking.Vehicle`);
4. adhesion per axle and sample, eq. 10, ``mu_i = (J w_dot_i / R + c p_i / R) / N_i``;
   absolute slip ``dv = v - R w``, relative slip ``dv / v`` and their derivatives;
5. identification windows: speed nearly constant and a fixed sign of the slip derivative,
   loss of adhesion (slip growing) and recovery (slip falling) told apart.

Filtering, consistently [our choice, documented in ``docs/identification.md``]: the paper
filters the accelerations and leaves the pressures raw. Here every term of one equation goes
through the same filter, so that a linear equation that holds sample by sample still holds
after filtering: in eq. 14 the deceleration, the angular accelerations and the pressures are
all filtered at the vehicle cut-off (0.5 Hz); in eq. 10 the angular accelerations and the
pressures at the wheel cut-off (2 Hz), and the slip that mu is paired with is filtered at 2 Hz
too, so mu and slip are smoothed alike. With noise-free data eq. 14 then returns the true c
exactly, whatever the filter. (Eq. 14 needs only the sums over the axles of the angular
accelerations and pressures: those sums are filtered, which the filter's linearity makes the
same as summing the filtered channels, to rounding.)

The channels (per segment: speed and deceleration, the eq. 14 sums, each axle's filters and
derivatives) and then the axles (loads, eq. 10, windows) run in compiled kernels and scipy's
filters, which release the GIL, in threads (``threads=``); each is computed alone, so the
results do not depend on the number of threads. The running resistance ``F_res`` is the
vehicle's Davis resistance (0 unless given): the paper neglects it (eq. 7).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numba import njit

from railadhesion._validate import check_choice, check_nonnegative, check_positive
from railadhesion.identification.logs import BAR, BrakingLog
from railadhesion.identification.signals import (
    FILTER_MODES,
    VEHICLE_CUTOFF,
    WHEEL_CUTOFF,
    FirstOrderFilter,
    gradient_coefficients,
    gradient_weighted,
)
from railadhesion.numerics import jitable, load_numba

load_numba()  # numba with the laws registry: the @jitable laws below register as they are defined

__all__ = [
    "BrakeCoefficient",
    "BrakingIdentification",
    "axle_adhesion_law",
    "brake_coefficient",
    "brake_coefficient_law",
    "brake_coefficient_per_sample",
    "identify_adhesion",
    "identification_windows",
    "worker_count",
]

#: Samples this close to a segment's ends are not used for the brake coefficient [s].
_EDGE_TIME = 2.0


@dataclass(frozen=True)
class BrakeCoefficient:
    """Brake coefficient c from eq. 14 (seed 002): per sample, and its mean over a window.

    Attributes
    ----------
    mean : float
        Mean of c over the window [N m/Pa] (the value used for mu; the paper's choice).
    median : float
        Median over the window [N m/Pa].
    std : float
        Standard deviation over the window [N m/Pa] (the spread of Fig. 6).
    window : tuple of float
        First and last time of the window [s].
    n_samples : int
        Samples in the window.
    per_sample : ndarray, shape (n,)
        c at every sample [N m/Pa] (NaN where the brake is released or data are invalid).
    in_window : ndarray of bool, shape (n,)
        Samples used for the mean.
    """

    mean: float
    median: float
    std: float
    window: tuple[float, float]
    n_samples: int
    per_sample: np.ndarray = field(repr=False)
    in_window: np.ndarray = field(repr=False)

    @property
    def mean_n_m_per_bar(self) -> float:
        """The mean in N m/bar (the paper's unit, Fig. 6)."""
        return self.mean * BAR


@dataclass(frozen=True, eq=False)
class BrakingIdentification:
    """Result of :func:`identify_adhesion`: per-sample quantities, c, windows.

    Arrays of shape (n,) are per sample, (n, N) per sample and axle (axle 1 leading).

    Attributes
    ----------
    time : ndarray (n,)
        Time [s].
    speed : ndarray (n,)
        Train speed v [m/s], filtered at the wheel cut-off.
    deceleration : ndarray (n,)
        d = -dv/dt [m/s^2], filtered at the vehicle cut-off.
    angular_acceleration : ndarray (n, N)
        d omega/dt [rad/s^2], filtered at the wheel cut-off.
    pressure : ndarray (n, N)
        Brake-cylinder pressures [Pa], filtered at the wheel cut-off.
    normal_load : ndarray (n, N)
        Axle normal loads N_i [N] (eqs. 11-12).
    pitch_angle : ndarray (n,) or None
        Car-body pitch angle [rad] (eq. 13; negative nose down under braking), when the
        vehicle gives its secondary stiffness k_2; else None.
    mu : ndarray (n, N)
        Adhesion coefficient (eq. 10) [-].
    slip : ndarray (n, N)
        Absolute slip dv = v - R omega [m/s] (filtered at the wheel cut-off).
    relative_slip : ndarray (n, N)
        dv / v [-] (NaN below ``min_speed``).
    slip_rate, relative_slip_rate : ndarray (n, N)
        Time derivatives of the two slips [m/s^2], [1/s].
    use : ndarray of bool (n, N)
        Samples usable for identification (valid data, v >= min_speed, wheel not locked, not
        within 1/f_c of a segment's ends where the filters start up).
    phase : ndarray of int8 (n, N)
        +1 inside a loss-of-adhesion window, -1 inside a recovery window, 0 elsewhere.
    windows : pandas.DataFrame
        One row per identification window (see :func:`identification_windows`).
    brake : BrakeCoefficient
        c per sample, its mean, spread and window.
    brake_coefficient : float
        The c used for mu [N m/Pa] (``brake.mean`` unless given).
    settings : dict
        The options used (filter mode, cut-offs, thresholds).
    log : BrakingLog
        The log processed.
    vehicle : object
        The vehicle.
    """

    time: np.ndarray
    speed: np.ndarray
    deceleration: np.ndarray
    angular_acceleration: np.ndarray
    pressure: np.ndarray
    normal_load: np.ndarray
    pitch_angle: np.ndarray | None
    mu: np.ndarray
    slip: np.ndarray
    relative_slip: np.ndarray
    slip_rate: np.ndarray
    relative_slip_rate: np.ndarray
    use: np.ndarray
    phase: np.ndarray
    windows: object
    brake: BrakeCoefficient
    brake_coefficient: float
    settings: dict
    log: BrakingLog = field(repr=False)
    vehicle: object = field(repr=False)
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def n_axles(self) -> int:
        return int(self.mu.shape[1])

    def samples(self, phase: str = "all"):
        """Flat arrays (speed, slip, relative_slip, mu, axle) of the usable samples, axle by axle.

        ``phase``: ``"all"``, ``"loss"`` or ``"recovery"`` (samples inside windows of that
        phase).
        """
        check_choice(phase, "phase", ("all", "loss", "recovery"))
        if phase in self._cache:
            return self._cache[phase]
        parts = []
        for i in range(self.n_axles):
            mask = self.use[:, i]
            if phase == "loss":
                mask = mask & (self.phase[:, i] == 1)
            elif phase == "recovery":
                mask = mask & (self.phase[:, i] == -1)
            rows = np.flatnonzero(mask)
            parts.append((self.speed[rows], self.slip[rows, i], self.relative_slip[rows, i],
                          self.mu[rows, i], np.full(rows.size, i)))
        out = tuple(np.concatenate(col) for col in zip(*parts, strict=True))
        self._cache[phase] = out
        return out

    def summary_dict(self) -> dict:
        """JSON-ready summary: c, counts, slip range, windows per phase, settings."""
        w = self.windows
        any_use = bool(self.use.any())

        def usable_range(x):
            if not any_use:
                return None
            lo = np.min(x, where=self.use, initial=np.inf)
            hi = np.max(x, where=self.use, initial=-np.inf)
            return [float(lo), float(hi)]

        rows = self.use.any(axis=1)
        out = {
            "samples": int(self.time.size),
            "axles": self.n_axles,
            "duration_s": float(self.time[-1] - self.time[0]),
            "usable_samples": int(np.count_nonzero(self.use)),
            "brake_coefficient": {
                "mean_N_m_per_Pa": self.brake.mean,
                "mean_N_m_per_bar": self.brake.mean_n_m_per_bar,
                "median_N_m_per_Pa": self.brake.median,
                "std_N_m_per_Pa": self.brake.std,
                "relative_spread": self.brake.std / self.brake.mean if self.brake.mean else None,
                "window_s": list(self.brake.window),
                "window_samples": self.brake.n_samples,
                "used_N_m_per_Pa": self.brake_coefficient,
            },
            "slip_range_m_s": usable_range(self.slip),
            "speed_range_m_s": [float(np.min(self.speed[rows])), float(np.max(self.speed[rows]))]
            if any_use else None,
            "mu_range": usable_range(self.mu),
            "pitch_angle_range_rad": None if self.pitch_angle is None else
            [float(np.min(self.pitch_angle)), float(np.max(self.pitch_angle))],
            "windows": {
                "loss": int((w["phase"] == "loss").sum()) if len(w) else 0,
                "recovery": int((w["phase"] == "recovery").sum()) if len(w) else 0,
            },
            "log_issues": [str(i) for i in self.log.issues],
            "settings": dict(self.settings),
        }
        return out


def _segments(seg: np.ndarray):
    cut = np.flatnonzero(np.diff(seg)) + 1
    bounds = np.concatenate(([0], cut, [seg.size]))
    return list(zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True))


def brake_coefficient(
    time, deceleration, angular_acceleration, pressure, vehicle, *, speed=None, mask=None,
    min_pressure: float = 0.5 * BAR,
) -> BrakeCoefficient:
    """Brake coefficient c per sample from eq. 14 of seed 002, and its mean over a window.

    Parameters
    ----------
    time : array_like (n,)
        Time [s].
    deceleration : array_like (n,)
        Vehicle deceleration d = -dv/dt [m/s^2] (filtered).
    angular_acceleration : array_like (n, N)
        Wheelset angular accelerations [rad/s^2] (filtered alike).
    pressure : array_like (n, N)
        Brake-cylinder pressures [Pa] (filtered alike).
    vehicle : Vehicle
        Supplies ``total_mass`` M_tot [kg], ``wheelset_inertia`` J [kg m^2], ``wheel_radius``
        R [m] and, if present, ``running_resistance(speed)`` [N].
    speed : array_like (n,), optional
        Train speed [m/s], for the running resistance.
    mask : array_like of bool (n,), optional
        Samples allowed in the window (default: all).
    min_pressure : float, default 0.5 bar
        The window holds the samples whose mean pressure is at least this [Pa] and at least
        half the log's largest mean pressure (steady braking), within ``mask``.

    Returns
    -------
    BrakeCoefficient

    Notes
    -----
    Eq. 14 (seed 002) at every sample is :func:`brake_coefficient_per_sample`, with the sums
    over the axles of the angular accelerations and pressures. The running resistance
    ``F_res(v)`` of the vehicle, when given with ``speed``, is subtracted from ``M_tot d`` (the
    paper neglects it). Valid while every wheel turns (a locked wheel's brake torque is not
    ``c p``).

    Examples
    --------
    Steady braking at 1 m/s^2 with rolling wheels (w_dot = -d/R), 3 bar on 4 axles:

    >>> import numpy as np
    >>> from railadhesion.braking import Vehicle
    >>> veh = Vehicle()
    >>> n = 5
    >>> d = np.ones(n)
    >>> wdot = np.full((n, 4), -1.0 / veh.wheel_radius)
    >>> torque = (veh.total_mass * 1.0 * veh.wheel_radius + 4 * veh.wheelset_inertia
    ...           * 1.0 / veh.wheel_radius) / 4
    >>> p = np.full((n, 4), torque / veh.brake_coefficient)
    >>> res = brake_coefficient(np.arange(n) * 0.1, d, wdot, p, veh)
    >>> round(res.mean / veh.brake_coefficient, 9)
    1.0
    """
    t = np.asarray(time, dtype=float)
    wd = np.asarray(angular_acceleration, dtype=float)
    p = np.asarray(pressure, dtype=float)
    resistance = None
    if speed is not None and hasattr(vehicle, "running_resistance"):
        resistance = vehicle.running_resistance(np.asarray(speed, float))
    ok = np.ones(t.size, bool) if mask is None else np.asarray(mask, bool).copy()
    return _brake_window(t, deceleration, wd.sum(axis=1), p.sum(axis=1), p.mean(axis=1),
                         vehicle, resistance, ok, min_pressure)


def brake_coefficient_per_sample(deceleration, wheel_acceleration_sum, pressure_sum, vehicle, *,
                                 resistance=None, where=None):
    """Eq. 14 of seed 002: the brake coefficient c at every sample [N m/Pa].

    ``c = (M_tot d - F_res - sum_i J w_dot_i / R) / (sum_i p_i / R)``, from the vehicle's
    translation (eq. 8) and each wheelset's rotation (eq. 6). The one implementation of
    eq. 14: :func:`brake_coefficient` and :func:`identify_adhesion` call it.

    Parameters
    ----------
    deceleration : array_like (n,)
        d = -dv/dt [m/s^2].
    wheel_acceleration_sum : array_like (n,)
        Sum over the axles of the angular accelerations w_dot_i [rad/s^2].
    pressure_sum : array_like (n,)
        Sum over the axles of the brake-cylinder pressures p_i [Pa].
    vehicle : Vehicle
        ``total_mass`` M_tot [kg], ``wheelset_inertia`` J [kg m^2] (each axle),
        ``wheel_radius`` R [m].
    resistance : array_like (n,), optional
        Running resistance F_res [N] (the paper neglects it, eq. 7).
    where : array_like of bool (n,), optional
        Samples to compute (the brake applied); NaN elsewhere. Default: every sample.

    Examples
    --------
    >>> from railadhesion.braking import Vehicle
    >>> veh = Vehicle()
    >>> torque = veh.total_mass * 1.0 * veh.wheel_radius  # 1 m/s^2 with massless wheels
    >>> c = brake_coefficient_per_sample([1.0], [0.0], [torque / veh.brake_coefficient],
    ...                                  veh)
    >>> round(float(c[0] / veh.brake_coefficient), 9)
    1.0
    """
    d = np.asarray(deceleration, dtype=float)
    f_res = 0.0 if resistance is None else np.asarray(resistance, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = brake_coefficient_law(float(vehicle.total_mass), d, f_res,
                                  float(vehicle.wheelset_inertia),
                                  np.asarray(wheel_acceleration_sum, dtype=float),
                                  np.asarray(pressure_sum, dtype=float),
                                  float(vehicle.wheel_radius))
    c = np.array(c, dtype=float, copy=True).reshape(np.broadcast(d, c).shape)
    if where is not None:
        c[~np.broadcast_to(np.asarray(where, dtype=bool), c.shape)] = np.nan
    return c


@jitable
def brake_coefficient_law(mass, deceleration, resistance, inertia, wheel_acceleration_sum,
                          pressure_sum, radius):
    """Eq. 14 of seed 002 (Allotta et al.), the brake coefficient c [N m/Pa]:
    ``c = (M_tot d - F_res - J sum_i w_dot_i / R) / (sum_i p_i / R)``.

    The one writing of eq. 14: :func:`brake_coefficient_per_sample` calls it on arrays (it is
    plain arithmetic, so floats and NumPy arrays both serve), the on-board monitor's compiled
    step on its filtered sums. ``resistance`` F_res [N] is 0 where it is neglected (eq. 7).
    """
    return ((mass * deceleration - resistance - inertia * wheel_acceleration_sum / radius)
            / (pressure_sum / radius))


@jitable
def axle_adhesion_law(inertia, wheel_acceleration, brake_coefficient, pressure, torque, radius,
                      load):
    """Eq. 10 of seed 002, the adhesion coefficient of one axle [-]:
    ``mu = (J w_dot + c p - tau) / (R N)``, from the wheelset's rotation (eq. 6) with the
    traction torque ``tau`` [N m] (0 in a braking test, the paper's case; the monitor passes
    the measured torque under traction). The one writing of eq. 10: the identification's
    compiled axle loop and the monitor's step call it.
    """
    return (inertia * wheel_acceleration + brake_coefficient * pressure - torque) / (radius * load)


def _brake_window(t, deceleration, wheel_acceleration_sum, pressure_sum, pressure_mean,
                  vehicle, resistance, ok, min_pressure):
    """:class:`BrakeCoefficient`: eq. 14 where the mean pressure is at least ``min_pressure``,
    its statistics over the window of steady braking (at least half the largest mean
    pressure among the allowed samples ``ok``)."""
    applied = pressure_mean >= max(float(min_pressure), 1e-9)
    c = brake_coefficient_per_sample(deceleration, wheel_acceleration_sum, pressure_sum,
                                     vehicle, resistance=resistance, where=applied)
    top = np.max(pressure_mean[ok & applied]) if np.any(ok & applied) else np.inf
    window = ok & applied & (pressure_mean >= 0.5 * top) & np.isfinite(c)
    if not window.any():
        raise ValueError(
            "no sample with the brake applied (mean pressure >= "
            f"{min_pressure / BAR:g} bar) in the usable part of the log (valid data, all wheels "
            f"turning, v >= min_speed, more than {_EDGE_TIME:g} s from a gap or an end): c "
            "cannot be identified"
        )
    vals = c[window]
    tw = t[window]
    return BrakeCoefficient(
        mean=float(np.mean(vals)), median=float(np.median(vals)),
        std=float(np.std(vals, ddof=1)) if vals.size > 1 else 0.0,
        window=(float(tw[0]), float(tw[-1])), n_samples=int(vals.size), per_sample=c,
        in_window=window,
    )


def identification_windows(time, speed, slip_rate, use, segment, *, speed_tolerance=1.0,
                           min_duration=0.1, deadband=0.05, mu=None, slip=None):
    """Identification windows of one axle: fixed sign of the slip derivative, speed ~ constant.

    Parameters
    ----------
    time, speed : ndarray (n,)
        Time [s], train speed [m/s].
    slip_rate : ndarray (n,)
        Derivative of the absolute slip [m/s^2].
    use : ndarray of bool (n,)
        Usable samples.
    segment : ndarray of int (n,)
        Segment index (windows never cross a gap).
    speed_tolerance : float, default 1 m/s
        A window is cut when the speed has moved this far from its value at the window's
        start (the paper's "speed approximately constant"; 1 m/s is its grid spacing).
    min_duration : float, default 0.1 s
        Shorter runs are not windows.
    deadband : float, default 0.05 m/s^2
        |slip_rate| below this has no sign (neither loss nor recovery).
    mu, slip : ndarray (n,), optional
        Not used (kept for compatibility).

    Returns
    -------
    starts, stops : ndarray of int
        Index ranges ``[start, stop)`` of the windows.
    sign : ndarray of int8
        +1 loss of adhesion (slip growing), -1 recovery.
    """
    n = np.shape(slip_rate)[0]
    if n == 0:
        z = np.zeros(0, np.int64)
        return z, z, np.zeros(0, np.int8)
    phase = np.zeros(n, np.int8)
    return _windows(
        np.asarray(time, dtype=float), np.asarray(speed, dtype=float),
        np.asarray(slip_rate, dtype=float), np.asarray(use, dtype=np.bool_),
        np.asarray(segment, dtype=np.int64), float(speed_tolerance), float(min_duration),
        float(deadband), phase,
    )


@njit(cache=True, nogil=True)
def _windows(time, speed, slip_rate, use, segment, tolerance, min_duration, deadband,
             phase):  # pragma: no cover - compiled
    """Windows of one axle (see :func:`identification_windows`); marks ``phase`` (+1 loss,
    -1 recovery) inside the windows kept. A run starts where the sign of the slip derivative
    (0 inside the dead band or on unusable samples) or the segment changes, or where the
    speed has moved ``tolerance`` from its value at the run's start."""
    n = slip_rate.size
    key = np.empty(n, np.int8)
    for k in range(n):
        x = slip_rate[k]
        key[k] = (1 if x > deadband else (-1 if x < -deadband else 0)) if use[k] else 0
    start = np.empty(n, np.bool_)
    start[0] = True
    v0 = speed[0]
    runs = 1
    for k in range(1, n):
        if key[k] != key[k - 1] or segment[k] != segment[k - 1] or \
                abs(speed[k] - v0) >= tolerance:
            start[k] = True
            v0 = speed[k]
            runs += 1
        else:
            start[k] = False
    s0 = np.empty(runs, np.int64)
    m = 0
    for k in range(n):
        if start[k]:
            s0[m] = k
            m += 1
    s1 = np.empty(runs, np.int64)
    s1[:runs - 1] = s0[1:]
    s1[runs - 1] = n
    keep = np.zeros(runs, np.bool_)
    kept = 0
    for q in range(runs):
        sg = key[s0[q]]
        if sg != 0 and time[s1[q] - 1] - time[s0[q]] >= min_duration:
            keep[q] = True
            kept += 1
    starts = np.empty(kept, np.int64)
    stops = np.empty(kept, np.int64)
    sign = np.empty(kept, np.int8)
    m = 0
    for q in range(runs):
        if keep[q]:
            starts[m] = s0[q]
            stops[m] = s1[q]
            sign[m] = key[s0[q]]
            for k in range(s0[q], s1[q]):
                phase[k] = key[s0[q]]
            m += 1
    return starts, stops, sign


@njit(cache=True, nogil=True)
def _window_sums(s0, s1, v, mu):  # pragma: no cover - compiled
    """Running sums of v, v^2 and mu (``numpy.cumsum`` with a leading 0, the same additions)
    read at the window starts ``s0`` and ends ``s1`` (sorted, not overlapping): the window
    means are differences of them."""
    m = s0.size
    out = np.empty((6, m))
    sv = 0.0
    sq = 0.0
    sm = 0.0
    q0 = 0
    q1 = 0
    n = v.size
    for k in range(n + 1):
        while q0 < m and s0[q0] == k:
            out[0, q0] = sv
            out[2, q0] = sq
            out[4, q0] = sm
            q0 += 1
        while q1 < m and s1[q1] == k:
            out[1, q1] = sv
            out[3, q1] = sq
            out[5, q1] = sm
            q1 += 1
        if k < n:
            sv += v[k]
            sq += v[k] * v[k]
            sm += mu[k]
    return out


@njit(cache=True, nogil=True)
def _column_sums(w, p, a, b, wsum, psum):  # pragma: no cover - compiled
    """Sums over the axles of the wheel speeds and of the pressures, samples [a, b)."""
    m = w.shape[1]
    for k in range(a, b):
        sw = 0.0
        sp = 0.0
        for i in range(m):
            sw += w[k, i]
            sp += p[k, i]
        wsum[k - a] = sw
        psum[k - a] = sp


@njit(cache=True, nogil=True)
def _brake_mask(wheel, train, valid, sub, edge, v_f, min_speed, r, out):  # pragma: no cover
    """Samples allowed in the window of eq. 14: every axle valid (or substituted), every wheel
    turning (R w > 0.05 v), not near a segment's end, v >= min_speed."""
    n, m = wheel.shape
    for k in range(n):
        vk = train[k]
        vr = 0.05 * (vk if (vk > 1e-9 or vk != vk) else 1e-9)  # np.maximum(v, 1e-9)
        ok = (not edge[k]) and v_f[k] >= min_speed
        if ok:
            for i in range(m):
                if not (wheel[k, i] * r > vr) or not (valid[k, i] or sub[i]):
                    ok = False
                    break
        out[k] = ok


@njit(cache=True, nogil=True)
def _finite(x):  # pragma: no cover - compiled
    """numpy.nan_to_num of one value."""
    if x != x:
        return 0.0
    if x == np.inf:
        return 1.7976931348623157e308
    if x == -np.inf:
        return -1.7976931348623157e308
    return x


@njit(cache=True, nogil=True)
def _axle_adhesion(i, wd, p, slip, v, d, wheel, train, valid, substituted, edge, t, gc,
                   seg_a, seg_b, j, c, r, min_speed, load0, load1, affine, loads, mu, rel,
                   rel_rate, use):  # pragma: no cover - compiled
    """Axle ``i``: loads (eqs. 11-12, affine in d when ``affine``), eq. 10
    mu = (J w_dot + c p) / (R N), the relative slip dv / v (NaN below ``min_speed``), the
    usable-sample mask (valid, v >= min_speed, wheel turning R w > 0.05 v, finite mu, not in a
    filter start-up zone, axle not substituted) and d(dv / v)/dt per segment (of the relative
    slip with NaN read as 0, as numpy.nan_to_num; NaN below ``min_speed``)."""
    n = v.size
    for k in range(n):
        if affine:
            x = load0 + load1 * d[k]
            loads[k, i] = x if x > 0.0 else 0.0
        fast = v[k] >= min_speed
        vr = max(train[k], 1e-9)
        x = axle_adhesion_law(j, wd[k, i], c, p[k, i], 0.0, r, loads[k, i])
        mu[k, i] = x
        rel[k, i] = slip[k, i] / v[k] if fast else np.nan
        use[k, i] = (valid[k, i] and not substituted and fast and wheel[k, i] * r > 0.05 * vr
                     and np.isfinite(x) and not edge[k])
    finite = np.empty(n)  # the relative slip with NaN read as 0 (numpy.nan_to_num)
    for k in range(n):
        finite[k] = _finite(rel[k, i])
    for q in range(seg_a.size):
        a = seg_a[q]
        b = seg_b[q]
        if b - a < 2:
            for k in range(a, b):
                rel_rate[k, i] = 0.0
        else:
            gradient_weighted(finite, t, gc, a, b, rel_rate[a:b, i], 1.0)
    for k in range(n):
        if not v[k] >= min_speed:
            rel_rate[k, i] = np.nan


def worker_count(threads=None) -> int:
    """Threads the identification runs in: ``threads`` (>= 1), or by default
    ``numba.get_num_threads()``, the number the package's compiled kernels use (every core
    available unless ``NUMBA_NUM_THREADS`` or :func:`numba.set_num_threads` says otherwise)."""
    if threads is None:
        import numba

        return max(1, int(numba.get_num_threads()))
    threads = int(threads)
    if threads < 1:
        raise ValueError(
            f"threads must be >= 1 (or None for numba.get_num_threads()), got {threads}")
    return threads


def _run_jobs(pool, jobs) -> None:
    """Run zero-argument callables, in the pool's threads if there is one; re-raise errors."""
    if pool is None:
        for job in jobs:
            job()
        return
    for future in [pool.submit(job) for job in jobs]:
        future.result()


def _affine_loads(vehicle, d):
    """(N(0), dN/dd) if the vehicle's axle loads are affine in the deceleration over the range
    of ``d`` (eqs. 11-12; checked at its ends and middle), else None."""
    lo, hi = float(np.min(d)), float(np.max(d))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return None
    probe = np.array([0.0, 1.0, lo, hi, 0.5 * (lo + hi)])
    loads = np.asarray(vehicle.axle_normal_loads(probe), dtype=float)
    if loads.ndim != 2 or loads.shape[0] != probe.size:
        return None
    base, slope = loads[0], loads[1] - loads[0]
    pred = np.maximum(base[None, :] + slope[None, :] * probe[:, None], 0.0)
    scale = max(float(np.max(np.abs(loads))), 1.0)
    if not np.allclose(pred, loads, rtol=1e-12, atol=1e-12 * scale):
        return None
    return base, slope


def identify_adhesion(
    log: BrakingLog,
    vehicle,
    *,
    filter_mode: str = "zero-phase",
    vehicle_cutoff: float = VEHICLE_CUTOFF,
    wheel_cutoff: float = WHEEL_CUTOFF,
    brake_coefficient_value: float | None = None,
    min_speed: float = 2.0,
    min_pressure: float = 0.5 * BAR,
    speed_tolerance: float = 1.0,
    min_window: float = 0.1,
    slip_rate_deadband: float = 0.05,
    progress: Callable[[str], None] | None = None,
    threads: int | None = None,
) -> BrakingIdentification:
    """Identify the adhesion coefficient from a braking-test log (seed 002, §5).

    Parameters
    ----------
    log : BrakingLog
        From :func:`~railadhesion.identification.logs.read_braking_log`.
    vehicle : Vehicle
        :class:`railadhesion.braking.Vehicle` (masses, inertia, radius, load transfer).
    filter_mode : {"zero-phase", "causal"}
        See :mod:`railadhesion.identification.signals` (zero-phase is the default: off-line, no
        delay between quantities filtered differently, less noise).
    vehicle_cutoff, wheel_cutoff : float, default 0.5 and 2 Hz
        Cut-offs of the deceleration and angular-acceleration filters (seed 002 §5).
    brake_coefficient_value : float, optional
        Use this c [N m/Pa] for mu instead of the identified mean (still identified and
        reported).
    min_speed : float, default 2 m/s
        Samples below this speed are not used (relative slip undefined near standstill).
    min_pressure : float, default 0.5 bar
        Brake applied for the c window [Pa].
    speed_tolerance, min_window, slip_rate_deadband : float
        Window rules (:func:`identification_windows`): 1 m/s, 0.1 s, 0.05 m/s^2.
    progress : callable, optional
        Called with the name of each stage (for progress bars).
    threads : int, optional
        Threads for the channels and axles (compiled kernels and scipy's filters release the
        GIL); default: :func:`worker_count`, ``numba.get_num_threads()``. The results do not
        depend on it.

    Returns
    -------
    BrakingIdentification

    Raises
    ------
    ValueError
        Bad options (named), a log whose axle count differs from the vehicle's, no braking.
    """
    check_choice(filter_mode, "filter_mode", FILTER_MODES)
    check_positive(vehicle_cutoff, "vehicle_cutoff")
    check_positive(wheel_cutoff, "wheel_cutoff")
    check_nonnegative(min_speed, "min_speed")
    check_nonnegative(min_pressure, "min_pressure")
    check_positive(speed_tolerance, "speed_tolerance")
    workers = worker_count(threads)
    step = progress or (lambda _stage: None)
    n_ax = log.n_axles
    if int(getattr(vehicle, "n_axles", n_ax)) != n_ax:
        raise ValueError(
            f"the log has {n_ax} axles but the vehicle {getattr(vehicle, 'name', '')!r} has "
            f"{vehicle.n_axles}"
        )
    if workers > 1:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            return _identify(log, vehicle, pool, step, filter_mode, vehicle_cutoff,
                             wheel_cutoff, brake_coefficient_value, min_speed, min_pressure,
                             speed_tolerance, min_window, slip_rate_deadband)
    return _identify(log, vehicle, None, step, filter_mode, vehicle_cutoff, wheel_cutoff,
                     brake_coefficient_value, min_speed, min_pressure, speed_tolerance,
                     min_window, slip_rate_deadband)


def _per_axle(n, n_ax, dtype=float):
    """An (n, n_ax) array whose axle columns are contiguous (Fortran order): threads working
    on different axles never write to the same cache line."""
    return np.empty((n_ax, n), dtype=dtype).T


def _identify(log, vehicle, pool, step, filter_mode, vehicle_cutoff, wheel_cutoff,
              brake_coefficient_value, min_speed, min_pressure, speed_tolerance, min_window,
              slip_rate_deadband):
    import pandas as pd

    n_ax = log.n_axles
    r = float(vehicle.wheel_radius)
    j = float(vehicle.wheelset_inertia)
    t = np.ascontiguousarray(log.time, dtype=float)
    n = t.size
    train = np.ascontiguousarray(log.train_speed, dtype=float)
    wheel = np.asarray(log.wheel_speed, dtype=float)
    press = np.asarray(log.brake_pressure, dtype=float)
    step("derivatives and filters")
    v_f = np.empty(n)
    d_f = np.empty(n)
    jsum = np.empty(n)   # sum_i w_dot_i at the vehicle cut-off (eq. 14)
    psum = np.empty(n)   # sum_i p_i at the vehicle cut-off (eq. 14)
    wd2 = _per_axle(n, n_ax)
    p2 = _per_axle(n, n_ax)
    slip = _per_axle(n, n_ax)
    slip_rate = _per_axle(n, n_ax)
    edge = np.zeros(n, bool)
    edge_fast = np.zeros(n, bool)
    segments = _segments(log.segment)
    gc = gradient_coefficients(t)  # shared by every derivative (weights depend on t only)
    longest = max(b - a for a, b in segments)
    local = threading.local()

    def scratch(k, m):
        """Work array k (0 or 1) of the calling thread, m samples long."""
        bufs = getattr(local, "bufs", None)
        if bufs is None:
            bufs = local.bufs = np.empty((2, longest))
        return bufs[k, :m]

    jobs = []
    for a, b in segments:
        ts = t[a:b]
        if b - a < 8:
            edge[a:b] = True
            edge_fast[a:b] = True
            v_f[a:b] = train[a:b]
            d_f[a:b] = 0.0
            jsum[a:b] = 0.0
            psum[a:b] = press[a:b].sum(axis=1)
            wd2[a:b] = 0.0
            p2[a:b] = press[a:b]
            slip[a:b] = train[a:b, None] - r * wheel[a:b]
            slip_rate[a:b] = 0.0
            continue
        fs = 1.0 / float(np.median(np.diff(ts)))
        slow = FirstOrderFilter(vehicle_cutoff, fs, filter_mode)
        fast = FirstOrderFilter(wheel_cutoff, fs, filter_mode)
        edge[a:b] = (ts - ts[0] < _EDGE_TIME) | (ts[-1] - ts < _EDGE_TIME)
        # filter start-up / end effects of the fast filter: 1/fc either side
        tf = 1.0 / wheel_cutoff
        edge_fast[a:b] = (ts - ts[0] < tf) | (ts[-1] - ts < tf)

        def vehicle_job(a=a, b=b, slow=slow, fast=fast):
            buf = scratch(0, b - a)
            gradient_weighted(train, t, gc, a, b, buf, -1.0)  # d = -dv/dt
            slow.apply(buf, d_f[a:b])
            fast.apply(train[a:b], v_f[a:b])

        def eq14_job(a=a, b=b, slow=slow):
            ws, ps = scratch(0, b - a), scratch(1, b - a)
            _column_sums(wheel, press, a, b, ws, ps)
            slow.apply(ps, psum[a:b])
            gradient_weighted(ws, t[a:b], gc[:, a:b], 0, b - a, ps, 1.0)
            slow.apply(ps, jsum[a:b])

        def axle_job(i, a=a, b=b, fast=fast):
            w = wheel[:, i]
            buf = scratch(0, b - a)
            gradient_weighted(w, t, gc, a, b, buf, 1.0)
            fast.apply(buf, wd2[a:b, i])
            fast.apply(press[a:b, i], p2[a:b, i])
            np.multiply(w[a:b], r, out=buf)
            np.subtract(train[a:b], buf, out=buf)
            fast.apply(buf, slip[a:b, i])
            gradient_weighted(slip[:, i], t, gc, a, b, slip_rate[a:b, i], 1.0)

        jobs += [vehicle_job, eq14_job] + [partial(axle_job, i) for i in range(n_ax)]
    _run_jobs(pool, jobs)
    step("brake coefficient (eq. 14)")
    sub = getattr(log, "substituted", None)
    sub = np.ascontiguousarray(np.zeros(n_ax, bool) if sub is None else sub, dtype=np.bool_)
    valid = np.asarray(log.valid, dtype=np.bool_)
    c_ok = np.empty(n, np.bool_)
    _brake_mask(wheel, train, valid, sub, edge, v_f, float(min_speed), r, c_ok)
    resistance = None
    if hasattr(vehicle, "running_resistance"):
        resistance = vehicle.running_resistance(v_f)
    brake = _brake_window(t, d_f, jsum, psum, psum / n_ax, vehicle, resistance, c_ok,
                          min_pressure)
    c = brake.mean if brake_coefficient_value is None else float(
        check_positive(brake_coefficient_value, "brake_coefficient_value"))
    step("normal loads and adhesion (eqs. 10-13)")
    affine = _affine_loads(vehicle, d_f)
    if affine is None:  # a vehicle whose loads are not affine in d: evaluate them all
        loads = np.asfortranarray(vehicle.axle_normal_loads(d_f), dtype=float)
        load0 = load1 = np.zeros(n_ax)
    else:
        loads = _per_axle(n, n_ax)
        load0, load1 = affine
    mu = _per_axle(n, n_ax)
    rel = _per_axle(n, n_ax)
    rel_rate = _per_axle(n, n_ax)
    use = _per_axle(n, n_ax, np.bool_)
    phase = np.zeros((n_ax, n), np.int8).T
    seg_a = np.array([s[0] for s in segments], dtype=np.int64)
    seg_b = np.array([s[1] for s in segments], dtype=np.int64)
    segment_index = np.ascontiguousarray(log.segment, dtype=np.int64)
    found = [None] * n_ax

    def adhesion_job(i):
        _axle_adhesion(i, wd2, p2, slip, v_f, d_f, wheel, train, valid, bool(sub[i]),
                       edge_fast, t, gc, seg_a, seg_b, j, c, r, float(min_speed),
                       float(load0[i]), float(load1[i]), affine is not None, loads, mu, rel,
                       rel_rate, use)

    _run_jobs(pool, [partial(adhesion_job, i) for i in range(n_ax)])
    pitch = None
    if getattr(vehicle, "secondary_stiffness", None) is not None:
        pitch = np.asarray(vehicle.pitch_angle(d_f), dtype=float)
    step("identification windows")

    def windows_job(i):
        s0, s1, sign = _windows(t, v_f, slip_rate[:, i], use[:, i], segment_index,
                                float(speed_tolerance), float(min_window),
                                float(slip_rate_deadband), phase[:, i])
        found[i] = (s0, s1, sign, _window_sums(s0, s1, v_f, mu[:, i]))

    _run_jobs(pool, [partial(windows_job, i) for i in range(n_ax)])
    parts = []
    for i, (s0, s1, sign, sums) in enumerate(found):
        if s0.size == 0:
            continue
        cnt = (s1 - s0).astype(float)
        v0, v1, q0, q1, m0, m1 = sums
        vm = (v1 - v0) / cnt
        vv = np.maximum((q1 - q0) / cnt - vm * vm, 0.0)
        parts.append((np.full(s0.size, i + 1, np.int64), sign, t[s0], t[s1 - 1], s1 - s0, vm,
                      np.sqrt(vv), slip[s0, i], slip[s1 - 1, i], (m1 - m0) / cnt))
    cols = ["axle", "phase", "start_time", "end_time", "n_samples", "speed_mean", "speed_std",
            "slip_start", "slip_end", "mu_mean"]
    if parts:
        data = [np.concatenate(col) for col in zip(*parts, strict=True)]
        data[1] = np.where(data[1] > 0, "loss", "recovery")
        windows = pd.DataFrame(dict(zip(cols, data, strict=True)))
    else:
        windows = pd.DataFrame(columns=cols)
    settings = {
        "filter_mode": filter_mode, "vehicle_cutoff_Hz": float(vehicle_cutoff),
        "wheel_cutoff_Hz": float(wheel_cutoff), "min_speed_m_s": float(min_speed),
        "min_pressure_Pa": float(min_pressure), "speed_tolerance_m_s": float(speed_tolerance),
        "min_window_s": float(min_window), "slip_rate_deadband_m_s2": float(slip_rate_deadband),
        "vehicle": getattr(vehicle, "name", ""), "log": log.source,
    }
    return BrakingIdentification(
        time=t, speed=v_f, deceleration=d_f, angular_acceleration=wd2, pressure=p2,
        normal_load=loads, pitch_angle=pitch, mu=mu, slip=slip, relative_slip=rel,
        slip_rate=slip_rate,
        relative_slip_rate=rel_rate, use=use, phase=phase, windows=windows, brake=brake,
        brake_coefficient=c, settings=settings, log=log, vehicle=vehicle,
    )
