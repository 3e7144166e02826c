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
  and falls at most at a deceleration limit. The limit is the train's deceleration that the
  measured cylinder pressures and wheel accelerations give (seed 002 eq. 3 with the vehicle's
  nominal brake rate ``deceleration_per_pressure``, eq. 8, and ``wheel_inertia_pressure``)
  with a tolerance (``brake_rate_tolerance``) and an allowance for gradient and resistance
  (``reference_deceleration_offset``), less what the speed fixes found it in excess of the
  train's (learnt, ``drift_gain``), capped at ``reference_deceleration``. Speed *fixes*
  correct it: a released wheel that has stopped re-accelerating rolls at the train speed; the
  reference takes its speed (downwards only if its brake pressure is below
  ``free_pressure``). When every valve group is in slide control and no fix came for a
  while (``probe_interval``, doubled up to ``probe_interval_max`` while the probes find the
  reference within ``probe_accuracy`` of the re-apply slip), one group (in turn) is released
  on purpose (**probe**), deeper until its wheels re-accelerate. An external speed (radar,
  GNSS) keeps the reference within ``external_tolerance`` of it.
* **Per valve group** (an axle, or a bogie with ``valves="bogie"``): slip ``v_ref − ωR``
  and wheel deceleration *relative to the reference's* decide APPLY → HOLD → VENT; VENT →
  HOLD when the wheel re-accelerates (or nothing is left to vent); then speed fix and
  **re-application**: fast up to ``reapply_fast_fraction`` of the pressure at which the slide
  began, then pressure steps that regulate the slip (looking ``reapply_lookahead`` ahead) in
  the group's **band**. The band is the settings' slip thresholds times a scale that adapts
  (perturb and observe): the group's adhesion, measured in quasi-steady regulation as the
  pressure the wheel holds corrected for its acceleration (seed 002 eqs. 2, 5), is compared
  before and after each move of the band; the band rises (up to ``band_scale_max``) while
  the adhesion does not fall, and falls (down to ``band_scale_min``) while that raises it.
* **Watchdog** (EN 15595 §5.1.4 "safety timer"): a group may not stay released (HOLD or VENT)
  for more than ``watchdog_time`` *without its wheels re-accelerating*; it is then forced to
  APPLY for ``watchdog_refill_time``. A wheel that is recovering (re-accelerating) is never
  re-applied by the watchdog: that is what re-locked unrecovered wheels before. Regulation
  steps at or above ``reapply_fast_fraction`` of the slide pressure are not a release. After
  ``watchdog_cutout_trips`` trips with no recovery in between the group's WSP is cut out
  (brake applied) until the brake command returns to 0: a fault reaction.
