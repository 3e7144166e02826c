"""Odometry test bench: a programme of low-adhesion runs, each with several sensor fits, on any
odometry (issue 23).

A *programme* (TOML, ``format = "railadhesion-odometry-programme"``; every field in
``docs/odometry.md``; the shipped ``default`` programme) lists runs of the braking simulator:
the vehicle and rail of a WSP-bench case (:mod:`railadhesion.braking.bench`: the same fields,
read by the same code), the default WSP in the loop, an optional traction phase with a torque
per axle (wheel spin), and the *fits*: sensor configurations of the odometry (radar and
accelerometer or not, encoder dropouts, faults). The vehicle runs once per case; every fit
has its own sensors (:mod:`railadhesion.braking.sensors`, seeded) and its own odometry
instance, called every odometry period with what its sensors read: the wheel speeds and
pulse counts of the chosen axles, the radar speed, the accelerometer, and the command
(``drive``: -1 brake, 0 none, +1 traction). The odometry never sees the true speed.

Per case and fit it reports the speed error (max and RMS), the distance error at the stop,
whether the true position stayed inside the odometry's interval at every sample (the safety
property; every violation listed with its time and size), the interval at the stop, the
status flags, the time the odometry's axles slid or spun, and checks against the criteria:
inside the interval, stop error, and for fits with bad input that it was flagged and that the
interval did not narrow against a healthy fit. JSON, CSV and figures are written after every
case; a fit whose odometry fails (bad output, an exception) is recorded with its message and
the others go on.
"""

from __future__ import annotations

import copy
import math
import os
import time as _time
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from railadhesion.braking._bench_common import (
    ProgrammeResult,
    ProgrammeRun,
    case_field,
    fmu_variable_problems,
    load_component,
    read_cosim_fmu,
    read_programme_file,
    release_fmu,
    save_figure,
    select_cases,
    whole_multiple,
    write_case,
    write_summary,
)
from railadhesion.braking._fields import (
    FieldError,
    boolean,
    integer,
    keys,
    number,
    string,
    table,
)
from railadhesion.braking.bench import (
    BenchCase,
    load_controller,
    programme_from_document,
)
from railadhesion.braking.odometry import STATUS_BITS, ReferenceOdometry
from railadhesion.braking.sensors import (
    FAULT_KINDS,
    AccelerometerSettings,
    EncoderFault,
    EncoderSettings,
    ExternalSpeedSettings,
    SensorModel,
    accelerometer,
    measure,
)
from railadhesion.braking.simulator import BrakingSimulator, SimulationError

__all__ = [
    "PROGRAMME_FORMAT",
    "STANDARD_FITS",
    "SensorFit",
    "OdometryCase",
    "OdometryProgramme",
    "OdometryProgrammeResult",
    "OdometryInterfaceError",
    "FmuOdometry",
    "check_output",
    "load_odometry_programme",
    "load_odometry",
    "run_odometry_case",
    "run_odometry_programme",
    "write_odometry_outputs",
    "SLIDE_CREEP",
]

PROGRAMME_FORMAT = "railadhesion-odometry-programme"
#: The four fits of every case unless it names others: (radar, accelerometer).
STANDARD_FITS = {"wheels": (False, False), "radar": (True, False),
                 "accelerometer": (False, True), "radar+accelerometer": (True, True)}
#: An odometry axle counts as sliding (spinning) while its creepage is above (below minus) this.
SLIDE_CREEP = 0.02


class OdometryInterfaceError(ValueError):
    """An odometry under test misbehaved; the message names the time, the signal and the value."""


# -- programme ------------------------------------------------------------------------------
# [sensors] and fit keys: (default, low, high); the encoder and radar defaults are those of
# railadhesion.braking.sensors (their sources there), the accelerometer's too.
_SENSOR_KEYS = {
    "pulses_per_revolution": (80.0, 0.0, 1e4),
    "edge_jitter": (0.005, 0.0, 0.5),
    "clock_resolution_s": (1e-6, 0.0, 1e-3),
    "diameter_error": (0.01, 0.0, 0.05),
    "diameter_drift_per_km": (0.0, 0.0, 1e-3),
    "dropout_probability": (0.0, 0.0, 0.5),
    "accelerometer_bias_m_s2": (0.005, -1.0, 1.0),
    "accelerometer_noise_m_s2": (0.05, 0.0, 5.0),
    "accelerometer_range_m_s2": (19.6, 0.0, 1000.0),
    "radar_noise_m_s": (0.13, 0.0, 10.0),
    "radar_latency_s": (0.05, 0.0, 5.0),
    "radar_period_s": (0.02, 1e-4, 5.0),
    "radar_min_speed_m_s": (0.3, 0.0, 10.0),
    "radar_dropout_probability": (0.0, 0.0, 1.0),
    "radar_scale_error": (0.0, -0.2, 0.2),
}
_RUN_KEYS = {  # odometry keys of [defaults] or a case: default
    "coast_time_s": 2.0,
    "traction_torque_N_m": 0.0,
    "traction_time_s": 0.0,
    "release_time_s": 0.0,
    "wsp": "default",
    "odometry_axles": [1, 4],
    "fits": list(STANDARD_FITS),
}
_CRITERIA_KEYS = ("max_stop_error_fraction", "require_inside")
_FIT_KEYS = ("name", "base", "radar", "accelerometer", "fault", "radar_outage_s", "baseline",
             "expect_status", "seed", "max_stop_error_fraction", "require_inside",
             *_SENSOR_KEYS)


@dataclass(frozen=True)
class SensorFit:
    """The odometry's sensors in one fit of a case, its fault if any, and its criteria."""

    name: str
    sensors: SensorModel
    radar: bool = False
    accelerometer: bool = False
    fault_start: float = math.nan
    baseline: str | None = None
    expect_status: int = 0
    max_stop_error_fraction: float = math.inf
    require_inside: bool = True

    def describe(self) -> dict:
        return {"fit": self.name, "radar": self.radar, "accelerometer": self.accelerometer,
                "fault_start_s": self.fault_start, "baseline": self.baseline,
                "expect_status": self.expect_status, "sensors": self.sensors.describe()}


