"""Parameter files: versioned, human-editable TOML for WILAC and Polach parameter sets.

The format is documented, with a complete annotated example, in ``docs/parameter-files.md``.
Two kinds of file exist, told apart by their ``format`` field:

* ``"railadhesion-wilac"``: a :class:`~railadhesion.models.wilac.WilacParameters` (four
  conditions, each with five regressions; normalisation; validity ranges; water transitions).
* ``"railadhesion-polach"``: one :class:`~railadhesion.models.parameters.PolachParameters`.

Both carry ``format_version = 1`` and an optional ``[provenance]`` table (``source``,
``reconstruction``, ``description``, ``created``, ``script``, ``licence``, ``notes``).

Loading validates every field. Any problem raises :class:`ParameterFileError` (a
``ValueError``) whose message starts with the file and the dotted path of the faulty field,
e.g. ``wilac.toml: conditions.damp2.k_S.coefficients: expected a list of numbers``. Unknown
fields are errors too: a misspelt key must not be silently ignored.

Files are read with :mod:`tomllib` and written with :mod:`tomli_w`; floats are written with
``repr`` precision, so save → load gives back exactly the same numbers.

The module sits with the models because :func:`railadhesion.models.wilac.default_wilac_parameters`
reads the package's default set with it (imports run down the floors, docs/architecture.md);
its public path is ``railadhesion.io.paramfiles``, which re-exports it.
"""

from __future__ import annotations

import datetime
import math
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import tomli_w

from railadhesion.models.regression import ParameterRegression, canonical_term

# The parameter classes, not the model: models.wilac loads its default file through this
# module, so importing models.wilac here would make an import circle.
from railadhesion.models.wilac_parameters import (
    POLACH_PARAMETER_NAMES,
    PROVENANCE_FIELDS,
    WILAC_CONDITIONS,
    WaterTransition,
    WilacCondition,
    WilacParameters,
    check_provenance,
    check_transitions,
)

if TYPE_CHECKING:
    from railadhesion.models.parameters import PolachParameters

__all__ = [
    "FORMAT_VERSION",
    "WILAC_FORMAT",
    "POLACH_FORMAT",
    "ParameterFileError",
    "load_wilac_parameters",
    "save_wilac_parameters",
    "load_polach_parameters",
    "save_polach_parameters",
    "load_parameter_file",
    "read_provenance",
    "wilac_parameters_to_toml",
    "polach_parameters_to_toml",
]

#: Version of the file format written by this module (and the only one it reads).
FORMAT_VERSION = 1
WILAC_FORMAT = "railadhesion-wilac"
POLACH_FORMAT = "railadhesion-polach"
_FORMATS = (WILAC_FORMAT, POLACH_FORMAT)

_TRANSITION_KEYS = ("e1", "e2", "e3")
_TRANSITION_LABELS = {"e1": "dry -> damp2", "e2": "damp2 -> damp1", "e3": "damp1 -> wet"}
_UNITS = {"k_A": "-", "k_S": "-", "mu0": "-", "A": "-", "B": "s/m"}


class ParameterFileError(ValueError):
    """A parameter file is unreadable or invalid; the message names the file and the field."""


# --------------------------------------------------------------------------------------------
# Field checks. Each takes the dotted path of the field for its error message.


class _Fail(Exception):
    """Internal: a field error, turned into ParameterFileError with the file name."""

    def __init__(self, where: str, message: str):
        super().__init__(f"{where}: {message}" if where else message)


def _is_number(x) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _table(value, where: str) -> Mapping:
    if not isinstance(value, Mapping):
        raise _Fail(where, f"expected a table, got {_describe(value)}")
    return value


def _keys(table: Mapping, where: str, required, optional=()) -> None:
    prefix = f"{where}." if where else ""
    unknown = [k for k in table if k not in required and k not in optional]
    if unknown:
        allowed = ", ".join(list(required) + list(optional))
        names = ", ".join(f"{prefix}{k}" for k in unknown)
        kind = "field(s)" if where else "top-level field(s)"
        raise _Fail(where, f"unknown {kind} {names}; allowed here: {allowed}")
    missing = [k for k in required if k not in table]
    if missing:
        names = ", ".join(f"{prefix}{k}" for k in missing)
        kind = "field(s)" if where else "top-level field(s)"
        raise _Fail(where, f"missing required {kind} {names}")


