"""Braking studies: many stops of the braking simulator over a design of scenarios.

A study is a sweep like any other (:func:`railadhesion.sweeps.run_sweep`): the model is
:class:`BrakingStudy`, whose task is one stop of :func:`railadhesion.braking.simulate` per
point of a full-factorial grid or a Monte Carlo design
(:func:`~railadhesion.sweeps.plan.monte_carlo`). Each stop is a pure task, so the study
runs in-process or unchanged on a Dask cluster, resumes after an interruption, and records a
failing stop in ``error`` without stopping the study.

Inputs (all may be swept; units SI, water in µl/s): ``initial_speed`` [m/s] (required),
``water_flow`` [µl/s] (0), ``wet_length`` [m] (inf: the whole stop is wet; else the rail is
wet from the braking point over this length, dry beyond), ``payload`` [kg] (0: added to the
car body), ``brake_pressure`` [Pa] (5.5e5, an emergency brake), ``wsp`` (1: wheel-slide
protection on, 0: off).

Outputs per stop: stopping distance and time, the same stop on a dry rail (``water_flow = 0``)
and the extension against it (m and %), the longest lock and the total locked time of any
axle [s], the maximum creepage, and whether the train stopped before ``max_time``.

A stop that cannot be trusted (the train did not stop within ``max_time``, a NaN distance, or
a braking result flagged ``trusted = False``) is a failed point: its outputs are NaN and
``error`` holds the reason, so that ``failed stops: N`` counts it (``docs/checks.md``).
Spec files are checked for careless values (``load_study_spec``): a brake pressure below
0.05 bar or above 20 bar (bar for Pa?), or above the cylinders' ``max_pressure``, an initial
speed above 100 m/s (km/h?), a water flow above 1000 µl/s.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from railadhesion.sweeps.models import SweepModel

__all__ = [
    "BrakingStudy",
    "STUDY_INPUTS",
    "STUDY_OUTPUTS",
    "StudySpec",
    "load_study_spec",
    "plot_extension_distribution",
    "run_study",
]

#: Study inputs: name -> (units, description, default; None = required).
STUDY_INPUTS: dict[str, tuple[str, str, float | None]] = {
    "initial_speed": ("m/s", "initial speed of the stop", None),
    "water_flow": ("µl/s", "water flow rate to the rail on the wet section", 0.0),
    "wet_length": ("m", "length of the wet section from the braking point (inf: all)", math.inf),
    "payload": ("kg", "mass added to the car body", 0.0),
    "brake_pressure": ("Pa", "commanded brake-cylinder pressure (step at t = 0)", 5.5e5),
    "wsp": ("1", "wheel-slide protection on (1) or off (0)", 1.0),
}

#: Study outputs: name -> (units, description).
STUDY_OUTPUTS: dict[str, tuple[str, str]] = {
    "stopping_distance": ("m", "stopping distance"),
    "stopping_time": ("s", "stopping time"),
    "dry_stopping_distance": ("m", "stopping distance of the same stop on a dry rail (w = 0)"),
    "extension": ("m", "stopping-distance extension against the dry stop"),
    "extension_percent": ("%", "stopping-distance extension against the dry stop"),
    "longest_lock": ("s", "longest continuous lock of any axle (wheel below 10 % of the "
                     "train speed, train above 0.5 m/s)"),
    "max_slip": ("1", "largest creepage of any axle"),
    "stopped": ("1", "1 if the train stopped before max_time, else 0"),
}


@functools.lru_cache(maxsize=256)
def _stop(vehicle, wsp_settings: tuple, dt: float, max_time: float, max_pressure: float | None,
          initial_speed: float, water_flow: float, wet_length: float, payload: float,
          brake_pressure: float, wsp: bool):  # fmt: skip
    """One simulated stop (summary dict); memoised per process: the dry reference of a
    scenario is shared by all its flow rates. Pure: same arguments, same result."""
    from dataclasses import replace

    from railadhesion.braking import (
        BrakeCylinders,
        WaterFlowProfile,
        WheelSlideProtection,
        WilacAdhesion,
        WSPSettings,
        simulate,
    )

    veh = replace(vehicle, body_mass=vehicle.body_mass + payload) if payload else vehicle
    if math.isinf(wet_length):
        profile = WaterFlowProfile.constant(water_flow)
    else:
        profile = WaterFlowProfile.sections([(0.0, wet_length, water_flow)], base=0.0)
    controller = WheelSlideProtection(WSPSettings(**dict(wsp_settings))) if wsp else None
    cylinders = BrakeCylinders() if max_pressure is None else BrakeCylinders(
        max_pressure=max_pressure)  # fmt: skip
    res = simulate(veh, WilacAdhesion(profile), initial_speed, brake_pressure, wsp=controller,
                   dt=dt, max_time=max_time, cylinders=cylinders)  # fmt: skip
    s = res.summary
    untrusted = [str(w) for w in getattr(res, "warnings", ())] if not getattr(
        res, "trusted", True) else []  # fmt: skip
    if not res.success:
        untrusted.append(f"the train did not stop within max_time = {max_time:g} s "
                         f"({res.message})")  # fmt: skip
    if not math.isfinite(s["stopping_distance_m"]):
        untrusted.append(f"the stopping distance is {s['stopping_distance_m']} (NaN results)")
    return {
        "stopping_distance": s["stopping_distance_m"],
        "stopping_time": s["stopping_time_s"],
        "longest_lock": s["longest_lock_s"],
        "max_slip": s["max_slip"],
        "stopped": float(res.success),
        "untrusted": tuple(untrusted),
    }


@dataclass(frozen=True, eq=False)
class BrakingStudy(SweepModel):
    """Stops of :func:`railadhesion.braking.simulate` with WILAC adhesion, as a sweep model.

    Parameters
    ----------
    vehicle : str or Vehicle, optional
        A shipped vehicle name (``"coach_default"``), a vehicle TOML file or a ``Vehicle``.
    wsp_settings : mapping, optional
        Fields of :class:`railadhesion.braking.WSPSettings` (thresholds of the WSP).
    dt : float, optional
        Simulation step [s].
    max_time : float, optional
        Longest simulated stop [s].
    max_pressure : float or None, optional
        Pressure limit of the brake cylinders [Pa]; default 6e5, as in the example scenarios,
        so that the default emergency demand ``brake_pressure = 5.5e5`` is applied as asked
        (``None``: the default of :class:`railadhesion.braking.BrakeCylinders`, 3.8 bar, which
        would clip it). A ``brake_pressure`` above it is clipped by the cylinders, and
        :func:`load_study_spec` warns.
    """

    vehicle: object = "coach_default"
    wsp_settings: dict = field(default_factory=dict)
    dt: float = 1e-3
    max_time: float = 600.0
    max_pressure: float | None = 6e5
    name = "braking_study"
    pointwise = True

    def __post_init__(self):
        object.__setattr__(self, "inputs", {k: v[2] for k, v in STUDY_INPUTS.items()})
        object.__setattr__(self, "labels", {})
        object.__setattr__(self, "wsp_settings", dict(self.wsp_settings))
        self._vehicle()  # validates
        from railadhesion.braking import BrakeCylinders, WSPSettings

        WSPSettings(**self.wsp_settings)
        if self.max_pressure is not None:
            BrakeCylinders(max_pressure=self.max_pressure)  # validates

    @property
    def cylinder_max_pressure(self) -> float:
        """The cylinders' pressure limit [Pa] the stops use."""
        from railadhesion.braking import BrakeCylinders

        return BrakeCylinders().max_pressure if self.max_pressure is None else self.max_pressure

    @property
    def input_attrs(self):
        return {k: {"units": u, "long_name": t} for k, (u, t, _) in STUDY_INPUTS.items()}

    @property
    def outputs(self):
        return dict(STUDY_OUTPUTS)

    def _vehicle(self):
        from railadhesion.braking import Vehicle, load_vehicle

        if isinstance(self.vehicle, Vehicle):
            return self.vehicle
        return load_vehicle(self.vehicle)

    def evaluate(self, values, labels):
        x = {k: float(np.ravel(v)[0]) for k, v in values.items()}
        if not x["initial_speed"] > 0:
            raise ValueError(f"initial_speed must be > 0 m/s, got {x['initial_speed']}")
        if x["wsp"] not in (0.0, 1.0):
            raise ValueError(f"wsp must be 0 or 1, got {x['wsp']}")
        common = (self._vehicle(), tuple(sorted(self.wsp_settings.items())), self.dt,
                  self.max_time, self.max_pressure, x["initial_speed"])  # fmt: skip
        rest = (x["payload"], x["brake_pressure"], bool(x["wsp"]))
        wet = _stop(*common, x["water_flow"], x["wet_length"], *rest)
        dry = _stop(*common, 0.0, math.inf, *rest)
        for label, stop in (("", wet), ("the dry reference stop: ", dry)):
            if stop["untrusted"]:  # a failed point, its reason in the sweep's error record
                raise ValueError(label + stop["untrusted"][0])
        d, d0 = wet["stopping_distance"], dry["stopping_distance"]
        out = {**wet, "dry_stopping_distance": d0, "extension": d - d0,
               "extension_percent": 100.0 * (d - d0) / d0}  # fmt: skip
        return tuple(out[k] for k in STUDY_OUTPUTS)

    def describe(self):
        import dataclasses

        veh = self._vehicle()
        fields_ = {f.name: getattr(veh, f.name) for f in dataclasses.fields(veh)
                   if f.name != "provenance"}  # fmt: skip
        return {"model": "braking stops: railadhesion.braking.simulate with WILAC adhesion "
                         "(Trummer et al. 2017) and the default WILAC set",
                "vehicle": fields_, "wsp_settings": self.wsp_settings, "dt": self.dt,
                "max_time": self.max_time,
                "max_pressure": self.cylinder_max_pressure}  # fmt: skip


