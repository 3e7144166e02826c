"""The careless-input policy: warning categories, plausible ranges, unit sniffers, result flags.

Written policy: ``docs/CONVENTIONS.md`` ("Careless inputs"); every check with its threshold:
``docs/checks.md``. Ground floor: imports only the standard library and NumPy, so every
module may use it.

* An **impossible** input raises ``ValueError`` naming the argument and the allowed range (the
  model functions do this themselves, :mod:`railadhesion._validate`).
* A **possible but implausible** input (outside what railway use produces, :data:`PLAUSIBLE`)
  gives a :class:`PlausibilityWarning`, or a :class:`UnitWarning` when the value would be
  plausible in another unit (bar for Pa, km/h for m/s, percent for a fraction); the message
  names the argument or field and the likely unit.
* A result that was **altered** (clipped, capped, extrapolated) gives an
  :class:`AlteredResultWarning`, and the result says so where it has a summary.
* A result that **cannot be trusted** (a poor fit, a run that did not finish, NaN) gives an
  :class:`UntrustedResultWarning` and carries ``trusted = False`` and its reasons in
  ``warnings`` (a tuple of str): the convention of every result object of the package
  (:func:`fit_warnings` is the quality gate of every fit; :func:`first_reason` what the CLI
  prints).

Every category derives from :class:`RailadhesionWarning`, so a user can silence, log or turn
into errors all of them at once (``warnings.simplefilter("error", RailadhesionWarning)``) or
one category at a time.
"""

from __future__ import annotations

import inspect
import math
import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "RailadhesionWarning",
    "PlausibilityWarning",
    "UnitWarning",
    "AlteredResultWarning",
    "UntrustedResultWarning",
    "warn",
    "PlausibleRange",
    "PLAUSIBLE",
    "ARGUMENT_QUANTITY",
    "check_plausible",
    "check_calibrated",
    "input_checker",
    "likely_unit",
    "sniff_speed_ratio",
    "sniff_sample_period",
    "sniff_ratio",
    "MAX_LOG_PERIOD",
    "MIN_R_SQUARED",
    "MIN_R_SQUARED_SCATTER",
    "MAX_RELATIVE_STDERR",
    "MIN_REGION_POINTS",
    "MAX_NOISE_RATIO",
    "MIN_NOISE_POINTS",
    "noise_rms",
    "explains_data",
    "fit_warnings",
    "is_trusted",
    "first_reason",
]


class RailadhesionWarning(UserWarning):
    """Base class of every warning this package issues."""


class PlausibilityWarning(RailadhesionWarning):
    """An input is possible but implausible for railway use."""


class UnitWarning(PlausibilityWarning):
    """An input looks as if it were given in another unit (bar for Pa, km/h for m/s, ...)."""


class AlteredResultWarning(RailadhesionWarning):
    """A result was altered: clipped, capped or extrapolated."""


class UntrustedResultWarning(RailadhesionWarning):
    """A result should not be trusted (a poor fit, a run that did not finish, NaN)."""


_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _is_ours(filename: str) -> bool:
    """A frame of this package (its files, or the wrappers ``_labelled`` generates)."""
    return filename.startswith((_PACKAGE_DIR, "<labelled ", "<plausibility "))


def _caller_level() -> int:
    """The ``stacklevel`` (for a ``warnings.warn`` call in :func:`warn`) of the first frame
    outside this package: the user's line that made the call."""
    frame = inspect.currentframe()
    frame = frame.f_back if frame is not None else None  # warn()'s own frame: level 1
    level = 1
    while frame is not None and _is_ours(frame.f_code.co_filename):
        frame = frame.f_back
        level += 1
    return level


def warn(message: str, category: type[RailadhesionWarning], *,
         stacklevel: int | None = None) -> str:  # fmt: skip
    """Issue ``message`` as ``category`` and return it, so that the caller can also record it
    on its result.

    ``stacklevel`` as in :func:`warnings.warn`, counted from the caller of ``warn`` (2: the
    caller's caller); ``None`` (default): the first frame outside this package, i.e. the
    user's line, however deep in the package the check sits.
    """
    level = _caller_level() if stacklevel is None else stacklevel + 1
    warnings.warn(message, category, stacklevel=level)
    return message


# ----------------------------------------------------------------------------- the table


