"""Wheel slide protection (WSP): the default controller and the controller interface.

Controller interface (how a user's, or a HIL rig's, controller attaches)
---------------------------------------------------------------------
A controller is any object with

``period`` : float
    Its control period [s] (called every ``period``; a whole multiple of the simulation step).
``reset(n_axles, wheel_radius)``
    Called once before a run.
``__call__(time, wheel_speeds, pressure_command[, brake_pressures, external_speed]) -> valves``
    ``time`` [s], ``wheel_speeds`` the *measured* wheelset angular speeds [rad/s] (ndarray,
    axle 1 = leading), ``pressure_command`` the commanded cylinder pressure [Pa] (a number or
    one per axle); optionally the measured brake-cylinder pressures [Pa] per axle and an
    external train speed [m/s] (NaN when there is none), passed when the controller's
    ``__call__`` accepts parameters of those names. Returns the valve state of each axle (or of
    each bogie with ``valves="bogie"``): 0 = apply, 1 = hold, 2 = vent.

A plain function with that signature works too (its period is then given separately). The
controller sees measurements only: the true train speed is never passed to it.

Default controller
------------------
:class:`WheelSlideProtection` is a generic logic of the usual kind (not a particular
supplier's), run by :func:`wsp_update`, a numba function on two structured records (settings
and state) that the compiled braking step calls every control period. Its behaviour, every
setting with its default and its source or the word *assumption*, and what follows EN 15595 /
UIC 541-05 as far as public sources describe them, are in ``docs/wsp.md``. In short:

* **Reference speed** from the (filtered) wheel speeds: it follows the fastest wheel upwards
  and falls at most at a deceleration limit. The limit adapts to the brake: the train cannot
  decelerate faster than its brakes make it, so the limit is the vehicle's nominal
  deceleration for the measured mean cylinder pressure (``deceleration_per_pressure``, from
  the vehicle, seed 002 eq. 8) with a tolerance (``brake_rate_tolerance``) and an allowance
  for gradient and resistance (``reference_deceleration_offset``), capped at
  ``reference_deceleration``. Speed *fixes* correct it: a released wheel that has stopped
  re-accelerating rolls at the train speed, and the reference takes its speed (downwards too
  if its brake pressure is below ``free_pressure``, where a wheel cannot stay in slip). When
  every valve group is in slide control and no fix came for ``probe_interval``, one group
  (in turn) is released on purpose until its wheels roll freely (**probe**). An external
  speed (radar, GNSS) keeps the reference within ``external_tolerance`` of it.
* **Per valve group** (an axle, or a bogie with ``valves="bogie"``): slip ``v_ref − ωR``
  and wheel deceleration *relative to the reference's* decide APPLY → HOLD → VENT; VENT →
  HOLD when the wheel re-accelerates (or nothing is left to vent); after the re-acceleration
  has ended for ``settle_time`` the wheel has rejoined the train: speed fix, then
  **re-application**: fast up to ``reapply_fast_fraction`` of the pressure at which the slide
  began, then in steps (an APPLY pulse of ``reapply_pulse`` every ``reapply_step``), until the
  command is reached or a new slide starts.
* **Watchdog** (EN 15595 §5.1.4 "safety timer"): a group may not stay released (HOLD or VENT)
  for more than ``watchdog_time`` *without its wheels re-accelerating*; it is then forced to
  APPLY for ``watchdog_refill_time``. A wheel that is recovering (re-accelerating) is never
  re-applied by the watchdog: that is what re-locked unrecovered wheels before. After
  ``watchdog_cutout_trips`` trips with no recovery in between the group's WSP is cut out
  (brake applied) until the brake command returns to 0: a fault reaction.
"""

from __future__ import annotations

import inspect
import math
import warnings
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from railadhesion.braking.cylinders import APPLY, HOLD, VENT

__all__ = ["WSPSettings", "WheelSlideProtection", "as_controller", "call_controller",
           "accepts_measurements",
           "wsp_update", "settings_file_keys", "state_diagnostics", "SETTINGS_DTYPE",
           "STATE_DTYPE", "PHASES"]

#: Largest number of axles (as in :mod:`railadhesion.braking.sensors`).
MAX_AXLES = 12

# phases of a valve group
NORMAL, ONSET, VENTING, RECOVER, REAPPLY, PROBE, CUTOUT = range(7)
#: Names of the phases of a valve group (diagnostics).
PHASES = ("normal", "onset hold", "vent", "recover", "re-apply", "probe", "cut out")

