"""FASTSIM: Kalker's simplified theory of rolling contact, batched over contacts.

FASTSIM (Kalker 1982) replaces the elastic half-space by a set of independent springs: the
elastic displacement at a point is ``u = L p`` with a flexibility ``L`` [m^3/N] per direction.
In steady rolling the traction then follows from a march along x from the leading edge to the
trailing edge, clipped to the traction bound ``mu p_n``. The three flexibilities are chosen so
that, without saturation, the forces equal those of Kalker's linear theory
(:func:`railadhesion.contact.kalker.linear_creep_forces`).

Two grid layouts are offered: Kalker's strips (each lateral strip split into elements over
its own length; the default, converging fast) and CONTACT's rectangular grid (reproduces the
numbers of Vollebregt's CONTACT program, e.g. its ``fastsim`` example).

This module solves many contacts at once: every input broadcasts to a *contact shape*. The
march runs in compiled code (numba, :mod:`railadhesion.contact._fastsim_kernels`): the strips
advance side by side in the inner loop, and large batches of contacts run in parallel; one
contact given as scalars takes a short path with ``math`` around the compiled march. The
NumPy march (contacts and grid rows vectorised, a Python loop along x) is kept as the readable
reference; it runs when ``return_tractions=True`` and the tests hold the compiled march to it
at 1e-12.

Sign convention (``docs/CONVENTIONS.md``): the returned forces are exerted by the rail on the
wheel and oppose the creepage (Kalker's, as CONTACT); at small creepage
``Fx = -G c^2 C11 xi`` and ``Fy = -G c^2 C22 eta - G c^3 C23 phi``.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from railadhesion._labelled import FASTSIM_UNITS, labelled
from railadhesion._validate import (
    check_choice,
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.contact.kalker import (
    _AOB_MAX,
    _AOB_MIN,
    _coefficients_scalar,
    axis_ratio,
    kalker_coefficients,
)
from railadhesion.plausibility import input_checker

__all__ = ["FastsimResult", "fastsim"]

_BOUNDS = ("parabolic", "elliptic")
_FLEXIBILITIES = ("original", "blended")
_GRIDS = ("strips", "rectangular")
#: CONTACT evaluates the spin part of the rigid slip a sixth of a step upstream of the element
#: centre, at x + dq/6 (input FACPHI, default 1/6: CONTACT ``m_sinput.f90``; used in
#: ``m_sdis.f90``, subroutine ``srztng``).
_FACPHI = 1.0 / 6.0
#: CONTACT evaluates the blending weight with spin in rad/mm; 1 rad/m = 1e-3 rad/mm.
_SPIN_TO_PER_MM = 1e-3
#: Target number of array elements (contacts x strips) processed together: keeps the march's
#: working arrays in cache for large batches.
_CHUNK_ELEMENTS = 16384
#: [Pa]; keeps g/|p| finite where p = 0 in the march (tractions that small are irrelevant).
_TINY_TRACTION = 1e-30
#: Largest creepage magnitude max(|xi|, |eta|, |phi| a) marched as given. Larger creepages
#: are scaled down to it, all three by the same factor (direction kept): the contact is then in
#: full slip for any physical contact, where the result does not depend on the magnitude, and
#: the march stays clear of overflow (|xi| ~ 1e150 gave 0 or NaN instead of mu Fz).
_CREEP_MAX = 1e50


@dataclass(frozen=True)
class FastsimResult:
    """Result of :func:`fastsim`.

    Forces follow Kalker's sign convention (exerted by the rail on the wheel, opposing the
    creepage). ``fx``, ``fy``, ``mz`` and ``slip_fraction`` have the broadcast contact shape
    of the inputs (NumPy scalars for scalar input).

    The grid fields are ``None`` unless ``return_tractions=True``; then they have the shape
    ``(*contact_shape, ny, nx)``: row (strip) index j along y (from y = -b to +b), element
    index i along x from the leading edge (+x) to the trailing edge. On the rectangular grid
    the elements whose centre lies outside the ellipse carry no traction (``px = py = 0``,
    ``slip`` False).
    """

    fx: np.ndarray
    """Longitudinal force [N]."""
    fy: np.ndarray
    """Lateral force [N]."""
    mz: np.ndarray
    """Spin moment about the contact normal (z) at the contact centre [N m]."""
    slip_fraction: np.ndarray
    """Fraction of the contact area (grid cells in contact, area-weighted) in slip [-]."""
    x: np.ndarray | None = None
    """Cell-centre x coordinates [m] (rolling direction)."""
    y: np.ndarray | None = None
    """Cell-centre y coordinates [m] (lateral)."""
    px: np.ndarray | None = None
    """Longitudinal traction at the cell centres [Pa]."""
    py: np.ndarray | None = None
    """Lateral traction at the cell centres [Pa]."""
    slip: np.ndarray | None = None
    """True where the cell slips (traction on the bound)."""


@lru_cache(maxsize=32)
def _grid_pattern(nx: int, ny: int, bound: str):
    """Dimensionless grid factors shared by all contacts of a call.

    Returns ``(eta, sq, tx, gy, norm)``:

    * ``eta`` (ny,): strip centres y_j / b;
    * ``sq`` (ny,): a(y_j)/a = sqrt(1 - eta^2);
    * ``tx`` (nx,), ``gy`` (ny,): the normal-pressure shape at cell (i, j) is
      ``gy[j] * tx[i]``;
    * ``norm``: sum over the cells of shape x (cell area / (a b)); the discrete pressure is
      scaled by ``Fz / (a b norm)`` so that it sums exactly to the normal force.
    """
    eta = -1.0 + (np.arange(ny) + 0.5) * (2.0 / ny)
    sq = np.sqrt(1.0 - eta * eta)
    s = np.arange(nx) + 0.5
    # 1 - x^2/a(y)^2 at the cell centres of a strip split into nx equal elements
    ux = 4.0 * s * (nx - s) / nx**2
    if bound == "parabolic":
        tx, gy = ux, sq * sq
    else:
        tx, gy = np.sqrt(ux), sq
    # cell area: (2 a sq_j / nx) * (2 b / ny)
    norm = float((gy * sq).sum() * tx.sum()) * 4.0 / (nx * ny)
    return eta, sq, tx, gy, norm


@lru_cache(maxsize=32)
def _rect_pattern(nx: int, ny: int, scale: float, bound: str):
    """Dimensionless factors of CONTACT's rectangular grid, shared by all contacts of a call.

    Returns ``(xh, yh, mask, shape, n_in)``:

    * ``xh`` (nx,): element centres x_i / a, from the leading edge (+x) to the trailing edge;
    * ``yh`` (ny,): row centres y_j / b, from -b to +b;
    * ``mask`` (nx, ny): 1.0 where the element centre lies inside the ellipse, else 0.0;
    * ``shape`` (nx, ny): normal pressure at the centres divided by ``Fz / (a b)``
      (``2/pi u`` or ``3/(2 pi) sqrt(u)``, ``u = 1 - x^2/a^2 - y^2/b^2``; zero outside);
    * ``n_in``: number of elements in contact.

    Arrays are indexed [column i, row j] so that the march reads one contiguous column.
    """
    # odd integer numerators: the centres are exactly symmetric about the contact centre
    xh = scale * ((nx - 1.0 - 2.0 * np.arange(nx)) / nx)
    yh = scale * ((2.0 * np.arange(ny) + 1.0 - ny) / ny)
    u = 1.0 - xh[:, None] ** 2 - yh[None, :] ** 2
    inside = u > 0.0
    u = np.where(inside, u, 0.0)
    shape = (2.0 / np.pi) * u if bound == "parabolic" else (1.5 / np.pi) * np.sqrt(u)
    return xh, yh, inside.astype(float), shape, int(inside.sum())


def _flexibilities(a, b, xi, eta, phi, normal_force, mu, g_mod, nu, blended):
    """Kalker's three flexibilities L1, L2, L3 [m^3/N], optionally blended (CONTACT 2023)."""
    a_over_b = axis_ratio(a, b)
    coef = kalker_coefficients(a_over_b, nu)
    c11, c22, c23 = coef.c11, coef.c22, coef.c23
    l1 = 8.0 * a / (3.0 * g_mod * c11)
    l2 = 8.0 * a / (3.0 * g_mod * c22)
    l3 = np.pi * a * np.sqrt(a_over_b) / (4.0 * g_mod * c23)
    if not blended:
        return l1, l2, l3
    # Vollebregt & Voltr (2023): blend the three flexibilities towards one combined value as the
    # creepage grows, so that the force at full sliding opposes the creepage.
    spin_term = (phi * (3.0 * np.pi * a / 32.0)) ** 2  # (phi f4/f3)^2, f4/f3 = 3 pi a / 32
    num = xi * xi + eta * eta + spin_term
    den = xi * xi / l1 + eta * eta / l2 + spin_term / l3
    l_crss = np.divide(num, den, out=np.array(l1, dtype=float, copy=True), where=den > 0.0)
    c2 = a * b
    c3 = c2 * np.sqrt(c2)
    mu_fz = mu * normal_force
    ch_xi = mu_fz / (c2 * g_mod * c11)
    ch_eta = mu_fz / (c2 * g_mod * c22)
    ch_phi = mu_fz / (c3 * g_mod * c23) * _SPIN_TO_PER_MM
    phi_mm = phi * _SPIN_TO_PER_MM
    ch2 = ch_xi * ch_xi + ch_eta * ch_eta + ch_phi * ch_phi
    crp2 = xi * xi + eta * eta + phi_mm * phi_mm
    # ch2 = 0 only when mu Fz = 0: then the bound is zero anyway and any weight will do.
    f_crp = np.sqrt(np.divide(crp2, ch2, out=np.zeros_like(crp2), where=ch2 > 0.0))
    w = np.clip(f_crp / 3.0, 0.0, 1.0)
    return (
        (1.0 - w) * l1 + w * l_crss,
        (1.0 - w) * l2 + w * l_crss,
        (1.0 - w) * l3 + w * l_crss,
    )


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "normal_force", "a", "b", "mu",
                            "shear_modulus", "poisson"))