@dataclass(frozen=True)
class OdometryCase:
    """One vehicle run of a programme and the fits evaluated on it."""

    run: BenchCase
    fits: tuple
    axles: tuple = (1, 4)
    coast_time: float = 2.0
    traction_torque: float = 0.0
    traction_time: float = 0.0
    release_time: float = 0.0
    wsp: bool = True

    @property
    def name(self) -> str:
        return self.run.name

    def command(self, t: float) -> tuple[float, float, float]:
        """(drive, pressure [Pa], torque per axle [N m]) at time t."""
        if t < self.coast_time:
            return 0.0, 0.0, 0.0
        t -= self.coast_time
        if t < self.traction_time:
            return (1.0 if self.traction_torque > 0 else 0.0), 0.0, self.traction_torque
        if t < self.traction_time + self.release_time:
            return 0.0, 0.0, 0.0
        return -1.0, self.run.pressure, 0.0

    def describe(self) -> dict:
        return {**self.run.describe(), "odometry_axles": list(self.axles),
                "coast_time_s": self.coast_time, "traction_torque_N_m": self.traction_torque,
                "traction_time_s": self.traction_time, "release_time_s": self.release_time,
                "wsp": "default" if self.wsp else "none"}


@dataclass
class OdometryProgramme:
    name: str
    cases: list
    description: str = ""
    source: str = ""

    def select(self, names) -> OdometryProgramme:
        """The programme with the named cases only (in the programme's order)."""
        return select_cases(self, names)


def _sensor_values(tab, where, base) -> dict:
    out = dict(base)
    for key, (_, lo, hi) in _SENSOR_KEYS.items():
        if key in tab:
            open_low = key in ("accelerometer_range_m_s2",)
            out[key] = number(tab[key], f"{where}.{key}", lo, hi, low_open=open_low)
    ppr = out["pulses_per_revolution"]
    if 0 < ppr < 4:
        raise FieldError(f"{where}.pulses_per_revolution", f"must be 0 or in [4, 10000], got "
                         f"{ppr!r}")
    return out


def _expect(value, where) -> int:
    if isinstance(value, int) and not isinstance(value, bool):
        return integer(value, where, 0, 2**31 - 1)
    if not isinstance(value, list):
        raise FieldError(where, "expected a list of status names or an integer bit mask")
    mask = 0
    for k, name in enumerate(value):
        name = string(name, f"{where}[{k}]")
        if name not in STATUS_BITS:
            raise FieldError(f"{where}[{k}]", f"unknown status {name!r}; known: "
                             f"{', '.join(STATUS_BITS)}")
        mask |= STATUS_BITS[name]
    return mask


def _fit(raw, where, values, criteria, n_axles, seed) -> SensorFit:
    if isinstance(raw, str):
        if raw not in STANDARD_FITS:
            raise FieldError(where, f"unknown fit {raw!r}; the standard fits are "
                             f"{', '.join(STANDARD_FITS)} (or give a table)")
        raw = {"name": raw, "base": raw}
    tab = table(raw, where)
    keys(tab, where, ("name",), _FIT_KEYS)
    name = string(tab["name"], f"{where}.name")
    if not name or any(ch in name for ch in '/\\:*?"<>|'):
        raise FieldError(f"{where}.name", f"must be a non-empty name usable in a file name, "
                         f"got {name!r}")
    radar = accel = False
    if "base" in tab:
        base = string(tab["base"], f"{where}.base")
        if base not in STANDARD_FITS:
            raise FieldError(f"{where}.base", f"must be one of {', '.join(STANDARD_FITS)}, got "
                             f"{base!r}")
        radar, accel = STANDARD_FITS[base]
    elif name in STANDARD_FITS:
        radar, accel = STANDARD_FITS[name]
    if "radar" in tab:
        radar = boolean(tab["radar"], f"{where}.radar")
    if "accelerometer" in tab:
        accel = boolean(tab["accelerometer"], f"{where}.accelerometer")
    v = _sensor_values(tab, where, values)
    fault = None
    start = math.nan
    if "fault" in tab:
        ft = table(tab["fault"], f"{where}.fault")
        keys(ft, f"{where}.fault", ("axle", "kind", "start_s"))
        axle = integer(ft["axle"], f"{where}.fault.axle", 1, n_axles)
        kind = string(ft["kind"], f"{where}.fault.kind")
        if kind not in FAULT_KINDS:
            raise FieldError(f"{where}.fault.kind", f"must be one of {', '.join(FAULT_KINDS)}, "
                             f"got {kind!r}")
        start = number(ft["start_s"], f"{where}.fault.start_s", 0.0, 1e5)
        fault = EncoderFault(axle, kind, start)
    outage = None
    if "radar_outage_s" in tab:
        o = tab["radar_outage_s"]
        w = f"{where}.radar_outage_s"
        if not isinstance(o, list) or len(o) != 2:
            raise FieldError(w, "expected [start, end] in seconds")
        a = number(o[0], f"{w}[0]", 0.0, 1e5)
        b = number(o[1], f"{w}[1]", a, 1e5, low_open=True)
        outage = (a, b)
        start = a if math.isnan(start) else min(start, a)
    if v["dropout_probability"] > 0 and "dropout_probability" in tab:
        start = 0.0 if math.isnan(start) else start
    if "radar_dropout_probability" in tab and v["radar_dropout_probability"] > 0:
        start = 0.0 if math.isnan(start) else start
    if "accelerometer_range_m_s2" in tab or "accelerometer_bias_m_s2" in tab:
        start = 0.0 if math.isnan(start) else start
    if (outage is not None or "radar_dropout_probability" in tab) and not radar:
        raise FieldError(f"{where}.radar", "a radar outage or dropout needs radar = true")
    if ("accelerometer_range_m_s2" in tab or "accelerometer_bias_m_s2" in tab) and not accel:
        raise FieldError(f"{where}.accelerometer", "accelerometer settings need "
                         "accelerometer = true")
    errors = tuple(v["diameter_error"] if i % 2 == 0 else -v["diameter_error"]
                   for i in range(n_axles))
    enc = EncoderSettings(v["pulses_per_revolution"], v["edge_jitter"], v["clock_resolution_s"],
                          errors, 0.0, 0.0, v["dropout_probability"],
                          v["diameter_drift_per_km"])
    ext = ExternalSpeedSettings(v["radar_noise_m_s"], v["radar_latency_s"], v["radar_period_s"],
                                v["radar_min_speed_m_s"], v["radar_dropout_probability"],
                                v["radar_scale_error"], outage) if radar else None
    acc = AccelerometerSettings(v["accelerometer_bias_m_s2"], v["accelerometer_noise_m_s2"],
                                v["accelerometer_range_m_s2"]) if accel else None
    fit_seed = integer(tab["seed"], f"{where}.seed", 0, 2**63 - 1) if "seed" in tab else seed
    try:
        if ext is not None and ext.latency / ext.period > 60:
            raise ValueError("radar_latency_s / radar_period_s must be at most 60")
        model = SensorModel(enc, ext, fit_seed, acc, () if fault is None else (fault,))
    except ValueError as exc:
        raise FieldError(where, str(exc)) from None
    baseline = string(tab["baseline"], f"{where}.baseline") if "baseline" in tab else None
    expect = _expect(tab["expect_status"], f"{where}.expect_status") if (
        "expect_status" in tab) else 0
    crit = _criteria(tab, where, criteria)
    return SensorFit(name, model, radar, accel, start, baseline, expect,
                     crit["max_stop_error_fraction"], crit["require_inside"])


