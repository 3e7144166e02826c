"""WILAC's parameter set and water-flow weighting: what a WILAC parameter file describes.

The four conditions, their Polach-parameter regressions on Q' and v' (Trummer et al., seed
000, section 5.2), the physical bounds, the erf transitions and blending weights of the water
flow rate (section 5.3, Table 1) and :class:`WilacParameters`. The forces are in
:mod:`railadhesion.models.wilac`, which re-exports every name here.

This module imports nothing from :mod:`railadhesion.io`, so that the parameter-file reader
(:mod:`railadhesion.io.paramfiles`) can build these objects and the model can load its
default file through that reader, without an import circle.
"""

from __future__ import annotations

import datetime
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from numbers import Real
from typing import NamedTuple

import numpy as np

from railadhesion._docstrings import docstring_entries
from railadhesion._labelled import labelled
from railadhesion._validate import check_choice, check_nonnegative, check_positive
from railadhesion.models.parameters import PARAMETER_RANGES
from railadhesion.models.regression import ParameterRegression
from railadhesion.numerics import exp, flatten, jitable, kernel, read_only
from railadhesion.plausibility import check_calibrated

__all__ = [
    "WILAC_CONDITIONS",
    "POLACH_PARAMETER_NAMES",
    "PHYSICAL_BOUNDS",
    "PROVENANCE_FIELDS",
    "WaterTransition",
    "PAPER_TRANSITIONS",
    "wilac_transitions",
    "wilac_weights",
    "WilacCondition",
    "WilacParameters",
    "PACKED_HEADER",
    "pack_wilac",
    "wilac_blend_weights",
    "wilac_clip",
    "wilac_factors",
    "wilac_normalise",
    "wilac_regression",
    "wilac_term",
    "wilac_terms",
    "wilac_transition",
]

#: The four representative conditions, from dry to wet (seed 000, section 5.3). Weights and
#: every per-condition array use this order.
WILAC_CONDITIONS: tuple[str, ...] = ("dry", "damp2", "damp1", "wet")

#: The five Polach parameters each condition defines (seed 000, section 5.1).
POLACH_PARAMETER_NAMES: tuple[str, ...] = ("k_A", "k_S", "mu0", "A", "B")

#: Physical ranges the regression outputs are clipped to, ``(low, high)``: the ranges of
#: :data:`railadhesion.models.parameters.PARAMETER_RANGES` (k_A, k_S in (0, 1], mu0 in (0, 1.5],
#: A in [0, 10], B in [0, 100] s/m), open lower bounds replaced by the floor 1e-4 so that the
#: clipped value stays strictly positive. ``k_S <= k_A`` is *not* enforced: Polach reports it as
#: typical, the model does not need it, and clipping one regression against another would
#: silently alter a calibrated set.
PHYSICAL_BOUNDS: dict[str, tuple[float, float]] = {
    name: (low if low_closed else max(low, 0.0) + 1e-4, high)
    for name, (low, high, low_closed, _high_closed) in PARAMETER_RANGES.items()
}

#: Allowed provenance fields and their types (``created`` is an ISO date, ``YYYY-MM-DD``).
PROVENANCE_FIELDS: dict[str, type] = {
    "source": str,
    "reconstruction": bool,
    "description": str,
    "created": datetime.date,
    "script": str,
    "licence": str,
    "notes": str,
}


class WaterTransition(NamedTuple):
    """One transition ``e(w) = ½ (erf((w − midpoint)/width) + 1)`` between two conditions.

    Attributes
    ----------
    midpoint : float
        Water flow rate where ``e = 0.5`` (``m`` in seed 000, Table 1) [µl/s].
    width : float
        Width of the transition (``s`` in seed 000, Table 1) [µl/s], > 0.
    """

    midpoint: float
    width: float


#: Transitions e_1 (Dry–Damp2), e_2 (Damp2–Damp1), e_3 (Damp1–Wet) of seed 000, Table 1.
PAPER_TRANSITIONS: tuple[WaterTransition, ...] = (
    WaterTransition(15.0, 5.0),
    WaterTransition(30.0, 3.0),
    WaterTransition(50.0, 7.0),
)