# settings: name -> (default, low, high, unit, source). None defaults are taken from the vehicle.
_SPEC = {
    "period": (5e-3, 1e-4, 0.1, "s", "assumption (WSP control cycles of a few ms)"),
    "reference_deceleration": (2.5, 0.1, 10.0, "m/s²", "assumption: above the full-brake "
                               "deceleration of a coach on a good rail (2.1 m/s² for the "
                               "shipped coach at 5.5 bar)"),
    "deceleration_per_pressure": (None, 0.0, 1e-3, "m/s² per Pa", "the vehicle's nominal "
                                  "brake rate n c / (R M_eff), seed 002 eq. 8; 0: not used"),
    "brake_rate_tolerance": (0.25, 0.0, 5.0, "-", "assumption: spread of pad friction and "
                             "load"),
    "reference_deceleration_offset": (0.15, 0.0, 5.0, "m/s²", "assumption: 1 % up-gradient "
                                      "(0.1 m/s²) plus running resistance"),
    "hold_slip_ratio": (0.05, 0.0, 1.0, "-", "assumption"),
    "hold_slip_min": (0.15, 0.0, 10.0, "m/s", "assumption"),
    "vent_slip_ratio": (0.10, 0.0, 1.0, "-", "assumption; on the HAROLD rig WSP units released "
                        "the brake above about 20 % creep (trade press)"),
    "vent_slip_min": (0.3, 0.0, 10.0, "m/s", "assumption; drivers' forums quote an axle "
                      "4 mph (1.8 m/s) slower than the others as sliding (anecdotal)"),
    "reapply_slip_ratio": (0.03, 0.0, 1.0, "-", "assumption"),
    "reapply_slip_min": (0.1, 0.0, 10.0, "m/s", "assumption"),
    "hold_deceleration": (3.0, 0.0, 100.0, "m/s²", "assumption (relative to the reference)"),
    "vent_deceleration": (6.0, 0.0, 100.0, "m/s²", "assumption (relative to the reference)"),
    "recovery_acceleration": (2.0, 0.0, 100.0, "m/s²", "assumption (relative to the "
                              "reference): vent until the wheel re-accelerates this fast"),
    "recovery_end_acceleration": (0.5, 0.0, 100.0, "m/s²", "assumption (relative to the "
                                  "reference): below it a wheel no longer re-accelerates"),
    "speed_filter": (0.02, 0.0, 1.0, "s", "assumption"),
    "deceleration_filter": (0.05, 0.0, 1.0, "s", "assumption"),
    "settle_time": (0.1, 0.0, 5.0, "s", "assumption"),
    "free_pressure": (0.2e5, 0.0, 1e6, "Pa", "assumption: 0.2 bar, a brake torque below the "
                      "adhesion torque of a wheel at μ = 0.02 on the shipped coach"),
    "onset_hold_time": (0.2, 0.0, 10.0, "s", "assumption"),
    "reapply_deceleration": (0.6, 0.0, 100.0, "m/s²", "assumption: no re-application step "
                             "while the wheel decelerates this much more than the reference"),
    "reapply_fast_fraction": (0.7, 0.0, 1.0, "-", "assumption"),
    "reapply_step_fraction": (0.05, 0.0, 1.0, "-", "assumption: a re-application step "
                              "changes the pressure by this fraction of the slide pressure"),
    "reapply_pulse": (5e-3, 0.0, 1.0, "s", "assumption: the APPLY pulse of a step when the "
                      "pressure is not measured"),
    "release_pulse": (0.01, 0.0, 1.0, "s", "assumption: the VENT pulse of a release step when "
                      "the pressure is not measured"),
    "reapply_step": (0.1, 1e-4, 10.0, "s", "assumption"),
    "reapply_max_time": (3.0, 0.01, 600.0, "s", "assumption"),
    "probe_interval": (2.0, 0.05, 600.0, "s", "assumption"),
    "probe_max_time": (2.0, 0.05, 600.0, "s", "assumption"),
    "probe_pressure_fraction": (0.5, 0.0, 1.0, "-", "assumption: a probe vents to this "
                                "fraction of the pressure (less while the wheel still slides)"),
    "probe_min_speed": (2.0, 0.0, 100.0, "m/s", "assumption"),
    "watchdog_time": (3.0, 0.01, 600.0, "s", "assumption; EN 15595 §5.1.4 names the safety "
                      "timer, its value is not public; Open Rails locks out after 7 s"),
    "watchdog_refill_time": (0.5, 0.0, 60.0, "s", "assumption"),
    "watchdog_cutout_trips": (3, 1, 1000, "-", "assumption"),
    "external_latency": (0.0, 0.0, 5.0, "s", "the external sensor's latency, if known"),
    "external_tolerance": (0.5, 0.0, 100.0, "m/s", "assumption: 3-4 standard deviations of "
                           "a radar sample (twin-radar error 0.47 km/h, a 2023 study)"),
    "wheel_radius": (None, 0.1, 1.0, "m", "the vehicle's nominal wheel radius"),
    "valves": (None, None, None, "", "'axle' or 'bogie': from the brake cylinders' valves"),
}

