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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["BrakeCylinders", "APPLY", "HOLD", "VENT", "VALVE_STATES", "ATMOSPHERIC_PRESSURE"]

APPLY, HOLD, VENT = 0, 1, 2
VALVE_STATES = {"apply": APPLY, "hold": HOLD, "vent": VENT}
ATMOSPHERIC_PRESSURE = 101325.0


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
        Pressure limit [Pa] (default 3.8 bar).
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
        """New pressures, mean pressures over the step, and pressure vented [Pa] per axle.

        The same operations as the compiled step (``exp`` of the two time constants, the mean
        factor ``(τ/dt)(1 − e)``), so both give the same numbers.
        """
        p0 = np.asarray(pressure, float)
        cmd = np.broadcast_to(np.asarray(command, float), p0.shape)
        cmd = np.minimum(np.maximum(cmd, 0.0), self.max_pressure)
        target = np.where(valves == VENT, 0.0, np.where(valves == HOLD, p0, cmd))
        fill = target > p0
        e_fill = math.exp(-dt / self.fill_time_constant)
        e_vent = math.exp(-dt / self.vent_time_constant)
        e = np.where(fill, e_fill, e_vent)
        mean_factor = np.where(fill, (self.fill_time_constant / dt) * (1.0 - e_fill),
                               (self.vent_time_constant / dt) * (1.0 - e_vent))
        p1 = target + (p0 - target) * e
        mean = target + (p0 - target) * mean_factor
        vented = np.where(valves == VENT, p0 - p1, 0.0)
        return p1, mean, vented
