"""WSP test bench: a programme of low-adhesion stops run on any WSP controller.

A *programme* (TOML, ``format = "railadhesion-wsp-programme"``; ``docs/wsp.md`` documents every
field; the shipped ``default`` programme has 31 cases) lists braking cases: vehicle, speed,
brake, valve arrangement, sensors and the rail's adhesion. :func:`run_wsp_programme` runs each
case in the braking simulator with the controller in the loop, through the stepping API: every
control period the sensors (:mod:`railadhesion.braking.sensors`) measure the wheel speeds,
brake pressures and, if fitted, an external speed; the controller turns the readings into valve
states; the simulator advances one period. The controller never sees the true train speed.

Controllers (:func:`load_controller`): the default :class:`~railadhesion.braking.wsp.
WheelSlideProtection`; a user's Python controller (the interface of
:mod:`railadhesion.braking.wsp`); or a WSP unit delivered as an FMI 2.0 co-simulation FMU,
imported with FMPy (:class:`FmuController`).

Per case it reports the stopping distance against the adhesion-limited stop
(:func:`adhesion_limited_stop`), the same stop without WSP and the dry-rail stop, the
adhesion utilisation, the lock and
slide figures of :func:`railadhesion.braking.metrics.slide_metrics`, the air consumption, and
pass/fail against the programme's criteria. A case that fails (a bad controller output, a
simulation error) is recorded with its message and the others still run; with ``out`` the
results so far are written after every case, so nothing is lost.
"""

from __future__ import annotations

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
    json_safe,
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
    BrakingFileError,
    FieldError,
    boolean,
    integer,
    keys,
    number,
    string,
    table,
)
from railadhesion.braking.adhesion import (
    AxleAdhesion,
    ExactTableAdhesion,
    PolachAdhesion,
    WaterFlowProfile,
    WilacAdhesion,
)
from railadhesion.braking.cylinders import BrakeCylinders
from railadhesion.braking.metrics import slide_metrics
from railadhesion.braking.scenario import polach_set_name, wsp_settings_fields
from railadhesion.braking.sensors import (
    ExternalSpeedSettings,
    SensorModel,
    measure,
    noisy_sensors,
)
from railadhesion.braking.simulator import BrakingSimulator, SimulationError
from railadhesion.braking.vehicle import GRAVITY, Vehicle, vehicle_from_field
from railadhesion.braking.wsp import (
    WheelSlideProtection,
    WSPSettings,
    accepts_measurements,
    settings_file_keys,
    state_diagnostics,
    wsp_update,
)
from railadhesion.models.parameters import POLACH_PARAMETER_SETS, PolachParameters

__all__ = [
    "PROGRAMME_FORMAT",
    "AdhesionCase",
    "BenchCase",
    "WSPProgramme",
    "WSPProgrammeResult",
    "WSPControllerError",
    "FmuController",
    "load_wsp_programme",
    "load_controller",
    "adhesion_limited_stop",
    "run_wsp_case",
    "run_wsp_programme",
    "write_programme_outputs",
    "json_safe",
]

PROGRAMME_FORMAT = "railadhesion-wsp-programme"
#: The criteria of a case and their defaults (the issue-20 targets).
DEFAULT_CRITERIA = {"max_longest_lock_s": 1.0, "max_mean_creep": 0.3,
                    "max_distance_ratio": math.inf, "max_ratio_no_wsp": math.inf}


class WSPControllerError(ValueError):
    """A controller under test misbehaved; the message names the time, the axle and the value."""


# -- cases ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class AdhesionCase:
    """The rail of a case: Polach (a named set, or ``mu0``/``A``/``B``/``k_A``/``k_S``) or WILAC
    (a water flow), on the whole track or on a section ``[start, end)`` [m] with a dry rail
    outside (``polach2005_dry`` for Polach, 0 µl/s for WILAC); or the table model of Kalker's
    exact theory (:class:`~railadhesion.braking.adhesion.ExactTableAdhesion`) with the
    friction μ0, A, B of ``parameters``, on the whole track (dry: the friction of
    ``polach2005_dry``)."""

    model: str
    parameters: PolachParameters | None = None
    water_flow: float = 0.0
    section: tuple[float, float] | None = None

    def build(self) -> AxleAdhesion:
        if self.model == "table":
            return ExactTableAdhesion.from_polach(self.parameters)
        if self.model == "polach":
            if self.section is None:
                return PolachAdhesion(self.parameters)
            return PolachAdhesion("polach2005_dry", [(*self.section, self.parameters)])
        if self.section is None:
            return WilacAdhesion(WaterFlowProfile.constant(self.water_flow))
        return WilacAdhesion(WaterFlowProfile.sections([(*self.section, self.water_flow)]))

    def build_dry(self) -> AxleAdhesion:
        if self.model == "table":
            return ExactTableAdhesion.from_polach("polach2005_dry")
        if self.model == "polach":
            return PolachAdhesion("polach2005_dry")
        return WilacAdhesion(WaterFlowProfile.constant(0.0))

    def describe(self) -> str:
        where = "" if self.section is None else f" on {self.section[0]:g}-{self.section[1]:g} m"
        if self.model == "wilac":
            return f"WILAC {self.water_flow:g} µl/s{where}"
        p = self.parameters
        if self.model == "table":
            return f"table model mu0={p.mu0:g} A={p.A:g} B={p.B:g}"
        return (f"Polach mu0={p.mu0:g} A={p.A:g} B={p.B:g} k_A={p.k_A:g} k_S={p.k_S:g}"
                f"{where}")


