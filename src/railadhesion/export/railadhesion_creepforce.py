"""FMI 2.0 co-simulation slave of the creep-force FMU (runs inside the FMU, via pythonfmu).

This file is copied into the FMU's ``resources/`` folder by
:func:`railadhesion.export.build_creep_force_fmu`; it is not meant to be imported by users.
At instantiation it reads ``resources/railadhesion_fmu.json`` (which model, which parameter
file, the elastic constants) and the embedded parameter file, then evaluates the model with
the public functions of the host's installed ``railadhesion`` (which must be importable by the
Python interpreter that runs the FMU).

Outputs are evaluated from the current inputs whenever they are read after an input changed
(the creep-force law is algebraic: direct feedthrough, no state), and at every ``doStep``.
A normal force <= 0 (wheel lift-off) gives zero forces and zero adhesion; other invalid
inputs (NaN, a <= 0, negative water flow, ...) give NaN outputs, the library's message in the
FMU log and, at ``doStep``, a failed step (``fmi2Discard``).
"""

from __future__ import annotations

import math

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status


def _import_railadhesion():
    try:
        import railadhesion
        from railadhesion.export import slave
    except ImportError as exc:  # the host's Python lacks the package: say what to do
        raise ImportError(
            "the railadhesion creep-force FMU needs the Python package 'railadhesion' (the "
            "release that built the FMU, or a later one) importable by the Python interpreter "
            f"that runs the FMU (pip install railadhesion, or add it to PYTHONPATH): {exc}"
        ) from exc
    return railadhesion, slave


class RailadhesionCreepForce(Fmi2Slave):
    """Creep forces Fx, Fy [N] and adhesion [-] of a wheel-rail contact (Polach, WILAC or the
    table model of Kalker's exact theory, which also gives the spin moment Mz [N m])."""

    author = "railadhesion"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        ra, slave = _import_railadhesion()
        from railadhesion.io.paramfiles import load_parameter_file

        resources, config = slave.open_slave(self)  # the exit work-around, the config
        self._model = config["model"]
        params = load_parameter_file(resources / config["parameter_file"])
        self._params = params
        self._adhesion = ra.adhesion
        if self._model == "table":
            from railadhesion.contact import exact_table_forces

            self._forces_fn = exact_table_forces
            coulomb = config.get("friction", "falling") == "coulomb"
            self._friction = (1.0, 0.0) if coulomb else (params.A, params.B)
        else:
            self._forces_fn = ra.wilac_forces if self._model == "wilac" else ra.polach_forces
        if ra.__version__ != config["railadhesion_version"]:
            self.log(
                f"the FMU was built with railadhesion {config['railadhesion_version']}, the "
                f"host runs {ra.__version__}",
                Fmi2Status.warning,
            )
        self._dirty = True
        self.Mz = 0.0  # an output of the table model only; the outputs start at 0 (below)
        slave.register_variables(self, config["variables"], getter=self._output_getter,
                                 setter=self._input_setter)  # fmt: skip

    # -- variable access --------------------------------------------------------------------

    def _input_setter(self, name):
        def setter(value):
            setattr(self, name, float(value))
            self._dirty = True

        return setter

    def _output_getter(self, name):
        def getter():
            if self._dirty:
                self._step()
            return getattr(self, name)

        return getter

    # -- model --------------------------------------------------------------------------------

    def _evaluate(self) -> None:
        q = self.normal_force
        if q <= 0.0 and math.isfinite(q):  # wheel lift-off: no contact, no force
            self.Fx = self.Fy = self.adhesion = self.Mz = 0.0
            self._dirty = False
            return
        if self._model == "table":
            ratio, decay = self._friction
            fx, fy, mz = self._forces_fn(
                self.creep_long, self.creep_lat, self.spin, q, self.a, self.b,
                self._params.mu0, shear_modulus=self.shear_modulus, poisson=self.poisson,
                speed=self.speed, friction_ratio=ratio, friction_decay=decay,
            )  # fmt: skip
            self.Mz = float(mz)
        elif self._model == "wilac":
            fx, fy = self._forces_fn(
                self.creep_long, self.creep_lat, self.spin, q, self.speed, self.a, self.b,
                self.water_flow, self._params,
                shear_modulus=self.shear_modulus, poisson=self.poisson,
            )  # fmt: skip
        else:
            p = self._params
            fx, fy = self._forces_fn(
                self.creep_long, self.creep_lat, self.spin, q, self.speed, self.a, self.b,
                mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
                shear_modulus=self.shear_modulus, poisson=self.poisson,
            )  # fmt: skip
        self.Fx = float(fx)
        self.Fy = float(fy)
        self.adhesion = float(self._adhesion(fx, fy, q))
        self._dirty = False

    def exit_initialization_mode(self):
        return self._step()

    def do_step(self, current_time, step_size):
        return self._step()

    def _step(self) -> bool:
        try:
            self._evaluate()
        except ValueError as exc:
            # Invalid inputs: NaN outputs (a number would be a wrong force), the message in
            # the log, and a failed step (pythonfmu reports it as fmi2Discard).
            self.Fx = self.Fy = self.adhesion = self.Mz = math.nan
            self._dirty = False
            self.log(f"railadhesion: {exc}", Fmi2Status.error)
            return False
        return True