@dataclass(frozen=True)
class PlausibleRange:
    """Plausible range of one physical quantity in railway use.

    Attributes
    ----------
    quantity : str
        What it is, for messages ("wheel load").
    unit : str
        Its unit in the package (SI; "bar" for the pressure columns of a braking-test log).
    low, high : float
        Plausible range, ``[low, high]`` (signed quantities: ``[-high, high]``, ``low = -high``).
    source : str
        Where the range comes from, or "assumption".
    other_units : tuple of (str, float)
        Units a careless user may have used instead, each with the value of one such unit in
        :attr:`unit` (``("bar", 1e5)`` for a pressure in Pa): a value outside the range that
        falls inside it once converted gives a :class:`UnitWarning` naming that unit.
    convention : str
        Who expects :attr:`unit`, for the message (default: the package).
    slack : float
        Values within ``slack`` of the range count as inside (numerical probes, e.g. the
        creepage ``1 + 1e-6`` a solver's finite difference evaluates next to a locked wheel).
    """

    quantity: str
    unit: str
    low: float
    high: float
    source: str
    other_units: tuple[tuple[str, float], ...] = ()
    convention: str = ""
    slack: float = 0.0

    def describe(self) -> str:
        return f"[{_g(self.low)}, {_g(self.high)}] {self.unit}".rstrip()


#: Plausible ranges of the physical inputs, by quantity (``docs/checks.md`` prints this table).
PLAUSIBLE: dict[str, PlausibleRange] = {
    "creepage": PlausibleRange(
        "creepage (a fraction)", "", -1.0, 1.0,
        "a locked braking wheel has creepage 1 (docs/CONVENTIONS.md); beyond, only a wheel "
        "spinning faster than twice the train speed in traction",
        (("percent", 0.01),), slack=1e-3,
    ),
    "spin": PlausibleRange(
        "spin creepage", "rad/m", -5.0, 5.0,
        "assumption: sin(contact angle)/rolling radius, below 1/(0.2 m) even in flange contact",
        (("deg/m", math.pi / 180.0),),
    ),
    "wheel_load": PlausibleRange(
        "wheel load (normal force)", "N", 500.0, 5e5,
        "tram rig 4.2 kN and locomotive 110 kN (seed 000); 40 t heavy-haul axles carry about "
        "200 kN per wheel, dynamic loads up to about twice the static one (assumption)",
        (("kN", 1e3),),
    ),
    "speed": PlausibleRange(
        "speed", "m/s", 0.0, 100.0,
        "fastest commercial services run at 350 km/h (97 m/s); only record runs go beyond",
        (("km/h", 1.0 / 3.6), ("mph", 0.44704)),
    ),
    "semi_axis": PlausibleRange(
        "contact semi-axis", "m", 2e-4, 0.05,
        "assumption: wheel-rail contacts measure a few mm (seed 000 tram rig; CONTACT's "
        "Eurosprinter case 6.3 x 12.6 mm); 0.2 mm small rigs, 50 mm conformal contacts",
        (("mm", 1e-3),),
    ),
    "friction_coefficient": PlausibleRange(
        "coefficient of friction (a fraction)", "", 0.0, 1.0,
        "assumption: dry wheel-rail friction is about 0.4-0.6 (Polach's dry set mu0 = 0.55), "
        "wet and contaminated rails lower; above 1 it is no wheel-rail value",
        (("percent", 0.01),),
    ),
    "shear_modulus": PlausibleRange(
        "shear modulus", "Pa", 2e10, 2e11,
        "steels about 80 GPa (CONTACT's examples: 82 GPa); assumption for the margins",
        (("MPa (N/mm^2)", 1e6), ("GPa", 1e9)),
    ),
    "young": PlausibleRange(
        "Young's modulus", "Pa", 5e10, 5e11,
        "steels about 210 GPa (seed 001); assumption for the margins",
        (("MPa (N/mm^2)", 1e6), ("GPa", 1e9)),
    ),
    "poisson": PlausibleRange(
        "Poisson's ratio", "", 0.2, 0.35,
        "steels 0.27-0.30 (seed 001: 0.3; CONTACT: 0.28); assumption for the margins",
    ),
    "water_flow": PlausibleRange(
        "water flow rate", "µl/s", 0.0, 1000.0,
        "seed 000 measured 0-350 µl/s (WILAC's wet condition from about 60 µl/s); "
        "assumption above",
    ),
    "rolling_radius": PlausibleRange(
        "rolling radius", "m", 0.005, 5.0,
        "assumption: twin discs of seed 001 (23.5 mm) to large roller rigs",
        (("mm", 1e-3),),
    ),
    "wheel_radius": PlausibleRange(
        "railway wheel radius", "m", 0.15, 0.75,
        "assumption: small tram and freight wheels (about 0.3 m) to locomotive wheels "
        "(CONTACT's Eurosprinter example: 0.625 m)",
        (("mm", 1e-3),),
    ),
    "line_half_width": PlausibleRange(
        "line-contact half-width", "m", 1e-5, 0.05,
        "seed 001 twin discs: 0.16-0.27 mm; assumption for the margins",
        (("mm", 1e-3),),
    ),
    "reduced_radius": PlausibleRange(
        "reduced radius", "m", 1e-3, 2.0,
        "seed 001 twin discs: 11.75 mm; assumption for the margins",
        (("mm", 1e-3),),
    ),
    "contact_pressure": PlausibleRange(
        "maximum contact pressure", "Pa", 1e8, 3e9,
        "seed 001 tests at 800-1500 MPa; wheel-rail contacts up to about 2 GPa (assumption)",
        (("MPa", 1e6), ("GPa", 1e9)),
    ),
    "brake_pressure": PlausibleRange(
        "brake-cylinder pressure", "Pa", 5e3, 2e6,
        "passenger brake cylinders reach about 3.8 bar (UIC 543, via a secondary source), the "
        "examples 5.5-6 bar; the bounds 0.05 bar (no brake acts) and 20 bar (no railway "
        "cylinder works) are issue 18's",
        (("bar", 1e5), ("kPa", 1e3), ("psi", 6894.757), ("MPa", 1e6)),
    ),
    "log_pressure": PlausibleRange(
        "brake-cylinder pressure in a braking-test log", "bar", -1.0, 20.0,
        "the log format records bar (docs/braking-log.md); 20 bar as brake_pressure; down to "
        "-1 bar for sensor offsets and noise (assumption)",
        (("Pa", 1e-5), ("kPa", 1e-2), ("psi", 0.06894757)),
        "the braking-log format records bar",
    ),
}

