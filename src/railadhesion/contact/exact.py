"""Exact tangential solver for steady rolling on the elastic half-space (Kalker's theory).

This is the "exact" theory of Kalker (1990), as solved by Vollebregt's CONTACT program in its
default mode, for two bodies of identical (quasi-identical) elastic materials:

* the normal pressure is Hertz's (quasi-identity uncouples normal and tangential problems);
* the contact area is covered with rectangular elements of size ``dx x dy`` carrying
  piecewise-constant tractions; the tangential displacement differences follow from the
  influence coefficients of the half-space for a uniform tangential load on a rectangle
  (:func:`tangential_influence`, closed forms integrated from Cerruti's point-load solution);
* steady rolling in +x: the slip of element I, per unit rolling distance, is the rigid slip
  plus the rolling difference quotient of the displacement difference,
  ``s_I = w_I + (u_I - u_{I+})/dx`` with ``I+`` the neighbour on the leading side (CONTACT's
  ``ss = ws + (u - u')`` with ``u'`` the displacement one step ``dq = dx`` upstream);
* Coulomb's law: ``|p| <= mu p_n``; ``s = 0`` where ``|p| < mu p_n`` (stick), else
  ``p = -mu p_n s/|s|`` (slip).

The contact problem is solved by one of two solvers of the same discrete equations
(``exact_rolling(method=...)``). An element-wise Gauss-Seidel iteration, sweeping from the
trailing to the leading edge, with the exact local solution of Coulomb's law per element
(stick trial, else a scalar Newton iteration for the slip direction), in numba-compiled code;
its influence sums by FFT along the columns of the grid (convolution in y, zero padded; the
Toeplitz structure of the coefficients, as in CONTACT: Vollebregt, J. Comput. Phys. 257, 2014),
which leaves the iteration unchanged and costs O(nx ny (nx + ny)) per sweep instead of
O((nx ny)^2) (``_gauss_seidel``). Or a semismooth Newton method with GMRES and 2-D FFT
products (:mod:`railadhesion.contact.rolling_newton`), started from a coarser grid's
solution: few steps whatever the grid, the default from 40 x 40 elements.

Extensions, as in CONTACT: slip-velocity dependent (falling) friction, solved by an outer
fixed-point iteration on the slip-velocity field (:func:`exact_rolling`, Notes); and the
discrete normal problem on the grid (:func:`solve_normal`, ``pressure="discrete"``), with
which the solver reproduces CONTACT's published Hertzian results to the digits printed.

Sign convention (``docs/CONVENTIONS.md``): forces exerted by the rail on the wheel, opposing
the creepages; at small creepage ``Fx = -G c^2 C11 xi``, ``Fy = -G c^2 C22 eta - G c^3 C23 phi``,
``Mz = G c^3 C23 eta - G c^4 C33 phi`` (Kalker's linear theory).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from railadhesion._validate import (
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.contact.friction import falling_friction_factor
from railadhesion.contact.kalker import check_creepages, check_rolling_inputs
from railadhesion.contact.rolling_newton import (
    DenseRolling,
    RollingOperator,
    cap_rigid_slip,
    solve_steady_rolling,
    solve_steady_rolling_batch,
)
from railadhesion.numerics import jit, jitable
from railadhesion.plausibility import input_checker

__all__ = [
    "ExactResult",
    "NormalSolution",
    "exact_rolling",
    "hertz_curvatures",
    "normal_influence",
    "solve_normal",
    "solve_tangential",
    "tangential_influence",
]

#: CONTACT evaluates the spin part of the rigid slip a sixth of a step upstream of the element
#: centre, at x + dq/6 (input FACPHI, default 1/6: CONTACT ``m_sinput.f90``, ``m_sdis.f90``).
SPIN_OFFSET_CONTACT = 1.0 / 6.0

# element states
_EXTERIOR, _STICK, _SLIP = 0, 1, 2


# ---------------------------------------------------------------------------------------------
# Influence coefficients
# ---------------------------------------------------------------------------------------------


@jit(error_model="python", inline="always")
def _ylnxr(x, y):
    """``y ln(x + r)``, ``r = sqrt(x^2 + y^2)``; 0 for y = 0; no cancellation for x < 0."""
    if y == 0.0:
        return 0.0
    r = math.sqrt(x * x + y * y)
    if x >= 0.0:
        return y * math.log(x + r)
    return y * math.log(y * y / (r - x))


@jit(error_model="python", inline="always")
def _prim_xx(x, y, nu):
    """Primitive of ``(1-nu)/r + nu x^2/r^3`` in x and y: ``y ln(x+r) + (1-nu) x ln(y+r)``."""
    return _ylnxr(x, y) + (1.0 - nu) * _ylnxr(y, x)


@jit(error_model="python")
def _influence_point(x, y, hx, hy, nu):
    """(Axx, Axy, Ayy) * pi * G at offset (x, y) of a (2hx x 2hy) element with unit traction."""
    xp, xm, yp, ym = x + hx, x - hx, y + hy, y - hy
    axx = _prim_xx(xp, yp, nu) - _prim_xx(xm, yp, nu) - _prim_xx(xp, ym, nu) + _prim_xx(xm, ym, nu)
    ayy = _prim_xx(yp, xp, nu) - _prim_xx(ym, xp, nu) - _prim_xx(yp, xm, nu) + _prim_xx(ym, xm, nu)
    rpp = math.sqrt(xp * xp + yp * yp)
    rmp = math.sqrt(xm * xm + yp * yp)
    rpm = math.sqrt(xp * xp + ym * ym)
    rmm = math.sqrt(xm * xm + ym * ym)
    axy = -nu * (rpp - rmp - rpm + rmm)
    return axx, axy, ayy


@jit(error_model="python")
def _influence_array(x, y, hx, hy, nu, out_xx, out_xy, out_yy):
    for k in range(x.size):
        out_xx[k], out_xy[k], out_yy[k] = _influence_point(x[k], y[k], hx, hy, nu[k])


def _influence(x, y, dx, dy, poisson, shear_modulus, *, with_nu: bool):
    """Validated inputs of the influence functions and the rectangle integrals.

    Returns ``(nu, G, shape, (axx, axy, ayy))``: the broadcast Poisson's ratio, the shear
    modulus, the broadcast shape of ``x, y, nu`` and the corner sums of
    :func:`_influence_point` (flat), evaluated with that ``nu`` if ``with_nu``, else with
    nu = 0.
    """
    x_, y_, nu = np.broadcast_arrays(
        check_finite(x, "x"), check_finite(y, "y"), check_range(poisson, "poisson", 0.0, 0.5)
    )
    dx_ = float(check_positive(dx, "dx"))
    dy_ = float(check_positive(dy, "dy"))
    g = float(check_positive(shear_modulus, "shear_modulus"))
    shape = x_.shape
    xf, yf = (np.ascontiguousarray(v, dtype=float).ravel() for v in (x_, y_))
    nuf = np.ascontiguousarray(nu, dtype=float).ravel() if with_nu else np.zeros_like(xf)
    axx, axy, ayy = np.empty_like(xf), np.empty_like(xf), np.empty_like(xf)
    _influence_array(xf, yf, 0.5 * dx_, 0.5 * dy_, nuf, axx, axy, ayy)
    return nu, g, shape, (axx, axy, ayy)


def tangential_influence(x, y, dx, dy, poisson=0.28, shear_modulus=8.2e10):
    """Tangential influence coefficients of the half-space for a uniform load on a rectangle.

    Displacement difference ``u = u(1) - u(2)`` of two identical elastic half-spaces at the
    surface point ``(x, y)``, caused by a uniform tangential traction of 1 Pa acting on the
    rectangle ``[-dx/2, dx/2] x [-dy/2, dy/2]`` (and its opposite on the other body).

    Parameters
    ----------
    x, y : array_like
        Position of the field point relative to the centre of the loaded rectangle [m].
    dx, dy : float
        Size of the rectangle along x and y [m], > 0.
    poisson : array_like, optional
        Poisson's ratio nu [-], in [0, 0.5]. Default 0.28.
    shear_modulus : float, optional
        Shear modulus G [Pa], > 0. Default 82 GPa.

    Returns
    -------
    axx, axy, ayy : ndarray
        ``u_x = axx p_x + axy p_y``, ``u_y = axy p_x + ayy p_y`` [m/Pa] (``ayx = axy``).

    Notes
    -----
    Cerruti's point load Q_x on a half-space gives the surface displacements
    ``u_x = Q_x/(2 pi G) ((1-nu)/r + nu x^2/r^3)``, ``u_y = Q_x/(2 pi G) nu x y/r^3``
    (Johnson, *Contact Mechanics*, 1985, eq. 2.19 at z = 0); two identical bodies double them.
    Integrated over the rectangle (Love 1929; Kalker 1990, section 5.2; Johnson 1985,
    section 3.6) with the primitives

    * ``(1-nu)/r + nu x^2/r^3``  ->  ``y ln(x + r) + (1-nu) x ln(y + r)``,
    * ``x y/r^3``  ->  ``-r``,

    evaluated at the four corners (``F(x+hx, y+hy) - F(x-hx, y+hy) - F(x+hx, y-hy) +
    F(x-hx, y-hy)``, ``hx = dx/2``, ``hy = dy/2``), and ``u = (1/(pi G)) (...)``. Checked
    against a numerical quadrature of the point-load solution in the tests.
    """
    _, g, shape, sums = _influence(x, y, dx, dy, poisson, shear_modulus, with_nu=True)
    f = 1.0 / (math.pi * g)
    return tuple((f * v).reshape(shape) for v in sums)


def normal_influence(x, y, dx, dy, poisson=0.28, shear_modulus=8.2e10):
    """Normal influence coefficient of the half-space for a uniform pressure on a rectangle.

    Normal displacement difference (approach of the surfaces) of two identical elastic
    half-spaces at the surface point ``(x, y)``, caused by a uniform pressure of 1 Pa on the
    rectangle ``[-dx/2, dx/2] x [-dy/2, dy/2]`` (Love 1929; Johnson 1985, eq. 3.25 for one
    body): ``(1 - nu)/(pi G) * integral of 1/r over the rectangle`` [m/Pa]. Parameters as in
    :func:`tangential_influence`.
    """
    # with nu = 0 the tangential xx-coefficient is the integral of 1/r over the rectangle
    nu, g, shape, (axx, _, _) = _influence(x, y, dx, dy, poisson, shear_modulus, with_nu=False)
    return ((1.0 - nu) / (math.pi * g)) * axx.reshape(shape)


def _grid_cells(field: np.ndarray, name: str, dx, dy) -> tuple[int, int, float, float]:
    """``(ny, nx, dx, dy)`` of a field on the element grid: ``field`` (named ``name`` in the
    error) must be 2-D, (ny, nx); the element sizes ``dx``, ``dy`` [m] must be > 0."""
    if field.ndim != 2:
        raise ValueError(f"{name} must be a 2-D array (ny, nx), got shape {field.shape}")
    ny, nx = field.shape
    return ny, nx, float(check_positive(dx, "dx")), float(check_positive(dy, "dy"))


@dataclass(frozen=True)
class NormalSolution:
    """Result of :func:`solve_normal`."""

    pressure: np.ndarray
    """Normal pressure p_n at the element centres [Pa], shape (ny, nx)."""
    approach: float
    """Approach of the bodies (penetration) [m]."""
    iterations: int
    """Active-set iterations used."""


def solve_normal(gap, dx, dy, normal_force, *, shear_modulus=8.2e10, poisson=0.28, max_iter=200):
    """Discrete normal contact problem (frictionless, prescribed normal force).

    Finds the pressure ``p_n >= 0`` and the approach ``delta`` of two identical elastic
    half-spaces with ``h_I - delta + u_I = 0`` where ``p_n > 0`` and ``>= 0`` elsewhere,
    ``sum(p_n) dx dy = Fz`` (Kalker 1990, section 5.2; CONTACT's normal problem with
    prescribed force), on a grid of ``ny x nx`` equal rectangles with piecewise-constant
    pressure (:func:`normal_influence`). Solved by an active-set iteration with a dense
    direct solve per iteration (grids up to a few thousand elements).

    Parameters
    ----------
    gap : array_like
        Undeformed distance h [m] at the element centres, shape (ny, nx).
    dx, dy : float
        Element size [m].
    normal_force : float
        Fz [N], > 0.
    shear_modulus, poisson : float, optional
        Combined G [Pa] and nu [-] of the (identical) materials.
    max_iter : int, optional
        Largest number of active-set iterations.

    Returns
    -------
    NormalSolution
    """
    h = check_finite(gap, "gap")
    ny, nx, dx_, dy_ = _grid_cells(h, "gap", dx, dy)
    fz = float(check_positive(normal_force, "normal_force"))
    g = float(check_positive(shear_modulus, "shear_modulus"))
    nu = float(check_range(poisson, "poisson", 0.0, 0.5))
    ix = np.arange(nx)
    iy = np.arange(ny)
    # coefficients for every offset, then the dense matrix by lookup
    ox = (np.arange(-(nx - 1), nx) * dx_)[None, :]
    oy = (np.arange(-(ny - 1), ny) * dy_)[:, None]
    coef = normal_influence(ox, oy, dx_, dy_, poisson=nu, shear_modulus=g)
    jj, ii = np.meshgrid(iy, ix, indexing="ij")
    jj, ii = jj.ravel(), ii.ravel()
    mat = coef[jj[:, None] - jj[None, :] + ny - 1, ii[:, None] - ii[None, :] + nx - 1]
    hf = h.ravel()
    n = hf.size
    active = hf <= np.min(hf) + 0.5 * (np.max(hf) - np.min(hf))  # initial guess
    p = np.zeros(n)
    delta = 0.0
    total = fz / (dx_ * dy_)
    iterations = 0
    for _ in range(int(max_iter)):
        iterations += 1
        idx = np.flatnonzero(active)
        m = idx.size
        sys = np.empty((m + 1, m + 1))
        sys[:m, :m] = mat[np.ix_(idx, idx)]
        sys[:m, m] = -1.0
        sys[m, :m] = 1.0
        sys[m, m] = 0.0
        rhs = np.concatenate([-hf[idx], [total]])
        sol = np.linalg.solve(sys, rhs)
        p[:] = 0.0
        p[idx] = sol[:m]
        delta = sol[m]
        neg = p < 0.0
        gap_def = hf - delta + mat @ p
        pen = (~active) & (gap_def < -1e-12 * max(abs(delta), 1e-30))
        if not neg.any() and not pen.any():
            break
        active = (active & ~neg) | pen
    else:
        raise RuntimeError(f"solve_normal: no convergence in {max_iter} iterations")
    return NormalSolution(p.reshape(ny, nx), float(delta), iterations)


@jit(error_model="python")
def _rolling_kernel(mx, my, dx, dy, nu):
    """Kernel of the steady-rolling slip, times G: ``s_I = w_I + sum_J K(I - J) p_J / G``.

    ``K(d) = (A(d) - A(d + e_x))/dx`` with ``A`` the influence coefficients (times G),
    returned as arrays of shape (2 my - 1, 2 mx - 1) indexed ``[dj + my - 1, di + mx - 1]``.
    """
    ny_off = 2 * my - 1
    nx_off = 2 * mx  # di = -(mx-1) ... mx
    axx = np.empty((ny_off, nx_off))
    axy = np.empty((ny_off, nx_off))
    ayy = np.empty((ny_off, nx_off))
    hx, hy = 0.5 * dx, 0.5 * dy
    f = 1.0 / math.pi
    for j in range(ny_off):
        yy = (j - (my - 1)) * dy
        for i in range(nx_off):
            xx = (i - (mx - 1)) * dx
            a1, a2, a3 = _influence_point(xx, yy, hx, hy, nu)
            axx[j, i] = f * a1
            axy[j, i] = f * a2
            ayy[j, i] = f * a3
    kxx = np.empty((ny_off, nx_off - 1))
    kxy = np.empty((ny_off, nx_off - 1))
    kyy = np.empty((ny_off, nx_off - 1))
    for j in range(ny_off):
        for i in range(nx_off - 1):
            kxx[j, i] = (axx[j, i] - axx[j, i + 1]) / dx
            kxy[j, i] = (axy[j, i] - axy[j, i + 1]) / dx
            kyy[j, i] = (ayy[j, i] - ayy[j, i + 1]) / dx
    return kxx, kxy, kyy


@jit(error_model="python")
def _gs_diagonal(ratio, nu):
    """Diagonal (x, y) used in the Gauss-Seidel update, for dx = 1 and dy = ``ratio``.

    The true diagonal of the rolling operator, (A(0) - A(e_x))/dx, is as large as the
    coupling to the trailing neighbour, -(A(0) - A(e_x))/dx, and plain Gauss-Seidel diverges.
    The self-displacement A(0)/dx instead (the element's effect on its upstream neighbour is
    lagged), enlarged by ``1 + (dx/dy - 1)/4`` for elements long in x (dy < dx), gives a
    convergent iteration: spectral radius 0.76-0.91 in the stick state, sweeping from the
    trailing edge, for 0.2 <= dy/dx <= 5 on grids up to 30 x 30 (measured on the dense
    iteration matrix). Any positive diagonal leaves the solution unchanged; the solver
    enlarges it further if the iteration diverges.
    """
    a0x, _, a0y = _influence_point(0.0, 0.0, 0.5, 0.5 * ratio, nu)
    fac = 1.0 if ratio >= 1.0 else 1.0 + 0.25 * (1.0 / ratio - 1.0)
    return fac * a0x / math.pi, fac * a0y / math.pi


# ---------------------------------------------------------------------------------------------
# Solver
# ---------------------------------------------------------------------------------------------


@jit(error_model="python")
def _local_slip(ssx, ssy, kx, ky, g):
    """Traction on the bound |p| = g with p = -g s/|s|, s = ss + diag(kx, ky) p.

    Writing p = g e, s = -lam e (lam >= 0): ``e = -ss/(lam + g k)``, and lam solves
    ``(ssx/(lam + g kx))^2 + (ssy/(lam + g ky))^2 = 1`` (convex, decreasing: Newton from
    below converges monotonically). The root lies in ``[|ss| - g max(k), |ss| - g min(k)]``:
    Newton starts from the lower end (or 0), so that ``ss/(lam + g k)`` stays of order one
    even when the slip dwarfs the bound (friction fallen to 1e-300), where a start from 0
    overflowed in the squares.
    """
    lam = max(0.0, math.hypot(ssx, ssy) - g * max(kx, ky))
    for _ in range(60):
        dx_ = lam + g * kx
        dy_ = lam + g * ky
        tx = ssx / dx_
        ty = ssy / dy_
        f = tx * tx + ty * ty - 1.0
        df = -2.0 * (tx * tx / dx_ + ty * ty / dy_)
        step = f / df
        lam -= step
        if lam < 0.0:
            lam = 0.0
        if abs(step) <= 1e-15 * (lam + g * (kx + ky)):
            break
    ex = -ssx / (lam + g * kx)
    ey = -ssy / (lam + g * ky)
    nrm = math.sqrt(ex * ex + ey * ey)
    if nrm > 0.0:
        ex /= nrm
        ey /= nrm
    return g * ex, g * ey


# ---------------------------------------------------------------------------------------------
# Influence sums by FFT along the columns
# ---------------------------------------------------------------------------------------------


@jit(error_model="python")
def _fft_tables(n):
    """Twiddle factors exp(-2 pi i k/n), k < n/2 (real, imaginary parts), and the bit-reversal
    permutation, for FFTs of length n = 2^m."""
    twr = np.ones(max(n // 2, 1))
    twi = np.zeros(max(n // 2, 1))
    for k in range(n // 2):
        t = -2.0 * math.pi * k / n
        twr[k] = math.cos(t)
        twi[k] = math.sin(t)
    rev = np.zeros(n, np.int64)
    bits = 0
    while (1 << bits) < n:
        bits += 1
    for i in range(n):
        r = 0
        v = i
        for _ in range(bits):
            r = (r << 1) | (v & 1)
            v >>= 1
        rev[i] = r
    return twr, twi, rev


@jit(error_model="python", fastmath=True)
def _fft(re, im, twr, twi, rev, sign):
    """In-place radix-2 FFT of ``re + i im`` (length n = 2^m; Cooley & Tukey 1965, iterative
    form): ``X_k = sum_j x_j exp(-sign 2 pi i jk/n)``, sign = 1 forward, -1 inverse (without
    the factor 1/n)."""
    n = re.size
    for i in range(n):
        j = rev[i]
        if j > i:
            t = re[i]
            re[i] = re[j]
            re[j] = t
            t = im[i]
            im[i] = im[j]
            im[j] = t
    half = 1
    while half < n:
        step = n // (2 * half)
        for start in range(0, n, 2 * half):
            for k in range(half):
                wr = twr[k * step]
                wi = sign * twi[k * step]
                a = start + k
                b = a + half
                vr = wr * re[b] - wi * im[b]
                vi = wr * im[b] + wi * re[b]
                re[b] = re[a] - vr
                im[b] = im[a] - vi
                re[a] += vr
                im[a] += vi
        half *= 2


@jit(error_model="python")
def _kernel_spectra(kxx, kxy, kyy):
    """Column-wise Fourier transforms of the rolling kernel, for the influence sums by FFT.

    The slip change of column ``jx`` caused by a traction change ``dp`` of column ``ix`` is a
    convolution along y with the kernel column ``K(., jx - ix)``: with the complex traction
    ``z = dp_x + i dp_y`` and slip ``s_x + i s_y`` it is ``P * z + Q * conj(z)``, with
    ``P = (K_xx + K_yy)/2`` and ``Q = (K_xx - K_yy)/2 + i K_xy``. Zero padding to a length
    ``n >= 2 my - 1`` (a power of two) makes the circular convolution the linear one.
    ``K_xx`` and ``K_yy`` are even in y and ``K_xy`` odd (the half-space is symmetric about
    the x axis), so the spectra of P and Q are real.
    Returns ``(phat, qhat, twr, twi, rev)``: the spectra of P and Q for every column offset,
    shape (2 mx - 1, n), scaled by 1/n (the inverse FFT's factor), and the FFT tables.
    """
    ny_off, nx_off = kxx.shape
    my = (ny_off + 1) // 2
    n = 1
    while n < ny_off:
        n *= 2
    twr, twi, rev = _fft_tables(n)
    phat = np.zeros((nx_off, n))
    qhat = np.zeros((nx_off, n))
    re = np.empty(n)
    im = np.empty(n)
    for k in range(nx_off):
        for which in range(2):
            re[:] = 0.0
            im[:] = 0.0
            for d in range(ny_off):
                pos = (d - (my - 1)) % n
                if which == 0:
                    re[pos] = 0.5 * (kxx[d, k] + kyy[d, k]) / n
                else:
                    re[pos] = 0.5 * (kxx[d, k] - kyy[d, k]) / n
                    im[pos] = kxy[d, k] / n
            _fft(re, im, twr, twi, rev, 1.0)
            if which == 0:
                phat[k, :] = re
            else:
                qhat[k, :] = re
    return phat, qhat, twr, twi, rev


@jit(error_model="python", fastmath=True)
def _push_column(pr_, pi_, zr, zi, cr, ci, ix, cmin, cmax, phat, qhat, spec_fft, mx, skip_self):
    """Add the effect of the traction change ``zr + i zi`` (column ``ix``, zero padded) to the
    pending slip spectra ``pr_ + i pi_`` of the columns ``cmin..cmax`` (except ``ix`` itself
    when ``skip_self``). ``zr, zi`` are transformed in place; ``cr, ci`` are work arrays."""
    twr, twi, rev = spec_fft
    n = zr.size
    _fft(zr, zi, twr, twi, rev, 1.0)
    cr[0] = zr[0]  # conj(Z(-f))
    ci[0] = -zi[0]
    for f in range(1, n):
        cr[f] = zr[n - f]
        ci[f] = -zi[n - f]
    for jx in range(cmin, cmax + 1):
        if skip_self and jx == ix:
            continue
        k = jx - ix + mx - 1
        ph = phat[k]
        qh = qhat[k]
        dr = pr_[jx]
        di = pi_[jx]
        for f in range(n):
            dr[f] += ph[f] * zr[f] + qh[f] * cr[f]
            di[f] += ph[f] * zi[f] + qh[f] * ci[f]


@jit(error_model="python")
def _flush_column(pr_, pi_, zr, zi, jx, my, sxt, syt, spec_fft):
    """Add the pending slip change of column ``jx`` (inverse FFT) to ``sxt[jx], syt[jx]``
    (transposed slip, one row per grid column); clear it."""
    twr, twi, rev = spec_fft
    n = zr.size
    for f in range(n):
        zr[f] = pr_[jx, f]
        zi[f] = pi_[jx, f]
        pr_[jx, f] = 0.0
        pi_[jx, f] = 0.0
    _fft(zr, zi, twr, twi, rev, -1.0)
    for jy in range(my):
        sxt[jx, jy] += zr[jy]
        syt[jx, jy] += zi[jy]


@jit(error_model="python")
def _full_slip_field(pxt, pyt, wxt, wyt, cmin, cmax, spec, mx, my, sxt, syt, work, dirty):
    """s = w + K p on the contact columns, computed from scratch (influence sums by FFT).
    Transposed fields: ``[ix, iy]``."""
    phat, qhat, twr, twi, rev = spec
    pr_, pi_, zr, zi, cr, ci = work
    sfft = (twr, twi, rev)
    pr_[:] = 0.0
    pi_[:] = 0.0
    sxt[:] = wxt
    syt[:] = wyt
    dirty[:] = False
    for ix in range(cmin, cmax + 1):
        nz = False
        zr[:] = 0.0
        zi[:] = 0.0
        for iy in range(my):
            if pxt[ix, iy] != 0.0 or pyt[ix, iy] != 0.0:
                zr[iy] = pxt[ix, iy]
                zi[iy] = pyt[ix, iy]
                nz = True
        if nz:
            _push_column(pr_, pi_, zr, zi, cr, ci, ix, cmin, cmax, phat, qhat, sfft, mx, False)
            for jx in range(cmin, cmax + 1):
                dirty[jx] = True
    for jx in range(cmin, cmax + 1):
        if dirty[jx]:
            _flush_column(pr_, pi_, zr, zi, jx, my, sxt, syt, sfft)
            dirty[jx] = False


@jit(error_model="python")
def _gauss_seidel(g, wx, wy, kxx, kxy, kyy, spec, dgx, dgy, tol, max_iter, px, py, sx, sy, state):
    """Block Gauss-Seidel for the steady rolling problem on one grid.

    ``g`` (my, mx): traction bound mu p_n / G (0 outside the contact). ``px, py`` hold the
    initial estimate (tractions / G) and receive the solution; ``sx, sy`` the slip; ``state``
    0/1/2 = exterior/stick/slip. ``spec``: :func:`_kernel_spectra` of the kernel. Returns
    (sweeps, last max |dp| / max |p|).

    Elements are visited column by column from the trailing to the leading edge, and within
    a column along y; each element solves its local problem with the current slip. The slip
    of the element's own column is updated at once (direct sums); the other columns receive
    the column's total traction change when the column is done, as a convolution along y
    done by FFT and kept in Fourier space until the column is visited (:func:`_push_column`,
    :func:`_flush_column`). Columns not yet visited in the sweep thus see every update, as in
    the element-wise Gauss-Seidel iteration with full sums, which this reproduces up to
    round-off, at O(nx ny (nx + ny)) instead of O((nx ny)^2) operations per sweep. The fields
    are worked on transposed (``[ix, iy]``), so that a column is contiguous.
    """
    phat, qhat, twr, twi, rev = spec
    sfft = (twr, twi, rev)
    my, mx = g.shape
    n = rev.size
    work = (np.zeros((mx, n)), np.zeros((mx, n)), np.zeros(n), np.zeros(n), np.zeros(n),
            np.zeros(n))  # fmt: skip
    pr_, pi_, zr, zi, cr, ci = work
    dirty = np.zeros(mx, np.bool_)
    dpx_col = np.zeros(my)
    dpy_col = np.zeros(my)
    c0 = mx - 1  # kernel column of zero offset along x, contiguous
    k0xx = np.ascontiguousarray(kxx[:, c0])
    k0xy = np.ascontiguousarray(kxy[:, c0])
    k0yy = np.ascontiguousarray(kyy[:, c0])
    gt = g.T.copy()  # copies (C order), scaled below: never views of the caller's arrays
    wxt = wx.T.copy()
    wyt = wy.T.copy()
    pxt = px.T.copy()
    pyt = py.T.copy()
    sxt = np.zeros((mx, my))
    syt = np.zeros((mx, my))
    stt = np.zeros((mx, my), np.int8)
    cmin = mx
    cmax = -1
    gmax = 0.0
    for ix in range(mx):
        for iy in range(my):
            if gt[ix, iy] > 0.0:
                cmin = min(cmin, ix)
                cmax = max(cmax, ix)
                gmax = max(gmax, gt[ix, iy])
            else:
                pxt[ix, iy] = 0.0
                pyt[ix, iy] = 0.0
    # the problem is invariant under (p, w, g) -> (p, w, g) 2^k: solved with the largest bound
    # in [0.5, 1), so that tiny friction (bounds of 1e-300) does not underflow in g^2; a power
    # of two keeps every product exact, so the iterates are those of the unscaled problem.
    # By ldexp: 2^-k overflows for denormal bounds (friction of 1e-310); and the rigid slips
    # beyond 2^800 bounds capped (full sliding, cap_rigid_slip), or they overflow when scaled
    expo = math.frexp(gmax)[1] if gmax > 0.0 else 0
    unit = math.ldexp(1.0, expo)  # exact down to 2^-1073, the exponent of the least bound
    wx_cut = np.zeros((mx, my))  # the part of w removed by the cap, added back to the slip
    wy_cut = np.zeros((mx, my))
    capped = np.zeros((mx, my), np.bool_)
    if gmax > 0.0:
        cx, cy, capped = cap_rigid_slip(wxt, wyt, np.full(mx, gmax))
        wx_cut = wxt - cx
        wy_cut = wyt - cy
        wxt = cx
        wyt = cy
    if expo != 0:
        for ix in range(mx):
            for iy in range(my):
                gt[ix, iy] = math.ldexp(gt[ix, iy], -expo)
                wxt[ix, iy] = math.ldexp(wxt[ix, iy], -expo)
                wyt[ix, iy] = math.ldexp(wyt[ix, iy], -expo)
                pxt[ix, iy] = math.ldexp(pxt[ix, iy], -expo)
                pyt[ix, iy] = math.ldexp(pyt[ix, iy], -expo)
        gmax = math.ldexp(gmax, -expo)
    sweeps = 0
    err = 0.0
    pref = 1.0
    if gmax > 0.0:
        k0x = dgx
        k0y = dgy
        _full_slip_field(pxt, pyt, wxt, wyt, cmin, cmax, spec, mx, my, sxt, syt, work, dirty)
        pref = gmax
        err_min = np.inf
        for _ in range(max_iter):
            sweeps += 1
            err = 0.0
            pmax = 0.0
            for ix in range(cmin, cmax + 1):  # from the trailing edge to the leading edge (+x)
                if dirty[ix]:
                    _flush_column(pr_, pi_, zr, zi, ix, my, sxt, syt, sfft)
                    dirty[ix] = False
                changed = False
                dpx_col[:] = 0.0
                dpy_col[:] = 0.0
                scx = sxt[ix]
                scy = syt[ix]
                for iy in range(my):
                    gi = gt[ix, iy]
                    if gi <= 0.0:
                        continue
                    ox = pxt[ix, iy]
                    oy = pyt[ix, iy]
                    ssx = scx[iy] - k0x * ox
                    ssy = scy[iy] - k0y * oy
                    tx = -ssx / k0x
                    ty = -ssy / k0y
                    if tx * tx + ty * ty <= gi * gi:
                        nx_, ny_ = tx, ty
                        stt[ix, iy] = _STICK
                    else:
                        nx_, ny_ = _local_slip(ssx, ssy, k0x, k0y, gi)
                        stt[ix, iy] = _SLIP
                    dpx = nx_ - ox
                    dpy = ny_ - oy
                    if dpx != 0.0 or dpy != 0.0:
                        pxt[ix, iy] = nx_
                        pyt[ix, iy] = ny_
                        dpx_col[iy] = dpx
                        dpy_col[iy] = dpy
                        changed = True
                        _column_update(scx, scy, k0xx, k0xy, k0yy, iy, my, dpx, dpy)
                        err = max(err, abs(dpx), abs(dpy))
                    pmax = max(pmax, abs(nx_), abs(ny_))
                if changed:  # the other columns, by FFT
                    zr[:] = 0.0
                    zi[:] = 0.0
                    zr[:my] = dpx_col
                    zi[:my] = dpy_col
                    _push_column(pr_, pi_, zr, zi, cr, ci, ix, cmin, cmax, phat, qhat, sfft, mx,
                                 True)  # fmt: skip
                    for jx in range(cmin, cmax + 1):
                        if jx != ix:
                            dirty[jx] = True
            pref = max(pmax, 1e-12 * gmax)
            if err <= tol * pref:
                break
            # divergence guard: relative change 1e3 x its minimum -> larger diagonal, restart
            rel = err / pref
            err_min = min(err_min, rel)
            if rel > 1e3 * err_min or not math.isfinite(rel):
                k0x *= 1.3
                k0y *= 1.3
                err_min = np.inf
                pxt[:] = 0.0
                pyt[:] = 0.0
                _full_slip_field(pxt, pyt, wxt, wyt, cmin, cmax, spec, mx, my, sxt, syt, work,
                                 dirty)  # fmt: skip
        # exact slip for the output (removes round-off accumulated by the updates)
        _full_slip_field(pxt, pyt, wxt, wyt, cmin, cmax, spec, mx, my, sxt, syt, work, dirty)
    else:
        sxt[:] = wxt
        syt[:] = wyt
    for iy in range(my):
        for ix in range(mx):
            px[iy, ix] = pxt[ix, iy] * unit
            py[iy, ix] = pyt[ix, iy] * unit
            if gt[ix, iy] <= 0.0:
                state[iy, ix] = _EXTERIOR
                sx[iy, ix] = 0.0 if gmax > 0.0 else sxt[ix, iy]
                sy[iy, ix] = 0.0 if gmax > 0.0 else syt[ix, iy]
            else:
                state[iy, ix] = stt[ix, iy]
                if stt[ix, iy] == _STICK:
                    sx[iy, ix] = 0.0  # zero up to the solver tolerance
                    sy[iy, ix] = 0.0
                else:
                    sx[iy, ix] = sxt[ix, iy] * unit
                    sy[iy, ix] = syt[ix, iy] * unit
                    if capped[ix, iy]:  # the slip is linear in w: the capped part added back
                        sx[iy, ix] += wx_cut[ix, iy]
                        sy[iy, ix] += wy_cut[ix, iy]
    return sweeps, err / pref


@jit(error_model="python", fastmath=True, inline="always")
def _column_update(scx, scy, k0xx, k0xy, k0yy, iy, my, dpx, dpy):
    """s_J += K(J - I) dp for the elements J of the column of element I (row ``iy``)."""
    off = my - 1 - iy
    for jy in range(my):
        d = jy + off
        scx[jy] += k0xx[d] * dpx + k0xy[d] * dpy
        scy[jy] += k0xy[d] * dpx + k0yy[d] * dpy


def _falling_friction(g0, inner, speed, ratio, decay, tol_outer, max_outer, sx, sy, mu_fac):
    """Steady rolling with slip-velocity dependent friction: outer fixed-point iteration.

    ``g0`` is the traction bound at zero slip (mu0 p_n / G). The local coefficient of
    friction ``mu_fac * mu0`` of every element is frozen at the estimate ``v`` of its slip
    velocity, the Coulomb problem with that bound is solved by ``inner(g)`` (either solver,
    started from the previous tractions; it returns (iterations, residual) and leaves the
    slip in ``sx, sy``), and the estimate is updated from the new slip,
    ``v <- v + omega (V |s| - v)``, starting from ``v = 0`` (static friction everywhere,
    "slip from below"). The relaxation ``omega`` starts at 1 and is halved whenever the
    update grows (down to 1/16). Stops when ``||V|s| - v||_2 <= tol_outer ||V|s|||_2``.
    ``mu_fac`` receives the factor at the final slip. Returns (total inner iterations, last
    inner residual, outer iterations, last outer change).
    """
    vel = np.zeros(g0.shape)  # slip-velocity estimate [m/s]
    g = np.empty(g0.shape)
    iterations = 0
    err = 0.0
    omega = 1.0
    last = np.inf
    change = 0.0
    outer = 0
    for _ in range(max_outer):
        outer += 1
        _friction_factors(g0, vel, ratio, decay, mu_fac, g)
        it, err = inner(g)
        iterations += it
        dnorm, snorm = _slip_velocity_change(g0, sx, sy, speed, vel)
        change = dnorm / snorm if snorm > 0.0 else 0.0
        if dnorm <= tol_outer * snorm:
            break
        if dnorm > last and omega > 1.0 / 16.0:
            omega *= 0.5
        last = dnorm
        _relax_slip_velocity(g0, sx, sy, speed, omega, vel)
    # the friction coefficient consistent with the final slip
    vel[:] = speed * np.hypot(sx, sy)
    _friction_factors(g0, vel, ratio, decay, mu_fac, g)
    mu_fac[g0 <= 0.0] = 0.0
    return iterations, err, outer, change


@jit(error_model="python")
def _friction_factors(g0, vel, ratio, decay, mu_fac, g):
    """``mu_fac = mu(v)/mu0`` (:func:`falling_friction_factor`) and the bound ``g = g0 mu_fac``
    of every element at the slip velocities ``vel``."""
    my, mx = g0.shape
    for j in range(my):
        for i in range(mx):
            mu_fac[j, i] = falling_friction_factor(vel[j, i], ratio, decay)
            g[j, i] = g0[j, i] * mu_fac[j, i]


@jit(error_model="python")
def _slip_velocity_change(g0, sx, sy, speed, vel):
    """``(||V|s| - v||_2, ||V|s|||_2)`` over the contact elements."""
    my, mx = g0.shape
    dnorm = 0.0
    snorm = 0.0
    for j in range(my):
        for i in range(mx):
            if g0[j, i] <= 0.0:
                continue
            v_new = speed * math.sqrt(sx[j, i] ** 2 + sy[j, i] ** 2)
            d = v_new - vel[j, i]
            dnorm += d * d
            snorm += v_new * v_new
    return math.sqrt(dnorm), math.sqrt(snorm)


@jit(error_model="python")
def _relax_slip_velocity(g0, sx, sy, speed, omega, vel):
    """``v <- v + omega (V |s| - v)`` on the contact elements."""
    my, mx = g0.shape
    for j in range(my):
        for i in range(mx):
            if g0[j, i] > 0.0:
                v_new = speed * math.sqrt(sx[j, i] ** 2 + sy[j, i] ** 2)
                vel[j, i] += omega * (v_new - vel[j, i])


@jit(error_model="python")
def _grid_shape(mx, my, scale, shape_in):
    """Element-centre coordinates over the semi-axes ``xh`` (mx), ``yh`` (my), the pressure
    shape on the grid (``shape_in`` clipped at 0, or Hertz's at the element centres when
    ``shape_in`` is empty) and its sum."""
    xh = np.empty(mx)
    yh = np.empty(my)
    for i in range(mx):
        xh[i] = scale * (-1.0 + (2.0 * i + 1.0) / mx)
    for j in range(my):
        yh[j] = scale * (-1.0 + (2.0 * j + 1.0) / my)
    shape = np.zeros((my, mx))
    ssum = 0.0
    for j in range(my):
        for i in range(mx):
            if shape_in.size > 0:
                shape[j, i] = max(shape_in[j, i], 0.0)
            else:
                q = 1.0 - xh[i] * xh[i] - yh[j] * yh[j]
                shape[j, i] = math.sqrt(q) if q > 0.0 else 0.0
            ssum += shape[j, i]
    return xh, yh, shape, ssum


@jitable
def _element_size(a, b, mx, my, scale):
    """Element size ``(dx, dy)`` [m] of the ``mx x my`` grid over ``[-scale a, scale a] x
    [-scale b, scale b]`` (scalars or arrays; callable from compiled code)."""
    return 2.0 * scale * a / mx, 2.0 * scale * b / my


@jit(error_model="python")
def _case_fields(xi, eta, phi, fz, a, b, mu, gmod, scale, spin_offset, xh, yh, shape, ssum, g,
                 wx, wy):  # fmt: skip
    """The traction bound ``g = mu p_n/G`` and the rigid slip ``w`` of one case on its grid
    (filled in); returns the element size (dx, dy) [m]. ``p_n`` is the shape scaled so that
    ``sum(p_n dA) = Fz`` exactly; ``w = (xi - phi y, eta + phi (x + spin_offset dx))``
    (Kalker 1990, eq. 1.1.11; the spin term CONTACT's FACPHI upstream)."""
    my, mx = shape.shape
    dx, dy = _element_size(a, b, mx, my, scale)
    pfac = fz / (ssum * dx * dy)
    for j in range(my):
        y = b * yh[j]
        for i in range(mx):
            x = a * xh[i]
            g[j, i] = mu * pfac * shape[j, i] / gmod
            wx[j, i] = xi - phi * y
            wy[j, i] = eta + phi * (x + spin_offset * dx)
    return dx, dy


@jit(error_model="python")
def _case_forces(px, py, st, shape, xh, yh, a, b, dx, dy, gmod, out):
    """``out[:4] = (Fx, Fy, Mz, slip fraction)`` from the tractions (over G) of one case."""
    my, mx = shape.shape
    fx = 0.0
    fy = 0.0
    mz = 0.0
    area_slip = 0.0
    area_c = 0.0
    for j in range(my):
        y = b * yh[j]
        for i in range(mx):
            if shape[j, i] <= 0.0:
                continue
            x = a * xh[i]
            fx += px[j, i]
            fy += py[j, i]
            mz += x * py[j, i] - y * px[j, i]
            area_c += 1.0
            if st[j, i] == _SLIP:
                area_slip += 1.0
    da = dx * dy * gmod
    out[0] = fx * da
    out[1] = fy * da
    out[2] = mz * da
    out[3] = area_slip / area_c if area_c > 0 else 0.0


@jit(error_model="python")
def _case_kernel(mx, my, ratio, nu):
    """Rolling kernel of a grid with dy/dx = ``ratio`` (for dx = 1: K is dimensionless), its
    column spectra and the Gauss-Seidel diagonal."""
    kxx, kxy, kyy = _rolling_kernel(mx, my, 1.0, ratio, nu)
    spec = _kernel_spectra(kxx, kxy, kyy)
    dgx, dgy = _gs_diagonal(ratio, nu)
    return kxx, kxy, kyy, spec, dgx, dgy


@jit(error_model="python")
def _start_tractions(px, py, g, restart):
    """Start of a case: zero tractions (``restart``), or the previous case's scaled into the
    new traction bound ``g`` (a warm start)."""
    my, mx = g.shape
    for j in range(my):
        for i in range(mx):
            if restart:
                px[j, i] = 0.0
                py[j, i] = 0.0
            else:
                pt = math.sqrt(px[j, i] ** 2 + py[j, i] ** 2)
                if pt > g[j, i]:
                    f = g[j, i] / pt
                    px[j, i] *= f
                    py[j, i] *= f


@jit(error_model="python")
def _gauss_seidel_batch(
    xi, eta, phi, fz, a, b, mu, gmod, nu, mx, my, scale, spin_offset, tol, max_iter, out_f,
    out_iter, out_err, px_all, py_all, sx_all, sy_all, state_all, mu_all, keep_fields, warm,
    shape_in,
):  # fmt: skip
    """Loop over Coulomb cases by Gauss-Seidel: pressure on the grid, kernel (reused when
    unchanged), solve.

    ``shape_in`` (my, mx): the pressure distribution to use (any scale), or an empty array for
    Hertz's at the element centres."""
    n = xi.size
    px = np.zeros((my, mx))
    py = np.zeros((my, mx))
    sx = np.zeros((my, mx))
    sy = np.zeros((my, mx))
    st = np.zeros((my, mx), np.int8)
    g = np.zeros((my, mx))
    wx = np.zeros((my, mx))
    wy = np.zeros((my, mx))
    kxx, kxy, kyy, spec, dgx, dgy = _case_kernel(1, 1, 1.0, 0.0)
    last_ratio = -1.0
    last_nu = -1.0
    xh, yh, shape, ssum = _grid_shape(mx, my, scale, shape_in)
    for c in range(n):
        dx, dy = _case_fields(xi[c], eta[c], phi[c], fz[c], a[c], b[c], mu[c], gmod[c], scale,
                              spin_offset, xh, yh, shape, ssum, g, wx, wy)  # fmt: skip
        ratio = dy / dx
        restart = True
        if ratio != last_ratio or nu[c] != last_nu:
            kxx, kxy, kyy, spec, dgx, dgy = _case_kernel(mx, my, ratio, nu[c])
            last_ratio = ratio
            last_nu = nu[c]
        elif warm:
            restart = False  # start from the previous case's tractions (same kernel)
        _start_tractions(px, py, g, restart)
        it, err = _gauss_seidel(
            g, wx, wy, kxx, kxy, kyy, spec, dgx, dgy, tol, max_iter, px, py, sx, sy, st
        )
        _case_forces(px, py, st, shape, xh, yh, a[c], b[c], dx, dy, gmod[c], out_f[c])
        out_iter[c] = it
        out_err[c] = err
        if keep_fields:
            for j in range(my):
                for i in range(mx):
                    px_all[c, j, i] = px[j, i] * gmod[c]
                    py_all[c, j, i] = py[j, i] * gmod[c]
                    sx_all[c, j, i] = sx[j, i]
                    sy_all[c, j, i] = sy[j, i]
                    state_all[c, j, i] = st[j, i]
                    mu_all[c, j, i] = mu[c] if g[j, i] > 0.0 else 0.0


# ---------------------------------------------------------------------------------------------
# Batches: Gauss-Seidel (compiled loop) or semismooth Newton (FFT products, per case)
# ---------------------------------------------------------------------------------------------

#: ``method="auto"`` solves Coulomb cases by semismooth Newton from this many grid elements
#: (40 x 40) up; below, the compiled Gauss-Seidel loop is as fast or faster
#: (``benchmarks/bench_exact.py``).
NEWTON_MIN_ELEMENTS = 1600
#: The coarse grids of the Newton start are solved to this tolerance.
_COARSE_TOL = 1e-2
#: Coarser grids are not used below this many elements along either axis.
_COARSE_MIN = 12
#: Newton steps allowed before a solve is handed to Gauss-Seidel (3-6 are typical).
_NEWTON_MAX_STEPS = 60
#: Newton solves the Coulomb cases of grids up to this many elements together, with dense
#: products (:class:`~railadhesion.contact.rolling_newton.DenseRolling`; its matrix has
#: (2 x contact elements)^2 entries: 21 MB in double precision at 32 x 32, 812 contact
#: elements, with about as much again in its single-precision and transposed copies);
#: larger grids case by case with FFT products.
_DENSE_MAX_ELEMENTS = 1024
#: Cases solved together (the Krylov bases of a batch take about 40 x 2 x elements x 4 bytes
#: per case).
_DENSE_BATCH = 256
#: Fewer cases of one a/b and nu than this go case by case: building the dense matrices
#: costs more than it saves (break-even measured at about 16 cases on 16 x 16 to 32 x 32).
_DENSE_MIN_CASES = 16
#: ``method="auto"`` solves groups of this many Coulomb cases (or more) of one a/b and nu on a
#: grid of up to ``_DENSE_MAX_ELEMENTS`` by Newton, together: 1.4-2.1 times faster than
#: Gauss-Seidel at 64 cases on 16 x 16 to 32 x 32 (docs/exact-solver.md), and more with more.
_DENSE_AUTO_CASES = 64
#: Coarse starts of the batched path: grids down to this many elements along an axis and
#: this many elements in all.
_DENSE_COARSE_MIN = 6
_DENSE_COARSE_ELEMENTS = 144


@dataclass
class _BatchOutput:
    forces: np.ndarray  # (n, 4)
    iterations: np.ndarray
    residual: np.ndarray
    outer: np.ndarray
    fields: list  # px, py, sx, sy: (n, ny, nx) or (1, 1, 1) placeholders
    state: np.ndarray
    mu_local: np.ndarray
    newton: np.ndarray  # bool: case solved by Newton (False: Gauss-Seidel)


def _is_coulomb(friction_ratio, friction_decay, speed):
    """Whether the friction law is Coulomb's: A = 1, or B V = 0 (works on arrays)."""
    return (friction_ratio == 1.0) | (friction_decay * speed == 0.0)


def _solve_cases(idx, flat, shape_in, opts, out: _BatchOutput, newton: bool,
                 auto: bool = False) -> None:  # fmt: skip
    """Solve the cases ``idx`` of the flat inputs into ``out``: Coulomb cases by the compiled
    Gauss-Seidel loop, or by Newton when ``newton``; falling-friction cases one by one, the
    outer iteration on the slip velocity around either solver. With ``auto`` (and not
    ``newton``), groups of at least ``_DENSE_AUTO_CASES`` Coulomb cases of one a/b and nu on
    a small grid go to Newton, solved together."""
    nx, ny, scale, spin_offset, tol, max_iter, tol_f, max_f, keep, warm = opts
    coulomb = _is_coulomb(flat[10][idx], flat[11][idx], flat[9][idx])
    by_loop = idx[:0] if newton else idx[coulomb]
    if auto and by_loop.size >= _DENSE_AUTO_CASES and nx * ny <= _DENSE_MAX_ELEMENTS:
        by_loop = _solve_dense_batches(by_loop, flat, shape_in, opts, out, by_loop,
                                       min_cases=_DENSE_AUTO_CASES)  # fmt: skip
    if by_loop.size:
        m = by_loop.size
        o_f, o_it, o_err = np.empty((m, 4)), np.empty(m, np.int64), np.empty(m)
        if keep:
            f_sub = [np.empty((m, ny, nx)) for _ in range(4)]
            st_sub = np.empty((m, ny, nx), np.int8)
            mu_sub = np.empty((m, ny, nx))
        else:
            f_sub, st_sub, mu_sub = out.fields, out.state, out.mu_local
        _gauss_seidel_batch(
            *[np.ascontiguousarray(v[by_loop]) for v in flat[:9]], nx, ny, scale, spin_offset,
            tol, max_iter, o_f, o_it, o_err, *f_sub, st_sub, mu_sub, keep, warm, shape_in,
        )  # fmt: skip
        out.forces[by_loop], out.iterations[by_loop], out.residual[by_loop] = o_f, o_it, o_err
        out.outer[by_loop] = 0
        if keep:
            for full, part in zip(out.fields, f_sub, strict=True):
                full[by_loop] = part
            out.state[by_loop] = st_sub
            out.mu_local[by_loop] = mu_sub
    rest = idx[~coulomb] if not newton else idx
    if newton and nx * ny <= _DENSE_MAX_ELEMENTS:
        rest = _solve_dense_batches(idx[coulomb], flat, shape_in, opts, out, rest)
    if rest.size:
        _solve_one_by_one(rest, flat, shape_in, opts, out, newton)


def _dense_fields(idx, flat, mx, my, scale, spin_offset, xh, yh, shape, ssum, inside):
    """The traction bounds (len(idx), m) and packed rigid slips (len(idx), 2m) of the cases
    ``idx`` on a grid, and their dy/dx."""
    m = int(inside.sum())
    g_all, w_all, ratio = np.empty((idx.size, m)), np.empty((idx.size, 2 * m)), np.empty(idx.size)
    g, wx, wy = np.empty((my, mx)), np.empty((my, mx)), np.empty((my, mx))
    for q, c in enumerate(idx):
        case = tuple(float(v[c]) for v in flat[:8])
        dx, dy = _case_fields(*case, scale, spin_offset, xh, yh, shape, ssum, g, wx, wy)
        g_all[q] = g[inside]
        w_all[q, :m] = wx[inside]
        w_all[q, m:] = wy[inside]
        ratio[q] = dy / dx
    return g_all, w_all, ratio


def _dense_newton(idx, flat, mx, my, scale, spin_offset, shape_in, tol, cache):
    """Semismooth Newton for the Coulomb cases ``idx`` of one (mx, my) grid, all with one
    dy/dx and nu, solved together (:func:`solve_steady_rolling_batch`), each started from
    the solution on a grid half as fine (nested iteration, as :func:`_coarse_start`;
    Hertz's pressure on the coarse grids). Returns the grid's shape data, its
    :class:`DenseRolling` and the solution; None when a case's traction bound underflows to 0
    on a contact element (mu p_n/G below 5e-324: friction of 1e-323), which Newton's scaling
    by the largest bound does not admit (the cases are then solved one by one)."""
    xh, yh, shape, ssum = _grid_shape(mx, my, scale, shape_in)
    inside = shape > 0.0
    g, w, ratio = _dense_fields(idx, flat, mx, my, scale, spin_offset, xh, yh, shape, ssum,
                                inside)  # fmt: skip
    if not np.all(g > 0.0):
        return None
    nu = float(flat[8][idx[0]])
    key = (mx, my, float(ratio[0]), nu, inside.tobytes())
    if key not in cache:
        cache[key] = DenseRolling(*_rolling_kernel(mx, my, 1.0, float(ratio[0]), nu), inside)
    dense = cache[key]
    start = None
    mc, nc = (mx + 1) // 2, (my + 1) // 2
    if min(mc, nc) >= _DENSE_COARSE_MIN and mc * nc >= _DENSE_COARSE_ELEMENTS:
        coarse = _dense_newton(idx, flat, mc, nc, scale, spin_offset, np.empty((0, 0)),
                               _COARSE_TOL, cache)  # fmt: skip
        if coarse is not None:
            (xc, yc, _, _), dense_c, sol_c = coarse
            key_i = ("interpolation", mc, nc, mx, my, scale, inside.tobytes())
            if key_i not in cache:
                cache[key_i] = _interpolation_matrix(dense_c, xc, yc, dense, xh, yh)
            start = sol_c.p @ cache[key_i].T
    sol = solve_steady_rolling_batch(g, w, dense, tol=tol, p=start, max_steps=_NEWTON_MAX_STEPS)
    return (xh, yh, shape, ssum), dense, sol


def _interpolation_matrix(coarse: DenseRolling, xc, yc, fine: DenseRolling, xf, yf):
    """The packed-to-packed matrix of :func:`_interpolate` (bilinear, separable: the product
    of its weights along x and along y) from a coarse grid's contact elements onto a fine
    grid's, the same for the x and y components."""
    wx = np.array([np.interp(xf, xc, e) for e in np.eye(xc.size)]).T  # (fine x, coarse x)
    wy = np.array([np.interp(yf, yc, e) for e in np.eye(yc.size)]).T
    full = np.kron(wy, wx)  # row-major (y, x) on both grids
    part = full[np.ix_(fine.rows * xf.size + fine.cols, coarse.rows * xc.size + coarse.cols)]
    out = np.zeros((2 * fine.m, 2 * coarse.m))
    out[: fine.m, : coarse.m] = part
    out[fine.m :, coarse.m :] = part
    return out


def _solve_dense_batches(idx, flat, shape_in, opts, out: _BatchOutput, rest, min_cases=None):
    """Newton on the Coulomb cases ``idx`` of a small grid, solved together in groups of one
    dy/dx and nu of at least ``min_cases`` cases (default ``_DENSE_MIN_CASES``;
    :func:`_dense_newton`); a case Newton does not finish is finished by Gauss-Seidel from
    Newton's iterate (and counts as solved by Gauss-Seidel). Returns ``rest`` without the
    cases solved here (smaller groups, cases without friction, mu p_n = 0, and chunks with a
    bound underflowing to 0 stay)."""
    nx, ny, scale, spin_offset, tol, max_iter, tol_f, max_f, keep, warm = opts
    min_cases = _DENSE_MIN_CASES if min_cases is None else min_cases
    if not idx.size:
        return rest
    bound = flat[6][idx] * flat[3][idx]  # mu Fz: no traction bound at all when 0
    idx = idx[bound > 0.0]
    # group by the grid's dy/dx (to 1e-12: the same a/b may round differently) and nu
    dx, dy = _element_size(flat[4][idx], flat[5][idx], nx, ny, scale)
    keys = np.stack((np.round(np.log(dy / dx), 12), flat[8][idx]), axis=1)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    cache: dict = {}
    kernels: dict = {}
    done = []
    for gi in range(int(group.max()) + 1 if group.size else 0):
        members = idx[group.ravel() == gi]
        if members.size < min_cases:
            continue
        for lo in range(0, members.size, _DENSE_BATCH):
            chunk = members[lo:lo + _DENSE_BATCH]
            solved = _dense_newton(chunk, flat, nx, ny, scale, spin_offset, shape_in, tol, cache)
            if solved is None:  # a bound underflowed: the chunk is solved one by one
                continue
            (xh, yh, shape, _), dense, sol = solved
            px, py = dense.unpack(sol.p)
            sx, sy = dense.unpack(sol.s)
            state = np.where(dense.inside, 1, 0).astype(np.int8)
            for q, c in enumerate(chunk):
                st = state.copy()
                st[dense.rows[sol.slip[q]], dense.cols[sol.slip[q]]] = _SLIP
                its, err = int(sol.newton_steps[q]), float(sol.residual[q])
                out.newton[c] = bool(sol.converged[q])
                case = tuple(float(v[c]) for v in flat[:8])
                if not sol.converged[q]:
                    its, err = _finish_by_gauss_seidel(
                        c, case, flat, opts, shape_in, kernels, px[q], py[q], sx[q], sy[q], st,
                        its)  # fmt: skip
                _case_forces(px[q], py[q], st, shape, xh, yh, case[4], case[5],
                             *_element_size(case[4], case[5], nx, ny, scale), case[7],
                             out.forces[c])  # fmt: skip
                out.iterations[c] = its
                out.residual[c] = err
                out.outer[c] = 0
                if keep:
                    out.fields[0][c] = px[q] * case[7]
                    out.fields[1][c] = py[q] * case[7]
                    out.fields[2][c] = sx[q]
                    out.fields[3][c] = sy[q]
                    out.state[c] = st
                    out.mu_local[c] = (shape > 0.0) * case[6]
            done.append(chunk)
    if not done:
        return rest
    return np.setdiff1d(rest, np.concatenate(done), assume_unique=True)


def _finish_by_gauss_seidel(c, case, flat, opts, shape_in, kernels, px, py, sx, sy, st, its):
    """Gauss-Seidel (always convergent) from Newton's last iterate ``px, py`` (over G, in
    place, with the slip and the state) for case ``c``; returns (Newton steps + sweeps,
    residual)."""
    nx, ny, scale, spin_offset, tol, max_iter = opts[:6]
    xh, yh, shape, ssum = _grid_shape(nx, ny, scale, shape_in)
    g, wx, wy = np.empty((ny, nx)), np.empty((ny, nx)), np.empty((ny, nx))
    dx, dy = _case_fields(*case, scale, spin_offset, xh, yh, shape, ssum, g, wx, wy)
    key = (dy / dx, float(flat[8][c]))
    if key not in kernels:
        kernels[key] = _case_kernel(nx, ny, key[0], key[1])
    sweeps, err = _gauss_seidel(g, wx, wy, *kernels[key], tol, max_iter, px, py, sx, sy, st)
    _check_finish(px, py, g, int(c), case[:3])
    return its + sweeps, err


def _check_finish(px, py, g, c, creepages):
    """FloatingPointError unless the tractions Gauss-Seidel finished from Newton's iterate are
    finite (a failure of both solvers: a bug to report)."""
    if not (np.all(np.isfinite(px)) and np.all(np.isfinite(py))):
        raise FloatingPointError(
            f"exact_rolling: no finite solution for case {c} (creepages {creepages}, "
            f"bound max {float(g.max()):.3g}): please report it"
        )


def _interpolate(field, xc, yc, xf, yf):
    """Bilinear interpolation of ``field`` (ny_c, nx_c) at centres ``xc, yc`` onto ``xf, yf``
    (constant beyond the outer centres)."""
    rows = np.array([np.interp(xf, xc, row) for row in field])
    return np.array([np.interp(yf, yc, col) for col in rows.T]).T


def _coarse_start(case, mx, my, scale, spin_offset, nu, xh, yh, operators):
    """Start (tractions over G, or None) for the case on the (mx, my) grid with element
    centres ``xh, yh``: the Newton solution on a grid half as fine, itself started the same
    way, interpolated. This nested iteration of multigrid practice (Briggs, Henson &
    McCormick, *A Multigrid Tutorial*, 2000, ch. 3) leaves 3-6 Newton steps on the fine grid.
    The coarse grids carry Hertz's pressure even when the case has another (a start only)."""
    if min(mx, my) < 2 * _COARSE_MIN:
        return None, None
    mc, nc = (mx + 1) // 2, (my + 1) // 2
    xc, yc, shape, ssum = _grid_shape(mc, nc, scale, np.empty((0, 0)))
    g, wx, wy = np.empty((nc, mc)), np.empty((nc, mc)), np.empty((nc, mc))
    dx, dy = _case_fields(*case, scale, spin_offset, xc, yc, shape, ssum, g, wx, wy)
    px, py = _coarse_start(case, mc, nc, scale, spin_offset, nu, xc, yc, operators)
    op = _operator(mc, nc, dy / dx, nu, operators)
    sol = solve_steady_rolling(g, wx, wy, op, tol=_COARSE_TOL, px=px, py=py)
    return _interpolate(sol.px, xc, yc, xh, yh), _interpolate(sol.py, xc, yc, xh, yh)


def _operator(mx, my, ratio, nu, operators):
    """The rolling operator of a grid, built once per call of :func:`exact_rolling`."""
    key = (mx, my, ratio, nu)
    if key not in operators:
        operators[key] = RollingOperator(*_rolling_kernel(mx, my, 1.0, ratio, nu))
    return operators[key]


def _solve_one_by_one(idx, flat, shape_in, opts, out: _BatchOutput, newton: bool) -> None:
    """The cases ``idx`` one by one, Coulomb or falling friction
    (:func:`_falling_friction` around the Coulomb solver), by Gauss-Seidel or by semismooth
    Newton (:mod:`railadhesion.contact.rolling_newton`).

    Newton starts each case from a coarser grid's solution (:func:`_coarse_start`; so the
    result does not depend on the order of the cases, and a start from the previous case's
    tractions saves nothing here), each friction update from the previous tractions; a solve
    Newton does not finish in ``_NEWTON_MAX_STEPS`` steps is finished by Gauss-Seidel from
    Newton's last iterate (the case then counts as solved by Gauss-Seidel). Gauss-Seidel
    starts from zero, or with ``warm`` from the previous case's tractions on the same grid."""
    nx, ny, scale, spin_offset, tol, max_iter, tol_f, max_f, keep, warm = opts
    xh, yh, shape, ssum = _grid_shape(nx, ny, scale, shape_in)
    g0, wx, wy = np.empty((ny, nx)), np.empty((ny, nx)), np.empty((ny, nx))
    px, py, sx, sy = (np.zeros((ny, nx)) for _ in range(4))
    st = np.zeros((ny, nx), np.int8)
    mu_fac = np.ones((ny, nx))
    operators: dict = {}
    kernels: dict = {}
    last_key = None
    op = None
    for c in idx:
        case = tuple(float(v[c]) for v in flat[:8])
        nu, speed, fratio, decay = (float(flat[k][c]) for k in (8, 9, 10, 11))
        dx, dy = _case_fields(*case, scale, spin_offset, xh, yh, shape, ssum, g0, wx, wy)
        key = (dy / dx, nu)

        def gs_kernel(key=key):  # the Gauss-Seidel spectra, only when Gauss-Seidel runs
            if key not in kernels:
                kernels[key] = _case_kernel(nx, ny, key[0], key[1])
            return kernels[key]

        finished_by_newton = newton
        if newton:
            op = _operator(nx, ny, key[0], nu, operators)
            start = _coarse_start(case, nx, ny, scale, spin_offset, nu, xh, yh, operators)
            _start_tractions(px, py, g0, True)
            if start[0] is not None:
                px[:], py[:] = start
        else:
            _start_tractions(px, py, g0, not (warm and key == last_key))
        last_key = key

        def inner(g, op=op if newton else None, gs_kernel=gs_kernel, label=(int(c), case[:3])):
            nonlocal finished_by_newton
            if op is None:
                return _gauss_seidel(g, wx, wy, *gs_kernel(), tol, max_iter, px, py, sx, sy, st)
            sol = solve_steady_rolling(g, wx, wy, op, tol=tol, px=px, py=py,
                                       max_steps=_NEWTON_MAX_STEPS)  # fmt: skip
            px[:], py[:], sx[:], sy[:], st[:] = sol.px, sol.py, sol.sx, sol.sy, sol.state
            if sol.converged:
                return sol.newton_steps, sol.residual
            finished_by_newton = False  # Gauss-Seidel (always convergent) from Newton's iterate
            sweeps, err = _gauss_seidel(g, wx, wy, *gs_kernel(), tol, max_iter, px, py, sx, sy,
                                        st)  # fmt: skip
            _check_finish(px, py, g, *label)
            return sol.newton_steps + sweeps, err

        if _is_coulomb(fratio, decay, speed):
            it, err = inner(g0)
            outer = 0
            mu_fac[:] = g0 > 0.0
        else:
            it, err, outer, _ = _falling_friction(g0, inner, speed, fratio, decay, tol_f, max_f,
                                                  sx, sy, mu_fac)  # fmt: skip
        out.newton[c] = finished_by_newton
        _case_forces(px, py, st, shape, xh, yh, case[4], case[5], dx, dy, case[7], out.forces[c])
        out.iterations[c] = it
        out.residual[c] = err
        out.outer[c] = outer
        if keep:
            out.fields[0][c] = px * case[7]
            out.fields[1][c] = py * case[7]
            out.fields[2][c] = sx
            out.fields[3][c] = sy
            out.state[c] = st
            out.mu_local[c] = mu_fac * case[6]


# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ExactResult:
    """Result of :func:`exact_rolling` / :func:`solve_tangential`.

    ``fx``, ``fy``, ``mz``, ``slip_fraction``, ``iterations`` and ``residual`` have the
    broadcast shape of the inputs (NumPy scalars for scalar input). The grid fields are
    ``None`` unless requested; then they have the shape ``(*shape, ny, nx)``, index ``[j, i]``
    with ``y_j`` increasing with j and ``x_i`` increasing with i (the leading edge, +x, is at
    the last column).
    """

    fx: np.ndarray
    """Longitudinal force [N] (rail on wheel, Kalker's sign convention)."""
    fy: np.ndarray
    """Lateral force [N]."""
    mz: np.ndarray
    """Spin moment about the contact normal through the contact centre [N m]."""
    slip_fraction: np.ndarray
    """Fraction of the contact elements in slip [-]."""
    iterations: np.ndarray
    """Newton steps (semismooth Newton) or sweeps (Gauss-Seidel) used; a case Newton leaves
    to Gauss-Seidel counts both."""
    residual: np.ndarray
    """Largest traction change of the last sweep (Gauss-Seidel), or of a local projection
    step ``p - P_g(p - r s)`` (Newton), relative to the largest traction [-]: comparable
    measures of convergence, not the same one."""
    x: np.ndarray | None = None
    """Element-centre x [m], shape (nx,) per case: (*shape, nx)."""
    y: np.ndarray | None = None
    """Element-centre y [m], (*shape, ny)."""
    px: np.ndarray | None = None
    """Tangential traction along x [Pa], (*shape, ny, nx)."""
    py: np.ndarray | None = None
    """Tangential traction along y [Pa]."""
    pn: np.ndarray | None = None
    """Normal pressure [Pa]."""
    sx: np.ndarray | None = None
    """Slip along x per unit rolling distance (slip velocity / V) [-]; 0 in stick."""
    sy: np.ndarray | None = None
    """Slip along y per unit rolling distance [-]."""
    state: np.ndarray | None = None
    """Element state: 0 = outside the contact, 1 = stick (adhesion), 2 = slip."""
    friction_iterations: np.ndarray | None = None
    """Outer (friction-update) iterations with falling friction; 0 with Coulomb friction."""
    mu_local: np.ndarray | None = None
    """Local coefficient of friction at the final slip velocity, (*shape, ny, nx) (0 outside
    the contact; the static value in stick)."""
    method: str = "gauss-seidel"
    """Solver used: ``"newton"`` (semismooth Newton, every case), ``"gauss-seidel"``, or
    ``"newton+gauss-seidel"`` (some cases by each: a case Newton did not finish counts as
    Gauss-Seidel's)."""


def _check_grid(value, name: str) -> int:
    try:
        n = int(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}") from exc
    if n != value or n < 1 or n > 2000:
        raise ValueError(f"{name} must be an integer in [1, 2000], got {value!r}")
    return n


def check_friction_law(speed, friction_ratio, friction_decay):
    """Validated (A, B, V) of the falling friction law; V = 0 stands for 'not given'."""
    ratio = check_range(friction_ratio, "friction_ratio", 0.0, 1.0)
    decay = check_nonnegative(friction_decay, "friction_decay")
    falling = np.any((ratio != 1.0) & (decay > 0.0))
    if speed is None:
        if falling:
            raise ValueError("speed (rolling speed [m/s], >= 0) is needed with falling friction")
        v = np.zeros(())
    else:
        v = check_nonnegative(speed, "speed")
    return ratio, decay, v


def hertz_curvatures(a, b, normal_force, shear_modulus=8.2e10, poisson=0.28):
    """Gap coefficients (A, B) [1/m] of the Hertz contact with semi-axes a, b under Fz.

    Inverse of :func:`railadhesion.contact.hertz.hertz_3d_from_curvatures` for two identical
    bodies (``E* = G/(1 - nu)``): with ``k = min(a,b)/max(a,b)``, ``e^2 = 1 - k^2``,
    ``max(A,B)/min(A,B) = (E/k^2 - K)/(K - E)`` (the smaller curvature along the longer
    axis) and ``A + B = 2/rho``, ``rho = 4 pi E* sqrt(k) (ab)^(3/2) / (3 Fz E)`` (Johnson
    1985, section 4.2; CONTACT ``hzcalc3d``). Scalars.
    """
    from scipy.special import ellipe, ellipk

    a, b, fz = float(a), float(b), float(normal_force)
    e_star = float(shear_modulus) / (1.0 - float(poisson))
    k = min(a, b) / max(a, b)
    m = 1.0 - k * k
    big_k, big_e = float(ellipk(m)), float(ellipe(m))
    ratio = (big_e / k**2 - big_k) / (big_k - big_e) if k < 1.0 else 1.0
    rho = 4.0 * math.pi * e_star * math.sqrt(k) * (a * b) ** 1.5 / (3.0 * fz * big_e)
    small = (2.0 / rho) / (1.0 + ratio)
    return (small, ratio * small) if a >= b else (ratio * small, small)


@lru_cache(maxsize=64)
def _discrete_shape(aob: float, nu: float, nx: int, ny: int, scale: float) -> np.ndarray:
    """Discrete normal pressure (relative) on the grid of :func:`exact_rolling` for a Hertz
    contact of ratio a/b; the normalised solution does not depend on the size or the load."""
    c, fz, g = 1e-2, 1e5, 8.2e10
    a, b = c * math.sqrt(aob), c / math.sqrt(aob)
    ca, cb = hertz_curvatures(a, b, fz, g, nu)
    xh = scale * (-1.0 + (2.0 * np.arange(nx) + 1.0) / nx)
    yh = scale * (-1.0 + (2.0 * np.arange(ny) + 1.0) / ny)
    gap = ca * (a * xh[None, :]) ** 2 + cb * (b * yh[:, None]) ** 2
    sol = solve_normal(gap, 2 * scale * a / nx, 2 * scale * b / ny, fz, shear_modulus=g,
                       poisson=nu)  # fmt: skip
    shp = sol.pressure / sol.pressure.max()
    shp.flags.writeable = False
    return shp


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "normal_force", "a", "b", "mu",
                            "shear_modulus", "poisson", "speed"))


