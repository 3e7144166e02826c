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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from railadhesion.braking.cylinders import APPLY, HOLD, VENT

__all__ = ["WSPSettings", "WheelSlideProtection", "as_controller"]


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


class WheelSlideProtection:
    """Generic per-axle WSP controller (see the module docstring). State kept between calls."""

    def __init__(self, settings: WSPSettings | None = None, **changes):
        if settings is None:
            settings = WSPSettings(**changes)
        elif changes:
            settings = WSPSettings(**{**settings.__dict__, **changes})
        self.settings = settings
        self.period = settings.period
        self.n_axles = 0

    def reset(self, n_axles: int, wheel_radius: float) -> None:
        self.n_axles = n_axles
        self.radius = float(wheel_radius)
        self.state = np.full(n_axles, APPLY, dtype=np.int64)
        self.released_since = np.full(n_axles, np.nan)
        self.forced_until = np.full(n_axles, -np.inf)
        self.previous = None
        self.deceleration = np.zeros(n_axles)
        self.reference_speed = None
        self.vent_actions = 0

    def __call__(self, time, wheel_speeds, pressure_command):
        s = self.settings
        u = np.asarray(wheel_speeds, float) * self.radius
        if self.previous is None:
            self.previous = u.copy()
            self.reference_speed = float(u.max())
        raw = (self.previous - u) / s.period
        alpha = s.period / (s.deceleration_filter + s.period)
        self.deceleration += alpha * (raw - self.deceleration)
        self.previous = u.copy()
        ref = self.reference_speed
        hold = max(s.hold_slip_ratio * ref, s.hold_slip_min)
        rate = (s.sliding_reference_deceleration if float(u.max()) < ref - hold
                else s.reference_deceleration)
        v_ref = max(float(u.max()), ref - rate * s.period)
        self.reference_speed = v_ref
        slip = v_ref - u
        hold = max(s.hold_slip_ratio * v_ref, s.hold_slip_min)
        vent = max(s.vent_slip_ratio * v_ref, s.vent_slip_min)
        reapply = max(s.reapply_slip_ratio * v_ref, s.reapply_slip_min)
        a = self.deceleration
        new = self.state.copy()
        for i in range(self.n_axles):
            st = self.state[i]
            want_vent = slip[i] > vent or a[i] > s.vent_deceleration
            want_hold = slip[i] > hold or a[i] > s.hold_deceleration
            if st == APPLY:
                new[i] = VENT if want_vent else (HOLD if want_hold else APPLY)
            elif st == VENT:
                if -a[i] > s.recovery_acceleration:
                    new[i] = HOLD
            else:  # HOLD
                accelerating = -a[i] > s.recovery_acceleration
                if want_vent and not accelerating:
                    new[i] = VENT
                elif slip[i] < reapply and not accelerating and a[i] < s.hold_deceleration:
                    new[i] = APPLY
            # watchdog
            if time < self.forced_until[i]:
                new[i] = APPLY
            elif new[i] != APPLY:
                if np.isnan(self.released_since[i]):
                    self.released_since[i] = time
                elif time - self.released_since[i] >= s.watchdog_time - 1e-12:
                    new[i] = APPLY
                    self.forced_until[i] = time + s.watchdog_refill_time
            if new[i] == APPLY:
                self.released_since[i] = np.nan
            if new[i] == VENT and st != VENT:
                self.vent_actions += 1
        self.state = new
        return new.copy()


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