"""

from __future__ import annotations

import functools
import inspect
import math
import warnings
from dataclasses import dataclass, fields
from typing import TypeVar

import numpy as np
from numba import njit

from railadhesion.braking.cylinders import APPLY, HOLD, VENT
from railadhesion.io.settings_table import (
    read_settings_table,
    settings_ranges,
    settings_sources,
)
from railadhesion.plausibility import check_plausible

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

# each setting's allowed range, unit and source (or the word assumption), in the order of the
# fields of WSPSettings, which hold the defaults: data/wsp_settings.toml
_TABLE = read_settings_table("wsp_settings")
_RANGES = settings_ranges(_TABLE)

_DEPRECATED = {
    "sliding_reference_deceleration": (
        "sliding_reference_deceleration is no longer used: while every axle slides the "
        "reference falls at most at the deceleration the measured brake pressures can give "
        "(deceleration_per_pressure) and is corrected by speed fixes and probes "
        "(docs/wsp.md); the value is ignored"),
}

SETTINGS_DTYPE = np.dtype(
    [(name, "f8") for name in _TABLE if name not in ("valves", "watchdog_cutout_trips")]
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
    ("p_fast", "f8", (MAX_AXLES,)),   # re-application is fast (APPLY) below this [Pa]
    ("dec0", "f8", (MAX_AXLES,)),     # relative deceleration when the onset hold began
    ("t_step", "f8", (MAX_AXLES,)),
    ("settle", "f8", (MAX_AXLES,)),
    ("turned", "i8", (MAX_AXLES,)),   # re-application step: 0 up, 1 down, 2 none
    ("p_target", "f8", (MAX_AXLES,)),
    ("wd_timer", "f8", (MAX_AXLES,)),
    ("wd_until", "f8", (MAX_AXLES,)),
    ("wd_trips", "i8", (MAX_AXLES,)),
    ("cutout", "i8", (MAX_AXLES,)),
    ("probe_gap", "f8"),           # current probe interval [s]
    ("rel_v0", "f8", (MAX_AXLES,)),   # reference when the group's release began [m/s]
    ("rel_d0", "f8", (MAX_AXLES,)),   # its deceleration then [m/s²]
    ("rel_t0", "f8", (MAX_AXLES,)),   # time the release began [s]
    ("recovered", "i8", (MAX_AXLES,)),  # the probed wheel re-accelerated
    ("excess", "f8"),              # learnt excess of the deceleration limit [m/s²]
    ("scale", "f8", (MAX_AXLES,)),    # slip band scale (1: the settings' band)
    ("a_dir", "i8", (MAX_AXLES,)),    # direction of the last band move: +1 up, -1 down
    ("a_prev", "f8", (MAX_AXLES,)),   # adhesion (pressure units) of the last dwell [Pa]
    ("a_sum", "f8", (MAX_AXLES,)),    # its integral over the current dwell [Pa s]
    ("a_time", "f8", (MAX_AXLES,)),   # regulation time of the current dwell [s]
    ("a_block", "f8", (MAX_AXLES,)),  # time left without raises [s]
], align=True)


@njit(cache=True)
def _enter(s, st, g, phase, p_slide):
    st.phase[g] = phase
    st.turned[g] = 2
    st.t_phase[g] = 0.0
    st.t_step[g] = 1e9  # the first step is decided at once
    if not math.isnan(p_slide):
        st.p_slide[g] = p_slide
        st.p_fast[g] = s.reapply_fast_fraction * p_slide


@njit(cache=True)
def _released(st, g, t):
    """A release (a slide's vent or a probe) of group g begins: remember the reference."""
    st.rel_v0[g] = st.v_ref
    st.rel_d0[g] = st.d_ref
    st.rel_t0[g] = t


@njit(cache=True)
def _reference_error(st, g, u, t):
    """The reference's error [m/s] found by group g's wheel speed ``u`` after its release:
    against where the reference would be had it gone on as before the release (meanwhile
    it followed the recovering wheel up)."""
    return u - (st.rel_v0[g] - st.rel_d0[g] * (t - st.rel_t0[g]))


@njit(cache=True)
def _learn(s, st, jump, t):
    """A speed fix found the reference ``jump`` [m/s] below the train (negative: above it):
    it fell faster than the train by jump / (time since the last fix) on average. That part
    (drift_gain) is taken off the deceleration limit from now on (``excess``)."""
    if s.deceleration_per_pressure > 0.0:
        st.excess = min(max(st.excess + s.drift_gain * jump
                            / max(t - st.t_fix, s.probe_interval), 0.0),
                        s.reference_deceleration)


@njit(cache=True)
def _forget(st, g):
    """The band adaptation of group g starts a new comparison (its regulation was
    interrupted: a slide, a probe, a speed fix, the end of the regulation)."""
    st.a_prev[g] = math.nan
    st.a_sum[g] = 0.0
    st.a_time[g] = 0.0


@njit(cache=True)
def _slide_at_raised_band(s, st, g):
    """A new slide: a raised band steps back down and stays there for adapt_block_time."""
    if st.scale[g] > 1.0:
        st.scale[g] = max(1.0, st.scale[g] / s.band_scale_step)
        st.a_block[g] = s.adapt_block_time
    _forget(st, g)


@njit(cache=True)
def _adapt_band(s, st, g, held):
    """End of a dwell: move the band of group g (perturb and observe).

    ``held`` is the mean adhesion torque of the group's wheels over the dwell in pressure
    units, R T / c = p + (J / (c R)) du/dt (seed 002 eqs. 2 and 5: the brake torque less
    what decelerates the wheel): it measures the adhesion at the band's slip. The band keeps
    moving in its direction while that pays (upwards: while the adhesion does not fall by
    more than adapt_tolerance; downwards: while it rises by more than twice that) and turns
    back when it does not.
    """
    eps = s.adapt_tolerance
    move = 0
    prev = st.a_prev[g]
    if prev == prev and prev > 0.0:
        gain = held / prev - 1.0
        if st.a_dir[g] > 0:
            if gain < -eps:  # the raise cost adhesion: back, and no raise for a while
                st.a_dir[g] = -1
                st.a_block[g] = s.adapt_block_time
                move = -1
            else:
                move = 1
        elif gain > 2.0 * eps:  # lowering clearly helped: go on
            move = -1
        else:
            st.a_dir[g] = 1
            move = 1
    # (the first dwell after an interruption only measures: no move without a comparison)
    if move > 0 and st.a_block[g] > 0.0:
        move = 0
    if move > 0:
        st.scale[g] = min(st.scale[g] * s.band_scale_step, s.band_scale_max)
    elif move < 0:
        if st.scale[g] <= s.band_scale_min:
            st.a_dir[g] = 1  # at the lowest band: the next move is a raise
        st.scale[g] = max(st.scale[g] / s.band_scale_step, s.band_scale_min)
    st.a_prev[g] = held
    st.a_sum[g] = 0.0
    st.a_time[g] = 0.0


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
    asum = 0.0
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
        asum += st.acc[i]
    if first:
        st.started = 1
        st.v_ref = umax
        st.d_ref = 0.0
        st.t_fix = t
        st.probe = -1
        st.probe_gap = s.probe_interval
        for g in range(ng):
            _enter(s, st, g, NORMAL, 0.0)
            st.valve[g] = APPLY
            st.wd_until[g] = -math.inf
            st.scale[g] = 1.0
            st.a_dir[g] = 1
            st.a_block[g] = 0.0
            _forget(st, g)
    # 2. reference speed
    limit = s.reference_deceleration
    if s.deceleration_per_pressure > 0.0 and psum == psum:
        # the train's deceleration that the measured pressures and wheel accelerations
        # give (seed 002 eq. 3: M d = Σ (c p_i + J dω_i/dt) / R); with the wheels
        # following the train it is the nominal brake rate k p̄ (eq. 8), with wheels
        # sliding deeper their inertia takes part of the brake torque:
        # d = (k p̄ + j ā) / (1 − j), j = n J / (R² M_eff) = k · J / (c R), ā the mean
        # wheel acceleration
        k = s.deceleration_per_pressure
        j = min(k * s.wheel_inertia_pressure, 0.5)
        d_hat = (k * psum / n + j * asum / n) / (1.0 - j)
        brake = (1.0 + s.brake_rate_tolerance) * d_hat + s.reference_deceleration_offset
        # less what the speed fixes found it exceeds the train's deceleration by, never
        # below that deceleration (with a margin)
        brake = max(brake - st.excess, (1.0 + s.drift_margin) * d_hat)
        limit = min(limit, max(brake, 0.0))
    v_new = max(umax, st.v_ref - limit * T)
    if external_speed == external_speed:
        v_ext = external_speed - st.d_ref * s.external_latency
        v_new = min(max(v_new, v_ext - s.external_tolerance), v_ext + s.external_tolerance)
    a_d = T / (0.2 + T)
    slope = (st.v_ref - v_new) / T
    st.d_ref += a_d * (min(max(slope, 0.0), s.reference_deceleration) - st.d_ref)
    st.v_ref = max(v_new, 0.0)
    v_ref = st.v_ref
    # the settings' re-apply slip: a wheel this close to the reference rolls with it (fixes)
    reapply = max(s.reapply_slip_ratio * v_ref, s.reapply_slip_min)
    # 3. valve groups
    normal_groups = 0
    fixing = 0
    v_before = v_ref
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
        # the group's band: the settings' thresholds times its adapted scale
        # (the minimum slips are not scaled: near standstill a raised minimum would let
        # a locked wheel stay below the vent threshold)
        f = st.scale[g]
        if v_ref < s.band_min_speed:  # back to the settings' band towards standstill
            f = 1.0 + (f - 1.0) * v_ref / s.band_min_speed
        hold_g = max(f * s.hold_slip_ratio * v_ref, s.hold_slip_min)
        reapply_g = max(f * s.reapply_slip_ratio * v_ref, s.reapply_slip_min)
        vent_g = max(f * s.vent_slip_ratio * v_ref, s.vent_slip_min)
        want_vent = slip > vent_g or dec > s.vent_deceleration
        want_hold = slip > hold_g or dec > s.hold_deceleration
        if st.a_block[g] > 0.0:
            st.a_block[g] -= T
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
                _enter(s, st, g, NORMAL, 0.0)
            _forget(st, g)
            st.cutout[g] = 0
            st.wd_trips[g] = 0
        elif st.cutout[g] != 0:
            phase = CUTOUT
        elif phase == NORMAL:
            if want_vent:
                _slide_at_raised_band(s, st, g)
                _released(st, g, t)
                _enter(s, st, g, VENTING, p)
            elif want_hold:
                _enter(s, st, g, ONSET, p)
                st.dec0[g] = dec
        elif phase == ONSET:
            # held: a wheel on a falling curve keeps falling behind faster (a runaway),
            # one on a rising curve converges to a new slip
            if want_vent or (st.t_phase[g] > s.onset_hold_time and (
                    dec > s.hold_deceleration
                    or slip + s.reapply_lookahead * dec > vent_g
                    or (dec > s.reapply_deceleration and dec >= st.dec0[g]))):
                _slide_at_raised_band(s, st, g)
                _released(st, g, t)
                _enter(s, st, g, VENTING, math.nan)
            elif st.t_phase[g] > s.onset_hold_time:
                # held, the wheel converges below the vent threshold: release steps
                _enter(s, st, g, REAPPLY, math.nan)
            elif slip < reapply_g and dec < 0.5 * s.hold_deceleration:
                _enter(s, st, g, REAPPLY, math.nan)
        elif phase == VENTING:
            if reacc > s.recovery_acceleration or p < 0.5 * s.free_pressure:
                _enter(s, st, g, RECOVER, math.nan)
        elif phase == RECOVER:
            if st.settle[g] >= s.settle_time:
                if slip < reapply or free:
                    fixing = 1
                    jump = _reference_error(st, g, u_g, t)
                    if free or jump > 0.0:  # (a wheel with its brake on may still slip)
                        _learn(s, st, jump, t)
                    st.v_ref = u_g if free else max(st.v_ref, u_g)
                    st.t_fix = t
                    st.fixes += 1
                    st.wd_trips[g] = 0
                    _enter(s, st, g, REAPPLY, math.nan)
                elif want_hold:
                    _enter(s, st, g, VENTING, math.nan)
                else:
                    _enter(s, st, g, REAPPLY, math.nan)
            elif slip < reapply_g and st.t_phase[g] >= s.settle_time:
                # nearly back: re-apply at once; if the wheel is back near the reference,
                # it found the reference's error on its way (it pulled the reference up)
                if slip < reapply:
                    jump = _reference_error(st, g, u_g, t)
                    if jump > 0.0:
                        _learn(s, st, jump, t)
                        st.t_fix = t
                _enter(s, st, g, REAPPLY, math.nan)
            elif want_vent and reacc < s.recovery_acceleration and st.t_phase[g] > s.settle_time:
                _enter(s, st, g, VENTING, math.nan)
        elif phase == REAPPLY:
            if want_vent:
                _slide_at_raised_band(s, st, g)
                _released(st, g, t)
                _enter(s, st, g, VENTING, p)
            elif slip > reapply_g and (dec > s.hold_deceleration or (
                    slip > hold_g and dec > s.reapply_deceleration)):
                # a slide: a wheel above its band that still falls behind, or one
                # decelerating fast (below its band a decelerating wheel is returning to
                # it; above it a steady wheel is brought back by release steps)
                _enter(s, st, g, ONSET, p)
                st.dec0[g] = dec
            elif p >= cmd - 5e3 or st.t_phase[g] > s.reapply_max_time:
                _forget(st, g)
                _enter(s, st, g, NORMAL, math.nan)
        elif phase == PROBE:
            if reacc > s.recovery_acceleration:
                st.recovered[g] = 1
            settled = st.settle[g] >= s.settle_time and (free or p <= st.p_target[g] or p != p)
            if settled and not (free or st.recovered[g] or (p != p and slip < reapply)):
                # settled without a recovery: the wheel rolled already, or the released
                # brake still holds it in a deep slide (on a falling curve a slide can
                # need much less torque than the band): vent deeper, until it recovers
                # or its brake is off
                st.p_target[g] = s.probe_pressure_fraction * min(st.p_target[g], p)
                st.settle[g] = 0.0
            elif settled:
                # the released wheel rolls near the train speed, a little below it (its
                # creep at the probe pressure): it may raise the reference, lower it only
                # when its brake is off (the same rule as a recovery's fix)
                fixing = 1
                # the reference's error: the wheel's speed against where the reference
                # would be had it gone on as before the probe (meanwhile it followed the
                # recovering wheel up)
                jump = _reference_error(st, g, u_g, t)
                st.v_ref = u_g if free else max(st.v_ref, u_g)
                # the probe interval adapts to the error the probe found: doubled while
                # it is within probe_accuracy of the settings' re-apply slip
                if abs(jump) <= s.probe_accuracy * reapply:
                    st.probe_gap = min(2.0 * st.probe_gap, s.probe_interval_max)
                else:
                    st.probe_gap = max(0.5 * st.probe_gap, s.probe_interval)
                _learn(s, st, jump, t)
                st.t_fix = t
                st.fixes += 1
                st.probe = -1
                _enter(s, st, g, REAPPLY, math.nan)
                # the wheel held the pressure before the probe at its band: back fast
                st.p_fast[g] = s.probe_refill_fraction * st.p_slide[g]
            elif st.t_phase[g] > s.probe_max_time:
                st.probe = -1
                _enter(s, st, g, REAPPLY, math.nan)
        phase = st.phase[g] if st.cutout[g] == 0 or cmd <= 0.0 else CUTOUT
        # valve of the phase
        regulating = False
        if phase == NORMAL or phase == CUTOUT:
            valve = APPLY
        elif phase == ONSET or phase == RECOVER:
            valve = HOLD
        elif phase == VENTING:
            valve = VENT
        elif phase == REAPPLY:
            valve = HOLD
            # stepping at or above the fast part: the brake is regulated, not released
            regulating = p >= s.reapply_fast_fraction * st.p_slide[g]
            if p < st.p_fast[g]:
                valve = APPLY  # fast part; the first step pulse follows at once
                st.t_step[g] = 0.0
            else:
                st.p_fast[g] = 0.0  # the fast part is over (no return to it on noise)
                # steps of the memorised slide pressure: up while the wheel follows the
                # reference, down when it falls behind (an incipient slide), else hold;
                # timed pulses when the pressure is not measured
                if st.t_step[g] >= s.reapply_step - 1e-12:
                    st.t_step[g] = 0.0
                    step = s.reapply_step_fraction * st.p_slide[g]
                    middle = 0.5 * (reapply_g + hold_g)
                    # the slip a lookahead ahead: beyond the saturation of the curve the
                    # slip integrates the excess brake torque, so its rate decides too
                    ahead = slip + s.reapply_lookahead * dec
                    quarter = 0.25 * (hold_g - reapply_g)
                    if slip > reapply_g and (dec > 2.0 * s.reapply_deceleration or (
                            ahead > middle + quarter) or (
                            ahead > middle and dec > 0.5 * s.reapply_deceleration)):
                        st.turned[g] = 1  # a release step
                        st.p_target[g] = p - step
                        st.t_phase[g] = 0.0  # regulating: reapply_max_time restarts
                    elif ahead < middle - quarter and dec < 2.0 * s.reapply_deceleration:
                        st.turned[g] = 0  # an apply step
                        st.p_target[g] = p + step
                    else:
                        st.turned[g] = 2
                        st.t_phase[g] = 0.0
                # a step ends when its pressure is reached (latched: a noisy reading
                # does not reopen it)
                if st.turned[g] == 0:
                    if (p < st.p_target[g]) if p == p else (
                            st.t_step[g] < s.reapply_pulse - 1e-12):
                        valve = APPLY
                    else:
                        st.turned[g] = 2
                elif st.turned[g] == 1:
                    if (p > st.p_target[g]) if p == p else (
                            st.t_step[g] < s.release_pulse - 1e-12):
                        valve = VENT
                    else:
                        st.turned[g] = 2
                # band adaptation: the adhesion torque while the wheel runs in its band,
                # in pressure units, R T / c = p + (J / (c R)) du/dt (seed 002 eqs. 2, 5)
                if (s.band_scale_max > s.band_scale_min and p == p
                        and reapply_g <= slip <= hold_g
                        and abs(dec) < s.hold_deceleration):
                    held = 0.0
                    for i in range(g * per, g * per + per):
                        held += pressure_meas[i] + s.wheel_inertia_pressure * st.acc[i]
                    st.a_sum[g] += held / per * T
                    st.a_time[g] += T
                    if st.a_time[g] >= s.adapt_time - 1e-12:
                        _adapt_band(s, st, g, st.a_sum[g] / st.a_time[g])
        else:  # PROBE: vent to a fraction of the pressure (deeper while the wheel slides)
            if dec > s.reapply_deceleration and st.t_phase[g] > s.settle_time:
                st.p_target[g] = min(st.p_target[g], s.probe_pressure_fraction * p)
            valve = VENT if (p > st.p_target[g] or p != p) and not free else HOLD
        # 4. watchdog (safety timer)
        if t < st.wd_until[g]:
            valve = APPLY
        elif valve != APPLY and not accelerating and not regulating:
            st.wd_timer[g] += T
            if st.wd_timer[g] >= s.watchdog_time - 1e-9:
                valve = APPLY
                st.wd_timer[g] = 0.0
                st.wd_until[g] = t + s.watchdog_refill_time
                st.wd_trips[g] += 1
                st.watchdog_trips += 1
                if st.probe == g:
                    st.probe = -1
                _slide_at_raised_band(s, st, g)
                _enter(s, st, g, REAPPLY, math.nan)
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
    # a speed fix that moved the reference moved every group's slip: new comparisons
    if fixing and abs(st.v_ref - v_before) > s.probe_accuracy * reapply:
        for g in range(ng):
            _forget(st, g)
    # 5. probe: every group in slide control and no speed fix for a while
    if (fixing == 0 and st.probe < 0 and normal_groups == 0 and ng > 1
            and t - st.t_fix > st.probe_gap and st.v_ref > s.probe_min_speed):
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
                    st.recovered[g] = 0
                    _released(st, g, t)
                    _forget(st, g)
                    p = -math.inf
                    for i in range(g * per, g * per + per):
                        p = max(p, pressure_meas[i])
                    _enter(s, st, g, PROBE, p)
                    st.p_target[g] = s.probe_pressure_fraction * p
                    break


_SUFFIX = {"s": "_s", "m/s²": "_m_s2", "m/s": "_m_s", "Pa": "_Pa", "m": "_m", "-": "",
           "m/s² per Pa": "_m_s2_per_Pa", "Pa per m/s²": "_Pa_s2_per_m"}


def settings_file_keys() -> dict:
    """The WSP settings as keys of a TOML table (name with its unit: ``period_s``,
    ``hold_slip_min_m_s``, ...): ``{key: (field, low, high)}``. The wheel radius and the valve
    arrangement come from the vehicle and the brake cylinders, not from the table; the
    deprecated ``sliding_reference_deceleration_m_s2`` maps to its (ignored) field."""
    keys = {}
    for name, limits in _RANGES.items():
        if name == "wheel_radius":  # (valves has no range)
            continue
        keys[name + _SUFFIX[limits.unit]] = (name, limits.low, limits.high)
    keys["sliding_reference_deceleration_m_s2"] = ("sliding_reference_deceleration", 0.0, 10.0)
    return keys


_Settings = TypeVar("_Settings")


def _named_keywords(cls: type[_Settings]) -> type[_Settings]:
    """WSPSettings' ``__init__``: the dataclass's, after the deprecated names are dropped (with
    a ``DeprecationWarning``) and an unknown name is refused with the known ones listed."""
    init = cls.__init__
    names = [f.name for f in fields(cls)]

    @functools.wraps(init)
    def __init__(self, **kwargs):
        for name, message in _DEPRECATED.items():
            if name in kwargs:
                kwargs.pop(name)
                warnings.warn(message, DeprecationWarning, stacklevel=3)
        unknown = set(kwargs) - set(names)
        if unknown:
            raise ValueError(f"unknown WSP setting(s) {sorted(unknown)}; known: "
                             f"{', '.join(names)}")
        init(self, **kwargs)

    cls.__init__ = __init__
    return cls


@_named_keywords
@dataclass(frozen=True, kw_only=True)
class WSPSettings:
    """Settings of :class:`WheelSlideProtection` (SI units), by keyword. Every default with its
    source or the word assumption: :func:`WSPSettings.sources` and ``docs/wsp.md`` (the
    defaults are the fields below; ranges, units and sources: ``data/wsp_settings.toml``).

    ``wheel_radius``, ``deceleration_per_pressure``, ``wheel_inertia_pressure`` and ``valves``
    default to None: taken from
    the vehicle and brake cylinders (:meth:`WheelSlideProtection.configure`, done by
    :func:`~railadhesion.braking.simulate` and the WSP bench). ``sliding_reference_deceleration``
    of earlier versions is accepted with a ``DeprecationWarning`` and ignored.
    """

    period: float = 0.005
    reference_deceleration: float = 2.5
    deceleration_per_pressure: float | None = None
    wheel_inertia_pressure: float | None = None
    brake_rate_tolerance: float = 0.25
    reference_deceleration_offset: float = 0.15
    hold_slip_ratio: float = 0.05
    hold_slip_min: float = 0.15
    vent_slip_ratio: float = 0.1
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
    free_pressure: float = 20000.0
    onset_hold_time: float = 0.2
    reapply_deceleration: float = 0.6
    reapply_fast_fraction: float = 0.7
    reapply_step_fraction: float = 0.05
    reapply_pulse: float = 0.005
    release_pulse: float = 0.01
    reapply_lookahead: float = 0.5
    reapply_step: float = 0.1
    reapply_max_time: float = 3.0
    probe_interval: float = 2.0
    probe_max_time: float = 2.0
    probe_pressure_fraction: float = 0.7
    probe_min_speed: float = 1.0
    probe_refill_fraction: float = 0.9
    probe_interval_max: float = 8.0
    probe_accuracy: float = 1.0
    drift_gain: float = 0.5
    drift_margin: float = 0.05
    band_scale_max: float = 3.0
    band_scale_min: float = 0.5
    band_min_speed: float = 5.0
    band_scale_step: float = 1.5
    adapt_time: float = 1.0
    adapt_tolerance: float = 0.02
    adapt_block_time: float = 4.0
    watchdog_time: float = 3.0
    watchdog_refill_time: float = 0.5
    watchdog_cutout_trips: int = 3
    external_latency: float = 0.0
    external_tolerance: float = 0.5
    wheel_radius: float | None = None
    valves: str | None = None

    def __post_init__(self):
        for field in fields(self):
            name, value = field.name, getattr(self, field.name)
            if name == "valves":
                if value not in (None, "axle", "bogie"):
                    raise ValueError(f"valves must be None, 'axle' or 'bogie', got {value!r}")
            elif name == "watchdog_cutout_trips":
                if isinstance(value, bool) or not isinstance(value, int) or not (
                        1 <= value <= 1000):
                    raise ValueError(f"watchdog_cutout_trips must be an integer in [1, 1000], "
                                     f"got {value!r}")
            elif value is not None or field.default is not None:
                _RANGES[name].check(name, value)
        if not self.reapply_slip_ratio <= self.hold_slip_ratio <= self.vent_slip_ratio:
            raise ValueError("slip ratios must satisfy reapply_slip_ratio <= hold_slip_ratio "
                             "<= vent_slip_ratio, got "
                             f"{self.reapply_slip_ratio}, {self.hold_slip_ratio}, "
                             f"{self.vent_slip_ratio}")
        if not self.hold_deceleration <= self.vent_deceleration:
            raise ValueError("hold_deceleration must not exceed vent_deceleration, got "
                             f"{self.hold_deceleration} > {self.vent_deceleration}")
        if not self.probe_interval <= self.probe_interval_max:
            raise ValueError("probe_interval must not exceed probe_interval_max, got "
                             f"{self.probe_interval} > {self.probe_interval_max}")
        if self.free_pressure > 0.0:  # 0.2 given in bar would pass the range check as Pa
            check_plausible(self.free_pressure, "free_pressure", quantity="brake_pressure",
                            what="WSP free pressure")

    def as_dict(self) -> dict:
        """The settings by name, in the order of the fields."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @staticmethod
    def sources() -> dict:
        """Each setting: ``(default, unit, source or 'assumption')``."""
        return settings_sources(WSPSettings, _TABLE)

    def replace(self, **changes) -> WSPSettings:
        return WSPSettings(**{**self.as_dict(), **changes})


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
            if s.wheel_inertia_pressure is None:
                changes["wheel_inertia_pressure"] = float(
                    vehicle.wheelset_inertia
                    / (vehicle.brake_coefficient * vehicle.wheel_radius))
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
        _RANGES["wheel_radius"].check("wheel_radius", float(radius))
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
        the phase and slip-band scale of each valve group, the reference speed and
        deceleration, the probe interval and the reference drift learnt from the fixes."""
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
            "phases": [PHASES[int(r["phase"][g])] for g in range(ng)],
            "band_scales": [float(r["scale"][g]) for g in range(ng)],
            "probe_interval_s": float(r["probe_gap"]),
            "learnt_drift_m_s2": float(r["excess"])}


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
