"""The native braking-vehicle FMU: the braking step compiled ahead of time, no Python at run time.

Same variables as the Python braking FMU (:func:`railadhesion.export.braking_fmu_variables`:
commanded pressure and WSP valve per axle in; train speed, distance, deceleration, stopped,
and per axle wheel speed, cylinder pressure, creep force, adhesion used, normal load out).
With the built-in WSP (``wsp=True``) the package's WSP controller and sensor model run inside
the step, as in the stepping API of a simulator built with ``wsp=``: the valve states are then
outputs. The model is a step function on the three records of :mod:`railadhesion.export.native`:

* ``state``: the braking simulator's machine (the record of
  :data:`railadhesion.braking.step.MACHINE`: vehicle state, WSP and sensor records), copied
  from a :class:`~railadhesion.braking.BrakingSimulator` built from the scenario, and a
  ``stopped`` flag as a number;
* ``settings``: the simulator's constant tables (adhesion sets, track, water profile);
* ``inputs``: the commanded pressure and the valve state of every axle.

Each ``doStep`` copies the inputs into the machine (valves rounded, as the Python FMU does;
not the valves when the built-in WSP commands them) and calls
:func:`railadhesion.braking.step.advance_unrecorded`, the compiled step the stepping API calls:
the physics is not retyped, and the outputs equal the stepping API's.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from railadhesion.export.braking_fmu import (
    braking_description,
    braking_documentation,
    braking_fmu_variables,
    load_scenario_alone,
    scenario_file,
)
from railadhesion.export.native import (
    NativeUnsupported,
    RecordVariable,
    StepModel,
    build_step_fmu,
)

__all__ = ["braking_step_model", "build_native_braking_fmu"]

_SCENARIO_FILE = "scenario.toml"
# per-axle outputs: FMU variable prefix -> field of the braking state record
_AXLE_OUTPUTS = {"wheel_speed": "omega", "brake_pressure": "pressure", "creep_force": "force",
                 "adhesion_used": "mu", "normal_load": "load", "valve": "valve"}  # fmt: skip
_SCALAR_OUTPUTS = {"train_speed": "machine.state.speed", "distance": "machine.state.distance",
                   "deceleration": "machine.state.deceleration", "stopped": "stopped"}  # fmt: skip


def _messages() -> dict[int, str]:
    from railadhesion.braking import records as r

    return {
        r.NONFINITE: "the adhesion model gave a non-finite value; the simulation cannot proceed",
        r.BAD_DT: "the step size must be in (0, inf) s",
        r.BAD_COMMAND: "a pressure_command is outside [0, inf) Pa",
        r.BAD_VALVE: "a valve is not 0 (apply), 1 (hold) or 2 (vent)",
        r.ROWS_FULL: "internal: history rows full (not recording)",
        r.BAD_TORQUE: "a traction torque is not finite",
        r.STALE: "the compiled braking step was built from other sources than this machine",
    }


def _braking_step(state_t, settings_t, inputs_t, n_axles: int, wsp: bool):
    """The FMU's step on the records of one export: inputs into the machine (the valves only
    without the built-in WSP), the compiled braking step, the stop flag."""
    from numba import carray

    from railadhesion.braking.records import STOPPED
    from railadhesion.braking.step import MACHINE, advance_unrecorded

    n = n_axles
    valves_in = not wsp
    n_tables = settings_t.fields["tables"][0].shape[0]

    def step(state, settings, inputs, dt):
        machine = carray(state, 1, MACHINE)  # the first field of the state record
        tables = carray(settings, n_tables, np.float64)  # the only field of the settings
        x = carray(inputs, 1, inputs_t)[0]
        u = machine[0].inputs
        for i in range(n):
            u.pressure_command[i] = x.pressure_command[i]
            if valves_in:
                u.valves[i] = np.round(x.valves[i])
        status = advance_unrecorded(machine, tables, dt, 0)
        out = carray(state, 1, state_t)[0]
        out.stopped = 1.0 if machine[0].state.stopped != 0 else 0.0
        if status == 0 or status == STOPPED:
            return 0
        return status

    return step


def braking_step_model(simulator, identifier: str = "railadhesion_braking") -> StepModel:
    """The braking vehicle of ``simulator`` (a :class:`~railadhesion.braking.BrakingSimulator`
    in its current state, not recording) as a :class:`StepModel` with the braking FMU's
    variables.

    A simulator with the built-in WSP (``wsp=``, the package's controller and sensor model)
    gives the FMU with the WSP inside: ``valve_k`` are then outputs
    (:func:`railadhesion.export.braking_fmu_variables` with ``wsp=True``)."""
    from railadhesion.braking.records import INPUTS, POLACH, WILAC
    from railadhesion.braking.step import MACHINE

    if simulator._rows is not None:  # noqa: SLF001
        raise ValueError("simulator: build it with record=False")
    buffer = simulator._buffer  # noqa: SLF001
    if buffer is None:
        raise NativeUnsupported(
            "simulator: the native braking FMU compiles the package's WSP controller and "
            "sensor model only (WheelSlideProtection, SensorModel); this simulator has another "
            "controller or sensor model: use the Python braking FMU")
    machine, tables = simulator._machine, simulator._tables  # noqa: SLF001
    n = int(machine[0]["settings"]["n_axles"])
    if int(machine[0]["settings"]["model"]) not in (POLACH, WILAC):
        raise NativeUnsupported(
            "simulator: the native braking FMU compiles the built-in adhesion models (Polach "
            "sets, WILAC) only; this simulator's model is a Python function, a user's law or "
            "the table model: use the Python braking FMU")
    wsp = int(machine[0]["settings"]["wsp_on"]) != 0
    state_t = np.dtype([("machine", MACHINE), ("stopped", "f8")], align=True)
    settings_t = np.dtype([("tables", "f8", (max(tables.size, 1),))], align=True)
    state = np.zeros(1, state_t)
    state["machine"] = machine
    settings = np.zeros(1, settings_t)
    settings["tables"][0, : tables.size] = tables
    state["stopped"] = float(machine[0]["state"]["stopped"] != 0)
    inputs = np.zeros(1, INPUTS)
    inputs["pressure_command"][0] = machine[0]["inputs"]["pressure_command"]
    variables = []
    for v in braking_fmu_variables(n, wsp=wsp):
        name = v.name
        if v.causality == "input":
            prefix, k = name.rsplit("_", 1)
            fieldname = "pressure_command" if prefix == "pressure_command" else "valves"
            variables.append(RecordVariable(v, fieldname, (int(k) - 1,)))
        elif name in _SCALAR_OUTPUTS:
            variables.append(RecordVariable(v, _SCALAR_OUTPUTS[name]))
        else:
            prefix, k = name.rsplit("_", 1)
            variables.append(RecordVariable(v, f"machine.state.{_AXLE_OUTPUTS[prefix]}",
                                            (int(k) - 1,)))  # fmt: skip
    return StepModel(
        identifier=identifier,
        step=_braking_step(state_t, settings_t, INPUTS, n, wsp),
        state=state,
        settings=settings,
        inputs=inputs,
        variables=variables,
        errors=_messages(),
    )


def build_native_braking_fmu(out, scenario, *, wsp: bool = False) -> Path:
    """Write a native FMI 2.0 co-simulation FMU of a braking vehicle: no Python at run time.

    Same scenario file, variables and outputs as :func:`railadhesion.export.build_braking_fmu`;
    the braking step (``railadhesion.braking.step``) is compiled in with the vehicle, the
    cylinders, the adhesion model and the track of the scenario (binary for linux64, sources
    in ``sources/``; ``docs/fmu.md``). Building needs a C compiler and FMPy.

    Parameters
    ----------
    out : str or os.PathLike
        The ``.fmu`` file to write.
    scenario : str or os.PathLike
        A braking scenario TOML file (``docs/braking.md``), embedded as documentation.
    wsp : bool
        Run the package's WSP controller (the scenario's ``[wsp]`` settings, or the defaults
        of :class:`~railadhesion.braking.wsp.WSPSettings` if it has none) and ideal sensors
        inside the FMU: the valve states become outputs. Default: the master commands the
        valves (inputs), as in the Python braking FMU.

    Returns
    -------
    pathlib.Path
        The path of the native braking FMU written (``out``): compiled C, no Python in the host.

    Notes
    -----
    A NaN or out-of-range input is refused by ``fmi2SetReal`` (``fmi2Error``, logged, naming
    the variable); a failed step returns ``fmi2Error`` with the reason logged.
    ``fmi2GetFMUstate``/``fmi2SetFMUstate`` save and restore the whole vehicle.
    """
    path = scenario_file(scenario)
    if not _generic_cpu():
        return _build_in_generic_process(out, path, wsp)
    return _build(out, path, wsp)


def _generic_cpu() -> bool:
    import numba

    return numba.config.CPU_NAME == "generic"  # numba's public settings (NUMBA_CPU_NAME)


def _build_in_generic_process(out, path: Path, wsp: bool) -> Path:
    """Build in a Python process whose numba compiles for a generic x86-64: the braking
    step's IR then holds no vector intrinsics of this machine's processor (AVX masked loads),
    which the portable binary may not contain."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CPU_NAME="generic", NUMBA_CPU_FEATURES="")
    code = ("import sys; from railadhesion.export.native_braking import _build; "
            "_build(sys.argv[1], sys.argv[2], sys.argv[3] == '1')")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code, str(out), str(path), str(int(wsp))],
                          env=env,
                          capture_output=True, text=True)  # fmt: skip
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        from railadhesion.export.native import NativeBuildError

        if "NativeUnsupported" in last:
            raise NativeUnsupported(last.split(": ", 1)[-1])
        if "NativeBuildError" in last:
            raise NativeBuildError(last.split(": ", 1)[-1])
        if "ValueError" in last:
            raise ValueError(last.split(": ", 1)[-1])
        raise RuntimeError(f"building the native braking FMU failed: {last}")
    return Path(out)