def exact_rolling(
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
    speed=None,
    friction_ratio=1.0,
    friction_decay=0.0,
    nx: int = 30,
    ny: int = 30,
    scale: float = 1.0,
    spin_offset: float = SPIN_OFFSET_CONTACT,
    tol: float = 1e-6,
    max_iter: int = 5000,
    tol_friction: float = 1e-4,
    max_friction_iter: int = 200,
    return_fields: bool = False,
    warm_start: bool = False,
    pressure: str = "hertz",
    method: str = "auto",
) -> ExactResult:
    """Creep forces of steady rolling by Kalker's exact theory (half-space, Coulomb friction).

    Parameters
    ----------
    creep_long, creep_lat : array_like
        Longitudinal creepage xi = (V - omega R)/V and lateral creepage eta [-].
    spin : array_like
        Spin creepage phi [rad/m].
    normal_force : array_like
        Normal force Fz [N], >= 0.
    a, b : array_like
        Hertzian contact semi-axes along x (rolling direction) and y [m], > 0
        (e.g. from :func:`railadhesion.contact.hertz.hertz_3d`).
    mu : array_like
        Coefficient of friction [-], >= 0: Coulomb's, or the static one mu0 of the falling
        friction law below.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa], > 0. Default 82 GPa.
    poisson : array_like, optional
        Combined Poisson's ratio nu [-], in [0, 0.5]. Default 0.28.
    speed : array_like, optional
        Rolling speed V [m/s], >= 0: the local slip velocity is ``V |s|``. Needed only with
        falling friction.
    friction_ratio, friction_decay : array_like, optional
        Falling friction: the local coefficient of friction falls with the local slip
        velocity w as ``mu(w) = mu [(1 - A) exp(-B w) + A]`` with ``A = friction_ratio``
        (mu_inf/mu0, in [0, 1]) and ``B = friction_decay`` [s/m], >= 0 (Polach 2005;
        CONTACT's law L = 5, and its exponential law L = 4 with FKIN = A mu,
        FEXP1 = (1 - A) mu and SABSH1 = ln(2)/B, SABSH1 being the slip velocity at which the
        falling part is halved). Defaults A = 1, B = 0: Coulomb friction. See Notes.
    nx, ny : int, optional
        Elements along x and y covering ``[-scale a, scale a] x [-scale b, scale b]``
        (CONTACT's MX, MY). Default 30 x 30.
    scale : float, optional
        Extent of the grid relative to the semi-axes (CONTACT's SCALE), >= 1. Default 1.
    spin_offset : float, optional
        The spin term of the rigid slip ``w_y = eta + phi (x + spin_offset dx)`` is evaluated
        ``spin_offset`` elements upstream of the element centre; CONTACT's FACPHI = 1/6
        (default). Vanishes with the grid size.
    tol : float, optional
        Gauss-Seidel: stop when no traction component changes by more than ``tol max|p|``
        in a sweep. Newton: stop when a local (Jacobi) step would change no traction by more
        than ``tol max|p|`` (a comparable measure, about the same accuracy).
    max_iter : int, optional
        Largest number of Gauss-Seidel sweeps (per friction update with falling friction);
        with Newton, of the sweeps that finish a solve Newton left unfinished (after 60
        Newton steps, or a step that found no decrease).
    tol_friction, max_friction_iter : optional
        Falling friction only: stop the outer iteration when the slip-velocity field changes
        by less than ``tol_friction`` (relative, 2-norm), or after ``max_friction_iter``
        updates (then ``friction_iterations == max_friction_iter`` flags non-convergence).
    return_fields : bool, optional
        Also return the grid, tractions, pressure, slip, the stick/slip map and the local
        coefficient of friction.
    warm_start : bool, optional
        Gauss-Seidel only (ignored where Newton solves, so with ``method="auto"`` from
        40 x 40 elements, and for groups of 64 Coulomb cases or more): start each case from
        the tractions of the previous case when the grid is the same (same a/b and nu):
        fewer sweeps along creep curves. The results then depend on the order of the cases
        within the tolerance ``tol``. Default False.
    pressure : {"hertz", "discrete"}, optional
        Normal pressure on the grid: Hertz's ellipse at the element centres (default), or the
        solution of the discrete normal problem on the same grid for the quadratic gap of
        that Hertz contact (:func:`solve_normal`, curvatures from a, b and Fz), which is what
        CONTACT solves: with it the results agree with CONTACT's to the 4 digits it prints
        (docs/validation/exact_solver.md). The discrete contact area is slightly larger than
        the ellipse: use ``scale >= 1.1`` (CONTACT's examples do). Costs one dense normal
        solve per distinct (a/b, nu), about 0.3-2 s on grids of 30 x 30 to 44 x 44.
    method : {"auto", "newton", "gauss-seidel"}, optional
        Solver of the discrete problem (Notes): semismooth Newton (``"newton"``),
        element-wise Gauss-Seidel (``"gauss-seidel"``), or ``"auto"`` (default): Newton on
        grids of 1600 elements (40 x 40, ``NEWTON_MIN_ELEMENTS``) or more; below, Newton for
        64 or more Coulomb cases of one a/b and nu on grids of up to 1024 elements (solved
        together, see Notes) and Gauss-Seidel for the rest. Both give the same solution
        within about ``tol``, with Coulomb or falling friction (the outer iteration on the
        slip velocity is the same around either); the result's ``method`` says which was
        used.

    Returns
    -------
    ExactResult

    Notes
    -----
    Kalker's exact theory of steady rolling (Kalker, *Three-dimensional elastic bodies in
    rolling contact*, Kluwer 1990, chapters 2 and 5; program CONTACT, Vollebregt, with its
    solver for steady rolling, ``m_solvpt.f90``). Discretisation as in CONTACT: a grid of
    ``nx x ny`` equal rectangles; an element is in contact when its centre lies inside the
    ellipse; the pressure is Hertz's, ``p_n = p0 sqrt(1 - x^2/a^2 - y^2/b^2)`` at the
    element centres, scaled so that ``sum(p_n dA) = Fz`` exactly (so ``|F| = mu Fz`` at full
    sliding on any grid; CONTACT solves the discrete normal problem instead). The rigid slip
    is ``w = (xi - phi y, eta + phi x)`` (Kalker 1990, eq. 1.1.11), the slip
    ``s_I = w_I + (u_I - u_{I+})/dx`` (steady state, step dq = dx). Coefficients:
    :func:`tangential_influence`.

    Falling friction (slip-velocity dependent, as in CONTACT; Vollebregt & Schuttelaars,
    J. Sound Vib. 331, 2012): in slip ``|p| = mu(V |s|) p_n``, in stick ``s = 0`` and
    ``|p| <= mu(0) p_n``. Solved by an outer fixed-point iteration on the slip-velocity
    field (as CONTACT does): the local coefficient of friction is frozen at the current
    estimate of the slip velocity, the Coulomb problem with that traction bound is solved
    (warm started), and the estimate is updated from the new slip (under-relaxed when the
    update grows); it starts from zero slip velocity (static friction everywhere, CONTACT's
    INISLP = 1, "slip from below"). Steep laws may have several solutions; this start
    selects the one reached from below. The fixed point satisfies the law exactly; typical
    cases converge in 5-15 updates (``friction_iterations``).

    Convergence: the discretisation error in the forces decreases about as 1/n; see
    ``docs/validation/exact_solver.md`` for a grid-convergence table and the comparison
    with CONTACT.

    Solvers (docs/exact-solver.md, "Solver: method and cost"). *Gauss-Seidel*: element by
    element from the trailing to the leading edge with the local solution of Coulomb's law;
    the influence sums by FFT along the grid's columns (the iteration is the same as with
    direct sums); the sweeps grow with the grid (about 100-300 at 60 x 60), each costing
    ``nx ny (nx + ny)``. *Semismooth Newton*
    (``railadhesion.contact.rolling_newton.solve_steady_rolling``): Coulomb's law as a
    projection equation, linearised on the current stick set and slip directions, each
    linear system solved by GMRES with 2-D FFT products, preconditioned by the summation
    along the rolling direction on the stick elements (the identity on the slip elements);
    each case starts from the solution on a grid half as fine (nested iteration down to 12
    elements), which leaves 3-6 Newton steps, each friction update from the previous
    tractions. On grids of up to 1024 elements, groups of 16 or more Coulomb cases of one
    a/b and nu are solved together, with dense matrix products for the whole group
    (``rolling_newton.solve_steady_rolling_batch``; their coarse starts too, down to 6
    elements along an axis and 144 in all): the fast way to many cases on a small grid. A
    solve Newton does not finish goes on by Gauss-Seidel from Newton's iterate.

    Examples
    --------
    CONTACT's ``fastsim`` example (a = 8 mm, b = 4 mm, Fz = 82 kN, eta = -0.000625,
    phi = 0.625 rad/m, mu = 0.3) on CONTACT's grid (44 x 44 over 1.1 a x 1.1 b); CONTACT
    gives Fy/(mu Fz) = -0.6074:

    >>> r = exact_rolling(0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3, nx=44, ny=44, scale=1.1)
    >>> round(float(r.fy / (0.3 * 82e3)), 4)
    -0.6097
    """
    xi, eta, phi, fz, a_, b_, mu_, g_mod, nu = check_rolling_inputs(
        creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus, poisson
    )
    ratio, decay, v = check_friction_law(speed, friction_ratio, friction_decay)
    tol_friction = float(check_range(tol_friction, "tol_friction", 1e-12, 1e-1))
    max_friction_iter = _check_grid(max_friction_iter, "max_friction_iter")
    nx = _check_grid(nx, "nx")
    ny = _check_grid(ny, "ny")
    scale = float(check_range(scale, "scale", 1.0, 10.0))
    spin_offset = float(check_range(spin_offset, "spin_offset", -1.0, 1.0))
    tol = float(check_range(tol, "tol", 1e-14, 1e-2))
    max_iter = _check_grid(max_iter, "max_iter") if max_iter <= 2000 else int(max_iter)

    args = np.broadcast_arrays(xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, v, ratio, decay)
    shape = args[0].shape
    flat = [np.ascontiguousarray(np.ravel(v), dtype=float) for v in args]
    n = flat[0].size
    out_f = np.empty((n, 4))
    out_iter = np.empty(n, np.int64)
    out_err = np.empty(n)
    out_outer = np.empty(n, np.int64)
    if return_fields:
        fields = [np.empty((n, ny, nx)) for _ in range(4)]
        state = np.empty((n, ny, nx), np.int8)
        mu_all = np.empty((n, ny, nx))
    else:
        fields = [np.empty((1, 1, 1)) for _ in range(4)]
        state = np.empty((1, 1, 1), np.int8)
        mu_all = np.empty((1, 1, 1))
    if pressure not in ("hertz", "discrete"):
        raise ValueError(f"pressure must be 'hertz' or 'discrete', got {pressure!r}")
    if method not in ("auto", "newton", "gauss-seidel"):
        raise ValueError(f"method must be 'auto', 'newton' or 'gauss-seidel', got {method!r}")
    newton = method == "newton" or (method == "auto" and nx * ny >= NEWTON_MIN_ELEMENTS)
    auto = method == "auto"
    out = _BatchOutput(out_f, out_iter, out_err, out_outer, fields, state, mu_all,
                       np.zeros(n, np.bool_))  # fmt: skip
    opts = (nx, ny, scale, spin_offset, tol, max_iter, tol_friction, max_friction_iter,
            bool(return_fields), bool(warm_start))  # fmt: skip
    if pressure == "hertz":
        shapes = None
        _solve_cases(np.arange(n), flat, np.empty((0, 0)), opts, out, newton, auto)
    else:  # one discrete normal solution per (a/b, nu), the cases solved group by group
        aob_all = flat[4] / flat[5]
        keys = np.stack([aob_all, flat[8]], axis=1)
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        shapes = np.empty((n, ny, nx)) if return_fields else None
        for k, (aob_k, nu_k) in enumerate(uniq):
            idx = np.flatnonzero(inverse == k)
            shp = _discrete_shape(float(aob_k), float(nu_k), nx, ny, scale)
            _solve_cases(idx, flat, shp, opts, out, newton, auto)
            if return_fields:
                shapes[idx] = shp
    if n == 0:
        used = "newton" if newton else "gauss-seidel"
    elif out.newton.all():
        used = "newton"
    elif out.newton.any():
        used = "newton+gauss-seidel"
    else:
        used = "gauss-seidel"

    def shaped(v):
        v = v.reshape(shape)
        return v[()] if v.ndim == 0 else v

    extra = {}
    if return_fields:
        xh = scale * (-1.0 + (2.0 * np.arange(nx) + 1.0) / nx)
        yh = scale * (-1.0 + (2.0 * np.arange(ny) + 1.0) / ny)
        a_f, b_f = flat[4], flat[5]
        if shapes is None:
            shapes = np.broadcast_to(
                np.clip(1.0 - xh[None, :] ** 2 - yh[:, None] ** 2, 0.0, None) ** 0.5,
                (n, ny, nx),
            )
        dxa = 2.0 * scale * a_f / nx
        dya = 2.0 * scale * b_f / ny
        pfac = flat[3] / (shapes.sum(axis=(1, 2)) * dxa * dya)
        extra = {
            "x": (a_f[:, None] * xh[None, :]).reshape(*shape, nx),
            "y": (b_f[:, None] * yh[None, :]).reshape(*shape, ny),
            "px": fields[0].reshape(*shape, ny, nx),
            "py": fields[1].reshape(*shape, ny, nx),
            "pn": (pfac[:, None, None] * shapes).reshape(*shape, ny, nx),
            "sx": fields[2].reshape(*shape, ny, nx),
            "sy": fields[3].reshape(*shape, ny, nx),
            "state": state.reshape(*shape, ny, nx),
            "mu_local": mu_all.reshape(*shape, ny, nx),
        }
    _PLAUSIBLE((xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, speed))  # implausible inputs warn
    return ExactResult(
        shaped(out_f[:, 0]),
        shaped(out_f[:, 1]),
        shaped(out_f[:, 2]),
        shaped(out_f[:, 3]),
        shaped(out_iter),
        shaped(out_err),
        friction_iterations=shaped(out_outer),
        method=used,
        **extra,
    )


