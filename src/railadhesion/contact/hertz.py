"""Hertzian normal contact: elliptical (wheel on rail, wheel on roller) and line (twin discs).

Axes follow ``docs/CONVENTIONS.md``: x is the rolling direction, y lateral; the contact
semi-axis ``a`` lies along x and ``b`` along y. Radii are positive for convex surfaces; a
concave wheel-profile radius is negative. SI units throughout.

The elliptical solution is the exact one, with complete elliptic integrals
(:func:`scipy.special.ellipkm1`, :func:`scipy.special.ellipe`); the axis ratio is found by a
vectorised, bracketed Newton iteration, so arrays of contacts are solved at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ellipe, ellipkm1

from railadhesion._labelled import HERTZ_UNITS, LINE_UNITS, labelled
from railadhesion._validate import as_float_array, check_positive, check_range
from railadhesion.plausibility import check_plausible, input_checker

__all__ = [
    "HertzContact",
    "LineContact",
    "combined_elastic_constants",
    "hertz_3d",
    "hertz_3d_from_curvatures",
    "line_contact",
    "line_contact_from_pressure",
]

# Bracket of ln(k), k = minor/major semi-axis ratio: k = e^-40 ~ 4e-18 covers any
# curvature ratio up to ~1e35.
_LNK_MIN = -40.0
_MAX_ITER = 80
#: Largest accepted curvature ratio max(A, B)/min(A, B): F(e^_LNK_MIN) is about 1.4e33; beyond
#: the bracket the solve would silently return k = e^-40 (a wrong ellipse).
_RATIO_MAX = 1e30


def _scalar_or_array(x):
    """Return a float for 0-d results, else the array itself."""
    x = np.asarray(x)
    return float(x) if x.ndim == 0 else np.array(x)


@dataclass(frozen=True)
class HertzContact:
    """Result of a 3D Hertzian contact (every field a float or an array, SI units).

    Attributes
    ----------
    a : float or ndarray
        Contact semi-axis in the rolling direction x [m].
    b : float or ndarray
        Lateral contact semi-axis (y) [m].
    max_pressure : float or ndarray
        Peak pressure p0 = 3Q/(2 pi a b) [Pa].
    approach : float or ndarray
        Mutual approach of distant points of the two bodies, delta [m].
    curvature_A : float or ndarray
        A = (1/R_wx + 1/R_rx)/2, gap coefficient along x [1/m].
    curvature_B : float or ndarray
        B = (1/R_wy + 1/R_ry)/2, gap coefficient along y [1/m].
    mean_radius : float or ndarray
        rho = 2/(A + B) [m].
    c : float or ndarray
        Geometric-mean semi-axis sqrt(a b) [m].
    normal_force : float or ndarray
        Normal force Q [N].
    effective_modulus : float or ndarray
        E*, with 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 [Pa].
    """

    a: float | np.ndarray
    b: float | np.ndarray
    max_pressure: float | np.ndarray
    approach: float | np.ndarray
    curvature_A: float | np.ndarray
    curvature_B: float | np.ndarray
    mean_radius: float | np.ndarray
    c: float | np.ndarray
    normal_force: float | np.ndarray
    effective_modulus: float | np.ndarray

    @property
    def a_over_b(self):
        """Ratio of the semi-axes a/b [-] (input of :func:`kalker_coefficients`)."""
        return self.a / self.b


@dataclass(frozen=True)
class LineContact:
    """Result of a 2D Hertzian line contact (cylinders with parallel axes), SI units.

    Attributes
    ----------
    half_width : float or ndarray
        Semi-width a of the contact strip [m].
    max_pressure : float or ndarray
        Peak pressure p0 [Pa].
    load_per_length : float or ndarray
        Normal load per unit length P [N/m].
    reduced_radius : float or ndarray
        R with 1/R = 1/R1 + 1/R2 [m].
    effective_modulus : float or ndarray
        E* [Pa].
    """

    half_width: float | np.ndarray
    max_pressure: float | np.ndarray
    load_per_length: float | np.ndarray
    reduced_radius: float | np.ndarray
    effective_modulus: float | np.ndarray


#: Plausibility checks of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE_MATERIAL = input_checker(("young", "poisson", "young_rail", "poisson_rail"))
_PLAUSIBLE_3D = input_checker(("normal_force", "wheel_radius"))


@labelled(units=("Pa", "Pa", "1"))
def combined_elastic_constants(young, poisson, young_rail=None, poisson_rail=None):
    """Effective modulus E*, combined shear modulus G and Poisson's ratio nu of two bodies.

    Parameters
    ----------
    young : array_like
        Young's modulus E1 of the wheel (first body) [Pa], > 0.
    poisson : array_like
        Poisson's ratio nu1 of the wheel [-], in [0, 0.5].
    young_rail : array_like, optional
        Young's modulus E2 of the rail or roller (second body) [Pa]; default: ``young``.
    poisson_rail : array_like, optional
        Poisson's ratio nu2 of the rail [-]; default: ``poisson``.

    Returns
    -------
    effective_modulus : float or ndarray
        E*, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 [Pa].
    shear_modulus : float or ndarray
        G, 1/G = (1/G1 + 1/G2)/2 with Gi = Ei/(2(1 + nui)) [Pa].
    poisson : float or ndarray
        nu = (G/2)(nu1/G1 + nu2/G2) [-].

    Notes
    -----
    E* is the Hertz modulus (Johnson, *Contact Mechanics*, 1985, eq. 4.22 with
    E* defined as there). G and nu are combined as CONTACT does for Kalker's theory of
    dissimilar, quasi-identical bodies (Kalker 1990, section 1.6; CONTACT user guide), so that
    equal materials give G = E/(2(1 + nu)) and the material's own nu.

    Examples
    --------
    >>> e_star, g, nu = combined_elastic_constants(2.1e11, 0.28)
    >>> round(e_star / 1e9, 2), round(g / 1e9, 2), round(float(nu), 2)
    (113.93, 82.03, 0.28)
    """
    e1 = check_positive(young, "young")
    nu1 = check_range(poisson, "poisson", 0.0, 0.5)
    e2 = e1 if young_rail is None else check_positive(young_rail, "young_rail")
    nu2 = nu1 if poisson_rail is None else check_range(poisson_rail, "poisson_rail", 0.0, 0.5)
    if e1.ndim == 0 and nu1.ndim == 0 and e2.ndim == 0 and nu2.ndim == 0:
        e1, nu1, e2, nu2 = float(e1), float(nu1), float(e2), float(nu2)  # cheap scalar path
    _PLAUSIBLE_MATERIAL((e1, nu1, young_rail, poisson_rail))  # implausible inputs warn
    e_star = 1.0 / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)
    g1 = e1 / (2.0 * (1.0 + nu1))
    g2 = e2 / (2.0 * (1.0 + nu2))
    g = 2.0 / (1.0 / g1 + 1.0 / g2)
    nu = 0.5 * g * (nu1 / g1 + nu2 / g2)
    return _scalar_or_array(e_star), _scalar_or_array(g), _scalar_or_array(nu)


def _log_curvature_ratio(lnk: np.ndarray):
    """ln F(k) and d ln F / d ln k with F(k) = (E/k^2 - K)/(K - E), m = 1 - k^2.

    F is the ratio (larger/smaller) of the gap curvatures for which the contact ellipse has
    minor/major axis ratio k (exact Hertz theory).
    """
    k2 = np.exp(2.0 * lnk)
    m = 1.0 - k2
    kk = ellipkm1(k2)  # K(m) = K(1 - k^2), accurate for thin ellipses (k -> 0)
    ee = ellipe(m)
    num = ee / k2 - kk
    den = kk - ee
    # derivatives with respect to m (Abramowitz & Stegun 17.3.11 and 17.3.12)
    dk_dm = (ee - k2 * kk) / (2.0 * m * k2)
    de_dm = (ee - kk) / (2.0 * m)
    dnum_dm = de_dm / k2 + ee / k2**2 - dk_dm
    dden_dm = dk_dm - de_dm
    dlnf_dm = dnum_dm / num - dden_dm / den
    return np.log(num / den), dlnf_dm * (-2.0 * k2), kk, ee


def _axis_ratio(ratio: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve F(k) = ratio (>= 1) for k = minor/major semi-axis ratio.

    Returns ``(k, K(1-k^2), E(1-k^2))``. Bracketed Newton in ln k, vectorised over the
    array: each element keeps a bracket [lo, hi] and falls back to bisection when the
    Newton step leaves it.
    """
    circle = ratio <= 1.0 + 1e-13
    target = np.log(np.where(circle, 2.0, ratio))  # circles: dummy target, k = 1 set below
    lo = np.full_like(target, _LNK_MIN)
    hi = np.zeros_like(target)
    # starting guess from the classic approximation k ~ (A/B)^(2/3), kept inside the bracket
    lnk = np.clip(-2.0 / 3.0 * target, _LNK_MIN + 1.0, -1e-6)
    for _ in range(_MAX_ITER):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            lnf, dlnf, _, _ = _log_curvature_ratio(lnk)
        resid = lnf - target
        # F decreases with k: resid > 0 means k too small
        lo = np.where(resid > 0.0, lnk, lo)
        hi = np.where(resid > 0.0, hi, lnk)
        step = resid / dlnf
        new = lnk - step
        bad = ~np.isfinite(new) | (new < lo) | (new > hi)
        new = np.where(bad, 0.5 * (lo + hi), new)
        done = np.abs(new - lnk) <= 1e-12  # Newton: the error is then ~1e-24
        lnk = new
        if np.all(done):
            break
    k = np.where(circle, 1.0, np.exp(lnk))
    return k, ellipkm1(k * k), ellipe(1.0 - k * k)