def check_transitions(transitions, where: str = "transitions") -> tuple[WaterTransition, ...]:
    """Validated tuple of three :class:`WaterTransition`; errors name ``where``."""
    try:
        items = list(transitions)
    except TypeError as exc:
        raise ValueError(
            f"{where}: expected 3 (midpoint, width) pairs, got {transitions!r}"
        ) from exc
    if len(items) != 3:
        raise ValueError(f"{where}: expected 3 (midpoint, width) pairs, got {len(items)}")
    out = []
    for i, item in enumerate(items, start=1):
        try:
            m, s = item
            m, s = float(m), float(s)
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"{where}: e{i} must be a (midpoint, width) pair, got {item!r}"
            ) from exc
        if not math.isfinite(m):
            raise ValueError(f"{where}: e{i} midpoint must be finite, got {m!r}")
        if not (math.isfinite(s) and s > 0):
            raise ValueError(f"{where}: e{i} width must be in (0, inf) µl/s, got {s!r}")
        out.append(WaterTransition(m, s))
    if not (out[0].midpoint < out[1].midpoint < out[2].midpoint):
        raise ValueError(
            f"{where}: midpoints must increase strictly (e1 < e2 < e3: dry → damp2 → damp1 → "
            f"wet), got {[t.midpoint for t in out]}"
        )
    # The weights f_Damp2 = e1 - e2 and f_Damp1 = e2 - e3 turn negative where a later, narrower
    # transition overtakes an earlier, wider one; reject sets where that is more than a rounding.
    lo = min(0.0, out[0].midpoint - 10 * out[0].width)
    hi = out[2].midpoint + 10 * max(t.width for t in out)
    e = _transitions(np.linspace(lo, hi, 4001), out)
    worst = float(np.min(e[:-1] - e[1:]))
    if worst < -1e-6:
        raise ValueError(
            f"{where}: the transitions cross (a blending weight reaches {worst:.3g} < 0); "
            "make the later transitions start after the earlier ones end"
        )
    return tuple(out)


@jitable
def wilac_transition(w, midpoint, width):
    """e(w) = ½ (erf((w − m)/s) + 1), one transition between two conditions (Trummer et al.,
    seed 000, section 5.3, with the (m, s) of Table 1)."""
    return 0.5 * (math.erf((w - midpoint) / width) + 1.0)


@jitable
def wilac_blend_weights(w, m1, s1, m2, s2, m3, s3):
    """The blending weights (f_Dry, f_Damp2, f_Damp1, f_Wet) at the water flow ``w`` [µl/s]
    from the three transitions (m_i, s_i): f_Dry = 1 − e_1, f_Damp2 = e_1 − e_2,
    f_Damp1 = e_2 − e_3, f_Wet = e_3 (seed 000, section 5.3)."""
    e1 = wilac_transition(w, m1, s1)
    e2 = wilac_transition(w, m2, s2)
    e3 = wilac_transition(w, m3, s3)
    return 1.0 - e1, e1 - e2, e2 - e3, e3


@kernel(nogil=True)
def _transitions_into(w, m1, s1, m2, s2, m3, s3, out):
    """e_1, e_2, e_3 (out rows 0-2) or, if out has 4 rows, the four weights of water flows w."""
    for k in range(w.size):
        if out.shape[0] == 4:
            out[0, k], out[1, k], out[2, k], out[3, k] = wilac_blend_weights(w[k], m1, s1, m2,
                                                                             s2, m3, s3)
        else:
            out[0, k] = wilac_transition(w[k], m1, s1)
            out[1, k] = wilac_transition(w[k], m2, s2)
            out[2, k] = wilac_transition(w[k], m3, s3)


def _transitions(w: np.ndarray, transitions, rows: int = 3) -> np.ndarray:
    """e_1, e_2, e_3 (``rows`` 3) or the four weights (4) of valid water flows ``w`` (any
    shape): (rows, *w.shape)."""
    w = np.asarray(w, dtype=float)
    flat = read_only(np.ascontiguousarray(w).reshape(-1))
    out = np.empty((rows, flat.size))
    _transitions_into(flat, *(float(x) for t in transitions for x in t), out)
    return out.reshape((rows, *w.shape))


