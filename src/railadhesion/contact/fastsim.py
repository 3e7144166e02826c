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
laws (the flexibilities, :func:`fastsim_flexibilities`; the marches on the strips and on
CONTACT's grid, :func:`fastsim_strips`, :func:`fastsim_rectangular`) are compiled (numba,
on first use) and looped over the contacts (:func:`march_strips`, :func:`march_rect`,
:func:`strips_one`, at the end of this module): the strips advance side
by side in the inner loop, and large batches of contacts run on several threads; one contact
given as scalars takes a short path (checks in plain Python, one compiled call). A NumPy
march (contacts and grid rows vectorised) is the tests' independent oracle
(``tests/oracles/fastsim.py``).

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
    check_positive,
    check_range,
)
from railadhesion.contact.kalker import (
    AOB_MAX,
    AOB_MIN,
    axis_ratio,
    check_rolling_inputs,
    creepage_docs,
    kalker_law,
)
from railadhesion.numerics import flatten, jitable, kernel, read_only, run_chunks
from railadhesion.plausibility import input_checker

__all__ = [
    "FastsimResult",
    "fastsim",
    "fastsim_bound",
    "fastsim_flexibilities",
    "fastsim_rectangular",
    "fastsim_strips",
    "limit_creepage",
]

_BOUNDS = ("parabolic", "elliptic")
_FLEXIBILITIES = ("original", "blended")
#: Flexibility mode of the compiled marches: explicit (L1, L2, L3) given per contact.
_FLEX_GIVEN = 2
_ONE = read_only(np.ones(1))
_GRIDS = ("strips", "rectangular")
#: CONTACT evaluates the spin part of the rigid slip a sixth of a step upstream of the element
#: centre, at x + dq/6 (input FACPHI, default 1/6: CONTACT ``m_sinput.f90``; used in
#: ``m_sdis.f90``, subroutine ``srztng``).
_FACPHI = 1.0 / 6.0
#: CONTACT evaluates the blending weight with spin in rad/mm; 1 rad/m = 1e-3 rad/mm.
_SPIN_TO_PER_MM = 1e-3
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


@jitable
def fastsim_flexibilities(a, b, xi, eta, phi, fz, mu, g_mod, c11, c22, c23, blended):
    """Kalker's three flexibilities (L1, L2, L3) [m^3/N] of one contact, blended towards one
    value as the creepage grows if ``blended`` (Vollebregt & Voltr 2023, CONTACT
    ``simpflex``); the formulas are in :func:`fastsim`, Notes. C11, C22, C23 are Kalker's
    coefficients of a/b (:func:`railadhesion.contact.kalker.kalker_law`)."""
    l1 = 8.0 * a / (3.0 * g_mod * c11)
    l2 = 8.0 * a / (3.0 * g_mod * c22)
    l3 = math.pi * a * math.sqrt(a / b) / (4.0 * g_mod * c23)
    if not blended:
        return l1, l2, l3
    spin_term = (phi * (3.0 * math.pi * a / 32.0)) ** 2  # (phi f4/f3)^2, f4/f3 = 3 pi a / 32
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
    # ch2 = 0 only when mu Fz = 0: then the bound is zero anyway and any weight will do
    f_crp = math.sqrt(crp2 / ch2) if ch2 > 0.0 else 0.0
    w = min(max(f_crp / 3.0, 0.0), 1.0)
    return ((1.0 - w) * l1 + w * l_crss, (1.0 - w) * l2 + w * l_crss,
            (1.0 - w) * l3 + w * l_crss)  # fmt: skip


@jitable
def limit_creepage(xi, eta, phi, a):
    """The creepages scaled down, all three by one factor, to magnitude :data:`_CREEP_MAX`
    where max(|xi|, |eta|, |phi| a) exceeds it (see there)."""
    size = max(max(abs(xi), abs(eta)), abs(phi) * a)
    scale = _CREEP_MAX / size if size > _CREEP_MAX else 1.0
    return xi * scale, eta * scale, phi * scale


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "normal_force", "a", "b", "mu",
                            "shear_modulus", "poisson"))