_DEPRECATED = {
    "sliding_reference_deceleration": (
        "sliding_reference_deceleration is no longer used: while every axle slides the "
        "reference falls at most at the deceleration the measured brake pressures can give "
        "(deceleration_per_pressure) and is corrected by speed fixes and probes "
        "(docs/wsp.md); the value is ignored"),
}

SETTINGS_DTYPE = np.dtype(
    [(name, "f8") for name in _SPEC if name not in ("valves", "watchdog_cutout_trips")]
    + [("watchdog_cutout_trips", "i8"), ("per_bogie", "i8")], align=True)

STATE_DTYPE = np.dtype([
    ("n_axles", "i8"),
    ("n_groups", "i8"),
    ("started", "i8"),
    ("v_ref", "f8"),               # reference speed [m/s]
    ("d_ref", "f8"),               # its filtered deceleration [m/s²]
    ("t_fix", "f8"),               # time of the last speed fix [s]
    ("probe", "i8"),               # group being probed, or -1
    ("probe_next", "i8"),
    ("fixes", "i8"),
    ("probes", "i8"),
    ("watchdog_trips", "i8"),
    ("vent_commands", "i8"),
    ("u", "f8", (MAX_AXLES,)),     # filtered wheel speeds [m/s]
    ("acc", "f8", (MAX_AXLES,)),   # filtered wheel accelerations [m/s²]
    ("phase", "i8", (MAX_AXLES,)),
    ("valve", "i8", (MAX_AXLES,)),
    ("t_phase", "f8", (MAX_AXLES,)),
    ("p_slide", "f8", (MAX_AXLES,)),
    ("t_step", "f8", (MAX_AXLES,)),
    ("settle", "f8", (MAX_AXLES,)),
    ("turned", "i8", (MAX_AXLES,)),   # re-application step: 0 up, 1 down, 2 none
    ("p_target", "f8", (MAX_AXLES,)),
    ("wd_timer", "f8", (MAX_AXLES,)),
    ("wd_until", "f8", (MAX_AXLES,)),
    ("wd_trips", "i8", (MAX_AXLES,)),
    ("cutout", "i8", (MAX_AXLES,)),
], align=True)


@njit(cache=True)
def _enter(st, g, phase, p_slide):
    st.phase[g] = phase
    st.turned[g] = 2
    st.t_phase[g] = 0.0
    st.t_step[g] = 1e9  # the first step is decided at once
    if not math.isnan(p_slide):
        st.p_slide[g] = p_slide


