"""Field-by-field checks for the braking TOML files (vehicle and scenario).

Every error is a :class:`BrakingFileError` (a ``ValueError``) whose message starts with the
file and the dotted name of the field, then states what was expected, e.g.
``coach.toml: vehicle.body_mass_kg: must be in (0, inf), got -3.0``.
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping

__all__ = ["BrakingFileError", "FieldError", "read_toml", "read_document", "number", "integer",
           "string", "table", "keys", "boolean"]


class BrakingFileError(ValueError):
    """A vehicle or scenario file is unreadable or invalid; the message names the field."""


class FieldError(Exception):
    """Internal: a field error, turned into :class:`BrakingFileError` with the file name."""

    def __init__(self, where: str, message: str):
        self.where = where
        super().__init__(f"{where}: {message}" if where else message)


def describe(value) -> str:
    kind = {bool: "a boolean", str: "a string", int: "an integer", float: "a number",
            list: "a list", dict: "a table"}.get(type(value), type(value).__name__)
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{kind} ({text})"


def read_toml(path) -> tuple[dict, str]:
    label = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh), label
    except FileNotFoundError:
        raise BrakingFileError(f"{label}: file not found") from None
    except tomllib.TOMLDecodeError as exc:
        raise BrakingFileError(f"{label}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise BrakingFileError(f"{label}: not UTF-8 text: {exc}") from None


def read_document(path, build):
    """``build(document, label)`` of the TOML file ``path`` (:func:`read_toml`; ``label`` names
    the file); a :class:`FieldError` or ``ValueError`` it raises becomes a
    :class:`BrakingFileError` naming the file."""
    doc, label = read_toml(path)
    try:
        return build(doc, label)
    except (FieldError, ValueError) as exc:
        raise BrakingFileError(f"{label}: {exc}") from None


def table(value, where: str) -> Mapping:
    if not isinstance(value, Mapping):
        raise FieldError(where, f"expected a table, got {describe(value)}")
    return value


def keys(tab: Mapping, where: str, required=(), optional=()) -> None:
    prefix = f"{where}." if where else ""
    unknown = [k for k in tab if k not in required and k not in optional]
    if unknown:
        allowed = ", ".join(list(required) + list(optional))
        raise FieldError(prefix + unknown[0], f"unknown field; allowed here: {allowed}")
    missing = [k for k in required if k not in tab]
    if missing:
        raise FieldError(prefix + missing[0], "missing required field")


def number(value, where: str, low: float = -math.inf, high: float = math.inf, *,
           low_open: bool = False, high_open: bool = False) -> float:
    """A finite number within [low, high] (bounds open when asked)."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise FieldError(where, f"expected a number, got {describe(value)}")
    x = float(value)
    ok = math.isfinite(x)
    ok = ok and (x > low if low_open else x >= low) and (x < high if high_open else x <= high)
    if not ok:
        lb = "(" if low_open or low == -math.inf else "["
        rb = ")" if high_open or high == math.inf else "]"
        raise FieldError(where, f"must be in {lb}{low:g}, {high:g}{rb}, got {x!r}")
    return x


def integer(value, where: str, low: int, high: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise FieldError(where, f"expected an integer, got {describe(value)}")
    if not low <= value <= high:
        raise FieldError(where, f"must be an integer in [{low}, {high}], got {value!r}")
    return int(value)


def string(value, where: str) -> str:
    if not isinstance(value, str):
        raise FieldError(where, f"expected a string, got {describe(value)}")
    return value


def boolean(value, where: str) -> bool:
    if not isinstance(value, bool):
        raise FieldError(where, f"expected true or false, got {describe(value)}")
    return value
