"""Sweep spec files (TOML): what ``railadhesion sweep SPEC.toml --out map.zarr`` computes.

Format (``format = "railadhesion-sweep"``, ``format_version = 1``)::

    title = "WILAC map"                     # optional, stored in the map's attrs
    chunk_points = 262144                   # optional, target points per chunk

    [model]
    name = "wilac"            # wilac | polach | table | fletcher | elastic_foundation | carter
    parameters = "default"    # wilac: "default" or a parameter file; polach, table: a named
                              # Polach set or file (table: its mu0, A, B only)
    geometry = "tram"         # wilac/polach/table: "tram", "locomotive" or [a, b] in m
    # friction = "falling"    # table: "falling" or "coulomb"; mu, friction_ratio,
                              # friction_decay (numbers) instead of the set's
    # condition = "W1"        # 2D models: Fletcher's test code

    [grid]                    # dimension order = order of the keys
    creep_long = { start = 0.001, stop = 0.9, num = 60, spacing = "log" }
    speed = [5.0, 10.0, 20.0]                    # a list of values
    water_flow = { start = 0.0, stop = 100.0, step = 5.0 }

    [fixed]                   # inputs that are not swept
    creep_lat = 0.0

    [chunks]                  # optional chunk sizes along some dimensions
    creep_long = 60

Every field is validated; errors name the file and the field
(``map.toml: grid.speed.num: expected an integer >= 1, got 'ten'``). Unknown fields are
errors. Relative parameter-file paths are taken relative to the spec file. Careless values
give a warning naming the file and the field (``docs/checks.md``): a creepage above 1 (given
in percent?), a speed above 100 m/s (km/h?), a normal force outside 500 N to 500 kN (kN?), a
water flow above 1000 µl/s; so do loads and speeds outside a WILAC set's calibrated ranges,
where it holds its parameters. They are kept in :attr:`SweepSpec.warnings` and in the map's
``attrs["warnings"]``.
"""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.sweeps.models import LABEL_DIMENSIONS, SWEEP_MODELS, SweepModel, sweep_model
from railadhesion.sweeps.plan import DEFAULT_CHUNK_POINTS, SweepPlan, plan_sweep

__all__ = ["SpecError", "SweepSpec", "load_sweep_spec", "parse_sweep_spec"]

FORMAT = "railadhesion-sweep"
FORMAT_VERSION = 1

_MODEL_OPTIONS = {
    "wilac": ("parameters", "geometry", "shear_modulus", "poisson"),
    "polach": ("parameters", "geometry", "shear_modulus", "poisson"),
    "table": ("parameters", "geometry", "shear_modulus", "poisson", "friction", "mu",
              "friction_ratio", "friction_decay"),
    "fletcher": ("condition",),
    "elastic_foundation": ("condition",),
    "carter": ("condition",),
}


class SpecError(ValueError):
    """A spec file is invalid; the message names the file and the field."""


@dataclass
class SweepSpec:
    """A validated sweep spec: the model, the grid and how to cut it."""

    model: SweepModel
    grid: dict
    fixed: dict = field(default_factory=dict)
    chunks: dict = field(default_factory=dict)
    chunk_points: int = DEFAULT_CHUNK_POINTS
    title: str = ""
    source: str = ""
    #: Careless values found when loading (each also issued as a warning).
    warnings: tuple = ()

    def plan(self) -> SweepPlan:
        return plan_sweep(self.model, self.grid, fixed=self.fixed, chunks=self.chunks,
                          chunk_points=self.chunk_points)  # fmt: skip

    def run(self, out=None, **kwargs):
        """:func:`railadhesion.sweeps.run_sweep` of this spec (keywords passed on)."""
        from railadhesion.sweeps.run import run_sweep

        attrs = {"spec_file": self.source}
        if self.title:
            attrs["title"] = self.title
        if self.warnings:  # the map records what its spec was warned for
            attrs["warnings"] = json.dumps(list(self.warnings))
        return run_sweep(self.plan(), out=out, attrs=attrs, **kwargs)


# Field readers of spec files, shared by sweep and study specs: each names the field
# (dotted path) in its SpecError.


def fail_field(where: str, message: str):
    """Raise a :class:`SpecError` naming the field ``where``."""
    raise SpecError(f"{where}: {message}")


def int_field(value, where: str, low: int = 1) -> int:
    """``value`` if it is an integer >= ``low`` (not a bool), else a SpecError."""
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        fail_field(where, f"expected an integer >= {low}, got {value!r}")
    return value