def _axis_ratio_scalar(ratio: float) -> tuple[float, float, float]:
    """Scalar version of :func:`_axis_ratio` (same iteration, plain floats)."""
    if ratio <= 1.0 + 1e-13:
        return 1.0, math.pi / 2.0, math.pi / 2.0
    target = math.log(ratio)
    lo, hi = _LNK_MIN, 0.0
    lnk = min(max(-2.0 / 3.0 * target, _LNK_MIN + 1.0), -1e-6)
    for _ in range(_MAX_ITER):
        k2 = math.exp(2.0 * lnk)
        m = 1.0 - k2
        kk = float(ellipkm1(k2))
        ee = float(ellipe(m))
        num = ee / k2 - kk
        den = kk - ee
        resid = math.log(num / den) - target
        if resid > 0.0:
            lo = lnk
        else:
            hi = lnk
        dk_dm = (ee - k2 * kk) / (2.0 * m * k2)
        de_dm = (ee - kk) / (2.0 * m)
        dlnf = ((de_dm / k2 + ee / k2**2 - dk_dm) / num - (dk_dm - de_dm) / den) * (-2.0 * k2)
        new = lnk - resid / dlnf if dlnf != 0.0 else math.nan
        if not (lo <= new <= hi):  # also catches NaN
            new = 0.5 * (lo + hi)
        done = abs(new - lnk) <= 1e-12
        lnk = new
        if done:
            break
    k = math.exp(lnk)
    return k, float(ellipkm1(k * k)), float(ellipe(1.0 - k * k))