#: Quantity of each argument or field name the package checks.
ARGUMENT_QUANTITY: dict[str, str] = {
    "creep_long": "creepage", "creep_lat": "creepage", "creep": "creepage",
    "spin": "spin",
    "normal_force": "wheel_load",
    "speed": "speed", "initial_speed": "speed",
    "a": "semi_axis", "b": "semi_axis",
    "shear_modulus": "shear_modulus",
    "mu": "friction_coefficient",
    "young": "young", "young_rail": "young",
    "poisson": "poisson", "poisson_rail": "poisson",
    "water_flow": "water_flow",
    "wheel_radius": "rolling_radius", "rail_radius": "rolling_radius",
    "half_width": "line_half_width",
    "radius": "reduced_radius",
    "max_pressure": "contact_pressure",
    "brake_pressure": "brake_pressure",
}  # fmt: skip


def _g(x: float) -> str:
    return f"{x:.4g}"


def likely_unit(rng: PlausibleRange, low: float, high: float) -> tuple[str, float] | None:
    """The first of ``rng.other_units`` in which values spanning ``[low, high]`` (given in that
    unit) would be plausible: ``(unit name, value of one such unit in rng.unit)``, or None."""
    for name, factor in rng.other_units:
        lo, hi = sorted((low * factor, high * factor))
        if rng.low <= lo and hi <= rng.high:
            return name, factor
    return None


def _extremes(value) -> tuple[float, float] | None:
    """(min, max) of a number or array, NaN ignored; None if there is nothing to check."""
    if type(value) is float or type(value) is int:
        x = float(value)
        return None if math.isnan(x) else (x, x)
    arr = np.asarray(value, dtype=float)
    if arr.size == 0:
        return None
    flat = arr.ravel()
    lo, hi = float(np.fmin.reduce(flat)), float(np.fmax.reduce(flat))
    if math.isnan(lo):
        return None
    return lo, hi