def _number(value, where: str, *, positive: bool = False) -> float:
    if not _is_number(value):
        raise _Fail(where, f"expected a number, got {_describe(value)}")
    x = float(value)
    if not math.isfinite(x):
        raise _Fail(where, f"expected a finite number, got {x!r}")
    if positive and not x > 0:
        raise _Fail(where, f"must be in (0, inf), got {x!r}")
    return x


def _number_list(value, where: str) -> list[float]:
    if not isinstance(value, list) or not all(_is_number(x) for x in value):
        raise _Fail(where, f"expected a list of numbers, got {_describe(value)}")
    out = [float(x) for x in value]
    bad = [i for i, x in enumerate(out) if not math.isfinite(x)]
    if bad:
        raise _Fail(f"{where}[{bad[0]}]", f"expected a finite number, got {out[bad[0]]!r}")
    return out


def _range(value, where: str) -> tuple[float, float]:
    values = _number_list(value, where)
    if len(values) != 2:
        raise _Fail(where, f"expected [low, high] (2 numbers), got {len(values)} numbers")
    lo, hi = values
    if not 0 < lo < hi:
        raise _Fail(where, f"expected 0 < low < high, got [{lo!r}, {hi!r}]")
    return lo, hi


def _string(value, where: str) -> str:
    if not isinstance(value, str):
        raise _Fail(where, f"expected a string, got {_describe(value)}")
    return value


def _describe(value) -> str:
    kind = {
        bool: "a boolean",
        str: "a string",
        int: "an integer",
        float: "a number",
        list: "a list",
        dict: "a table",
    }.get(type(value), type(value).__name__)
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{kind} ({text})"


def _regression(value, where: str) -> ParameterRegression:
    table = _table(value, where)
    _keys(table, where, ("terms", "coefficients"), ("r_squared",))
    terms_raw = table["terms"]
    if not isinstance(terms_raw, list) or not all(isinstance(t, str) for t in terms_raw):
        raise _Fail(f"{where}.terms", f"expected a list of strings, got {_describe(terms_raw)}")
    if not terms_raw:
        raise _Fail(f"{where}.terms", "expected at least one term (use [\"1\"] for a constant)")
    terms = []
    for i, term in enumerate(terms_raw):
        try:
            terms.append(canonical_term(term))
        except ValueError as exc:
            raise _Fail(f"{where}.terms[{i}]", f"{exc} (see docs/parameter-files.md)") from None
    seen: dict[str, int] = {}
    for i, term in enumerate(terms):
        if term in seen:
            raise _Fail(
                f"{where}.terms[{i}]",
                f"term {terms_raw[i]!r} repeats terms[{seen[term]}] ({terms_raw[seen[term]]!r})",
            )
        seen[term] = i
    coefficients = _number_list(table["coefficients"], f"{where}.coefficients")
    if len(coefficients) != len(terms):
        raise _Fail(
            where,
            f"'terms' has {len(terms)} entries but 'coefficients' has {len(coefficients)}",
        )
    r_squared = None
    if "r_squared" in table:
        r_squared = _number(table["r_squared"], f"{where}.r_squared")
        if r_squared > 1:
            raise _Fail(f"{where}.r_squared", f"must be <= 1, got {r_squared!r}")
    return ParameterRegression(tuple(terms), tuple(coefficients), r_squared=r_squared)


def _provenance(value, where: str = "provenance") -> dict:
    table = _table(value, where)
    _keys(table, where, (), tuple(PROVENANCE_FIELDS))
    try:
        return check_provenance(table, where)
    except ValueError as exc:  # the message already starts with the dotted path
        raise _Fail("", str(exc)) from None


def _header(doc: Mapping, expected: str | None) -> str:
    if "format" not in doc:
        raise _Fail("format", f"missing; expected format = {' or '.join(map(repr, _FORMATS))}")
    fmt = doc["format"]
    if fmt not in _FORMATS:
        raise _Fail("format", f"expected one of {', '.join(map(repr, _FORMATS))}, got {fmt!r}")
    if expected is not None and fmt != expected:
        raise _Fail("format", f"this is a {fmt!r} file, expected {expected!r}")
    if "format_version" not in doc:
        raise _Fail(
            "format_version", f"missing; this library reads format_version = {FORMAT_VERSION}"
        )
    version = doc["format_version"]
    if not isinstance(version, int) or isinstance(version, bool):
        raise _Fail("format_version", f"expected an integer, got {_describe(version)}")
    if version != FORMAT_VERSION:
        raise _Fail(
            "format_version",
            f"version {version} is not supported; this version of railadhesion reads "
            f"format_version = {FORMAT_VERSION}",
        )
    return fmt