def _build(out, path, wsp: bool = False) -> Path:
    import railadhesion
    from railadhesion.braking import BrakingSimulator
    from railadhesion.braking.wsp import WheelSlideProtection

    text, loaded = load_scenario_alone(Path(path))
    sim = BrakingSimulator(
        loaded.vehicle, loaded.adhesion(), loaded.initial_speed, cylinders=loaded.cylinders,
        gradient=loaded.gradient, refresh_period=loaded.refresh_period, record=False,
        wsp=WheelSlideProtection(loaded.wsp) if wsp else None,
    )  # fmt: skip
    model = braking_step_model(sim)
    vehicle = loaded.vehicle
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    description = braking_description(
        loaded, wsp, f"Native: no Python at run time. Scenario in documentation/{_SCENARIO_FILE} "
        f"(sha256 {sha[:12]}...).",
    )  # fmt: skip
    variables = [rv.variable for rv in model.variables]
    documentation = braking_documentation(description, variables, text, native=True)
    return build_step_fmu(
        model, out,
        model_name=f"railadhesion braking vehicle '{vehicle.name}' (native)",
        description=description,
        documentation=documentation,
        version=f"railadhesion {railadhesion.__version__}, scenario {sha[:12]}",
        extra_documentation={_SCENARIO_FILE: text},
    )  # fmt: skip