@njit(cache=True)
def wsp_update(settings, state, t, omega_meas, pressure_meas, command, external_speed,
               valves_out):
    """One control period of the default WSP (see the module docstring and docs/wsp.md).

    ``settings``/``state``: one-element structured arrays (:meth:`WheelSlideProtection.
    settings_record`, :meth:`~WheelSlideProtection.state_record`); ``omega_meas`` [rad/s],
    ``pressure_meas`` [Pa] (NaN: unknown), ``command`` [Pa] per axle, ``external_speed`` [m/s]
    or NaN; writes the valve codes (0 apply, 1 hold, 2 vent) into ``valves_out`` (int64, per
    axle; per-bogie valves: the same code for the axles of a bogie). No exceptions, no
    allocation.
    """
    s = settings[0]
    st = state[0]
    n = st.n_axles
    ng = st.n_groups
    per = n // ng
    T = s.period
    radius = s.wheel_radius
    first = st.started == 0
    # 1. wheel speeds and accelerations (two first-order filters)
    a_u = T / (s.speed_filter + T)
    a_a = T / (s.deceleration_filter + T)
    umax = -math.inf
    psum = 0.0
    for i in range(n):
        u = omega_meas[i] * radius
        if first:
            st.u[i] = u
            st.acc[i] = 0.0
        else:
            u_new = st.u[i] + a_u * (u - st.u[i])
            st.acc[i] += a_a * ((u_new - st.u[i]) / T - st.acc[i])
            st.u[i] = u_new
        umax = max(umax, st.u[i])
        psum += pressure_meas[i]
    if first:
        st.started = 1
        st.v_ref = umax
        st.d_ref = 0.0
        st.t_fix = t
        st.probe = -1
        for g in range(ng):
            _enter(st, g, NORMAL, 0.0)
            st.valve[g] = APPLY
            st.wd_until[g] = -math.inf
    # 2. reference speed
    limit = s.reference_deceleration
    if s.deceleration_per_pressure > 0.0 and psum == psum:
        brake = ((1.0 + s.brake_rate_tolerance) * s.deceleration_per_pressure * psum / n
                 + s.reference_deceleration_offset)
        limit = min(limit, brake)
    v_new = max(umax, st.v_ref - limit * T)
    if external_speed == external_speed:
        v_ext = external_speed - st.d_ref * s.external_latency
        v_new = min(max(v_new, v_ext - s.external_tolerance), v_ext + s.external_tolerance)
    a_d = T / (0.2 + T)
    slope = (st.v_ref - v_new) / T
    st.d_ref += a_d * (min(max(slope, 0.0), s.reference_deceleration) - st.d_ref)
    st.v_ref = max(v_new, 0.0)
    v_ref = st.v_ref
    hold = max(s.hold_slip_ratio * v_ref, s.hold_slip_min)
    vent = max(s.vent_slip_ratio * v_ref, s.vent_slip_min)
    reapply = max(s.reapply_slip_ratio * v_ref, s.reapply_slip_min)
    # 3. valve groups
    normal_groups = 0
    fixing = 0
    for g in range(ng):
        slip = -math.inf
        dec = -math.inf
        reacc = -math.inf
        p = -math.inf
        u_g = -math.inf
        cmd = 0.0
        for i in range(g * per, g * per + per):
            slip = max(slip, v_ref - st.u[i])
            dec = max(dec, -st.acc[i] - st.d_ref)
            reacc = max(reacc, st.acc[i] + st.d_ref)
            if pressure_meas[i] == pressure_meas[i]:
                p = max(p, pressure_meas[i])
            else:
                p = math.nan
            u_g = max(u_g, st.u[i])
            cmd = max(cmd, command[i])
        want_vent = slip > vent or dec > s.vent_deceleration
        want_hold = slip > hold or dec > s.hold_deceleration
        accelerating = reacc > s.recovery_end_acceleration
        if not accelerating and dec < s.recovery_end_acceleration:
            st.settle[g] += T
        else:
            st.settle[g] = 0.0
        free = p < s.free_pressure  # False when the pressure is unknown (NaN)
        st.t_phase[g] += T
        phase = st.phase[g]
        if cmd <= 0.0:
            # not braking: nothing to protect; a cut-out ends with the brake application
            if phase != NORMAL:
                _enter(st, g, NORMAL, 0.0)
            st.cutout[g] = 0
            st.wd_trips[g] = 0
        elif st.cutout[g] != 0:
            phase = CUTOUT
        elif phase == NORMAL:
            if want_vent:
                _enter(st, g, VENTING, p)
            elif want_hold:
                _enter(st, g, ONSET, p)
        elif phase == ONSET:
            if want_vent or st.t_phase[g] > s.onset_hold_time:
                _enter(st, g, VENTING, math.nan)
            elif slip < reapply and dec < 0.5 * s.hold_deceleration:
                _enter(st, g, REAPPLY, math.nan)
        elif phase == VENTING:
            if reacc > s.recovery_acceleration or p < 0.5 * s.free_pressure:
                _enter(st, g, RECOVER, math.nan)
        elif phase == RECOVER:
            if st.settle[g] >= s.settle_time:
                if slip < reapply or free:
                    fixing = 1
                    st.v_ref = u_g if free else max(st.v_ref, u_g)
                    st.t_fix = t
                    st.fixes += 1
                    st.wd_trips[g] = 0
                    _enter(st, g, REAPPLY, math.nan)
                elif want_hold:
                    _enter(st, g, VENTING, math.nan)
                else:
                    _enter(st, g, REAPPLY, math.nan)
            elif slip < reapply and st.t_phase[g] >= s.settle_time:
                _enter(st, g, REAPPLY, math.nan)  # nearly back: re-apply at once (no fix)
            elif want_vent and reacc < s.recovery_acceleration and st.t_phase[g] > s.settle_time:
                _enter(st, g, VENTING, math.nan)
        elif phase == REAPPLY:
            if want_vent:
                _enter(st, g, VENTING, p)
            elif want_hold:
                _enter(st, g, ONSET, p)
            elif p >= cmd - 5e3 or st.t_phase[g] > s.reapply_max_time:
                _enter(st, g, NORMAL, math.nan)
        elif phase == PROBE:
            if st.settle[g] >= s.settle_time and (free or p <= st.p_target[g]
                                                  or (p != p and slip < reapply)):
                st.v_ref = u_g
                st.t_fix = t
                st.fixes += 1
                st.probe = -1
                _enter(st, g, REAPPLY, math.nan)
            elif st.t_phase[g] > s.probe_max_time:
                st.probe = -1
                _enter(st, g, REAPPLY, math.nan)
        phase = st.phase[g] if st.cutout[g] == 0 or cmd <= 0.0 else CUTOUT
        # valve of the phase
        if phase == NORMAL or phase == CUTOUT:
            valve = APPLY
        elif phase == ONSET or phase == RECOVER:
            valve = HOLD
        elif phase == VENTING:
            valve = VENT
        elif phase == REAPPLY:
            valve = HOLD
            if p < s.reapply_fast_fraction * st.p_slide[g]:
                valve = APPLY  # fast part; the first step pulse follows at once
                st.t_step[g] = 0.0
            else:
                # steps of the memorised slide pressure: up while the wheel follows the
                # reference, down when it falls behind (an incipient slide), else hold;
                # timed pulses when the pressure is not measured
                if st.t_step[g] >= s.reapply_step - 1e-12:
                    st.t_step[g] = 0.0
                    step = s.reapply_step_fraction * st.p_slide[g]
                    middle = 0.5 * (reapply + hold)
                    if dec > 2.0 * s.reapply_deceleration or (
                            slip > middle and dec > 0.5 * s.reapply_deceleration):
                        st.turned[g] = 1  # a release step
                        st.p_target[g] = p - step
                    elif slip < middle and dec < s.reapply_deceleration:
                        st.turned[g] = 0  # an apply step
                        st.p_target[g] = p + step
                    else:
                        st.turned[g] = 2
                if st.turned[g] == 0:
                    if (p < st.p_target[g]) if p == p else (
                            st.t_step[g] < s.reapply_pulse - 1e-12):
                        valve = APPLY
                elif st.turned[g] == 1:
                    if (p > st.p_target[g]) if p == p else (
                            st.t_step[g] < s.release_pulse - 1e-12):
                        valve = VENT
        else:  # PROBE: vent to a fraction of the pressure (deeper while the wheel slides)
            if dec > s.reapply_deceleration and st.t_phase[g] > s.settle_time:
                st.p_target[g] = min(st.p_target[g], s.probe_pressure_fraction * p)
            valve = VENT if (p > st.p_target[g] or p != p) and not free else HOLD
        # 4. watchdog (safety timer)
        if t < st.wd_until[g]:
            valve = APPLY
        elif valve != APPLY and not accelerating:
            st.wd_timer[g] += T
            if st.wd_timer[g] >= s.watchdog_time - 1e-9:
                valve = APPLY
                st.wd_timer[g] = 0.0
                st.wd_until[g] = t + s.watchdog_refill_time
                st.wd_trips[g] += 1
                st.watchdog_trips += 1
                if st.probe == g:
                    st.probe = -1
                _enter(st, g, REAPPLY, math.nan)
                if st.wd_trips[g] >= s.watchdog_cutout_trips:
                    st.cutout[g] = 1
        else:
            st.wd_timer[g] = 0.0
        st.t_step[g] += T
        if valve == VENT and st.valve[g] != VENT:
            st.vent_commands += 1
        st.valve[g] = valve
        if st.phase[g] == NORMAL:
            normal_groups += 1
        for i in range(g * per, g * per + per):
            valves_out[i] = valve
    # 5. probe: every group in slide control and no speed fix for a while
    if (fixing == 0 and st.probe < 0 and normal_groups == 0 and ng > 1
            and t - st.t_fix > s.probe_interval and st.v_ref > s.probe_min_speed):
        busy = False
        for g in range(ng):
            if st.phase[g] == VENTING or st.phase[g] == RECOVER:
                busy = True  # a fix is on its way
        if not busy:
            for k in range(ng):
                g = (st.probe_next + k) % ng
                if st.phase[g] == ONSET or st.phase[g] == REAPPLY:
                    st.probe = g
                    st.probe_next = (g + 1) % ng
                    st.probes += 1
                    _enter(st, g, PROBE, math.nan)
                    p = -math.inf
                    for i in range(g * per, g * per + per):
                        p = max(p, pressure_meas[i])
                    st.p_target[g] = s.probe_pressure_fraction * p
                    break