@dataclass(frozen=True)
class BenchCase:
    """One stop of a programme (SI units)."""

    name: str
    adhesion: AdhesionCase
    vehicle: Vehicle
    initial_speed: float
    pressure: float = 5.5e5
    max_pressure: float = 6e5
    valves: str = "axle"
    sensors: str = "ideal"
    diameter_error: float = 0.01
    external_speed: bool = False
    seed: int = 0
    dt: float = 1e-3
    max_time: float = 600.0
    gradient: float = 0.0
    criteria: dict = field(default_factory=lambda: dict(DEFAULT_CRITERIA))

    @property
    def cylinders(self) -> BrakeCylinders:
        return BrakeCylinders(max_pressure=self.max_pressure, valves=self.valves)

    def sensor_model(self) -> SensorModel:
        external = ExternalSpeedSettings() if self.external_speed else None
        if self.sensors == "noisy":
            return noisy_sensors(self.vehicle.n_axles, self.seed, self.diameter_error, external)
        return SensorModel(external=external, seed=self.seed)

    def describe(self) -> dict:
        return {"name": self.name, "adhesion": self.adhesion.describe(),
                "vehicle": self.vehicle.name, "initial_speed_m_s": self.initial_speed,
                "initial_speed_km_h": self.initial_speed * 3.6,
                "pressure_Pa": self.pressure, "max_pressure_Pa": self.max_pressure,
                "valves": self.valves, "sensors": self.sensors,
                "diameter_error": self.diameter_error if self.sensors == "noisy" else 0.0,
                "external_speed": self.external_speed, "seed": self.seed,
                "time_step_s": self.dt, "gradient": self.gradient}


@dataclass
class WSPProgramme:
    """A loaded programme: its cases, and WSP settings for the default controller."""

    name: str
    cases: list
    description: str = ""
    wsp: dict = field(default_factory=dict)
    source: str = ""

    def select(self, names) -> WSPProgramme:
        """The programme with the named cases only (in the programme's order)."""
        return select_cases(self, names)


_CASE_KEYS = {
    # key: (default, parser)
    "vehicle": "coach_default",
    "initial_speed_m_s": None,
    "pressure_Pa": 5.5e5,
    "max_pressure_Pa": 6e5,
    "valves": "axle",
    "sensors": "ideal",
    "diameter_error": 0.01,
    "external_speed": False,
    "seed": None,
    "time_step_s": 1e-3,
    "max_time_s": 600.0,
    "gradient": 0.0,
}
_CRITERIA_KEYS = ("max_longest_lock_s", "max_mean_creep", "max_distance_ratio",
                  "max_ratio_no_wsp")


def _criteria(tab, where, base):
    tab = table(tab, where)
    keys(tab, where, (), _CRITERIA_KEYS)
    out = dict(base)
    out["max_longest_lock_s"] = number(tab.get("max_longest_lock_s", out["max_longest_lock_s"]),
                                       f"{where}.max_longest_lock_s", 0.0, 1e4)
    out["max_mean_creep"] = number(tab.get("max_mean_creep", out["max_mean_creep"]),
                                   f"{where}.max_mean_creep", 0.0, 1.0)
    for key, low in (("max_distance_ratio", 1.0), ("max_ratio_no_wsp", 0.01)):
        ratio = tab.get(key, out[key])
        out[key] = math.inf if ratio == math.inf else number(ratio, f"{where}.{key}", low,
                                                             100.0)
    return out


def _named_set(tab, where, values, either: str) -> PolachParameters:
    """The Polach set named by ``tab["parameters"]``, which excludes the ``values`` (their
    error: ``either``)."""
    for k in values:
        if k in tab:
            raise FieldError(f"{where}.{k}", either)
    return POLACH_PARAMETER_SETS[polach_set_name(tab["parameters"], f"{where}.parameters")]


def _adhesion_case(tab, where) -> AdhesionCase:
    tab = table(tab, where)
    model = string(tab.get("model", ""), f"{where}.model")
    section = None
    if "start_m" in tab or "end_m" in tab:
        for k in ("start_m", "end_m"):
            if k not in tab:
                raise FieldError(f"{where}.{k}", "give both start_m and end_m (a section)")
        start = number(tab["start_m"], f"{where}.start_m", 0.0, 1e6)
        end = number(tab["end_m"], f"{where}.end_m", start, 1e6, low_open=True)
        section = (start, end)
    if model == "polach":
        keys(tab, where, ("model",), ("parameters", "mu0", "A", "B", "k_A", "k_S", "start_m",
                                      "end_m"))
        if "parameters" in tab:
            params = _named_set(tab, where, ("mu0", "A", "B", "k_A", "k_S"),
                                "give either parameters (a named set) or the values mu0, A, B, "
                                "k_A, k_S")
        else:
            if "mu0" not in tab:
                raise FieldError(f"{where}.mu0", "required for model = 'polach' (or give "
                                 "parameters = a named set)")
            mu0 = number(tab["mu0"], f"{where}.mu0", 0.0, 1.5, low_open=True)
            a = number(tab.get("A", 1.0), f"{where}.A", 0.0, 10.0)
            b = number(tab.get("B", 0.0), f"{where}.B", 0.0, 100.0)
            k_a = number(tab.get("k_A", 1.0), f"{where}.k_A", 0.0, 1.0, low_open=True)
            k_s = number(tab.get("k_S", 0.4), f"{where}.k_S", 0.0, 1.0, low_open=True)
            params = PolachParameters(k_A=k_a, k_S=k_s, mu0=mu0, A=a, B=b, name="case",
                                      source="WSP programme case")
        return AdhesionCase("polach", params, 0.0, section)
    if model == "table":
        keys(tab, where, ("model",), ("parameters", "mu0", "A", "B"))
        if "parameters" in tab:
            params = _named_set(tab, where, ("mu0", "A", "B"), "give either parameters (a "
                                "named Polach set: its mu0, A, B) or the values mu0, A, B")
        else:
            if "mu0" not in tab:
                raise FieldError(f"{where}.mu0", "required for model = 'table' (or give "
                                 "parameters = a named Polach set)")
            params = PolachParameters(  # k_A, k_S: not used by the table model
                k_A=1.0, k_S=1.0,
                mu0=number(tab["mu0"], f"{where}.mu0", 0.0, 1.5, low_open=True),
                A=number(tab.get("A", 1.0), f"{where}.A", 0.0, 1.0),
                B=number(tab.get("B", 0.0), f"{where}.B", 0.0, 100.0),
                name="case", source="WSP programme case")  # fmt: skip
        return AdhesionCase("table", params, 0.0, None)
    if model == "wilac":
        keys(tab, where, ("model", "water_flow_ul_s"), ("start_m", "end_m"))
        w = number(tab["water_flow_ul_s"], f"{where}.water_flow_ul_s", 0.0, 1e4)
        return AdhesionCase("wilac", None, w, section)
    raise FieldError(f"{where}.model", f"must be 'polach', 'wilac' or 'table', got {model!r}")