@labelled(units=FASTSIM_UNITS)
@creepage_docs
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
    {creepages}
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
    xi, eta, phi, fz, a_, b_, mu_, g_mod, nu = check_rolling_inputs(
        creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus, poisson
    )
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

    if not flx_given:
        axis_ratio(a_, b_)  # Kalker's coefficients are looked up: a/b in their range
    _PLAUSIBLE((xi, eta, phi, fz, a_, b_, mu_, g_mod, nu))  # implausible inputs warn
    shape, n, flat = flatten([xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, *flx_given])
    mode = _FLEX_GIVEN if flx_given else _FLEXIBILITIES.index(flexibility)
    flex = flat[9:] if flx_given else (_ONE, _ONE, _ONE)
    store = None
    if return_tractions:
        store = (np.empty((n, ny, nx)), np.empty((n, ny, nx)), np.empty((n, ny, nx), bool))
    if grid == "strips":
        pattern = _grid_pattern(nx, ny, bound)
        out = march_strips(*flat[:9], *flex, mode, pattern, store)
    else:
        out = march_rect(*flat[:9], *flex, mode, scale, rect, store)

    def shaped(v):
        v = v.reshape(shape)
        return v[()] if v.ndim == 0 else v

    extra = {}
    if return_tractions:
        a_ = np.broadcast_to(a_, shape).reshape(-1)
        b_ = np.broadcast_to(b_, shape).reshape(-1)
        if grid == "strips":
            eta_j, sq = pattern[0], pattern[1]
            s_centre = (np.arange(nx) + 0.5) / nx  # fraction of the strip length from the lead
            a_strip = a_[:, None] * sq[None, :]  # (n, ny)
            x = a_strip[:, :, None] * (1.0 - 2.0 * s_centre)[None, None, :]
            y = np.broadcast_to((b_[:, None] * eta_j[None, :])[:, :, None], x.shape)
        else:
            xh, yh = rect[0], rect[1]
            x = np.broadcast_to(a_[:, None, None] * xh[None, None, :], (n, ny, nx))
            y = np.broadcast_to(b_[:, None, None] * yh[None, :, None], (n, ny, nx))
        grid_shape = (*shape, ny, nx)
        extra = {"x": np.array(x).reshape(grid_shape), "y": np.array(y).reshape(grid_shape)}
        extra.update(zip(("px", "py", "slip"), (v.reshape(grid_shape) for v in store),
                         strict=True))  # fmt: skip
    return FastsimResult(*(shaped(v) for v in out), **extra)


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
    """:func:`fastsim` for one contact on the strips: checks in plain Python, one compiled
    call. ``None`` if any input is invalid or out of range: the caller's array path then
    raises the error naming it."""
    fin = math.isfinite
    if not (fin(xi) and fin(eta) and fin(phi) and fin(fz) and fin(a) and fin(b) and fin(mu)
            and fin(g_mod) and fz >= 0 and a > 0 and b > 0 and mu >= 0 and g_mod > 0
            and 0.0 <= nu <= 0.5 and nx >= 1 and ny >= 1 and bound in _BOUNDS
            and flexibility in _FLEXIBILITIES):  # fmt: skip
        return None
    if not AOB_MIN <= a / b <= AOB_MAX:
        return None
    out = strips_one(xi, eta, phi, fz, a, b, mu, g_mod, nu,
                             _FLEXIBILITIES.index(flexibility),
                             _grid_pattern(nx, ny, bound))  # fmt: skip
    return FastsimResult(*(np.float64(v) for v in out))


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


@jitable(inline="always")
def fastsim_bound(px, py, g):
    """A trial traction (px, py) scaled back onto the traction bound g where |p| > g, keeping
    its direction (Kalker 1982: the element slips): (px, py, slipping)."""
    r = math.sqrt(px * px + py * py)
    f = min(g / (r + _TINY_TRACTION), 1.0)
    return px * f, py * f, r > g


