"""railadhesion: wheel-rail adhesion models, contact mechanics and calibration.

Sign convention and units: see ``docs/CONVENTIONS.md``. In short: SI units; creepage
xi = (V - omega R)/V (braking positive); forces are exerted by the rail on the wheel and
oppose the creepage (Kalker's convention, as in CONTACT).
"""

import math as _math

import numpy as _np

from railadhesion._labelled import labelled as _labelled

__version__ = "0.1.0"


@_labelled(units="1")
def adhesion(fx, fy, normal_force):
    """Adhesion coefficient |T|/Q = sqrt(Fx^2 + Fy^2)/Q (dimensionless, >= 0).

    Parameters
    ----------
    fx, fy : array_like
        Tangential forces [N].
    normal_force : array_like
        Normal force Q [N], > 0.

    Examples
    --------
    >>> float(adhesion(3.0, 4.0, 20.0))
    0.25
    """
    if isinstance(fx, float) and isinstance(fy, float) and isinstance(normal_force, float):
        # scalar fast path (FMU steps, ODE right-hand sides): same result and error
        if 0.0 < normal_force < _math.inf:
            return _np.float64(_math.hypot(fx, fy) / normal_force)
    from railadhesion._validate import check_positive

    q = check_positive(normal_force, "normal_force")
    return _np.hypot(fx, fy) / q


# The public API at the top level (imported after ``adhesion``, which the models use).
from railadhesion.contact import (  # noqa: E402
    contact_semi_axes,
    fastsim,
    hertz_3d,
    kalker_coefficients,
    line_contact,
    linear_creep_forces,
)
from railadhesion.models import (  # noqa: E402
    Polach,
    PolachParameters,
    Wilac,
    WilacParameters,
    carter,
    default_wilac_parameters,
    elastic_foundation,
    fletcher,
    fletcher_condition,
    polach_forces,
    polach_parameters,
    wilac_forces,
    wilac_weights,
)

__all__ = [
    "Polach",
    "PolachParameters",
    "Wilac",
    "WilacParameters",
    "adhesion",
    "carter",
    "contact_semi_axes",
    "default_wilac_parameters",
    "elastic_foundation",
    "fastsim",
    "fletcher",
    "fletcher_condition",
    "hertz_3d",
    "kalker_coefficients",
    "line_contact",
    "linear_creep_forces",
    "polach_forces",
    "polach_parameters",
    "wilac_forces",
    "wilac_weights",
]