def _programme_from_document(doc, base: Path) -> WSPProgramme:
    keys(doc, "", ("format", "version", "case"), ("name", "description", "defaults",
                                                   "criteria", "wsp"))
    if doc["format"] != PROGRAMME_FORMAT:
        raise FieldError("format", f"expected {PROGRAMME_FORMAT!r}, got {doc['format']!r}")
    integer(doc["version"], "version", 1, 1)
    name = string(doc.get("name", ""), "name")
    description = string(doc.get("description", ""), "description")
    defaults = table(doc.get("defaults", {}), "defaults")
    keys(defaults, "defaults", (), tuple(_CASE_KEYS))
    criteria = _criteria(doc.get("criteria", {}), "criteria", DEFAULT_CRITERIA)
    wsp = {}
    if "wsp" in doc:
        wt = table(doc["wsp"], "wsp")
        keys(wt, "wsp", (), tuple(settings_file_keys()))
        wsp = wsp_settings_fields(wt)[0]
    cases = doc["case"]
    if not isinstance(cases, list) or not cases:
        raise FieldError("case", "expected one or more [[case]] tables")
    vehicles = {}
    out = []
    seen = set()
    for k, raw in enumerate(cases):
        where = f"case[{k}]"
        tab = table(raw, where)
        keys(tab, where, ("name", "adhesion"), (*_CASE_KEYS, "criteria"))
        cname = string(tab["name"], f"{where}.name")
        if not cname or any(ch in cname for ch in '/\\:*?"<>|'):
            raise FieldError(f"{where}.name", f"must be a non-empty name usable as a file name, "
                             f"got {cname!r}")
        if cname in seen:
            raise FieldError(f"{where}.name", f"duplicate case name {cname!r}")
        seen.add(cname)
        where = f"case[{k}] ({cname})"
        get = partial(case_field, tab=tab, defaults=defaults, fallback=_CASE_KEYS, where=where)
        value, w = get("vehicle")
        vfile = string(value, w)
        if vfile not in vehicles:
            vehicles[vfile] = vehicle_from_field(vfile, w, base)
        vehicle = vehicles[vfile]
        value, w = get("initial_speed_m_s")
        if value is None:
            raise FieldError(f"{where}.initial_speed_m_s", "required (here or in [defaults])")
        v0 = number(value, w, 0.5, 150.0)
        pressure = number(*get("pressure_Pa"), 0.0, 2e6, low_open=True)
        max_pressure = number(*get("max_pressure_Pa"), 0.0, 2e6, low_open=True)
        value, w = get("valves")
        valves = string(value, w)
        if valves not in ("axle", "bogie"):
            raise FieldError(w, f"must be 'axle' or 'bogie', got {valves!r}")
        value, w = get("sensors")
        sensors = string(value, w)
        if sensors not in ("ideal", "noisy"):
            raise FieldError(w, f"must be 'ideal' or 'noisy', got {sensors!r}")
        diameter = number(*get("diameter_error"), 0.0, 0.05)
        external = boolean(*get("external_speed"))
        value, w = get("seed")
        seed = k if value is None else integer(value, w, 0, 2**63 - 1)
        dt = number(*get("time_step_s"), 1e-5, 0.01)
        max_time = number(*get("max_time_s"), 0.0, 1e5, low_open=True)
        gradient = number(*get("gradient"), -0.1, 0.1)
        adhesion = _adhesion_case(tab["adhesion"], f"{where}.adhesion")
        case_criteria = _criteria(tab.get("criteria", {}), f"{where}.criteria", criteria)
        out.append(BenchCase(cname, adhesion, vehicle, v0, pressure, max_pressure, valves,
                             sensors, diameter, external, seed, dt, max_time, gradient,
                             case_criteria))
    return WSPProgramme(name, out, description, wsp)


def programme_from_document(doc, base=".") -> WSPProgramme:
    """A programme from a parsed TOML document (``base``: the folder vehicle files are relative
    to). Errors are :class:`~railadhesion.braking.BrakingFileError` naming the field (the
    odometry bench reads its vehicle runs this way)."""
    try:
        return _programme_from_document(doc, Path(os.fspath(base)))
    except FieldError as exc:
        raise BrakingFileError(str(exc)) from None


