"""Two-dimensional (line contact, twin-disc) creep models: Carter, elastic foundation, Fletcher.

All three models describe a line contact of half-width ``a`` (along the rolling direction x)
between two cylinders of reduced radius ``R`` (1/R = 1/R1 + 1/R2) carrying a normal load ``P``
per unit length, rolling with a longitudinal creep ratio ``xi`` and a constant friction
coefficient ``mu``. They return the tangential force per unit length and its split into the
part carried by the stick (adhesion) zone at the leading edge and the part carried by the slip
zone at the trailing edge.

Sign convention (``docs/CONVENTIONS.md``): ``creep`` may be signed, ``xi = (V - omega R)/V``
(braking positive); the returned traction is the force *exerted by the rail (disc 1) on the
wheel (disc 2)* and opposes the creep, so it has the sign of ``-xi``. The adhesion coefficient
is ``|traction| / normal_load``.

Models
------
- :func:`carter`: Carter's (1926) half-space solution, closed form.
- :func:`elastic_foundation`: Johnson's elastic-foundation (Winkler) model, as written by
  Fletcher (2013), eqs. (2)-(12), with ``k_a = k_s = 1``.
- :func:`fletcher`: Fletcher's (2013) extension with reduction factors ``k_a`` (stick zone)
  and ``k_s`` (slip zone).

Fletcher's twin-disc test conditions (his Tables 1 and 2) are available through
:func:`fletcher_condition` and :data:`FLETCHER_CONDITIONS`.

References
----------
.. [1] F. W. Carter, "On the action of a locomotive driving wheel", Proc. R. Soc. Lond. A
   112 (1926) 151-157.
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, chapter 8
   (rolling contact; Carter's solution and the elastic-foundation model), cited by [3] as
   its ref. 5.
.. [3] D. I. Fletcher, "A new two-dimensional model of rolling-sliding contact creep curves
   for a range of lubrication types", Proc. IMechE Part J: J. Engineering Tribology 227(6)
   (2013) 529-537, doi:10.1177/1350650112465694.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from importlib import resources
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from railadhesion._labelled import TWOD_UNITS, labelled
from railadhesion._validate import (
    check_finite,
    check_nonnegative,
    check_positive,
)
from railadhesion.numerics import flatten, jitable, kernel
from railadhesion.plausibility import input_checker

__all__ = [
    "TwoDTraction",
    "carter",
    "carter_law",
    "fletcher_curve",
    "fletcher_law",
    "elastic_foundation",
    "fletcher",
    "creep_from_surface_speeds",
    "FletcherCondition",
    "FLETCHER_CONDITIONS",
    "fletcher_condition",
    "FLETCHER_DISC_DIAMETER",
    "FLETCHER_REDUCED_RADIUS",
    "FLETCHER_YOUNG",
    "FLETCHER_POISSON",
]


class TwoDTraction(NamedTuple):
    """Result of a 2D creep-force model (all per unit length of the line contact).

    Attributes
    ----------
    traction : ndarray
        Total tangential force per unit length Q [N/m], exerted by the rail on the wheel; it
        opposes the creep (sign of ``-creep``). ``traction == stick + slip``.
    stick : ndarray
        Part of ``traction`` carried by the stick (adhesion) zone, Q_A [N/m], same sign.
    slip : ndarray
        Part of ``traction`` carried by the slip zone, Q_S [N/m], same sign.
    stick_half_width : ndarray
        Half-width of the stick zone [m] (``a'`` in Carter's notation, ``c`` in Fletcher's);
        equal to ``half_width`` at zero creep and 0 at full slip.
    """

    traction: np.ndarray
    stick: np.ndarray
    slip: np.ndarray
    stick_half_width: np.ndarray


@jitable
def _ratio_or_inf(num, den):
    """num/den for num, den >= 0: 0 where num == 0, inf where only den == 0."""
    if num == 0.0:
        return 0.0
    return num / den if den > 0.0 else math.inf


@jitable
def _sign(x):
    """The sign of x: -1, 1, or 0 for zero (as NumPy's)."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@jitable
def carter_law(creep, normal_load, half_width, radius, mu):
    """Carter's traction, its stick and slip parts [N/m] and the stick half-width [m] of one
    line contact (Carter 1926; Johnson 1985, chapter 8; the formulas in :func:`carter`,
    Notes): (traction, stick, slip, stick_half_width)."""
    kappa = min(_ratio_or_inf(abs(creep) * radius, mu * half_width), 1.0)
    total = 2.0 * kappa - kappa * kappa
    s = 2.0 * kappa - 1.0
    slip_frac = (math.asin(s) + s * math.sqrt(1.0 - s * s) + 0.5 * math.pi) / math.pi
    scale = _sign(-creep) * mu * normal_load
    traction = scale * total
    slip = scale * slip_frac
    return traction, traction - slip, slip, half_width * (1.0 - kappa)


@jitable
def fletcher_law(creep, normal_load, half_width, radius, mu, k_a, k_s):
    """Fletcher's (2013) traction, its stick part Q_A and slip part Q_S [N/m] and the stick
    half-width c [m] of one line contact, eqs. (8)-(12) (:func:`fletcher`, Notes):
    (traction, stick, slip, stick_half_width)."""
    mag = abs(creep)
    # eq. (8): c = max(a - 2 k_a xi R / (3 k_s mu), 0)
    c = max(half_width - _ratio_or_inf(2.0 * k_a * mag * radius, 3.0 * k_s * mu), 0.0)
    u = c / half_width
    # eq. (9): Q_A / P = 2 k_a c^2 xi R / a^3
    stick_frac = 2.0 * k_a * u * u * mag * radius / half_width
    # eq. (11): Q_S / P = 3/2 mu k_s (a - c)/a - 1/4 mu k_s (a^3 - (2c - a)^3)/a^3
    w = 2.0 * u - 1.0
    slip_frac = mu * k_s * (1.5 * (1.0 - u) - 0.25 * (1.0 - w * w * w))
    scale = _sign(-creep) * normal_load
    stick = scale * stick_frac
    slip = scale * slip_frac
    return stick + slip, stick, slip, c  # eq. (12)


@jitable
def fletcher_curve(creep, slope, inverse_mu):
    """Fletcher's (2013) 2D creep curve with k_s = 1 and its partial derivatives.

    ``creep`` >= 0 is the creep magnitude xi [-], ``slope`` > 0 the initial slope
    d(Q/P)/d xi = 2 k_a R / a [-], ``inverse_mu`` >= 0 the inverse 1/mu of the friction
    coefficient (the saturation level of the curve); 0 gives the limit mu -> inf, the straight
    line ``slope * creep``. Returns ``(Q/P, d/d creep, d/d slope, d/d inverse_mu)``.

    Fletcher's eqs. (8)-(12) (Proc. IMechE Part J 227(6) (2013) 529-537) reduce to
    ``Q/P = mu (1 - (c/a)**3)`` with ``c/a = max(1 - x/mu, 0)`` and ``x = 2 k_a xi R/(3 a)
    = slope * xi / 3`` (:func:`railadhesion.models.twod.fletcher`, its Notes). Written with
    u = 1 - x q (q = 1/mu): ``Q/P = x (3 - 3 x q + x**2 q**2)`` while u > 0 (finite at q = 0),
    ``1/q`` at and beyond full slip (u <= 0); d/d xi = slope u**2, d/d slope = xi u**2,
    d/d q = -x**2 (3 - 2 x q) before full slip, 0, 0, -1/q**2 beyond.
    """
    x = slope * creep / 3.0
    u = 1.0 - x * inverse_mu
    if u > 0.0:
        uu = u * u
        return (x * (3.0 - 3.0 * x * inverse_mu + x * x * inverse_mu * inverse_mu),
                slope * uu, creep * uu, -x * x * (3.0 - 2.0 * x * inverse_mu))
    return 1.0 / inverse_mu, 0.0, 0.0, -1.0 / (inverse_mu * inverse_mu)


@kernel(nogil=True)
def _twod_into(fletcher, xi, load, a, r, m, ka, ks, out):
    """:func:`fletcher_law` (``fletcher``) or :func:`carter_law` of arrays of length n or 1
    into out (4, n)."""
    for k in range(out.shape[1]):
        x, p, h, rr, mu = (xi[k if xi.size > 1 else 0], load[k if load.size > 1 else 0],
                           a[k if a.size > 1 else 0], r[k if r.size > 1 else 0],
                           m[k if m.size > 1 else 0])  # fmt: skip
        if fletcher:
            res = fletcher_law(x, p, h, rr, mu, ka[k if ka.size > 1 else 0],
                               ks[k if ks.size > 1 else 0])  # fmt: skip
        else:
            res = carter_law(x, p, h, rr, mu)
        out[0, k], out[1, k], out[2, k], out[3, k] = res


def _evaluate(fletcher, creep, normal_load, half_width, radius, mu, k_a, k_s, *,
              plausible=True) -> TwoDTraction:  # fmt: skip
    """Validate the inputs (errors name them), then the compiled law over their broadcast;
    ``plausible``: warn for implausible inputs too (a caller that checked them once, a fit's
    optimiser, passes False)."""
    inputs = [
        check_finite(creep, "creep"),
        check_nonnegative(normal_load, "normal_load"),
        check_positive(half_width, "half_width"),
        check_positive(radius, "radius"),
        check_nonnegative(mu, "mu"),
        check_positive(k_a, "k_a"),
        check_positive(k_s, "k_s"),
    ]
    shape, n, flat = flatten(inputs)
    out = np.empty((4, n))
    _twod_into(fletcher, *flat, out)
    if plausible:  # implausible inputs warn (docs/checks.md)
        _PLAUSIBLE((inputs[0], inputs[2], inputs[3]))
    return TwoDTraction(*(x.reshape(shape)[()] for x in out))


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep", "half_width", "radius"))


@labelled(units=TWOD_UNITS)
def carter(creep, normal_load, half_width, radius, mu) -> TwoDTraction:
    """Carter's (1926) 2D rolling-contact creep force, closed form.

    Parameters
    ----------
    creep : array_like
        Longitudinal creep ratio xi [-], signed (``(V - omega R)/V``, braking positive), finite.
    normal_load : array_like
        Normal load per unit length P [N/m], >= 0.
    half_width : array_like
        Hertzian contact half-width a [m], > 0 (``a = sqrt(4 P R / (pi E*))``).
    radius : array_like
        Reduced radius of the two cylinders R [m], > 0 (1/R = 1/R1 + 1/R2; for a wheel on a
        straight rail, the wheel radius).
    mu : array_like
        Coefficient of friction [-], >= 0.

    Returns
    -------
    TwoDTraction
        ``traction`` Q [N/m] (opposes the creep), its ``stick`` and ``slip`` parts [N/m] and the
        ``stick_half_width`` a' [m]. All broadcast to the common shape of the inputs.

    Notes
    -----
    With the normalised creep kappa = |xi| R / (mu a), Carter's solution (Carter 1926;
    Johnson 1985, chapter 8) is::

        |Q| / (mu P) = 2 kappa - kappa**2   for kappa <= 1, else 1
        a' / a       = 1 - kappa            (stick zone at the leading edge)

    The traction is the full-sliding Hertz traction ``mu p(x)`` minus a smaller ellipse of
    half-width a' centred in the stick zone, so the slip zone, ``-a <= x <= a - 2a'``, carries
    ``mu`` times the Hertz pressure there. With ``s = 2 kappa - 1`` (derived here by integrating
    the Hertz pressure over the slip zone)::

        |Q_S| / (mu P) = (arcsin(s) + s sqrt(1 - s**2) + pi/2) / pi
        |Q_A| / (mu P) = 2 kappa - kappa**2 - |Q_S| / (mu P)

    The initial slope is d|Q|/d|xi| = 2 P R / a, the same as the elastic-foundation model.
    For ``mu = 0`` the traction is zero.

    References
    ----------
    F. W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157; K. L. Johnson, *Contact
    Mechanics* (1985), chapter 8.

    Examples
    --------
    CONTACT's ``carter2d`` example: R = 500 mm, a = 1 mm, mu = 0.3, xi = -0.024 % (traction):

    >>> res = carter(-2.4e-4, normal_load=178.9e3, half_width=1e-3, radius=0.5, mu=0.3)
    >>> round(float(res.traction / (0.3 * 178.9e3)), 4)
    0.64
    >>> round(float(res.stick_half_width * 1e3), 4)
    0.6
    """
    return _evaluate(False, creep, normal_load, half_width, radius, mu, 1.0, 1.0)


@labelled(units=TWOD_UNITS)
def fletcher(creep, normal_load, half_width, radius, mu, k_a=1.0, k_s=1.0) -> TwoDTraction:
    """Fletcher's (2013) 2D elastic-foundation creep force with reduction factors k_a, k_s.

    Parameters
    ----------
    creep : array_like
        Longitudinal creep ratio xi [-], signed (``(V - omega R)/V``, braking positive), finite.
        Fletcher's eq. (7) defines xi = (V1 - V2)/V with V the rolling speed; to first order
        this is the same quantity (see :func:`creep_from_surface_speeds`).
    normal_load : array_like
        Normal load per unit length P [N/m], >= 0.
    half_width : array_like
        Contact half-width a [m], > 0.
    radius : array_like
        Reduced radius R [m], > 0 (1/R = 1/R1 + 1/R2; 11.75 mm for Fletcher's 47 mm discs).
    mu : array_like
        Coefficient of friction [-], >= 0 (the saturation adhesion coefficient is ``k_s mu``).
    k_a : array_like, optional
        Reduction factor of the tangential stiffness in the stick (adhesion) zone [-], > 0.
        Fletcher intends values in (0, 1]; values > 1 are accepted (e.g. during a fit).
    k_s : array_like, optional
        Reduction factor of the friction in the slip zone [-], > 0 (intended in (0, 1]).

    Returns
    -------
    TwoDTraction
        ``traction`` Q [N/m] (opposes the creep), its ``stick`` part Q_A and ``slip`` part Q_S
        [N/m] (same sign, ``stick + slip == traction``), and the stick-zone half-width c [m].

    Notes
    -----
    Elastic (Winkler) foundation of normal modulus K_p and tangential modulus K_q = (2/3) K_p
    (Fletcher 2013, eqs. (2), (3), (5), (6); Johnson 1985). With xi taken as ``|creep|``:

    - eq. (8), stick-zone half-width: ``c = max(a - 2 k_a xi R / (3 k_s mu), 0)``;
    - eq. (9), stick part: ``Q_A / P = 2 k_a c**2 xi R / a**3``;
    - eq. (11), slip part:
      ``Q_S / P = (3/2) mu k_s (a - c)/a - (1/4) mu k_s (a**3 - (2c - a)**3)/a**3``;
    - eq. (12): ``Q / P = Q_A / P + Q_S / P``.

    These simplify (derived here, checked in the tests) to ``Q / P = k_s mu (1 - (c/a)**3)``:
    the elastic-foundation curve with friction ``k_s mu`` evaluated at the creep ``k_a xi``.
    Full slip (c = 0) gives ``Q / P = k_s mu``; the initial slope is
    ``d(Q/P)/d xi = 2 k_a R / a``, independent of mu and k_s. The normal load P enters only as
    a factor (eq. (10), ``P = 2 K_p a**3 / (3 h R)``, fixes the foundation stiffness).
    For ``mu = 0`` the traction is zero.

    References
    ----------
    D. I. Fletcher, Proc. IMechE Part J 227(6) (2013) 529-537, eqs. (2)-(12);
    K. L. Johnson, *Contact Mechanics* (1985).

    Examples
    --------
    Fletcher's oil-lubricated test O1 (mu = 0.055, k_a = 0.193, a = 0.204 mm, R = 11.75 mm)
    at 0.2 % creep, as the adhesion coefficient Q/P:

    >>> res = fletcher(0.002, 1.0, 0.204e-3, 11.75e-3, 0.055, k_a=0.193)
    >>> round(float(abs(res.traction)), 4), round(float(res.stick_half_width * 1e3), 4)
    (0.0336, 0.149)
    >>> round(float(res.stick + res.slip - res.traction), 12)
    0.0
    """
    return _evaluate(True, creep, normal_load, half_width, radius, mu, k_a, k_s)


def fletcher_quiet(creep, normal_load, half_width, radius, mu, k_a=1.0, k_s=1.0) -> TwoDTraction:
    """:func:`fletcher` (Fletcher 2013, eqs. (8)-(12), the same errors for impossible inputs)
    without its plausibility warnings, unlabelled: for a caller that checked its inputs once
    (:func:`railadhesion.calibration.fitting.fit_fletcher`, whose optimiser evaluates it
    hundreds of times)."""
    return _evaluate(True, creep, normal_load, half_width, radius, mu, k_a, k_s,
                     plausible=False)  # fmt: skip


@labelled(units=TWOD_UNITS)
def elastic_foundation(creep, normal_load, half_width, radius, mu) -> TwoDTraction:
    """Johnson's 2D elastic-foundation creep force (Fletcher 2013 with ``k_a = k_s = 1``).

    Parameters
    ----------
    creep : array_like
        Longitudinal creep ratio xi [-], signed (braking positive), finite.
    normal_load : array_like
        Normal load per unit length P [N/m], >= 0.
    half_width : array_like
        Contact half-width a [m], > 0.
    radius : array_like
        Reduced radius R [m], > 0.
    mu : array_like
        Coefficient of friction [-], >= 0.

    Returns
    -------
    TwoDTraction
        As :func:`fletcher`.

    Notes
    -----
    Fletcher (2013) eqs. (8)-(12) with k_a = k_s = 1. In closed form, with
    ``c/a = max(1 - 2 |xi| R / (3 mu a), 0)``: ``|Q| / (mu P) = 1 - (c/a)**3``. Carter's model
    (:func:`carter`) has the same initial slope 2 P R / a and the same saturation mu P.

    References
    ----------
    K. L. Johnson, *Contact Mechanics* (1985); D. I. Fletcher, Proc. IMechE Part J 227(6)
    (2013) 529-537, eqs. (8)-(12).

    Examples
    --------
    Half-way to full slip (|xi| R / (mu a) = 0.75, so c = a/2): Q/(mu P) = 1 - 1/8:

    >>> res = elastic_foundation(0.75 * 0.3 * 1e-3 / 0.5, 1.0, 1e-3, 0.5, 0.3)
    >>> round(float(-res.traction / 0.3), 4)
    0.875
    """
    return fletcher(creep, normal_load, half_width, radius, mu, 1.0, 1.0)


@labelled(units="1")
def creep_from_surface_speeds(v1, v2):
    """Creep ratio from two surface speeds, Fletcher's (2013) eq. (1), as a fraction.

    Parameters
    ----------
    v1 : array_like
        Surface speed of the rail (rail disc) [m/s], >= 0 (Fletcher's R_rail S_rail).
    v2 : array_like
        Surface speed of the wheel (wheel disc) [m/s], >= 0 (R_wheel S_wheel).
        ``v1 + v2`` must be > 0.

    Returns
    -------
    ndarray
        ``2 (v1 - v2) / (v1 + v2)`` [-]: the speed difference over the mean speed
        (0.01 = 1 %).

    Notes
    -----
    Fletcher's eq. (1) gives creep in percent, ``200 (v1 - v2) / (v1 + v2)``; this function
    returns it divided by 100. A driving wheel (v2 > v1) gives negative creep, as in our
    convention (``docs/CONVENTIONS.md``: xi = (V - omega R)/V, traction negative). With
    V = v1 the rolling speed and omega R = v2, our xi = (v1 - v2)/v1 and Fletcher's
    xi_F = (v1 - v2)/((v1 + v2)/2) are related by ``xi = 2 xi_F / (2 + xi_F)``, i.e. they
    agree to first order (relative difference xi/2: 0.5 % at 1 % creep).

    References
    ----------
    D. I. Fletcher, Proc. IMechE Part J 227(6) (2013) 529-537, eq. (1).

    Examples
    --------
    >>> round(float(creep_from_surface_speeds(1.0, 1.01)), 6)
    -0.00995
    """
    s1 = check_nonnegative(v1, "v1")
    s2 = check_nonnegative(v2, "v2")
    total = s1 + s2
    if not np.all(total > 0):
        raise ValueError("v1 + v2 must be in (0, inf): at least one surface must move")
    return np.asarray(2.0 * (s1 - s2) / total)[()]


# ---------------------------------------------------------------------------------------------
# Fletcher's twin-disc test conditions (his Tables 1 and 2)
# ---------------------------------------------------------------------------------------------

#: Disc diameter of Fletcher's SUROS twin-disc tests [m] (Fletcher 2013, section 2).
FLETCHER_DISC_DIAMETER = 0.047
#: Reduced radius of two 47 mm discs, 1/R = 2/(23.5 mm) [m].
FLETCHER_REDUCED_RADIUS = FLETCHER_DISC_DIAMETER / 4.0
#: Young's modulus assumed for the rail and wheel steel discs [Pa] (MODELS.md section 1; it
#: reproduces the half-widths 0.163/0.204/0.265 mm that Fletcher states).
FLETCHER_YOUNG = 210e9
#: Poisson's ratio assumed for the disc steels [-].
FLETCHER_POISSON = 0.3


@dataclass(frozen=True)
class FletcherCondition:
    """One of Fletcher's (2013) twin-disc test conditions (Tables 1 and 2).

    Attributes
    ----------
    test_code : str
        Fletcher's test code, e.g. ``"W1"``, ``"D3"``, ``"O1"``.
    lubricant : str
        Contact condition (Table 1, "Lubricant type").
    max_pressure : float
        Maximum Hertzian pressure p0 [Pa].
    mu : float
        Friction coefficient, the saturation adhesion coefficient at full slip [-] (Table 1).
    creep_coefficient : float
        Measured initial gradient of the adhesion coefficient versus creep, as printed in
        Table 1. The numbers match d(Q/P)/d(creep in %) (per percent creep): see Notes.
    k_a : float
        Stick-zone reduction factor fitted by Fletcher with ``k_s = 1`` (Table 2) [-].
    k_s : float
        Slip-zone reduction factor, 1 in all of Fletcher's fits [-].
    radius : float
        Reduced radius of the discs R [m] (11.75 mm).
    half_width : float
        Hertz line-contact half-width a = 2 p0 R / E* [m], E* = E / (2 (1 - nu**2)).
    normal_load : float
        Normal load per unit length P = pi a p0 / 2 [N/m].

    Notes
    -----
    Table 1's creep coefficient against the model's initial gradient: the elastic-foundation
    model (k_a = 1) has d(Q/P)/d xi = 2 R / a, i.e. 1.154 per percent creep at 1000 MPa. The
    ratio (creep coefficient) / (2 R / a / 100) equals k_a within a factor 0.73 to 1.40 for
    all ten tests (Pearson correlation 0.98): k_a is close to, but not identical with, the
    measured initial gradient divided by the elastic-foundation gradient, because Fletcher
    fitted k_a to the whole 0-1 % curve.

    Examples
    --------
    >>> cond = fletcher_condition("o1")
    >>> cond.lubricant, round(cond.half_width * 1e3, 3), round(float(cond.adhesion(0.01)), 4)
    ('Oil', 0.204, 0.055)
    """

    test_code: str
    lubricant: str
    max_pressure: float
    mu: float
    creep_coefficient: float
    k_a: float
    k_s: float = 1.0
    radius: float = FLETCHER_REDUCED_RADIUS
    half_width: float = math.nan
    normal_load: float = math.nan
    source: str = "Fletcher 2013, Proc. IMechE Part J 227(6) 529-537, Tables 1 and 2"

    def traction(self, creep) -> TwoDTraction:
        """Fletcher's model (:func:`fletcher`) for this condition; creep xi [-], signed."""
        return fletcher(
            creep, self.normal_load, self.half_width, self.radius, self.mu, self.k_a, self.k_s
        )

    @labelled(units="1")
    def adhesion(self, creep):
        """Adhesion coefficient |Q|/P [-] of Fletcher's fitted model at creep xi [-] (fraction).

        Examples
        --------
        >>> round(float(fletcher_condition("D3").adhesion(-0.002)), 4)
        0.1672
        """
        res = self.traction(creep)
        return np.abs(res.traction) / self.normal_load

    @labelled(units="1")
    def elastic_foundation_adhesion(self, creep):
        """Adhesion coefficient |Q|/P [-] of the unmodified model (k_a = k_s = 1), Fig. 4/5's
        "original model", at creep xi [-]."""
        res = elastic_foundation(creep, self.normal_load, self.half_width, self.radius, self.mu)
        return np.abs(res.traction) / self.normal_load

    @property
    def initial_gradient(self) -> float:
        """Initial slope of the fitted model d(Q/P)/d xi = 2 k_a R / a [-] (per unit creep)."""
        return 2.0 * self.k_a * self.radius / self.half_width


def _hertz_line_half_width(max_pressure: float, radius: float) -> float:
    """Line-contact half-width a = 2 p0 R / E* for equal steels (MODELS.md section 1, 2D)."""
    e_star = FLETCHER_YOUNG / (2.0 * (1.0 - FLETCHER_POISSON**2))
    return 2.0 * max_pressure * radius / e_star


def _load_conditions() -> MappingProxyType:
    """Read ``data/fletcher2013_tables.csv`` (package data) once."""
    text = (
        resources.files("railadhesion")
        .joinpath("data/fletcher2013_tables.csv")
        .read_text(encoding="utf-8")
    )
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    table: dict[str, FletcherCondition] = {}
    for row in csv.DictReader(lines):
        p0 = float(row["p0_MPa"]) * 1e6
        a = _hertz_line_half_width(p0, FLETCHER_REDUCED_RADIUS)
        code = row["test_code"].strip()
        table[code] = FletcherCondition(
            test_code=code,
            lubricant=row["lubricant"].strip(),
            max_pressure=p0,
            mu=float(row["mu"]),
            creep_coefficient=float(row["creep_coefficient"]),
            k_a=float(row["ka"]),
            k_s=1.0,
            radius=FLETCHER_REDUCED_RADIUS,
            half_width=a,
            normal_load=0.5 * math.pi * a * p0,
        )
    return MappingProxyType(table)


#: Fletcher's ten test conditions by test code (read-only mapping of :class:`FletcherCondition`).
FLETCHER_CONDITIONS = _load_conditions()


def fletcher_condition(test_code: str) -> FletcherCondition:
    """Fletcher's (2013) twin-disc test condition by its code (case-insensitive).

    Parameters
    ----------
    test_code : str
        One of ``W1, SL1, SL2, SL3, SW1, O1, TG1, CG1, L1, D3`` (Fletcher 2013, Table 1).

    Returns
    -------
    FletcherCondition
        Friction coefficient, creep coefficient (Table 1), k_a (Table 2, k_s = 1), and the
        derived Hertz half-width and load per unit length.

    Raises
    ------
    ValueError
        If the code is unknown; the message lists the valid codes.

    Examples
    --------
    >>> cond = fletcher_condition("SL2")
    >>> cond.mu, cond.k_a, round(cond.half_width * 1e3, 3)
    (0.16, 0.306, 0.163)
    """
    key = test_code.strip().upper() if isinstance(test_code, str) else None
    if key not in FLETCHER_CONDITIONS:
        valid = ", ".join(FLETCHER_CONDITIONS)
        raise ValueError(f"test_code must be one of {valid} (Fletcher 2013), got {test_code!r}")
    return FLETCHER_CONDITIONS[key]