def _message(where: str, rng: PlausibleRange, lo: float, hi: float, what: str):
    """(message, category) for values spanning [lo, hi] that left the plausible range."""
    shown = _g(lo) if lo == hi else f"from {_g(lo)} to {_g(hi)}"
    bad = hi if hi > rng.high else lo
    unit = f" {rng.unit}" if rng.unit else ""
    text = (f"{where} = {shown}{unit} is outside the plausible range {rng.describe()} of a "
            f"{what or rng.quantity} (docs/checks.md)")  # fmt: skip
    guess = likely_unit(rng, lo, hi)
    if guess is None:
        return text + ": check the value and its unit", PlausibilityWarning
    name, factor = guess
    convention = rng.convention or f"the package works in {rng.unit or 'fractions'}"
    return (text + f"; given in {name}? ({_g(bad)} {name} = {_g(bad * factor)}{unit}; "
            f"{convention})"), UnitWarning  # fmt: skip


def check_plausible(value, name: str, *, where: str | None = None, quantity: str | None = None,
                    what: str = "", emit: bool = True) -> str | None:  # fmt: skip
    """Check ``value`` (a number or an array) against the plausible range of its quantity.

    Parameters
    ----------
    value : float or array_like
        The input (NaN ignored: non-finite inputs are errors of the caller's own checks).
    name : str
        The argument name; its quantity is ``ARGUMENT_QUANTITY[name]`` unless ``quantity``.
    where : str, optional
        How the message names it (a file field such as ``brake.pressure_Pa``; default
        ``name``).
    quantity : str, optional
        A key of :data:`PLAUSIBLE`.
    what : str, optional
        A more precise description for the message.
    emit : bool, default True
        Issue the warning (:class:`UnitWarning` when another unit fits, else
        :class:`PlausibilityWarning`); else only return the message.

    Returns
    -------
    str or None
        The message, or None when the value is plausible.

    Examples
    --------
    >>> print(check_plausible(160.0, "speed", emit=False))  # doctest: +NORMALIZE_WHITESPACE
    speed = 160 m/s is outside the plausible range [0, 100] m/s of a speed (docs/checks.md);
    given in km/h? (160 km/h = 44.44 m/s; the package works in m/s)
    >>> check_plausible(44.4, "speed") is None
    True
    """
    rng = PLAUSIBLE[quantity or ARGUMENT_QUANTITY[name]]
    ext = _extremes(value)
    if ext is None:
        return None
    lo, hi = ext
    if rng.low - rng.slack <= lo and hi <= rng.high + rng.slack:
        return None
    text, category = _message(where or name, rng, lo, hi, what)
    if emit:
        warn(text, category)
    return text


def input_checker(names: Sequence[str]) -> Callable[[Sequence], tuple[str, ...]]:
    """A checker of a function's arguments: ``check(values)`` with ``values`` in the order of
    ``names`` warns for every implausible one and returns the messages (``()`` if none).

    Names without a quantity in :data:`ARGUMENT_QUANTITY` are skipped. Python floats and ints
    and NumPy float64 scalars are compared directly (two comparisons each: model functions are
    called in inner loops); other values get one vectorised pass (their minimum and maximum).
    """
    ranges = {n: PLAUSIBLE[ARGUMENT_QUANTITY[n]] for n in names if n in ARGUMENT_QUANTITY}
    spec = tuple(
        (i, n, ranges[n].low - ranges[n].slack, ranges[n].high + ranges[n].slack)
        for i, n in enumerate(names) if n in ranges
    )  # fmt: skip

    def slow(values) -> tuple[str, ...]:
        found = []
        for i, name, _, _ in spec:
            text = check_plausible(values[i], name)
            if text is not None:
                found.append(text)
        return tuple(found)

    if not spec:
        return lambda values: ()
    # The fast test as one generated expression, with no loop (its cost in the model
    # functions: benchmarks/bench_plausibility.py):
    # ``type(v) in (float, numpy.float64, int) and lo <= v <= hi`` for each checked argument.
    unpack = ", ".join(f"v{i}" for i in range(len(names)))
    test = " and ".join(
        f"_t(v{i}) in _f and {lo!r} <= v{i} <= {hi!r}" for i, _, lo, hi in spec
    )
    src = (f"def check(values, _t=type, _f=_scalar_types, _slow=_slow):\n"
           f"    {unpack}, = values\n"
           f"    if {test}:\n        return ()\n    return _slow(values)\n")  # fmt: skip
    namespace: dict = {"_slow": slow, "_scalar_types": frozenset((float, np.float64, int))}
    exec(compile(src, "<plausibility checker>", "exec"), namespace)  # noqa: S102
    return namespace["check"]


