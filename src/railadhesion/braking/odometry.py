"""Odometry under low adhesion (issue 23): the odometry interface and a reference odometry.

An odometry unit estimates the train's speed and the distance it has travelled from sensors on
a few axles, and states a confidence interval on the distance: the train's minimum and maximum
safe position, as train-control systems report it (ETCS's "min/max safe front end" around
the "estimated position", measured from the last reference point). When its axles slide
under braking or spin under traction, wheel speeds no longer give the train speed.

Odometry interface
------------------
An odometry is any object with

``period`` : float
    Its cycle [s] (a whole multiple of the bench's control period).
``reset(axles, wheel_radius, pulses_per_revolution, gradient)``
    Called once before a run: the axles it reads (numbers counted from 1, the leading axle),
    the nominal wheel radius [m], the encoders' pulses per revolution (0: continuous speed
    only, the pulse counts are then NaN) and the track gradient from its track data (rise
    over run; its accelerometer reads the gravity component of it).
``__call__(time, wheel_speeds, pulse_counts, radar_speed, acceleration, drive)``
    ``time`` [s]; ``wheel_speeds`` the measured angular speeds of its axles [rad/s] (ndarray);
    ``pulse_counts`` the encoder pulses counted on them since the start (ndarray of floats);
    ``radar_speed`` [m/s], NaN without a radar or when its sample is lost; ``acceleration``
    the longitudinal accelerometer's reading [m/s²] (specific force along the track,
    gravity included), NaN without one; ``drive`` the train's command as its train interface
    reports it: -1 brake, 0 neither, +1 traction. Returns ``(speed, distance, distance_min,
    distance_max[, status])`` [m/s, m, m, m; status an integer of flags] or a mapping with
    those keys.

A Python object, or an FMI 2.0 co-simulation FMU imported with FMPy
(:class:`railadhesion.braking.odometry_bench.FmuOdometry`), is run by the odometry bench
(:func:`railadhesion.braking.odometry_bench.run_odometry_programme`).

Reference odometry
------------------
:class:`ReferenceOdometry` (the numba function :func:`odometry_update` on two structured
records, settings and state) is our own baseline, for users to compare theirs against. Every
setting with its default and its source or the word *assumption*:
:meth:`OdometrySettings.sources` and ``docs/odometry.md``. Two parts:

**The interval: guaranteed speed bounds, integrated.** Each cycle every source gives bounds
on the train speed that hold whatever the adhesion, and the interval on the distance is the
integral of the tightest of them: ``d_min += T min(v_lo(t−T), v_lo(t))``, ``d_max += T
max(v_hi(t−T), v_hi(t))``.

* Wheels. With the brake applied no wheel runs faster than the train (creepage ≥ 0): a wheel
  gives a *lower* bound, ``(u − δ)/(1 + e)`` with ``u = ωR`` the measured surface speed, ``e``
  the diameter tolerance and ``δ`` the speed-measurement tolerance. Under traction no wheel
  runs slower than the train: an *upper* bound ``(u + δ)/(1 − e)``. Coasting (no command for
  ``settle_time``) both, widened by ``micro_slip``. Bounds of several axles are voted two out
  of n (the second best), so one faulty encoder cannot tighten the interval alone.
* Accelerometer. Its specific force minus the gravity component of the known gradient,
  integrated from the last bound it did not set (an *anchor*), with its bias bound, the
  gradient tolerance and ``accel_sigmas`` standard deviations of the integrated noise.
* Physics, when nothing else holds: the speed cannot rise faster than ``max_acceleration``
  (traction) or the gravity of the gradient, nor fall faster than ``max_deceleration``
  (brake) or ``coast_deceleration`` (no brake).
* Radar: its sample ± ``radar_sigmas`` standard deviations, its scale tolerance and the speed
  change over its latency.

When the sources contradict each other (their bounds do not overlap), the interval becomes
their hull with the physical bounds and ``CONFLICT`` is flagged: bad data widens it, it never
narrows it.

**The estimate: a Kalman filter** (Kalman 1960) on (distance, speed, accelerometer bias),
driven by the accelerometer; without one, on (distance, speed, acceleration) with white jerk.
Wheel speeds and the radar are its measurements. **Slide and spin detection** by innovation
gating: a wheel whose speed differs from the prediction by more than its tolerance (diameter,
measurement, ``gate_sigmas`` standard deviations of the prediction) is not used until it has
stayed within the gate for ``admit_time`` (the slide or spin has ended); gating measurements
that disagree with the other sensors is the approach of Palmer and Nourani-Vatani
("Robust odometry using sensor consensus analysis", IROS 2018), here as a plain gate.
Without an accelerometer and with every axle sliding, the fastest axle (slowest under
traction) is used with a loose variance, as wheel-slide protection units do. The estimate is
then projected on the guaranteed bounds (estimate projection, D. Simon, "Kalman filtering
with state constraints: a survey", IET Control Theory & Applications 4 (2010) 1303-1318).

Bad input is flagged (``status`` bits, :data:`STATUS_BITS`): a reading that jumps faster than
a wheel can (a lost pulse), an encoder reading that stays exactly constant while the train's
speed changes (stuck), a wheel far below the guaranteed minimum speed for long (a locked
wheel or a dead sensor), a radar silent while the train moves, an accelerometer at its full
scale or repeating one value (saturated or stuck). Such a source is left out, and the
interval widens accordingly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from railadhesion.braking.vehicle import GRAVITY
from railadhesion.io.settings_table import (
    read_settings_table,
    settings_ranges,
    settings_sources,
)

__all__ = [
    "MAX_AXLES",
    "STATUS_BITS",
    "OdometrySettings",
    "ReferenceOdometry",
    "odometry_update",
    "status_names",
]

#: Largest number of axles an odometry reads (as :mod:`railadhesion.braking.sensors`).
MAX_AXLES = 12

#: Status flags of the reference odometry (bit values).
SLIDE, SPIN, DEAD_RECKONING, ENCODER_JUMP, ENCODER_STUCK, ENCODER_LOW, RADAR_LOST, \
    ACCEL_FAULT, CONFLICT = (1 << k for k in range(9))
STATUS_BITS = {"slide": SLIDE, "spin": SPIN, "dead_reckoning": DEAD_RECKONING,
               "encoder_jump": ENCODER_JUMP, "encoder_stuck": ENCODER_STUCK,
               "encoder_low": ENCODER_LOW, "radar_lost": RADAR_LOST,
               "accelerometer_fault": ACCEL_FAULT, "conflict": CONFLICT}

# each setting's allowed range, unit and source (or the word assumption), in the order of the
# fields of OdometrySettings, which hold the defaults: data/odometry_settings.toml
_TABLE = read_settings_table("odometry_settings")
_RANGES = settings_ranges(_TABLE)

SETTINGS_DTYPE = np.dtype([(name, "f8") for name in _TABLE]
                          + [("wheel_radius", "f8"), ("gradient", "f8"), ("n_axles", "i8")],
                          align=True)

STATE_DTYPE = np.dtype([
    ("started", "i8"),
    ("t_prev", "f8"),
    ("mode", "i8"),                     # 1 accelerometer, 0 none, -1 not yet
    ("x", "f8", (3,)),                  # distance, speed, bias (or acceleration)
    ("p", "f8", (3, 3)),                # covariance
    ("fp", "f8", (3, 3)),               # work: F P
    ("v_lo", "f8"), ("v_hi", "f8"), ("d_lo", "f8"), ("d_hi", "f8"),
    ("hi_v", "f8"), ("hi_s", "f8"), ("hi_t", "f8"), ("hi_t2", "f8"),   # upper anchor
    ("lo_v", "f8"), ("lo_s", "f8"), ("lo_t", "f8"), ("lo_t2", "f8"),   # lower anchor
    ("f_prev", "f8"), ("f_same", "i8"), ("a_last", "f8"),
    ("t_brake", "f8"), ("t_traction", "f8"),
    ("regime", "i8"), ("t_regime", "f8"), ("switched", "i8"),   # last command's sign
    ("radar_seen", "i8"), ("radar_t", "f8"),
    ("u_prev", "f8", (MAX_AXLES,)),
    ("same_time", "f8", (MAX_AXLES,)),
    ("v_freeze", "f8", (MAX_AXLES,)),
    ("w_freeze", "f8", (MAX_AXLES,)),
    ("u_ok", "f8", (MAX_AXLES,)),
    ("t_ok", "f8", (MAX_AXLES,)),
    ("low_t", "f8", (MAX_AXLES,)),
    ("ok_time", "f8", (MAX_AXLES,)),
    ("q_fast", "f8", (MAX_AXLES,)),      # wheel speed minus the accelerometer's, fast mean
    ("q_slow", "f8", (MAX_AXLES,)),      # ... slow mean
    ("q_peak", "f8", (MAX_AXLES,)),      # highest fast mean while re-accelerating (-inf: not)
    ("q_env", "f8", (MAX_AXLES,)),       # envelope of the wheel's accepted peaks
    ("v_int", "f8"),                     # free-running integral of the accelerometer
    ("scratch", "f8", (2 * MAX_AXLES,)),
    ("status", "i8"),
], align=True)


@dataclass(frozen=True)
class OdometrySettings:
    """Settings of :class:`ReferenceOdometry` (SI units); every default with its source or the
    word assumption: :meth:`sources` and ``docs/odometry.md`` (the defaults are the fields
    below; ranges, units and sources: ``data/odometry_settings.toml``)."""

    period: float = 0.005
    diameter_tolerance: float = 0.01
    speed_tolerance: float = 0.005
    speed_tolerance_abs: float = 0.1
    micro_slip: float = 0.005
    settle_time: float = 2.0
    accel_bias_bound: float = 0.02
    accel_noise: float = 0.05
    accel_sigmas: float = 5.0
    accel_range: float = 19.6
    accel_stuck_samples: float = 4.0
    gradient_tolerance: float = 0.001
    max_acceleration: float = 1.5
    max_deceleration: float = 3.0
    coast_deceleration: float = 0.15
    radar_noise: float = 0.13
    radar_sigmas: float = 5.0
    radar_scale_tolerance: float = 0.02
    radar_latency: float = 0.05
    radar_loss_time: float = 0.5
    max_wheel_acceleration: float = 150.0
    stuck_time: float = 1.0
    low_fraction: float = 0.1
    low_time: float = 3.0
    gate_sigmas: float = 3.0
    trend_fast: float = 0.05
    trend_slow: float = 0.2
    trend_threshold: float = 0.05
    accel_bias_sigma: float = 0.005
    admit_time: float = 0.3
    bias_walk: float = 1e-6
    jerk_noise: float = 1.0
    slide_speed_noise: float = 0.03

    def __post_init__(self):
        for name, limits in _RANGES.items():
            value = getattr(self, name)
            limits.check(name, value)
            object.__setattr__(self, name, float(value))
        if self.accel_range <= 0.0:
            raise ValueError(f"accel_range must be in (0, 1000] m/s², got {self.accel_range!r}")

    def settings_record(self, n_axles: int, wheel_radius: float,
                        gradient: float = 0.0) -> np.ndarray:
        """The settings as a one-element structured array (for :func:`odometry_update`)."""
        if isinstance(n_axles, bool) or not isinstance(n_axles, int | np.integer) or not (
                1 <= n_axles <= MAX_AXLES):
            raise ValueError(f"the odometry reads 1 to {MAX_AXLES} axles, got {n_axles!r}")
        for name, value, low, high in (("wheel_radius", wheel_radius, 0.1, 1.0),
                                       ("gradient", gradient, -0.1, 0.1)):
            if isinstance(value, bool) or not isinstance(value, int | float) or not (
                    low <= value <= high):
                raise ValueError(f"{name} must be in [{low:g}, {high:g}], got {value!r}")
        rec = np.zeros(1, SETTINGS_DTYPE)
        for name in _TABLE:
            rec[0][name] = getattr(self, name)
        rec[0]["wheel_radius"] = wheel_radius
        rec[0]["gradient"] = gradient
        rec[0]["n_axles"] = n_axles
        return rec

    def as_dict(self) -> dict:
        """The settings by name, in the order of the fields."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @staticmethod
    def sources() -> dict:
        """Each setting: ``(default, unit, source or 'assumption')``."""
        return settings_sources(OdometrySettings, _TABLE)