@jitable(inline="always")
def _settle(j, px_j, py_j, bound, px, py, spx, spy, slip, nslip):
    """One step of the marches at element j of a column: the traction ``(px_j, py_j)`` back
    onto the ``bound`` (:func:`fastsim_bound`) into ``px[j]``, ``py[j]``, its slip flag (1.0 or
    0.0) into ``slip[j]``, added to the sums ``spx[j]``, ``spy[j]`` and the slip count
    ``nslip[j]``. Returns the bounded py. Inlined where it is called (once per march), so that
    the loop over the strips stays one loop that vectorises."""
    pxj, pyj, slipping = fastsim_bound(px_j, py_j, bound)
    slip[j] = 1.0 if slipping else 0.0
    nslip[j] += slip[j]
    px[j] = pxj
    py[j] = pyj
    spx[j] += pxj
    spy[j] += pyj
    return pyj


@jitable(inline="always")
def _store_column(i, px, py, slip, px_out, py_out, slip_out):
    """Column i of the outputs of the marches (``store``): the tractions and the slip flags of
    the current column (inlined where it is called, once per march)."""
    for j in range(px.size):
        px_out[j, i] = px[j]
        py_out[j, i] = py[j]
        slip_out[j, i] = slip[j] != 0.0


# Rows of the work array of :func:`fastsim_strips` (ny values each).
_W_PX, _W_PY, _W_DPX, _W_DPY1, _W_INC, _W_GFAC, _W_SPX, _W_SPY, _W_QPY, _W_NSLIP = range(10)
_W_SLIP = 10  # the slip flags of the current column (1.0 or 0.0), for ``store``
#: Rows of the work array :func:`fastsim_strips` needs.
STRIPS_WORK_ROWS = 11


@jitable(inline="never")
def fastsim_strips(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm, work,
                   px_out, py_out, slip_out, store):  # fmt: skip
    """FASTSIM on Kalker's strips for one contact (Kalker 1982; layout in :func:`fastsim`,
    Notes): (fx, fy, mz, slip_fraction).

    ``eta_j, sq, tx, gy, norm`` are the grid factors of :func:`_grid_pattern`; ``work`` is a
    (:data:`STRIPS_WORK_ROWS`, ny) float64 scratch array. With ``store`` True the tractions
    and slip flags of the cells are written to ``px_out``, ``py_out``, ``slip_out`` (ny, nx).
    All strips advance side by side (the inner loop runs over the strips and vectorises).
    A plain function compiled where compiled code calls it.
    """
    ny = eta_j.size
    nx = tx.size
    px, py, dpx, dpy1 = work[_W_PX], work[_W_PY], work[_W_DPX], work[_W_DPY1]
    inc, gfac, spx, spy = work[_W_INC], work[_W_GFAC], work[_W_SPX], work[_W_SPY]
    qpy, nslip, slip = work[_W_QPY], work[_W_NSLIP], work[_W_SLIP]
    phi_l3 = phi / l3
    xi_l1 = xi / l1
    eta_l2 = eta / l2
    gf = mu * fz / (a * b * norm)  # traction bound at cell (i, j): gf gy[j] tx[i]
    for j in range(ny):
        dx = (2.0 / nx) * a * sq[j]  # element length of strip j
        y = b * eta_j[j]
        a_strip = a * sq[j]
        # constant increment of px per element: -dx (xi/L1 - phi y/L3); increment of py from
        # centre i-1 to centre i, at the midpoint x = a(y) - i dx: dpy0 + i dpy1
        dpx[j] = -dx * (xi_l1 - phi_l3 * y)
        dpy0 = -dx * (eta_l2 + phi_l3 * a_strip)
        dpy1[j] = phi_l3 * dx * dx
        gfac[j] = gf * gy[j]
        # first half step, from the leading edge x = a(y) to the first centre
        px[j] = 0.5 * dpx[j]
        py[j] = 0.5 * dpy0 + 0.125 * dpy1[j]
        inc[j] = dpy0
        spx[j] = 0.0
        spy[j] = 0.0
        qpy[j] = 0.0  # running sum of the partial sums of py (for sum_i i py_i)
        nslip[j] = 0.0
    for i in range(nx):
        t = tx[i]
        if i > 0:
            for j in range(ny):
                inc[j] += dpy1[j]
                px[j] += dpx[j]
                py[j] += inc[j]
        for j in range(ny):  # back onto the bound where |p| exceeds it (slip); vectorised
            _settle(j, px[j], py[j], gfac[j] * t, px, py, spx, spy, slip, nslip)
            qpy[j] += spy[j]
        if store:  # a loop of its own: a store in the loop above keeps it from vectorising
            _store_column(i, px, py, slip, px_out, py_out, slip_out)
    dy = (2.0 / ny) * b
    sfx = 0.0
    sfy = 0.0
    smz = 0.0
    sns = 0.0
    sq_sum = 0.0
    for j in range(ny):
        dx = (2.0 / nx) * a * sq[j]
        da = dx * dy
        y = b * eta_j[j]
        a_strip = a * sq[j]
        sfx += spx[j] * da
        sfy += spy[j] * da
        # sum_i x_i py_i with x_i = a(y) - (i + 1/2) dx and sum_i i py_i = nx spy - qpy
        sum_xpy = a_strip * spy[j] - dx * (nx * spy[j] - qpy[j] + 0.5 * spy[j])
        smz += (sum_xpy - y * spx[j]) * da
        sns += nslip[j] * sq[j]
        sq_sum += sq[j]
    return sfx, sfy, smz, min(sns / (nx * sq_sum), 1.0)