def _criteria(tab, where, base) -> dict:
    out = dict(base)
    if "max_stop_error_fraction" in tab:
        out["max_stop_error_fraction"] = number(tab["max_stop_error_fraction"],
                                                f"{where}.max_stop_error_fraction", 0.0, 10.0)
    if "require_inside" in tab:
        out["require_inside"] = boolean(tab["require_inside"], f"{where}.require_inside")
    return out


def _programme_from_document(doc, base: Path) -> OdometryProgramme:
    keys(doc, "", ("format", "version", "case"), ("name", "description", "defaults",
                                                   "criteria", "sensors", "wsp"))
    if doc["format"] != PROGRAMME_FORMAT:
        raise FieldError("format", f"expected {PROGRAMME_FORMAT!r}, got {doc['format']!r}")
    integer(doc["version"], "version", 1, 1)
    defaults = dict(table(doc.get("defaults", {}), "defaults"))
    odo_defaults = {k: defaults.pop(k) for k in list(defaults) if k in _RUN_KEYS}
    crit_tab = table(doc.get("criteria", {}), "criteria")
    keys(crit_tab, "criteria", (), _CRITERIA_KEYS)
    criteria = _criteria(crit_tab, "criteria", {"max_stop_error_fraction": math.inf,
                                                "require_inside": True})
    sens_tab = table(doc.get("sensors", {}), "sensors")
    keys(sens_tab, "sensors", (), tuple(_SENSOR_KEYS))
    sensor_values = _sensor_values(sens_tab, "sensors",
                                   {k: v[0] for k, v in _SENSOR_KEYS.items()})
    cases = doc["case"]
    if not isinstance(cases, list) or not cases:
        raise FieldError("case", "expected one or more [[case]] tables")
    wsp_cases = []
    extras = []
    for k, raw in enumerate(cases):
        tab = dict(table(raw, f"case[{k}]"))
        extras.append({key: tab.pop(key) for key in list(tab)
                       if key in _RUN_KEYS or key == "criteria"})
        wsp_cases.append(tab)
    wsp_doc = {"format": "railadhesion-wsp-programme", "version": 1,
               "name": doc.get("name", ""), "description": doc.get("description", ""),
               "defaults": defaults, "case": wsp_cases}
    if "wsp" in doc:
        wsp_doc["wsp"] = doc["wsp"]
    # its BrakingFileError (a ValueError) names the field; read_programme_file adds the file
    runs = programme_from_document(wsp_doc, base)
    out = []
    for k, (run, extra) in enumerate(zip(runs.cases, extras, strict=True)):
        where = f"case[{k}] ({run.name})"
        get = partial(case_field, tab=extra, defaults=odo_defaults, fallback=_RUN_KEYS,
                      where=where)
        n = run.vehicle.n_axles
        coast = number(*get("coast_time_s"), 0.1, 600.0)
        torque = number(*get("traction_torque_N_m"), 0.0, 1e5)
        t_trac = number(*get("traction_time_s"), 0.0, 600.0)
        t_rel = number(*get("release_time_s"), 0.0, 600.0)
        value, w = get("wsp")
        wsp = string(value, w)
        if wsp not in ("default", "none"):
            raise FieldError(w, f"must be 'default' or 'none', got {wsp!r}")
        value, w = get("odometry_axles")
        if not isinstance(value, list) or not value:
            raise FieldError(w, "expected a list of axle numbers")
        axles = tuple(integer(a, f"{w}[{j}]", 1, n) for j, a in enumerate(value))
        if len(set(axles)) != len(axles):
            raise FieldError(w, f"axles must differ, got {list(axles)}")
        case_criteria = criteria
        if "criteria" in extra:
            ct = table(extra["criteria"], f"{where}.criteria")
            keys(ct, f"{where}.criteria", (), _CRITERIA_KEYS)
            case_criteria = _criteria(ct, f"{where}.criteria", criteria)
        value, w = get("fits")
        if not isinstance(value, list) or not value:
            raise FieldError(w, "expected a list of fits (names or tables)")
        fits = [_fit(f, f"{w}[{j}]", sensor_values, case_criteria, n, run.seed)
                for j, f in enumerate(value)]
        names = [f.name for f in fits]
        for j, f in enumerate(fits):
            if f.name in names[:j]:
                raise FieldError(f"{w}[{j}].name", f"duplicate fit name {f.name!r}")
            if f.baseline is not None and f.baseline not in names:
                raise FieldError(f"{w}[{j}].baseline", f"no fit named {f.baseline!r} in this "
                                 f"case; fits: {', '.join(names)}")
        out.append(OdometryCase(run, tuple(fits), axles, coast, torque, t_trac, t_rel,
                                wsp == "default"))
    return OdometryProgramme(runs.name, out, runs.description)


