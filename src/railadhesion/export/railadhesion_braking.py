"""FMI 2.0 co-simulation slave of the braking-vehicle FMU (runs inside the FMU, via pythonfmu).

Copied into the FMU's ``resources/`` folder by :func:`railadhesion.export.build_braking_fmu`;
not meant to be imported by users. At instantiation it loads the embedded scenario
(``resources/scenario.toml``: vehicle, initial speed, brake cylinders, adhesion model and
track) and builds a :class:`railadhesion.braking.BrakingSimulator` from it with the host's
installed ``railadhesion``. Every ``doStep(t, h)`` calls ``simulator.step(h, inputs)`` with the
current inputs (commanded pressure and valve state per axle), so the outputs equal those of
the stepping API driven directly with the same inputs. The scenario's brake demand is not
used: the co-simulation master (a HIL rig's WSP unit, a train model) commands the pressures
and the valves; or, when the FMU was built with the built-in WSP (``"wsp": true`` in its
configuration), the pressures only, and the package's WSP controller (the scenario's ``[wsp]``
settings, ideal sensors) sets the valves, which are then outputs.
"""

from __future__ import annotations

import math

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status


class RailadhesionBraking(Fmi2Slave):
    """A braking rail vehicle with per-axle brake cylinders, WSP valves and creep forces."""

    author = "railadhesion"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        try:
            import numpy as np

            from railadhesion.braking import BrakingSimulator
            from railadhesion.braking.scenario import load_scenario
            from railadhesion.export.slave import open_slave, register_variables
        except ImportError as exc:
            raise ImportError(
                "the railadhesion braking FMU needs the Python package 'railadhesion' (the "
                "release that built the FMU, or a later one) importable by the Python "
                f"interpreter that runs the FMU: {exc}"
            ) from exc
        resources, config = open_slave(self)  # the exit work-around, the config
        self._np = np
        scenario = load_scenario(resources / config["scenario_file"])
        self._n = scenario.vehicle.n_axles
        self._wsp = bool(config.get("wsp", False))
        wsp = None
        if self._wsp:
            from railadhesion.braking.wsp import WheelSlideProtection

            wsp = WheelSlideProtection(scenario.wsp)
        self._sim = BrakingSimulator(
            scenario.vehicle, scenario.adhesion(), scenario.initial_speed,
            cylinders=scenario.cylinders, gradient=scenario.gradient,
            refresh_period=scenario.refresh_period, record=False, wsp=wsp,
        )  # fmt: skip
        self._failed = False
        register_variables(self, config["variables"])
        self._publish(self._sim.state())

    def _publish(self, state) -> None:
        self.train_speed = float(state.train_speed)
        self.distance = float(state.distance)
        self.deceleration = float(state.deceleration)
        self.stopped = 1.0 if state.stopped else 0.0
        for i in range(self._n):
            k = i + 1
            setattr(self, f"wheel_speed_{k}", float(state.wheel_speeds[i]))
            setattr(self, f"brake_pressure_{k}", float(state.brake_pressures[i]))
            setattr(self, f"creep_force_{k}", float(state.creep_forces[i]))
            setattr(self, f"adhesion_used_{k}", float(state.adhesion_used[i]))
            setattr(self, f"normal_load_{k}", float(state.normal_loads[i]))
            if self._wsp:  # the valve states the built-in WSP chose (outputs)
                setattr(self, f"valve_{k}", float(state.valves[i]))

    def do_step(self, current_time, step_size):
        np = self._np
        if self._failed:
            return False
        if self._sim.stopped:  # at rest: nothing moves any more
            return True
        n = self._n
        command = np.array([getattr(self, f"pressure_command_{k}") for k in range(1, n + 1)])
        inputs = {"pressure_command": command}
        if not self._wsp:  # else the built-in WSP sets them
            inputs["valves"] = np.array(
                [int(round(getattr(self, f"valve_{k}"))) for k in range(1, n + 1)],
                dtype=np.int64)  # fmt: skip
        try:
            state = self._sim.step(float(step_size), inputs)
        except (ValueError, RuntimeError) as exc:  # bad input or a failed solve: say so
            self._failed = not isinstance(exc, ValueError)
            self.log(f"railadhesion: {exc}", Fmi2Status.error)
            return False
        if not all(math.isfinite(x) for x in (state.train_speed, state.distance)):
            self._failed = True
            self.log("railadhesion: non-finite state", Fmi2Status.error)
            return False
        self._publish(state)
        return True
