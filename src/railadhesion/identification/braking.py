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
exactly, whatever the filter. The running resistance ``F_res`` is the vehicle's Davis
resistance (0 unless given): the paper neglects it (eq. 7).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from railadhesion._validate import check_choice, check_nonnegative, check_positive
from railadhesion.identification.logs import BAR, BrakingLog
from railadhesion.identification.signals import (
    FILTER_MODES,
    VEHICLE_CUTOFF,
    WHEEL_CUTOFF,
    derivative,
    lowpass,
)

__all__ = [
    "BrakeCoefficient",
    "BrakingIdentification",
    "brake_coefficient",
    "identify_adhesion",
    "identification_windows",
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
        speed, slip, _, mu, _ = self.samples()
        w = self.windows
        out = {
            "samples": int(self.time.size),
            "axles": self.n_axles,
            "duration_s": float(self.time[-1] - self.time[0]),
            "usable_samples": int(self.use.sum()),
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
            "slip_range_m_s": [float(np.min(slip)), float(np.max(slip))] if slip.size else None,
            "speed_range_m_s": [float(np.min(speed)), float(np.max(speed))] if speed.size
            else None,
            "mu_range": [float(np.min(mu)), float(np.max(mu))] if mu.size else None,
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
    return list(zip(bounds[:-1], bounds[1:], strict=True))


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
    Eq. 14 (seed 002), from the vehicle's translation (eq. 8) and each wheelset's rotation
    (eq. 6): ``c = (M_tot d - sum_i J w_dot_i / R) / (sum_i p_i / R)``. The running resistance
    ``F_res(v)`` of the vehicle, when given, is subtracted from ``M_tot d`` (the paper neglects
    it). Valid while every wheel turns (a locked wheel's brake torque is not ``c p``).

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
    d = np.asarray(deceleration, dtype=float)
    wd = np.asarray(angular_acceleration, dtype=float)
    p = np.asarray(pressure, dtype=float)
    r = float(vehicle.wheel_radius)
    j = float(vehicle.wheelset_inertia)
    force = float(vehicle.total_mass) * d - j * wd.sum(axis=1) / r
    if speed is not None and hasattr(vehicle, "running_resistance"):
        force = force - np.asarray(vehicle.running_resistance(np.asarray(speed, float)))
    psum = p.sum(axis=1) / r
    pmean = p.mean(axis=1)
    ok = np.ones(t.size, bool) if mask is None else np.asarray(mask, bool).copy()
    applied = pmean >= max(float(min_pressure), 1e-9)
    c = np.full(t.size, np.nan)
    c[applied] = force[applied] / psum[applied]
    top = np.max(pmean[ok & applied]) if np.any(ok & applied) else np.inf
    window = ok & applied & (pmean >= 0.5 * top) & np.isfinite(c)
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
        Adhesion and slip, for the window statistics.

    Returns
    -------
    starts, stops : ndarray of int
        Index ranges ``[start, stop)`` of the windows.
    sign : ndarray of int8
        +1 loss of adhesion (slip growing), -1 recovery.
    """
    key = np.where(slip_rate > deadband, 1, np.where(slip_rate < -deadband, -1, 0))
    key = np.where(use, key, 0).astype(np.int8)
    n = key.size
    if n == 0:
        z = np.zeros(0, np.int64)
        return z, z, np.zeros(0, np.int8)
    change2 = _window_starts(key, np.ascontiguousarray(segment, dtype=np.int64),
                             np.ascontiguousarray(speed, dtype=float), float(speed_tolerance))
    starts = np.flatnonzero(change2)
    stops = np.concatenate((starts[1:], [n]))
    sign = key[starts]
    dur = time[stops - 1] - time[starts]
    keep = (sign != 0) & (dur >= min_duration)
    return starts[keep], stops[keep], sign[keep]


@njit(cache=True)
def _adhesion(wd, p, loads, slip, v, wheel, train, valid, sub, edge, j, c, r,
              min_speed):  # pragma: no cover - compiled
    """Eq. 10 per axle and sample, the relative slip and the usable-sample mask, in one pass:
    mu = (J w_dot + c p) / (R N); usable = valid, v >= min_speed, wheel turning
    (R w > 0.05 v), finite mu, not in a filter start-up zone, axle not substituted."""
    n, m = wd.shape
    mu = np.empty((n, m))
    rel = np.empty((n, m))
    use = np.empty((n, m), np.bool_)
    for k in range(n):
        fast = v[k] >= min_speed
        vr = max(train[k], 1e-9)
        for a in range(m):
            x = (j * wd[k, a] + c * p[k, a]) / (r * loads[k, a])
            mu[k, a] = x
            rel[k, a] = slip[k, a] / v[k] if fast else np.nan
            use[k, a] = (valid[k, a] and not sub[a] and fast and wheel[k, a] * r > 0.05 * vr
                         and np.isfinite(x) and not edge[k])
    return mu, rel, use


@njit(cache=True)
def _window_starts(key, segment, speed, tolerance):  # pragma: no cover - compiled
    """Start flags of the runs: a new run where the key or the segment changes, or where the
    speed has moved ``tolerance`` from its value at the current run's start."""
    n = key.size
    start = np.zeros(n, np.bool_)
    start[0] = True
    v0 = speed[0]
    for k in range(1, n):
        if key[k] != key[k - 1] or segment[k] != segment[k - 1] or \
                abs(speed[k] - v0) >= tolerance:
            start[k] = True
            v0 = speed[k]
    return start


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

    Returns
    -------
    BrakingIdentification

    Raises
    ------
    ValueError
        Bad options (named), a log whose axle count differs from the vehicle's, no braking.
    """
    import pandas as pd

    check_choice(filter_mode, "filter_mode", FILTER_MODES)
    check_positive(vehicle_cutoff, "vehicle_cutoff")
    check_positive(wheel_cutoff, "wheel_cutoff")
    check_nonnegative(min_speed, "min_speed")
    check_nonnegative(min_pressure, "min_pressure")
    check_positive(speed_tolerance, "speed_tolerance")
    step = progress or (lambda _stage: None)
    n_ax = log.n_axles
    if int(getattr(vehicle, "n_axles", n_ax)) != n_ax:
        raise ValueError(
            f"the log has {n_ax} axles but the vehicle {getattr(vehicle, 'name', '')!r} has "
            f"{vehicle.n_axles}"
        )
    r = float(vehicle.wheel_radius)
    j = float(vehicle.wheelset_inertia)
    t = log.time
    n = t.size
    step("derivatives and filters")
    v_f = np.empty(n)
    d_f = np.empty(n)
    wd2 = np.empty((n, n_ax))
    wd05 = np.empty((n, n_ax))
    p2 = np.empty((n, n_ax))
    p05 = np.empty((n, n_ax))
    slip = np.empty((n, n_ax))
    slip_rate = np.empty((n, n_ax))
    edge = np.zeros(n, bool)
    edge_fast = np.zeros(n, bool)
    for a, b in _segments(log.segment):
        ts = t[a:b]
        if b - a < 8:
            edge[a:b] = True
            edge_fast[a:b] = True
            v_f[a:b] = log.train_speed[a:b]
            d_f[a:b] = 0.0
            wd2[a:b] = wd05[a:b] = 0.0
            p2[a:b] = p05[a:b] = log.brake_pressure[a:b]
            slip[a:b] = log.train_speed[a:b, None] - r * log.wheel_speed[a:b]
            slip_rate[a:b] = 0.0
            continue
        fs = 1.0 / float(np.median(np.diff(ts)))
        vs = log.train_speed[a:b]
        ws = log.wheel_speed[a:b]
        ps = log.brake_pressure[a:b]
        # one filter call per cut-off on stacked channels
        d_raw = -derivative(vs, ts)
        wd_raw = derivative(ws, ts)
        slow = lowpass(np.column_stack([d_raw, wd_raw, ps]), vehicle_cutoff, fs, filter_mode)
        d_f[a:b] = slow[:, 0]
        wd05[a:b] = slow[:, 1:1 + n_ax]
        p05[a:b] = slow[:, 1 + n_ax:]
        sl_raw = vs[:, None] - r * ws
        fast = lowpass(np.column_stack([vs, wd_raw, ps, sl_raw]), wheel_cutoff, fs, filter_mode)
        v_f[a:b] = fast[:, 0]
        wd2[a:b] = fast[:, 1:1 + n_ax]
        p2[a:b] = fast[:, 1 + n_ax:1 + 2 * n_ax]
        slip[a:b] = fast[:, 1 + 2 * n_ax:]
        slip_rate[a:b] = derivative(slip[a:b], ts)
        edge[a:b] = (ts - ts[0] < _EDGE_TIME) | (ts[-1] - ts < _EDGE_TIME)
        # filter start-up / end effects of the fast filter: 1/fc either side
        tf = 1.0 / wheel_cutoff
        edge_fast[a:b] = (ts - ts[0] < tf) | (ts[-1] - ts < tf)
    step("brake coefficient (eq. 14)")
    turning = np.all(log.wheel_speed * r > 0.05 * np.maximum(log.train_speed, 1e-9)[:, None],
                     axis=1)
    sub = getattr(log, "substituted", None)
    sub = np.ascontiguousarray(np.zeros(n_ax, bool) if sub is None else sub, dtype=np.bool_)
    c_ok = np.all(log.valid | sub[None, :], axis=1) & ~edge & turning & (v_f >= min_speed)
    brake = brake_coefficient(t, d_f, wd05, p05, vehicle, speed=v_f, mask=c_ok,
                              min_pressure=min_pressure)
    c = brake.mean if brake_coefficient_value is None else float(
        check_positive(brake_coefficient_value, "brake_coefficient_value"))
    step("normal loads and adhesion (eqs. 10-13)")
    loads = np.ascontiguousarray(vehicle.axle_normal_loads(d_f), dtype=float)
    mu, rel, use = _adhesion(
        wd2, p2, loads, slip, v_f, np.ascontiguousarray(log.wheel_speed),
        np.ascontiguousarray(log.train_speed), np.ascontiguousarray(log.valid), sub,
        edge_fast, j, c, r, float(min_speed),
    )
    pitch = None
    if getattr(vehicle, "secondary_stiffness", None) is not None:
        pitch = np.asarray(vehicle.pitch_angle(d_f), dtype=float)
    fast_ok = v_f >= min_speed
    rel_rate = np.empty((n, n_ax))
    for a, b in _segments(log.segment):
        if b - a >= 2:
            rel_rate[a:b] = derivative(np.nan_to_num(rel[a:b]), t[a:b])
        else:
            rel_rate[a:b] = 0.0
    rel_rate[~fast_ok] = np.nan
    step("identification windows")
    phase = np.zeros((n, n_ax), np.int8)
    rows = []
    for i in range(n_ax):
        s0, s1, sign = identification_windows(
            t, v_f, slip_rate[:, i], use[:, i], log.segment, speed_tolerance=speed_tolerance,
            min_duration=min_window, deadband=slip_rate_deadband,
        )
        if s0.size == 0:
            continue
        marks = np.zeros(n + 1, np.int64)
        np.add.at(marks, s0, sign)
        np.add.at(marks, s1, -sign)
        phase[:, i] = np.cumsum(marks[:-1]).astype(np.int8)
        cnt = (s1 - s0).astype(float)
        cs_v = np.concatenate(([0.0], np.cumsum(v_f)))
        cs_v2 = np.concatenate(([0.0], np.cumsum(v_f * v_f)))
        cs_mu = np.concatenate(([0.0], np.cumsum(mu[:, i])))
        vm = (cs_v[s1] - cs_v[s0]) / cnt
        vv = np.maximum((cs_v2[s1] - cs_v2[s0]) / cnt - vm * vm, 0.0)
        rows.append(pd.DataFrame({
            "axle": i + 1,
            "phase": np.where(sign > 0, "loss", "recovery"),
            "start_time": t[s0], "end_time": t[s1 - 1], "n_samples": (s1 - s0),
            "speed_mean": vm, "speed_std": np.sqrt(vv),
            "slip_start": slip[s0, i], "slip_end": slip[s1 - 1, i],
            "mu_mean": (cs_mu[s1] - cs_mu[s0]) / cnt,
        }))
    cols = ["axle", "phase", "start_time", "end_time", "n_samples", "speed_mean", "speed_std",
            "slip_start", "slip_end", "mu_mean"]
    windows = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=cols)
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