_SUFFIX = {"s": "_s", "m/s²": "_m_s2", "m/s": "_m_s", "Pa": "_Pa", "m": "_m", "-": "",
           "m/s² per Pa": "_m_s2_per_Pa"}


def settings_file_keys() -> dict:
    """The WSP settings as keys of a TOML table (name with its unit: ``period_s``,
    ``hold_slip_min_m_s``, ...): ``{key: (field, low, high)}``. The wheel radius and the valve
    arrangement come from the vehicle and the brake cylinders, not from the table; the
    deprecated ``sliding_reference_deceleration_m_s2`` maps to its (ignored) field."""
    keys = {}
    for name, (_, low, high, unit, _) in _SPEC.items():
        if name in ("wheel_radius", "valves"):
            continue
        keys[name + _SUFFIX[unit]] = (name, low, high)
    keys["sliding_reference_deceleration_m_s2"] = ("sliding_reference_deceleration", 0.0, 10.0)
    return keys


def _number(name, value):
    default, low, high, unit, _ = _SPEC[name]
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    if not low <= value <= high:
        raise ValueError(f"{name} must be in [{low:g}, {high:g}] {unit}, got {value!r}")


@dataclass(frozen=True)
class WSPSettings:
    """Settings of :class:`WheelSlideProtection` (SI units). Every default with its source or
    the word assumption: :func:`WSPSettings.sources` and ``docs/wsp.md``.

    ``wheel_radius``, ``deceleration_per_pressure`` and ``valves`` default to None: taken from
    the vehicle and brake cylinders (:meth:`WheelSlideProtection.configure`, done by
    :func:`~railadhesion.braking.simulate` and the WSP bench). ``sliding_reference_deceleration``
    of earlier versions is accepted with a ``DeprecationWarning`` and ignored.
    """

    period: float = 5e-3
    reference_deceleration: float = 2.5
    deceleration_per_pressure: float | None = None
    brake_rate_tolerance: float = 0.25
    reference_deceleration_offset: float = 0.15
    hold_slip_ratio: float = 0.05
    hold_slip_min: float = 0.15
    vent_slip_ratio: float = 0.10
    vent_slip_min: float = 0.3
    reapply_slip_ratio: float = 0.03
    reapply_slip_min: float = 0.1
    hold_deceleration: float = 3.0
    vent_deceleration: float = 6.0
    recovery_acceleration: float = 2.0
    recovery_end_acceleration: float = 0.5
    speed_filter: float = 0.02
    deceleration_filter: float = 0.05
    settle_time: float = 0.1
    free_pressure: float = 0.2e5
    onset_hold_time: float = 0.2
    reapply_deceleration: float = 0.6
    reapply_fast_fraction: float = 0.7
    reapply_step_fraction: float = 0.05
    reapply_pulse: float = 5e-3
    release_pulse: float = 0.01
    reapply_step: float = 0.1
    reapply_max_time: float = 3.0
    probe_interval: float = 2.0
    probe_max_time: float = 2.0
    probe_pressure_fraction: float = 0.5
    probe_min_speed: float = 2.0
    watchdog_time: float = 3.0
    watchdog_refill_time: float = 0.5
    watchdog_cutout_trips: int = 3
    external_latency: float = 0.0
    external_tolerance: float = 0.5
    wheel_radius: float | None = None
    valves: str | None = None

    def __init__(self, **kwargs):
        for name, message in _DEPRECATED.items():
            if name in kwargs:
                kwargs.pop(name)
                warnings.warn(message, DeprecationWarning, stacklevel=3)
        unknown = set(kwargs) - set(_SPEC)
        if unknown:
            raise ValueError(f"unknown WSP setting(s) {sorted(unknown)}; known: "
                             f"{', '.join(_SPEC)}")
        for name, spec in _SPEC.items():
            object.__setattr__(self, name, kwargs.get(name, spec[0]))
        self.__post_init__()

    def __post_init__(self):
        for name in _SPEC:
            value = getattr(self, name)
            if name == "valves":
                if value not in (None, "axle", "bogie"):
                    raise ValueError(f"valves must be None, 'axle' or 'bogie', got {value!r}")
            elif name == "watchdog_cutout_trips":
                if isinstance(value, bool) or not isinstance(value, int) or not (
                        1 <= value <= 1000):
                    raise ValueError(f"watchdog_cutout_trips must be an integer in [1, 1000], "
                                     f"got {value!r}")
            elif value is not None or _SPEC[name][0] is not None:
                _number(name, value)
        if not self.reapply_slip_ratio <= self.hold_slip_ratio <= self.vent_slip_ratio:
            raise ValueError("slip ratios must satisfy reapply_slip_ratio <= hold_slip_ratio "
                             "<= vent_slip_ratio, got "
                             f"{self.reapply_slip_ratio}, {self.hold_slip_ratio}, "
                             f"{self.vent_slip_ratio}")
        if not self.hold_deceleration <= self.vent_deceleration:
            raise ValueError("hold_deceleration must not exceed vent_deceleration, got "
                             f"{self.hold_deceleration} > {self.vent_deceleration}")

    def replace(self, **changes) -> WSPSettings:
        return WSPSettings(**{**self.as_dict(), **changes})

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @staticmethod
    def sources() -> dict:
        """Each setting: ``(default, unit, source or 'assumption')``."""
        return {k: (v[0], v[3], v[4]) for k, v in _SPEC.items()}


