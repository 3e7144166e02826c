"""Wheel slide protection (WSP): the default controller and the controller interface.

Controller interface (how a user's, or a HIL rig's, controller attaches)
---------------------------------------------------------------------
A controller is any object with

``period`` : float
    Its control period [s] (the simulator calls it every ``period``; must be a whole
    multiple of the simulation step).
``reset(n_axles, wheel_radius)``
    Called once before a run.
``__call__(time, wheel_speeds, pressure_command) -> valves``
    ``time`` [s], ``wheel_speeds`` the measured wheelset angular speeds [rad/s] (ndarray,
    axle 1 = leading), ``pressure_command`` the driver's/brake system's commanded cylinder
    pressure [Pa]. Returns the valve state of each axle (or of each bogie with
    ``valves="bogie"``): 0 = apply, 1 = hold, 2 = vent.

A plain function with the ``__call__`` signature works too (the period is then given to
:func:`~railadhesion.braking.simulate`). The controller sees wheel speeds only: the true train
speed is never passed to it. A HIL rig attaches its real WSP unit by a controller object whose
``__call__`` writes the wheel speeds to the rig's speed outputs and reads back the unit's
valve signals, or by driving :meth:`BrakingSimulator.step` itself with the valve states.

Default controller
------------------
:class:`WheelSlideProtection` is a generic per-axle logic of the usual kind (not a
particular supplier's): a reference speed from the wheel speeds only, slip and wheel
deceleration thresholds, the three valve states and a watchdog.

* Reference speed: ``v_ref = max(max_i ω_i R, v_ref_prev − a_ref · period)``: the fastest
  wheel, but not falling faster than the plausible train deceleration ``a_ref`` (default
  2.5 m/s²; it must exceed the deceleration the brakes can give on a good rail, else the
  reference lags the train and fakes slip; too large and a slide of all axles at once is seen
  late). While every wheel is below the reference by more than the hold threshold (all
  axles sliding), the reference falls at ``sliding_reference_deceleration`` instead (default
  1 m/s², about what a train achieves on a low-adhesion rail), so that a slide of all axles
  at once does not drag the reference down with it.
* Per axle: slip speed ``s_i = v_ref − ω_i R``; wheel deceleration ``a_i`` from the
  difference of successive wheel speeds, low-pass filtered (time constant
  ``deceleration_filter``).
* APPLY → HOLD when ``s_i > hold_slip`` or ``a_i > hold_deceleration``; → VENT when
  ``s_i > vent_slip`` or ``a_i > vent_deceleration``. Slip thresholds are
  ``max(ratio · v_ref, minimum)`` [m/s].
* VENT → HOLD when the wheel re-accelerates (``−a_i > recovery_acceleration``); HOLD →
  APPLY once the wheel has stopped re-accelerating (it has rejoined the train) and its slip
  is below ``reapply_slip``; HOLD → VENT on the vent conditions if the wheel is not
  re-accelerating. Waiting for the end of the re-acceleration is what lets a wheel that slid
  together with all the others find the train speed again (and lift the reference).
* Watchdog: a valve group may not stay out of APPLY (hold or vent) longer than
  ``watchdog_time``; it is then forced to APPLY (refilled) for ``watchdog_refill_time``.

Compiled form (what the braking step runs)
------------------------------------------
The logic is written once, :func:`wsp_update`, a numba function on two one-element record
arrays, the controller's settings (:meth:`WheelSlideProtection.settings_record`) and state
(:meth:`WheelSlideProtection.state_record`)::

    wsp_update(settings, state, t, omega_meas, pressure_meas, command, external_speed,
               valves_out)

``omega_meas`` [rad/s] and ``pressure_meas`` [Pa] are the measured wheelset speeds and
cylinder pressures (from :func:`railadhesion.braking.sensors.measure`), ``command`` the
commanded pressure per axle [Pa], ``external_speed`` a measured train speed [m/s] or NaN
(none; this controller does not use it), ``valves_out`` the new valve state per axle (int64:
0 apply, 1 hold, 2 vent). It raises nothing and allocates nothing. The built-in WSP of the
braking step calls it every control period; :meth:`WheelSlideProtection.__call__` calls it
for Python loops.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from railadhesion.braking.cylinders import APPLY, HOLD, VENT
from railadhesion.braking.records import MAX_AXLES

__all__ = ["WSPSettings", "WheelSlideProtection", "as_controller", "wsp_update"]


@dataclass(frozen=True)
class WSPSettings:
    """Thresholds of :class:`WheelSlideProtection` (SI units; defaults are assumptions)."""

    period: float = 5e-3
    reference_deceleration: float = 2.5
    sliding_reference_deceleration: float = 1.0
    hold_slip_ratio: float = 0.05
    hold_slip_min: float = 0.3
    vent_slip_ratio: float = 0.10
    vent_slip_min: float = 0.6
    reapply_slip_ratio: float = 0.03
    reapply_slip_min: float = 0.2
    hold_deceleration: float = 3.0
    vent_deceleration: float = 6.0
    recovery_acceleration: float = 1.0
    deceleration_filter: float = 0.02
    watchdog_time: float = 3.0
    watchdog_refill_time: float = 0.5

    def __post_init__(self):
        for f in fields(self):
            x = getattr(self, f.name)
            if not (isinstance(x, int | float) and math.isfinite(x) and x >= 0):
                raise ValueError(f"{f.name} must be a finite number >= 0, got {x!r}")
        for name in ("period", "reference_deceleration", "sliding_reference_deceleration",
                     "watchdog_time"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be in (0, inf), got {getattr(self, name)!r}")
        if not self.reapply_slip_ratio <= self.hold_slip_ratio <= self.vent_slip_ratio:
            raise ValueError("slip ratios must satisfy reapply <= hold <= vent")


#: The controller's settings record: the thresholds of WSPSettings and the wheel radius.
SETTINGS_DTYPE = np.dtype([(f.name, "f8") for f in fields(WSPSettings)]
                          + [("wheel_radius", "f8")], align=True)
#: The controller's state record (per-axle fields: the first n_axles values are used).
STATE_DTYPE = np.dtype([
    ("started", "i8"), ("reference_speed", "f8"), ("previous_speed", "f8", (MAX_AXLES,)),
    ("deceleration", "f8", (MAX_AXLES,)), ("valve", "i8", (MAX_AXLES,)),
    ("released_since", "f8", (MAX_AXLES,)), ("forced_until", "f8", (MAX_AXLES,)),
    ("vent_actions", "i8"),
], align=True)


@njit(cache=True, error_model="numpy")
def wsp_update(settings, state, t, omega_meas, pressure_meas, command, external_speed,
               valves_out):
    """One control period of the default WSP (see the module docstring)."""
    p = settings[0]
    s = state[0]
    n = omega_meas.shape[0]
    radius = p.wheel_radius
    period = p.period
    fastest = -math.inf
    for i in range(n):
        fastest = max(fastest, omega_meas[i] * radius)
    if s.started == 0:
        for i in range(n):
            s.previous_speed[i] = omega_meas[i] * radius
        s.reference_speed = fastest
        s.started = 1
    alpha = period / (p.deceleration_filter + period)
    for i in range(n):  # wheel deceleration, low-pass filtered
        u = omega_meas[i] * radius
        raw = (s.previous_speed[i] - u) / period
        s.deceleration[i] += alpha * (raw - s.deceleration[i])
        s.previous_speed[i] = u
    ref = s.reference_speed
    rate = p.reference_deceleration
    if fastest < ref - max(p.hold_slip_ratio * ref, p.hold_slip_min):  # every axle sliding
        rate = p.sliding_reference_deceleration
    v_ref = max(fastest, ref - rate * period)
    s.reference_speed = v_ref
    hold = max(p.hold_slip_ratio * v_ref, p.hold_slip_min)
    vent = max(p.vent_slip_ratio * v_ref, p.vent_slip_min)
    reapply = max(p.reapply_slip_ratio * v_ref, p.reapply_slip_min)
    for i in range(n):
        slip = v_ref - omega_meas[i] * radius
        a = s.deceleration[i]
        old = s.valve[i]
        new = old
        want_vent = slip > vent or a > p.vent_deceleration
        want_hold = slip > hold or a > p.hold_deceleration
        accelerating = -a > p.recovery_acceleration
        if old == APPLY:
            new = VENT if want_vent else (HOLD if want_hold else APPLY)
        elif old == VENT:
            if accelerating:
                new = HOLD
        elif want_vent and not accelerating:
            new = VENT
        elif slip < reapply and not accelerating and a < p.hold_deceleration:
            new = APPLY
        # watchdog
        if t < s.forced_until[i]:
            new = APPLY
        elif new != APPLY:
            if math.isnan(s.released_since[i]):
                s.released_since[i] = t
            elif t - s.released_since[i] >= p.watchdog_time - 1e-12:
                new = APPLY
                s.forced_until[i] = t + p.watchdog_refill_time
        if new == APPLY:
            s.released_since[i] = math.nan
        if new == VENT and old != VENT:
            s.vent_actions += 1
        s.valve[i] = new
        valves_out[i] = new


class WheelSlideProtection:
    """Generic per-axle WSP controller (see the module docstring). State kept between calls.

    The logic is :func:`wsp_update`; this object holds its settings and state records
    (:meth:`settings_record`, :meth:`state_record`), built by :meth:`reset`.
    """

    def __init__(self, settings: WSPSettings | None = None, **changes):
        if settings is None:
            settings = WSPSettings(**changes)
        elif changes:
            settings = WSPSettings(**{**settings.__dict__, **changes})
        self.settings = settings
        self.period = settings.period
        self.n_axles = 0
        self.radius = math.nan

    def reset(self, n_axles: int, wheel_radius: float) -> None:
        """Start afresh for a vehicle of ``n_axles`` wheelsets of radius ``wheel_radius``."""
        if not 1 <= n_axles <= MAX_AXLES:
            raise ValueError(f"n_axles must be in [1, {MAX_AXLES}], got {n_axles!r}")
        self.n_axles = int(n_axles)
        self.radius = float(wheel_radius)
        self._settings = self.settings_record()
        self._state = self.state_record(n_axles)
        self._valves = np.zeros(n_axles, dtype=np.int64)

    def settings_record(self) -> np.ndarray:
        """The settings as a one-element record array (after :meth:`reset`: it holds the
        wheel radius)."""
        rec = np.zeros(1, SETTINGS_DTYPE)
        for f in fields(WSPSettings):
            rec[0][f.name] = getattr(self.settings, f.name)
        rec[0]["wheel_radius"] = self.radius
        return rec

    def state_record(self, n_axles: int) -> np.ndarray:
        """A fresh state as a one-element record array (all valves APPLY)."""
        rec = np.zeros(1, STATE_DTYPE)
        rec[0]["released_since"] = np.nan
        rec[0]["forced_until"] = -np.inf
        return rec

    @property
    def reference_speed(self):
        """The reference speed [m/s] (None before the first call)."""
        s = self._state[0]
        return float(s["reference_speed"]) if s["started"] else None

    @property
    def vent_actions(self) -> int:
        return int(self._state[0]["vent_actions"])

    def __call__(self, time, wheel_speeds, pressure_command):
        omega = np.ascontiguousarray(wheel_speeds, dtype=float)
        n = self.n_axles
        command = np.broadcast_to(np.asarray(pressure_command, float), (n,)).copy()
        pressures = np.full(n, np.nan)  # not given to a controller called from Python
        wsp_update(self._settings, self._state, float(time), omega, pressures, command,
                   math.nan, self._valves)
        return self._valves.copy()


def as_controller(controller, period: float | None):
    """Wrap a plain callable into an object with ``period`` and ``reset``."""
    if controller is None:
        return None
    if hasattr(controller, "reset") and hasattr(controller, "period"):
        return controller

    class _Wrapped:
        def __init__(self, fn, p):
            if p is None or not p > 0:
                raise ValueError("a plain controller function needs control_period > 0 [s]")
            self.fn, self.period = fn, float(p)

        def reset(self, n_axles, wheel_radius):
            pass

        def __call__(self, time, wheel_speeds, pressure_command):
            return self.fn(time, wheel_speeds, pressure_command)

    return _Wrapped(controller, period)