def solve_tangential(
    pressure,
    dx,
    dy,
    creep_long,
    creep_lat,
    spin,
    mu,
    *,
    x0=None,
    y0=None,
    shear_modulus=8.2e10,
    poisson=0.28,
    speed=None,
    friction_ratio=1.0,
    friction_decay=0.0,
    spin_offset: float = SPIN_OFFSET_CONTACT,
    tol: float = 1e-6,
    max_iter: int = 5000,
    tol_friction: float = 1e-4,
    max_friction_iter: int = 200,
) -> ExactResult:
    """Steady-rolling tangential problem on a given grid and normal pressure (one case).

    The building block of :func:`exact_rolling`, for non-Hertzian pressures or special grids
    (e.g. a single row of long elements, CONTACT's 2D approximation).

    Parameters
    ----------
    pressure : array_like
        Normal pressure p_n [Pa] at the element centres, shape (ny, nx), x along the last
        axis (increasing); elements with p_n <= 0 are outside the contact.
    dx, dy : float
        Element size along x (rolling direction; also the rolling step) and y [m].
    creep_long, creep_lat, spin, mu : float
        Creepages [-], spin [rad/m], coefficient of friction [-].
    x0, y0 : float, optional
        Centre of the first element (column 0, row 0) [m]; default: the grid is centred at
        the origin. Spin and the moment refer to the origin.
    shear_modulus, poisson, speed, friction_ratio, friction_decay, spin_offset, tol, max_iter,
    tol_friction, max_friction_iter
        As in :func:`exact_rolling` (scalars here).

    Returns
    -------
    ExactResult
        Scalars and the fields (always returned here).
    """
    pn = check_nonnegative(pressure, "pressure")
    ny, nx, dx_, dy_ = _grid_cells(pn, "pressure", dx, dy)
    xi, eta, phi = (float(c) for c in check_creepages(creep_long, creep_lat, spin))
    mu_ = float(check_nonnegative(mu, "mu"))
    g = float(check_positive(shear_modulus, "shear_modulus"))
    nu = float(check_range(poisson, "poisson", 0.0, 0.5))
    ratio, decay, v = (float(q) for q in check_friction_law(speed, friction_ratio, friction_decay))
    tol_friction = float(check_range(tol_friction, "tol_friction", 1e-12, 1e-1))
    max_friction_iter = _check_grid(max_friction_iter, "max_friction_iter")
    x0 = -0.5 * (nx - 1) * dx_ if x0 is None else float(check_finite(x0, "x0"))
    y0 = -0.5 * (ny - 1) * dy_ if y0 is None else float(check_finite(y0, "y0"))
    x = x0 + dx_ * np.arange(nx)
    y = y0 + dy_ * np.arange(ny)
    kxx, kxy, kyy = _rolling_kernel(nx, ny, 1.0, dy_ / dx_, nu)
    spec = _kernel_spectra(kxx, kxy, kyy)
    dgx, dgy = _gs_diagonal(dy_ / dx_, nu)
    gb = np.ascontiguousarray(mu_ * pn / g)
    wx = np.ascontiguousarray(np.broadcast_to(xi - phi * y[:, None], (ny, nx)))
    wy = np.ascontiguousarray(
        np.broadcast_to(eta + phi * (x[None, :] + spin_offset * dx_), (ny, nx))
    )
    px = np.zeros((ny, nx))
    py = np.zeros((ny, nx))
    sx = np.zeros((ny, nx))
    sy = np.zeros((ny, nx))
    st = np.zeros((ny, nx), np.int8)
    contact = pn > 0.0
    gb[~contact] = 0.0
    mu_fac = np.ones((ny, nx))

    def inner(bound):
        return _gauss_seidel(bound, wx, wy, kxx, kxy, kyy, spec, dgx, dgy, float(tol),
                             int(max_iter), px, py, sx, sy, st)  # fmt: skip

    if _is_coulomb(ratio, decay, v):
        it, err = inner(gb)
        outer = 0
    else:
        it, err, outer, _ = _falling_friction(gb, inner, v, ratio, decay, tol_friction,
                                              max_friction_iter, sx, sy, mu_fac)  # fmt: skip
    st[~contact] = _EXTERIOR
    mu_fac[~contact] = 0.0
    da = dx_ * dy_
    px *= g
    py *= g
    fx = px.sum() * da
    fy = py.sum() * da
    mz = ((x[None, :] * py - y[:, None] * px).sum()) * da
    nc = max(int(contact.sum()), 1)
    return ExactResult(
        np.float64(fx), np.float64(fy), np.float64(mz),
        np.float64((st == _SLIP).sum() / nc), np.int64(it), np.float64(err),
        x=x, y=y, px=px, py=py, pn=np.array(pn, dtype=float), sx=sx, sy=sy, state=st,
        friction_iterations=np.int64(outer), mu_local=mu_fac * mu_,
    )  # fmt: skip
