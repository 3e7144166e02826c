"""The adhesion-monitor FMU: :class:`railadhesion.monitor.AdhesionMonitor` as an FMI 2.0
co-simulation FMU (pythonfmu), so that a rig or a train-control model can run it.

Inputs: the speed reference, and per axle the wheel speed, the brake-cylinder pressure and/or
the torque; outputs per axle: creepage, adhesion in use, the available adhesion estimated with
its band, the level (0 unknown, 1 normal, 2 caution, 3 low), the reason code (the table is in
the FMU's documentation and ``docs/monitor.md``) and the time of the level's last change; and
the vehicle's level. The vehicle and the monitor's settings are embedded
(``resources/vehicle.toml``, ``resources/monitor_settings.json``). Every ``doStep(t, h)`` is one
sample of the monitor at ``t + h``: the master's communication step should be the settings'
``sample_period`` (2.4 ms by default).

Native (Python-free) FMUs are another helper's work; this one runs Python, like the package's
other FMUs: the host needs a Python interpreter with ``railadhesion`` installed.
"""

from __future__ import annotations

import hashlib
import html
import json
import tempfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from railadhesion._validate import instance_or_default
from railadhesion.export.fmu import (
    RUNS_PYTHON,
    FmuVariable,
    build_fmu,
    documentation_page,
    variables_table,
)
from railadhesion.export.slave import CONFIG_FILE

__all__ = ["build_monitor_fmu", "build_native_monitor_fmu", "monitor_fmu_variables",
           "monitor_step_model"]

_VEHICLE_FILE = "vehicle.toml"
_SETTINGS_FILE = "monitor_settings.json"


# per-axle outputs: FMU variable prefix -> (field of the monitor's output record, unit,
# description of axle {k}'s variable)
_AXLE_OUTPUTS = {
    "creep": ("creep", "1",
              "creepage of axle {k}, (v - omega R)/v, braking > 0 (filtered, 2 Hz)"),
    "adhesion_used": ("adhesion_used", "1",
                      "adhesion in use by axle {k} (seed 002 eq. 10; braking > 0)"),
    "adhesion_available": ("estimate", "1",
                           "available adhesion of axle {k}, estimated (NaN before any estimate)"),
    "adhesion_lower": ("lower", "1",
                       "lower end of the band of the available adhesion of axle {k}"),
    "adhesion_upper": ("upper", "1",
                       "upper end of the band of axle {k} (+inf: no upper bound seen)"),
    "level": ("level", "1", "level of axle {k}: 0 unknown, 1 normal, 2 caution, 3 low"),
    "reason": ("reason", "1", "reason code of axle {k}'s level (see the documentation)"),
    "level_since": ("level_since", "s", "time of the last change of axle {k}'s level"),
}  # fmt: skip


def monitor_fmu_variables(n_axles: int, pressure=True, torque=False) -> list[FmuVariable]:
    """The variables of a monitor FMU with ``n_axles`` axles (axle 1 leading); ``pressure``
    and ``torque`` say which input channels it has (booleans, for all axles)."""
    v = [FmuVariable("train_speed", "input", "m/s",
                     "speed reference (radar, GNSS or the WSP's reference)", 0.0, min=0.0)]
    for k in range(1, n_axles + 1):
        v.append(FmuVariable(f"wheel_speed_{k}", "input", "rad/s",
                             f"angular speed of wheelset {k}", 0.0))
        if pressure:
            v.append(FmuVariable(f"brake_pressure_{k}", "input", "Pa",
                                 f"brake-cylinder pressure of axle {k}", 0.0))
        if torque:
            v.append(FmuVariable(f"torque_{k}", "input", "N.m",
                                 f"torque on wheelset {k} (traction > 0, electric brake < 0)",
                                 0.0))
    v.append(FmuVariable("vehicle_level", "output", "1",
                         "most severe axle level: 0 unknown, 1 normal, 2 caution, 3 low"))
    for k in range(1, n_axles + 1):
        v += [FmuVariable(f"{name}_{k}", "output", unit, text.format(k=k))
              for name, (_, unit, text) in _AXLE_OUTPUTS.items()]  # fmt: skip
    return v


