"""Friction laws of the contact models: the coefficient of friction falling with the slip
velocity, shared by Polach's model, Kalker's exact theory and its table.

Polach (2005, section 2) and CONTACT (its exponential law) let the coefficient of friction
fall from mu0 at zero slip velocity towards A mu0 at large slip velocity w [m/s]:

    mu(w) = mu0 [(1 - A) exp(-B w) + A],  A = mu_inf/mu0 >= 0,  B >= 0 [s/m].

References
----------
O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit, Wear
258, 2005, 992-1000.
E. A. H. Vollebregt, CONTACT user guide, friction law L = 4 and 5 (Apache-2.0).
"""

from __future__ import annotations

from railadhesion.numerics import exp, jitable

__all__ = ["falling_friction_factor", "falling_friction_slope"]


@jitable
def falling_friction_factor(slip_velocity, ratio, decay):
    """mu(w)/mu0 = (1 - A) exp(-B w) + A of the falling friction law (module docstring), with
    ``ratio`` = A and ``decay`` = B [s/m]; exactly 1.0 for constant friction (B = 0 or
    A = 1), where the formula could differ from 1 by an ulp.

    A plain function compiled where compiled code calls it
    (:func:`railadhesion.numerics.jitable`).
    """
    factor = (1.0 - ratio) * exp(-decay * slip_velocity) + ratio
    return 1.0 if (decay == 0.0) | (ratio == 1.0) else factor


@jitable
def falling_friction_slope(slip_velocity, ratio, decay):
    """d(mu/mu0)/dw = -(1 - A) B exp(-B w) [s/m] of :func:`falling_friction_factor` (the
    derivative of the same law, for Newton iterations); exactly 0.0 for constant friction."""
    slope = -(1.0 - ratio) * decay * exp(-decay * slip_velocity)
    return 0.0 if (decay == 0.0) | (ratio == 1.0) else slope
