"""The adhesion (traction) coefficient: the tangential force over the normal force.

Ground floor of the models: every creep-force model, the export tables and the CLI call
:func:`adhesion`; it is re-exported as ``railadhesion.adhesion``.
"""

from __future__ import annotations

import math

import numpy as np

from railadhesion._labelled import labelled
from railadhesion._validate import check_positive

__all__ = ["adhesion"]


@labelled(units="1")
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
        if 0.0 < normal_force < math.inf:
            return np.float64(math.hypot(fx, fy) / normal_force)
    q = check_positive(normal_force, "normal_force")
    return np.hypot(fx, fy) / q