def state_record() -> np.ndarray:
    """A fresh state of the reference odometry (one-element structured array)."""
    return np.zeros(1, STATE_DTYPE)


def status_names(status: int) -> list[str]:
    """The names of the flags set in a status word."""
    return [name for name, bit in STATUS_BITS.items() if int(status) & bit]


# -- the filter ----------------------------------------------------------------------------
@njit(cache=True)
def _predict(st, T, with_accel, a_in, s):
    """Kalman prediction over T: (distance, speed, bias) driven by the accelerometer input
    a_in, or (distance, speed, acceleration) with white jerk."""
    x = st.x
    p = st.p
    sign = -1.0 if with_accel else 1.0
    c1 = sign * 0.5 * T * T
    c2 = sign * T
    drive = a_in if with_accel else 0.0
    x[0] += x[1] * T + c1 * x[2] + 0.5 * T * T * drive
    x[1] += c2 * x[2] + T * drive
    # P <- F P F', F = [[1, T, c1], [0, 1, c2], [0, 0, 1]]
    fp = st.fp
    for j in range(3):
        fp[0, j] = p[0, j] + T * p[1, j] + c1 * p[2, j]
        fp[1, j] = p[1, j] + c2 * p[2, j]
        fp[2, j] = p[2, j]
    for i in range(3):
        p[i, 0] = fp[i, 0] + T * fp[i, 1] + c1 * fp[i, 2]
        p[i, 1] = fp[i, 1] + c2 * fp[i, 2]
        p[i, 2] = fp[i, 2]
    if with_accel:
        g0 = 0.5 * T * T
        q = s.accel_noise * s.accel_noise
        p[0, 0] += q * g0 * g0
        p[0, 1] += q * g0 * T
        p[1, 0] += q * g0 * T
        p[1, 1] += q * T * T
        p[2, 2] += s.bias_walk * T
    else:
        q = s.jerk_noise
        t2 = T * T
        t3 = t2 * T
        p[0, 0] += q * t3 * t2 / 20.0
        p[0, 1] += q * t2 * t2 / 8.0
        p[1, 0] += q * t2 * t2 / 8.0
        p[0, 2] += q * t3 / 6.0
        p[2, 0] += q * t3 / 6.0
        p[1, 1] += q * t3 / 3.0
        p[1, 2] += q * t2 / 2.0
        p[2, 1] += q * t2 / 2.0
        p[2, 2] += q * T


