"""FMI 2.0 co-simulation slave of the adhesion-monitor FMU (runs inside the FMU, via pythonfmu).

Copied into the FMU's ``resources/`` folder by :func:`railadhesion.export.build_monitor_fmu`;
not meant to be imported by users. At instantiation it loads the embedded vehicle and settings
and builds a :class:`railadhesion.monitor.AdhesionMonitor` with the host's installed
``railadhesion``. Every ``doStep(t, h)`` writes the inputs into the monitor and calls its
per-sample step at ``t + h``: the outputs equal the per-sample call's with the same inputs.
"""

from __future__ import annotations

import json

from pythonfmu import Fmi2Slave


class RailadhesionMonitor(Fmi2Slave):
    """On-board adhesion monitor: per axle, creepage, adhesion in use, available adhesion and
    its level."""

    author = "railadhesion"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        try:
            from railadhesion.braking import load_vehicle
            from railadhesion.export.slave import open_slave, register_variables
            from railadhesion.monitor import AdhesionMonitor, MonitorSettings
        except ImportError as exc:
            raise ImportError(
                "the railadhesion monitor FMU needs the Python package 'railadhesion' (the "
                "release that built the FMU, or a later one) importable by the Python "
                f"interpreter that runs the FMU: {exc}"
            ) from exc
        resources, config = open_slave(self)  # the exit work-around, the config
        vehicle = load_vehicle(resources / config["vehicle_file"])
        settings = MonitorSettings.from_dict(json.loads(
            (resources / config["settings_file"]).read_text(encoding="utf-8")))
        self._mon = AdhesionMonitor(vehicle, settings, pressure=config["pressure"],
                                    torque=config["torque"])
        self._n = vehicle.n_axles
        self._pressure = config["pressure"]
        self._torque = config["torque"]
        register_variables(self, config["variables"])
        self._publish()

    def _publish(self) -> None:
        out = self._mon.live
        self.vehicle_level = float(self._mon.outputs["vehicle_level"][0])
        for i in range(self._n):
            k = i + 1
            setattr(self, f"creep_{k}", float(out.creep[i]))
            setattr(self, f"adhesion_used_{k}", float(out.adhesion_used[i]))
            setattr(self, f"adhesion_available_{k}", float(out.estimate[i]))
            setattr(self, f"adhesion_lower_{k}", float(out.lower[i]))
            setattr(self, f"adhesion_upper_{k}", float(out.upper[i]))
            setattr(self, f"level_{k}", float(out.level[i]))
            setattr(self, f"reason_{k}", float(out.reason[i]))
            setattr(self, f"level_since_{k}", float(out.level_since[i]))

    def do_step(self, current_time, step_size):
        u = self._mon.inputs
        n = self._n
        u.train_speed = self.train_speed
        u.wheel_speeds[:] = [getattr(self, f"wheel_speed_{k}") for k in range(1, n + 1)]
        if self._pressure:
            u.brake_pressures[:] = [getattr(self, f"brake_pressure_{k}") for k in range(1, n + 1)]
        if self._torque:
            u.torques[:] = [getattr(self, f"torque_{k}") for k in range(1, n + 1)]
        # bad values never raise: the monitor reports them in its levels and reasons
        self._mon.step(float(current_time) + float(step_size))
        self._publish()
        return True