@labelled(units=HERTZ_UNITS)
def hertz_3d_from_curvatures(
    normal_force,
    curvature_A,
    curvature_B,
    *,
    young=2.1e11,
    poisson=0.28,
    young_rail=None,
    poisson_rail=None,
) -> HertzContact:
    """Hertzian elliptical contact from the gap coefficients A (along x) and B (along y).

    Parameters
    ----------
    normal_force : array_like
        Normal force Q [N], > 0.
    curvature_A : array_like
        Gap coefficient A along the rolling direction x [1/m], > 0: the undeformed gap is
        h = A x^2 + B y^2, A = (1/R_wx + 1/R_rx)/2.
    curvature_B : array_like
        Gap coefficient B along y [1/m], > 0; max(A, B)/min(A, B) <= 1e30.
    young, poisson : array_like
        Young's modulus [Pa] and Poisson's ratio [-] of the wheel (and of the rail unless
        ``young_rail``/``poisson_rail`` are given).
    young_rail, poisson_rail : array_like, optional
        Young's modulus [Pa] and Poisson's ratio [-] of the rail (or roller).

    Returns
    -------
    HertzContact

    Notes
    -----
    Exact Hertz solution (Johnson, *Contact Mechanics*, 1985, section 4.2, eqs. 4.36-4.39,
    written as in CONTACT ``hzcalc3d``). With k = minor/major semi-axis ratio,
    e^2 = 1 - k^2, K = K(e^2), E = E(e^2), the major axis lies along the smaller curvature and

    * ``max(A,B)/min(A,B) = (E/k^2 - K)/(K - E)`` (solved for k),
    * ``c = sqrt(ab) = (3 Q rho E / (4 pi E* sqrt(k)))^(1/3)``, ``rho = 2/(A+B)``,
    * ``delta = 2 c^2 k K / (rho E)``, ``p0 = 3Q/(2 pi a b)``.

    For A = B (sphere on a flat: A = B = 1/(2R)) this is c = (3QR/(4E*))^(1/3), delta = c^2/R.

    References
    ----------
    K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, chapter 4.
    E. A. H. Vollebregt, CONTACT, ``src/m_hertz.f90``, subroutine ``hzcalc3d``.

    Examples
    --------
    CONTACT's FASTSIM example (A = 0.8464 1/m, B = 2.406 1/m, Q = 82 kN, G = 82 GPa,
    nu = 0.28, i.e. E = 2G(1+nu)) gives a = 8 mm, b = 4 mm:

    >>> h = hertz_3d_from_curvatures(82e3, 0.8464, 2.406, young=2 * 82e9 * 1.28)
    >>> round(h.a * 1e3, 3), round(h.b * 1e3, 3), round(h.max_pressure / 1e6)
    (8.0, 4.0, 1223)
    """
    q = check_positive(normal_force, "normal_force")
    ca = check_positive(curvature_A, "curvature_A")
    cb = check_positive(curvature_B, "curvature_B")
    out = _hertz_core(q, ca, cb, young, poisson, young_rail, poisson_rail)
    _PLAUSIBLE_3D((q, None))  # implausible inputs warn (docs/checks.md)
    return out


