"""Semismooth Newton solver for the discrete steady-rolling contact problem.

The problem is the one :mod:`railadhesion.contact.exact` states (Kalker's exact theory,
CONTACT's discretisation): on a grid of ``my x mx`` elements with traction bound ``g``
(``mu p_n / G``, 0 outside the contact), find the tractions ``p`` (over G) with the slip
``s = w + K p`` such that, element by element, Coulomb's law holds: ``|p| <= g``; ``s = 0``
where ``|p| < g``; ``p = -g s/|s|`` where ``s != 0``. ``K`` is the rolling operator, a
convolution (its kernel from ``exact._rolling_kernel``).

Coulomb's law is written as the projection equation ``F(p) = p - P_g(p - r s(p)) = 0``
(``P_g`` the projection on the disc of radius g; any r > 0, one scalar for both components, or
the slip would no longer be parallel to the traction; Alart & Curnier, Comput. Methods Appl.
Mech. Eng. 92, 1991, for this form of the friction law), and solved by a semismooth Newton
method (Qi & Sun, Math. Program. 58, 1993; for frictional contact, Christensen, Klarbring, Pang
& Stroemberg, Int. J. Numer. Methods Eng. 42, 1998): each step fixes the stick set and the slip
directions of the current iterate and solves the linearised equations. The linear systems are
solved by restarted GMRES (Saad & Schultz, SIAM J. Sci. Stat. Comput. 7, 1986) with the
products by ``K`` done by 2-D FFT on the zero-padded grid (the Toeplitz structure of the
influence coefficients, as in CONTACT: Vollebregt, J. Comput. Phys. 257, 2014), preconditioned
on the right by the summation along the rolling direction from the leading edge on the stick
elements (the inverse of the rolling difference ``(u_I - u_{I+})/dx`` that dominates ``K``;
what is left is close to the half-space compliance) and by the identity on the slip elements
(whose equations are dominated by the traction change itself). GMRES's tolerance per step is
Eisenstat & Walker's choice 2 (SIAM J. Sci. Comput. 17, 1996; without their safeguard), never
tighter than the stop needs; a backtracking line search on ``|F|`` guards each step.

On small grids, many cases of one grid are solved together (:func:`solve_steady_rolling_batch`):
the products by ``K`` are then one dense matrix product for all of them
(:class:`DenseRolling`), each case keeping its own Newton steps, Krylov space and stop.

The solution is the discrete solution the Gauss-Seidel solver finds; the two stop on
comparable, not identical, measures (here ``max |F|``, a Jacobi step with the true diagonal;
there the change of a sweep), so the same ``tol`` gives about the same accuracy. With a start
from a coarser grid's solution (done by :func:`railadhesion.contact.exact.exact_rolling`) a
case takes 3-6 Newton steps. Everything here is plain NumPy and :mod:`scipy.fft`; the cost is
in the FFTs. Used by ``exact_rolling``; not a public API (the operator is built from the
exact solver's kernel).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from railadhesion._validate import check_finite, check_nonnegative, check_range
from railadhesion.numerics import jit, jitable

__all__ = [
    "SLIP_CAP",
    "BatchSolution",
    "DenseRolling",
    "RollingOperator",
    "SteadySolution",
    "cap_rigid_slip",
    "gmres",
    "gmres_batch",
    "solve_steady_rolling",
    "solve_steady_rolling_batch",
]


class RollingOperator:
    """The rolling operator ``s = K p`` of one grid as a 2-D convolution by FFT.

    Parameters
    ----------
    kxx, kxy, kyy : ndarray
        Kernel ``K(d)`` for every offset ``d = I - J``, shape (2 my - 1, 2 mx - 1), indexed
        ``[dj + my - 1, di + mx - 1]`` (``exact._rolling_kernel``).
    """

    def __init__(self, kxx, kxy, kyy):
        shapes = {np.shape(k) for k in (kxx, kxy, kyy)}
        if len(shapes) != 1 or len(next(iter(shapes))) != 2 or any(
            v % 2 == 0 for v in next(iter(shapes))
        ):
            raise ValueError(
                "kxx, kxy, kyy must be 2-D arrays of one shape (2 my - 1, 2 mx - 1) (odd "
                f"lengths), got shapes {[np.shape(k) for k in (kxx, kxy, kyy)]}"
            )
        ny_off, nx_off = np.shape(kxx)
        self.my = (ny_off + 1) // 2
        self.mx = (nx_off + 1) // 2
        self.fft_shape = (
            sfft.next_fast_len(ny_off, real=True),
            sfft.next_fast_len(nx_off, real=True),
        )
        rows = (np.arange(ny_off) - (self.my - 1)) % self.fft_shape[0]
        cols = (np.arange(nx_off) - (self.mx - 1)) % self.fft_shape[1]

        def spectrum(k):
            pad = np.zeros(self.fft_shape)
            pad[np.ix_(rows, cols)] = k
            return sfft.rfft2(pad)

        self._spectra = np.stack([spectrum(kxx), spectrum(kxy), spectrum(kyy)])
        self._spectra32 = self._spectra.astype(np.complex64)
        self._buf = np.zeros((2, *self.fft_shape))
        self._buf32 = np.zeros((2, *self.fft_shape), np.float32)
        #: ``K(0)``, the (x, y) coefficients of an element's traction in its own slip
        self.diagonal = (float(kxx[self.my - 1, self.mx - 1]), float(kyy[self.my - 1, self.mx - 1]))
        #: products by K done so far by this operator (the measure of cost); the buffers are
        #: reused, so one operator serves one thread at a time
        self.products = 0

    def __call__(self, px, py, single=False):
        """``(K p)_x, (K p)_y`` for tractions ``px, py`` of shape (my, mx). ``single``: in
        single precision (for the Newton systems, solved to 1e-1 to 1e-4 only)."""
        self.products += 1
        buf, spectra = (self._buf32, self._spectra32) if single else (self._buf, self._spectra)
        my, mx = self.my, self.mx
        buf[0, :my, :mx] = px
        buf[1, :my, :mx] = py
        f = sfft.rfft2(buf)
        _spectral_product(spectra, f)
        k = sfft.irfft2(f, self.fft_shape)
        return k[0, :my, :mx], k[1, :my, :mx]


@jit(fastmath=True)
def _spectral_product(spectra, f):
    """In place: ``f[0], f[1] <- Kxx f0 + Kxy f1, Kxy f0 + Kyy f1`` (spectra of the kernel)."""
    hxx, hxy, hyy = spectra[0], spectra[1], spectra[2]
    f0, f1 = f[0], f[1]
    for i in range(f0.shape[0]):
        for j in range(f0.shape[1]):
            a = f0[i, j]
            b = f1[i, j]
            f0[i, j] = hxx[i, j] * a + hxy[i, j] * b
            f1[i, j] = hxy[i, j] * a + hyy[i, j] * b


def gmres(matvec, rhs, rtol, restart=40, max_products=400):
    """Restarted GMRES(m) for ``A x = rhs`` from ``x = 0`` (Saad & Schultz 1986): one system,
    by :func:`gmres_batch` (the one implementation) with a double-precision basis.

    Arnoldi with classical Gram-Schmidt, repeated once when the first pass loses more than
    half the norm's square ("twice is enough": Giraud et al., Numer. Math. 101, 2005), Givens
    rotations for the least-squares problem. Stops when ``|rhs - A x| <= rtol |rhs|`` or
    after ``max_products`` products. Returns ``(x, products, relative residual)``.
    """
    x, products, rel = gmres_batch(lambda cases, v: matvec(v[0])[None], np.asarray(rhs)[None],
                                   np.array([float(rtol)]), restart, max_products,
                                   single=False)  # fmt: skip
    return x[0], int(products[0]), float(rel[0])


@jit
def _givens_column(hess, rot, e, h, hn, k):
    """Column ``k`` of the Hessenberg matrix (``h``, then ``hn`` below the diagonal): apply
    the earlier rotations, make and apply the new one to it and to ``e``; store it in
    ``hess[:, k]``. Returns ``|e[k+1]|``, the least-squares residual."""
    col = np.empty(k + 2)
    col[: k + 1] = h
    col[k + 1] = hn
    for i in range(k):
        t = rot[0, i] * col[i] + rot[1, i] * col[i + 1]
        col[i + 1] = -rot[1, i] * col[i] + rot[0, i] * col[i + 1]
        col[i] = t
    den = math.hypot(col[k], col[k + 1])
    c = col[k] / den if den > 0.0 else 1.0
    s = col[k + 1] / den if den > 0.0 else 0.0
    rot[0, k] = c
    rot[1, k] = s
    col[k] = den
    col[k + 1] = 0.0
    e[k + 1] = -s * e[k]
    e[k] = c * e[k]
    for i in range(k + 2):
        hess[i, k] = col[i]
    return abs(e[k + 1])


@dataclass
class SteadySolution:
    """Result of :func:`solve_steady_rolling` (fields of shape (my, mx))."""

    px: np.ndarray
    """Traction along x, over G [-]."""
    py: np.ndarray
    """Traction along y, over G [-]."""
    sx: np.ndarray
    """Slip along x [-] (0 in stick)."""
    sy: np.ndarray
    """Slip along y [-]."""
    state: np.ndarray
    """0 outside the contact, 1 stick, 2 slip (int8)."""
    newton_steps: int
    """Newton steps taken."""
    products: int
    """Products by the rolling operator in this solve (the cost)."""
    residual: float
    """``max |F(p)|`` over the largest traction."""
    converged: bool
    """Whether ``residual <= tol``."""


#: Floor of |z| in the projection's divisions.
_TINY = 1e-300

#: Largest rigid slip over the largest traction bound that the solvers scale (2^800): beyond,
#: an element slides fully whatever the tractions (the elastic slip ``K p`` is at most some
#: 1e3 bounds), so its rigid slip is capped there, keeping its direction (:func:`cap_rigid_slip`).
SLIP_CAP = 2.0**800


@jit
def cap_rigid_slip(wx, wy, gmax):
    """The rigid slip ``wx, wy`` [-] (R, C), row i a case with largest traction bound
    ``gmax[i]`` (R,), with every element's slip capped at magnitude ``SLIP_CAP gmax[i]``, its
    direction kept. Returns the capped copies and where they were capped (R, C).

    The problem is invariant under ``(p, w, g) -> (p, w, g)/gmax``; the solvers solve it so
    scaled, where a friction so small that the bound is denormal (mu = 1e-310) makes ``w/gmax``
    overflow. An element whose rigid slip exceeds ``SLIP_CAP gmax`` slides fully, ``p = -g
    w/|w|`` to rounding, with or without the cap; capped, nothing overflows. The slip is
    linear in ``w``: the caller adds the removed part ``w - capped`` back to the slip it
    reports. Ordinary inputs (creepages below 1, mu p_n/G above 1e-200) are never capped and
    are returned bit for bit.
    """
    rows, cols = wx.shape
    cx = np.empty((rows, cols))
    cy = np.empty((rows, cols))
    capped = np.zeros((rows, cols), np.bool_)
    for i in range(rows):
        lim = SLIP_CAP * gmax[i]  # inf for bounds beyond 2^223: nothing to cap then
        for j in range(cols):
            x = wx[i, j]
            y = wy[i, j]
            n = math.hypot(x, y)
            if n > lim:  # the unit vector times lim: w lim/|w| could underflow in lim/|w|
                cx[i, j] = x / n * lim
                cy[i, j] = y / n * lim
                capped[i, j] = True
            else:
                cx[i, j] = x
                cy[i, j] = y
    return cx, cy, capped


def _projection(px, py, sx, sy, g, r):
    """Coulomb's law as a projection, element by element, for fields of any shape:
    ``F = p - P_g(p - r s)`` with ``P_g`` the projection on the disc of radius ``g`` (0
    outside the contact; Alart & Curnier 1991). Returns ``(Fx, Fy, zx, zy, |z|, slip, |P_g(z)|)``
    with ``z = p - r s`` and ``slip`` where ``|z| > g`` in the contact."""
    inside = g > 0.0
    zx, zy = px - r * sx, py - r * sy
    nz = np.hypot(zx, zy)
    slip = inside & (nz > g)
    f = np.where(slip, g / np.maximum(nz, _TINY), 1.0) * inside
    qx, qy = f * zx, f * zy  # P_g(z), the projected traction
    return px - qx, py - qy, zx, zy, nz, slip, np.hypot(qx, qy)


def _onto_bound(px, py, g, slip):
    """The factor that puts tractions back on their bound: where ``|p| > g``, and on it where
    ``slip`` (0 outside the contact)."""
    pt = np.hypot(px, py)
    on = (pt > g) | (slip & (pt > 0.0))
    return np.where(on, g / np.where(pt > 0.0, pt, 1.0), 1.0) * (g > 0.0)


def _forcing(err, last_err, later, tol):
    """GMRES's relative tolerance for a Newton step: Eisenstat & Walker's choice 2
    (``0.9 (err/last_err)^2``, 0.1 at the first step, ``later`` False; without their
    safeguard), never tighter than the stop needs (``0.3 tol/err``) nor looser than 0.1."""
    eta = np.where(later, np.minimum(0.1, 0.9 * (err / np.maximum(last_err, _TINY)) ** 2), 0.1)
    return np.minimum(np.maximum(eta, 0.3 * tol / err), 0.1)


@jitable
def _newton_row(dx, dy, kx, ky, slip, nx, ny, c, r):
    """One element's row of the Newton matrix times ``dp = (dx, dy)``, with ``(kx, ky) = K dp``
    there: ``r K dp`` in stick; ``dp - c (I - n n^T)(dp - r K dp)`` in slip (the derivative of
    ``p - P_g(p - r s)`` at ``z = p - r s``, ``n = z/|z|``, ``c = g/|z|``)."""
    if slip:
        ux = dx - r * kx
        uy = dy - r * ky
        d = nx * ux + ny * uy
        return dx - c * (ux - d * nx), dy - c * (uy - d * ny)
    return r * kx, r * ky


@jit(fastmath=True)
def _linearised(dx, dy, kx, ky, rows, cols, slip, nx, ny, c, r, out):
    """Newton matrix times ``dp`` on the contact elements (``rows, cols``; packed as in
    :func:`_mixed_precondition`; :func:`_newton_row` each, ``slip, nx, ny, c`` packed)."""
    m = rows.size
    for k in range(m):
        j = rows[k]
        i = cols[k]
        out[k], out[m + k] = _newton_row(dx[j, i], dy[j, i], kx[j, i], ky[j, i], slip[k],
                                         nx[k], ny[k], c[k], r)  # fmt: skip


def solve_steady_rolling(
    g, wx, wy, operator: RollingOperator, *, tol=1e-6, px=None, py=None, max_steps=60
) -> SteadySolution:
    """Steady rolling with Coulomb friction on one grid, by semismooth Newton (module doc).

    Parameters
    ----------
    g : ndarray
        Traction bound ``mu p_n / G`` per element, >= 0 and finite, shape (my, mx) of the
        operator's grid; 0 outside the contact.
    wx, wy : ndarray
        Rigid slip per element [-], (my, mx).
    operator : RollingOperator
        The rolling operator of the grid.
    tol : float, optional
        Stop when ``max |F(p)| <= tol max |p|`` (F as in the module doc, with
        ``r = 1/mean(K(0))``: the change a Jacobi step with the local solution would make;
        comparable to the Gauss-Seidel solver's stop, not the same), in [1e-14, 0.1].
    px, py : ndarray, optional
        Start (tractions over G); projected on the bound. Default 0.
    max_steps : int, optional
        Largest number of Newton steps, >= 1; ``converged`` is False when they run out, or
        when a step finds no decrease of ``|F|``.

    Returns
    -------
    SteadySolution
    """
    shape = (operator.my, operator.mx)
    g = check_nonnegative(g, "g")
    wx, wy = check_finite(wx, "wx"), check_finite(wy, "wy")
    for name, v in (("g", g), ("wx", wx), ("wy", wy)):
        if v.shape != shape:
            raise ValueError(f"{name} must have the operator's grid shape {shape}, got {v.shape}")
    if not np.all(np.isfinite(g)):
        raise ValueError("g must be finite (a traction bound >= 0 per element)")
    tol = float(check_range(tol, "tol", 1e-14, 1e-1))
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) or \
            max_steps < 1:  # fmt: skip
        raise ValueError(f"max_steps must be an integer >= 1, got {max_steps!r}")
    if (px is None) != (py is None):
        raise ValueError("px and py must be given together (the start), or neither")
    products0 = operator.products
    inside = g > 0.0
    gmax = float(g.max()) if g.size else 0.0
    zero = np.zeros(shape)
    if gmax <= 0.0:
        return SteadySolution(zero.copy(), zero.copy(), wx.copy(), wy.copy(),
                              np.zeros(shape, np.int8), 0, 0, 0.0, True)  # fmt: skip
    # the problem is invariant under (p, w, g) -> (p, w, g)/gmax: solved at a bound of order 1
    # whatever mu p_n/G is (no underflow in norms and floors), scaled back at the end; rigid
    # slips beyond 2^800 bounds capped (full sliding), or w/gmax overflows for denormal bounds
    wx0, wy0 = wx, wy
    cx, cy, capped = cap_rigid_slip(wx, wy, np.full(shape[0], gmax))
    g = g / gmax
    wx, wy = cx / gmax, cy / gmax
    r = 2.0 / (operator.diagonal[0] + operator.diagonal[1])
    if px is None:
        px, py = zero.copy(), zero.copy()
    else:
        px = check_finite(px, "px") / gmax
        py = check_finite(py, "py") / gmax
        f = _onto_bound(px, py, g, False)
        px, py = px * f, py * f

    def evaluate(px, py):
        kx, ky = operator(px, py)
        sx, sy = wx + kx, wy + ky
        fx, fy, zx, zy, nz, slip, qn = _projection(px, py, sx, sy, g, r)
        pref = max(float(np.max(qn)), 1e-12)  # the bound is scaled to 1
        err = max(float(np.max(np.abs(fx))), float(np.max(np.abs(fy)))) / pref
        return (fx, fy, sx, sy, zx, zy, nz, slip), err

    (fx, fy, sx, sy, zx, zy, nz, slip), err = evaluate(px, py)
    steps = 0
    last_err = err
    rows, cols = np.nonzero(inside)
    m = rows.size
    dpx, dpy = np.zeros_like(g), np.zeros_like(g)
    one = np.zeros(1, np.int64)

    def precondition(v, slip_k):  # dp = M v, on the grid (0 outside the contact)
        dp = np.empty((1, v.size))
        _mixed_precondition(v[None], rows, one, slip_k[None], dp)
        dpx[rows, cols] = dp[0, :m]
        dpy[rows, cols] = dp[0, m:]
    while err > tol and steps < max_steps:
        steps += 1
        slip_k = slip[rows, cols]
        inv = np.where(slip_k, 1.0 / np.maximum(nz[rows, cols], _TINY), 0.0)
        nx_, ny_ = zx[rows, cols] * inv, zy[rows, cols] * inv
        c = g[rows, cols] * inv

        def jac(v, slip_k=slip_k, nx_=nx_, ny_=ny_, c=c):
            precondition(v, slip_k)
            kx, ky = operator(dpx, dpy, single=True)
            out = np.empty(v.size)
            _linearised(dpx, dpy, kx, ky, rows, cols, slip_k, nx_, ny_, c, r, out)
            return out

        eta = float(_forcing(err, last_err, steps > 1, tol))
        rhs = -np.concatenate((fx[rows, cols], fy[rows, cols]))
        y, _, _ = gmres(jac, rhs, eta)
        precondition(y, slip_k)
        # backtracking on |F| (2-norm): the full step unless it fails to decrease; no step
        # that decreases it in 5 halvings: stop, unconverged (the caller hands over)
        fnorm = math.sqrt(float(np.sum(fx * fx + fy * fy)))
        lam = 1.0
        accepted = None
        for _ in range(5):
            cand = (px + lam * dpx, py + lam * dpy)
            res, err_new = evaluate(*cand)
            if math.sqrt(float(np.sum(res[0] ** 2 + res[1] ** 2))) <= (1.0 - 1e-4 * lam) * fnorm:
                accepted = (cand, res, err_new)
                break
            lam *= 0.5
        if accepted is None:
            break
        last_err = err
        (px, py), (fx, fy, sx, sy, zx, zy, nz, slip), err = accepted
    state = np.where(inside, np.where(slip, 2, 1), 0).astype(np.int8)
    sx = np.where(slip, sx, 0.0) * gmax
    sy = np.where(slip, sy, 0.0) * gmax
    back = capped & slip  # the slip is linear in w: the capped part of w added back
    sx[back] += (wx0 - cx)[back]
    sy[back] += (wy0 - cy)[back]
    # the returned tractions satisfy the bound exactly, and lie on it in slip
    f = _onto_bound(px, py, g, slip)
    return SteadySolution(px * (f * gmax), py * (f * gmax), sx, sy, state, steps,
                          operator.products - products0, err, err <= tol)  # fmt: skip


# ---------------------------------------------------------------------------------------------
# Many cases of one grid at once: dense products, batched GMRES
# ---------------------------------------------------------------------------------------------


class DenseRolling:
    """The rolling operator of one grid as dense matrices on its contact elements, for solving
    many cases of that grid at once (:func:`solve_steady_rolling_batch`).

    On small grids a product by ``K`` costs less as one matrix product for a whole batch of
    cases than as FFTs case by case: the influence matrix is shared by every case of the grid,
    and a matrix-matrix product runs near the processor's peak. Built from the same kernel as
    :class:`RollingOperator`, for the elements where ``inside`` is True (the same for every
    case of the batch); vectors are packed as ``[x components, y components]`` of those
    elements in row-major order.

    Parameters
    ----------
    kxx, kxy, kyy : ndarray
        Kernel as for :class:`RollingOperator`, shape (2 my - 1, 2 mx - 1).
    inside : ndarray of bool
        The contact elements, shape (my, mx).
    """

    def __init__(self, kxx, kxy, kyy, inside):
        shape_k = np.shape(kxx)
        inside = np.asarray(inside, dtype=bool)
        if any(np.shape(k) != shape_k for k in (kxy, kyy)) or len(shape_k) != 2 or \
                inside.shape != ((shape_k[0] + 1) // 2, (shape_k[1] + 1) // 2):  # fmt: skip
            raise ValueError(
                "kxx, kxy, kyy must have one shape (2 my - 1, 2 mx - 1) and inside (my, mx), "
                f"got {[np.shape(k) for k in (kxx, kxy, kyy)]} and {inside.shape}"
            )
        self.my, self.mx = inside.shape
        self.inside = inside
        self.rows, self.cols = np.nonzero(inside)
        m = self.rows.size
        self.m = m
        dj = self.rows[:, None] - self.rows[None, :] + self.my - 1
        di = self.cols[:, None] - self.cols[None, :] + self.mx - 1
        bxx, bxy, byy = (np.asarray(k, float)[dj, di] for k in (kxx, kxy, kyy))
        #: ``K`` on the packed contact elements, (2m, 2m): ``(K p)_k = sum_l K[k, l] p_l``
        self.matrix = np.block([[bxx, bxy], [bxy, byy]])
        #: the same in single precision, for the products of the Newton systems
        self.matrix32 = self.matrix.astype(np.float32)
        self.diagonal = (float(kxx[self.my - 1, self.mx - 1]), float(kyy[self.my - 1, self.mx - 1]))

    def pack(self, fx, fy):
        """Packed vectors (B, 2m) of fields (B, my, mx)."""
        return np.concatenate((fx[:, self.rows, self.cols], fy[:, self.rows, self.cols]), axis=1)

    def unpack(self, v):
        """Fields (B, my, mx) x and y of packed vectors (B, 2m); 0 outside the contact."""
        m = self.m
        fx = np.zeros((v.shape[0], self.my, self.mx))
        fy = np.zeros_like(fx)
        fx[:, self.rows, self.cols] = v[:, :m]
        fy[:, self.rows, self.cols] = v[:, m:]
        return fx, fy


@jit
def _givens_batch(hess, rot, e, live, h, hn, k, out):
    """:func:`_givens_column` for the cases ``live`` of a batch (``hess`` (b, M+1, M), ``rot``
    (b, 2, M), ``e`` (b, M+1); ``h`` (len(live), k+1), ``hn`` (len(live),)); ``out`` receives
    each case's least-squares residual."""
    for q in range(live.size):
        out[q] = _givens_column(hess[live[q]], rot[live[q]], e[live[q]], h[q], hn[q], k)


@jit
def _back_substitute(hess, e, k_used, y):
    """``y[b, :k] = R_b^{-1} e_b[:k]`` (R the upper triangle of ``hess[b]``, k = ``k_used[b]``);
    0 beyond. A zero pivot (a breakdown) gives a zero component."""
    for b in range(k_used.size):
        k = k_used[b]
        y[b, :] = 0.0
        for i in range(k - 1, -1, -1):
            s = e[b, i]
            for j in range(i + 1, k):
                s -= hess[b, i, j] * y[b, j]
            d = hess[b, i, i]
            y[b, i] = s / d if d != 0.0 else 0.0


def gmres_batch(matvec, rhs, rtol, restart=40, max_products=400, single=True):
    """GMRES(m) for many independent systems ``A_b x_b = rhs_b`` at once (:func:`gmres`, case
    by case: each case its own Krylov space, stop and solution; the products of a step are one
    call for all cases still running).

    ``matvec(cases, V)`` returns ``A_b v_b`` for the cases ``cases`` (indices into the batch)
    and vectors ``V`` (len(cases), n). ``rhs`` (B, n), ``rtol`` (B,). ``single``: the Krylov
    basis in single precision (enough for systems solved to 1e-1 to 1e-4, as Newton's are;
    half the memory traffic). A breakdown (a zero pivot) leaves the solution as far as it got.
    Returns ``(x, products, relative residual)`` per case.
    """
    if isinstance(restart, bool) or not isinstance(restart, int | np.integer) or restart < 1:
        raise ValueError(f"restart must be an integer >= 1, got {restart!r}")
    if isinstance(max_products, bool) or not isinstance(max_products, int | np.integer) or \
            max_products < 1:  # fmt: skip
        raise ValueError(f"max_products must be an integer >= 1, got {max_products!r}")
    dtype = np.float32 if single else np.float64
    nb, n = rhs.shape
    x = np.zeros((nb, n))
    bnorm = np.linalg.norm(rhs, axis=1)
    rel_all = np.zeros(nb)
    products = np.zeros(nb, np.int64)
    todo = np.flatnonzero(bnorm > 0.0)
    r = rhs[todo]
    m = int(restart)
    while todo.size:
        beta = np.linalg.norm(r, axis=1)
        rel_all[todo] = beta / bnorm[todo]
        go = (rel_all[todo] > rtol[todo]) & (products[todo] < max_products) & (beta > 0.0)
        todo, r, beta = todo[go], r[go], beta[go]
        if not todo.size:
            break
        _gmres_cycle(matvec, todo, r, beta, bnorm, rtol, m, max_products, x, products, rel_all,
                     dtype)  # fmt: skip
        again = (rel_all[todo] > rtol[todo]) & (products[todo] < max_products)
        todo = todo[again]
        if todo.size:
            r = rhs[todo] - matvec(todo, x[todo])
            products[todo] += 1
    return x, products, rel_all


def _gmres_cycle(matvec, slots, r, beta, bnorm, rtol, m, max_products, x, products, rel_all,
                 dtype):  # fmt: skip
    """One cycle of :func:`gmres_batch` (at most ``m`` products per case) for the cases
    ``slots`` with residuals ``r``: adds the corrections to ``x``; the basis of ``dtype``.
    Cases that stop early still ride
    along in the products (their results unused) until they are half the batch; then they
    are finished and the arrays compacted, so the basis is copied at most a few times."""
    b, n = r.shape
    basis = np.zeros((b, m + 1, n), dtype)
    hess = np.zeros((b, m + 1, m))
    rot = np.zeros((b, 2, m))
    e = np.zeros((b, m + 1))
    e[:, 0] = beta
    basis[:, 0] = r / beta[:, None]
    k_used = np.zeros(b, np.int64)
    live = np.ones(b, bool)

    def finish(which):
        y = np.zeros((which.sum(), m))
        _back_substitute(hess[which], e[which], k_used[which], y)
        x[slots[which]] += np.einsum("bk,bkn->bn", y, basis[which, :m], dtype=float)

    for k in range(m):
        if live.sum() <= b // 2:  # compact: finish the stopped cases, keep the live ones
            finish(~live)
            slots, basis, hess, rot, e, k_used = (
                v[live] for v in (slots, basis, hess, rot, e, k_used))
            b = slots.size
            live = np.ones(b, bool)
        w = matvec(slots, basis[:, k])
        idx = np.flatnonzero(live)
        products[slots[idx]] += 1
        h = np.empty((idx.size, k + 1))
        hn = np.empty(idx.size)
        _arnoldi(basis, idx, w, k, h, hn)
        res = np.empty(idx.size)
        _givens_batch(hess, rot, e, idx, h, hn, k, res)
        cases = slots[idx]
        rel = res / bnorm[cases]
        rel_all[cases] = rel
        k_used[idx] = k + 1
        stop = (hn == 0.0) | (rel <= rtol[cases]) | (products[cases] >= max_products)
        live[idx[stop]] = False
        if not live.any():
            break
    finish(np.ones(b, bool))


@jit(fastmath=True)
def _arnoldi(basis, idx, w, k, h, hn):
    """Orthogonalise ``w[c]`` against ``basis[c, :k+1]`` for the cases ``c = idx[q]``
    (classical Gram-Schmidt, repeated once when the first pass loses more than half the norm's
    square, as :func:`gmres`); ``h[q]``, ``hn[q]`` receive the Hessenberg column and the norm
    left, ``basis[c, k+1]`` the new vector (when there is room)."""
    n = w.shape[1]
    m1 = basis.shape[1]
    for q in range(idx.size):
        c = idx[q]
        v = basis[c]
        wc = w[c]
        wn = 0.0
        for i in range(n):
            wn += wc[i] * wc[i]
        for j in range(k + 1):
            h[q, j] = 0.0
        for rep in range(2):
            for j in range(k + 1):
                t = 0.0
                for i in range(n):
                    t += v[j, i] * wc[i]
                h[q, j] += t
                for i in range(n):
                    wc[i] -= t * v[j, i]
            left = 0.0
            for i in range(n):
                left += wc[i] * wc[i]
            if rep == 0 and left >= 0.49 * wn:
                break
        hn[q] = math.sqrt(left)
        if k + 1 < m1 and hn[q] > 0.0:
            inv = 1.0 / hn[q]
            for i in range(n):
                v[k + 1, i] = wc[i] * inv


@jit(fastmath=True)
def _mixed_precondition(v, rows, cases, slip, out):
    """``out = M v`` with M the summation from the leading edge on the stick elements and the
    identity on the slip elements of case ``cases[q]`` (row q)."""
    m = rows.size
    for q in range(cases.size):
        c = cases[q]
        for half in range(2):
            o = half * m
            acc = 0.0
            for k in range(m - 1, -1, -1):
                if k == m - 1 or rows[k] != rows[k + 1]:
                    acc = 0.0
                if slip[c, k]:
                    out[q, o + k] = v[q, o + k]
                else:
                    acc += v[q, o + k]
                    out[q, o + k] = acc


@jit(fastmath=True)
def _batch_linearised(dp, kd, cases, slip, nx, ny, cf, r, out):
    """:func:`_linearised` for packed batches: row ``q`` of ``out`` from ``dp = M v`` and
    ``kd = K M v`` of case ``cases[q]`` (its ``slip``, ``nx, ny, cf`` rows;
    :func:`_newton_row` each)."""
    m = slip.shape[1]
    for q in range(cases.size):
        c = cases[q]
        for k in range(m):
            out[q, k], out[q, m + k] = _newton_row(dp[q, k], dp[q, m + k], kd[q, k],
                                                   kd[q, m + k], slip[c, k], nx[c, k],
                                                   ny[c, k], cf[c, k], r)  # fmt: skip


@dataclass
class BatchSolution:
    """Result of :func:`solve_steady_rolling_batch`: fields packed (B, 2m) as in
    :class:`DenseRolling`, the rest per case (B,)."""

    p: np.ndarray
    """Tractions over G, packed [-]."""
    s: np.ndarray
    """Slip, packed [-] (0 in stick)."""
    slip: np.ndarray
    """Whether each contact element slips, (B, m)."""
    newton_steps: np.ndarray
    products: np.ndarray
    residual: np.ndarray
    converged: np.ndarray


def solve_steady_rolling_batch(g, w, dense: DenseRolling, *, tol=1e-6, p=None, max_steps=60):
    """:func:`solve_steady_rolling` for many cases of one grid at once, with dense products
    (:class:`DenseRolling`) and :func:`gmres_batch`: the same equations, start, forcing
    terms, line search and stop, case by case.

    Parameters
    ----------
    g : ndarray
        Traction bound per contact element, > 0 and finite, (B, m).
    w : ndarray
        Rigid slip, packed (B, 2m).
    dense : DenseRolling
    tol, max_steps
        As for :func:`solve_steady_rolling`.
    p : ndarray, optional
        Start, packed (B, 2m); projected on the bound. Default 0.
    """
    m = dense.m
    g = np.asarray(g, float)
    w = np.asarray(w, float)
    nb = g.shape[0] if g.ndim == 2 else -1
    if g.shape != (nb, m) or w.shape != (nb, 2 * m):
        raise ValueError(f"g must have shape (B, {m}) and w (B, {2 * m}), got {g.shape}, "
                         f"{w.shape}")  # fmt: skip
    if not (np.all(np.isfinite(g)) and np.all(g > 0.0)):
        raise ValueError("g must be finite and > 0 on every contact element")
    w = check_finite(w, "w")
    tol = float(check_range(tol, "tol", 1e-14, 1e-1))
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) or \
            max_steps < 1:  # fmt: skip
        raise ValueError(f"max_steps must be an integer >= 1, got {max_steps!r}")
    # scaled to a bound of 1 per case, rigid slips capped (as solve_steady_rolling)
    gmax = g.max(axis=1)
    cx, cy, capped = cap_rigid_slip(w[:, :m], w[:, m:], gmax)
    capped = np.concatenate((capped, capped), axis=1)
    w_capped = np.concatenate((cx, cy), axis=1)
    removed = w - w_capped  # 0 where not capped
    g = g / gmax[:, None]
    w = w_capped / gmax[:, None]
    if p is None:
        p = np.zeros((nb, 2 * m))
    else:
        p = check_finite(np.asarray(p, float), "p")
        if p.shape != (nb, 2 * m):
            raise ValueError(f"p must have shape ({nb}, {2 * m}) (one start per case), got "
                             f"{p.shape}")  # fmt: skip
        p = p / gmax[:, None]
        f = _onto_bound(p[:, :m], p[:, m:], g, False)
        p = p * np.concatenate((f, f), axis=1)
    r = 2.0 / (dense.diagonal[0] + dense.diagonal[1])
    kt = np.ascontiguousarray(dense.matrix.T)
    k32 = np.ascontiguousarray(dense.matrix32.T)

    def evaluate(cases, pc):
        s = w[cases] + pc @ kt
        fx, fy, zx, zy, nz, slip, qn = _projection(pc[:, :m], pc[:, m:], s[:, :m], s[:, m:],
                                                   g[cases], r)  # fmt: skip
        fres = np.concatenate((fx, fy), axis=1)
        err = np.abs(fres).max(axis=1) / np.maximum(qn.max(axis=1), 1e-12)
        return fres, s, np.concatenate((zx, zy), axis=1), nz, slip, err

    allc = np.arange(nb)
    fres, s, z, nz, slip, err = evaluate(allc, p)
    steps = np.zeros(nb, np.int64)
    products = np.zeros(nb, np.int64)
    last_err = err.copy()
    failed = np.zeros(nb, bool)
    while True:
        act = np.flatnonzero((err > tol) & ~failed & (steps < max_steps))
        if not act.size:
            break
        steps[act] += 1
        slip_a = slip[act]
        inv = np.where(slip_a, 1.0 / np.maximum(nz[act], _TINY), 0.0)
        nx_, ny_ = z[act, :m] * inv, z[act, m:] * inv
        c = g[act] * inv

        def jac(k, v, nx_=nx_, ny_=ny_, c=c, slip_a=slip_a):  # k: indices into act
            dp = np.empty(v.shape)
            _mixed_precondition(v, dense.rows, k, slip_a, dp)
            kd = dp.astype(np.float32) @ k32
            out = np.empty(v.shape)
            _batch_linearised(dp, kd, k, slip_a, nx_, ny_, c, r, out)
            return out

        eta = _forcing(err[act], last_err[act], steps[act] > 1, tol)
        y, used, _ = gmres_batch(jac, -fres[act], eta)
        products[act] += used
        dp = np.empty(y.shape)
        _mixed_precondition(y, dense.rows, np.arange(act.size), slip_a, dp)
        fnorm = np.linalg.norm(fres[act], axis=1)
        lam = np.ones(act.size)
        pending = np.arange(act.size)
        for _ in range(5):
            cases = act[pending]
            cand = p[cases] + lam[pending, None] * dp[pending]
            res = evaluate(cases, cand)
            products[cases] += 1
            ok = np.linalg.norm(res[0], axis=1) <= (1.0 - 1e-4 * lam[pending]) * fnorm[pending]
            good = cases[ok]
            last_err[good] = err[good]
            p[good] = cand[ok]
            fres[good], s[good], z[good], nz[good], slip[good], err[good] = (
                v[ok] for v in res)
            lam[pending[~ok]] *= 0.5
            pending = pending[~ok]
            if not pending.size:
                break
        failed[act[pending]] = True
    # the returned tractions satisfy the bound exactly, and lie on it in slip
    f = _onto_bound(p[:, :m], p[:, m:], g, slip)
    f2 = np.concatenate((f, f), axis=1)
    slip2 = np.concatenate((slip, slip), axis=1)
    s = np.where(slip2, s, 0.0) * gmax[:, None]
    back = slip2 & capped  # the slip is linear in w: the capped part of w added back
    s[back] += removed[back]
    return BatchSolution(p * f2 * gmax[:, None], s, slip, steps, products, err,
                         err <= tol)  # fmt: skip