def _as_transition_key(transitions) -> tuple:
    try:
        return tuple((float(m), float(s)) for m, s in transitions)
    except (TypeError, ValueError):
        check_transitions(transitions)  # raises the specific error
        raise


#: The numpydoc entry of the water flow, shared by :func:`wilac_transitions` and
#: :func:`wilac_weights` (put in place of ``{water_flow}``).
_WATER_FLOW_PARAMETER = """water_flow : array_like
        Water flow rate w to the rail surface [µl/s], finite and >= 0."""


@labelled(units="1", leading={"transition": ("e1", "e2", "e3")})
@docstring_entries(water_flow=_WATER_FLOW_PARAMETER)
def wilac_transitions(water_flow, transitions=PAPER_TRANSITIONS) -> np.ndarray:
    """Transition functions e_1, e_2, e_3 of the WILAC model.

    Parameters
    ----------
    {water_flow}
    transitions : sequence of 3 (midpoint, width) pairs, optional
        Position m_i and width s_i of each transition [µl/s]; default: seed 000, Table 1.

    Returns
    -------
    numpy.ndarray
        Shape ``(3, *np.shape(water_flow))``: ``e_i = ½ (erf((w − m_i)/s_i) + 1)``, in [0, 1].

    Notes
    -----
    Trummer et al. (seed 000), section 5.3, the equation for e_i, with Table 1:
    (m, s) = (15, 5), (30, 3), (50, 7) µl/s for e_1 (Damp2–Dry), e_2 (Damp1–Damp2) and
    e_3 (Wet–Damp1).

    References
    ----------
    G. Trummer, L.E. Buckley-Johnstone, P. Voltr, A. Meierhofer, R. Lewis, K. Six.
    Wheel-rail creep force model for predicting water induced low adhesion phenomena.
    Tribology International 109 (2017) 409–415.

    Examples
    --------
    >>> [round(float(x), 4) for x in wilac_transitions(30.0)]
    [1.0, 0.5, 0.0]
    """
    return _water_flow_laws(water_flow, transitions, 3)


@labelled(units="1", leading={"condition": WILAC_CONDITIONS})
@docstring_entries(water_flow=_WATER_FLOW_PARAMETER)
def wilac_weights(water_flow, transitions=PAPER_TRANSITIONS) -> np.ndarray:
    """Blending weights f_Dry, f_Damp2, f_Damp1, f_Wet of the WILAC model.

    Parameters
    ----------
    {water_flow}
    transitions : sequence of 3 (midpoint, width) pairs, optional
        Transition positions and widths [µl/s]; default: seed 000, Table 1.

    Returns
    -------
    numpy.ndarray
        Shape ``(4, *np.shape(water_flow))``, in :data:`WILAC_CONDITIONS` order. The weights
        sum to 1 for every w.

    Notes
    -----
    Trummer et al. (seed 000), section 5.3, the equations for f_i: f_Dry = 1 − e_1,
    f_Damp2 = e_1 − e_2, f_Damp1 = e_2 − e_3, f_Wet = e_3, with e_i from
    :func:`wilac_transitions` (reference there); evaluated by :func:`wilac_blend_weights`.

    Examples
    --------
    >>> [round(float(f), 4) for f in wilac_weights(25.0)]
    [0.0023, 0.9885, 0.0092, 0.0]
    >>> [round(float(f), 4) for f in wilac_weights(350.0)]
    [0.0, 0.0, 0.0, 1.0]
    """
    return _water_flow_laws(water_flow, transitions, 4)


@functools.lru_cache(maxsize=32)
def _checked_transitions(transitions: tuple) -> tuple:
    return check_transitions(transitions)


def _water_flow_laws(water_flow, transitions, rows: int) -> np.ndarray:
    """The transitions (``rows`` 3) or the weights (4) of the validated water flows."""
    w = check_nonnegative(water_flow, "water_flow")
    if transitions is not PAPER_TRANSITIONS:
        transitions = _checked_transitions(_as_transition_key(transitions))
    return _transitions(w, transitions, rows)