@njit(cache=True)
def _update_speed(st, z, r):
    """Kalman update with a speed measurement z of variance r."""
    x = st.x
    p = st.p
    s = p[1, 1] + r
    if not s > 0.0:
        return
    k0 = p[0, 1] / s
    k1 = p[1, 1] / s
    k2 = p[2, 1] / s
    y = z - x[1]
    x[0] += k0 * y
    x[1] += k1 * y
    x[2] += k2 * y
    r0, r1, r2 = p[1, 0], p[1, 1], p[1, 2]
    p[0, 0] -= k0 * r0
    p[0, 1] -= k0 * r1
    p[0, 2] -= k0 * r2
    p[1, 0] -= k1 * r0
    p[1, 1] -= k1 * r1
    p[1, 2] -= k1 * r2
    p[2, 0] -= k2 * r0
    p[2, 1] -= k2 * r1
    p[2, 2] -= k2 * r2


@njit(cache=True)
def _second(values, n, largest):
    """The second largest (smallest) of values[:n]; the only one when n == 1 (2-out-of-n)."""
    if n == 1:
        return values[0]
    best = -math.inf if largest else math.inf
    second = best
    for k in range(n):
        v = values[k]
        if (v > best) if largest else (v < best):
            second = best
            best = v
        elif (v > second) if largest else (v < second):
            second = v
    return second