@labelled(units=FASTSIM_UNITS)
def fastsim(
    creep_long,
    creep_lat,
    spin,
    normal_force,
    a,
    b,
    mu,
    *,
    shear_modulus=8.2e10,
    poisson=0.28,
    nx: int = 40,
    ny: int = 40,
    bound: str = "parabolic",
    flexibility="original",
    grid: str = "strips",
    scale: float = 1.1,
    return_tractions: bool = False,
) -> FastsimResult:
    """Tangential forces of steady rolling contact by Kalker's FASTSIM algorithm.

    Parameters
    ----------
    creep_long : array_like
        Longitudinal creepage xi = (V - omega R)/V [-] (braking positive).
    creep_lat : array_like
        Lateral creepage eta [-].
    spin : array_like
        Spin creepage phi [rad/m].
    normal_force : array_like
        Normal force Fz [N], >= 0.
    a : array_like
        Contact semi-axis along the rolling direction x [m], > 0.
    b : array_like
        Lateral contact semi-axis [m], > 0.
    mu : array_like
        Coefficient of friction [-], >= 0.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa], > 0. Default 82 GPa (steel).
    poisson : array_like, optional
        Combined Poisson's ratio nu [-], in [0, 0.5]. Default 0.28.
    nx : int, optional
        Elements along x (>= 1): per strip (``grid="strips"``) or per grid row
        (``grid="rectangular"``). Default 40.
    ny : int, optional
        Number of strips / grid rows along y (>= 1). Default 40.
    bound : {"parabolic", "elliptic"}, optional
        Traction bound ``mu p_n``: ``"parabolic"`` (Kalker's original,
        ``p_n = 2Fz/(pi a b) (1 - x^2/a^2 - y^2/b^2)``) or ``"elliptic"`` (Hertz,
        ``p_n = 3Fz/(2 pi a b) sqrt(1 - x^2/a^2 - y^2/b^2)``).
    flexibility : {"original", "blended"} or sequence of three array_like, optional
        ``"original"``: Kalker's three flexibilities L1, L2, L3. ``"blended"``: CONTACT's
        blending towards one flexibility as the creepage grows (Vollebregt & Voltr 2023), which
        makes the force at full sliding oppose the creepage. Or explicit ``(L1, L2, L3)``
        [m^3/N], each > 0 and broadcasting with the contacts (e.g. the ``FLX1..3`` printed by
        CONTACT, converted from mm^3/N by 1e-9, or Kalker's divided by a slope-reduction
        factor).
    grid : {"strips", "rectangular"}, optional
        Grid layout (see Notes): ``"strips"`` (Kalker's, default) or ``"rectangular"``
        (CONTACT's, to reproduce its numbers).
    scale : float, optional
        ``grid="rectangular"`` only: the grid covers ``[-scale a, scale a] x
        [-scale b, scale b]`` (CONTACT's SCALE), >= 1. Default 1.1.
    return_tractions : bool, optional
        Also return the grid, tractions and slip flags (see :class:`FastsimResult`).

    Returns
    -------
    FastsimResult
        ``fx``, ``fy`` [N], ``mz`` [N m] (exerted by the rail on the wheel, Kalker's sign
        convention) and ``slip_fraction`` [-], each of the broadcast contact shape.

    Raises
    ------
    ValueError
        If an argument is not numeric, not finite or outside its range, or if ``bound``,
        ``flexibility``, ``grid``, ``nx``, ``ny`` or ``scale`` is invalid (including a
        rectangular grid with no element centre inside the ellipse).

    Notes
    -----
    *Flexibilities* (Kalker 1982; CONTACT ``simpflex``; MODELS.md section 4), with Kalker's
    coefficients C11, C22, C23 of the ellipse a/b and Poisson's ratio nu
    (:func:`railadhesion.contact.kalker.kalker_coefficients`)::

        L1 = 8a / (3 G C11),  L2 = 8a / (3 G C22),  L3 = pi a sqrt(a/b) / (4 G C23)

    *Blended* (Vollebregt & Voltr 2023, as implemented in CONTACT ``simpflex``)::

        L_crss = (xi^2 + eta^2 + (phi f4/f3)^2) / (xi^2/L1 + eta^2/L2 + (phi f4/f3)^2/L3),
        f3 = 8a/3,  f4 = pi a^2/4,
        f_crp = sqrt((xi^2 + eta^2 + phi^2) / (ch_xi^2 + ch_eta^2 + ch_phi^2)),
        ch_xi = mu Fz/(c^2 G C11), ch_eta = mu Fz/(c^2 G C22), ch_phi = mu Fz/(c^3 G C23),
        w = clip(f_crp/3, 0, 1),  L_i <- (1 - w) L_i + w L_crss.

    ``f_crp`` adds spin to creepages, so it depends on the unit of spin: it is evaluated, as
    CONTACT's source does, with phi and ch_phi in rad/mm. The output of CONTACT revision 2707
    in its ``fastsim`` example (FLX1..3 = 0.4937, 0.5152, 0.4090 e-4 mm^3/N) implies a weight
    w = 0.0799, i.e. ``f_crp`` without the spin terms (this formula gives 0.110); both agree
    on the forces of that example to 0.35 %.

    Creepages beyond 1e50 in magnitude (max of |xi|, |eta|, |phi| a) are scaled down to
    1e50, all three by the same factor: the contact is then in full slip, where the result
    does not depend on the magnitude (|F| = mu Fz), and the march cannot overflow.

    *Algorithm* (Kalker 1982). Rigid slip ``w = (xi - phi y, eta + phi x)``. Along each
    row, from the leading edge, the trial traction is
    ``p(x - dx) = p(x) - dx (xi/L1 - phi y/L3, eta/L2 + phi xs/L3)``; where
    ``|p| > mu p_n`` it is scaled back onto the bound in its own direction (slip). Forces are
    sums of ``p dA``; ``Mz = sum (x py - y px) dA`` about the contact centre.

    *Grid layout* ``"strips"`` (Kalker 1982): ``ny`` strips of equal width ``2b/ny`` with
    centres ``y_j``; each strip is split into ``nx`` equal elements spanning its own length
    ``2a(y_j)``, ``a(y) = a sqrt(1 - y^2/b^2)``. Tractions, bound and slip are evaluated at
    the element centres (the first step is half an element from the exact leading edge), the
    spin term at the midpoint ``xs`` of each step, and the forces by the midpoint rule. In the
    stick state this reproduces Kalker's linear forces up to the midpoint-rule error,
    relative O(1/(2 nx^2) + 1/(2 ny^2)). The discrete normal pressure is scaled so that it
    sums exactly to Fz, hence ``|F| -> mu Fz`` at full sliding on any grid. The spin moment
    is the simplified theory's own: in full stick it is
    ``Mz = pi a^3 b eta/(4 L2) - 8 a^2 b^3 phi/(15 L3)`` (integrating the stick tractions), not
    Kalker's linear ``G c^3 C23 eta - G c^4 C33 phi``; only Fx and Fy match linear theory.

    *Grid layout* ``"rectangular"`` (CONTACT, ``m_solvpt.f90``, ``modif_fastsim``):
    ``nx x ny`` equal elements of size ``dx = 2 scale a/nx``, ``dy = 2 scale b/ny`` over the
    box ``[-scale a, scale a] x [-scale b, scale b]``; an element is in contact when its
    centre lies inside the ellipse. Each row is marched from the leading edge (+x) one
    element per step, starting from zero traction outside the contact, so the first element
    of a row receives a whole step; the spin term is evaluated at ``xs = x_i + dx/6``
    (CONTACT's FACPHI = 1/6). The bound is the normal pressure at the element centres,
    not rescaled, so at full sliding ``|F| = mu sum(p_n dA)``, which differs from ``mu Fz``
    by the quadrature error (0.08 % for the elliptic bound on 44 x 44). CONTACT's "40 x 40
    elements in contact" is ``nx = ny = 44`` with ``scale = 1.1``. This layout converges
    more slowly, about 1/n, than the strips, to the same limit.

    References
    ----------
    J. J. Kalker, "A fast algorithm for the simplified theory of rolling contact", Vehicle
    System Dynamics 11 (1982) 1-13.
    E. A. H. Vollebregt, P. Voltr, "Improved accuracy for FASTSIM using one or three
    flexibility values", Vehicle System Dynamics 61(1) (2023).
    E. A. H. Vollebregt, CONTACT, ``src/m_hertz.f90`` (``simpflex``), ``src/m_solvpt.f90``
    (``modif_fastsim``), ``src/m_sdis.f90`` (``srztng``), Apache-2.0.

    Examples
    --------
    An 8 mm x 4 mm contact, 82 kN, lateral creepage and spin as in CONTACT's ``fastsim``
    example. On CONTACT's grid (220 x 220 elements over 1.1 a x 1.1 b) with CONTACT's printed
    flexibilities it gives CONTACT's Fy/(mu Fz) = -0.6359; the strip layout converges faster
    (to about -0.647):

    >>> case = (0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3)
    >>> flx = (0.4937e-13, 0.5152e-13, 0.4090e-13)  # CONTACT's FLX1..3 [mm^3/N] * 1e-9
    >>> r = fastsim(*case, nx=220, ny=220, grid="rectangular", flexibility=flx)
    >>> round(float(r.fy / (0.3 * 82e3)), 4)
    -0.6359
    >>> r = fastsim(*case)
    >>> round(float(r.fy / (0.3 * 82e3)), 4), round(float(r.slip_fraction), 2)
    (-0.6508, 0.42)

    Small creepage recovers Kalker's linear theory (Fx = -G c^2 C11 xi):

    >>> r = fastsim([1e-6, -1e-6], 0.0, 0.0, 82e3, 8e-3, 4e-3, 0.3)
    >>> [round(float(f), 2) for f in r.fx]
    [-13.66, 13.66]
    """
    if (
        grid == "strips" and not return_tractions and type(flexibility) is str
        and type(nx) is int and type(ny) is int
    ):  # fmt: skip
        values = _float_scalars(
            (creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus, poisson)
        )
        if values is not None:
            out = _fastsim_scalar(*values, nx, ny, bound, flexibility)
            if out is not None:
                _PLAUSIBLE(values)  # implausible inputs warn (docs/checks.md)
                return out
    xi = check_finite(creep_long, "creep_long")
    eta = check_finite(creep_lat, "creep_lat")
    phi = check_finite(spin, "spin")
    fz = check_nonnegative(normal_force, "normal_force")
    a_ = check_positive(a, "a")
    b_ = check_positive(b, "b")
    mu_ = check_nonnegative(mu, "mu")
    g_mod = check_positive(shear_modulus, "shear_modulus")
    nu = check_range(poisson, "poisson", 0.0, 0.5)
    check_choice(bound, "bound", _BOUNDS)
    check_choice(grid, "grid", _GRIDS)
    flx_given = _check_flexibility(flexibility)
    nx = _check_count(nx, "nx")
    ny = _check_count(ny, "ny")
    if grid == "rectangular":
        scale = _check_scale(scale)
        rect = _rect_pattern(nx, ny, scale, bound)
        if rect[4] == 0:
            raise ValueError(
                f"no element centre of the {nx} x {ny} grid (nx x ny) lies inside the contact "
                f"ellipse with scale={scale!r}: increase nx, ny or decrease scale (>= 1)"
            )

    args = np.broadcast_arrays(xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, *flx_given)
    shape = args[0].shape
    xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, *flx_given = (np.ravel(v) for v in args)
    xi, eta, phi = _limit_creepage(xi, eta, phi, a_)
    if flx_given:
        l1, l2, l3 = flx_given
    else:
        l1, l2, l3 = _flexibilities(
            a_, b_, xi, eta, phi, fz, mu_, g_mod, nu, flexibility == "blended"
        )

    _PLAUSIBLE(args[:9])  # implausible inputs warn (docs/checks.md); errors were raised above
    if not return_tractions:  # the compiled march (same numbers as the NumPy one below)
        from railadhesion.contact import _fastsim_kernels as kern

        flat = [np.ascontiguousarray(x, dtype=float) for x in
                (xi, eta, phi, fz, a_, b_, mu_, *np.broadcast_arrays(l1, l2, l3, xi)[:3])]
        if grid == "strips":
            out = kern.march_strips(*flat, _grid_pattern(nx, ny, bound))
        else:
            out = kern.march_rect(*flat, scale, rect)
        return FastsimResult(*(_shaped(v, shape) for v in out))
    return _fastsim_reference(xi, eta, phi, fz, a_, b_, mu_, l1, l2, l3, shape, nx, ny, bound,
                              grid, scale, rect if grid == "rectangular" else None,
                              return_tractions)  # fmt: skip