def _as_regression(value, where: str) -> ParameterRegression:
    if isinstance(value, ParameterRegression):
        return value
    if isinstance(value, Real) and not isinstance(value, bool):
        if not math.isfinite(float(value)):
            raise ValueError(f"{where} must be finite, got {value!r}")
        return ParameterRegression.constant(float(value))
    if isinstance(value, Mapping):
        return ParameterRegression.from_dict(value, where=where)
    raise ValueError(
        f"{where}: expected a ParameterRegression, a number or a mapping with 'terms' and "
        f"'coefficients', got {type(value).__name__}"
    )


@dataclass(frozen=True)
class WilacCondition:
    """Regressions giving the five Polach parameters of one WILAC condition.

    Each field is a :class:`~railadhesion.models.regression.ParameterRegression` of the
    normalised normal force Q' and speed v' (seed 000, section 5.2). A plain number is accepted
    and turned into a constant regression; a mapping is read with
    :meth:`ParameterRegression.from_dict`.

    Parameters
    ----------
    k_A, k_S : ParameterRegression or float
        Polach's reduction factors of the initial slope in the adhesion and slip areas [-].
    mu0 : ParameterRegression or float
        Maximum friction coefficient [-].
    A : ParameterRegression or float
        Ratio mu_inf / mu0 [-].
    B : ParameterRegression or float
        Exponential decay of friction with slip velocity [s/m].

    Examples
    --------
    >>> dry = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    >>> dry.k_S(0.5, 0.5)
    0.4
    """

    k_A: ParameterRegression
    k_S: ParameterRegression
    mu0: ParameterRegression
    A: ParameterRegression
    B: ParameterRegression

    def __post_init__(self):
        for name in POLACH_PARAMETER_NAMES:
            object.__setattr__(self, name, _as_regression(getattr(self, name), name))

    @classmethod
    def from_polach(cls, params) -> WilacCondition:
        """Constant regressions from a parameter set with ``k_A, k_S, mu0, A, B`` attributes
        (e.g. :class:`railadhesion.models.parameters.PolachParameters`) or such a mapping."""
        get = params.get if isinstance(params, Mapping) else functools.partial(getattr, params)
        return cls(**{name: float(get(name)) for name in POLACH_PARAMETER_NAMES})

    def regressions(self) -> dict[str, ParameterRegression]:
        """The five regressions by parameter name."""
        return {name: getattr(self, name) for name in POLACH_PARAMETER_NAMES}


def check_provenance(provenance, where: str = "provenance") -> dict:
    """Validated provenance table (the fields of :data:`PROVENANCE_FIELDS`; ``created`` an ISO
    date); errors name ``where``. ``None`` gives an empty dict."""
    if provenance is None:
        return {}
    if not isinstance(provenance, Mapping):
        raise ValueError(f"{where}: expected a table/mapping, got {type(provenance).__name__}")
    unknown = sorted(set(provenance) - set(PROVENANCE_FIELDS))
    if unknown:
        raise ValueError(
            f"{where}: unknown field(s) {unknown}; allowed: {', '.join(PROVENANCE_FIELDS)}"
        )
    out = {}
    for key in PROVENANCE_FIELDS:
        if key not in provenance:
            continue
        value = provenance[key]
        if key == "created":
            if isinstance(value, datetime.datetime) or not isinstance(
                value, datetime.date | str
            ):
                raise ValueError(
                    f"{where}.created: expected a date such as 2025-06-01, got {value!r}"
                )
            if isinstance(value, str):
                try:
                    value = datetime.date.fromisoformat(value)
                except ValueError as exc:
                    raise ValueError(
                        f"{where}.created: expected a date such as 2025-06-01, got {value!r}"
                    ) from exc
            out[key] = value.isoformat()
        elif key == "reconstruction":
            if not isinstance(value, bool):
                raise ValueError(f"{where}.reconstruction: expected true or false, got {value!r}")
            out[key] = value
        else:
            if not isinstance(value, str):
                raise ValueError(f"{where}.{key}: expected a string, got {value!r}")
            out[key] = value
    return out


