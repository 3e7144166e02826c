"""Named parameter sets of the Polach creep-force model, with their provenance.

The five parameters of Polach's extended model (Polach 2005, Wear 258, 992-1000) are

========  ============================================================  ===========
name      meaning                                                       range here
========  ============================================================  ===========
``k_A``   reduction of the Kalker stiffness in the area of adhesion      (0, 1]
``k_S``   reduction of the Kalker stiffness in the area of slip          (0, 1]
``mu0``   maximum friction coefficient (at zero slip velocity)           (0, 1.5]
``A``     ratio mu_inf / mu0 of the friction coefficient at infinite     [0, 10]
          slip velocity to ``mu0``
``B``     exponential decay rate of friction with slip velocity [s/m]    [0, 100]
========  ============================================================  ===========

Polach recommends ``k_S <= k_A <= 1``; this is *not* enforced (fitted or regressed parameters
may violate it), but note that only with ``k_S <= k_A`` is the creep force of the model bounded
by ``mu Q`` (see :func:`railadhesion.models.polach.polach_forces`).

Sets are looked up by name, as in pvlib's ``TEMPERATURE_MODEL_PARAMETERS``::

    >>> from railadhesion.models.parameters import polach_parameters
    >>> p = polach_parameters("polach2005_dry")
    >>> p.as_dict()
    {'k_A': 1.0, 'k_S': 0.4, 'mu0': 0.55, 'A': 0.4, 'B': 0.6}
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from railadhesion.plausibility import PLAUSIBLE, PlausibilityWarning, warn

__all__ = [
    "MU0_PLAUSIBLE_MAX",
    "PARAMETER_RANGES",
    "POLACH_PARAMETER_SETS",
    "PolachParameters",
    "mu0_message",
    "parameter_range_error",
    "polach_parameters",
]

#: Allowed range of each field: (low, high, low_closed, high_closed).
PARAMETER_RANGES: dict[str, tuple[float, float, bool, bool]] = {
    "k_A": (0.0, 1.0, False, True),
    "k_S": (0.0, 1.0, False, True),
    "mu0": (0.0, 1.5, False, True),
    "A": (0.0, 10.0, True, True),
    "B": (0.0, 100.0, True, True),
}


def _range_text(low: float, high: float, low_closed: bool, high_closed: bool) -> str:
    return f"{'[' if low_closed else '('}{low:g}, {high:g}{']' if high_closed else ')'}"


def _in_range(value: float, field: str) -> bool:
    low, high, low_closed, high_closed = PARAMETER_RANGES[field]
    ok = value >= low if low_closed else value > low
    return bool(ok and (value <= high if high_closed else value < high))


def parameter_range_error(field: str, value: float) -> ValueError:
    """The ``ValueError`` of a Polach parameter ``field`` whose ``value`` is outside its range
    (:data:`PARAMETER_RANGES`), as :class:`PolachParameters` and
    :func:`~railadhesion.models.polach.polach_forces` raise it: it names the field and the
    range and, for ``mu0`` (a fraction) whose value / 100 is in range, the likely unit.

    >>> print(parameter_range_error("mu0", 30.0))
    mu0 must be in (0, 1.5], got 30.0; given in percent? (30 percent = 0.3; mu0 is a fraction)
    """
    rng = _range_text(*PARAMETER_RANGES[field])
    text = f"{field} must be in {rng}, got {value!r}"
    if field == "mu0" and math.isfinite(value) and _in_range(value / 100.0, field):
        text += f"; given in percent? ({value:g} percent = {value / 100.0:g}; mu0 is a fraction)"
    return ValueError(text)


#: Largest plausible mu0: the upper end of the plausible coefficient of friction
#: (:data:`railadhesion.plausibility.PLAUSIBLE`, ``friction_coefficient``).
MU0_PLAUSIBLE_MAX = PLAUSIBLE["friction_coefficient"].high


def mu0_message(mu0) -> str | None:
    """The message of a mu0 (a number or an array, already in its range (0, 1.5]) above
    :data:`MU0_PLAUSIBLE_MAX`, or None: possible in the model, but no wheel-rail value."""
    high = float(np.nanmax(mu0)) if np.ndim(mu0) else float(mu0)
    if not high > MU0_PLAUSIBLE_MAX:
        return None
    return (f"mu0 = {high:.4g} is outside the plausible range [0, {MU0_PLAUSIBLE_MAX:g}] of a "
            "coefficient of friction (a fraction) (docs/checks.md): above 1 it is no "
            "wheel-rail value (dry rails about 0.4-0.6); check the value")  # fmt: skip


@dataclass(frozen=True)
class PolachParameters:
    """One set of the five parameters of Polach's extended creep-force model.

    Validated on construction: every value must be a finite real number in its range
    (:data:`PARAMETER_RANGES`), else ``ValueError`` naming the field and the range.

    Parameters
    ----------
    k_A : float
        Reduction factor of Kalker's creep coefficient in the area of adhesion [-], (0, 1].
    k_S : float
        Reduction factor in the area of slip [-], (0, 1]. Polach recommends k_S <= k_A.
    mu0 : float
        Maximum (static) friction coefficient [-], (0, 1.5]; above 1 (no wheel-rail value) a
        :class:`~railadhesion.plausibility.PlausibilityWarning`.
    A : float
        mu_inf / mu0, ratio of the friction coefficient at infinite slip velocity to mu0 [-],
        [0, 10]. ``A = 1`` (or ``B = 0``) means friction independent of slip velocity.
    B : float
        Exponential friction decrease rate [s/m], [0, 100].
    name : str
        Short name of the set (the registry key for the built-in sets).
    source : str
        Where the numbers come from (paper, table, file), stated honestly.
    notes : str
        Free text: conditions, caveats.

    Notes
    -----
    Friction law (Polach 2005, Wear 258, eq. for the friction coefficient):
    mu = mu0 [(1 - A) exp(-B w) + A], w = slip (creep) velocity [m/s].

    Examples
    --------
    >>> p = PolachParameters(k_A=0.5, k_S=0.2, mu0=0.3, A=0.4, B=0.3, name="mine")
    >>> p.replace(mu0=0.25).mu0
    0.25
    """

    k_A: float
    k_S: float
    mu0: float
    A: float
    B: float
    name: str = ""
    source: str = ""
    notes: str = ""

    def __post_init__(self) -> None:
        for field, (low, high, low_closed, high_closed) in PARAMETER_RANGES.items():
            raw = getattr(self, field)
            rng = _range_text(low, high, low_closed, high_closed)
            # float() would also take bools, numeric strings ("0.5") and 1-element arrays
            if isinstance(raw, bool | np.bool_ | str | bytes) or np.ndim(raw) != 0:
                raise ValueError(f"{field} must be a real number in {rng}, got {raw!r}")
            try:
                value = float(raw)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{field} must be a real number in {rng}, got {raw!r}") from exc
            if not (math.isfinite(value) and _in_range(value, field)):
                raise parameter_range_error(field, value)
            object.__setattr__(self, field, value)
        text = mu0_message(self.mu0)
        if text is not None:
            warn(f"{self.name or 'PolachParameters'}: {text}", PlausibilityWarning)
        for field in ("name", "source", "notes"):
            if not isinstance(getattr(self, field), str):
                raise ValueError(f"{field} must be a string, got {getattr(self, field)!r}")

    def as_dict(self) -> dict[str, float]:
        """The five model parameters as ``{"k_A", "k_S", "mu0", "A", "B"}`` (no provenance)."""
        return {"k_A": self.k_A, "k_S": self.k_S, "mu0": self.mu0, "A": self.A, "B": self.B}

    def replace(self, **changes) -> PolachParameters:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)


_POLACH2005_SOURCE = (
    "Polach O., Creep forces in simulations of traction vehicles running on adhesion limit, "
    "Wear 258 (2005) 992-1000, as quoted in third-party codes, labelled typical locomotive "
    "values; not read in the paper"
)


def _polach2005(rail: str, **values: float) -> PolachParameters:
    """The Polach 2005 set for a ``"dry"`` or ``"wet"`` rail, from its five ``values``."""
    return PolachParameters(
        **values,
        name=f"polach2005_{rail}",
        source=_POLACH2005_SOURCE,
        notes=f"{rail.capitalize()} rail. Identical values found in two independent "
        "third-party codes.",
    )


#: Built-in parameter sets, by name.
POLACH_PARAMETER_SETS: dict[str, PolachParameters] = {
    "polach2005_dry": _polach2005("dry", k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6),
    "polach2005_wet": _polach2005("wet", k_A=0.3, k_S=0.1, mu0=0.3, A=0.4, B=0.2),
    "contact_eurosprinter": PolachParameters(
        k_A=1.0,
        k_S=1.0,
        mu0=0.36,
        A=0.38,
        B=1.0 / 0.99,
        name="contact_eurosprinter",
        source=(
            "CONTACT (Vollebregt, eve70a/CONTACT, Apache-2.0) example examples/tractcurv.inp, "
            "4th series (Eurosprinter locomotive, after Polach 2005): exponential falling "
            "friction FKIN = 0.1368, FEXP1 = 0.2232, SABSH1 = 990 mm/s, i.e. mu_stat = 0.36, "
            "A = 0.1368/0.36 = 0.38, B = 1/(0.99 m/s) = 1.0101 s/m"
        ),
        notes=(
            "Friction law only; k_A = k_S = 1 (no slope reduction). CONTACT applies its law to "
            "the local slip velocity, Polach's to the creep velocity s*V, so the mapping is "
            "approximate. CONTACT itself combines this friction with a FASTSIM slope reduction "
            "(k0 = 0.54, alpha = 0.02, beta = 0.62) that has no exact Polach equivalent. "
            "A value B = 0.7 s/m is quoted elsewhere for this case; it could not be confirmed "
            "in the CONTACT input file."
        ),
    ),
}


def polach_parameters(name: str) -> PolachParameters:
    """Built-in Polach parameter set ``name`` (a key of :data:`POLACH_PARAMETER_SETS`).

    Parameters
    ----------
    name : str
        Name of the set, e.g. ``"polach2005_dry"``, ``"polach2005_wet"``,
        ``"contact_eurosprinter"``.

    Returns
    -------
    PolachParameters

    Raises
    ------
    ValueError
        If ``name`` is unknown; the message lists the valid names.

    Examples
    --------
    >>> polach_parameters("polach2005_wet").k_A
    0.3
    """
    try:
        return POLACH_PARAMETER_SETS[name]
    except (KeyError, TypeError):
        valid = ", ".join(sorted(POLACH_PARAMETER_SETS))
        raise ValueError(
            f"unknown Polach parameter set {name!r}; valid names (see "
            f"railadhesion.models.parameters.POLACH_PARAMETER_SETS): {valid}"
        ) from None