def load_odometry_programme(path="default") -> OdometryProgramme:
    """Read and check an odometry programme (``"default"``: the shipped one). Errors are
    :class:`~railadhesion.braking.BrakingFileError` naming the file and the field."""
    return read_programme_file(path, "odometry_programme_default.toml", _programme_from_document)


# -- odometries ------------------------------------------------------------------------------
_OUTPUTS = ("speed", "distance", "distance_min", "distance_max", "status")


def check_output(raw, t: float, label: str) -> np.ndarray:
    """An odometry's output as ``(speed, distance, distance_min, distance_max, status)``;
    errors name the time, the signal and the value."""
    out = np.zeros(5)
    try:
        if isinstance(raw, dict):
            missing = [k for k in _OUTPUTS[:4] if k not in raw]
            if missing:
                raise OdometryInterfaceError(f"{label} returned no {', '.join(missing)} at "
                                             f"t = {t:.6g} s")
            values = [raw[k] for k in _OUTPUTS[:4]] + [raw.get("status", 0)]
        else:
            if raw is None or np.ndim(raw) != 1:
                raise TypeError
            values = list(raw)
            if len(values) not in (4, 5):
                raise OdometryInterfaceError(
                    f"{label} returned {len(values)} values at t = {t:.6g} s; expected 4 or 5: "
                    "speed, distance, distance_min, distance_max[, status]")
            if len(values) == 4:
                values.append(0)
        for k, (name, x) in enumerate(zip(_OUTPUTS, values, strict=True)):
            if isinstance(x, bool) or not isinstance(x, int | float | np.number):
                raise OdometryInterfaceError(f"{label} returned {name} = {x!r} at t = {t:.6g} s;"
                                             " expected a number")
            out[k] = float(x)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, OdometryInterfaceError):
            raise
        raise OdometryInterfaceError(f"{label} returned {raw!r} at t = {t:.6g} s; expected "
                                     "(speed, distance, distance_min, distance_max[, status])"
                                     ) from None
    speed, dist, lo, hi, status = (float(v) for v in out)
    for name, x in (("speed", speed), ("distance", dist)):
        if not math.isfinite(x):
            raise OdometryInterfaceError(f"{label} returned {name} = {x!r} at t = {t:.6g} s; "
                                         "expected a finite number")
    if math.isnan(lo) or lo == math.inf:
        raise OdometryInterfaceError(f"{label} returned distance_min = {lo!r} at t = {t:.6g} s;"
                                     " expected a number (or -inf: no lower bound)")
    if math.isnan(hi) or hi == -math.inf:
        raise OdometryInterfaceError(f"{label} returned distance_max = {hi!r} at t = {t:.6g} s;"
                                     " expected a number (or inf: no upper bound)")
    if lo > hi:
        raise OdometryInterfaceError(f"{label} returned distance_min = {lo!r} > distance_max = "
                                     f"{hi!r} at t = {t:.6g} s")
    if not (math.isfinite(status) and status >= 0 and status == int(status)):
        raise OdometryInterfaceError(f"{label} returned status = {status!r} at t = {t:.6g} s; "
                                     "expected a non-negative integer")
    return out


class _ReferenceSession:
    def __init__(self, odo: ReferenceOdometry):
        self.odo = odo

    def step(self, t, omega, pulses, radar, accel, drive):
        return self.odo.step_record(t, omega, radar, accel, drive)

    def close(self):
        pass


class _PythonSession:
    def __init__(self, obj, label):
        self.obj = obj
        self.label = label

    def step(self, t, omega, pulses, radar, accel, drive):
        try:
            raw = self.obj(t, omega.copy(), pulses.copy(), radar, accel, drive)
        except Exception as exc:
            raise OdometryInterfaceError(f"{self.label} raised {type(exc).__name__} at "
                                         f"t = {t:.6g} s: {exc}") from exc
        return check_output(raw, t, self.label)

    def close(self):
        close = getattr(self.obj, "close", None)
        if callable(close):
            close()


class _PythonOdometry:
    """A user's odometry object (``period``, ``reset``, ``__call__``) or class; every fit gets
    its own copy (a class: a new instance)."""

    def __init__(self, obj, period=None):
        self.obj = obj
        proto = obj() if isinstance(obj, type) else obj
        p = getattr(proto, "period", period)
        if p is None or isinstance(p, bool) or not (isinstance(p, int | float)
                                                    and math.isfinite(p) and p > 0):
            raise ValueError("the odometry needs a period: give it a 'period' attribute [s] or "
                             f"pass period, got {p!r}")
        if not callable(proto):
            raise ValueError(f"the odometry {obj!r} is not callable")
        self.period = float(p)
        self.label = getattr(proto, "label", None) or type(proto).__qualname__

    def session(self, case: OdometryCase, fit: SensorFit):
        obj = self.obj() if isinstance(self.obj, type) else copy.deepcopy(self.obj)
        reset = getattr(obj, "reset", None)
        if reset is not None:
            try:
                reset(case.axles, case.run.vehicle.wheel_radius,
                      fit.sensors.encoders.pulses_per_revolution, case.run.gradient)
            except Exception as exc:
                raise OdometryInterfaceError(f"{self.label}: reset raised {type(exc).__name__}: "
                                             f"{exc}") from exc
        if isinstance(obj, ReferenceOdometry):
            return _ReferenceSession(obj)
        return _PythonSession(obj, self.label)

    def close(self):
        pass


