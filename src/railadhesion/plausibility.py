"""Warning categories of the input and result policy (docs/CONVENTIONS.md, "Careless inputs").

Ground floor: imports only the standard library, so every module may use it.

* An **impossible** input raises ``ValueError`` naming the argument and the allowed range.
* A **possible but implausible** input (outside what railway use produces, or a value that
  looks like another unit) gives a :class:`PlausibilityWarning` (:class:`UnitWarning` for a
  unit slip).
* A result that was **altered** (clipped, capped, extrapolated) gives an
  :class:`AlteredResultWarning`.
* A result that **cannot be trusted** (a poor fit, a stop that did not end, NaN) gives an
  :class:`UntrustedResultWarning`.

Every category derives from :class:`RailadhesionWarning`, so a user can silence, log or turn
into errors all of them at once (``warnings.simplefilter("error", RailadhesionWarning)``) or
one category at a time.
"""

from __future__ import annotations

import warnings

__all__ = [
    "RailadhesionWarning",
    "PlausibilityWarning",
    "UnitWarning",
    "AlteredResultWarning",
    "UntrustedResultWarning",
    "warn",
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


def warn(message: str, category: type[RailadhesionWarning], *, stacklevel: int = 2) -> str:
    """Issue ``message`` as ``category`` (pointing at the caller's caller by default) and
    return it, so that the caller can also record it on its result."""
    warnings.warn(message, category, stacklevel=stacklevel + 1)
    return message