def _hertz_core(q, ca, cb, young, poisson, young_rail, poisson_rail) -> HertzContact:
    """Solve the validated problem; ``q``, ``ca``, ``cb`` are float arrays, A, B > 0."""
    e_star = combined_elastic_constants(young, poisson, young_rail, poisson_rail)[0]
    with np.errstate(over="ignore"):
        ratio_ok = np.all((ca <= _RATIO_MAX * cb) & (cb <= _RATIO_MAX * ca))
    if not ratio_ok:
        raise ValueError(
            f"curvature_A, curvature_B: the curvature ratio max(A, B)/min(A, B) must be in "
            f"[1, {_RATIO_MAX:g}], got A = {np.ravel(ca)[:3].tolist()}, "
            f"B = {np.ravel(cb)[:3].tolist()} 1/m"
        )
    if q.ndim == 0 and ca.ndim == 0 and cb.ndim == 0 and np.ndim(e_star) == 0:
        return _hertz_scalar(float(q), float(ca), float(cb), float(e_star))
    q, ca, cb, e_star = np.broadcast_arrays(q, ca, cb, e_star)
    a_le_b_curv = ca <= cb  # smaller curvature along x: major axis along x, a >= b
    ratio = np.where(a_le_b_curv, cb / ca, ca / cb)
    k, kk, ee = _axis_ratio(ratio)
    rho = 2.0 / (ca + cb)
    c = np.cbrt(3.0 * q * rho * ee / (4.0 * np.pi * e_star * np.sqrt(k)))
    approach = 2.0 * c * c * k * kk / (rho * ee)
    major = c / np.sqrt(k)
    minor = c * np.sqrt(k)
    a = np.where(a_le_b_curv, major, minor)
    b = np.where(a_le_b_curv, minor, major)
    return _hertz_result(_scalar_or_array, a, b, approach, ca, cb, rho, c, q, e_star)


def _hertz_scalar(q: float, ca: float, cb: float, e_star: float) -> HertzContact:
    """Scalar version of :func:`_hertz_core` (same formulas, plain floats)."""
    a_le_b_curv = ca <= cb
    k, kk, ee = _axis_ratio_scalar(cb / ca if a_le_b_curv else ca / cb)
    rho = 2.0 / (ca + cb)
    c = (3.0 * q * rho * ee / (4.0 * math.pi * e_star * math.sqrt(k))) ** (1.0 / 3.0)
    approach = 2.0 * c * c * k * kk / (rho * ee)
    major, minor = c / math.sqrt(k), c * math.sqrt(k)
    a, b = (major, minor) if a_le_b_curv else (minor, major)
    return _hertz_result(float, a, b, approach, ca, cb, rho, c, q, e_star)


def _hertz_result(convert, a, b, approach, ca, cb, rho, c, q, e_star) -> HertzContact:
    """The :class:`HertzContact` of a solved problem, p0 = 3Q/(2 pi a b), every field passed
    through ``convert`` (:func:`_scalar_or_array` for arrays, ``float`` for the scalar path)."""
    return HertzContact(
        a=convert(a),
        b=convert(b),
        max_pressure=convert(3.0 * q / (2.0 * np.pi * a * b)),
        approach=convert(approach),
        curvature_A=convert(ca),
        curvature_B=convert(cb),
        mean_radius=convert(rho),
        c=convert(c),
        normal_force=convert(q),
        effective_modulus=convert(e_star),
    )