class FmuOdometry:
    """An odometry delivered as an FMI 2.0 co-simulation FMU, run with FMPy.

    Variables (``i`` the number of an axle the programme gives the odometry): inputs
    ``wheel_speed_i`` [rad/s] or ``pulse_count_i`` (pulses since the start; Real or Integer)
    for each, at least one of the two; outputs ``speed`` [m/s], ``distance``, ``distance_min``,
    ``distance_max`` [m], all required; optional inputs ``radar_speed`` [m/s] (NaN without a
    sample), ``acceleration`` [m/s²] (NaN without an accelerometer), ``drive`` (-1, 0, +1), an
    optional output ``status`` (Integer or Real) and optional parameters ``wheel_radius`` [m],
    ``pulses_per_revolution`` and ``gradient``. Every odometry period the bench sets the inputs
    of time t, calls ``doStep(t, period)`` and reads the outputs for t. Every fit runs its own
    instance. ``period``: the FMU's DefaultExperiment step size, else 5 ms.
    """

    def __init__(self, path, period: float | None = None):
        self.path, self.md, self.vars, self.period = read_cosim_fmu(path, period,
                                                                    "FMU odometries")
        from fmpy import extract

        self.label = f"FMU {self.path.name}"
        self.dir = extract(str(self.path))

    def _check(self, axles):
        v = self.vars
        missing = []
        for i in axles:
            if f"wheel_speed_{i}" not in v and f"pulse_count_{i}" not in v:
                missing.append(f"wheel_speed_{i} (or pulse_count_{i})")
        for name in _OUTPUTS[:4]:
            if name not in v:
                missing.append(name)
        problems = fmu_variable_problems(
            v, missing, [*((f"wheel_speed_{i}", "input") for i in axles),
                          *((f"pulse_count_{i}", "input") for i in axles),
                          *((n, "input") for n in ("radar_speed", "acceleration", "drive")),
                          *((n, "output") for n in _OUTPUTS)])
        if problems:
            axl = ", ".join(str(i) for i in axles)
            raise OdometryInterfaceError(
                f"{self.path.name}: the FMU {problems}; an odometry FMU reading axles "
                f"{axl} needs inputs wheel_speed_i [rad/s] or pulse_count_i for each, outputs "
                "speed, distance, distance_min, distance_max; optional inputs radar_speed, "
                "acceleration, drive and output status")

    def session(self, case: OdometryCase, fit: SensorFit):
        from fmpy.fmi2 import FMU2Slave

        self._check(case.axles)
        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                        modelIdentifier=self.md.coSimulation.modelIdentifier,
                        instanceName=f"odometry_{fit.name}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        for name, value in (("wheel_radius", case.run.vehicle.wheel_radius),
                            ("pulses_per_revolution", fit.sensors.encoders.pulses_per_revolution),
                            ("gradient", case.run.gradient)):
            if name in self.vars:
                fmu.setReal([self.vars[name].valueReference], [float(value)])
        fmu.exitInitializationMode()
        return _FmuSession(self, fmu, case.axles)

    def close(self):
        import shutil

        shutil.rmtree(self.dir, ignore_errors=True)


class _FmuSession:
    def __init__(self, owner, fmu, axles):
        v = owner.vars
        self.fmu = fmu
        self.label = owner.label
        self.period = owner.period
        self.w = [(k, v[f"wheel_speed_{i}"].valueReference) for k, i in enumerate(axles)
                  if f"wheel_speed_{i}" in v]
        self.p_real = [(k, v[f"pulse_count_{i}"].valueReference) for k, i in enumerate(axles)
                       if f"pulse_count_{i}" in v and v[f"pulse_count_{i}"].type == "Real"]
        self.p_int = [(k, v[f"pulse_count_{i}"].valueReference) for k, i in enumerate(axles)
                      if f"pulse_count_{i}" in v and v[f"pulse_count_{i}"].type != "Real"]
        self.extra = [(n, v[n].valueReference, v[n].type) for n in ("radar_speed",
                                                                     "acceleration", "drive")
                      if n in v]
        self.out = [v[n].valueReference for n in _OUTPUTS[:4]]
        self.status = (v["status"].valueReference, v["status"].type) if "status" in v else None

    def step(self, t, omega, pulses, radar, accel, drive):
        f = self.fmu
        if self.w:
            f.setReal([r for _, r in self.w], [float(omega[k]) for k, _ in self.w])
        if self.p_real:
            f.setReal([r for _, r in self.p_real], [float(pulses[k]) for k, _ in self.p_real])
        if self.p_int:
            f.setInteger([r for _, r in self.p_int],
                         [int(pulses[k]) if math.isfinite(pulses[k]) else 0
                          for k, _ in self.p_int])
        for name, ref, kind in self.extra:
            value = {"radar_speed": radar, "acceleration": accel, "drive": drive}[name]
            if kind == "Real":
                f.setReal([ref], [float(value)])
            else:
                f.setInteger([ref], [int(value) if math.isfinite(value) else 0])
        status = f.doStep(currentCommunicationPoint=t, communicationStepSize=self.period)
        if status not in (0, None):
            raise OdometryInterfaceError(f"{self.label}: doStep at t = {t:.6g} s returned "
                                         f"status {status}")
        values = list(f.getReal(self.out))
        if self.status is not None:
            ref, kind = self.status
            values.append(f.getReal([ref])[0] if kind == "Real" else f.getInteger([ref])[0])
        return check_output(values, t, self.label)

    def close(self):
        release_fmu(self.fmu)


def load_odometry(spec=None, *, period: float | None = None):
    """An odometry for the bench: ``None`` or ``"reference"`` (:class:`ReferenceOdometry`), a
    path ending in ``.fmu`` (:class:`FmuOdometry`), ``"module:name"`` or ``"file.py:name"`` (an
    object or class with ``period``, ``reset`` and ``__call__``: docs/odometry.md), or such an
    object or class itself."""
    if spec is None or spec == "reference":
        return _PythonOdometry(ReferenceOdometry())
    if isinstance(spec, _PythonOdometry | FmuOdometry):
        return spec
    if isinstance(spec, str | os.PathLike):
        text = os.fspath(spec)
        if text.lower().endswith(".fmu"):
            return FmuOdometry(text, period)
        return _PythonOdometry(load_component(text, "odometry", "reference", "odometry_"),
                               period)
    return _PythonOdometry(spec, period)


# -- one case ---------------------------------------------------------------------------------
def _events(t, below, above):
    """Violations grouped into events: start, end, time and size of the worst sample, side."""
    out = []
    for side, size in (("below distance_min", below), ("above distance_max", above)):
        bad = size > 0
        if not np.any(bad):
            continue
        edges = np.flatnonzero(np.diff(np.r_[0, bad.astype(np.int8), 0]))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            k = a + int(np.argmax(size[a:b]))
            out.append({"side": side, "start_s": float(t[a]), "end_s": float(t[b - 1]),
                        "samples": int(b - a), "worst_time_s": float(t[k]),
                        "worst_size_m": float(size[k])})
    return sorted(out, key=lambda e: e["start_s"])