def _float_scalars(values) -> list | None:
    """``values`` as floats if every one is a Python or NumPy float or int, else ``None``."""
    out = []
    for v in values:
        t = type(v)
        if t is float or t is np.float64 or t is int:
            out.append(float(v))
        else:
            return None
    return out


def _fastsim_scalar(xi, eta, phi, fz, a, b, mu, g_mod, nu, nx, ny, bound, flexibility):
    """:func:`fastsim` for one contact on the strips, with ``math`` instead of NumPy around
    the compiled march (a few microseconds of Python). ``None`` if any input is invalid or
    out of range: the caller's array path then raises the error naming it."""
    fin = math.isfinite
    if not (fin(xi) and fin(eta) and fin(phi) and fin(fz) and fin(a) and fin(b) and fin(mu)
            and fin(g_mod) and fz >= 0 and a > 0 and b > 0 and mu >= 0 and g_mod > 0
            and 0.0 <= nu <= 0.5 and nx >= 1 and ny >= 1 and bound in _BOUNDS
            and flexibility in _FLEXIBILITIES):  # fmt: skip
        return None
    a_over_b = a / b
    if not _AOB_MIN <= a_over_b <= _AOB_MAX:
        return None
    size = max(abs(xi), abs(eta), abs(phi) * a)
    if size > _CREEP_MAX:
        scale = _CREEP_MAX / size
        xi, eta, phi = xi * scale, eta * scale, phi * scale
    c11, c22, c23, _ = _coefficients_scalar(a_over_b, nu)
    l1 = 8.0 * a / (3.0 * g_mod * c11)
    l2 = 8.0 * a / (3.0 * g_mod * c22)
    l3 = math.pi * a * math.sqrt(a_over_b) / (4.0 * g_mod * c23)
    if flexibility == "blended":  # the operations of _flexibilities, in floats
        spin_term = (phi * (3.0 * math.pi * a / 32.0)) ** 2
        num = xi * xi + eta * eta + spin_term
        den = xi * xi / l1 + eta * eta / l2 + spin_term / l3
        l_crss = num / den if den > 0.0 else l1
        c2 = a * b
        c3 = c2 * math.sqrt(c2)
        mu_fz = mu * fz
        ch_xi = mu_fz / (c2 * g_mod * c11)
        ch_eta = mu_fz / (c2 * g_mod * c22)
        ch_phi = mu_fz / (c3 * g_mod * c23) * _SPIN_TO_PER_MM
        phi_mm = phi * _SPIN_TO_PER_MM
        ch2 = ch_xi * ch_xi + ch_eta * ch_eta + ch_phi * ch_phi
        crp2 = xi * xi + eta * eta + phi_mm * phi_mm
        f_crp = math.sqrt(crp2 / ch2) if ch2 > 0.0 else 0.0
        w = min(max(f_crp / 3.0, 0.0), 1.0)
        l1, l2, l3 = ((1.0 - w) * l1 + w * l_crss, (1.0 - w) * l2 + w * l_crss,
                      (1.0 - w) * l3 + w * l_crss)  # fmt: skip
    from railadhesion.contact import _fastsim_kernels as kern

    eta_j, sq, tx, gy, norm = _grid_pattern(nx, ny, bound)
    out = kern.strips_one(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm)
    return FastsimResult(*(np.float64(v) for v in out))