# --------------------------------------------------------------------------------------------
# Reading


def _read(path) -> tuple[dict, str]:
    label = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh), label
    except tomllib.TOMLDecodeError as exc:
        raise ParameterFileError(f"{label}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ParameterFileError(f"{label}: not UTF-8 text: {exc}") from None


def _wilac_from_doc(doc: Mapping) -> WilacParameters:
    _header(doc, WILAC_FORMAT)
    _keys(
        doc,
        "",
        ("format", "format_version", "normalisation", "validity", "conditions"),
        ("name", "provenance", "transitions"),
    )
    name = _string(doc.get("name", ""), "name")
    provenance = _provenance(doc["provenance"]) if "provenance" in doc else {}

    norm = _table(doc["normalisation"], "normalisation")
    _keys(norm, "normalisation", ("normal_force_ref_N", "speed_ref_m_s"))
    q_ref = _number(norm["normal_force_ref_N"], "normalisation.normal_force_ref_N", positive=True)
    v_ref = _number(norm["speed_ref_m_s"], "normalisation.speed_ref_m_s", positive=True)

    valid = _table(doc["validity"], "validity")
    _keys(valid, "validity", ("normal_force_range_N", "speed_range_m_s"))
    q_range = _range(valid["normal_force_range_N"], "validity.normal_force_range_N")
    v_range = _range(valid["speed_range_m_s"], "validity.speed_range_m_s")

    transitions = None
    if "transitions" in doc:
        trans = _table(doc["transitions"], "transitions")
        _keys(trans, "transitions", _TRANSITION_KEYS)
        items = []
        for key in _TRANSITION_KEYS:
            where = f"transitions.{key}"
            t = _table(trans[key], where)
            _keys(t, where, ("midpoint_ul_s", "width_ul_s"))
            m = _number(t["midpoint_ul_s"], f"{where}.midpoint_ul_s")
            s = _number(t["width_ul_s"], f"{where}.width_ul_s", positive=True)
            items.append(WaterTransition(m, s))
        try:
            transitions = check_transitions(items, "transitions")
        except ValueError as exc:  # the message already starts with "transitions"
            raise _Fail("", str(exc)) from None

    conds_doc = _table(doc["conditions"], "conditions")
    _keys(conds_doc, "conditions", WILAC_CONDITIONS)
    conditions = {}
    for cond in WILAC_CONDITIONS:
        where = f"conditions.{cond}"
        table = _table(conds_doc[cond], where)
        _keys(table, where, POLACH_PARAMETER_NAMES)
        conditions[cond] = WilacCondition(
            **{p: _regression(table[p], f"{where}.{p}") for p in POLACH_PARAMETER_NAMES}
        )

    kwargs: dict[str, Any] = {}
    if transitions is not None:
        kwargs["transitions"] = transitions
    try:
        return WilacParameters(
            conditions=conditions,
            normal_force_ref=q_ref,
            speed_ref=v_ref,
            normal_force_range=q_range,
            speed_range=v_range,
            name=name,
            provenance=provenance,
            **kwargs,
        )
    except ValueError as exc:  # the message names the field (e.g. conditions.dry.k_A)
        raise _Fail("", str(exc)) from None


def _polach_from_doc(doc: Mapping):
    from railadhesion.models.parameters import PolachParameters

    _header(doc, POLACH_FORMAT)
    _keys(doc, "", ("format", "format_version", "parameters"), ("name", "provenance"))
    name = _string(doc.get("name", ""), "name")
    provenance = _provenance(doc["provenance"]) if "provenance" in doc else {}
    table = _table(doc["parameters"], "parameters")
    _keys(table, "parameters", POLACH_PARAMETER_NAMES)
    values = {p: _number(table[p], f"parameters.{p}") for p in POLACH_PARAMETER_NAMES}
    try:
        return PolachParameters(
            **values,
            name=name,
            source=provenance.get("source", ""),
            notes=provenance.get("notes", ""),
        )
    except ValueError as exc:
        # PolachParameters names the field first ("k_A must be in (0, 1], got 1.5")
        raise _Fail("parameters", str(exc)) from None


def _load(path, loader):
    doc, label = _read(path)
    try:
        return loader(doc)
    except _Fail as exc:
        raise ParameterFileError(f"{label}: {exc}") from None


def load_wilac_parameters(path) -> WilacParameters:
    """Read a WILAC parameter file (``format = "railadhesion-wilac"``).

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file.

    Returns
    -------
    WilacParameters

    Raises
    ------
    ParameterFileError
        (a ``ValueError``) if the file is not valid TOML or any field is missing, unknown, of
        the wrong type or out of range; the message names the file and the dotted field path.
    """
    return _load(path, _wilac_from_doc)


def load_polach_parameters(path) -> PolachParameters:
    """Read a Polach parameter file (``format = "railadhesion-polach"``).

    ``provenance.source`` and ``provenance.notes`` become the ``source`` and ``notes`` of the
    returned :class:`~railadhesion.models.parameters.PolachParameters`; read the full
    provenance with :func:`read_provenance`.

    Raises
    ------
    ParameterFileError
        (a ``ValueError``) naming the file and the dotted path of the faulty field.
    """
    return _load(path, _polach_from_doc)


def load_parameter_file(path):
    """Read a parameter file of either kind, dispatching on its ``format`` field.

    Returns a :class:`~railadhesion.models.wilac.WilacParameters` or a
    :class:`~railadhesion.models.parameters.PolachParameters`.
    """
    doc, label = _read(path)
    try:
        fmt = _header(doc, None)
        return (_wilac_from_doc if fmt == WILAC_FORMAT else _polach_from_doc)(doc)
    except _Fail as exc:
        raise ParameterFileError(f"{label}: {exc}") from None


def read_provenance(path) -> dict:
    """The validated ``[provenance]`` table of a parameter file of either kind (``created`` as
    an ISO date string); ``{}`` if the file has none."""
    doc, label = _read(path)
    try:
        _header(doc, None)
        return _provenance(doc["provenance"]) if "provenance" in doc else {}
    except _Fail as exc:
        raise ParameterFileError(f"{label}: {exc}") from None


# --------------------------------------------------------------------------------------------
# Writing. The document is composed section by section so that it can carry comments (units,
# meaning); each value is formatted by tomli_w, floats at full (repr) precision.


def _value(value) -> str:
    """One TOML value as tomli_w spells it (floats at repr precision)."""
    return tomli_w.dumps({"x": value})[len("x = ") :].rstrip("\n")


def _kv(mapping: Mapping) -> str:
    """``key = value`` lines; arrays on one line, wrapped with several items a line if long."""
    lines = []
    for key, value in mapping.items():
        if not isinstance(value, list | tuple):
            lines.append(tomli_w.dumps({key: value}).rstrip("\n"))
            continue
        items = [_value(x) for x in value]
        one_line = f"{key} = [{', '.join(items)}]"
        if len(one_line) <= 100:
            lines.append(one_line)
            continue
        rows, row = [], ""
        for item in items:
            if row and len(row) + len(item) + 2 > 92:
                rows.append(row)
                row = ""
            row = f"{row} {item}," if row else f"{item},"
        rows.append(row)
        lines.append(f"{key} = [\n" + "".join(f"    {r}\n" for r in rows) + "]")
    return "".join(line + "\n" for line in lines)


def _provenance_block(provenance: Mapping) -> str:
    prov = check_provenance(provenance)
    if not prov:
        return ""
    out = dict(prov)
    if "created" in out:
        out["created"] = datetime.date.fromisoformat(out["created"])
    return "\n# Where this parameter set comes from\n[provenance]\n" + _kv(out)


def wilac_parameters_to_toml(params: WilacParameters) -> str:
    """The text :func:`save_wilac_parameters` writes (format ``railadhesion-wilac``, version 1)."""
    if not isinstance(params, WilacParameters):
        raise ValueError(f"params must be a WilacParameters, got {type(params).__name__}")
    parts = [
        "# WILAC creep-force model parameter set (Trummer et al., water-induced low adhesion).\n"
        "# File format: railadhesion docs/parameter-files.md. Units: N, m/s, µl/s; B in s/m.\n",
        _kv({"format": WILAC_FORMAT, "format_version": FORMAT_VERSION, "name": params.name}),
        _provenance_block(params.provenance),
        "\n# Regressors are Q' = Q / normal_force_ref_N and v' = v / speed_ref_m_s\n"
        "[normalisation]\n",
        _kv({"normal_force_ref_N": params.normal_force_ref, "speed_ref_m_s": params.speed_ref}),
        "\n# Calibrated ranges [low, high]; outside them the parameters are held at the boundary\n"
        "[validity]\n",
        _kv(
            {
                "normal_force_range_N": list(params.normal_force_range),
                "speed_range_m_s": list(params.speed_range),
            }
        ),
        "\n# Water-flow transitions e_i(w) = 0.5 (erf((w - midpoint)/width) + 1), w in µl/s\n",
    ]
    for key, t in zip(_TRANSITION_KEYS, params.transitions, strict=True):
        parts.append(f"[transitions.{key}]  # {_TRANSITION_LABELS[key]}\n")
        parts.append(_kv({"midpoint_ul_s": t.midpoint, "width_ul_s": t.width}))
    parts.append(
        "\n# Polach parameters per condition: p(Q', v') = sum(coefficients[k] * terms[k]).\n"
        "# Term grammar: \"1\" or products of up to 3 of Q, v, 1/Q, 1/v, exp(Q), exp(v).\n"
    )
    for cond in WILAC_CONDITIONS:
        for p, reg in params.conditions[cond].regressions().items():
            parts.append(f"\n[conditions.{cond}.{p}]  # [{_UNITS[p]}]\n")
            parts.append(_kv(reg.to_dict()))
    return "".join(parts)


def polach_parameters_to_toml(params: PolachParameters, *, provenance=None) -> str:
    """The text :func:`save_polach_parameters` writes (format ``railadhesion-polach``)."""
    from railadhesion.models.parameters import PolachParameters

    if not isinstance(params, PolachParameters):
        raise ValueError(f"params must be a PolachParameters, got {type(params).__name__}")
    prov = {}
    if params.source:
        prov["source"] = params.source
    if params.notes:
        prov["notes"] = params.notes
    prov.update(check_provenance(provenance))
    return "".join(
        [
            "# Polach creep-force model parameter set (Polach 2005, Wear 258, 992-1000).\n"
            "# File format: railadhesion docs/parameter-files.md.\n",
            _kv({"format": POLACH_FORMAT, "format_version": FORMAT_VERSION, "name": params.name}),
            _provenance_block(prov),
            "\n# k_A, k_S, mu0, A dimensionless; B in s/m\n[parameters]\n",
            _kv(params.as_dict()),
        ]
    )


def _write(text: str, path) -> Path:
    path = Path(path)
    path.write_text(text, encoding="utf-8")
    return path


def save_wilac_parameters(params: WilacParameters, path) -> Path:
    """Write ``params`` as a WILAC parameter file (TOML, format version 1); returns the path.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from railadhesion.models.wilac import WilacCondition, WilacParameters, WILAC_CONDITIONS
    >>> cond = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    >>> p = WilacParameters({c: cond for c in WILAC_CONDITIONS}, 1e5, 40.0, (4e3, 1e5),
    ...                     (1.0, 40.0), name="demo")
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = save_wilac_parameters(p, pathlib.Path(tmp) / "demo.toml")
    ...     load_wilac_parameters(path) == p
    True
    """
    return _write(wilac_parameters_to_toml(params), path)


def save_polach_parameters(params: PolachParameters, path, *, provenance=None) -> Path:
    """Write ``params`` as a Polach parameter file (TOML, format version 1); returns the path.

    Parameters
    ----------
    params : PolachParameters
        The set; its ``name``, ``source`` and ``notes`` are written as ``name``,
        ``provenance.source`` and ``provenance.notes``.
    path : str or os.PathLike
        Target file (overwritten).
    provenance : mapping, optional
        Further provenance fields (``reconstruction``, ``description``, ``created``,
        ``script``, ``licence``; ``source``/``notes`` here override the params' own).
    """
    return _write(polach_parameters_to_toml(params, provenance=provenance), path)