def _flag_summary(t, status):
    s = status.astype(np.int64)
    names = dict(STATUS_BITS)
    seen = int(np.bitwise_or.reduce(s)) if s.size else 0
    for k in range(31):
        bit = 1 << k
        if seen & bit and bit not in names.values():
            names[f"bit_{k}"] = bit
    out = {}
    dt = np.diff(t, append=t[-1]) if t.size else t
    for name, bit in names.items():
        on = (s & bit) != 0
        if np.any(on):
            out[name] = {"first_s": float(t[np.argmax(on)]), "time_s": float(np.sum(dt[on]))}
    return out


def _fit_report(fit: SensorFit, tr: dict, out: np.ndarray) -> dict:
    t, v, x = tr["time"], tr["speed"], tr["distance"]
    vh, xh, lo, hi, st = out.T
    below = np.where(x < lo, lo - x, 0.0)
    above = np.where(x > hi, x - hi, 0.0)
    tol = 1e-9 * np.maximum(1.0, np.abs(x))
    below[below <= tol] = 0.0
    above[above <= tol] = 0.0
    events = _events(t, below, above)
    dist = float(x[-1])
    stop_err = float(xh[-1] - x[-1])
    width = hi - lo
    rep = {
        **fit.describe(),
        "status": "ok",
        "speed_error_max_m_s": float(np.max(np.abs(vh - v))),
        "speed_error_rms_m_s": float(np.sqrt(np.mean((vh - v) ** 2))),
        "distance_error_max_m": float(np.max(np.abs(xh - x))),
        "distance_error_rms_m": float(np.sqrt(np.mean((xh - x) ** 2))),
        "stop_error_m": stop_err,
        "stop_error_fraction": stop_err / dist if dist > 0 else math.nan,
        "distance_min_at_stop_m": float(lo[-1]),
        "distance_max_at_stop_m": float(hi[-1]),
        "interval_width_at_stop_m": float(width[-1]),
        "interval_below_at_stop_m": float(x[-1] - lo[-1]),
        "interval_above_at_stop_m": float(hi[-1] - x[-1]),
        "inside": not events,
        "violation_samples": int(np.count_nonzero(below) + np.count_nonzero(above)),
        "violations": events,
        "worst_violation_m": max((e["worst_size_m"] for e in events), default=0.0),
        "estimate_outside_interval_samples": int(np.count_nonzero((xh < lo) | (xh > hi))),
        "flags": _flag_summary(t, st),
    }
    checks = {}
    if fit.require_inside:
        checks["inside"] = {"value": rep["violation_samples"], "limit": 0,
                            "passed": rep["inside"]}
    if math.isfinite(fit.max_stop_error_fraction):
        checks["stop_error"] = {"value": abs(rep["stop_error_fraction"]),
                                "limit": fit.max_stop_error_fraction,
                                "passed": bool(abs(rep["stop_error_fraction"])
                                               <= fit.max_stop_error_fraction)}
    if fit.expect_status:
        start = 0.0 if math.isnan(fit.fault_start) else fit.fault_start
        hit = (st.astype(np.int64) & fit.expect_status) != 0
        hit &= t >= start
        first = float(t[np.argmax(hit)]) if np.any(hit) else math.nan
        checks["flagged"] = {"value": first - start if np.any(hit) else math.nan,
                             "limit": fit.expect_status, "passed": bool(np.any(hit)),
                             "first_s": first}
    rep["checks"] = checks
    rep["_width"] = width
    return rep


def _widening(rep, base, fit, t):
    start = 0.0 if math.isnan(fit.fault_start) else fit.fault_start
    after = t >= start
    w, wb = rep["_width"][after], base["_width"][after]
    ok = np.isfinite(w) & np.isfinite(wb)
    if not np.any(ok):
        ratio = math.inf if np.any(~np.isfinite(w)) else math.nan
    else:
        ratio = float(np.mean(w[ok]) / np.mean(wb[ok])) if np.mean(wb[ok]) > 0 else math.nan
    rep["interval_widening_ratio"] = ratio
    rep["checks"]["widened"] = {"value": ratio, "limit": 1.0, "baseline": fit.baseline,
                                "passed": bool(ratio >= 1.0)}


