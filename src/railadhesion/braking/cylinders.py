"""Brake cylinders with WSP hold and vent valves.

Each axle's brake-cylinder pressure p follows a first-order lag towards its target
(an assumption of the usual kind for pneumatic brake cylinders; time constants are inputs):

* valve ``APPLY`` (0): target = min(commanded pressure, ``max_pressure``); time constant
  ``fill_time_constant`` when the target is above p, ``vent_time_constant`` when below;
* valve ``HOLD`` (1): p is held (both valves closed);
* valve ``VENT`` (2): target 0 (atmospheric), time constant ``vent_time_constant``.

Over a step of length dt with the valve state and command held, the lag is integrated exactly:
``p(dt) = target + (p0 − target) exp(−dt/τ)``; the mean pressure over the step (which sets the
brake torque of the implicit wheel update) is exact too. Pressures are gauge pressures [Pa].

Air consumption: every change APPLY/HOLD → VENT counts one vent action; the air vented by
WSP is reported as free air at atmospheric pressure, ``V_cyl Δp / p_atm`` [m³], with
``cylinder_volume`` the brake-cylinder volume per axle (an input; 2 l by default, an
assumption for the cylinders of one disc-braked axle).

The lag and the valve grouping are written once, as compiled functions
(:func:`lag_factors`, :func:`cylinder_step`, :func:`set_valves`) that the braking step calls
and :meth:`BrakeCylinders.advance` runs for NumPy callers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from railadhesion.plausibility import check_plausible

__all__ = ["BrakeCylinders", "APPLY", "HOLD", "VENT", "VALVE_STATES", "ATMOSPHERIC_PRESSURE",
           "lag_factors", "cylinder_step", "set_valves"]

APPLY, HOLD, VENT = 0, 1, 2
VALVE_STATES = {"apply": APPLY, "hold": HOLD, "vent": VENT}
ATMOSPHERIC_PRESSURE = 101325.0


@njit(cache=True, error_model="numpy")
def lag_factors(dt, fill_time_constant, vent_time_constant):
    """The first-order lag over a step dt, for filling and for venting: the decay factors
    ``exp(-dt/τ)`` and the mean factors ``(τ/dt)(1 - exp(-dt/τ))`` of the exact mean over
    the step. Returns (fill_decay, fill_mean, vent_decay, vent_mean)."""
    fill = math.exp(-dt / fill_time_constant)
    vent = math.exp(-dt / vent_time_constant)
    return (fill, (fill_time_constant / dt) * (1.0 - fill), vent,
            (vent_time_constant / dt) * (1.0 - vent))


@njit(cache=True, error_model="numpy")
def cylinder_step(p0, valve, command, max_pressure, fill_decay, fill_mean, vent_decay,
                  vent_mean):
    """One cylinder over one step with its valve state and command held: returns the end
    pressure, the exact mean pressure over the step and the pressure vented [Pa]
    (see the module docstring; factors from :func:`lag_factors`)."""
    if valve == VENT:
        target = 0.0
    elif valve == HOLD:
        target = p0
    else:
        target = min(max(command, 0.0), max_pressure)
    if target > p0:
        decay, mean = fill_decay, fill_mean
    else:
        decay, mean = vent_decay, vent_mean
    p1 = target + (p0 - target) * decay
    return p1, target + (p0 - target) * mean, p0 - p1 if valve == VENT else 0.0


@njit(cache=True, error_model="numpy")
def set_valves(valves, new, per_bogie, vent_actions):
    """Make ``new`` (one state per axle) the valve states ``valves``; with valves per bogie
    every axle of a bogie takes the most severe state of the bogie (vent > hold > apply);
    each change to VENT counts one vent action. ``new`` is grouped in place."""
    n = valves.shape[0]
    if per_bogie:
        half = n // 2
        first = 0.0
        second = 0.0
        for i in range(half):
            first = max(first, new[i])
            second = max(second, new[half + i])
        for i in range(half):
            new[i] = first
            new[half + i] = second
    for i in range(n):
        if new[i] == VENT and valves[i] != VENT:
            vent_actions[i] += 1
        valves[i] = new[i]


@dataclass(frozen=True)
class BrakeCylinders:
    """Brake-cylinder dynamics and WSP valve arrangement (see the module docstring).

    Parameters
    ----------
    fill_time_constant : float
        Time constant of the pressure rise [s] (default 0.3 s, an assumption).
    vent_time_constant : float
        Time constant of the pressure fall [s] (default 0.15 s, an assumption).
    max_pressure : float
        Pressure limit [Pa] (default 3.8 bar). A command above it is clipped to it (the
        simulation reports it: ``BrakingResult.summary["pressure_clipped"]``). A limit
        outside the plausible brake-cylinder pressures, 0.05-20 bar, warns (a
        :class:`~railadhesion.plausibility.UnitWarning` when it looks like bar, kPa, psi or
        MPa: ``max_pressure=6.0`` is 6 Pa; docs/checks.md).
    cylinder_volume : float
        Brake-cylinder volume per axle [m³], for the vented air (default 2e-3).
    valves : {"axle", "bogie"}
        WSP valves per axle, or one valve pair per bogie (then all axles of a bogie follow the
        most severe command of its axles: vent over hold over apply).
    """

    fill_time_constant: float = 0.3
    vent_time_constant: float = 0.15
    max_pressure: float = 3.8e5
    cylinder_volume: float = 2e-3
    valves: str = "axle"

    def __post_init__(self):
        for name in ("fill_time_constant", "vent_time_constant", "max_pressure",
                     "cylinder_volume"):
            x = getattr(self, name)
            if not (isinstance(x, int | float) and math.isfinite(x) and x > 0):
                raise ValueError(f"{name} must be in (0, inf), got {x!r}")
        if self.valves not in ("axle", "bogie"):
            raise ValueError(f"valves must be 'axle' or 'bogie', got {self.valves!r}")
        self.max_pressure_note()

    def max_pressure_note(self, *, emit: bool = True) -> str | None:
        """The warning for an implausible ``max_pressure`` (bar for Pa?), or None; issued
        unless ``emit`` is False (the simulator records it on its result without warning a
        second time)."""
        return check_plausible(self.max_pressure, "max_pressure", quantity="brake_pressure",
                               where="BrakeCylinders.max_pressure",
                               what="brake-cylinder pressure limit", emit=emit)

    def group_valves(self, valves: np.ndarray, n_axles: int) -> np.ndarray:
        """Per-axle valve states after the per-bogie grouping (if any)."""
        v = valves if isinstance(valves, np.ndarray) and valves.dtype == np.int64 else (
            np.asarray(valves, dtype=np.int64))
        if self.valves == "axle":
            if v.shape != (n_axles,):
                raise ValueError(f"valves must have {n_axles} entries, got shape {v.shape}")
            return v
        k = n_axles // 2
        if v.shape == (2,):
            return np.repeat(v, k)
        if v.shape != (n_axles,):
            raise ValueError(f"valves must have 2 (bogies) or {n_axles} entries, got {v.shape}")
        return np.repeat([v[:k].max(), v[k:].max()], k)

    def advance(self, pressure, valves, command, dt):
        """New pressures, mean pressures over the step, and pressure vented [Pa] per axle
        (:func:`cylinder_step` for every axle)."""
        p0 = np.asarray(pressure, float)
        cmd = np.broadcast_to(np.asarray(command, float), p0.shape)
        valves = np.broadcast_to(np.asarray(valves, float), p0.shape)
        factors = lag_factors(float(dt), self.fill_time_constant, self.vent_time_constant)
        out = np.array([cylinder_step(p0[i], valves[i], cmd[i], self.max_pressure, *factors)
                        for i in range(p0.size)]).reshape(p0.size, 3)
        return out[:, 0], out[:, 1], out[:, 2]