def check_calibrated(value, name: str, low: float, high: float, *, unit: str,
                     what: str) -> str | None:  # fmt: skip
    """Report an input outside the range a model was calibrated for, where the model clamps
    it (an extrapolation): an :class:`AlteredResultWarning` naming the input, the range and
    what the model does; returns the message, or None when ``value`` is inside.

    Examples
    --------
    >>> check_calibrated(2.0, "speed", 2.0, 40.0, unit="m/s", what="the WILAC set") is None
    True
    """
    if type(value) is float and low <= value <= high:
        return None
    ext = _extremes(value)
    if ext is None or (low <= ext[0] and ext[1] <= high):
        return None
    lo, hi = ext
    shown = _g(lo) if lo == hi else f"from {_g(lo)} to {_g(hi)}"
    return warn(f"{name} = {shown} {unit} is outside the calibrated range [{_g(low)}, "
                f"{_g(high)}] {unit} of {what}: its parameters are held at their values at the "
                "nearest end (an extrapolation; docs/checks.md)", AlteredResultWarning)  # fmt: skip


# ----------------------------------------------------------------------------- sniffers


def sniff_ratio(ratio: float, expected: str, candidates: Mapping[str, float], *,
                tolerance: float = 3.0) -> tuple[bool, str | None]:  # fmt: skip
    """Is ``ratio`` (measured / expected) near 1, or near one of the ``candidates``?

    Returns ``(ok, unit)``: ``ok`` if ``1/tolerance <= ratio <= tolerance``; else the name of
    the candidate whose ratio is closest (within the same factor), or None. ``expected`` only
    documents what the ratio compares.
    """
    del expected
    if not (ratio > 0 and math.isfinite(ratio)):
        return False, None
    if 1.0 / tolerance <= ratio <= tolerance:
        return True, None
    best, dist = None, math.log(tolerance)
    for unit, r in candidates.items():
        d = abs(math.log(ratio / r))
        if d < dist:
            best, dist = unit, d
    return False, best