def run_odometry_case(case: OdometryCase, odometry=None, *, wsp_settings=None):
    """Run one case: the vehicle once, every fit's sensors and odometry along. Returns
    ``(summary dict, traces)``; ``traces`` holds the truth per sample (``time``, ``speed``,
    ``distance``, ``creep`` of the odometry axles, ``drive``) and, per fit, the odometry's
    outputs (``outputs[fit]``: speed, distance, min, max, status). A fit whose odometry
    misbehaves is reported with ``status = "error"`` and its message."""
    odo = load_odometry(odometry) if not isinstance(odometry, _PythonOdometry | FmuOdometry) \
        else odometry
    started = _time.perf_counter()
    run = case.run
    vehicle = run.vehicle
    n = vehicle.n_axles
    ctrl = None
    if case.wsp:
        ctrl = load_controller(None, wsp_settings=wsp_settings)
        ctrl.prepare(run)
    base = odo.period if ctrl is None else ctrl.period
    ratio = whole_multiple(odo.period, base, "the odometry period", "the WSP's control period")
    whole_multiple(base, run.dt, "the control period", "the time step")
    sim = BrakingSimulator(vehicle, run.adhesion.build(), run.initial_speed,
                           cylinders=run.cylinders, gradient=run.gradient, max_step=run.dt,
                           record=False)
    live = sim.live
    inputs = sim.inputs
    w_sens = run.sensor_model()
    w_set, w_state = w_sens.settings_record(n), w_sens.state_record(n)
    idx = np.array(case.axles) - 1
    sessions = {}
    errors = {}
    records = {}
    for fit in case.fits:
        try:
            sessions[fit.name] = odo.session(case, fit)
        except (OdometryInterfaceError, ValueError) as exc:
            errors[fit.name] = f"{type(exc).__name__}: {exc}"
    fit_state = {f.name: (f.sensors.settings_record(n, gradient=run.gradient,
                                                    wheel_radius=vehicle.wheel_radius),
                          f.sensors.state_record(n), f.sensors.encoders.pulses_per_revolution)
                 for f in case.fits}
    nmax = int(math.ceil(run.max_time / base)) + 1
    n_out = nmax // ratio + 2
    trace_t = np.empty(n_out)
    trace_v = np.empty(n_out)
    trace_x = np.empty(n_out)
    trace_c = np.empty((n_out, idx.size))
    trace_d = np.empty(n_out)
    for fit in case.fits:
        records[fit.name] = np.full((n_out, 5), np.nan)
    omega_w = np.zeros(n)
    p_w = np.zeros(n)
    omega_o = np.zeros(n)
    p_o = np.zeros(n)
    command = np.zeros(n)
    label = getattr(odo, "label", "the odometry")
    k = 0
    j = 0
    final = False
    while True:
        t = k * base
        stopped = live.stopped
        if stopped or k >= nmax:
            final = True
        drive, pressure, torque = case.command(t)
        if ctrl is not None and not final:
            command[:] = pressure
            ext = measure(w_set, w_state, t, live.wheel_speeds, live.brake_pressures,
                          live.train_speed, -live.deceleration, omega_w, p_w)
            inputs.valves[:] = ctrl.step(t, omega_w, p_w, command, ext)
        if k % ratio == 0 or final:
            trace_t[j] = t
            trace_v[j] = 0.0 if stopped else live.train_speed
            trace_x[j] = sim.stop_distance if stopped else live.distance
            trace_c[j] = live.creep[idx]
            trace_d[j] = drive
            for fit in case.fits:
                name = fit.name
                if name not in sessions:
                    continue
                s_set, s_state, ppr = fit_state[name]
                radar = measure(s_set, s_state, t, live.wheel_speeds, live.brake_pressures,
                                trace_v[j], -live.deceleration, omega_o, p_o)
                acc = accelerometer(s_state)
                pulses = (s_state[0]["pulses"][idx].astype(float) if ppr > 0
                          else np.full(idx.size, np.nan))
                try:
                    records[name][j] = sessions[name].step(t, omega_o[idx], pulses, radar, acc,
                                                           drive)
                except OdometryInterfaceError as exc:
                    errors[name] = f"{type(exc).__name__}: {exc}"
                    sessions.pop(name).close()
            j += 1
        if final:
            break
        inputs.pressure_command[:] = pressure
        inputs.torque[:] = torque
        sim.advance(base)
        k += 1
    for s in sessions.values():
        s.close()
    tr = {"time": trace_t[:j], "speed": trace_v[:j], "distance": trace_x[:j],
          "creep": trace_c[:j], "drive": trace_d[:j],
          "outputs": {name: rec[:j] for name, rec in records.items()}}
    stopped = bool(live.stopped)
    creep = tr["creep"]
    dt = np.diff(tr["time"], append=tr["time"][-1])
    slide = np.any(creep > SLIDE_CREEP, axis=1)
    spin = np.any(creep < -SLIDE_CREEP, axis=1)
    summary = {
        **case.describe(),
        "odometry": label,
        "status": "ok" if stopped else "not stopped",
        "message": "the train stopped" if stopped else
        f"max_time = {run.max_time} s reached before the train stopped",
        "stopping_distance_m": float(tr["distance"][-1]),
        "stopping_time_s": float(sim.stop_time) if stopped else math.nan,
        "slide_time_s": float(np.sum(dt[slide])),
        "spin_time_s": float(np.sum(dt[spin])),
        "slide_definition": f"an odometry axle's creepage above {SLIDE_CREEP:g} (slide) or "
                            f"below {-SLIDE_CREEP:g} (spin)",
    }
    reports = {}
    for fit in case.fits:
        if fit.name in errors:
            reports[fit.name] = {**fit.describe(), "status": "error",
                                 "message": errors[fit.name], "passed": False, "checks": {}}
            continue
        reports[fit.name] = _fit_report(fit, tr, tr["outputs"][fit.name])
    for fit in case.fits:
        rep = reports[fit.name]
        if fit.baseline is not None and rep["status"] == "ok":
            base_rep = reports.get(fit.baseline, {})
            if base_rep.get("status") == "ok":
                _widening(rep, base_rep, fit, tr["time"])
            else:
                rep["checks"]["widened"] = {"value": math.nan, "limit": 1.0, "passed": False,
                                            "baseline": fit.baseline,
                                            "message": "the baseline fit did not run"}
    for rep in reports.values():
        rep.pop("_width", None)
        if rep["status"] == "ok":
            rep["passed"] = all(c["passed"] for c in rep["checks"].values())
    summary["fits"] = list(reports.values())
    summary["passed"] = stopped and all(r["passed"] for r in reports.values())
    summary["wall_time_s"] = _time.perf_counter() - started
    return summary, tr


# -- a programme --------------------------------------------------------------------------------
@dataclass
class OdometryProgrammeResult(ProgrammeResult):
    """Results of :func:`run_odometry_programme`: one summary per case (each with its fits;
    failed cases with ``status = "error"``) and the overall figures."""

    odometry: str
    cases: list
    overall: dict = field(default_factory=dict)

    def frame(self):
        """One row per case and fit (the scalar figures and the checks)."""
        import pandas as pd

        rows = []
        for c in self.cases:
            head = {"case": c["name"], "case_status": c.get("status"),
                    "stopping_distance_m": c.get("stopping_distance_m"),
                    "slide_time_s": c.get("slide_time_s"), "spin_time_s": c.get("spin_time_s")}
            for f in c.get("fits", []):
                row = {**head, **self.table_row(f)}
                row["flags"] = " ".join(f.get("flags", {}))
                rows.append(self.add_checks(row, f))
            if c.get("status") == "error":
                rows.append({**head, "fit": None, "status": "error", "message": c["message"]})
        return pd.DataFrame(rows)

    def violation_frame(self):
        """Every violation event of every case and fit."""
        import pandas as pd

        return pd.DataFrame([{"case": c["name"], "fit": f["fit"], **e}
                             for c in self.cases for f in c.get("fits", [])
                             for e in f.get("violations", [])],
                            columns=["case", "fit", "side", "start_s", "end_s", "samples",
                                     "worst_time_s", "worst_size_m"])