def plot_extension_distribution(ds, by: str = "water_flow", *, bins: int = 8, ax=None):
    """Distribution of the stopping-distance extension [%] per water flow rate (box plots).

    ``by`` is a dimension of the study (one box per value, over all other dimensions) or a
    coordinate along a Monte Carlo ``sample`` dimension (then grouped into ``bins``
    quantile bins). Failed stops are left out. Returns the matplotlib Figure.
    """
    from matplotlib.figure import Figure

    ext = ds["extension_percent"]
    if "error" in ds:
        ext = ext.where(ds["error"] == 0)
    groups, labels = [], []
    if by in ext.dims:
        for value in ds[by].values:
            v = ext.sel({by: value}).values.ravel()
            groups.append(v[np.isfinite(v)])
            labels.append(f"{value:g}")
    elif by in ds.coords:
        key = np.broadcast_to(ds[by].values.reshape(
            [ext.sizes[d] if d in ds[by].dims else 1 for d in ext.dims]), ext.shape).ravel()
        vals = ext.values.ravel()
        distinct = np.unique(key)
        if distinct.size <= bins:  # e.g. a "choice" distribution: one box per value
            for value in distinct:
                sel = (key == value) & np.isfinite(vals)
                groups.append(vals[sel])
                labels.append(f"{value:g}")
        else:
            edges = np.unique(np.quantile(key, np.linspace(0, 1, bins + 1)))
            for lo, hi in zip(edges[:-1], edges[1:], strict=True):
                sel = (key >= lo) & ((key < hi) | (hi == edges[-1])) & np.isfinite(vals)
                groups.append(vals[sel])
                labels.append(f"{lo:.3g}–{hi:.3g}")
    else:
        raise ValueError(f"by: {by!r} is neither a dimension nor a coordinate of the study")
    if ax is None:
        fig = Figure(figsize=(7, 4.2), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    ax.boxplot(groups, tick_labels=labels)
    units = ds[by].attrs.get("units", "")
    ax.set_xlabel(f"{by} [{units}]" if units else by)
    ax.set_ylabel("stopping-distance extension against dry [%]")
    ax.set_title(f"Stopping-distance extension per {by} ({sum(map(len, groups))} stops)")
    ax.grid(True, axis="y", alpha=0.3)
    return fig


# ----------------------------------------------------------------------------- spec files

STUDY_FORMAT = "railadhesion-study"
_DISTRIBUTIONS = {"uniform": 2, "normal": 2, "lognormal": 2, "choice": 1}


@dataclass
class StudySpec:
    """A validated study spec (``railadhesion study SPEC.toml --out DIR``); ``warnings`` holds
    the careless values found when loading it (each also issued as a warning)."""

    model: BrakingStudy
    grid: dict
    fixed: dict
    chunks: dict
    title: str = ""
    source: str = ""
    warnings: tuple = ()

    def plan(self):
        from railadhesion.sweeps.plan import plan_sweep

        return plan_sweep(self.model, self.grid, fixed=self.fixed, chunks=self.chunks,
                          chunk_points=4)  # fmt: skip


def _plausible_study(name: str, model: BrakingStudy, grid: dict, fixed: dict) -> tuple:
    """Warnings for careless values of a study spec (module notes), naming the field."""
    from railadhesion.plausibility import AlteredResultWarning, check_plausible, warn

    def values(key):  # (field, values) of a study input: swept, drawn, fixed or default
        if key in grid:
            return f"grid.{key}", np.asarray(grid[key], dtype=float)
        for dim, columns in grid.items():
            if isinstance(columns, dict) and key in columns:
                return f"distributions.{key} (along {dim})", np.asarray(columns[key], float)
        if key in fixed:
            return f"fixed.{key}", np.asarray(fixed[key], dtype=float)
        return f"{key} (default)", np.asarray(STUDY_INPUTS[key][2], dtype=float)

    found = []
    for key in ("initial_speed", "water_flow", "brake_pressure"):
        where, x = values(key)
        if x.size:
            found.append(check_plausible(x, key, where=f"{name}: {where}"))
    where, x = values("brake_pressure")
    limit = model.cylinder_max_pressure
    if x.size and float(np.max(x)) > limit:
        given = "study.max_pressure" if model.max_pressure is not None else (
            "the cylinders' default; set study.max_pressure")  # fmt: skip
        found.append(warn(
            f"{name}: {where} reaches {float(np.max(x)):g} Pa, above the brake cylinders' "
            f"max_pressure = {limit:g} Pa ({given}): the cylinders will hold {limit:g} Pa, not "
            "the demand (docs/checks.md)", AlteredResultWarning,
        ))  # fmt: skip
    return tuple(f for f in found if f)


def load_study_spec(path) -> StudySpec:
    """Read and validate a study spec; errors name the file and the field.

    Format (``format = "railadhesion-study"``, ``format_version = 1``): ``[study]`` vehicle,
    dt, max_time, max_pressure (the cylinders' limit [Pa]), wsp_settings; ``[design]`` kind =
    "factorial" or "monte_carlo" (with n and seed); ``[grid]`` swept inputs (lists or ranges,
    as in sweep specs); ``[distributions]`` (Monte Carlo) input = ["uniform", low, high] |
    ["normal", mean, sd] | ["lognormal", mean_of_log, sd_of_log] | ["choice", [values]];
    ``[fixed]`` other inputs.
    See ``examples/braking_study.toml``.
    """
    import tomllib
    from pathlib import Path

    from railadhesion.sweeps.plan import monte_carlo
    from railadhesion.sweeps.spec import (
        SpecError,
        axis_values,
        check_keys,
        fail_field,
        int_field,
        number_field,
    )

    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"{path}: cannot read the spec file: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"{path}: not valid TOML: {exc}") from None
    try:
        check_keys(doc, "", ("format", "format_version", "title", "study", "design", "grid",
                        "distributions", "fixed", "chunks"),
              ("format", "format_version", "design"))  # fmt: skip
        if doc["format"] != STUDY_FORMAT:
            fail_field("format", f"expected {STUDY_FORMAT!r}, got {doc['format']!r}")
        if doc["format_version"] != 1:
            fail_field("format_version", f"expected 1, got {doc['format_version']!r}")
        study = doc.get("study", {})
        check_keys(study, "study", ("vehicle", "dt", "max_time", "max_pressure", "wsp_settings"))
        options = {}
        if "vehicle" in study:
            v = study["vehicle"]
            if not isinstance(v, str):
                fail_field("study.vehicle", f"expected a vehicle name or file, got {v!r}")
            options["vehicle"] = str((path.parent / v).resolve()) if v.endswith(".toml") else v
        for key in ("dt", "max_time", "max_pressure"):
            if key in study:
                options[key] = number_field(study[key], f"study.{key}")
                if options[key] <= 0:
                    fail_field(f"study.{key}", f"expected a number > 0, got {study[key]!r}")
        if "wsp_settings" in study:
            ws = study["wsp_settings"]
            if not isinstance(ws, dict):
                fail_field("study.wsp_settings", f"expected a table, got {ws!r}")
            options["wsp_settings"] = {k: number_field(v, f"study.wsp_settings.{k}")
                                       for k, v in ws.items()}  # fmt: skip
        try:
            model = BrakingStudy(**options)
        except (ValueError, TypeError) as exc:
            fail_field("study", str(exc))
        design = doc["design"]
        check_keys(design, "design", ("kind", "n", "seed"), ("kind",))
        kind = design["kind"]
        if kind not in ("factorial", "monte_carlo"):
            fail_field("design.kind", f"expected 'factorial' or 'monte_carlo', got {kind!r}")
        grid = {}
        for dim, value in doc.get("grid", {}).items():
            if dim not in STUDY_INPUTS:
                fail_field(f"grid.{dim}", f"not a study input; inputs: {', '.join(STUDY_INPUTS)}")
            grid[dim] = axis_values(dim, value, f"grid.{dim}", path.parent)
        dists = doc.get("distributions", {})
        if kind == "monte_carlo":
            for key in ("n", "seed"):
                if key not in design:
                    fail_field(f"design.{key}", "missing (required for a Monte Carlo design)")
            n = int_field(design["n"], "design.n")
            seed = int_field(design["seed"], "design.seed", low=0)
            if not isinstance(dists, dict) or not dists:
                fail_field("distributions", "a Monte Carlo design needs at least one distribution")
            checked = {}
            for name, spec in dists.items():
                where = f"distributions.{name}"
                if name not in STUDY_INPUTS:
                    fail_field(where, f"not a study input; inputs: {', '.join(STUDY_INPUTS)}")
                if not (isinstance(spec, list) and spec and spec[0] in _DISTRIBUTIONS
                        and len(spec) == 1 + _DISTRIBUTIONS[spec[0]]):  # fmt: skip
                    fail_field(where, "expected [\"uniform\", low, high], [\"normal\", mean, sd], "
                          "[\"lognormal\", mean_of_log, sd_of_log] or [\"choice\", [values]], "
                          f"got {spec!r}")  # fmt: skip
                if spec[0] == "choice":
                    if not isinstance(spec[1], list) or not spec[1]:
                        fail_field(where, "choice needs a non-empty list of values")
                    args = [[number_field(x, f"{where}[1]") for x in spec[1]]]
                else:
                    args = [number_field(x, f"{where}[{i + 1}]") for i, x in enumerate(spec[1:])]
                checked[name] = (spec[0], *args)
            grid.update(monte_carlo(n, seed, **checked))
        elif dists:
            fail_field("distributions", "only for design.kind = 'monte_carlo'")
        elif "n" in design or "seed" in design:
            fail_field("design.n" if "n" in design else "design.seed",
                  "only for design.kind = 'monte_carlo'")  # fmt: skip
        if not grid:
            fail_field("grid", "expected at least one swept input")
        fixed = doc.get("fixed", {})
        if not isinstance(fixed, dict):
            fail_field("fixed", f"expected a table, got {fixed!r}")
        fixed = {k: number_field(v, f"fixed.{k}") for k, v in fixed.items()}
        chunks = {k: int_field(v, f"chunks.{k}") for k, v in doc.get("chunks", {}).items()}
        title = doc.get("title", "")
        if not isinstance(title, str):
            fail_field("title", f"expected a string, got {title!r}")
        spec = StudySpec(model, grid, fixed, chunks, title, str(path))
        try:
            spec.plan()
        except ValueError as exc:
            raise SpecError(str(exc)) from None
        spec.warnings = _plausible_study(path.name, model, grid, fixed)
        return spec
    except SpecError as exc:
        raise SpecError(f"{path.name}: {exc}") from None


def run_study(spec: StudySpec, out_dir, **kwargs):
    """Run a study into ``out_dir``: ``study.zarr`` (resumable), ``study.csv`` (one row per
    stop), ``extension.png`` (extension distribution per flow rate). Keywords go to
    :func:`railadhesion.sweeps.run_sweep`. Returns the :class:`SweepResult`."""
    from pathlib import Path

    from railadhesion.sweeps.run import run_sweep

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    attrs = {"spec_file": spec.source, "title": spec.title or "braking study"}
    if spec.warnings:  # the study records what its spec was warned for
        import json

        attrs["warnings"] = json.dumps(list(spec.warnings))
    result = run_sweep(spec.plan(), out=out_dir / "study.zarr", attrs=attrs, **kwargs)
    ds = result.dataset.load()
    ds.to_dataframe().reset_index().to_csv(out_dir / "study.csv", index=False)
    if "water_flow" in ds.dims or "water_flow" in ds.coords:
        fig = plot_extension_distribution(ds)
        fig.savefig(out_dir / "extension.png", dpi=110)
    return result
