"""A naive odometry, as an FMI 2.0 co-simulation slave (pythonfmu) and as a Python object.

The tests build an FMU from this file and run it on the odometry bench beside the same logic
called from Python (``ComplementaryOdometry``): both must give the same numbers. The logic:
a complementary filter between the accelerometer (when there is one) and the fastest wheel,
with a fixed-percentage interval (5 m + 5 % of the distance) - the kind of interval that slides
violate. Inputs ``wheel_speed_1``, ``wheel_speed_4`` [rad/s], ``acceleration`` [m/s²],
``radar_speed`` [m/s], ``drive``; outputs ``speed``, ``distance``, ``distance_min``,
``distance_max``, ``status`` (Integer); parameter ``wheel_radius`` [m]. Built with
``VARIANT = "wrong"`` the distance output is called ``dist`` (a unit that does not follow the
bench's names).
"""

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real

AXLES = (1, 4)
VARIANT = "ok"
TIME_CONSTANT = 2.0  # s: how fast the estimate follows the wheels


def cf_step(state, time, speeds, acceleration, radar, radius):
    """One cycle; ``state`` a dict (time, speed, distance). Returns the five outputs."""
    u = max(speeds) * radius
    if radar == radar:
        u = radar
    if not state:
        state.update(time=time, speed=u, distance=0.0)
    dt = time - state["time"]
    a = acceleration if acceleration == acceleration else 0.0
    v = state["speed"] + a * dt
    if dt > 0:
        v += (u - v) * dt / TIME_CONSTANT
    x = state["distance"] + 0.5 * (state["speed"] + v) * dt
    state.update(time=time, speed=v, distance=x)
    margin = 5.0 + 0.05 * x
    return v, x, x - margin, x + margin, 1 if abs(u - v) > 0.5 else 0


class ComplementaryOdometry:
    """The same logic for the bench's Python interface."""

    period = 0.005

    def reset(self, axles, wheel_radius, pulses_per_revolution, gradient):
        self.radius = wheel_radius
        self.state = {}

    def __call__(self, time, wheel_speeds, pulse_counts, radar_speed, acceleration, drive):
        return cf_step(self.state, time, list(wheel_speeds), acceleration, radar_speed,
                       self.radius)


class OdometryCf(Fmi2Slave):
    """Complementary-filter odometry (test helper)."""

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
        for i in AXLES:
            setattr(self, f"wheel_speed_{i}", 0.0)
            self.register_variable(Real(f"wheel_speed_{i}", causality=Fmi2Causality.input))
        for name in ("acceleration", "radar_speed", "drive"):
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        self._names = ("speed", "dist" if VARIANT == "wrong" else "distance", "distance_min",
                       "distance_max")
        for name in self._names:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output))
        self.status = 0
        self.register_variable(Integer("status", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete))
        self._state = {}

    def do_step(self, current_time, step_size):
        speeds = [getattr(self, f"wheel_speed_{i}") for i in AXLES]
        out = cf_step(self._state, current_time, speeds, self.acceleration, self.radar_speed,
                      self.wheel_radius)
        for name, value in zip(self._names, out[:4], strict=True):
            setattr(self, name, value)
        self.status = int(out[4])
        return True