def _check_pair(value, where: str) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: expected a (low, high) pair of numbers, got {value!r}") from exc
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"{where}: expected 0 < low < high (finite), got [{lo!r}, {hi!r}]")
    return lo, hi


def _check_ref(value, where: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: expected a number, got {value!r}") from exc
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"{where} must be in (0, inf), got {x!r}")
    return x


@dataclass(frozen=True, eq=True)
class WilacParameters:
    """A complete WILAC parameter set: four conditions, normalisation, validity, transitions.

    Parameters
    ----------
    conditions : mapping of str to WilacCondition
        Exactly the four conditions of :data:`WILAC_CONDITIONS`; stored in that order.
    normal_force_ref : float
        Reference normal force for ``Q' = Q / normal_force_ref`` [N], > 0 (the paper uses the
        maximum of the parameterised range).
    speed_ref : float
        Reference rolling speed for ``v' = v / speed_ref`` [m/s], > 0.
    normal_force_range : (float, float)
        Calibrated normal-force range ``(low, high)`` [N], ``0 < low < high``.
    speed_range : (float, float)
        Calibrated speed range ``(low, high)`` [m/s], ``0 < low < high``.
    transitions : sequence of 3 (midpoint, width) pairs, optional
        Water-flow transitions [µl/s]; default seed 000, Table 1.
    name : str, optional
        Short name of the set.
    provenance : mapping, optional
        Where the set comes from; keys from :data:`PROVENANCE_FIELDS` (``source``,
        ``reconstruction``, ``description``, ``created``, ``script``, ``licence``, ``notes``).

    Notes
    -----
    Outside the calibrated ranges the Polach parameters are held at their boundary values:
    :meth:`polach_parameters` clamps Q and v into the ranges before normalising. In particular a
    speed below the range (a braking train near standstill) uses the lowest calibrated speed, as
    the ``1/v'`` terms of a regression would otherwise diverge. The Polach model itself still
    sees the true speed (its slip velocity is creepage × true speed).
    """

    conditions: Mapping[str, WilacCondition]
    normal_force_ref: float
    speed_ref: float
    normal_force_range: tuple[float, float]
    speed_range: tuple[float, float]
    transitions: tuple[WaterTransition, ...] = PAPER_TRANSITIONS
    name: str = ""
    provenance: Mapping = field(default_factory=dict)
    _scalar_plan: dict = field(init=False, repr=False, compare=False, default=None)

    def __post_init__(self):
        if not isinstance(self.conditions, Mapping):
            raise ValueError(
                f"conditions: expected a mapping of {list(WILAC_CONDITIONS)} to WilacCondition"
            )
        missing = [c for c in WILAC_CONDITIONS if c not in self.conditions]
        if missing:
            raise ValueError(
                f"conditions: missing condition(s) {missing}; all of {list(WILAC_CONDITIONS)} "
                "are required"
            )
        unknown = sorted(set(self.conditions) - set(WILAC_CONDITIONS))
        if unknown:
            raise ValueError(
                f"conditions: unknown condition(s) {unknown}; allowed: {list(WILAC_CONDITIONS)}"
            )
        conds = {}
        for c in WILAC_CONDITIONS:
            value = self.conditions[c]
            if isinstance(value, Mapping):
                value = _condition_from_mapping(value, f"conditions.{c}")
            elif not isinstance(value, WilacCondition):
                raise ValueError(
                    f"conditions.{c}: expected a WilacCondition, got {type(value).__name__}"
                )
            conds[c] = value
        object.__setattr__(self, "conditions", conds)
        object.__setattr__(
            self, "normal_force_ref", _check_ref(self.normal_force_ref, "normal_force_ref")
        )
        object.__setattr__(self, "speed_ref", _check_ref(self.speed_ref, "speed_ref"))
        object.__setattr__(
            self,
            "normal_force_range",
            _check_pair(self.normal_force_range, "normal_force_range"),
        )
        object.__setattr__(self, "speed_range", _check_pair(self.speed_range, "speed_range"))
        object.__setattr__(self, "transitions", check_transitions(self.transitions))
        if not isinstance(self.name, str):
            raise ValueError(f"name: expected a string, got {self.name!r}")
        object.__setattr__(self, "provenance", check_provenance(self.provenance))
        # Every regression must be finite over the whole calibrated range (corners and a grid).
        q = np.linspace(*self.normal_force_range, 9)[:, None] / self.normal_force_ref
        v = np.linspace(*self.speed_range, 9)[None, :] / self.speed_ref
        for c, cond in conds.items():
            for p, reg in cond.regressions().items():
                with np.errstate(all="ignore"):
                    values = np.asarray(reg(q, v))
                if not np.all(np.isfinite(values)):
                    raise ValueError(
                        f"conditions.{c}.{p}: the regression is not finite within the "
                        "calibrated normal force and speed ranges"
                    )

        object.__setattr__(
            self, "_scalar_plan", {c: _compile_condition(cond) for c, cond in conds.items()}
        )

    __hash__ = None  # holds dicts: not hashable

    def polach_parameters(self, condition: str, normal_force, speed) -> dict[str, np.ndarray]:
        """Polach parameters of one condition at normal force Q and speed v.

        Parameters
        ----------
        condition : str
            One of :data:`WILAC_CONDITIONS`.
        normal_force : array_like
            Normal force Q [N], > 0. Clamped into :attr:`normal_force_range`.
        speed : array_like
            Rolling speed v [m/s], >= 0. Clamped into :attr:`speed_range`.

        Returns
        -------
        dict of str to numpy.ndarray
            ``k_A, k_S, mu0, A, B`` (B in s/m), each of the broadcast shape of the inputs and
            clipped to :data:`PHYSICAL_BOUNDS`.

        Notes
        -----
        Trummer et al. (seed 000), section 5.2, the regression equation given there for k_A:
        each parameter is a linear regression on Q' = Q/Q_ref and v' = v/v_ref. Inputs are
        clamped into the calibrated ranges first (parameters are held at the boundary values),
        outputs clipped to the physical ranges.

        Examples
        --------
        >>> cond = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
        >>> p = WilacParameters({c: cond for c in WILAC_CONDITIONS}, 1e5, 40.0,
        ...                     (4e3, 1e5), (1.0, 40.0))
        >>> round(float(p.polach_parameters("wet", 5e4, 20.0)["mu0"]), 4)
        0.55

        Below the calibrated speed range (a train near standstill) the parameters are those
        of the lowest calibrated speed, with an
        :class:`~railadhesion.plausibility.AlteredResultWarning` saying so:

        >>> import warnings
        >>> with warnings.catch_warnings(record=True) as caught:
        ...     warnings.simplefilter("always")
        ...     mu0 = p.polach_parameters("wet", 5e4, 0.0)["mu0"]
        >>> type(caught[0].message).__name__, round(float(mu0), 4)
        ('AlteredResultWarning', 0.55)
        """
        check_choice(condition, "condition", WILAC_CONDITIONS)
        q = check_positive(normal_force, "normal_force")
        v = check_nonnegative(speed, "speed")
        what = f"the WILAC set {self.name or '(unnamed)'!r}"
        check_calibrated(q, "normal_force", *self.normal_force_range, unit="N", what=what)
        check_calibrated(v, "speed", *self.speed_range, unit="m/s", what=what)
        shape, n, (qf, vf) = flatten([q, v])
        out = np.empty((5, n))
        _parameters_into(qf, vf, pack_wilac(self), WILAC_CONDITIONS.index(condition), out)
        return {name: out[j].reshape(shape) for j, name in enumerate(POLACH_PARAMETER_NAMES)}

    def replace(self, **changes) -> WilacParameters:
        """A copy with some fields changed (validated again)."""
        kwargs = {f.name: getattr(self, f.name) for f in fields(self) if f.init}
        kwargs.update(changes)
        return WilacParameters(**kwargs)