# Rows of the work array of :func:`fastsim_rectangular` (ny values each).
_R_PX, _R_PY, _R_DPX, _R_SPX, _R_SPY, _R_SXPY, _R_NSLIP, _R_SLIP = range(8)
#: Rows of the work array :func:`fastsim_rectangular` needs.
RECT_WORK_ROWS = 8


@jitable(inline="never")
def fastsim_rectangular(xi, eta, phi, fz, a, b, mu, l1, l2, l3, scale, xh, yh, mask, shape,
                        n_in, work, px_out, py_out, slip_out, store):  # fmt: skip
    """FASTSIM on CONTACT's rectangular grid for one contact (CONTACT ``m_solvpt.f90``,
    ``modif_fastsim``; layout in :func:`fastsim`, Notes): (fx, fy, mz, slip_fraction).

    ``xh, yh, mask, shape, n_in`` are the grid factors of :func:`_rect_pattern`; ``work`` is a
    (:data:`RECT_WORK_ROWS`, ny) float64 scratch array; ``store`` as :func:`fastsim_strips`.
    Each grid row is marched from the leading edge (+x), all rows side by side. A plain
    function compiled where compiled code calls it.
    """
    nx = xh.size
    ny = yh.size
    px, py, dpx, spx = work[_R_PX], work[_R_PY], work[_R_DPX], work[_R_SPX]
    spy, sxpy, nslip, slip = work[_R_SPY], work[_R_SXPY], work[_R_NSLIP], work[_R_SLIP]
    dx = (2.0 * scale / nx) * a
    dy = (2.0 * scale / ny) * b
    phi_l3 = phi / l3
    xi_l1 = xi / l1
    for j in range(ny):
        # constant increment of px per element: -dx (xi/L1 - phi y/L3)
        dpx[j] = -dx * (xi_l1 - phi_l3 * (b * yh[j]))
        px[j] = 0.0
        py[j] = 0.0
        spx[j] = 0.0
        spy[j] = 0.0
        sxpy[j] = 0.0  # sum_i xh_i py_i
        nslip[j] = 0.0
    # increment of py at column i: -dx (eta/L2 + phi (a xh_i + dx/6)/L3) = dpy0 + xh_i dpy1
    dpy0 = -dx * (eta / l2 + phi_l3 * (_FACPHI * dx))
    dpy1 = -dx * phi_l3 * a
    gfac = mu * fz / (a * b)  # bound at (i, j): gfac shape[i, j]
    for i in range(nx):
        dpy = dpy0 + xh[i] * dpy1
        for j in range(ny):
            # step from the previous element; elements outside the contact reset to zero
            m = mask[i, j]
            pyj = _settle(j, (px[j] + dpx[j]) * m, (py[j] + dpy) * m, gfac * shape[i, j], px,
                          py, spx, spy, slip, nslip)  # fmt: skip
            sxpy[j] += pyj * xh[i]
        if store:  # a loop of its own, as in fastsim_strips
            _store_column(i, px, py, slip, px_out, py_out, slip_out)
    da = dx * dy
    sx = 0.0
    sy = 0.0
    sxy = 0.0
    syx = 0.0
    sns = 0.0
    for j in range(ny):
        sx += spx[j]
        sy += spy[j]
        sxy += sxpy[j]
        syx += (b * yh[j]) * spx[j]
        sns += nslip[j]
    return sx * da, sy * da, (a * sxy - syx) * da, sns / n_in