def _overall(cases: list) -> dict:
    fits = [f for c in cases for f in c.get("fits", []) if f.get("status") == "ok"]

    def worst(key, where=lambda f: True):
        v = [abs(f[key]) for f in fits if where(f) and isinstance(f.get(key), float)
             and math.isfinite(f[key])]
        return max(v) if v else math.nan

    return {
        "cases": len(cases),
        "errors": [c["name"] for c in cases if c.get("status") == "error"],
        "fits_run": len(fits),
        "fit_errors": [f"{c['name']}/{f['fit']}" for c in cases for f in c.get("fits", [])
                       if f.get("status") == "error"],
        "passed": sum(1 for c in cases if c.get("passed")),
        "failed": [c["name"] for c in cases if not c.get("passed")],
        "inside_everywhere": all(f["inside"] for f in fits),
        "violation_events": sum(len(f["violations"]) for f in fits),
        "worst_violation_m": max((f["worst_violation_m"] for f in fits), default=0.0),
        "worst_stop_error_fraction": worst("stop_error_fraction"),
        "worst_stop_error_fraction_with_accelerometer": worst(
            "stop_error_fraction", lambda f: f["accelerometer"] and math.isnan(f["fault_start_s"])),
        "worst_stop_error_fraction_without_accelerometer": worst(
            "stop_error_fraction", lambda f: not f["accelerometer"]
            and math.isnan(f["fault_start_s"])),
        "worst_speed_error_m_s": worst("speed_error_max_m_s"),
        "wall_time_s": float(sum(c.get("wall_time_s", 0.0) for c in cases)),
    }


def run_odometry_programme(programme="default", odometry=None, *, out=None, figures=True,
                           histories=False, period=None, cases=None,
                           progress=None) -> OdometryProgrammeResult:
    """Run an odometry programme (see the module docstring).

    Parameters
    ----------
    programme : str, path or OdometryProgramme
        ``"default"`` (the shipped programme), a programme file, or a loaded programme.
    odometry : None, "reference", a ``.fmu`` path, "module:name", "file.py:name", or an
        odometry object or class (:func:`load_odometry`).
    out : path, optional
        Folder for the outputs (:func:`write_odometry_outputs`), rewritten after every case.
    figures, histories : bool
        With ``out``: a figure per case and a summary figure; each case's samples (Parquet).
    period : float, optional
        Period [s] of an odometry without one (an FMU without a default step).
    cases : list of str, optional
        Run only these cases.
    progress : callable, optional
        Called with ``(index, number of cases, case name)`` before each case.
    """
    if isinstance(programme, OdometryProgramme):
        prog = programme
    else:
        prog = load_odometry_programme(programme)
    if cases:
        prog = prog.select(cases)
    odo = load_odometry(odometry, period=period)
    return _OdometryRun(prog.name, odo).run(prog.cases, out=out, figures=figures,
                                            histories=histories, progress=progress)


class _OdometryRun(ProgrammeRun):
    """:func:`run_odometry_programme`'s loop: the odometry under test on every case."""

    case_errors = (SimulationError, ValueError, ArithmeticError)
    no_record = (None,)  # no traces

    def run_case(self, case):
        return run_odometry_case(case, self.unit)

    def error_summary(self, case, message, seconds):
        return {**case.describe(), "odometry": self.label, "status": "error",
                "message": message, "passed": False, "fits": [], "wall_time_s": seconds}

    def result(self, summaries):
        return OdometryProgrammeResult(self.programme, self.label, summaries,
                                       _overall(summaries))

    def write_outputs(self, result, out, **options):
        return write_odometry_outputs(result, out, **options)


def write_odometry_outputs(result: OdometryProgrammeResult, out, *, case=None,
                           figures: bool = True, histories: bool = False,
                           summary_figure: bool = False) -> list:
    """Write ``summary.json`` (overall, every case and fit), ``fits.csv`` (a row per case and
    fit), ``violations.csv`` (every violation event) and, for ``case = (case, summary,
    traces)``, ``cases/<name>.json``, ``figures/<name>.png`` and (``histories``)
    ``histories/<name>.parquet``; with ``summary_figure``, ``figures/summary.png``."""
    out = Path(out)
    doc = {"format": "railadhesion-odometry-results", "programme": result.programme,
           "odometry": result.odometry, "overall": result.overall, "cases": result.cases}
    written = write_summary(out, doc, {"fits.csv": result.frame(),
                                       "violations.csv": result.violation_frame()})
    if case is not None:
        ocase, summary, tr = case
        figure = history = None
        if tr is not None and figures:
            from railadhesion.braking.figures import odometry_case_figure

            figure = odometry_case_figure(tr, summary, title=f"{ocase.name}: "
                                          f"{ocase.run.adhesion.describe()}")
        if tr is not None and histories:
            history = _samples_frame(ocase, tr)
        written += write_case(out, ocase.name, summary, figure, history, dpi=80)
    if summary_figure:
        from railadhesion.braking.figures import odometry_summary_figure

        written.append(save_figure(odometry_summary_figure(result.cases), out, "summary", 80))
    return written


def _samples_frame(case: OdometryCase, tr: dict):
    """A case's samples (the traces of :func:`run_odometry_case`) as a DataFrame: the truth,
    the creepage of the odometry axles and every fit's outputs (``<fit>:<output>``)."""
    import pandas as pd

    cols = {"time": tr["time"], "train_speed": tr["speed"],
            "distance": tr["distance"], "drive": tr["drive"]}
    for k, a in enumerate(case.axles):
        cols[f"creep_{a}"] = tr["creep"][:, k]
    for name, rec in tr["outputs"].items():
        for k, what in enumerate(_OUTPUTS):
            cols[f"{name}:{what}"] = rec[:, k]
    return pd.DataFrame(cols)
