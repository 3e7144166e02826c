"""The brake demand of a whole stop: :class:`BrakeDemand` (and its compiled form).

The commanded brake-cylinder pressure is 0 before ``start_time``, then rises linearly over
``ramp_time`` up to ``pressure`` (a step when ``ramp_time`` is 0). :func:`demanded_pressure`
is the one implementation: ``BrakeDemand.__call__`` runs it, and so does the compiled loop of
:func:`railadhesion.braking.simulate`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from numba import njit

__all__ = ["BrakeDemand", "demanded_pressure"]


@njit(cache=True, error_model="numpy")
def demanded_pressure(pressure, start_time, ramp_time, time):
    """Commanded pressure [Pa] at ``time`` [s] (see the module docstring)."""
    if time < start_time:
        return 0.0
    if ramp_time <= 0.0:
        return pressure
    return pressure * min(1.0, (time - start_time) / ramp_time)


@dataclass(frozen=True)
class BrakeDemand:
    """Commanded brake-cylinder pressure over time: 0 before ``start_time``, then a linear
    ramp over ``ramp_time`` [s] up to ``pressure`` [Pa] (a step when ``ramp_time`` is 0)."""

    pressure: float = 3.0e5
    start_time: float = 0.0
    ramp_time: float = 0.0

    def __post_init__(self):
        for name in ("pressure", "start_time", "ramp_time"):
            x = getattr(self, name)
            if not (isinstance(x, int | float) and math.isfinite(x) and x >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {x!r}")

    def __call__(self, time: float) -> float:
        return demanded_pressure.py_func(float(self.pressure), float(self.start_time),
                                         float(self.ramp_time), float(time))