class WheelSlideProtection:
    """The default WSP controller (see the module docstring and ``docs/wsp.md``).

    ``WheelSlideProtection(WSPSettings(...))`` or ``WheelSlideProtection(**settings)``.
    For a run: :meth:`configure` with the vehicle (and cylinders), then either the records
    (:meth:`settings_record`, :meth:`state_record`, :func:`wsp_update`: what compiled code
    calls) or, from Python, :meth:`reset` and calls.
    """

    def __init__(self, settings: WSPSettings | None = None, **changes):
        if settings is None:
            settings = WSPSettings(**changes)
        elif changes:
            settings = settings.replace(**changes)
        if not isinstance(settings, WSPSettings):
            raise ValueError(f"settings must be a WSPSettings, got {type(settings).__name__}")
        self.settings = settings
        self.period = settings.period
        self.n_axles = 0
        self._state = None
        self._record = None

    def configure(self, vehicle=None, cylinders=None) -> WheelSlideProtection:
        """Take the settings left at None from the vehicle (wheel radius, nominal brake
        rate) and the brake cylinders (valve arrangement); returns self."""
        s = self.settings
        changes = {}
        if vehicle is not None:
            if s.wheel_radius is None:
                changes["wheel_radius"] = float(vehicle.wheel_radius)
            if s.deceleration_per_pressure is None:
                changes["deceleration_per_pressure"] = float(
                    vehicle.n_axles * vehicle.brake_coefficient
                    / (vehicle.wheel_radius * vehicle.effective_mass))
        if cylinders is not None and s.valves is None:
            changes["valves"] = cylinders.valves
        if changes:
            self.settings = s.replace(**changes)
        self._record = None
        return self

    def settings_record(self, wheel_radius: float | None = None) -> np.ndarray:
        """The settings as a one-element structured array (for :func:`wsp_update`).

        The wheel radius comes from the settings, :meth:`configure`, :meth:`reset` or
        ``wheel_radius``; a missing brake rate means the reference deceleration limit is
        fixed at ``reference_deceleration`` (the pressure-adaptive limit needs the vehicle).
        """
        s = self.settings
        radius = s.wheel_radius if s.wheel_radius is not None else (
            wheel_radius if wheel_radius is not None else getattr(self, "radius", None))
        if radius is None:
            raise ValueError("the WSP needs the nominal wheel radius: give wheel_radius, or "
                             "call configure(vehicle) or reset(n_axles, wheel_radius) first")
        _number("wheel_radius", float(radius))
        rec = np.zeros(1, SETTINGS_DTYPE)
        r = rec[0]
        for name in SETTINGS_DTYPE.names:
            if name in ("per_bogie",):
                continue
            value = getattr(s, name)
            r[name] = 0.0 if value is None else value
        r["wheel_radius"] = radius
        r["per_bogie"] = s.valves == "bogie"
        return rec

    def state_record(self, n_axles: int) -> np.ndarray:
        """A fresh state (one-element structured array) for ``n_axles`` axles."""
        if isinstance(n_axles, bool) or not isinstance(n_axles, int | np.integer) or not (
                1 <= n_axles <= MAX_AXLES):
            raise ValueError(f"n_axles must be an integer in [1, {MAX_AXLES}], got {n_axles!r}")
        rec = np.zeros(1, STATE_DTYPE)
        rec[0]["n_axles"] = n_axles
        if self.settings.valves == "bogie":
            if n_axles % 2:
                raise ValueError(f"per-bogie valves need an even number of axles, got {n_axles}")
            rec[0]["n_groups"] = 2
        else:
            rec[0]["n_groups"] = n_axles
        rec[0]["probe"] = -1
        return rec

    def reset(self, n_axles: int, wheel_radius: float) -> None:
        """Start a run (Python calls): a fresh state for ``n_axles`` axles."""
        self.n_axles = int(n_axles)
        self.radius = float(wheel_radius)
        self._record = self.settings_record(self.radius)
        self._state = self.state_record(self.n_axles)
        self._out = np.zeros(self.n_axles, dtype=np.int64)

    def __call__(self, time, wheel_speeds, pressure_command, brake_pressures=None,
                 external_speed=math.nan):
        """Valve states for this control period (a new array per call)."""
        if self._state is None:
            raise ValueError("call reset(n_axles, wheel_radius) before the first call")
        n = self.n_axles
        w = np.ascontiguousarray(wheel_speeds, dtype=float)
        if w.shape != (n,):
            raise ValueError(f"wheel_speeds must have {n} entries, got shape {w.shape}")
        cmd = np.ascontiguousarray(np.broadcast_to(np.asarray(pressure_command, float), (n,)))
        p = (np.full(n, math.nan) if brake_pressures is None
             else np.ascontiguousarray(brake_pressures, dtype=float))
        wsp_update(self._record, self._state, float(time), w, p, cmd,
                   float(external_speed) if external_speed is not None else math.nan,
                   self._out)
        return self._out.copy()

    @property
    def reference_speed(self) -> float:
        """The current reference speed [m/s] (NaN before the first call)."""
        return math.nan if self._state is None or self._state[0]["started"] == 0 else float(
            self._state[0]["v_ref"])

    @property
    def vent_actions(self) -> int:
        return 0 if self._state is None else int(self._state[0]["vent_commands"])

    def diagnostics(self) -> dict:
        """Counters of the run so far: speed fixes, probes, watchdog trips, cut-out groups,
        the phase of each valve group and the reference speed and deceleration."""
        if self._state is None:
            return {}
        return state_diagnostics(self._state)