# --- the loops over contacts (compiled on first use) ------------------------------------------

#: From this many contacts the FASTSIM marches run on several threads.
FASTSIM_PARALLEL_MIN = 500
#: Contacts per chunk of the FASTSIM drivers.
FASTSIM_CHUNK = 16


@jitable
def _at(x, c):
    """x[c], or x[0] for an array of one value shared by every contact."""
    return x[c] if x.size > 1 else x[0]


@jitable
def _contact_flexibilities(xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode, c):
    """Contact c's creepages (limited, :func:`limit_creepage`)
    and flexibilities: Kalker's (mode 0), blended (1) or given in l1, l2, l3 (2)."""
    x, y, p = limit_creepage(_at(xi, c), _at(eta, c), _at(phi, c), _at(a, c))
    if mode == 2:
        return x, y, p, _at(l1, c), _at(l2, c), _at(l3, c)
    ac = _at(a, c)
    bc = _at(b, c)
    c11, c22, c23, _ = kalker_law(ac / bc, _at(nu, c))
    f1, f2, f3 = fastsim_flexibilities(ac, bc, x, y, p, _at(fz, c), _at(mu, c), _at(g, c), c11,
                                       c22, c23, mode == 1)  # fmt: skip
    return x, y, p, f1, f2, f3


@kernel(nogil=True)
def _march_chunks(xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode, rect, p1, p2, p3, p4, q1,
                  q2, s1, s2, out, px_out, py_out, slip_out, store, first, last):  # fmt: skip
    """FASTSIM of the contacts of chunks first to last - 1 (of FASTSIM_CHUNK contacts) into out
    (4, n): fx, fy, mz, slip fraction; the tractions and slip flags into px_out, py_out,
    slip_out (n, ny, nx) if ``store``. The layout's factors: on the strips (``rect`` False,
    :func:`fastsim_strips`) p1-p4 = eta_j, sq, tx, gy and s1 = norm; on CONTACT's grid
    (:func:`fastsim_rectangular`) p1, p2 = xh, yh, q1, q2 = mask, shape, s1, s2 = scale,
    n_in."""
    work = np.empty((max(STRIPS_WORK_ROWS, RECT_WORK_ROWS), p2.size))
    for c in range(first * FASTSIM_CHUNK, min(last * FASTSIM_CHUNK, out.shape[1])):
        x, y, p, f1, f2, f3 = _contact_flexibilities(xi, eta, phi, fz, a, b, mu, g, nu, l1, l2,
                                                     l3, mode, c)  # fmt: skip
        k = c if store else 0
        if rect:
            res = fastsim_rectangular(x, y, p, _at(fz, c), _at(a, c), _at(b, c), _at(mu, c), f1,
                                      f2, f3, s1, p1, p2, q1, q2, s2, work, px_out[k],
                                      py_out[k], slip_out[k], store)  # fmt: skip
        else:
            res = fastsim_strips(x, y, p, _at(fz, c), _at(a, c), _at(b, c), _at(mu, c), f1, f2,
                                 f3, p1, p2, p3, p4, s1, work, px_out[k], py_out[k],
                                 slip_out[k], store)  # fmt: skip
        out[0, c], out[1, c], out[2, c], out[3, c] = res
    return 0