@njit(cache=True)
def odometry_update(settings, state, t, wheel_speeds, radar, accel, drive, out):
    """One cycle of the reference odometry (see the module docstring).

    ``settings``/``state``: the records of :meth:`OdometrySettings.settings_record` and
    :func:`state_record`; ``wheel_speeds`` [rad/s] of the axles read; ``radar`` [m/s] and
    ``accel`` [m/s²] or NaN; ``drive`` -1, 0 or +1. Writes ``out[:5] = (speed, distance,
    distance_min, distance_max, status)``. numba ``@njit``, raises nothing, allocates
    nothing (its state is the record).
    """
    s = settings[0]
    st = state[0]
    n = s.n_axles
    radius = s.wheel_radius
    first = st.started == 0
    if first:
        st.started = 1
        st.t_prev = t
        st.mode = -1
        st.v_lo = 0.0
        st.v_hi = math.inf
        st.d_lo = 0.0
        st.d_hi = 0.0
        st.t_brake = -math.inf
        st.t_traction = -math.inf
        st.radar_t = -math.inf
        st.f_prev = math.nan
        for i in range(n):
            st.u_prev[i] = wheel_speeds[i] * radius
            st.u_ok[i] = st.u_prev[i]
            st.t_ok[i] = t
            st.same_time[i] = 0.0
            st.low_t[i] = 0.0
            st.ok_time[i] = s.admit_time
            st.q_peak[i] = -math.inf
            st.q_env[i] = -math.inf
    T = t - st.t_prev
    if T < 0.0:
        T = 0.0
    status = 0
    # -- the command: which side wheels bound ----------------------------------------------
    # Within a regime (the sign of the last brake or traction command, kept while the command
    # returns to 0) the creepage has one sign: braked wheels run no faster than the train,
    # driven wheels no slower. After a change of sign the wheels need settle_time to come
    # round; before any command (coasting from the start) both, within micro_slip.
    if drive < 0.0:
        st.t_brake = t
    elif drive > 0.0:
        st.t_traction = t
    sign = 1 if drive > 0.0 else (-1 if drive < 0.0 else 0)
    if sign != 0 and sign != st.regime:
        st.switched = 1 if st.regime != 0 else 0
        st.regime = sign
        st.t_regime = t
    since_brake = t - st.t_brake
    since_traction = t - st.t_traction
    coasting = st.regime == 0
    settled = st.switched == 0 or t - st.t_regime >= s.settle_time
    lower_ok = coasting or (st.regime < 0 and settled)
    upper_ok = coasting or (st.regime > 0 and settled)
    micro = s.micro_slip if coasting else 0.0
    g_sin = GRAVITY * math.sin(math.atan(s.gradient))
    g_tol = GRAVITY * math.sin(math.atan(s.gradient_tolerance))
    # -- accelerometer -----------------------------------------------------------------------
    f_ok = accel == accel
    if f_ok:
        if accel == st.f_prev:
            st.f_same += 1
        else:
            st.f_same = 0
        if st.f_same >= s.accel_stuck_samples - 1.0 or abs(accel) >= s.accel_range:
            f_ok = False
            status |= ACCEL_FAULT
    st.f_prev = accel
    a_in = accel - g_sin
    # -- propagation of the bounds -------------------------------------------------------------
    traction_now = drive > 0.0 or since_traction < s.settle_time
    braking_now = drive < 0.0 or since_brake < s.settle_time
    a_max = s.max_acceleration if traction_now else max(0.0, -g_sin) + g_tol
    d_max = s.max_deceleration if braking_now else s.coast_deceleration + max(0.0, g_sin) + g_tol
    v_hi_phys = st.v_hi + a_max * T
    v_lo_phys = st.v_lo - d_max * T
    v_hi_prop = v_hi_phys
    v_lo_prop = v_lo_phys
    v_hi_acc = math.inf
    v_lo_acc = -math.inf
    if f_ok and T > 0.0:
        beta = s.accel_bias_bound + g_tol
        st.hi_s += a_in * T
        st.hi_t += T
        st.hi_t2 += T * T
        st.lo_s += a_in * T
        st.lo_t += T
        st.lo_t2 += T * T
        v_hi_acc = (st.hi_v + st.hi_s + beta * st.hi_t
                    + s.accel_sigmas * s.accel_noise * math.sqrt(st.hi_t2))
        v_lo_acc = (st.lo_v + st.lo_s - beta * st.lo_t
                    - s.accel_sigmas * s.accel_noise * math.sqrt(st.lo_t2))
        v_hi_prop = min(v_hi_prop, v_hi_acc)
        v_lo_prop = max(v_lo_prop, v_lo_acc)
    # -- wheels --------------------------------------------------------------------------------
    v_est = st.x[1]
    lows = st.scratch[:MAX_AXLES]
    highs = st.scratch[MAX_AXLES:]
    n_lo = 0
    n_hi = 0
    e = s.diameter_tolerance
    top1 = -math.inf  # the two fastest readings (for "the other axles")
    top2 = -math.inf
    for i in range(n):
        u = wheel_speeds[i] * radius
        if u > top1:
            top2 = top1
            top1 = u
        elif u > top2:
            top2 = u
    for i in range(n):
        u = wheel_speeds[i] * radius
        valid = u == u and u >= 0.0 and u < math.inf
        others = top2 if u == top1 else top1
        if valid and T > 0.0:
            # a reading a wheel cannot reach from the last good one (a lost pulse)
            since = t - st.t_ok[i]
            jump = abs(u - st.u_ok[i])
            limit = (s.max_wheel_acceleration * since + s.speed_tolerance * max(u, st.u_ok[i])
                     + s.speed_tolerance_abs)
            if jump > limit:
                valid = False
                status |= ENCODER_JUMP
            # a reading that stays exactly the same while the train's speed, or the other
            # axles', changes (zero is a wheel at rest: the "low" test below)
            if u == st.u_prev[i] and u > 0.0:
                st.same_time[i] += T
            else:
                st.same_time[i] = 0.0
                st.v_freeze[i] = v_est
                st.w_freeze[i] = others
            if st.same_time[i] >= s.stuck_time:
                tol_v = e * st.v_freeze[i] + s.speed_tolerance_abs
                tol_w = (e + s.speed_tolerance) * st.w_freeze[i] + s.speed_tolerance_abs
                if abs(v_est - st.v_freeze[i]) > tol_v or (
                        n > 1 and abs(others - st.w_freeze[i]) > tol_w):
                    valid = False
                    status |= ENCODER_STUCK
            if u < s.low_fraction * st.v_lo:
                st.low_t[i] += T
                if st.low_t[i] >= s.low_time:
                    status |= ENCODER_LOW
            else:
                st.low_t[i] = 0.0
        elif first:
            st.v_freeze[i] = u
            st.w_freeze[i] = others
        st.u_prev[i] = u
        if valid:
            st.u_ok[i] = u
            st.t_ok[i] = t
        else:
            st.ok_time[i] = -1.0  # marks the axle unusable this cycle
            continue
        tol = s.speed_tolerance * u + s.speed_tolerance_abs
        if lower_ok:
            lows[n_lo] = max(u - tol, 0.0) / ((1.0 + e) * (1.0 + micro))
            n_lo += 1
        if upper_ok:
            highs[n_hi] = (u + tol) / ((1.0 - e) * (1.0 - micro))
            n_hi += 1
    # two out of n: with two or more axles a bound needs two good readings (an axle left out,
    # bad data, must not leave a single encoder to set the interval)
    vote = min(2, n)
    wheel_lo = _second(lows, n_lo, True) if n_lo >= vote else -math.inf
    wheel_hi = _second(highs, n_hi, False) if n_hi >= vote else math.inf
    # -- radar ---------------------------------------------------------------------------------
    r_ok = radar == radar
    radar_lo = -math.inf
    radar_hi = math.inf
    if r_ok:
        st.radar_seen = 1
        st.radar_t = t
        spread = s.radar_sigmas * s.radar_noise
        radar_lo = (radar - spread) / (1.0 + s.radar_scale_tolerance) - d_max * s.radar_latency
        radar_hi = (radar + spread) / (1.0 - s.radar_scale_tolerance) + a_max * s.radar_latency
    elif st.radar_seen != 0 and st.v_lo > 1.0 and t - st.radar_t >= s.radar_loss_time:
        status |= RADAR_LOST
    # -- combination ---------------------------------------------------------------------------
    lo = max(v_lo_prop, wheel_lo, radar_lo)
    hi = min(v_hi_prop, wheel_hi, radar_hi)
    if lo > hi:  # the sources contradict each other: their hull, never a narrow interval
        status |= CONFLICT
        lo = min(v_lo_phys, v_lo_prop)
        hi = max(v_hi_phys, v_hi_prop)
        if n_lo >= vote:
            lo = min(lo, wheel_lo)
        if r_ok:
            lo = min(lo, radar_lo)
            hi = max(hi, radar_hi)
        if n_hi >= vote:
            hi = max(hi, wheel_hi)
    lo = max(lo, 0.0)
    hi = max(hi, lo)
    if first:
        lo_prev, hi_prev = lo, hi
    else:
        lo_prev, hi_prev = st.v_lo, st.v_hi
    if T > 0.0:
        st.d_lo += T * min(lo_prev, lo)
        st.d_hi += T * max(hi_prev, hi)
    st.v_lo = lo
    st.v_hi = hi
    # re-anchor the accelerometer's bounds where another source set them
    if not (f_ok and hi >= v_hi_acc):
        st.hi_v, st.hi_s, st.hi_t, st.hi_t2 = hi, 0.0, 0.0, 0.0
    if not (f_ok and lo <= v_lo_acc):
        st.lo_v, st.lo_s, st.lo_t, st.lo_t2 = lo, 0.0, 0.0, 0.0
    # -- the estimate: Kalman filter -----------------------------------------------------------
    mode = 1 if f_ok else 0
    if st.mode != mode:
        if st.mode < 0:
            v0 = 0.0
            k = 0
            for i in range(n):
                if st.ok_time[i] >= 0.0:
                    v0 += wheel_speeds[i] * radius
                    k += 1
            if k > 0:
                v0 /= k
            elif r_ok:
                v0 = radar
            else:
                v0 = 0.5 * (lo + hi) if hi < math.inf else lo
            st.x[0] = 0.0
            st.x[1] = v0
            for a in range(3):
                for b in range(3):
                    st.p[a, b] = 0.0
            st.p[1, 1] = (e * v0) ** 2 + s.speed_tolerance_abs ** 2
        for a in range(3):
            st.p[a, 2] = 0.0
            st.p[2, a] = 0.0
        if mode == 1:  # the third state becomes the bias
            st.x[2] = 0.0
            st.p[2, 2] = s.accel_bias_sigma ** 2
            st.v_int = st.x[1]
            for i in range(n):
                q = wheel_speeds[i] * radius - st.v_int
                st.q_fast[i] = q
                st.q_slow[i] = q
        else:  # ... or the acceleration, from the last estimate
            st.x[2] = st.a_last if st.mode == 1 else 0.0
            st.p[2, 2] = 1.0
        st.mode = mode
    if T > 0.0:
        _predict(st, T, mode == 1, a_in, s)
    if mode == 1:
        st.a_last = a_in - st.x[2]
        st.v_int += a_in * T
    else:  # the model's own acceleration stands in for the accelerometer
        st.v_int += st.x[2] * T
    v_pred = st.x[1]
    a_fast = T / (s.trend_fast + T)
    a_slow = T / (s.trend_slow + T)
    env_decay = (s.accel_bias_bound + g_tol) * T
    gate = (e + s.speed_tolerance) * abs(v_pred) + s.speed_tolerance_abs
    used = 0
    fixes = 0
    unused = 0
    fastest = -math.inf
    slowest = math.inf
    for i in range(n):
        if st.ok_time[i] < 0.0:  # unusable reading
            st.ok_time[i] = 0.0
            unused += 1
            continue
        u = wheel_speeds[i] * radius
        fastest = max(fastest, u)
        slowest = min(slowest, u)
        # the wheel's speed against the accelerometer's (or model's): no drift
        q = u - st.v_int
        st.q_fast[i] += a_fast * (q - st.q_fast[i])
        st.q_slow[i] += a_slow * (q - st.q_slow[i])
        trend = st.q_fast[i] - st.q_slow[i]
        steady = abs(trend) <= s.trend_threshold
        st.q_env[i] -= env_decay
        if trend > s.trend_threshold and lower_ok:
            st.q_peak[i] = max(st.q_peak[i], st.q_fast[i])
        elif st.q_peak[i] > -math.inf and trend < 0.0:
            # the end of a re-acceleration under braking: at its peak the wheel rolled at
            # the train speed (a speed fix) unless it re-applied before: a partial
            # recovery peaks below the wheel's earlier full ones (its envelope; the
            # accelerometer's integral moves it by at most the bias bound) and below
            # the estimate's gate
            peak = st.q_peak[i]
            z = st.v_int + peak
            st.q_peak[i] = -math.inf
            if (lower_ok and z >= v_pred - gate
                    and peak >= st.q_env[i] - s.speed_tolerance * z - s.speed_tolerance_abs):
                _update_speed(st, z, (e * z) ** 2 / 3.0 + (s.speed_tolerance * z) ** 2
                              + s.speed_tolerance_abs ** 2)
                fixes += 1
                st.q_env[i] = max(st.q_env[i], peak)
        # a rolling wheel while coasting: inside the innovation gate (its tolerances and the
        # prediction's uncertainty) and steady, for admit_time
        r = (e * u) ** 2 / 3.0 + (s.speed_tolerance * u) ** 2 + s.speed_tolerance_abs ** 2
        gate_i = max(gate, s.gate_sigmas * math.sqrt(max(st.p[1, 1], 0.0) + r))
        if steady and abs(u - v_pred) <= gate_i and coasting:
            st.ok_time[i] += T
        else:
            st.ok_time[i] = 0.0
        if st.ok_time[i] >= s.admit_time:
            _update_speed(st, u, r)
            used += 1
        else:
            unused += 1
    if r_ok:
        rate = (a_in - st.x[2]) if mode == 1 else st.x[2]
        r = (s.radar_noise ** 2 + (s.radar_scale_tolerance * radar) ** 2 / 3.0
             + (rate * s.radar_latency) ** 2)
        _update_speed(st, radar + rate * s.radar_latency, r)
    elif used == 0 and fixes == 0:
        status |= DEAD_RECKONING
        if mode == 0 and fastest > -math.inf:
            z = slowest if drive > 0.0 else fastest
            _update_speed(st, z, (s.slide_speed_noise * z) ** 2 + s.speed_tolerance_abs ** 2)
    if unused > 0:
        status |= SPIN if st.regime > 0 else SLIDE
    # projection on the guaranteed bounds
    st.x[1] = min(max(st.x[1], lo), hi)
    st.x[0] = min(max(st.x[0], st.d_lo), st.d_hi)
    st.t_prev = t
    st.status = status
    out[0] = st.x[1]
    out[1] = st.x[0]
    out[2] = st.d_lo
    out[3] = st.d_hi
    out[4] = status