def _condition_from_mapping(value: Mapping, where: str) -> WilacCondition:
    missing = [p for p in POLACH_PARAMETER_NAMES if p not in value]
    if missing:
        raise ValueError(f"{where}: missing parameter(s) {missing}")
    unknown = sorted(set(value) - set(POLACH_PARAMETER_NAMES))
    if unknown:
        raise ValueError(
            f"{where}: unknown parameter(s) {unknown}; allowed: {list(POLACH_PARAMETER_NAMES)}"
        )
    return WilacCondition(**{p: _as_regression(value[p], f"{where}.{p}") for p in value})


_FACTOR_INDEX = {"Q": 0, "v": 1, "1/Q": 2, "1/v": 3, "exp(Q)": 4, "exp(v)": 5}


def _compile_condition(cond: WilacCondition) -> tuple:
    """Plan for the scalar fast path: per parameter ((factor indices, coefficient), ...),
    low, high. Terms are canonical (see :func:`railadhesion.models.regression.canonical_term`).
    """
    plan = []
    for name in POLACH_PARAMETER_NAMES:
        reg = getattr(cond, name)
        terms = tuple(
            (() if t == "1" else tuple(_FACTOR_INDEX[f] for f in t.split("*")), c)
            for t, c in zip(reg.terms, reg.coefficients, strict=True)
        )
        plan.append((terms, *PHYSICAL_BOUNDS[name]))
    return tuple(plan)