def sniff_speed_ratio(train_speed, wheel_speed, wheel_radius: float | None = None, *,
                      where: str = "train_speed") -> str | None:  # fmt: skip
    """Warn if the train speed and the wheel angular speeds are in inconsistent units.

    While the wheels roll, ``v = R omega``: the median over the samples (train speed above
    1 m/s) of ``v / max_i omega_i`` (the fastest axle is the one nearest to rolling) is the
    wheel radius. Against the vehicle's ``wheel_radius`` (or, without one, against the
    plausible railway wheel radius of :data:`PLAUSIBLE`), a factor of 3.6 means km/h, 2.24
    mph, 0.105 a wheel speed in rpm. Returns the message (a :class:`UnitWarning` issued) or
    None.
    """
    v = np.asarray(train_speed, dtype=float).ravel()
    w = np.asarray(wheel_speed, dtype=float)
    w = w.reshape(v.size, -1) if w.size else w
    if v.size == 0 or w.size == 0:
        return None
    stride = max(1, v.size // 20_000)  # a median of 20 000 samples is plenty (and cheap)
    v, w = v[::stride], w[::stride]
    with np.errstate(invalid="ignore", divide="ignore"):
        fastest = np.fmax.reduce(w, axis=1)
        moving = (v > 1.0) & (fastest > 0) & np.isfinite(v) & np.isfinite(fastest)
        if np.count_nonzero(moving) < 3:
            return None
        radius = float(np.median(v[moving] / fastest[moving]))
    slips = {"km/h": 3.6, "mph": 1.0 / 0.44704, "wheel speeds in rpm": math.pi / 30.0,
             "wheel speeds in rev/s": 2.0 * math.pi}  # fmt: skip
    rng = PLAUSIBLE["wheel_radius"]
    if wheel_radius is not None:
        ok, unit = sniff_ratio(radius / float(wheel_radius), "wheel radius", slips,
                               tolerance=1.25)  # fmt: skip
        ref = f"the vehicle's wheel radius {_g(float(wheel_radius))} m"
    else:
        ok = rng.low <= radius <= rng.high
        fits = [u for u, r in slips.items() if rng.low <= radius / r <= rng.high]
        unit = " or ".join(fits) if fits else None  # without the vehicle, maybe ambiguous
        ref = f"the plausible railway wheel radius {rng.describe()}"
    if ok:
        return None
    text = (f"{where}: the train speed over the fastest wheel's angular speed gives a rolling "
            f"radius of {_g(radius)} m, not {ref} (v = R omega while the wheels roll)")  # fmt: skip
    if unit is None:
        text += ": check the units of train_speed [m/s] and wheel_speed_i [rad/s]"
        category: type[RailadhesionWarning] = PlausibilityWarning
    elif unit.startswith("wheel"):
        text += f"; {unit}? (the log format records rad/s)"
        category = UnitWarning
    else:
        text += f"; train_speed in {unit}? (the log format records m/s)"
        category = UnitWarning
    return warn(text, category)


#: Longest sampling period of a braking-test log [s] (seed 002 samples every 2.4 ms; the
#: identification filters at 2 Hz need far finer sampling).
MAX_LOG_PERIOD = 0.1


def sniff_sample_period(period: float, *, where: str = "time") -> str | None:
    """Warn if a braking-test log's median sampling period [s] is implausibly long: above
    :data:`MAX_LOG_PERIOD`, and a :class:`UnitWarning` (time in ms) when it would be a
    plausible period in milliseconds. Returns the message or None."""
    if not (period > MAX_LOG_PERIOD):
        return None
    text = (f"{where}: the median sampling period is {_g(period)} s, above the "
            f"{_g(MAX_LOG_PERIOD)} s a braking-test log can be identified from (seed 002 "
            "samples every 2.4 ms)")  # fmt: skip
    if period * 1e-3 <= MAX_LOG_PERIOD:
        return warn(text + f"; time in ms? ({_g(period)} ms = {_g(period * 1e-3)} s; the log "
                    "format records s)", UnitWarning)  # fmt: skip
    return warn(text, PlausibilityWarning)


# ----------------------------------------------------------------------------- result flags

#: Smallest R^2 of a trusted fit of a creep curve (below it the model does not describe the
#: data). An assumption; fits may pass their own.
MIN_R_SQUARED = 0.9
#: Smallest R^2 of a trusted fit to scattered samples: adhesion identified from braking logs,
#: low-creep data near the measurement noise. Measured: a good fit to a braking log has R^2
#: of 0.64-0.8 with the zero-phase filters and down to 0.50 with the paper's causal one (the
#: tests' closed loops); low-creep data with noise 0.002 give 0.83 (Fletcher's CG1 to 0.2 %);
#: the curves that do not describe their samples give 0.12 and 0.05 (the damp-rail example's
#: log, 0-10 m/s and all speeds) and -16.9 (Fletcher's model on data at 20-60 % creep).
MIN_R_SQUARED_SCATTER = 0.3
#: Largest standard error of a fitted parameter, relative to its value, in a trusted fit.
MAX_RELATIVE_STDERR = 1.0
#: Fewest points in the part of the curve that carries a parameter (e.g. points beyond the
#: peak for the falling friction).
MIN_REGION_POINTS = 3


#: Largest ratio of a fit's residual RMS to the data's own noise (:func:`noise_rms`) at which
#: a low R^2 is put down to a nearly flat curve rather than to the model (an assumption: the
#: residual of the right model is the noise, and the noise estimate is itself uncertain).
MAX_NOISE_RATIO = 1.5
#: Fewest samples from which :func:`noise_rms` estimates the noise (with fewer, the curve's own
#: change between samples dominates the successive differences; an assumption).
MIN_NOISE_POINTS = 10


def noise_rms(x, y) -> float:
    """Standard deviation of the noise of samples ``y(x)``, from successive differences.

    ``sqrt(sum((y[k+1] - y[k])^2) / (2 (n - 1)))`` with the samples in order of ``x``: the
    mean square successive difference of J. von Neumann et al., Ann. Math. Statist. 12
    (1941) 153-162, which the noise dominates when the curve changes little from one sample
    to the next. Where the curve itself changes between samples it over-estimates the noise
    (the check that uses it is then more lenient, never stricter). NaN for fewer than
    :data:`MIN_NOISE_POINTS` samples.

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> x = np.linspace(0.0, 1.0, 2000)
    >>> round(noise_rms(x, 0.15 + 0.01 * x + rng.normal(0.0, 0.004, x.size)), 4)
    0.004
    """
    xs = np.asarray(x, dtype=float).ravel()
    ys = np.asarray(y, dtype=float).ravel()
    if ys.size < MIN_NOISE_POINTS or xs.size != ys.size:
        return math.nan
    d = np.diff(ys[np.argsort(xs, kind="stable")])
    return float(np.sqrt(np.mean(d * d) / 2.0))


def explains_data(r_squared: float, *, residual_rms: float | None = None,
                  noise: float | None = None, min_r_squared: float = MIN_R_SQUARED) -> bool:
    """Whether a fit describes its data: R^2 at least ``min_r_squared``, or else (a nearly flat
    curve, whose variance is mostly noise, has a low R^2 even when the model is right) a
    residual RMS within :data:`MAX_NOISE_RATIO` times the data's noise (:func:`noise_rms`).

    >>> explains_data(0.8, residual_rms=0.004, noise=0.004)   # flat wet curve, right model
    True
    >>> explains_data(0.0004, residual_rms=0.03, noise=0.004)  # wrong model
    False
    """
    if r_squared >= min_r_squared:
        return True
    if residual_rms is None or noise is None:
        return False
    return bool(residual_rms <= MAX_NOISE_RATIO * noise)  # NaN: False


def fit_warnings(*, r_squared: float, params: Mapping[str, float], fitted: Sequence[str],
                 stderr: Mapping[str, float], at_bound: Sequence[str] = (),
                 region_points: Mapping[str, tuple[int, str]] | None = None,
                 min_r_squared: float = MIN_R_SQUARED, success: bool = True,
                 ignore_stderr: Sequence[str] = (), residual_rms: float | None = None,
                 noise: float | None = None) -> tuple[str, ...]:  # fmt: skip
    """The quality gate of every fit: why its result should not be trusted (empty if none).

    Flags a low R^2, fitted parameters ending on a bound of the search, non-finite or very
    large standard errors (above :data:`MAX_RELATIVE_STDERR` times the value), and too few
    points (below :data:`MIN_REGION_POINTS`) in the region of the data that carries a
    parameter.

    Parameters
    ----------
    r_squared : float
    params, stderr : mapping
        Values and standard errors of the parameters.
    fitted : sequence of str
        The fitted parameters (only they are checked).
    at_bound : sequence of str
        Fitted parameters that ended on a bound that is not a limit of the model's domain.
    region_points : mapping, optional
        ``{parameter: (points, "description of the region")}``.
    min_r_squared : float
        Smallest acceptable R^2.
    residual_rms, noise : float, optional
        The fit's residual RMS and the data's noise (:func:`noise_rms`): a low R^2 is not
        flagged when the residual is within :data:`MAX_NOISE_RATIO` times the noise
        (:func:`explains_data`).
    success : bool
        The optimiser converged.
    ignore_stderr : sequence of str
        Parameters whose standard error does not matter (e.g. the rate of a fall of size 0).

    Examples
    --------
    >>> fit_warnings(r_squared=0.0004, params={"mu0": 0.13}, fitted=("mu0",),
    ...              stderr={"mu0": 0.02})
    ('R^2 = 0.0004 is below 0.9: the model does not describe the data',)
    """
    out = []
    if not success:
        out.append("the optimiser did not converge")
    if not explains_data(r_squared, residual_rms=residual_rms, noise=noise,
                         min_r_squared=min_r_squared):  # NaN fails too
        out.append(f"R^2 = {r_squared:.3g} is below {min_r_squared:g}: the model does not "
                   "describe the data")  # fmt: skip
    for name in fitted:
        if name in at_bound:
            out.append(f"{name} = {params[name]:.4g} is on a bound of the search: the data "
                       "push it beyond the range allowed")  # fmt: skip
            continue
        if name in ignore_stderr:
            continue
        err, val = stderr.get(name, math.nan), params[name]
        if not math.isfinite(err):
            out.append(f"{name}: standard error not finite, the data do not determine it")
        elif err > MAX_RELATIVE_STDERR * abs(val):
            out.append(f"{name} = {val:.4g} +/- {err:.2g}: standard error above "
                       f"{MAX_RELATIVE_STDERR:g} x the value, the data hardly determine it")
    for name, (count, region) in (region_points or {}).items():
        if name in fitted and count < MIN_REGION_POINTS:
            out.append(f"{name}: {count} point(s) {region} (fewer than {MIN_REGION_POINTS}): "
                       "the data do not carry it")  # fmt: skip
    return tuple(out)


def is_trusted(result) -> bool:
    """``result.trusted`` (True for objects without the attribute)."""
    return bool(getattr(result, "trusted", True))


def first_reason(result) -> str:
    """The first of ``result.warnings`` (the reason it is not trusted), or ""."""
    found = tuple(getattr(result, "warnings", ()) or ())
    return found[0] if found else ""