class ReferenceOdometry:
    """The reference odometry as an object of the odometry interface (see the module
    docstring). ``ReferenceOdometry(OdometrySettings(...))`` or ``ReferenceOdometry(**settings)``.

    After a call, :attr:`speed_bounds` gives the guaranteed speed interval [m/s] and
    :attr:`status` the flags (:func:`status_names`).
    """

    label = "reference odometry"

    def __init__(self, settings: OdometrySettings | None = None, **changes):
        if settings is None:
            settings = OdometrySettings(**changes)
        elif changes:
            settings = OdometrySettings(**{**settings.as_dict(), **changes})
        if not isinstance(settings, OdometrySettings):
            raise ValueError(f"settings must be an OdometrySettings, got "
                             f"{type(settings).__name__}")
        self.settings = settings
        self.period = settings.period
        self._record = None
        self._state = None
        self._out = np.zeros(5)

    def reset(self, axles, wheel_radius, pulses_per_revolution=0.0, gradient=0.0):
        """Start a run reading ``axles`` (numbers from 1) with the nominal ``wheel_radius`` [m]
        on a track of ``gradient`` (rise over run, from the track data)."""
        axles = tuple(int(a) for a in axles)
        self.axles = axles
        self._record = self.settings.settings_record(len(axles), float(wheel_radius),
                                                     float(gradient))
        self._state = state_record()

    def __call__(self, time, wheel_speeds, pulse_counts=None, radar_speed=math.nan,
                 acceleration=math.nan, drive=0):
        if self._state is None:
            raise ValueError("call reset(axles, wheel_radius, ...) before the first call")
        w = np.ascontiguousarray(wheel_speeds, dtype=float)
        n = int(self._record[0]["n_axles"])
        if w.shape != (n,):
            raise ValueError(f"wheel_speeds must have {n} entries, got shape {w.shape}")
        odometry_update(self._record, self._state, float(time), w, float(radar_speed),
                        float(acceleration), float(drive), self._out)
        out = self._out
        return float(out[0]), float(out[1]), float(out[2]), float(out[3]), int(out[4])

    def step_record(self, time, wheel_speeds, radar_speed, acceleration, drive):
        """The same as a call, without conversions (for a bench that passes float arrays);
        returns the output array (speed, distance, distance_min, distance_max, status)."""
        odometry_update(self._record, self._state, time, wheel_speeds, radar_speed,
                        acceleration, drive, self._out)
        return self._out

    @property
    def speed_bounds(self) -> tuple[float, float]:
        """The guaranteed speed interval (v_min, v_max) [m/s] after the last call."""
        if self._state is None:
            return (math.nan, math.nan)
        return float(self._state[0]["v_lo"]), float(self._state[0]["v_hi"])

    @property
    def status(self) -> int:
        return 0 if self._state is None else int(self._state[0]["status"])

    def describe(self) -> dict:
        return {"method": "Kalman filter with innovation gating; guaranteed speed bounds "
                          "integrated for the interval", **self.settings.as_dict()}
