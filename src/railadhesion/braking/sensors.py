"""What the WSP controller measures: the sensor model between the vehicle and the controller.

The braking step calls, before every control period of its built-in WSP::

    external_speed = measure(settings, state, t, omega_true, pressure_true, speed_true,
                             accel_true, omega_meas, pressure_meas)

with the true wheelset speeds [rad/s] and cylinder pressures [Pa], the true train speed
[m/s] and acceleration [m/s²] (a sensor model may use them for a radar or GNSS speed; the
controller never sees them), and fills the measured wheelset speeds and pressures; it returns
the externally measured train speed [m/s], or NaN when there is no such sensor.
``settings``/``state`` are one-element record arrays built by the sensor object
(:meth:`IdealSensors.settings_record`, :meth:`IdealSensors.state_record`). No exceptions, no
allocation (a C host can run it).

:class:`IdealSensors` (the default) measures exactly and has no external speed sensor.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["IdealSensors", "measure"]

#: Settings and state records of the ideal sensors (no fields needed; one placeholder).
SETTINGS_DTYPE = np.dtype([("ideal", "i8")], align=True)
STATE_DTYPE = np.dtype([("calls", "i8")], align=True)


class IdealSensors:
    """Exact wheel-speed and pressure measurement, no external train-speed sensor."""

    def settings_record(self) -> np.ndarray:
        rec = np.zeros(1, SETTINGS_DTYPE)
        rec[0]["ideal"] = 1
        return rec

    def state_record(self, n_axles: int) -> np.ndarray:
        return np.zeros(1, STATE_DTYPE)


@njit(cache=True, error_model="numpy")
def measure(settings, state, t, omega_true, pressure_true, speed_true, accel_true, omega_meas,
            pressure_meas):
    """Ideal sensors: the measured values are the true ones; no external speed (NaN)."""
    state[0].calls += 1
    for i in range(omega_true.shape[0]):
        omega_meas[i] = omega_true[i]
        pressure_meas[i] = pressure_true[i]
    return math.nan
