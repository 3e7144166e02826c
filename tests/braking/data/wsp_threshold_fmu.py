"""A simple threshold WSP, as an FMI 2.0 co-simulation slave (pythonfmu) and as a function.

The tests build an FMU from this file and run it on the WSP bench beside the same logic called
from Python (``threshold_valves``): both must give the same numbers. ``N_AXLES`` inputs
``wheel_speed_i`` [rad/s] and ``brake_pressure_i`` [Pa], outputs ``valve_i`` (Integer), a
parameter ``wheel_radius`` [m]. When built with ``VARIANT = "wrong"`` the outputs are named
``valve1``... (a unit that does not follow the bench's names).
"""

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real

N_AXLES = 4
VARIANT = "ok"


def threshold_valves(wheel_speeds, radius):
    """Valve codes from the wheel speeds: slip against the fastest wheel; vent above
    15 % + 0.5 m/s, hold above 5 % + 0.2 m/s, else apply."""
    u = [w * radius for w in wheel_speeds]
    ref = max(u)
    out = []
    for x in u:
        slip = ref - x
        if slip > 0.15 * ref + 0.5:
            out.append(2)
        elif slip > 0.05 * ref + 0.2:
            out.append(1)
        else:
            out.append(0)
    return out


class WspThreshold(Fmi2Slave):
    """Threshold WSP unit (test helper)."""

    author = "railadhesion tests"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        try:  # pythonfmu's binary can abort at exit in a Python host (railadhesion.export)
            from railadhesion.export._host import release_pythonfmu_state_at_exit

            release_pythonfmu_state_at_exit(self.resources)
        except ImportError:
            pass
        self.wheel_radius = 0.46
        self.register_variable(Real("wheel_radius", causality=Fmi2Causality.parameter,
                                    variability=Fmi2Variability.fixed))
        out_name = "valve_{}" if VARIANT == "ok" else "valve{}"
        for i in range(1, N_AXLES + 1):
            setattr(self, f"wheel_speed_{i}", 0.0)
            self.register_variable(Real(f"wheel_speed_{i}", causality=Fmi2Causality.input))
            setattr(self, f"brake_pressure_{i}", 0.0)
            self.register_variable(Real(f"brake_pressure_{i}", causality=Fmi2Causality.input))
            setattr(self, out_name.format(i), 0)
            self.register_variable(Integer(out_name.format(i), causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
        self._out_name = out_name

    def do_step(self, current_time, step_size):
        speeds = [getattr(self, f"wheel_speed_{i}") for i in range(1, N_AXLES + 1)]
        for i, v in enumerate(threshold_valves(speeds, self.wheel_radius), 1):
            setattr(self, self._out_name.format(i), v)
        return True
