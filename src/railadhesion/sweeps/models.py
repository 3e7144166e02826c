"""The library's creep-force models as sweep models: named inputs, units and provenance.

A sweep model adapts one model function of :mod:`railadhesion.models` to a labelled grid: it
names the inputs that may be swept (the dimensions of the map), their units and defaults, and
evaluates a block of the grid by one broadcasting call of the model function. It adds no
physics: :meth:`SweepModel.evaluate` is the model function with the contact geometry filled in.

Numeric dimensions (:data:`DIMENSIONS`): ``creep_long``, ``creep_lat``, ``spin``, ``speed``,
``normal_force``, ``water_flow``. Label dimensions: ``parameter_set`` (Polach and WILAC: a
named set, ``"default"`` or a parameter-file path) and ``condition`` (the 2D models: one of
Fletcher's test codes).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from railadhesion.contact.geometry import check_geometry, contact_semi_axes

__all__ = [
    "DIMENSIONS",
    "LABEL_DIMENSIONS",
    "SweepModel",
    "ContactSweep",
    "WilacSweep",
    "PolachSweep",
    "ExactTableSweep",
    "TwoDSweep",
    "FunctionSweep",
    "SWEEP_MODELS",
    "sweep_model",
]

#: Numeric sweep dimensions: name -> (units, description). Creepage is a fraction.
DIMENSIONS: dict[str, tuple[str, str]] = {
    "creep_long": ("1", "longitudinal creepage xi = (V - omega R)/V, braking > 0"),
    "creep_lat": ("1", "lateral creepage eta"),
    "spin": ("rad/m", "spin creepage phi"),
    "speed": ("m/s", "rolling speed V"),
    "normal_force": ("N", "normal force Q"),
    "water_flow": ("µl/s", "water flow rate w to the rail surface"),
}

#: Label (categorical) sweep dimensions: name -> description.
LABEL_DIMENSIONS: dict[str, str] = {
    "parameter_set": "parameter set: a named set, 'default' or a parameter-file path",
    "condition": "Fletcher (2013) test condition (Table 1 test code)",
}


@dataclass(frozen=True)
class SweepModel:
    """Base of the sweep models; subclasses define the inputs and :meth:`evaluate`.

    Attributes
    ----------
    name : str
        Model name stored in the map's attributes.
    inputs : dict
        Numeric inputs the model takes, with their defaults (``None``: must be swept or fixed).
    labels : dict
        Label inputs the model takes, with their defaults.
    force_units : str
        Units of ``fx`` and ``fy`` (``"N"``; ``"N/m"`` for the 2D line-contact models).
    """

    name = "model"
    inputs: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    labels: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    force_units = "N"

    @property
    def outputs(self) -> dict[str, tuple[str, str]]:
        """Output variables in the order :meth:`evaluate` returns them: name -> (units, text)."""
        return {
            "fx": (self.force_units, "longitudinal force of the rail on the wheel (Kalker's "
                   "signs)"),
            "fy": (self.force_units, "lateral force of the rail on the wheel (Kalker's signs)"),
            "adhesion": ("1", "adhesion coefficient |T|/Q"),
        }  # fmt: skip

    def check_label(self, dim: str, label: str) -> None:
        """Raise ValueError if ``label`` is not valid for label dimension ``dim``."""
        self.resolve(dim, label)

    def resolve(self, dim: str, label: str):  # pragma: no cover - overridden
        raise ValueError(f"{dim}: the model {self.name!r} takes no labels")

    def evaluate(self, values: dict, labels: dict):  # pragma: no cover - overridden
        """The :attr:`outputs` (e.g. ``(fx, fy, adhesion)``) at broadcastable ``values``."""
        raise NotImplementedError

    def describe(self) -> dict:
        """JSON-serialisable description (model, parameters, provenance) for attrs."""
        raise NotImplementedError  # pragma: no cover


def _from_file(cache: dict, label: str, loader):
    """The parameter set of the file ``label`` read by ``loader`` (once: kept in ``cache``);
    a file that cannot be read is a ``ValueError`` naming the label."""
    if label not in cache:
        try:
            cache[label] = loader(label)
        except OSError as exc:
            raise ValueError(f"parameter_set: cannot read {label}: {exc}") from exc
    return cache[label]


@dataclass(frozen=True)
class ContactSweep(SweepModel):
    """Base of the 3D contact models with a parameter set (:class:`WilacSweep`,
    :class:`PolachSweep`): a Hertz geometry, elastic constants, a ``parameter_set`` label.
    Subclasses give :meth:`resolve` and :meth:`forces` (and their extra numeric inputs)."""

    parameters: object = None
    geometry: object = "tram"
    shear_modulus: float = 8.2e10
    poisson: float = 0.28
    extra_inputs = {}

    def __post_init__(self):
        object.__setattr__(self, "geometry", check_geometry(self.geometry))
        object.__setattr__(
            self, "inputs",
            {"creep_long": None, "creep_lat": 0.0, "spin": 0.0, "normal_force": None,
             "speed": None, **self.extra_inputs},
        )  # fmt: skip
        label = self.parameters if isinstance(self.parameters, str) else "<given>"
        object.__setattr__(self, "labels", {"parameter_set": label})
        self.resolve("parameter_set", label)

    @cached_property
    def _cache(self) -> dict:
        return {}

    def forces(self, values: dict, a, b, params):  # pragma: no cover - overridden
        """``(fx, fy)`` of the model at ``values`` with semi-axes ``a``, ``b`` and the set."""
        raise NotImplementedError

    def evaluate(self, values, labels):
        params = self.resolve("parameter_set", labels["parameter_set"])
        q = values["normal_force"]
        a, b = contact_semi_axes(self.geometry, q)
        fx, fy = self.forces(values, a, b, params)
        return fx, fy, np.hypot(fx, fy) / q


@dataclass(frozen=True)
class WilacSweep(ContactSweep):
    """WILAC (:func:`railadhesion.models.wilac.wilac_forces`, Trummer et al. 2017 §5) on a grid.

    Parameters
    ----------
    parameters : str or WilacParameters, optional
        ``"default"`` (the package's reconstructed set), a parameter-file path, or a set.
        Also the default label of a ``parameter_set`` dimension.
    geometry : str or (float, float), optional
        Named Hertz geometry (``"tram"``, ``"locomotive"``; semi-axes follow Q) or fixed
        semi-axes ``(a, b)`` [m].
    shear_modulus, poisson : float, optional
        Elastic constants passed to the model [Pa, -].

    Inputs: creep_long, creep_lat (0), spin (0), normal_force, speed, water_flow; labels:
    parameter_set.
    """

    parameters: object = "default"
    geometry: object = "tram"
    name = "wilac"
    extra_inputs = {"water_flow": None}

    def resolve(self, dim, label):
        from railadhesion.models.wilac import WilacParameters, default_wilac_parameters

        if dim != "parameter_set":
            raise ValueError(f"{dim}: the WILAC model takes only a 'parameter_set' label")
        if label == "<given>" and isinstance(self.parameters, WilacParameters):
            return self.parameters
        if label == "default":
            return default_wilac_parameters()
        from railadhesion.io.paramfiles import load_wilac_parameters

        return _from_file(self._cache, label, load_wilac_parameters)

    def forces(self, values, a, b, params):
        from railadhesion.models.wilac import wilac_forces

        return wilac_forces(
            values["creep_long"], values["creep_lat"], values["spin"], values["normal_force"],
            values["speed"], a, b, values["water_flow"], params,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )  # fmt: skip

    def describe(self):
        from railadhesion.io.paramfiles import wilac_parameters_to_toml

        out = {"model": "WILAC (Trummer et al. 2017, Tribology International 109, §5)",
               "geometry": _geometry_text(self.geometry),
               "shear_modulus": self.shear_modulus, "poisson": self.poisson}  # fmt: skip
        label = self.labels["parameter_set"]
        out["parameter_set"] = label
        out["parameters_toml"] = wilac_parameters_to_toml(self.resolve("parameter_set", label))
        return out


@dataclass(frozen=True)
class PolachSweep(ContactSweep):
    """Polach (:func:`railadhesion.models.polach.polach_forces`, Polach 2005) on a grid.

    Parameters
    ----------
    parameters : str or PolachParameters, optional
        A named set (:data:`railadhesion.models.parameters.POLACH_PARAMETER_SETS`), a Polach
        parameter-file path, or a set. Also the default label of a ``parameter_set`` dimension.
    geometry : str or (float, float), optional
        Named Hertz geometry (``"locomotive"``, ``"tram"``) or fixed semi-axes ``(a, b)`` [m].
    shear_modulus, poisson : float, optional
        Elastic constants [Pa, -].

    Inputs: creep_long, creep_lat (0), spin (0), normal_force, speed; labels: parameter_set.
    """

    parameters: object = "polach2005_dry"
    geometry: object = "locomotive"
    name = "polach"

    def resolve(self, dim, label):
        from railadhesion.models.parameters import (
            POLACH_PARAMETER_SETS,
            PolachParameters,
            polach_parameters,
        )

        if dim != "parameter_set":
            raise ValueError(f"{dim}: the Polach model takes only a 'parameter_set' label")
        if label == "<given>" and isinstance(self.parameters, PolachParameters):
            return self.parameters
        if label in POLACH_PARAMETER_SETS:
            return polach_parameters(label)
        if not (label.endswith(".toml") or Path(label).exists()):
            polach_parameters(label)  # raises, listing the named sets
        from railadhesion.io.paramfiles import load_polach_parameters

        return _from_file(self._cache, label, load_polach_parameters)

    def forces(self, values, a, b, params):
        from railadhesion.models.polach import polach_forces

        return polach_forces(
            values["creep_long"], values["creep_lat"], values["spin"], values["normal_force"],
            values["speed"], a, b, **params.as_dict(), shear_modulus=self.shear_modulus,
            poisson=self.poisson,
        )  # fmt: skip

    def describe(self):
        label = self.labels["parameter_set"]
        p = self.resolve("parameter_set", label)
        return {"model": "Polach (Polach 1999, VSD 33 suppl.; 2005, Wear 258)",
                "geometry": _geometry_text(self.geometry), "parameter_set": label,
                "parameters": {**p.as_dict(), "name": p.name, "source": p.source},
                "shear_modulus": self.shear_modulus, "poisson": self.poisson}  # fmt: skip


#: Friction laws of :class:`ExactTableSweep`.
TABLE_FRICTION = ("falling", "coulomb")


@dataclass(frozen=True)
class ExactTableSweep(PolachSweep):
    """The table model of Kalker's exact theory
    (:func:`railadhesion.contact.exact_table_forces`, Kalker 1990 ch. 5 tabulated) on a
    grid, with the inputs of :class:`PolachSweep`.

    Parameters
    ----------
    parameters : str or PolachParameters, optional
        A Polach set (named, a parameter-file path, or a set), of which the table model
        takes the friction only: μ0, and A, B with ``friction="falling"`` (its k_A, k_S,
        which reduce Polach's initial slope, have no counterpart in the exact theory). Also
        the default label of a ``parameter_set`` dimension.
    geometry : str or (float, float), optional
        Named Hertz geometry or fixed semi-axes ``(a, b)`` [m]; a/b in [0.2, 5].
    shear_modulus, poisson : float, optional
        Elastic constants [Pa, -]; ν in [0.25, 0.30] (the table's range).
    friction : str, optional
        ``"falling"`` (default): the set's falling friction μ0 [(1 − A) exp(−B w) + A] at the
        global slip velocity w = V sqrt(ξ² + η²) (where that is accurate:
        :func:`~railadhesion.contact.exact_table_forces`); ``"coulomb"``: μ0 throughout.
    mu, friction_ratio, friction_decay : float, optional
        μ0, A, B [s/m] instead of the set's (A, B only with ``friction="falling"``).

    Inputs: creep_long, creep_lat (0), spin (0), normal_force, speed; labels: parameter_set.
    """

    geometry: object = "locomotive"
    friction: str = "falling"
    mu: float | None = None
    friction_ratio: float | None = None
    friction_decay: float | None = None
    name = "table"

    def __post_init__(self):
        if self.friction not in TABLE_FRICTION:
            raise ValueError(f"friction: expected one of {list(TABLE_FRICTION)}, got "
                             f"{self.friction!r}")
        if self.friction == "coulomb" and (self.friction_ratio is not None
                                           or self.friction_decay is not None):
            raise ValueError("friction_ratio: friction_ratio and friction_decay only with "
                             "friction='falling'")
        for key, lo, hi in (("mu", 0.0, 2.0), ("friction_ratio", 0.0, 1.0),
                            ("friction_decay", 0.0, 100.0)):
            v = getattr(self, key)
            if v is not None and not (isinstance(v, int | float) and not isinstance(v, bool)
                                      and lo <= v <= hi and (key != "mu" or v > 0.0)):
                what = "(0, 2]" if key == "mu" else f"[{lo:g}, {hi:g}]"
                raise ValueError(f"{key}: must be a number in {what}, got {v!r}")
        if not 0.25 <= self.poisson <= 0.30:
            raise ValueError(f"poisson: must be in [0.25, 0.3] for the table model, got "
                             f"{self.poisson!r}")
        super().__post_init__()
        a, b = contact_semi_axes(self.geometry, 1e5)  # a/b does not change with the load
        if not 0.2 <= float(a) / float(b) <= 5.0:
            raise ValueError(f"geometry: a/b must be in [0.2, 5] for the table model, got "
                             f"{float(a) / float(b):.4g}")

    def law(self, params) -> tuple[float, float, float]:
        """(μ0, A, B) of the table model with the set ``params``."""
        mu = params.mu0 if self.mu is None else self.mu
        if self.friction == "coulomb":
            return mu, 1.0, 0.0
        ratio = params.A if self.friction_ratio is None else self.friction_ratio
        decay = params.B if self.friction_decay is None else self.friction_decay
        return mu, ratio, decay

    def forces(self, values, a, b, params):
        from railadhesion.contact.table import exact_table_forces

        mu, ratio, decay = self.law(params)
        fx, fy, _ = exact_table_forces(
            values["creep_long"], values["creep_lat"], values["spin"], values["normal_force"],
            a, b, mu, shear_modulus=self.shear_modulus, poisson=self.poisson,
            speed=values["speed"], friction_ratio=ratio, friction_decay=decay,
        )  # fmt: skip
        return fx, fy

    def describe(self):
        label = self.labels["parameter_set"]
        mu, ratio, decay = self.law(self.resolve("parameter_set", label))
        return {"model": "table model of Kalker's exact theory (Kalker 1990, ch. 5; "
                         "railadhesion.contact.exact_table_forces)",
                "geometry": _geometry_text(self.geometry), "parameter_set": label,
                "friction": self.friction, "mu": mu, "friction_ratio": ratio,
                "friction_decay": decay, "shear_modulus": self.shear_modulus,
                "poisson": self.poisson}  # fmt: skip


#: The 2D twin-disc models :class:`TwoDSweep` can evaluate.
TWOD_VARIANTS = ("fletcher", "elastic_foundation", "carter")


@dataclass(frozen=True)
class TwoDSweep(SweepModel):
    """Fletcher's 2D models (:mod:`railadhesion.models.twod`) at his test conditions.

    Parameters
    ----------
    condition : str, optional
        Fletcher 2013 test code (Table 1, e.g. ``"W1"``): load, half-width, radius, mu and the
        fitted k_a, k_s. Also the default label of a ``condition`` dimension.
    variant : str, optional
        ``"fletcher"`` (eqs. 8-12 with the condition's k_a, k_s), ``"elastic_foundation"``
        (k_a = k_s = 1) or ``"carter"`` (Carter 1926).

    Inputs: creep_long; labels: condition. Forces are per unit length of the line contact
    (``fx`` = traction [N/m], ``fy`` = 0); adhesion is |Q|/P.
    """

    condition: str = "W1"
    variant: str = "fletcher"
    force_units = "N/m"

    def __post_init__(self):
        if self.variant not in TWOD_VARIANTS:
            raise ValueError(
                f"variant: expected one of {list(TWOD_VARIANTS)}, got {self.variant!r}"
            )
        object.__setattr__(self, "inputs", {"creep_long": None})
        object.__setattr__(self, "labels", {"condition": self.condition})
        self.resolve("condition", self.condition)

    @property
    def name(self) -> str:
        return self.variant

    def resolve(self, dim, label):
        from railadhesion.models.twod import fletcher_condition

        if dim != "condition":
            raise ValueError(f"{dim}: the 2D models take only a 'condition' label")
        return fletcher_condition(label)

    def evaluate(self, values, labels):
        from railadhesion.models import twod

        c = self.resolve("condition", labels["condition"])
        xi = values["creep_long"]
        args = (xi, c.normal_load, c.half_width, c.radius, c.mu)
        if self.variant == "fletcher":
            res = twod.fletcher(*args, c.k_a, c.k_s)
        else:
            res = getattr(twod, self.variant)(*args)
        q = np.asarray(res.traction, dtype=float)
        return q, np.zeros_like(q), np.abs(q) / c.normal_load

    def describe(self):
        c = self.resolve("condition", self.condition)
        return {"model": f"{self.variant} 2D twin-disc model (Fletcher 2013, Proc. IMechE J 227)",
                "condition": self.condition, "source": c.source,
                "parameters": {"k_a": c.k_a, "k_s": c.k_s, "mu": c.mu,
                               "normal_load": c.normal_load, "half_width": c.half_width,
                               "radius": c.radius}}  # fmt: skip


@dataclass(frozen=True, eq=False)
class FunctionSweep(SweepModel):
    """Any task function as a sweep model: a study is a function over a scenario design.

    Parameters
    ----------
    function : callable
        ``function(**inputs) -> mapping or tuple`` of the outputs, in the order of
        ``outputs``. Must be importable by name (a module-level function) to run on a
        cluster, and pure: the same inputs give the same outputs.
    inputs : mapping
        Input names and defaults (``None``: must be swept or fixed).
    outputs : mapping
        Output names and their units (or ``(units, description)``).
    vectorized : bool, optional
        ``True``: ``function`` is called once per block with broadcastable arrays.
        ``False`` (default): once per point with floats, and a point that raises is recorded
        in ``error`` without affecting its neighbours.
    name : str, optional
        Stored in the attrs; default the function's qualified name.
    input_attrs : mapping, optional
        Per input name, attrs of its coordinate (``{"units": ..., "long_name": ...}``).
    description : mapping, optional
        JSON-serialisable parameters and provenance stored in the attrs.

    Examples
    --------
    >>> import math
    >>> from railadhesion.sweeps import run_sweep
    >>> def radius(x, y):
    ...     return math.sqrt(x * x - y)        # raises for y > x**2
    >>> model = FunctionSweep(radius, {"x": None, "y": 0.0}, {"r": "m"})
    >>> ds = run_sweep(model, {"x": [2.0, 3.0], "y": [0.0, 5.0]}).dataset
    >>> ds.r.values, ds.error.values
    (array([[ 2., nan],
           [ 3.,  2.]]), array([[0, 1],
           [0, 0]], dtype=uint8))
    """

    function: Callable = None
    input_defaults: Mapping = field(default_factory=dict)
    output_units: Mapping = field(default_factory=dict)
    vectorized: bool = False
    model_name: str = ""
    input_attrs: Mapping = field(default_factory=dict)
    description: Mapping = field(default_factory=dict)

    def __init__(self, function, inputs, outputs, *, vectorized=False, name="",
                 input_attrs=None, description=None):  # fmt: skip
        if not callable(function):
            raise ValueError(f"function: expected a callable, got {function!r}")
        if not inputs or not outputs:
            raise ValueError("inputs, outputs: expected at least one of each")
        for attr, value in (
            ("function", function), ("input_defaults", dict(inputs)),
            ("output_units", dict(outputs)), ("vectorized", bool(vectorized)),
            ("model_name", name or getattr(function, "__qualname__", "function")),
            ("input_attrs", dict(input_attrs or {})), ("description", dict(description or {})),
            ("inputs", dict(inputs)), ("labels", {}),
        ):  # fmt: skip
            object.__setattr__(self, attr, value)

    @property
    def name(self) -> str:
        return self.model_name

    @property
    def pointwise(self) -> bool:
        return not self.vectorized

    @property
    def outputs(self):
        return {k: (v, k) if isinstance(v, str) else tuple(v)
                for k, v in self.output_units.items()}  # fmt: skip

    def evaluate(self, values, labels):
        if self.vectorized:
            res = self.function(**values)
        else:
            res = self.function(**{k: float(np.ravel(v)[0]) for k, v in values.items()})
        if isinstance(res, Mapping):
            return tuple(res[k] for k in self.output_units)
        res = tuple(res) if isinstance(res, tuple | list) else (res,)
        if len(res) != len(self.output_units):
            raise ValueError(f"{self.name} returned {len(res)} values for the "
                             f"{len(self.output_units)} outputs {list(self.output_units)}")
        return res

    def describe(self):
        mod = getattr(self.function, "__module__", "?")
        return {"model": f"task function {mod}.{self.model_name}",
                "function": f"{mod}.{getattr(self.function, '__qualname__', '?')}",
                "vectorized": self.vectorized, **self.description}  # fmt: skip


def _geometry_text(geometry) -> str:
    if isinstance(geometry, str):
        return f"{geometry} (Hertz, railadhesion.contact.geometry.NAMED_GEOMETRIES)"
    return f"fixed semi-axes a = {geometry[0]!r} m, b = {geometry[1]!r} m"


#: Sweep models by name (the ``model.name`` of a spec file).
SWEEP_MODELS = {
    "wilac": WilacSweep,
    "polach": PolachSweep,
    "table": ExactTableSweep,
    "fletcher": lambda **kw: TwoDSweep(variant="fletcher", **kw),
    "elastic_foundation": lambda **kw: TwoDSweep(variant="elastic_foundation", **kw),
    "carter": lambda **kw: TwoDSweep(variant="carter", **kw),
}


def sweep_model(name: str, **options) -> SweepModel:
    """The sweep model ``name`` (a key of :data:`SWEEP_MODELS`) with its options.

    Examples
    --------
    >>> sweep_model("polach", parameters="polach2005_wet").inputs["creep_lat"]
    0.0
    """
    if name not in SWEEP_MODELS:
        raise ValueError(f"model: expected one of {list(SWEEP_MODELS)}, got {name!r}")
    return SWEEP_MODELS[name](**options)