def _shaped(v, shape):
    v = v.reshape(shape)
    return v[()] if v.ndim == 0 else v


def _fastsim_reference(xi, eta, phi, fz, a_, b_, mu_, l1, l2, l3, shape, nx, ny, bound, grid,
                       scale, rect, return_tractions):  # fmt: skip
    """NumPy reference of :func:`fastsim` (validated, raveled inputs): the readable march, used
    for ``return_tractions=True``; the compiled march is tested against it."""
    n = xi.size
    l1, l2, l3 = (np.broadcast_to(x, (n,)) for x in (l1, l2, l3))
    fx = np.empty(n)
    fy = np.empty(n)
    mz = np.empty(n)
    slip_fraction = np.empty(n)
    if return_tractions:
        px_all = np.empty((n, ny, nx))
        py_all = np.empty((n, ny, nx))
        slip_all = np.empty((n, ny, nx), dtype=bool)
    else:
        px_all = py_all = slip_all = None

    if grid == "strips":
        eta_j, sq, tx, gy, norm = _grid_pattern(nx, ny, bound)
    step = max(1, _CHUNK_ELEMENTS // ny)
    for lo in range(0, n, step):
        sl = slice(lo, min(lo + step, n))
        store = None if px_all is None else (px_all[sl], py_all[sl], slip_all[sl])
        if grid == "strips":
            out = _march(
                xi[sl], eta[sl], phi[sl], fz[sl], a_[sl], b_[sl], mu_[sl],
                l1[sl], l2[sl], l3[sl], nx, eta_j, sq, tx, gy, norm, store,
            )  # fmt: skip
        else:
            out = _march_rect(
                xi[sl], eta[sl], phi[sl], fz[sl], a_[sl], b_[sl], mu_[sl],
                l1[sl], l2[sl], l3[sl], scale, rect, store,
            )  # fmt: skip
        fx[sl], fy[sl], mz[sl], slip_fraction[sl] = out

    def shaped(v):
        v = v.reshape(shape)
        return v[()] if v.ndim == 0 else v

    extra = {}
    if return_tractions:
        if grid == "strips":
            s_centre = (np.arange(nx) + 0.5) / nx  # fraction of the strip length from the lead
            a_strip = a_[:, None] * sq[None, :]  # (n, ny)
            x = a_strip[:, :, None] * (1.0 - 2.0 * s_centre)[None, None, :]
            y = np.broadcast_to((b_[:, None] * eta_j[None, :])[:, :, None], x.shape)
        else:
            xh, yh = rect[0], rect[1]
            x = np.broadcast_to(a_[:, None, None] * xh[None, None, :], (n, ny, nx))
            y = np.broadcast_to(b_[:, None, None] * yh[None, :, None], (n, ny, nx))
        grid_shape = (*shape, ny, nx)
        extra = {
            "x": np.array(x).reshape(grid_shape),
            "y": np.array(y).reshape(grid_shape),
            "px": px_all.reshape(grid_shape),
            "py": py_all.reshape(grid_shape),
            "slip": slip_all.reshape(grid_shape),
        }
    return FastsimResult(shaped(fx), shaped(fy), shaped(mz), shaped(slip_fraction), **extra)


def _limit_creepage(xi, eta, phi, a):
    """Creepages scaled down to magnitude :data:`_CREEP_MAX` where they exceed it (see there)."""
    with np.errstate(over="ignore"):
        size = np.maximum(np.maximum(np.abs(xi), np.abs(eta)), np.abs(phi) * a)
    over = size > _CREEP_MAX
    if not over.any():
        return xi, eta, phi
    scale = np.where(over, _CREEP_MAX / np.where(over, size, 1.0), 1.0)
    return xi * scale, eta * scale, phi * scale


def _check_flexibility(flexibility) -> list:
    """``[]`` for a valid model name, else the three validated explicit flexibilities."""
    if isinstance(flexibility, str):
        check_choice(flexibility, "flexibility", _FLEXIBILITIES)
        return []
    try:
        values = list(flexibility)
    except TypeError:
        values = None
    if values is None or len(values) != 3:
        raise ValueError(
            f"flexibility must be one of {sorted(_FLEXIBILITIES)} or a sequence of three "
            f"flexibilities (L1, L2, L3) in (0, inf) [m^3/N], got {flexibility!r}"
        )
    return [check_positive(v, f"flexibility L{k + 1}") for k, v in enumerate(values)]


def _check_scale(value) -> float:
    """``value`` as a float scalar >= 1, else ValueError naming ``scale``."""
    arr = check_range(value, "scale", 1.0, np.inf, closed="left")
    if arr.ndim != 0:
        raise ValueError(f"scale must be a scalar in [1.0, inf), got shape {arr.shape}")
    return float(arr)


def _check_count(value, name: str) -> int:
    """``value`` as an int >= 1, else ValueError naming ``name``."""
    try:
        k = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer in [1, inf), got {value!r}") from None
    if k < 1:
        raise ValueError(f"{name} must be an integer in [1, inf), got {k!r}")
    return k


def _clip_to_bound(px, py, g, slip, r, tmp):
    """Scale the tractions (px, py) back onto the bound ``g`` where ``|p| > g``, in place.

    The step shared by both grid layouts: ``slip`` receives the flags ``|p| > g``; the factor
    is ``min(1, g/|p|)``, so the traction keeps its direction. ``r`` and ``tmp`` are work
    arrays of the same shape (overwritten).
    """
    np.multiply(px, px, out=r)
    np.multiply(py, py, out=tmp)
    r += tmp
    np.sqrt(r, out=r)
    np.greater(r, g, out=slip)
    r += _TINY_TRACTION
    np.divide(g, r, out=tmp)
    np.minimum(tmp, 1.0, out=tmp)
    px *= tmp
    py *= tmp


def _store_column(store, i, px, py, slip) -> None:
    """Copy the tractions and slip flags of column ``i`` into the (m, ny, nx) ``store``."""
    store[0][:, :, i] = px
    store[1][:, :, i] = py
    store[2][:, :, i] = slip


def _march(xi, eta, phi, fz, a, b, mu, l1, l2, l3, nx, eta_j, sq, tx, gy, norm, store):
    """FASTSIM march for a chunk of m contacts; returns (fx, fy, mz, slip_fraction), each (m,).

    Working arrays have shape (m, ny). ``store`` is None or a tuple of (m, ny, nx) arrays
    receiving px, py and the slip flags.
    """
    col = np.newaxis
    dx = (2.0 / nx) * a[:, col] * sq  # element length per strip (m, ny)
    y = b[:, col] * eta_j  # strip centres (m, ny)
    a_strip = a[:, col] * sq
    phi_l3 = (phi / l3)[:, col]
    # constant increment of px per element: -dx (xi/L1 - phi y/L3)
    dpx = -dx * ((xi / l1)[:, col] - phi_l3 * y)
    # increment of py from centre i-1 to centre i (i >= 1), midpoint x = a(y) - i dx:
    # -dx (eta/L2 + phi (a(y) - i dx)/L3) = dpy0 + i dpy1
    dpy0 = -dx * ((eta / l2)[:, col] + phi_l3 * a_strip)
    dpy1 = phi_l3 * dx * dx
    # traction bound at cell (i, j): gfac[j] * tx[i]
    gfac = (mu * fz / (a * b * norm))[:, col] * gy

    # first half step, from the leading edge x = a(y) to the first centre (midpoint a - dx/4)
    px = 0.5 * dpx
    py = 0.5 * dpy0 + 0.125 * dpy1
    inc = dpy0.copy()  # dpy0 + i dpy1, updated in place
    spx = np.zeros_like(px)
    spy = np.zeros_like(px)
    qpy = np.zeros_like(px)  # running sum of the partial sums of py (for sum i py_i)
    nslip = np.zeros_like(px)
    r = np.empty_like(px)
    g = np.empty_like(px)
    tmp = np.empty_like(px)
    slip = np.empty(px.shape, dtype=bool)
    for i in range(nx):
        if i > 0:
            inc += dpy1
            px += dpx
            py += inc
        np.multiply(gfac, tx[i], out=g)
        _clip_to_bound(px, py, g, slip, r, tmp)
        spx += px
        spy += py
        qpy += spy
        nslip += slip
        if store is not None:
            _store_column(store, i, px, py, slip)

    dy = (2.0 / eta_j.size) * b  # (m,)
    da = dx * dy[:, col]  # cell area per strip (m, ny)
    fx = (spx * da).sum(axis=1)
    fy = (spy * da).sum(axis=1)
    # sum_i x_i py_i with x_i = a(y) - (i + 1/2) dx and sum_i i py_i = nx spy - qpy
    sum_xpy = a_strip * spy - dx * (nx * spy - qpy + 0.5 * spy)
    mz = ((sum_xpy - y * spx) * da).sum(axis=1)
    slip_fraction = np.minimum((nslip * sq).sum(axis=1) / (nx * sq.sum()), 1.0)
    return fx, fy, mz, slip_fraction


def _march_rect(xi, eta, phi, fz, a, b, mu, l1, l2, l3, scale, rect, store):
    """FASTSIM on CONTACT's rectangular grid for a chunk of m contacts.

    Returns (fx, fy, mz, slip_fraction), each (m,). Working arrays have shape (m, ny), one
    entry per grid row; the loop runs over the nx columns from the leading edge (+x).
    ``store`` is None or a tuple of (m, ny, nx) arrays receiving px, py and the slip flags.
    """
    xh, yh, mask, shape, n_in = rect
    nx, ny = mask.shape
    col = np.newaxis
    dx = (2.0 * scale / nx) * a  # (m,)
    dy = (2.0 * scale / ny) * b
    y = b[:, col] * yh  # row centres (m, ny)
    phi_l3 = phi / l3
    # constant increment of px per element: -dx (xi/L1 - phi y/L3)
    dpx = -dx[:, col] * ((xi / l1)[:, col] - phi_l3[:, col] * y)
    # increment of py at column i: -dx (eta/L2 + phi (a xh_i + dx/6)/L3), shape (nx, m, 1)
    dpy0 = -dx * (eta / l2 + phi_l3 * (_FACPHI * dx))
    dpy1 = -dx * phi_l3 * a
    dpy = (dpy0 + xh[:, col] * dpy1)[:, :, col]
    gfac = (mu * fz / (a * b))[:, col]  # bound at (i, j): gfac * shape[i, j]

    px = np.zeros_like(y)
    py = np.zeros_like(y)
    spx = np.zeros_like(y)
    spy = np.zeros_like(y)
    sxpy = np.zeros_like(y)  # sum_i xh_i py_i
    nslip = np.zeros_like(y)
    r = np.empty_like(y)
    g = np.empty_like(y)
    tmp = np.empty_like(y)
    slip = np.empty(y.shape, dtype=bool)
    for i in range(nx):
        m_i = mask[i]
        # step from the previous element; elements outside the contact reset to zero
        px += dpx
        px *= m_i
        py += dpy[i]
        py *= m_i
        np.multiply(gfac, shape[i], out=g)
        _clip_to_bound(px, py, g, slip, r, tmp)
        spx += px
        spy += py
        np.multiply(py, xh[i], out=tmp)
        sxpy += tmp
        nslip += slip
        if store is not None:
            _store_column(store, i, px, py, slip)

    da = dx * dy
    fx = spx.sum(axis=1) * da
    fy = spy.sum(axis=1) * da
    mz = (a * sxpy.sum(axis=1) - (y * spx).sum(axis=1)) * da
    slip_fraction = nslip.sum(axis=1) / n_in
    return fx, fy, mz, slip_fraction