def _check_radius_nonzero(value, name: str) -> np.ndarray:
    """Radius that may be negative (concave) or +-inf, but not zero or NaN."""
    arr = as_float_array(value, name)
    if not np.all((arr != 0.0) & ~np.isnan(arr)):
        raise ValueError(
            f"{name} must be a nonzero radius in [-inf, 0) or (0, inf] (negative = concave), "
            f"got {arr.ravel()[:3].tolist()}"
        )
    return arr


@labelled(units=HERTZ_UNITS)
def hertz_3d(
    normal_force,
    wheel_radius,
    wheel_lateral_radius,
    rail_lateral_radius,
    rail_radius=np.inf,
    *,
    young=2.1e11,
    poisson=0.28,
    young_rail=None,
    poisson_rail=None,
) -> HertzContact:
    """Hertzian contact of a wheel on a rail (or on a roller) from the principal radii.

    Parameters
    ----------
    normal_force : array_like
        Normal force Q [N], > 0.
    wheel_radius : array_like
        Rolling radius of the wheel R_wx [m], in (0, inf).
    wheel_lateral_radius : array_like
        Radius of the wheel profile in the lateral plane R_wy [m]: positive convex, negative
        concave (e.g. a worn tread or the flange root), ``np.inf`` for a conical tread.
    rail_lateral_radius : array_like
        Radius of the rail-head profile R_ry [m], in (0, inf].
    rail_radius : array_like, optional
        Radius of the rail in the rolling direction R_rx [m], in (0, inf]: ``np.inf``
        (default) for a track, the roller radius on a roller rig.
    young, poisson, young_rail, poisson_rail : array_like
        Elastic constants, see :func:`combined_elastic_constants` [Pa, -].

    Returns
    -------
    HertzContact

    Raises
    ------
    ValueError
        If an input is out of range, or if a concave wheel profile makes
        B = (1/R_wy + 1/R_ry)/2 <= 0 (conformal contact: not Hertzian).

    Notes
    -----
    A = (1/R_wx + 1/R_rx)/2, B = (1/R_wy + 1/R_ry)/2, then
    :func:`hertz_3d_from_curvatures` (exact Hertz solution; Johnson 1985, section 4.2,
    eqs. 4.36-4.39, written as in CONTACT ``hzcalc3d``).

    References
    ----------
    K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, chapter 4.
    E. A. H. Vollebregt, CONTACT, ``src/m_hertz.f90``, subroutine ``hzcalc3d``.

    Examples
    --------
    Tram wheel (0.696 m diameter) on the 0.905 m rail roller of Trummer et al. (WILAC),
    effective lateral radius 0.660 m, Q = 4.2 kN:

    >>> h = hertz_3d(4.2e3, 0.348, np.inf, 0.660, rail_radius=0.4525)
    >>> round(h.a * 1e3, 2), round(h.b * 1e3, 2), round(h.max_pressure / 1e6)
    (1.41, 3.15, 450)
    """
    q = check_positive(normal_force, "normal_force")
    rwx = check_positive(wheel_radius, "wheel_radius")
    rwy = _check_radius_nonzero(wheel_lateral_radius, "wheel_lateral_radius")
    rry = check_positive(rail_lateral_radius, "rail_lateral_radius", allow_inf=True)
    rrx = check_positive(rail_radius, "rail_radius", allow_inf=True)
    if rwx.ndim == 0 and rwy.ndim == 0 and rry.ndim == 0 and rrx.ndim == 0:
        rwx, rwy, rry, rrx = float(rwx), float(rwy), float(rry), float(rrx)  # cheap scalars
    ca = 0.5 * (1.0 / rwx + 1.0 / rrx)
    cb = 0.5 * (1.0 / rwy + 1.0 / rry)
    if not np.all(cb > 0.0):
        raise ValueError(
            "wheel_lateral_radius: the lateral curvature sum B = (1/wheel_lateral_radius + "
            "1/rail_lateral_radius)/2 must be in (0, inf); a concave wheel profile needs "
            "|wheel_lateral_radius| > rail_lateral_radius, got "
            f"B = {np.asarray(cb).ravel()[:3].tolist()} 1/m"
        )
    out = _hertz_core(q, np.asarray(ca), np.asarray(cb), young, poisson, young_rail, poisson_rail)
    _PLAUSIBLE_3D((q, rwx))  # implausible inputs warn (docs/checks.md)
    return out