def build_monitor_fmu(out, vehicle="coach_default", settings=None, *, pressure=True,
                      torque=False) -> Path:
    """Write an FMI 2.0 co-simulation FMU of the adhesion monitor.

    Parameters
    ----------
    out : str or os.PathLike
        The ``.fmu`` file to write.
    vehicle : Vehicle or str
        The vehicle (object, TOML file or shipped name); embedded as ``resources/vehicle.toml``.
    settings : MonitorSettings, optional
        Embedded as ``resources/monitor_settings.json``; ``sample_period`` should be the
        master's communication step.
    pressure, torque : bool
        Input channels: brake pressures and/or torques (all axles).

    Returns
    -------
    pathlib.Path
        The path of the monitor FMU written (``out``): FMI 2.0 co-simulation, Python inside.

    Notes
    -----
    Each ``doStep(t, h)`` writes the inputs into the monitor and calls
    :meth:`~railadhesion.monitor.AdhesionMonitor.step` at ``t + h``, so the outputs equal
    those of the per-sample call driven with the same inputs (tested under FMPy).
    """
    import railadhesion
    from railadhesion.braking import Vehicle, load_vehicle
    from railadhesion.monitor import MonitorSettings

    if not isinstance(vehicle, Vehicle):
        vehicle = load_vehicle(vehicle)
    settings = instance_or_default(settings, MonitorSettings, "settings", MonitorSettings)
    if not (pressure or torque):
        raise ValueError("the FMU needs brake-pressure or torque inputs (pressure or torque)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / _VEHICLE_FILE
        vehicle.to_toml(path)
        vehicle_text = path.read_text(encoding="utf-8")
    settings_text = json.dumps(settings.to_dict(), indent=2)
    variables = monitor_fmu_variables(vehicle.n_axles, pressure, torque)
    sha = hashlib.sha256((vehicle_text + settings_text).encode("utf-8")).hexdigest()
    channels = " and ".join(c for c, on in (("brake pressures", pressure), ("torques", torque))
                            if on)
    description = (
        f"railadhesion {railadhesion.__version__}: on-board adhesion monitor for vehicle "
        f"'{vehicle.name}' ({vehicle.n_axles} axles); inputs: speed reference, wheel speeds, "
        f"{channels}; outputs per axle: creepage, adhesion in use, available adhesion with its "
        f"band, level (threshold {settings.threshold:g}) and reason. One monitor sample per "
        f"doStep (sample period {settings.sample_period:g} s)."
    )
    config = {
        "vehicle_file": _VEHICLE_FILE, "settings_file": _SETTINGS_FILE,
        "pressure": bool(pressure), "torque": bool(torque),
        "railadhesion_version": railadhesion.__version__, "description": description,
        "fmu_version": f"railadhesion {railadhesion.__version__}, monitor {sha[:12]}",
        "variables": [v.to_config() for v in variables],
    }
    meta = ET.Element("Monitor", {"vehicle": vehicle.name, "sha256": sha,
                                  "threshold": repr(settings.threshold),
                                  "samplePeriod": repr(settings.sample_period),
                                  "railadhesionVersion": railadhesion.__version__})
    return build_fmu(
        Path(__file__).with_name("railadhesion_monitor.py"), variables, out,
        resources={CONFIG_FILE: json.dumps(config, indent=2), _VEHICLE_FILE: vehicle_text,
                   _SETTINGS_FILE: settings_text},
        documentation=_documentation(description, variables, settings_text), metadata=meta,
    )


def _documentation(description, variables, settings_text) -> str:
    from railadhesion.monitor.layout import REASONS

    esc = html.escape
    reasons = "".join(f"<tr><td>{code}</td><td>{esc(label)}</td><td>{esc(text)}</td></tr>"
                      for code, (label, text) in sorted(REASONS.items()))
    return documentation_page(
        "Adhesion monitor FMU",
        f"<p>{esc(description)}</p>\n<p>{RUNS_PYTHON}</p>\n{variables_table(variables)}\n"
        "<h2>Reason codes</h2>\n<table border='1'><tr><th>code</th><th>label</th>"
        f"<th>sentence (its values v1, v2)</th></tr>{reasons}</table>\n"
        f"<h2>Settings</h2>\n<pre>{esc(settings_text)}</pre>\n",
    )


# --------------------------------------------------------------------------------------------
# Native (Python-free) FMU of the monitor


def _native_records(config):
    """(state, inputs) dtypes of the native FMU: the state holds the monitor's own records
    (its input record, state, outputs and estimator bank) and the time since the start."""
    from railadhesion.monitor import layout

    a = (layout.MAX_AXLES,)
    state_t = np.dtype([("time", "f8"), ("inp", layout.INPUT_DTYPE),
                        ("st", layout.STATE_DTYPE), ("out", layout.OUTPUT_DTYPE),
                        ("bank", "f8", (3, layout.MAX_AXLES, layout.NODES))], align=True)
    inputs_t = np.dtype([("train_speed", "f8"), ("wheel_speed", "f8", a),
                         ("brake_pressure", "f8", a), ("torque", "f8", a)], align=True)
    return state_t, inputs_t


def _native_step(state_t, config_t, inputs_t, n_axles):
    """The step of the native FMU: one monitor sample at the time since the start."""
    from numba import carray

    from railadhesion.monitor.kernel import step_record

    def step(state, settings, inputs, dt):
        s = carray(state, 1, state_t)[0]
        c = carray(settings, 1, config_t)[0]
        x = carray(inputs, 1, inputs_t)[0]
        s.time += dt
        s.inp.time = s.time
        s.inp.train_speed = x.train_speed
        for i in range(n_axles):
            s.inp.wheel_speed[i] = x.wheel_speed[i]
            s.inp.brake_pressure[i] = x.brake_pressure[i]
            s.inp.torque[i] = x.torque[i]
        step_record(c, s.inp, s.st, s.out, s.bank)
        return 0  # bad data show in the levels and reasons: the step never fails

    return step


def monitor_step_model(vehicle="coach_default", settings=None, *, pressure=True,
                       torque=False):
    """The monitor as a :class:`railadhesion.export.native.StepModel` (for
    :func:`railadhesion.export.native.build_step_fmu`): the same compiled step
    (:func:`railadhesion.monitor.kernel.step_record`) on its own records."""
    from railadhesion.braking import Vehicle, load_vehicle
    from railadhesion.export.native import RecordVariable, StepModel
    from railadhesion.monitor import MonitorSettings
    from railadhesion.monitor.estimator import build_config

    if not isinstance(vehicle, Vehicle):
        vehicle = load_vehicle(vehicle)
    settings = settings if settings is not None else MonitorSettings()
    if not (pressure or torque):
        raise ValueError("the FMU needs brake-pressure or torque inputs (pressure or torque)")
    config = build_config(vehicle, settings, pressure, torque)
    state_t, inputs_t = _native_records(config)
    n = vehicle.n_axles
    state = np.zeros(1, state_t)
    rv = []
    for v in monitor_fmu_variables(n, pressure, torque):
        name = v.name
        if v.causality == "input":
            if name == "train_speed":
                rv.append(RecordVariable(v, "train_speed"))
            else:
                field, k = name.rsplit("_", 1)
                rv.append(RecordVariable(v, field, (int(k) - 1,)))
        elif name == "vehicle_level":
            rv.append(RecordVariable(v, "out.vehicle_level"))
        else:
            field, k = name.rsplit("_", 1)
            rv.append(RecordVariable(v, f"out.{_AXLE_OUTPUTS[field][0]}", (int(k) - 1,)))
    return StepModel(identifier="railadhesion_monitor",
                     step=_native_step(state_t, config.dtype, inputs_t, n), state=state,
                     settings=config, inputs=np.zeros(1, inputs_t), variables=rv)


def build_native_monitor_fmu(out, vehicle="coach_default", settings=None, *, pressure=True,
                             torque=False) -> Path:
    """Write a native FMI 2.0 co-simulation FMU of the adhesion monitor: no Python at run time.

    Same variables as :func:`build_monitor_fmu`; the vehicle, the settings and the compiled
    step are in the binary (linux64; sources in ``sources/``, see ``docs/fmu.md``). Building
    needs a C compiler. Differences from the Python FMU: the monitor's time is the time since
    the start (the sum of the steps), and the C layer refuses a NaN or infinite input with
    ``fmi2Error`` (a master signals a missing value by holding the last one or by a value the
    monitor calls implausible, e.g. a negative wheel speed); every other bad input is reported
    in the levels and reasons as by the per-sample call.

    Raises
    ------
    railadhesion.export.native.NativeBuildError
        No C compiler or FMI headers here, or the compiled step needs more than libm.
    """
    import railadhesion
    from railadhesion.export.native import build_step_fmu
    from railadhesion.monitor import MonitorSettings

    settings = instance_or_default(settings, MonitorSettings, "settings", MonitorSettings)
    model = monitor_step_model(vehicle, settings, pressure=pressure, torque=torque)
    variables = [r.variable for r in model.variables]
    description = (f"railadhesion {railadhesion.__version__}: on-board adhesion monitor, "
                   f"native (no Python at run time); threshold {settings.threshold:g}, sample "
                   f"period {settings.sample_period:g} s (one sample per doStep).")
    return build_step_fmu(model, out, model_name="railadhesion adhesion monitor (native)",
                          description=description,
                          documentation=_documentation(description, variables,
                                                       json.dumps(settings.to_dict(), indent=2)),
                          step_size=settings.sample_period)