def number_field(value, where: str) -> float:
    """``value`` as a float if it is a finite number (not a bool), else a SpecError."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        fail_field(where, f"expected a finite number, got {value!r}")
    return float(value)


def check_keys(table, where: str, allowed, required=()) -> None:
    """A SpecError unless ``table`` is a table holding only ``allowed`` keys and every
    ``required`` one."""
    if not isinstance(table, dict):
        fail_field(where, f"expected a table, got {table!r}")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        fail_field(f"{where}.{unknown[0]}" if where else unknown[0],
                   f"unknown field; allowed: {', '.join(allowed)}")  # fmt: skip
    for key in required:
        if key not in table:
            fail_field(f"{where}.{key}" if where else key, "missing (required)")


def axis_values(dim: str, value, where: str, base: Path):
    """Values of one grid dimension from a list or a range table."""
    if dim in LABEL_DIMENSIONS:
        values = value.get("values") if isinstance(value, dict) else value
        if isinstance(value, dict):
            check_keys(value, where, ("values",), ("values",))
            where = f"{where}.values"
        if not isinstance(values, list) or not values or not all(
            isinstance(v, str) for v in values
        ):
            fail_field(where, f"expected a non-empty list of names, got {values!r}")
        return [_path_label(v, base) for v in values]
    if isinstance(value, list):
        return [number_field(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if not isinstance(value, dict):
        fail_field(where, f"expected a list of numbers or a table (values, or start/stop/num), "
                     f"got {value!r}")  # fmt: skip
    check_keys(value, where, ("values", "start", "stop", "num", "step", "spacing"))
    if "values" in value:
        if len(value) > 1:
            fail_field(where,
                       "give either 'values' or a range (start, stop, num or step), not both")
        if not isinstance(value["values"], list) or not value["values"]:
            fail_field(f"{where}.values", f"expected a non-empty list of numbers, "
                                     f"got {value['values']!r}")  # fmt: skip
        return [number_field(v, f"{where}.values[{i}]") for i, v in enumerate(value["values"])]
    for key in ("start", "stop"):
        if key not in value:
            fail_field(f"{where}.{key}", "missing (a range needs start, stop and num or step)")
    start = number_field(value["start"], f"{where}.start")
    stop = number_field(value["stop"], f"{where}.stop")
    spacing = value.get("spacing", "linear")
    if spacing not in ("linear", "log"):
        fail_field(f"{where}.spacing", f"expected 'linear' or 'log', got {spacing!r}")
    if ("num" in value) == ("step" in value):
        fail_field(where, "give exactly one of 'num' and 'step'")
    if "step" in value:
        if spacing == "log":
            fail_field(f"{where}.step", "a step needs linear spacing; use num with spacing = 'log'")
        step = number_field(value["step"], f"{where}.step")
        if step <= 0 or stop < start:
            fail_field(f"{where}.step", f"expected step > 0 and stop >= start, got start={start}, "
                                   f"stop={stop}, step={step}")  # fmt: skip
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        return list(start + step * np.arange(n))
    num = int_field(value["num"], f"{where}.num")
    if spacing == "log":
        if start <= 0 or stop <= 0:
            fail_field(f"{where}.start",
                       f"log spacing needs start and stop > 0, got {start}, {stop}")
        return list(np.geomspace(start, stop, num))
    return list(np.linspace(start, stop, num))


def _path_label(label: str, base: Path) -> str:
    """Parameter-file labels relative to the spec file; names are kept."""
    if label.endswith(".toml") and not Path(label).is_absolute():
        return str((base / label).resolve())
    return label


def parse_sweep_spec(doc: dict, *, base: Path = Path("."), source: str = "") -> SweepSpec:
    """Validate a parsed spec (a dict from TOML) into a :class:`SweepSpec`."""
    check_keys(doc, "", ("format", "format_version", "title", "chunk_points", "model", "grid",
                    "fixed", "chunks"), ("format", "format_version", "model", "grid"))  # fmt: skip
    if doc["format"] != FORMAT:
        fail_field("format", f"expected {FORMAT!r}, got {doc['format']!r}")
    if doc["format_version"] != FORMAT_VERSION:
        fail_field("format_version", f"expected {FORMAT_VERSION}, got {doc['format_version']!r}")
    title = doc.get("title", "")
    if not isinstance(title, str):
        fail_field("title", f"expected a string, got {title!r}")
    chunk_points = int_field(doc.get("chunk_points", DEFAULT_CHUNK_POINTS), "chunk_points")

    m = doc["model"]
    check_keys(m, "model", ("name", *sorted({o for v in _MODEL_OPTIONS.values() for o in v})),
          ("name",))  # fmt: skip
    name = m["name"]
    if name not in SWEEP_MODELS:
        fail_field("model.name", f"expected one of {list(SWEEP_MODELS)}, got {name!r}")
    options = {}
    for key, value in m.items():
        if key == "name":
            continue
        if key not in _MODEL_OPTIONS[name]:
            fail_field(f"model.{key}", f"not an option of the {name!r} model; options: "
                                  f"{', '.join(_MODEL_OPTIONS[name])}")  # fmt: skip
        if key in ("shear_modulus", "poisson", "mu", "friction_ratio", "friction_decay"):
            value = number_field(value, f"model.{key}")
        elif key == "geometry" and isinstance(value, list):
            value = tuple(number_field(v, f"model.geometry[{i}]") for i, v in enumerate(value))
        elif not isinstance(value, str):
            fail_field(f"model.{key}", f"expected a string, got {value!r}")
        elif key == "parameters":
            value = _path_label(value, base)
        options[key] = value
    try:
        model = sweep_model(name, **options)
    except ValueError as exc:
        text = str(exc)
        if text.startswith("geometry:"):
            fail_field("model.geometry", text.split(":", 1)[1].strip())
        head = text.split(":", 1)[0]
        if head in options and head != "parameters":
            fail_field(f"model.{head}", text.split(":", 1)[1].strip())
        culprit = next((k for k in ("parameters", "condition") if k in options), None)
        fail_field(f"model.{culprit}" if culprit else "model", text)

    grid_doc = doc["grid"]
    if not isinstance(grid_doc, dict) or not grid_doc:
        fail_field("grid", "expected a table with at least one dimension")
    grid = {dim: axis_values(dim, value, f"grid.{dim}", base) for dim, value in grid_doc.items()}
    fixed = doc.get("fixed", {})
    if not isinstance(fixed, dict):
        fail_field("fixed", f"expected a table, got {fixed!r}")
    fixed = {k: (_path_label(v, base) if isinstance(v, str) else number_field(v, f"fixed.{k}"))
             for k, v in fixed.items()}  # fmt: skip
    chunks = doc.get("chunks", {})
    if not isinstance(chunks, dict):
        fail_field("chunks", f"expected a table, got {chunks!r}")
    chunks = {k: int_field(v, f"chunks.{k}") for k, v in chunks.items()}
    spec = SweepSpec(model, grid, fixed, chunks, chunk_points, title, source)
    try:
        spec.plan()  # the plan's checks name grid.<dim>, fixed.<input>, chunks.<dim>
    except ValueError as exc:
        raise SpecError(str(exc)) from None
    spec.warnings = _plausible_inputs(Path(source).name if source else "spec", model, grid,
                                      fixed)  # fmt: skip
    return spec


def _plausible_inputs(name: str, model, grid: dict, fixed: dict) -> tuple[str, ...]:
    """Warnings for careless numeric inputs of a spec (module notes), naming the field; for a
    WILAC map also the loads and speeds outside each parameter set's calibrated ranges, where
    the model holds its parameters (an AlteredResultWarning)."""
    from railadhesion.plausibility import ARGUMENT_QUANTITY, check_calibrated, check_plausible
    from railadhesion.sweeps.models import WilacSweep

    found = []
    if isinstance(model, WilacSweep):
        labels = grid.get("parameter_set", [fixed.get("parameter_set",
                                                      model.labels["parameter_set"])])
        for label in labels:
            params = model.resolve("parameter_set", str(label))
            what = f"the WILAC set {params.name or label!r}"
            for key, (lo, hi), unit in (("normal_force", params.normal_force_range, "N"),
                                        ("speed", params.speed_range, "m/s")):  # fmt: skip
                where, values = (f"grid.{key}", grid[key]) if key in grid else (
                    f"fixed.{key}", fixed.get(key))  # fmt: skip
                if values is not None and not isinstance(values, dict):
                    found.append(check_calibrated(np.asarray(values, dtype=float),
                                                  f"{name}: {where}", lo, hi, unit=unit,
                                                  what=what))  # fmt: skip
    for where, values in [*((f"grid.{k}", v) for k, v in grid.items()),
                          *((f"fixed.{k}", v) for k, v in fixed.items())]:  # fmt: skip
        columns = values if isinstance(values, dict) else {where.split(".", 1)[1]: values}
        for key, column in columns.items():
            if key in ARGUMENT_QUANTITY and not isinstance(column, str):
                label = where if not isinstance(values, dict) else f"{where}.{key}"
                found.append(check_plausible(np.asarray(column, dtype=float), key,
                                             where=f"{name}: {label}"))  # fmt: skip
    return tuple(f for f in found if f)


def load_sweep_spec(path) -> SweepSpec:
    """Read and validate a sweep spec file; errors name the file and the field.

    Raises
    ------
    SpecError
        A ValueError whose message starts with the file name and the dotted field.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"{path}: cannot read the spec file: {exc}") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"{path}: not valid TOML: {exc}") from None
    try:
        return parse_sweep_spec(doc, base=path.parent, source=str(path))
    except ValueError as exc:
        raise SpecError(f"{path.name}: {exc}") from None