def _reduced_radius(radius_1, radius_2) -> np.ndarray:
    r1 = check_positive(radius_1, "radius_1")
    r2 = _check_radius_nonzero(radius_2, "radius_2")
    inv = 1.0 / r1 + 1.0 / r2
    if not np.all(inv > 0.0):
        raise ValueError(
            "radius_2: 1/radius_1 + 1/radius_2 must be in (0, inf); a concave radius_2 needs "
            f"|radius_2| > radius_1, got 1/R = {np.asarray(inv).ravel()[:3].tolist()} 1/m"
        )
    return 1.0 / inv


@labelled(units=LINE_UNITS)
def line_contact(
    load_per_length,
    radius_1,
    radius_2=np.inf,
    *,
    young=2.1e11,
    poisson=0.3,
    young_2=None,
    poisson_2=None,
) -> LineContact:
    """Hertzian line contact of two cylinders with parallel axes (twin-disc rig), from the load.

    Parameters
    ----------
    load_per_length : array_like
        Normal load per unit length P [N/m], > 0.
    radius_1 : array_like
        Radius of the first cylinder [m], in (0, inf).
    radius_2 : array_like, optional
        Radius of the second cylinder [m]; ``np.inf`` (default) for a flat, negative for a
        concave surface with |radius_2| > radius_1.
    young, poisson : array_like
        Young's modulus [Pa] and Poisson's ratio [-] of body 1 (and 2 unless given).
    young_2, poisson_2 : array_like, optional
        Young's modulus [Pa] and Poisson's ratio [-] of body 2.

    Returns
    -------
    LineContact

    Notes
    -----
    Johnson, *Contact Mechanics* (1985), eqs. 4.43 and 4.45: with 1/R = 1/R1 + 1/R2,
    a = sqrt(4 P R/(pi E*)), p0 = 2P/(pi a) = sqrt(P E*/(pi R)).

    Examples
    --------
    >>> lc = line_contact(5.0e5, 0.0235, 0.0235)
    >>> round(lc.half_width * 1e3, 4), round(lc.max_pressure / 1e6, 1)
    (0.2546, 1250.2)
    """
    p = check_positive(load_per_length, "load_per_length")
    r = _reduced_radius(radius_1, radius_2)
    e_star = combined_elastic_constants(young, poisson, young_2, poisson_2)[0]
    a = np.sqrt(4.0 * p * r / (np.pi * e_star))
    p0 = 2.0 * p / (np.pi * a)
    return _line_result(a, p0, p, r, e_star)


@labelled(units=LINE_UNITS)
def line_contact_from_pressure(
    max_pressure,
    radius_1,
    radius_2=np.inf,
    *,
    young=2.1e11,
    poisson=0.3,
    young_2=None,
    poisson_2=None,
) -> LineContact:
    """Hertzian line contact from the peak pressure (how twin-disc tests are specified).

    Parameters
    ----------
    max_pressure : array_like
        Peak Hertz pressure p0 [Pa], > 0.
    radius_1, radius_2, young, poisson, young_2, poisson_2
        As in :func:`line_contact` [m, m, Pa, -, Pa, -].

    Returns
    -------
    LineContact

    Notes
    -----
    Inverse of :func:`line_contact` (Johnson 1985, eqs. 4.43, 4.45): a = 2 p0 R / E*,
    P = pi a p0 / 2.

    Examples
    --------
    Fletcher's 47 mm discs at 1000 MPa (seed paper: a = 0.204 mm):

    >>> lc = line_contact_from_pressure(1.0e9, 0.0235, 0.0235)
    >>> round(lc.half_width * 1e3, 3)
    0.204
    """
    p0 = check_positive(max_pressure, "max_pressure")
    r = _reduced_radius(radius_1, radius_2)
    e_star = combined_elastic_constants(young, poisson, young_2, poisson_2)[0]
    a = 2.0 * p0 * r / e_star
    p = np.pi * a * p0 / 2.0
    check_plausible(p0, "max_pressure")  # implausible inputs warn (docs/checks.md)
    return _line_result(a, p0, p, r, e_star)


def _line_result(a, p0, p, r, e_star) -> LineContact:
    a, p0, p, r, e_star = np.broadcast_arrays(a, p0, p, r, e_star)
    return LineContact(
        half_width=_scalar_or_array(a),
        max_pressure=_scalar_or_array(p0),
        load_per_length=_scalar_or_array(p),
        reduced_radius=_scalar_or_array(r),
        effective_modulus=_scalar_or_array(e_star),
    )