def state_diagnostics(state) -> dict:
    """Readable summary of a WSP state record (see :meth:`WheelSlideProtection.diagnostics`)."""
    r = state[0]
    ng = int(r["n_groups"])
    return {"reference_speed_m_s": float(r["v_ref"]),
            "reference_deceleration_m_s2": float(r["d_ref"]),
            "speed_fixes": int(r["fixes"]), "probes": int(r["probes"]),
            "watchdog_trips": int(r["watchdog_trips"]),
            "vent_commands": int(r["vent_commands"]),
            "cut_out_groups": [g + 1 for g in range(ng) if r["cutout"][g]],
            "phases": [PHASES[int(r["phase"][g])] for g in range(ng)]}


def accepts_measurements(fn) -> bool:
    """True if the controller ``fn`` takes ``brake_pressures`` and ``external_speed`` keyword
    arguments (or ``**kwargs``)."""
    return _accepts(fn, ("brake_pressures", "external_speed"))


def _accepts(fn, names) -> bool:
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False
    if any(p.kind == p.VAR_KEYWORD for p in params.values()):
        return True
    return all(n in params for n in names)


def as_controller(controller, period: float | None):
    """Wrap a plain callable into an object with ``period`` and ``reset``; return objects that
    have both unchanged."""
    if controller is None:
        return None
    if hasattr(controller, "reset") and hasattr(controller, "period"):
        return controller

    class _Wrapped:
        def __init__(self, fn, p):
            if p is None or not p > 0:
                raise ValueError("a plain controller function needs control_period > 0 [s]")
            self.fn, self.period = fn, float(p)
            self.extra = _accepts(fn, ("brake_pressures", "external_speed"))

        def reset(self, n_axles, wheel_radius):
            pass

        def __call__(self, time, wheel_speeds, pressure_command, brake_pressures=None,
                     external_speed=math.nan):
            if self.extra:
                return self.fn(time, wheel_speeds, pressure_command,
                               brake_pressures=brake_pressures, external_speed=external_speed)
            return self.fn(time, wheel_speeds, pressure_command)

    return _Wrapped(controller, period)


def call_controller(controller, time, wheel_speeds, pressure_command, brake_pressures,
                    external_speed):
    """Call a controller with the measured pressures and external speed if it accepts them."""
    if isinstance(controller, WheelSlideProtection) or _accepts(
            controller.__call__, ("brake_pressures", "external_speed")):
        return controller(time, wheel_speeds, pressure_command, brake_pressures=brake_pressures,
                          external_speed=external_speed)
    return controller(time, wheel_speeds, pressure_command)