#: Number of header values of a packed WILAC set (:func:`pack_wilac`).
PACKED_HEADER = 22
# Offsets of the term counts and of the regressions in a packed set.
_COUNTS = PACKED_HEADER + 1
_TERMS = _COUNTS + 20


def pack_wilac(params: WilacParameters) -> np.ndarray:
    """Pack a :class:`~railadhesion.models.WilacParameters` into one read-only float64 array
    (for the compiled laws), computed once per set.

    Returns
    -------
    numpy.ndarray, shape (43 + 80 T,)
        ``packed[0:22]``: ``[Q_ref, v_ref, Q_low, Q_high, v_low, v_high, m1, s1, m2, s2,
        m3, s3, k_A_low, k_A_high, k_S_low, k_S_high, mu0_low, mu0_high, A_low, A_high,
        B_low, B_high]``, i.e. the normalisation, the calibrated ranges (Q and v are clamped
        into them), the three erf transitions (midpoint, width) [µl/s] and the clipping bounds
        of the five Polach parameters; ``packed[22]``: T, the largest number of terms of any
        regression; ``packed[23:43]``: the number of terms of each regression, (4, 5) in C
        order; ``packed[43:]``: the regressions, an array of shape (4, 5, T, 4) in C order:
        for condition i (dry, damp2, damp1, wet), parameter j (k_A, k_S, mu0, A, B) and term
        k, ``(coefficient, f1, f2, f3)`` with the factor indices f into
        ``(Q', v', 1/Q', 1/v', exp(Q'), exp(v'), 1)`` stored as floats (6, the factor 1, for
        none); unused terms are zero.

    Examples
    --------
    >>> from railadhesion.models.wilac import default_wilac_parameters
    >>> packed = pack_wilac(default_wilac_parameters())
    >>> packed.dtype, (packed.size - 43) % 80, packed[6:12].tolist()
    (dtype('float64'), 0, [15.0, 5.0, 30.0, 3.0, 50.0, 7.0])
    """
    packed = params.__dict__.get("_packed")
    if packed is not None:
        return packed
    plan = params._scalar_plan
    nterm = max(len(plan[c][j][0]) for c in WILAC_CONDITIONS for j in range(5))
    regression = np.zeros((4, 5, nterm, 4))
    counts = np.zeros((4, 5))
    for i, cond in enumerate(WILAC_CONDITIONS):
        for j in range(5):
            counts[i, j] = len(plan[cond][j][0])
            for k, (idx, coef) in enumerate(plan[cond][j][0]):
                regression[i, j, k] = (coef, 6.0, 6.0, 6.0)
                for m, f in enumerate(idx):
                    regression[i, j, k, 1 + m] = f
    header = np.empty(PACKED_HEADER + 1)
    header[0] = params.normal_force_ref
    header[1] = params.speed_ref
    header[2:4] = params.normal_force_range
    header[4:6] = params.speed_range
    header[6:12] = np.ravel([(t.midpoint, t.width) for t in params.transitions])
    header[12:22] = np.ravel([PHYSICAL_BOUNDS[p] for p in POLACH_PARAMETER_NAMES])
    header[22] = nterm
    packed = np.concatenate([header, counts.ravel(), regression.ravel()])
    packed.flags.writeable = False  # the compiled code is compiled for read-only arrays
    object.__setattr__(params, "_packed", packed)
    return packed