def _run(inputs, rect, vectors, grids, scalars, store):
    """Run the FASTSIM loop over the contacts; ``inputs`` the 12 per-contact arrays (length n
    or 1) and the mode, then the layout's factors. Returns (fx, fy, mz, slip fraction)."""
    n = max(x.size for x in inputs[:12])
    out = np.empty((4, n))
    if store is None:
        store = (np.empty((1, 1, 1)), np.empty((1, 1, 1)), np.empty((1, 1, 1), bool), False)
    else:
        store = (*store, True)
    run_chunks(_march_chunks, (*inputs, rect, *vectors, *grids, *scalars, out, *store),
               -(-n // FASTSIM_CHUNK), n >= FASTSIM_PARALLEL_MIN)  # fmt: skip
    return out


_NO_GRID = np.zeros((1, 1))


def march_strips(xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode, pattern, store=None):
    """FASTSIM on Kalker's strips for n contacts: read-only 1-d float64 arrays of length n or
    1 (:func:`railadhesion.numerics.flatten`), validated; ``mode`` 0 (Kalker's
    flexibilities), 1 (blended) or 2 (l1, l2, l3 given; else they are ignored); ``pattern``
    from :func:`_grid_pattern`; ``store`` None or (px, py, slip) arrays (n, ny, nx) for
    the tractions and slip flags. Returns (fx, fy, mz, slip_fraction) as a (4, n) array."""
    eta_j, sq, tx, gy, norm = pattern
    return _run((xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode), False,
                (eta_j, sq, tx, gy), (_NO_GRID, _NO_GRID), (float(norm), 0.0), store)


def march_rect(xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode, scale, rect, store=None):
    """FASTSIM on CONTACT's rectangular grid for n contacts; as :func:`march_strips`, ``rect``
    from :func:`_rect_pattern`."""
    xh, yh, mask, shape, n_in = rect
    return _run((xi, eta, phi, fz, a, b, mu, g, nu, l1, l2, l3, mode), True, (xh, yh, xh, yh),
                (mask, shape), (float(scale), float(n_in)), store)


@kernel
def _strips_one(xi, eta, phi, fz, a, b, mu, g, nu, mode, eta_j, sq, tx, gy, norm):
    x, y, p = limit_creepage(xi, eta, phi, a)
    c11, c22, c23, _ = kalker_law(a / b, nu)
    f1, f2, f3 = fastsim_flexibilities(a, b, x, y, p, fz, mu, g, c11, c22, c23, mode == 1)
    work = np.empty((STRIPS_WORK_ROWS, eta_j.size))
    none = np.empty((1, 1))
    return fastsim_strips(x, y, p, fz, a, b, mu, f1, f2, f3, eta_j, sq, tx, gy, norm, work, none,
                          none, none > 0.0, False)  # fmt: skip


def strips_one(xi, eta, phi, fz, a, b, mu, g, nu, mode, pattern):
    """FASTSIM on Kalker's strips for one contact given as valid floats, Kalker's (mode 0) or
    blended (1) flexibilities: (fx, fy, mz, slip_fraction)."""
    eta_j, sq, tx, gy, norm = pattern
    return _strips_one(xi, eta, phi, fz, a, b, mu, g, nu, mode, eta_j, sq, tx, gy, float(norm))
