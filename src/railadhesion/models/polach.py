"""Polach's creep-force model (Polach 1999, 2005), in Kalker's sign convention.

Polach's method gives the tangential wheel-rail forces in closed form from the creepages, the
Hertzian contact ellipse and a friction coefficient. The 2005 extension adds a friction
coefficient falling with slip velocity and two factors reducing the creep stiffness in the
areas of adhesion (``k_A``) and slip (``k_S``); with ``k_A = k_S = 1`` and ``A = 1`` (or
``B = 0``) it is the original 1999 model.

Sign convention (``docs/CONVENTIONS.md``): the forces returned are exerted by the rail on the
wheel and oppose the creepages, as in Kalker's linear theory and CONTACT. Polach's papers
count forces positive along the creepages, so both of his components (spin term included) are
negated here.

References
----------
O. Polach, A fast wheel-rail forces calculation computer code, Vehicle System Dynamics 33
(Suppl.), 1999, 728-739.
O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit, Wear 258,
2005, 992-1000.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from railadhesion._labelled import labelled
from railadhesion._validate import (
    as_float_array,
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.contact.kalker import _AOB_MAX, _AOB_MIN, axis_ratio, kalker_coefficients
from railadhesion.models.parameters import PolachParameters, polach_parameters
from railadhesion.plausibility import input_checker

__all__ = ["Polach", "PolachContact", "polach_forces"]

_TWO_OVER_PI = 2.0 / math.pi
_PI_OVER_4 = math.pi / 4.0
# The gradient eps is clipped here: the term k eps / (1 + (k eps)^2) ~ 1/(k eps) it feeds is
# then below 1e-50 of mu*Q, and squaring it cannot overflow. The spin gradient eps_psi is not
# clipped: F_yS ~ |s_yC| / (1 + eps_psi^2)^2 with eps_psi proportional to |s_yC|, so a clipped
# eps_psi would let F_yS grow without bound at huge creepages; (1 + eps_psi^2) = inf gives 0.
_EPS_MAX = 1e50
_SCALAR_TYPES = (float, int, np.float64)
_INF = math.inf


@lru_cache(maxsize=4096)
def _kalker_scalar(a_over_b: float, poisson: float) -> tuple[float, float, float]:
    """C11, C22, C23 for scalar inputs, memoised (repeated geometries cost ~0.1 us)."""
    c = kalker_coefficients(a_over_b, poisson)
    return float(c.c11), float(c.c22), float(c.c23)


@labelled(units=("N", "N"))
def polach_forces(
    creep_long,
    creep_lat,
    spin,
    normal_force,
    speed,
    a,
    b,
    *,
    mu0,
    k_A=1.0,
    k_S=1.0,
    A=1.0,
    B=0.0,
    shear_modulus=8.2e10,
    poisson=0.28,
):
    """Tangential creep forces of Polach's model (1999, extended 2005), Kalker's signs.

    Parameters
    ----------
    creep_long : array_like
        Longitudinal creepage xi = (V - omega R)/V [-]; braking > 0, traction < 0. Finite.
    creep_lat : array_like
        Lateral creepage eta [-]. Finite.
    spin : array_like
        Spin creepage phi [rad/m]. Finite.
    normal_force : array_like
        Normal force Q [N], > 0.
    speed : array_like
        Rolling speed V [m/s], >= 0. Enters only through the slip velocity w = s_C V of the
        falling friction law.
    a : array_like
        Contact semi-axis **in the rolling direction** x [m], > 0 (whether or not it is the
        longer one).
    b : array_like
        Lateral contact semi-axis [m], > 0.
    mu0 : array_like
        Maximum friction coefficient mu0 [-], > 0.
    k_A : array_like, optional
        Stiffness reduction factor in the area of adhesion [-], in (0, 1] (Polach 2005:
        k_S <= k_A <= 1).
    k_S : array_like, optional
        Stiffness reduction factor in the area of slip [-], in (0, 1]. Polach recommends
        k_S <= k_A; k_S > k_A is accepted and evaluated as published (see Notes, Bounds).
    A : array_like, optional
        mu_inf/mu0 [-], >= 0. ``A = 1`` gives constant friction.
    B : array_like, optional
        Exponential friction decrease rate [s/m], >= 0. ``B = 0`` gives constant friction.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa], > 0.
    poisson : array_like, optional
        Combined Poisson's ratio nu [-], in [0, 0.5].

    All arguments broadcast against each other, the five model parameters included (so a
    model such as WILAC can pass one parameter set per contact).

    Returns
    -------
    fx, fy : numpy.float64 or ndarray
        Longitudinal and lateral forces exerted by the rail on the wheel [N] (they oppose the
        creepages: ``fx < 0`` in braking). Scalars for scalar input, else arrays of the
        broadcast shape. Zero creepage gives exactly zero force.

    Raises
    ------
    ValueError
        If an argument is not finite or outside its range; the message names it.

    Notes
    -----
    With s_x = xi, s_y = eta, psi = phi, s = sqrt(s_x^2 + s_y^2) (Polach 1999, 2005; the
    formulas below are those of Polach 2005, section 2, which restates the 1999 model):

    * spin-corrected lateral creepage: s_yC = s_y + psi a if abs(s_y + psi a) > abs(s_y), else
      s_y; s_C = sqrt(s_x^2 + s_yC^2);
    * friction falling with the slip velocity w = s_C V:
      mu = mu0 [(1 - A) exp(-B w) + A];
    * Kalker's coefficient in the creep direction c_jj = sqrt((C11 s_x/s)^2 + (C22 s_y/s)^2),
      contact stiffness C = (3/8)(G/a) c_jj and gradient of the tangential stress
      eps = (2/3) C pi a^2 b s_C / (Q mu) = pi G a b c_jj s_C / (4 Q mu);
    * force (2005 extension):
      F = (2 Q mu / pi) [k_A eps / (1 + (k_A eps)^2) + arctan(k_S eps)]
      (the 1999 model is k_A = k_S = 1; some public codes write ``1 + k_A eps^2``, wrongly);
    * spin: K_psi = 1 + 6.3 (1 - exp(-a/b)),
      eps_psi = (8/3) G b sqrt(ab) C23 abs(s_yC) / (K_psi Q mu),
      delta = (eps_psi^2 - 1)/(eps_psi^2 + 1),
      K_M = abs(eps_psi) (delta^3/3 - delta^2/2 + 1/6) - (1/3) sqrt((1 - delta^2)^3),
      F_yS = -(9/16) a Q mu K_M K_psi psi / s_C;
    * in Polach's signs F_x = F s_x/s_C, F_y = F s_y/s_C + F_yS; returned here:
      ``fx = -F s_x/s_C``, ``fy = -(F s_y/s_C + F_yS)``.

    C11, C22, C23 come from :func:`railadhesion.contact.kalker.kalker_coefficients` at a/b.

    Implementation: compiled kernels (:mod:`railadhesion.models.kernels`, numba, compiled on
    first use and cached on disk) evaluate the model, validating in the same pass; the
    Kalker lookup is done once per call when a/b and nu are constant. The NumPy reference
    (``_polach_reference`` for arrays, ``_polach_scalar`` for scalars) is the readable
    implementation the tests hold the kernels to (1e-12 relative); it also raises the errors
    naming the argument. For repeated calls on one contact see :class:`PolachContact`; from
    numba code, :func:`railadhesion.models.kernels.polach_scalar`.

    Implementation detail [derived here]: substituting delta, Polach's K_M simplifies
    exactly to K_M = -(2/3) eps_psi / (1 + eps_psi^2)^2, hence
    F_yS = G c^3 C23 psi (abs(s_yC) / s_C) / (1 + eps_psi^2)^2 with c = sqrt(ab). This form is
    evaluated (no cancellation at large eps_psi, no 0/0). At small pure spin it is exactly
    Kalker's linear term, so ``fy -> -G c^3 C23 phi``; likewise ``fx -> -G c^2 C11 xi`` at small
    xi when k_A = k_S = 1. In general the initial slope is (k_A + k_S)/2 times Kalker's.

    **Which semi-axis is a.** In Polach's papers a is the half-axis of the contact ellipse in
    the longitudinal (rolling) direction and b the lateral one (variable list of the FORTRAN
    code of Polach 1999: "semiaxis a of the contact ellipse (in longitudinal direction)");
    this is also our convention (``docs/CONVENTIONS.md``), so ``a`` is passed through as is.
    Some later papers (e.g. Trummer et al., WILAC) call a the "semi-major" axis; that is only
    true when the contact is longer in the rolling direction (a/b > 1), which is often not
    the case on wheel treads (CONTACT's Eurosprinter case has a/b = 0.5). The choice
    matters: eps is symmetric in a and b, but s_yC, K_psi, eps_psi, F_yS and the Kalker
    coefficients are not.

    Bounds: with k_S <= k_A the bracket of F is at most pi/2, so |F| <= mu Q <=
    mu0 Q max(1, A). With k_S > k_A (which Polach 2005 excludes, k_S <= k_A <= 1, but a
    fitted or regressed set may reach) the published model itself exceeds mu Q: the bracket
    reaches up to pi/2 + 1/2, so |F| <= (1 + 1/pi) mu Q (e.g. a/b = 0.5, k_A = 0.1, k_S = 1,
    pure longitudinal creep: |F|/(mu Q) = 1.19, 1.23, 1.09 at 1, 3, 10 % on the Eurosprinter
    contact at Q = 100 kN, mu = 0.3). This is returned as published, unchanged.

    **The spin cap.** When the spin opposes the lateral creepage on long contacts (a/b > 1),
    the spin term F_yS, which k_A and k_S do not reduce, can push |(fx, fy)| above mu Q (up
    to about 1.6 mu Q with k_A = 0.3, k_S = 0.1 at a/b = 5). A tangential force above the
    friction limit is not physical, so **where the spin term is non-zero this implementation
    caps |(fx, fy)| at max(mu Q, |F|)** (mu at the current slip velocity, F the force of the
    creepage part above), scaling both components: it removes only the overshoot the spin
    term adds. Without spin the cap never acts, whatever k_A and k_S.

    **Known limit with spin reinforcing the lateral creep.** When psi a has the sign of s_y,
    s_yC = s_y + psi a and F_yS is added along F_y, but Polach's F_yS falls with eps_psi like
    1/(1 + eps_psi^2)^2 while the exact theory keeps a spin contribution: the lateral force
    is then underestimated. On the Eurosprinter contact (a/b = 0.5, Q = 106.7 kN, mu = 0.33)
    at eta = 0.01, psi a = 0.01, Polach gives Fy = -0.51 mu Q where FASTSIM (40 x 40 strips)
    gives -0.83 mu Q with blended flexibilities (-0.72 mu Q with Kalker's original ones);
    without the spin both give -1.00 mu Q. Use FASTSIM or CONTACT where large spin matters.

    References
    ----------
    O. Polach, A fast wheel-rail forces calculation computer code, Vehicle System Dynamics 33
    (Suppl.), 1999, 728-739.
    O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit,
    Wear 258, 2005, 992-1000.

    Examples
    --------
    CONTACT's Eurosprinter case (a = 6.304 mm, b = 12.61 mm, Q = 106.7 kN, V = 10 m/s,
    G = 82 GPa, nu = 0.28), Coulomb friction 0.33, braking creepage 2 per mille:

    >>> fx, fy = polach_forces(2e-3, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3, mu0=0.33)
    >>> round(float(fx / (0.33 * 106.7e3)), 4), float(fy)
    (-0.8434, -0.0)

    Arrays and parameter arrays broadcast; the dry and wet sets of Polach (2005) at 5 %
    traction creepage:

    >>> import numpy as np
    >>> fx, fy = polach_forces(-0.05, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3,
    ...                        mu0=np.array([0.55, 0.3]), k_A=np.array([1.0, 0.3]),
    ...                        k_S=np.array([0.4, 0.1]), A=0.4, B=np.array([0.6, 0.2]))
    >>> np.round(fx / 106.7e3, 4)
    array([0.4416, 0.2465])
    """
    args = (
        creep_long, creep_lat, spin, normal_force, speed, a, b,
        mu0, k_A, k_S, A, B, shear_modulus, poisson,
    )  # fmt: skip
    scalars = _scalars(args)
    if scalars is None:
        out = _polach_array(*args)
        _PLAUSIBLE(args)  # implausible inputs warn (docs/checks.md); errors were raised above
        return out
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu = scalars
    fx, fy, bad = _kernels().polach_checked(
        sx, sy, psi, q, v, a, b, g, nu, 0.0, 0.0, 0.0, k_a, k_s, mu0, big_a, big_b
    )
    if bad >= 0:
        _polach_scalar(*scalars)  # the reference scalar path raises the error naming it
        raise AssertionError("polach kernel flagged an input the reference accepts")
    _PLAUSIBLE(scalars)  # implausible inputs warn (docs/checks.md)
    return np.float64(fx), np.float64(fy)


def _scalars(values) -> tuple | list | None:
    """``values`` for the scalar fast path, or ``None`` if any of them is not a real scalar.

    Python and NumPy scalars and 0-d arrays qualify (no array work is then needed); ``float``
    and ``numpy.float64`` are passed through, ints, other NumPy scalars and 0-d arrays become
    floats (so that the compiled kernels see one signature).
    """
    for v in values:  # the common case first: Python floats only
        if type(v) is not float:
            break
    else:
        return values
    scalars = []
    for v in values:
        t = type(v)
        if t is float or t is np.float64:
            scalars.append(v)
        elif t is int:
            scalars.append(float(v))
        elif isinstance(v, np.generic | np.ndarray) and v.ndim == 0 and v.dtype.kind in "fiu":
            scalars.append(float(v))
        else:
            return None
    return scalars


def _bad(name: str, rng: str, value) -> ValueError:
    return ValueError(f"{name} must be in {rng}, got {float(value)!r}")


def _polach_scalar(
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu, check_contact=True
):
    """Scalar path of :func:`polach_forces` with the ``math`` module (a few microseconds).

    ``check_contact=False`` checks only the five model parameters: for a caller (WILAC) that
    evaluates several parameter sets on one contact whose other inputs an earlier call with
    ``check_contact=True`` has already validated.
    """
    isf = math.isfinite
    if check_contact:
        for name, val in (("creep_long", sx), ("creep_lat", sy), ("spin", psi)):
            if not isf(val):
                raise ValueError(f"{name} must be finite (no NaN or inf), got {float(val)!r}")
        positive = (
            ("normal_force", q), ("a", a), ("b", b), ("mu0", mu0), ("shear_modulus", g),
        )  # fmt: skip
        nonnegative = (("speed", v), ("A", big_a), ("B", big_b))
    else:
        positive = (("mu0", mu0),)
        nonnegative = (("A", big_a), ("B", big_b))
    for name, val in (("k_A", k_a), ("k_S", k_s)):
        if not 0.0 < val <= 1.0:  # NaN fails too
            raise _bad(name, "(0.0, 1.0]", val)
    for name, val in positive:
        if not (val > 0 and isf(val)):
            raise _bad(name, "(0, inf)", val)
    for name, val in nonnegative:
        if not (val >= 0 and isf(val)):
            raise _bad(name, "[0, inf)", val)
    if check_contact and not 0.0 <= nu <= 0.5:
        raise _bad("poisson", "[0.0, 0.5]", nu)

    a_over_b = a / b
    if not _AOB_MIN <= a_over_b <= _AOB_MAX:  # kalker_coefficients' range; message names a, b
        axis_ratio(np.float64(a), np.float64(b))
    c11, c22, c23 = _kalker_scalar(a_over_b, float(nu))
    syc = sy + psi * a
    if not abs(syc) > abs(sy):
        syc = sy
    sc = math.hypot(sx, syc)
    if sc == 0.0:  # then psi == 0 too: no creepage, no force
        return np.float64(0.0), np.float64(0.0)
    s = math.hypot(sx, sy)
    cjj = math.hypot(c11 * sx, c22 * sy) / s if s > 0.0 else c22
    mu = mu0 * ((1.0 - big_a) * math.exp(-big_b * sc * v) + big_a)
    qmu = q * mu
    if qmu == 0.0:  # A = 0 and exp(-B w) underflowed: no friction left, no force
        return np.float64(0.0), np.float64(0.0)
    eps = min(_PI_OVER_4 * g * a * b * cjj * sc / qmu, _EPS_MAX)
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + math.atan(k_s * eps)) / sc
    k_psi = 1.0 + 6.3 * (1.0 - math.exp(-a_over_b))
    gc3c23 = g * a * b * math.sqrt(a * b) * c23
    eps_psi = 8.0 / 3.0 * gc3c23 / a * abs(syc) / (k_psi * qmu)
    e2 = 1.0 + eps_psi * eps_psi  # may be inf (float overflow): then F_yS = 0
    # |psi|/s_C <= 2/a and |s_yC|/e2 is bounded: this order cannot overflow (a product
    # psi*|s_yC| first would, for huge creepages, and give inf*0 = NaN after the cap)
    fys = gc3c23 * (psi / sc) * (abs(syc) / e2) / e2
    fx, fy = -f_over_sc * sx, -(f_over_sc * sy + fys)
    if fys != 0.0:  # spin cap (see Notes): removes only the overshoot the spin term adds
        limit = max(qmu, f_over_sc * math.hypot(sx, sy))
        total = math.hypot(fx, fy)
        if total > limit:
            fx, fy = fx * (limit / total), fy * (limit / total)
    return np.float64(fx), np.float64(fy)


_ARG_NAMES = (
    "creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b",
    "mu0", "k_A", "k_S", "A", "B", "shear_modulus", "poisson",
)  # fmt: skip
#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(_ARG_NAMES)


_KERNELS = []


def _kernels():
    """The compiled kernels (:mod:`railadhesion.models.kernels`), imported on first use so
    that ``import railadhesion`` does not import numba."""
    if _KERNELS:
        return _KERNELS[0]
    from railadhesion.models import kernels

    _KERNELS.append(kernels)
    return kernels


def _polach_array(*args):
    """Array path of :func:`polach_forces`: the compiled kernel, validated in the same pass.

    Gives the numbers of :func:`_polach_reference` (to rounding). If any argument is out of
    range, the reference runs to raise the error naming it.
    """
    arrays = [as_float_array(x, name) for x, name in zip(args, _ARG_NAMES, strict=True)]
    k = _kernels()
    shape, n, flat = k.flatten_args(arrays)
    fx, fy, ok = k.polach_many(flat, n)
    if not ok:
        _polach_reference(*arrays)  # raises the ValueError naming the argument
        raise AssertionError("polach kernel flagged an input the reference accepts")
    if not shape:
        return np.float64(fx[0]), np.float64(fy[0])
    return fx.reshape(shape), fy.reshape(shape)


def _polach_reference(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu):
    """NumPy reference of the array path of :func:`polach_forces` (validated, broadcast, no
    Python loops): the readable implementation the compiled kernel is tested against."""
    sx = check_finite(sx, "creep_long")
    sy = check_finite(sy, "creep_lat")
    psi = check_finite(psi, "spin")
    q = check_positive(q, "normal_force")
    v = check_nonnegative(v, "speed")
    a = check_positive(a, "a")
    b = check_positive(b, "b")
    mu0 = check_positive(mu0, "mu0")
    k_a = check_range(k_a, "k_A", 0.0, 1.0, closed="right")
    k_s = check_range(k_s, "k_S", 0.0, 1.0, closed="right")
    big_a = check_nonnegative(big_a, "A")
    big_b = check_nonnegative(big_b, "B")
    g = check_positive(g, "shear_modulus")
    nu = check_range(nu, "poisson", 0.0, 0.5)

    a_over_b = axis_ratio(a, b)
    coef = kalker_coefficients(a_over_b, nu)
    c11, c22, c23 = coef.c11, coef.c22, coef.c23

    syc = sy + psi * a
    syc = np.where(np.abs(syc) > np.abs(sy), syc, sy)
    sc = np.hypot(sx, syc)
    moving = sc > 0.0
    sc_safe = np.where(moving, sc, 1.0)
    s = np.hypot(sx, sy)
    has_s = s > 0.0
    cjj = np.where(has_s, np.hypot(c11 * sx, c22 * sy) / np.where(has_s, s, 1.0), c22)

    mu = mu0 * ((1.0 - big_a) * np.exp(-big_b * (sc * v)) + big_a)
    qmu = q * mu
    # qmu == 0 only if A = 0 and exp(-B w) underflowed: no friction left, no force
    active = moving & (qmu > 0.0)
    qmu = np.where(qmu > 0.0, qmu, 1.0)
    k_psi = 1.0 + 6.3 * (1.0 - np.exp(-a_over_b))
    gc3c23 = g * a * b * np.sqrt(a * b) * c23
    abs_syc = np.abs(syc)
    with np.errstate(over="ignore"):  # huge gradients become inf (eps is then clipped)
        eps = np.minimum(_PI_OVER_4 * g * a * b * cjj * sc / qmu, _EPS_MAX)
        eps_psi = (8.0 / 3.0) * gc3c23 / a * abs_syc / (k_psi * qmu)
        e2 = 1.0 + eps_psi * eps_psi  # inf gives F_yS = 0
    x = k_a * eps
    f_over_sc = _TWO_OVER_PI * qmu * (x / (1.0 + x * x) + np.arctan(k_s * eps)) / sc_safe
    fys = gc3c23 * (psi / sc_safe) * (abs_syc / e2) / e2  # same order as the scalar path

    fx = np.where(active, -f_over_sc * sx, 0.0)
    fy = np.where(active, -(f_over_sc * sy + fys), 0.0)
    total = np.hypot(fx, fy)
    # spin cap at max(mu Q, |F|) where F_yS != 0 (see Notes); divide only where it applies
    # (limit/total of a tiny force would overflow)
    limit = np.maximum(qmu, f_over_sc * np.hypot(sx, sy))
    over = (total > limit) & (fys != 0.0) & active
    scale = np.where(over, limit / np.where(over, total, 1.0), 1.0)
    fx, fy = fx * scale, fy * scale
    if fx.ndim == 0:
        return np.float64(fx), np.float64(fy)
    # the five parameters may not reach fx (e.g. spin-only shapes): broadcast both fully
    shape = np.broadcast_shapes(fx.shape, fy.shape)
    if fx.shape != shape:
        fx = np.broadcast_to(fx, shape).copy()
    if fy.shape != shape:
        fy = np.broadcast_to(fy, shape).copy()
    return fx, fy


@dataclass(frozen=True)
class Polach:
    """Polach's creep-force model with one parameter set (object layer, no physics of its own).

    Parameters
    ----------
    params : PolachParameters or str
        Parameter set, or the name of a built-in set
        (:data:`railadhesion.models.parameters.POLACH_PARAMETER_SETS`).
    shear_modulus : float, optional
        Combined shear modulus G [Pa], > 0.
    poisson : float, optional
        Combined Poisson's ratio nu [-], in [0, 0.5].

    Examples
    --------
    >>> model = Polach("polach2005_wet")
    >>> fx, fy = model.forces(-0.02, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3)
    >>> round(float(fx), 1)
    22666.4
    >>> round(float(model.adhesion(-0.02, 0.0, 0.0, 106.7e3, 10.0, 6.304e-3, 12.61e-3)), 4)
    0.2124
    """

    params: PolachParameters
    shear_modulus: float = 8.2e10
    poisson: float = 0.28

    def __post_init__(self) -> None:
        params = self.params
        if isinstance(params, str):
            params = polach_parameters(params)
        if not isinstance(params, PolachParameters):
            raise ValueError(
                f"params must be a PolachParameters or the name of a built-in set, "
                f"got {type(params).__name__}"
            )
        object.__setattr__(self, "params", params)
        g = float(check_positive(self.shear_modulus, "shear_modulus"))
        nu = float(check_range(self.poisson, "poisson", 0.0, 0.5))
        object.__setattr__(self, "shear_modulus", g)
        object.__setattr__(self, "poisson", nu)

    def forces(self, creep_long, creep_lat, spin, normal_force, speed, a, b):
        """Forces (fx, fy) [N] exerted by the rail on the wheel; see :func:`polach_forces`."""
        p = self.params
        return polach_forces(
            creep_long, creep_lat, spin, normal_force, speed, a, b,
            mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )  # fmt: skip

    def adhesion(self, creep_long, creep_lat, spin, normal_force, speed, a, b):
        """Adhesion coefficient sqrt(fx^2 + fy^2)/Q [-] (:func:`railadhesion.adhesion`)."""
        from railadhesion.contact.traction import adhesion

        fx, fy = self.forces(creep_long, creep_lat, spin, normal_force, speed, a, b)
        return adhesion(fx, fy, normal_force)

    def contact(self, normal_force, speed, a, b) -> PolachContact:
        """A :class:`PolachContact` of this model on one contact (fast repeated calls)."""
        p = self.params
        return PolachContact(
            normal_force, speed, a, b, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )  # fmt: skip


class PolachContact:
    """One contact's fixed data, for fast repeated calls of Polach's model in inner loops.

    Holds the parameter set, G, nu, the semi-axes and their Kalker coefficients (looked up
    once); :meth:`forces` then evaluates :func:`polach_forces` for new creepages (and
    optionally a new speed or normal force) through the compiled scalar kernel
    (:func:`railadhesion.models.kernels.polach_scalar`, compiled for float64 arguments only:
    ints and NumPy scalars are converted), well under a microsecond a call, and returns
    Python floats. The same numbers as :func:`polach_forces` with scalar arguments. Building
    one imports numba (the kernel is loaded from numba's cache, or compiled once).

    Parameters
    ----------
    normal_force : float
        Normal force Q [N], > 0 (default for :meth:`forces`).
    speed : float
        Rolling speed V [m/s], >= 0 (default for :meth:`forces`).
    a, b : float
        Contact semi-axes in the rolling and lateral directions [m], > 0.
    mu0, k_A, k_S, A, B, shear_modulus, poisson : float
        As :func:`polach_forces` (validated once, here).

    Examples
    --------
    An ODE right-hand side (one wheel braking: state V, omega):

    >>> contact = PolachContact(1e5, 20.0, 6.3e-3, 12.6e-3, mu0=0.55, k_S=0.4, A=0.4, B=0.6)
    >>> def rhs(t, y, mass=8000.0, inertia=100.0, radius=0.46, torque=9e3):
    ...     speed, omega = y  # braking creepage > 0 gives fx < 0
    ...     fx, _ = contact.forces((speed - omega * radius) / speed, speed=speed)
    ...     return [fx / mass, (-torque - fx * radius) / inertia]
    >>> from scipy.integrate import solve_ivp
    >>> sol = solve_ivp(rhs, (0.0, 0.1), [20.0, 20.0 / 0.46 * 0.99], max_step=1e-3)
    >>> bool(sol.success)
    True
    >>> fx, fy = contact.forces(0.01)
    >>> fx == float(polach_forces(0.01, 0.0, 0.0, 1e5, 20.0, 6.3e-3, 12.6e-3, mu0=0.55,
    ...                           k_S=0.4, A=0.4, B=0.6)[0])
    True

    For compiled inner loops (numba) use
    :func:`railadhesion.models.kernels.polach_scalar` instead.
    """

    __slots__ = (
        "normal_force", "speed", "a", "b", "mu0", "k_A", "k_S", "A", "B", "shear_modulus",
        "poisson", "c11", "c22", "c23", "_data", "_kernel",
    )  # fmt: skip

    def __init__(self, normal_force, speed, a, b, *, mu0, k_A=1.0, k_S=1.0, A=1.0, B=0.0,
                 shear_modulus=8.2e10, poisson=0.28):  # fmt: skip
        values = (0.0, 0.0, 0.0, normal_force, speed, a, b, mu0, k_A, k_S, A, B,
                  shear_modulus, poisson)  # fmt: skip
        scalars = _scalars(values)
        if scalars is None:
            raise ValueError("PolachContact holds one contact: every argument must be a scalar")
        _polach_scalar(*scalars)  # validates every argument, errors name it
        _PLAUSIBLE(scalars)  # implausible inputs warn (docs/checks.md), once per contact
        (_, _, _, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g, nu) = (float(x) for x in scalars)
        self.normal_force, self.speed, self.a, self.b = q, v, a, b
        self.mu0, self.k_A, self.k_S, self.A, self.B = mu0, k_a, k_s, big_a, big_b
        self.shear_modulus, self.poisson = g, nu
        self.c11, self.c22, self.c23 = _kernels().kalker_scalar(a / b, nu)[:3]
        object.__setattr__(self, "_kernel", _kernels().contact_kernel())
        self._refresh()

    def _refresh(self) -> None:
        """The fixed data in the order of :func:`railadhesion.models.kernels.polach_scalar`."""
        object.__setattr__(self, "_data", np.array([
            self.a, self.b, self.shear_modulus, self.poisson, self.c11, self.c22, self.c23,
            self.k_A, self.k_S, self.mu0, self.A, self.B,
        ]))  # fmt: skip

    _INPUTS = ("normal_force", "speed", "a", "b", "mu0", "k_A", "k_S", "A", "B",
               "shear_modulus", "poisson")  # fmt: skip

    def __setattr__(self, name, value) -> None:
        if not hasattr(self, "_data"):  # being built by __init__
            object.__setattr__(self, name, value)
            return
        if name not in self._INPUTS:
            raise AttributeError(f"PolachContact.{name} is derived from the contact's inputs "
                                 f"({', '.join(self._INPUTS)}): set those")  # fmt: skip
        # a changed input: validated and everything derived from it (Kalker's coefficients,
        # the kernel's data) recomputed, as by the constructor
        values = {k: getattr(self, k) for k in self._INPUTS}
        values[name] = value
        q, v, a, b = (values.pop(k) for k in ("normal_force", "speed", "a", "b"))
        fresh = PolachContact(q, v, a, b, **values)
        for k in self.__slots__:
            object.__setattr__(self, k, getattr(fresh, k))

    def __repr__(self) -> str:
        return (f"PolachContact(normal_force={self.normal_force!r}, speed={self.speed!r}, "
                f"a={self.a!r}, b={self.b!r}, mu0={self.mu0!r}, k_A={self.k_A!r}, "
                f"k_S={self.k_S!r}, A={self.A!r}, B={self.B!r})")  # fmt: skip

    def forces(self, creep_long, creep_lat=0.0, spin=0.0, speed=None, normal_force=None):
        """Forces (fx, fy) [N] of the rail on the wheel, as Python floats.

        ``speed`` and ``normal_force`` default to the values given at construction. Raises
        ``ValueError`` for non-finite creepages or an out-of-range speed or normal force.
        """
        sx, sy, psi = creep_long, creep_lat, spin
        if (sx - sx) + (sy - sy) + (psi - psi) != 0.0:  # NaN or inf in a creepage
            for name, val in (("creep_long", sx), ("creep_lat", sy), ("spin", psi)):
                if not math.isfinite(val):
                    raise ValueError(f"{name} must be finite (no NaN or inf), got {val!r}")
        if normal_force is None:
            normal_force = self.normal_force
        elif not 0.0 < normal_force < _INF:
            raise _bad("normal_force", "(0, inf)", normal_force)
        if speed is None:
            speed = self.speed
        elif not 0.0 <= speed < _INF:
            raise _bad("speed", "[0, inf)", speed)
        return self._kernel(sx, sy, psi, normal_force, speed, self._data)