@jitable
def wilac_normalise(q, v, packed):
    """(Q', v') = (clamp(Q)/Q_ref, clamp(v)/v_ref): Q and v clamped into the calibrated
    ranges of the packed set (:func:`pack_wilac`), so that the parameters are held at their
    boundary values outside (:class:`WilacParameters`, Notes), then normalised (seed 000,
    section 5.2)."""
    qn = min(max(q, packed[2]), packed[3]) / packed[0]
    vn = min(max(v, packed[4]), packed[5]) / packed[1]
    return qn, vn


@jitable(inline="always")
def wilac_factors(qn, vn):
    """The six regression factors (Q', v', 1/Q', 1/v', exp(Q'), exp(v')) (seed 000, section
    5.2; :mod:`railadhesion.models.regression`), in the order of the packed factor indices."""
    return qn, vn, 1.0 / qn, 1.0 / vn, exp(qn), exp(vn)


@jitable
def wilac_terms(packed, i, j):
    """(first, count): where the terms of the regression of parameter j of condition i start
    in the packed set, and how many there are (each term: coefficient, three factor
    indices)."""
    nterm = int(packed[PACKED_HEADER])
    return _TERMS + (i * 5 + j) * nterm * 4, int(packed[_COUNTS + i * 5 + j])


@jitable
def wilac_term(coefficient, fa, fb, fc):
    """One term of a regression of seed 000, section 5.2: its coefficient times its factors
    (up to three; the factor 1 where a term has fewer)."""
    return coefficient * fa * fb * fc


@jitable
def wilac_clip(total, packed, j):
    """The sum of a regression's terms clipped to parameter j's :data:`PHYSICAL_BOUNDS`."""
    return min(max(total, packed[12 + 2 * j]), packed[13 + 2 * j])


@jitable
def wilac_regression(packed, i, j, f0, f1, f2, f3, f4, f5):
    """Polach parameter j (k_A, k_S, mu0, A, B) of condition i (dry, damp2, damp1, wet): the
    linear regression of seed 000, section 5.2 (:func:`wilac_term` summed over the terms,
    :func:`wilac_clip`); f0-f5 are the factors of :func:`wilac_factors`, indexed by the
    packed factor indices (6 for the factor 1)."""
    first, count = wilac_terms(packed, i, j)
    total = 0.0
    for t in range(count):
        p = first + 4 * t
        total = total + wilac_term(packed[p], _factor(packed[p + 1], f0, f1, f2, f3, f4, f5),
                                   _factor(packed[p + 2], f0, f1, f2, f3, f4, f5),
                                   _factor(packed[p + 3], f0, f1, f2, f3, f4, f5))  # fmt: skip
    return wilac_clip(total, packed, j)


@jitable
def _factor(index, f0, f1, f2, f3, f4, f5):
    """Factor ``index`` (a packed factor index, a float: 0-5, 6 for the factor 1) of
    :func:`wilac_factors`: the tuple of the factors indexed at ``index`` clamped into 0-6, so
    that no indexing can raise (the native FMUs compile the laws without numba's runtime).
    One load, no branch: about half the time of a chain of comparisons in WILAC's
    regressions, with the same values."""
    return (f0, f1, f2, f3, f4, f5, 1.0)[min(max(int(index), 0), 6)]


@kernel(nogil=True)
def _parameters_into(q, v, packed, i, out):
    """The five parameters of condition i at (Q, v) (arrays of length n or 1) into out."""
    sq = 1 if q.size > 1 else 0
    sv = 1 if v.size > 1 else 0
    for k in range(out.shape[1]):
        qn, vn = wilac_normalise(q[k * sq], v[k * sv], packed)
        f0, f1, f2, f3, f4, f5 = wilac_factors(qn, vn)
        for j in range(5):
            out[j, k] = wilac_regression(packed, i, j, f0, f1, f2, f3, f4, f5)