def load_wsp_programme(path="default") -> WSPProgramme:
    """Read and check a programme file (``"default"``: the shipped 31-case programme).
    Errors are :class:`~railadhesion.braking.BrakingFileError` naming the file and field."""
    return read_programme_file(path, "wsp_programme_default.toml", _programme_from_document)


# -- controllers ----------------------------------------------------------------------------
class _DefaultController:
    """The default WSP through its compiled records (no Python per call but the dispatch)."""

    label = "default WheelSlideProtection"

    def __init__(self, wsp: WheelSlideProtection):
        self.wsp = wsp
        self.period = wsp.period

    def prepare(self, case: BenchCase):
        w = WheelSlideProtection(self.wsp.settings).configure(case.vehicle, case.cylinders)
        self.settings = w.settings_record()
        self.state = w.state_record(case.vehicle.n_axles)
        self._v_ref = self.state["v_ref"]  # a view: cheap to read every period
        self.out = np.zeros(case.vehicle.n_axles, dtype=np.int64)

    def step(self, t, omega, pressure, command, external):
        wsp_update(self.settings, self.state, t, omega, pressure, command, external, self.out)
        return self.out

    @property
    def reference_speed(self):
        return self._v_ref[0]

    def diagnostics(self):
        return state_diagnostics(self.state)


class _PythonController:
    """A user's controller object (``period``, ``reset``, ``__call__``) or plain function."""

    def __init__(self, obj, period=None):
        if isinstance(obj, type):
            obj = obj()
        self.obj = obj
        p = getattr(obj, "period", period)
        if p is None or not (isinstance(p, int | float) and math.isfinite(p) and p > 0):
            raise ValueError("the controller needs a control period: give it a 'period' "
                             f"attribute [s] or pass control_period, got {p!r}")
        self.period = float(p)
        self.label = getattr(obj, "label", None) or getattr(
            type(obj), "__qualname__", type(obj).__name__)
        if not callable(obj):
            raise ValueError(f"the controller {self.label!r} is not callable")
        self.extra = accepts_measurements(obj)

    def prepare(self, case: BenchCase):
        if isinstance(self.obj, WheelSlideProtection):
            self.obj.configure(case.vehicle, case.cylinders)
        reset = getattr(self.obj, "reset", None)
        if reset is not None:
            reset(case.vehicle.n_axles, case.vehicle.wheel_radius)

    def step(self, t, omega, pressure, command, external):
        if self.extra:
            return self.obj(t, omega.copy(), float(command[0]), brake_pressures=pressure.copy(),
                            external_speed=external)
        return self.obj(t, omega.copy(), float(command[0]))

    @property
    def reference_speed(self):
        r = getattr(self.obj, "reference_speed", math.nan)
        try:
            return float(r)
        except (TypeError, ValueError):
            return math.nan

    def diagnostics(self):
        d = getattr(self.obj, "diagnostics", None)
        return d() if callable(d) else {}


class FmuController:
    """A WSP unit delivered as an FMI 2.0 co-simulation FMU, run with FMPy.

    Variables (names as here; ``n`` the number of axles): inputs ``wheel_speed_1`` …
    ``wheel_speed_n`` [rad/s] (measured), outputs ``valve_1`` … ``valve_n`` (0 apply, 1 hold,
    2 vent; Integer or Real), both required; optional inputs ``brake_pressure_1`` …
    ``brake_pressure_n`` [Pa], ``pressure_command`` [Pa] and ``external_speed`` [m/s] (NaN
    without a sensor), and an optional parameter ``wheel_radius`` [m]. Every control period the
    bench sets the inputs measured at t, calls ``doStep(t, period)`` and applies the outputs
    it then reads from t on (a discrete controller computing its outputs from the inputs set
    before the step, as pythonfmu slaves do). ``period`` defaults to the FMU's
    DefaultExperiment step size, else 5 ms.
    """

    def __init__(self, path, period: float | None = None):
        self.path, self.md, self.vars, self.period = read_cosim_fmu(path, period,
                                                                    "FMU controllers")
        from fmpy import extract

        self.label = f"FMU {self.path.name}"
        self._extract = extract
        self.fmu = None
        self.n = None

    def _check_variables(self, n: int):
        want = [(f"wheel_speed_{i}", "input") for i in range(1, n + 1)] + [
            (f"valve_{i}", "output") for i in range(1, n + 1)]
        problems = fmu_variable_problems(
            self.vars, [name for name, _ in want if name not in self.vars], want)
        if problems:
            raise WSPControllerError(
                f"{self.path.name}: the FMU {problems}; a WSP FMU needs inputs "
                f"wheel_speed_1..{n} [rad/s] and outputs valve_1..{n} (0 apply, 1 hold, 2 vent); "
                f"optional inputs brake_pressure_1..{n} [Pa], pressure_command [Pa], "
                "external_speed [m/s]")

    def prepare(self, case: BenchCase):
        from fmpy.fmi2 import FMU2Slave

        n = case.vehicle.n_axles
        self._check_variables(n)
        self.close()
        self.dir = self._extract(str(self.path))
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier,
                             instanceName="wsp")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        if "wheel_radius" in self.vars:
            self.fmu.setReal([self.vars["wheel_radius"].valueReference],
                             [case.vehicle.wheel_radius])
        self.fmu.exitInitializationMode()
        vr = self.vars
        self.vr_w = [vr[f"wheel_speed_{i}"].valueReference for i in range(1, n + 1)]
        self.vr_p = ([vr[f"brake_pressure_{i}"].valueReference for i in range(1, n + 1)]
                     if all(f"brake_pressure_{i}" in vr for i in range(1, n + 1)) else None)
        self.vr_cmd = vr["pressure_command"].valueReference if "pressure_command" in vr else None
        self.vr_ext = vr["external_speed"].valueReference if "external_speed" in vr else None
        outs = [vr[f"valve_{i}"] for i in range(1, n + 1)]
        self.integer_out = outs[0].type == "Integer"
        self.vr_out = [v.valueReference for v in outs]
        self.n = n

    def step(self, t, omega, pressure, command, external):
        f = self.fmu
        f.setReal(self.vr_w, list(map(float, omega)))
        if self.vr_p is not None:
            f.setReal(self.vr_p, list(map(float, pressure)))
        if self.vr_cmd is not None:
            f.setReal([self.vr_cmd], [float(command[0])])
        if self.vr_ext is not None:
            f.setReal([self.vr_ext], [float(external)])
        status = f.doStep(currentCommunicationPoint=t, communicationStepSize=self.period)
        if status not in (0, None):
            raise WSPControllerError(f"{self.label}: doStep at t = {t:.6g} s returned status "
                                     f"{status}")
        return (f.getInteger(self.vr_out) if self.integer_out else f.getReal(self.vr_out))

    reference_speed = math.nan

    def diagnostics(self):
        return {}

    def close(self):
        if self.fmu is not None:
            release_fmu(self.fmu)
            self.fmu = None
            import shutil

            shutil.rmtree(self.dir, ignore_errors=True)


