"""Braking scenarios in TOML: vehicle, initial speed, brake demand, track adhesion, WSP.

The format (``format = "railadhesion-brake-scenario"``, ``version = 1``) is documented with
every field in ``docs/braking.md``; ``examples/brake_dry.toml`` and ``examples/brake_damp.toml``
are complete examples. Loading checks every field; errors are
:class:`~railadhesion.braking.BrakingFileError` naming the file, the dotted field and the
allowed range, e.g. ``damp.toml: brake.pressure_Pa: must be in (0, 2e+06], got -1.0``.

Possible but implausible values give a warning naming the file and the field
(``docs/checks.md``): a pressure below 0.05 bar or above 20 bar (a
:class:`~railadhesion.plausibility.UnitWarning` when it would be plausible in bar, kPa or
psi: ``pressure_Pa = 5.5`` means 5.5 bar), an initial speed above 100 m/s (km/h?), a water
flow above 1000 µl/s, and a demand above ``max_pressure_Pa``, which the cylinders would clip
(an :class:`~railadhesion.plausibility.AlteredResultWarning`). They are kept in
:attr:`BrakeScenario.warnings`.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from railadhesion.braking._fields import (
    FieldError,
    boolean,
    integer,
    keys,
    number,
    read_document,
    string,
    table,
)
from railadhesion.braking.adhesion import (
    AdhesionRecovery,
    AxleAdhesion,
    CallableAdhesion,
    ContactGeometry,
    ExactTableAdhesion,
    PolachAdhesion,
    WaterFlowProfile,
    WilacAdhesion,
)
from railadhesion.braking.cylinders import BrakeCylinders
from railadhesion.braking.run import BrakeDemand, BrakingResult, simulate
from railadhesion.braking.vehicle import Vehicle, vehicle_from_field
from railadhesion.braking.wsp import WheelSlideProtection, WSPSettings, settings_file_keys
from railadhesion.models.parameters import POLACH_PARAMETER_SETS
from railadhesion.plausibility import (
    AlteredResultWarning,
    PlausibilityWarning,
    check_plausible,
    warn,
)

__all__ = ["BrakeScenario", "load_scenario", "run_scenario", "SCENARIO_FORMAT",
           "polach_set_name", "wsp_settings_fields"]

SCENARIO_FORMAT = "railadhesion-brake-scenario"

# WSP settings: TOML key -> (field, low, high) (railadhesion.braking.wsp.settings_file_keys)
_WSP_KEYS = settings_file_keys()


@dataclass
class BrakeScenario:
    """A loaded scenario: everything :func:`run_scenario` needs."""

    name: str
    vehicle: Vehicle
    initial_speed: float
    brake: BrakeDemand
    cylinders: BrakeCylinders
    adhesion: Callable[[], AxleAdhesion]
    dry_adhesion: Callable[[], AxleAdhesion]
    wsp: WSPSettings | None
    dt: float = 1e-3
    max_time: float = 600.0
    gradient: float = 0.0
    refresh_period: float = 0.01
    compare_dry: bool = True
    description: str = ""
    source: dict = field(default_factory=dict)
    #: Implausible fields found when loading (each also issued as a warning).
    warnings: tuple = ()

    def simulate(self, dry: bool = False, dt: float | None = None,
                 progress=None) -> BrakingResult:
        """Run the scenario (``dry=True``: the same stop on a dry rail)."""
        adhesion = self.dry_adhesion() if dry else self.adhesion()
        wsp = WheelSlideProtection(self.wsp) if self.wsp is not None else None
        return simulate(self.vehicle, adhesion, self.initial_speed, self.brake,
                        cylinders=self.cylinders, wsp=wsp, dt=self.dt if dt is None else dt,
                        max_time=self.max_time, gradient=self.gradient,
                        refresh_period=self.refresh_period, progress=progress)


def polach_set_name(value, where: str) -> str:
    """The field ``value`` (at ``where``) as the name of a Polach set of
    :data:`~railadhesion.models.parameters.POLACH_PARAMETER_SETS`; a ``FieldError`` listing
    the known sets otherwise."""
    name = string(value, where)
    if name not in POLACH_PARAMETER_SETS:
        raise FieldError(where, f"unknown Polach set {name!r}; known: "
                         f"{', '.join(sorted(POLACH_PARAMETER_SETS))}")
    return name


def _dry_set(tab: Mapping) -> str:
    """The Polach set of the dry reference: ``adhesion.dry_parameters``, by default
    ``polach2005_dry``."""
    return polach_set_name(tab.get("dry_parameters", "polach2005_dry"), "adhesion.dry_parameters")


def _wilac_parameters(value, where, base: Path):
    from railadhesion.io.paramfiles import load_wilac_parameters

    text = string(value, where)
    if text == "default":
        return None
    path = Path(text) if Path(text).is_absolute() else base / text
    try:
        return load_wilac_parameters(path)
    except (OSError, ValueError) as exc:
        raise FieldError(where, f"cannot load WILAC parameters: {exc}") from None


def _adhesion(doc: Mapping, base: Path, wheel_radius: float):
    where = "adhesion"
    tab = table(doc, where)
    keys(tab, where, ("model",), ("parameters", "water_flow_ul_s", "over", "sections",
                                  "table", "recovery_energy_J_per_m", "rail_lateral_radius_m",
                                  "dry_parameters", "file", "mu", "friction_ratio",
                                  "friction_decay_s_per_m"))
    model = string(tab["model"], "adhesion.model")
    if model not in ("polach", "wilac", "law", "table"):
        raise FieldError("adhesion.model", f"unknown model {model!r}; allowed: polach, wilac, "
                         "law, table (user functions: use the Python API, CallableAdhesion)")
    if model != "table":
        for k in ("mu", "friction_ratio", "friction_decay_s_per_m"):
            if k in tab:
                raise FieldError(f"adhesion.{k}", "only for model = 'table'")
    if model == "law":
        return _identified_law(tab, base, wheel_radius)
    if "file" in tab:
        raise FieldError("adhesion.file", "only for model = 'law'")
    rail = number(tab.get("rail_lateral_radius_m", 0.3), "adhesion.rail_lateral_radius_m",
                  0.05, 10.0)
    over = string(tab.get("over", "distance"), "adhesion.over")
    if over not in ("distance", "time"):
        raise FieldError("adhesion.over", f"must be 'distance' or 'time', got {over!r}")
    unit = "m" if over == "distance" else "s"
    sections = tab.get("sections", [])
    if not isinstance(sections, list):
        raise FieldError("adhesion.sections", "expected an array of tables [[adhesion.sections]]")
    contact = ContactGeometry(wheel_radius=wheel_radius, rail_lateral_radius=rail)

    def contact_copy():
        return contact

    if model == "table":
        return _table_model(tab, contact, sections)
    if model == "polach":
        for k in ("water_flow_ul_s", "table", "recovery_energy_J_per_m"):
            if k in tab:
                raise FieldError(f"adhesion.{k}", "only for model = 'wilac'")
        base_set = polach_set_name(tab.get("parameters", "polach2005_dry"), "adhesion.parameters")
        dry_set = _dry_set(tab)
        secs = []
        for i, sec in enumerate(sections):
            w = f"adhesion.sections[{i}]"
            sec = table(sec, w)
            keys(sec, w, (f"start_{unit}", f"end_{unit}", "parameters"))
            start = number(sec[f"start_{unit}"], f"{w}.start_{unit}", 0.0, 1e7)
            end = number(sec[f"end_{unit}"], f"{w}.end_{unit}", start, 1e7, low_open=True)
            secs.append((start, end, polach_set_name(sec["parameters"], f"{w}.parameters")))
        if over == "time" and secs:
            raise FieldError("adhesion.over", "Polach sections are along the track: use "
                             "over = 'distance'")
        return (lambda: PolachAdhesion(base_set, secs, contact_copy()),
                lambda: PolachAdhesion(dry_set, (), contact_copy()),
                {"model": "polach", "parameters": base_set, "sections": secs})
    if "dry_parameters" in tab:
        raise FieldError("adhesion.dry_parameters", "only for model = 'polach'")
    params = _wilac_parameters(tab.get("parameters", "default"), "adhesion.parameters", base)
    w0 = number(tab.get("water_flow_ul_s", 0.0), "adhesion.water_flow_ul_s", 0.0, 1e4)
    if "table" in tab and sections:
        raise FieldError("adhesion.table", "give either sections or a table, not both")
    if "table" in tab:
        t = table(tab["table"], "adhesion.table")
        keys(t, "adhesion.table", (unit, "water_flow_ul_s"))
        xs, ws = t[unit], t["water_flow_ul_s"]
        if not isinstance(xs, list) or not isinstance(ws, list) or len(xs) != len(ws) or not xs:
            raise FieldError("adhesion.table", f"'{unit}' and 'water_flow_ul_s' must be lists "
                             "of the same length >= 1")
        xs = [number(x, f"adhesion.table.{unit}[{i}]") for i, x in enumerate(xs)]
        ws = [number(x, f"adhesion.table.water_flow_ul_s[{i}]", 0.0, 1e4)
              for i, x in enumerate(ws)]
        if any(b < a for a, b in zip(xs, xs[1:], strict=False)):
            raise FieldError(f"adhesion.table.{unit}", "must be non-decreasing")
        profile = WaterFlowProfile(xs, ws, over, "linear")
    else:
        secs = []
        for i, sec in enumerate(sections):
            w = f"adhesion.sections[{i}]"
            sec = table(sec, w)
            keys(sec, w, (f"start_{unit}", f"end_{unit}", "water_flow_ul_s"))
            start = number(sec[f"start_{unit}"], f"{w}.start_{unit}", -1e7, 1e7)
            end = number(sec[f"end_{unit}"], f"{w}.end_{unit}", start, 1e7, low_open=True)
            secs.append((start, end,
                         number(sec["water_flow_ul_s"], f"{w}.water_flow_ul_s", 0.0, 1e4)))
        try:
            profile = WaterFlowProfile.sections(secs, base=w0, over=over)
        except ValueError as exc:
            raise FieldError("adhesion.sections", str(exc)) from None
    recovery = None
    if "recovery_energy_J_per_m" in tab:
        recovery = AdhesionRecovery(number(tab["recovery_energy_J_per_m"],
                                           "adhesion.recovery_energy_J_per_m", 0.0, 1e9,
                                           low_open=True))
    return (lambda: WilacAdhesion(profile, params, recovery, contact_copy()),
            lambda: WilacAdhesion(0.0, params, None, contact_copy()),
            {"model": "wilac", "water_flow_ul_s": w0, "over": over})


def _table_model(tab: Mapping, contact: ContactGeometry, sections):
    """``model = "table"``: the table model of Kalker's exact theory on every axle
    (:class:`~railadhesion.braking.adhesion.ExactTableAdhesion`), its friction the μ0, A, B of
    a Polach set (``parameters``) or given (``mu``, ``friction_ratio``,
    ``friction_decay_s_per_m``; Coulomb friction by default); the dry reference is the table
    model with the friction of a Polach set (``dry_parameters``, default ``polach2005_dry``)."""
    for k in ("water_flow_ul_s", "table", "recovery_energy_J_per_m", "over"):
        if k in tab:
            raise FieldError(f"adhesion.{k}", "only for model = 'wilac'")
    if sections:
        raise FieldError("adhesion.sections", "not for model = 'table' (one friction law on "
                         "the whole track)")
    if "parameters" in tab:
        for k in ("mu", "friction_ratio", "friction_decay_s_per_m"):
            if k in tab:
                raise FieldError(f"adhesion.{k}", "give either parameters (a Polach set's "
                                 "mu0, A, B) or mu, friction_ratio, friction_decay_s_per_m")
        name = polach_set_name(tab["parameters"], "adhesion.parameters")
        friction = {"parameters": name}
        p = POLACH_PARAMETER_SETS[name]
        law = (p.mu0, p.A, p.B)
    else:
        law = (number(tab.get("mu", 0.3), "adhesion.mu", 0.0, 2.0, low_open=True),
               number(tab.get("friction_ratio", 1.0), "adhesion.friction_ratio", 0.0, 1.0),
               number(tab.get("friction_decay_s_per_m", 0.0), "adhesion.friction_decay_s_per_m",
                      0.0, 100.0))
        friction = dict(zip(("mu", "friction_ratio", "friction_decay_s_per_m"), law,
                            strict=True))
    dry_set = _dry_set(tab)
    try:  # the contact must be in the table's range: say so when loading
        ExactTableAdhesion(*law, contact=contact)
    except ValueError as exc:
        raise FieldError("adhesion.rail_lateral_radius_m", str(exc)) from None
    return (lambda: ExactTableAdhesion(*law, contact=contact),
            lambda: ExactTableAdhesion.from_polach(dry_set, contact),
            {"model": "table", **friction})


def _identified_law(tab: Mapping, base: Path, wheel_radius: float):
    """``model = "law"``: an adhesion law identified from braking-test logs
    (:func:`railadhesion.identification.load_adhesion_law`, the ``adhesion_law.toml`` that
    ``railadhesion identify`` writes), the same on every axle and all along the track; the dry
    reference is a named Polach set (``dry_parameters``, default ``polach2005_dry``)."""
    from railadhesion.braking.adhesion_law import load_adhesion_law

    for k in ("parameters", "water_flow_ul_s", "sections", "table", "recovery_energy_J_per_m",
              "over"):
        if k in tab:
            raise FieldError(f"adhesion.{k}", "not for model = 'law' (the law file holds the "
                             "adhesion; give adhesion.file)")
    if "file" not in tab:
        raise FieldError("adhesion.file", "required for model = 'law': an adhesion-law TOML "
                         "file (as written by 'railadhesion identify')")
    text = string(tab["file"], "adhesion.file")
    path = Path(text) if Path(text).is_absolute() else base / text
    try:
        law = load_adhesion_law(path)
    except ValueError as exc:
        raise FieldError("adhesion.file", f"cannot load the adhesion law: {exc}") from None
    dry_set = _dry_set(tab)
    rail = number(tab.get("rail_lateral_radius_m", 0.3), "adhesion.rail_lateral_radius_m",
                  0.05, 10.0)
    contact = ContactGeometry(wheel_radius=wheel_radius, rail_lateral_radius=rail)
    label = f"identified law {path.name}"
    return (lambda: CallableAdhesion(law, label=label),
            lambda: PolachAdhesion(dry_set, (), contact),
            {"model": "law", "file": str(path), "slip": law.slip_kind})


def wsp_settings_fields(wt: Mapping) -> tuple[dict, WSPSettings]:
    """The WSP settings of a file's ``[wsp]`` table ``wt`` (its keys already checked): the
    keyword arguments of :class:`~railadhesion.braking.wsp.WSPSettings` from the TOML keys
    present (:func:`~railadhesion.braking.wsp.settings_file_keys`, each checked against its
    range) and the settings they make; errors are a ``FieldError`` naming the field, or
    ``wsp``."""
    kwargs = {}
    for key, (attr, lo, hi) in _WSP_KEYS.items():
        if key in wt:
            if attr == "watchdog_cutout_trips":
                kwargs[attr] = integer(wt[key], f"wsp.{key}", int(lo), int(hi))
            else:
                kwargs[attr] = number(wt[key], f"wsp.{key}", lo, hi)
    try:
        return kwargs, WSPSettings(**kwargs)
    except ValueError as exc:
        raise FieldError("wsp", str(exc)) from None


def _plausible_fields(label: str, v0: float, demand: float, max_pressure: float,
                      max_given: bool, water: float) -> tuple[str, ...]:  # fmt: skip
    """Warnings for the implausible fields of a scenario (module notes), naming them."""
    found = [
        check_plausible(v0, "initial_speed", where=f"{label}: run.initial_speed_m_s"),
        check_plausible(demand, "brake_pressure", where=f"{label}: brake.pressure_Pa"),
        check_plausible(max_pressure, "brake_pressure", where=f"{label}: brake.max_pressure_Pa",
                        what="brake-cylinder pressure limit"),
        check_plausible(water, "water_flow", where=f"{label}: adhesion.water_flow_ul_s"),
    ]  # fmt: skip
    if demand > max_pressure:
        given = "" if max_given else " (its default; set brake.max_pressure_Pa)"
        found.append(warn(
            f"{label}: brake.pressure_Pa = {demand:g} Pa is above brake.max_pressure_Pa = "
            f"{max_pressure:g} Pa{given}: the cylinders will hold {max_pressure:g} Pa, not the "
            "demand (docs/checks.md)", AlteredResultWarning,
        ))  # fmt: skip
    return tuple(f for f in found if f)


def _scenario_from_document(doc: Mapping, base: Path, label: str = "") -> BrakeScenario:
    keys(doc, "", ("format", "version", "vehicle", "run", "brake", "adhesion"),
         ("name", "description", "wsp"))
    if doc["format"] != SCENARIO_FORMAT:
        raise FieldError("format", f"expected {SCENARIO_FORMAT!r}, got {doc['format']!r}")
    integer(doc["version"], "version", 1, 1)
    name = string(doc.get("name", ""), "name")
    description = string(doc.get("description", ""), "description")
    # vehicle
    vt = table(doc["vehicle"], "vehicle")
    keys(vt, "vehicle", ("file",))
    vehicle = vehicle_from_field(string(vt["file"], "vehicle.file"), "vehicle.file", base)
    # run
    rt = table(doc["run"], "run")
    keys(rt, "run", ("initial_speed_m_s",), ("time_step_s", "max_time_s", "gradient",
                                              "refresh_period_s", "compare_dry"))
    v0 = number(rt["initial_speed_m_s"], "run.initial_speed_m_s", 0.1, 150.0)
    dt = number(rt.get("time_step_s", 1e-3), "run.time_step_s", 1e-5, 0.05)
    max_time = number(rt.get("max_time_s", 600.0), "run.max_time_s", 0.0, 1e5, low_open=True)
    gradient = number(rt.get("gradient", 0.0), "run.gradient", -0.1, 0.1)
    refresh = number(rt.get("refresh_period_s", 0.01), "run.refresh_period_s", 1e-5, 1.0)
    compare = boolean(rt.get("compare_dry", True), "run.compare_dry")
    # brake
    bt = table(doc["brake"], "brake")
    keys(bt, "brake", ("pressure_Pa",), ("start_time_s", "ramp_time_s", "fill_time_constant_s",
                                          "vent_time_constant_s", "max_pressure_Pa",
                                          "cylinder_volume_m3", "valves"))
    demand = BrakeDemand(
        number(bt["pressure_Pa"], "brake.pressure_Pa", 0.0, 2e6, low_open=True),
        number(bt.get("start_time_s", 0.0), "brake.start_time_s", 0.0, 1e4),
        number(bt.get("ramp_time_s", 0.0), "brake.ramp_time_s", 0.0, 100.0),
    )
    valves = string(bt.get("valves", "axle"), "brake.valves")
    if valves not in ("axle", "bogie"):
        raise FieldError("brake.valves", f"must be 'axle' or 'bogie', got {valves!r}")
    cylinder_fields = (
        number(bt.get("fill_time_constant_s", 0.3), "brake.fill_time_constant_s", 0.0, 100.0,
               low_open=True),
        number(bt.get("vent_time_constant_s", 0.15), "brake.vent_time_constant_s", 0.0, 100.0,
               low_open=True),
        number(bt.get("max_pressure_Pa", 3.8e5), "brake.max_pressure_Pa", 0.0, 2e6,
               low_open=True),
        number(bt.get("cylinder_volume_m3", 2e-3), "brake.cylinder_volume_m3", 0.0, 1.0,
               low_open=True),
        valves,
    )
    with warnings.catch_warnings():  # the field's own warning, naming it, follows
        warnings.simplefilter("ignore", PlausibilityWarning)
        cylinders = BrakeCylinders(*cylinder_fields)
    adhesion, dry, adhesion_info = _adhesion(doc["adhesion"], base, vehicle.wheel_radius)
    found = _plausible_fields(
        label or "scenario", v0, demand.pressure, cylinders.max_pressure,
        "max_pressure_Pa" in bt, float(adhesion_info.get("water_flow_ul_s", 0.0)),
    )  # fmt: skip
    # wsp
    wsp = None
    if "wsp" in doc:
        wt = table(doc["wsp"], "wsp")
        keys(wt, "wsp", (), ("enabled", *_WSP_KEYS))
        if boolean(wt.get("enabled", True), "wsp.enabled"):
            wsp = wsp_settings_fields(wt)[1]
            ratio = wsp.period / dt
            if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
                raise FieldError("wsp.period_s", f"must be a whole multiple of run.time_step_s "
                                 f"({dt} s), got {wsp.period} s")
    return BrakeScenario(name, vehicle, v0, demand, cylinders, adhesion, dry, wsp, dt,
                         max_time, gradient, refresh, compare, description,
                         {"adhesion": adhesion_info, "vehicle": vehicle.name}, found)


def load_scenario(path) -> BrakeScenario:
    """Read and validate a scenario TOML file (paths inside are relative to the file)."""
    return read_document(path, lambda doc, label: _scenario_from_document(
        doc, Path(os.fspath(path)).resolve().parent, label))


def run_scenario(scenario: BrakeScenario, progress=None, dt: float | None = None):
    """Run a scenario and, if ``compare_dry``, the same stop on a dry rail.

    Returns (result, dry_result or None); the result's summary holds the extension.
    """
    result = scenario.simulate(progress=progress, dt=dt)
    dry = None
    if scenario.compare_dry:
        dry = scenario.simulate(dry=True, dt=dt)
        result.compare_dry(dry)
    result.summary["scenario"] = scenario.name
    if scenario.warnings:  # the summary records what the file was warned for
        result.summary["scenario_warnings"] = list(scenario.warnings)
    return result, dry


_ = math
