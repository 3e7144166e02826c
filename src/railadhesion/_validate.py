"""Input checks shared by every public function.

Each helper converts its argument with :func:`numpy.asarray` (float64), checks it and
raises ``ValueError`` naming the argument and the allowed range. They are cheap on
scalars, for models called inside ODE right-hand sides.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "as_float_array",
    "check_finite",
    "check_positive",
    "check_nonnegative",
    "check_range",
    "check_choice",
    "check_number",
    "instance_or_default",
]


def as_float_array(value, name: str) -> np.ndarray:
    """Return ``value`` as a float64 array, or raise ``ValueError`` naming ``name``."""
    # np.asarray(None, dtype=float) would silently give NaN
    if value is None or (
        isinstance(value, list | tuple)
        and any(v is None for v in np.ravel(np.array(value, dtype=object)))
    ):
        raise ValueError(f"{name} must be numeric, got {value!r}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {value!r}") from exc
    return arr


def check_finite(value, name: str) -> np.ndarray:
    """Array of ``value``; every element must be finite (no NaN, no inf)."""
    arr = as_float_array(value, name)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {_show(arr)}")
    return arr


def check_positive(value, name: str, *, allow_inf: bool = False) -> np.ndarray:
    """Array of ``value``; every element must be > 0 (and finite unless ``allow_inf``)."""
    arr = as_float_array(value, name)
    ok = arr > 0
    if not allow_inf:
        ok &= np.isfinite(arr)
    if not np.all(ok):  # NaN fails ``arr > 0`` too
        rng = "(0, inf]" if allow_inf else "(0, inf)"
        raise ValueError(f"{name} must be in {rng}, got {_show(arr)}")
    return arr


def check_nonnegative(value, name: str) -> np.ndarray:
    """Array of ``value``; every element must be finite and >= 0."""
    arr = as_float_array(value, name)
    if not np.all(np.isfinite(arr) & (arr >= 0)):
        raise ValueError(f"{name} must be in [0, inf), got {_show(arr)}")
    return arr


def check_range(value, name: str, low: float, high: float, *, closed: str = "both") -> np.ndarray:
    """Array of ``value`` within [low, high]; ``closed``: 'both', 'left', 'right', 'neither'."""
    arr = as_float_array(value, name)
    lo_ok = arr >= low if closed in ("both", "left") else arr > low
    hi_ok = arr <= high if closed in ("both", "right") else arr < high
    if not np.all(lo_ok & hi_ok):
        lb = "[" if closed in ("both", "left") else "("
        rb = "]" if closed in ("both", "right") else ")"
        raise ValueError(f"{name} must be in {lb}{low}, {high}{rb}, got {_show(arr)}")
    return arr


def check_choice(value: str, name: str, choices) -> str:
    """``value`` if it is one of ``choices``, else ``ValueError`` listing them."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {sorted(choices)}, got {value!r}")
    return value


def check_number(value, name: str, low: float, high: float, *, unit: str = "",
                 low_open: bool = False, high_open: bool = False,
                 finite_message: bool = True) -> None:
    """Raise ``ValueError`` naming ``name`` unless ``value`` is a finite number (an int or a
    float, not a bool) from ``low`` to ``high``: the one range check of a scalar setting (the
    settings of the WSP, the odometry, the monitor and the sensor models).

    Both ends are in the range unless ``low_open`` or ``high_open``. Messages: ``"<name> must
    be a finite number, got <value>"`` for a value that is not a finite number, and ``"<name>
    must be in [<low>, <high>] <unit>, got <value>"`` for one outside the range (a parenthesis
    at an open end; no unit when ``unit`` is empty). With ``finite_message=False`` (the
    monitor's settings) a value that is not a number is ``"<name> must be a number, got
    <value>"`` and NaN or an infinity gets the range's message.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "a finite number" if finite_message else "a number"
        raise ValueError(f"{name} must be {kind}, got {value!r}")
    finite = math.isfinite(value)
    if finite_message and not finite:
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    above = low < value if low_open else low <= value
    below = value < high if high_open else value <= high
    if not (finite and above and below):
        lb = "(" if low_open else "["
        rb = ")" if high_open else "]"
        in_unit = f" {unit}" if unit else ""
        raise ValueError(f"{name} must be in {lb}{low:g}, {high:g}{rb}{in_unit}, got {value!r}")


def instance_or_default(value, cls: type, name: str, default, *, expected: str | None = None):
    """An optional argument that must be a ``cls`` (a parameter set, settings): ``default()``
    when ``value`` is None, else ``value``; a ValueError names the argument ``name`` and the
    type given otherwise. ``expected`` words what is allowed in that message (default
    ``"a <cls name>"``)."""
    if value is None:
        value = default()
    if not isinstance(value, cls):
        expected = f"a {cls.__name__}" if expected is None else expected
        raise ValueError(f"{name} must be {expected}, got {type(value).__name__}")
    return value


def _show(arr: np.ndarray) -> str:
    """Short description of the offending values for an error message."""
    if arr.ndim == 0:
        return repr(float(arr))
    bad = arr[~np.isfinite(arr)] if not np.all(np.isfinite(arr)) else arr
    return f"array with values such as {bad.ravel()[:3].tolist()} (shape {arr.shape})"