def load_controller(spec=None, *, control_period: float | None = None, wsp_settings=None):
    """A bench controller from a specification.

    ``None`` or ``"default"``: the default :class:`~railadhesion.braking.wsp.
    WheelSlideProtection` (with ``wsp_settings``, a dict or :class:`WSPSettings`); a
    :class:`WheelSlideProtection`; a path ending in ``.fmu``: an FMI 2.0 co-simulation WSP unit
    (:class:`FmuController`); ``"module:name"`` or ``"file.py:name"``: a Python controller
    object, class or plain function (``control_period`` for a function); or such an object
    itself.
    """
    if spec is None or spec == "default":
        s = wsp_settings if isinstance(wsp_settings, WSPSettings) else WSPSettings(
            **(wsp_settings or {}))
        return _DefaultController(WheelSlideProtection(s))
    if isinstance(spec, WheelSlideProtection):
        return _DefaultController(spec)
    if isinstance(spec, _DefaultController | _PythonController | FmuController):
        return spec
    if isinstance(spec, str | os.PathLike):
        text = os.fspath(spec)
        if text.lower().endswith(".fmu"):
            return FmuController(text, control_period)
        obj = load_component(text, "controller", "default", "wsp_controller_")
        if isinstance(obj, WheelSlideProtection):
            return _DefaultController(obj)
        return _PythonController(obj, control_period)
    return _PythonController(spec, control_period)


