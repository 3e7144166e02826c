"""The channels every log of a train's axles holds: :class:`AxleLog`.

The base of the braking-test log (:class:`railadhesion.identification.BrakingLog`) and of the
monitor's replay log (:class:`railadhesion.monitor.replay.MonitorLog`). It lives here, with
the readers, so that the monitor does not import the identification package to have it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AxleLog"]


@dataclass(frozen=True, eq=False)
class AxleLog:
    """The channels every log of a train's axles holds, SI units (n samples, N axles): time
    [s] (n,), train speed [m/s] (n,), wheelset angular speeds [rad/s] (n, N) and
    brake-cylinder pressures [Pa] (n, N). Base of :class:`BrakingLog` (identification) and
    :class:`railadhesion.monitor.replay.MonitorLog` (the monitor's replay)."""

    time: np.ndarray
    train_speed: np.ndarray
    wheel_speed: np.ndarray
    brake_pressure: np.ndarray

    @property
    def n_axles(self) -> int:
        """Number of axles N."""
        return int(self.wheel_speed.shape[1])

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.time.size)