def _valves(raw, n: int, bogie: bool, t: float, label: str) -> np.ndarray:
    """The controller's output checked: n codes (2 with per-bogie valves may be given per
    bogie), each 0, 1 or 2; errors name the time, the axle (or bogie) and the value."""
    if isinstance(raw, np.ndarray) and raw.dtype == np.int64 and raw.shape == (n,) and all(
            x in (0, 1, 2) for x in raw.tolist()):
        return raw  # the common case, checked cheaply
    try:
        if raw is None or np.ndim(raw) == 0:
            raise TypeError
        arr = np.asarray(raw, dtype=float).ravel()
    except (TypeError, ValueError):
        raise WSPControllerError(f"{label} returned {raw!r} at t = {t:.6g} s; expected {n} "
                                 "valve states (0 apply, 1 hold, 2 vent)") from None
    per_bogie = bogie and arr.size == 2 and n != 2
    if arr.size != n and not per_bogie:
        expected = f"{n} (one per axle)" + (" or 2 (one per bogie)" if bogie else "")
        raise WSPControllerError(f"{label} returned {arr.size} valve state(s) at t = {t:.6g} "
                                 f"s; expected {expected}")
    what = "bogie" if per_bogie else "axle"
    for k, x in enumerate(arr):
        if not (math.isfinite(x) and x in (0.0, 1.0, 2.0)):
            raise WSPControllerError(f"{label} returned the valve state {x:g} for {what} "
                                     f"{k + 1} at t = {t:.6g} s; allowed: 0 (apply), 1 (hold), "
                                     "2 (vent)")
    return np.repeat(arr, n // 2) if per_bogie else arr


# -- reference stops ------------------------------------------------------------------------
def adhesion_limited_stop(vehicle: Vehicle, adhesion: AxleAdhesion, initial_speed: float,
                          pressure: float, cylinders: BrakeCylinders | None = None,
                          gradient: float = 0.0, max_step_m: float = 5.0) -> dict:
    """The adhesion-limited stop: every axle, at every instant, brakes with the lesser of its
    brake force and the peak of its adhesion curve.

    ``M dv/dt = −Σ_i min(μ_peak,i N_i, c p_i/R − J d/R²) − F_res(v) − F_grade`` with the
    cylinders filling towards ``min(pressure, max_pressure)`` (APPLY, their first-order lag),
    μ_peak,i the peak of axle i's curve at its speed, load and track position
    (``adhesion.available``), N_i the axle loads with the load transfer of the deceleration d
    (seed 002 eqs. 11-12); the rolling wheels' inertia is carried by the brake-limited axles
    (``J d/R²``). Solved for d by a fixed-point iteration each step, integrated by Heun's
    method with steps of at most ``max_step_m`` (5 m) and 0.25 s (halving them changes a
    stop by less than 0.1 %: tested). This is the bound no WSP can beat with these
    brakes; a WSP that keeps every axle at its peak all the time reaches it.

    Returns ``{"distance_m", "time_s"}``.
    """
    for name, value in (("initial_speed", initial_speed), ("pressure", pressure),
                        ("max_step_m", max_step_m)):
        if isinstance(value, bool) or not isinstance(value, int | float) or not (
                math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be in (0, inf), got {value!r}")
    if not isinstance(adhesion, AxleAdhesion):
        raise ValueError(f"adhesion must be an AxleAdhesion, got {type(adhesion).__name__}")
    cyl = cylinders or BrakeCylinders()
    n = vehicle.n_axles
    radius = vehicle.wheel_radius
    adhesion.bind(n, radius)
    offsets = vehicle.axle_offsets()
    mass = vehicle.total_mass
    j_r2 = vehicle.wheelset_inertia / radius**2
    grade = mass * GRAVITY * math.sin(math.atan(gradient))
    target = min(pressure, cyl.max_pressure)

    zeros = np.zeros(n)
    static = vehicle.axle_normal_loads(0.0)
    transfer = vehicle.axle_normal_loads(1.0) - static  # loads are linear in d
    last = [0.0]

    def decel(v, x, t):
        p = target * (1.0 - math.exp(-t / cyl.fill_time_constant))
        brake = vehicle.brake_coefficient * p / radius
        resistance = vehicle.davis_a + vehicle.davis_b * v + vehicle.davis_c * v * v
        d = last[0]
        for _ in range(8):
            loads = np.maximum(static + transfer * d, 0.0)
            adhesion.prepare(max(v, 1e-3), 0.5 * loads, x - offsets, t, zeros)
            peak = np.asarray(adhesion.available(max(v, 1e-3)), float)
            force = float(np.sum(np.minimum(peak * loads, max(brake - j_r2 * d, 0.0))))
            d_new = (force + resistance + grade) / mass
            if abs(d_new - d) < 1e-7:
                break
            d = d_new
        last[0] = d_new
        return d_new

    v, x, t = float(initial_speed), 0.0, 0.0
    while v > 0.0:
        d0 = decel(v, x, t)
        h = min(0.25, max_step_m / max(v, 1e-6))
        if d0 > 0 and v - d0 * h < 0:
            h = v / d0
        v1 = v - d0 * h
        d1 = decel(max(v1, 0.0), x + v * h, t + h)
        dm = 0.5 * (d0 + d1)
        if dm <= 0:
            return {"distance_m": math.inf, "time_s": math.inf}
        if v - dm * h <= 0:
            x += v * v / (2 * dm)
            t += v / dm
            break
        x += h * (v - 0.5 * dm * h)
        v -= dm * h
        t += h
        if t > 1e5:
            return {"distance_m": math.inf, "time_s": math.inf}
    return {"distance_m": x, "time_s": t}


def _no_wsp_stop(case: BenchCase, cache: dict) -> dict:
    """The same stop on the same rail without WSP (valves always apply; cached per vehicle,
    speed, brake and rail): what a WSP is measured against where locking costs little."""
    from railadhesion.braking.run import simulate

    key = ("no wsp", id(case.vehicle), case.initial_speed, case.pressure, case.max_pressure,
           case.valves, case.dt, case.max_time, case.gradient, case.adhesion.describe())
    if key not in cache:
        res = simulate(case.vehicle, case.adhesion.build(), case.initial_speed, case.pressure,
                       cylinders=case.cylinders, dt=case.dt, max_time=case.max_time,
                       gradient=case.gradient)
        cache[key] = {"distance_m": res.stopping_distance if res.success else math.nan,
                      "time_s": res.stopping_time if res.success else math.nan}
    return cache[key]


def _dry_stop(case: BenchCase, cache: dict) -> dict:
    """The same stop on a dry rail without WSP (cached per vehicle, speed and brake)."""
    from railadhesion.braking.run import simulate

    key = (id(case.vehicle), case.initial_speed, case.pressure, case.max_pressure, case.valves,
           case.dt, case.gradient, case.adhesion.model)
    if key not in cache:
        res = simulate(case.vehicle, case.adhesion.build_dry(), case.initial_speed,
                       case.pressure, cylinders=case.cylinders, dt=case.dt,
                       max_time=case.max_time, gradient=case.gradient)
        cache[key] = {"distance_m": res.stopping_distance, "time_s": res.stopping_time}
    return cache[key]


# -- one case -------------------------------------------------------------------------------
def _utilisation(h) -> float:
    n = sum(1 for c in h.columns if c.startswith("wheel_speed_"))
    dt = np.diff(h["time"].to_numpy(), prepend=0.0)
    ok = (h["pressure_command"].to_numpy() > 0) & (h["train_speed"].to_numpy() > 0.5)
    used = np.zeros(len(h))
    avail = np.zeros(len(h))
    for i in range(1, n + 1):
        a = h[f"adhesion_available_{i}"].to_numpy()
        good = np.isfinite(a) & (a > 0)
        used += np.where(good, h[f"adhesion_used_{i}"].to_numpy(), 0.0) * h[
            f"normal_load_{i}"].to_numpy()
        avail += np.where(good, a, 0.0) * h[f"normal_load_{i}"].to_numpy()
    ok &= avail > 0
    if not np.any(ok):
        return math.nan
    return float(np.sum((used[ok] / avail[ok]) * dt[ok]) / np.sum(dt[ok]))


def run_wsp_case(case: BenchCase, controller=None, *, dry_cache: dict | None = None):
    """Run one case; returns ``(summary dict, histories DataFrame, trace)`` where ``trace``
    holds the control-period samples: time, reference speed (NaN if the controller has none)
    and the measured wheel speeds. Controller faults raise :class:`WSPControllerError`,
    simulation faults :class:`~railadhesion.braking.SimulationError`."""
    ctrl = load_controller(controller) if not hasattr(controller, "prepare") else controller
    started = _time.perf_counter()
    vehicle = case.vehicle
    n = vehicle.n_axles
    cyl = case.cylinders
    period = ctrl.period
    whole_multiple(period, case.dt, "the control period", "the time step")
    adhesion = case.adhesion.build()
    sim = BrakingSimulator(vehicle, adhesion, case.initial_speed, cylinders=cyl,
                           gradient=case.gradient, max_step=case.dt, record=True)
    sensors = case.sensor_model()
    s_set, s_state = sensors.settings_record(n), sensors.state_record(n)
    ctrl.prepare(case)
    live = sim.live
    omega_meas = np.zeros(n)
    p_meas = np.zeros(n)
    command = np.full(n, case.pressure)
    inputs = sim.inputs
    inputs.pressure_command[:] = case.pressure
    nmax = int(math.ceil(case.max_time / period))
    trace_t = np.empty(nmax + 1)
    trace_ref = np.empty(nmax + 1)
    trace_w = np.empty((nmax + 1, n))
    label = getattr(ctrl, "label", "the controller")
    k = 0
    while k < nmax and not live.stopped:
        t = k * period
        ext = measure(s_set, s_state, t, live.wheel_speeds, live.brake_pressures,
                      live.train_speed, -live.deceleration, omega_meas, p_meas)
        try:
            raw = ctrl.step(t, omega_meas, p_meas, command, ext)
        except WSPControllerError:
            raise
        except Exception as exc:
            raise WSPControllerError(f"{label} raised {type(exc).__name__} at t = {t:.6g} s: "
                                     f"{exc}") from exc
        inputs.valves[:] = _valves(raw, n, case.valves == "bogie", t, label)
        trace_t[k] = t
        trace_ref[k] = ctrl.reference_speed
        trace_w[k] = omega_meas
        sim.advance(period)
        k += 1
    h = sim.histories()
    trace = {"time": trace_t[:k], "reference_speed": trace_ref[:k],
             "measured_wheel_speed": trace_w[:k]}
    slides = slide_metrics(h, vehicle.wheel_radius, cylinder_volume=cyl.cylinder_volume)
    ideal = adhesion_limited_stop(vehicle, case.adhesion.build(), case.initial_speed,
                                  case.pressure, cyl, case.gradient)
    cache = {} if dry_cache is None else dry_cache
    dry = _dry_stop(case, cache)
    bare = _no_wsp_stop(case, cache)
    stopped = bool(live.stopped)
    distance = float(sim.stop_distance) if stopped else math.nan
    ratio_ideal = distance / ideal["distance_m"] if stopped else math.nan
    summary = {
        **case.describe(),
        "controller": label,
        "status": "ok" if stopped else "not stopped",
        "message": "the train stopped" if stopped else
        f"max_time = {case.max_time} s reached before the train stopped",
        "stopping_distance_m": distance,
        "stopping_time_s": float(sim.stop_time) if stopped else math.nan,
        "adhesion_limited_distance_m": ideal["distance_m"],
        "distance_ratio": ratio_ideal,
        "no_wsp_distance_m": bare["distance_m"],
        "distance_vs_no_wsp": distance / bare["distance_m"] if stopped else math.nan,
        "dry_stopping_distance_m": dry["distance_m"],
        "extension_vs_dry_m": distance - dry["distance_m"],
        "extension_vs_dry_percent": 100.0 * (distance - dry["distance_m"]) / dry["distance_m"],
        "mean_adhesion_utilisation": _utilisation(h),
        **{k: v for k, v in slides.items() if k != "axles"},
        "axles": slides["axles"],
        "controller_diagnostics": ctrl.diagnostics(),
    }
    c = case.criteria
    summary["checks"] = {
        "longest_lock": {"value": slides["longest_lock_s"], "limit": c["max_longest_lock_s"],
                         "passed": slides["longest_lock_s"] <= c["max_longest_lock_s"]},
        "mean_creep": {"value": slides["mean_creep"], "limit": c["max_mean_creep"],
                       "passed": bool(slides["mean_creep"] <= c["max_mean_creep"])},
        "distance_ratio": {"value": ratio_ideal, "limit": c["max_distance_ratio"],
                           "passed": bool(ratio_ideal <= c["max_distance_ratio"])},
        "distance_vs_no_wsp": {"value": summary["distance_vs_no_wsp"],
                               "limit": c["max_ratio_no_wsp"],
                               "passed": bool(summary["distance_vs_no_wsp"]
                                              <= c["max_ratio_no_wsp"])},
    }
    summary["passed"] = stopped and all(v["passed"] for v in summary["checks"].values())
    summary["wall_time_s"] = _time.perf_counter() - started
    return summary, h, trace


# -- a programme ----------------------------------------------------------------------------
@dataclass
class WSPProgrammeResult(ProgrammeResult):
    """Results of :func:`run_wsp_programme`: one summary dict per case (failed cases with
    ``status = "error"`` and the message), and the overall figures."""

    controller: str
    cases: list
    overall: dict

    def frame(self):
        """One row per case (the scalar figures) as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.add_checks(self.table_row(c), c) for c in self.cases])

    def axle_frame(self):
        """One row per case and axle (lock, slide, creep and air figures)."""
        import pandas as pd

        rows = [{"case": c["name"], **a} for c in self.cases for a in c.get("axles", [])]
        return pd.DataFrame(rows)


def _overall(cases: list) -> dict:
    ran = [c for c in cases if c.get("status") != "error"]

    def values(key):
        return [c[key] for c in ran if isinstance(c.get(key), int | float)
                and math.isfinite(c[key])]

    def agg(fn, key):
        v = values(key)
        return fn(v) if v else math.nan

    return {
        "cases": len(cases),
        "ran": len(ran),
        "errors": [c["name"] for c in cases if c.get("status") == "error"],
        "passed": sum(1 for c in cases if c.get("passed")),
        "failed": [c["name"] for c in cases if not c.get("passed")],
        "worst_longest_lock_s": agg(max, "longest_lock_s"),
        "worst_distance_ratio": agg(max, "distance_ratio"),
        "mean_distance_ratio": agg(lambda v: float(np.mean(v)), "distance_ratio"),
        "worst_distance_vs_no_wsp": agg(max, "distance_vs_no_wsp"),
        "worst_mean_creep": agg(max, "mean_creep"),
        "mean_adhesion_utilisation": agg(lambda v: float(np.mean(v)),
                                         "mean_adhesion_utilisation"),
        "total_deep_slide_s": agg(sum, "deep_slide_s"),
        "total_vent_actions": int(agg(sum, "vent_actions")) if values("vent_actions") else 0,
        "total_vented_air_l": agg(sum, "vented_air_l"),
        "wall_time_s": agg(sum, "wall_time_s"),
    }


def run_wsp_programme(programme="default", controller=None, *, out=None,
                      figures: bool = True, histories: bool = False,
                      control_period: float | None = None, cases=None,
                      progress=None) -> WSPProgrammeResult:
    """Run a programme of WSP cases on a controller (see the module docstring).

    Parameters
    ----------
    programme : str, path or WSPProgramme
        ``"default"`` (the shipped programme), a programme TOML file, or a loaded programme.
    controller : None, "default", WheelSlideProtection, path to an FMU, "module:name",
        "file.py:name", or a controller object (see :func:`load_controller`).
    out : path, optional
        Folder for the outputs (:func:`write_programme_outputs`), rewritten after every case.
    figures : bool
        With ``out``: one figure per case and a summary figure.
    histories : bool
        With ``out``: each case's time histories as Parquet.
    control_period : float, optional
        Period [s] of a plain-function controller, or of an FMU without a default step.
    cases : list of str, optional
        Run only these cases.
    progress : callable, optional
        Called with ``(index, number of cases, case name)`` before each case.

    Returns
    -------
    WSPProgrammeResult
    """
    prog = programme if isinstance(programme, WSPProgramme) else load_wsp_programme(programme)
    if cases:
        prog = prog.select(cases)
    ctrl = load_controller(controller, control_period=control_period,
                           wsp_settings=prog.wsp or None)
    return _WSPRun(prog.name, ctrl).run(prog.cases, out=out, figures=figures,
                                        histories=histories, progress=progress)


class _WSPRun(ProgrammeRun):
    """:func:`run_wsp_programme`'s loop: the controller under test on every case."""

    case_errors = (WSPControllerError, SimulationError, ValueError, ArithmeticError)
    no_record = (None, None)  # no histories, no trace

    def __init__(self, programme: str, controller):
        super().__init__(programme, controller)
        self.dry_cache: dict = {}  # the dry and no-WSP stops, shared by the cases

    def run_case(self, case):
        return run_wsp_case(case, self.unit, dry_cache=self.dry_cache)

    def error_summary(self, case, message, seconds):
        return {**case.describe(), "controller": self.label, "status": "error",
                "message": message, "passed": False, "wall_time_s": seconds}

    def result(self, summaries):
        return WSPProgrammeResult(self.programme, self.label, summaries, _overall(summaries))

    def write_outputs(self, result, out, **options):
        return write_programme_outputs(result, out, **options)


def write_programme_outputs(result: WSPProgrammeResult, out, *, case=None,
                            figures: bool = True, histories: bool = False,
                            summary_figure: bool = False) -> list:
    """Write ``summary.json`` (overall and every case), ``cases.csv``, ``axles.csv`` and, for
    ``case = (case, summary, histories, trace)``, that case's ``cases/<name>.json``, figure
    ``figures/<name>.png`` and (``histories``) ``histories/<name>.parquet``; with
    ``summary_figure`` the figure across cases ``figures/summary.png``. Returns the paths."""
    out = Path(out)
    doc = {"format": "railadhesion-wsp-results", "programme": result.programme,
           "controller": result.controller, "overall": result.overall, "cases": result.cases}
    written = write_summary(out, doc, {"cases.csv": result.frame(),
                                       "axles.csv": result.axle_frame()})
    if case is not None:
        bench_case, summary, h, trace = case
        figure = None
        if h is not None and figures:
            from railadhesion.braking.figures import wsp_case_figure

            figure = wsp_case_figure(h, trace, bench_case.vehicle.wheel_radius,
                                     title=f"{bench_case.name}: {bench_case.adhesion.describe()}")
        written += write_case(out, bench_case.name, summary, figure,
                              h if histories else None, dpi=90)
    if summary_figure:
        from railadhesion.braking.figures import wsp_summary_figure

        written.append(save_figure(wsp_summary_figure(result.cases), out, "summary", 90))
    return written
