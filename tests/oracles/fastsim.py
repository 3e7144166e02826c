"""NumPy oracle of FASTSIM (Kalker 1982; CONTACT's rectangular grid and blended
flexibilities, Vollebregt & Voltr 2023): the march vectorised over contacts and grid rows,
a Python loop along x. The equations are in :func:`railadhesion.contact.fastsim.fastsim`,
Notes; the grid factors are the package's (``_grid_pattern``, ``_rect_pattern``).
"""

from __future__ import annotations

import numpy as np

from oracles.kalker import kalker_coefficients
from railadhesion.contact.fastsim import FastsimResult, _grid_pattern, _rect_pattern

_FACPHI = 1.0 / 6.0
_SPIN_TO_PER_MM = 1e-3
_CHUNK_ELEMENTS = 16384
_TINY_TRACTION = 1e-30
_CREEP_MAX = 1e50


def fastsim(creep_long, creep_lat, spin, normal_force, a, b, mu, *, shear_modulus=8.2e10,
            poisson=0.28, nx=40, ny=40, bound="parabolic", flexibility="original",
            grid="strips", scale=1.1, return_tractions=False):  # fmt: skip
    """FASTSIM of valid inputs, as :func:`railadhesion.contact.fastsim.fastsim`."""
    flx = [] if isinstance(flexibility, str) else [np.asarray(v, float) for v in flexibility]
    args = np.broadcast_arrays(*(np.asarray(v, float) for v in (
        creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus, poisson)), *flx)
    shape = args[0].shape
    xi, eta, phi, fz, a_, b_, mu_, g_mod, nu, *flx = (np.ravel(v) for v in args)
    xi, eta, phi = _limit_creepage(xi, eta, phi, a_)
    if flx:
        l1, l2, l3 = flx
    else:
        l1, l2, l3 = _flexibilities(a_, b_, xi, eta, phi, fz, mu_, g_mod, nu,
                                    flexibility == "blended")
    rect = _rect_pattern(nx, ny, scale, bound) if grid == "rectangular" else None
    return _fastsim_reference(xi, eta, phi, fz, a_, b_, mu_, l1, l2, l3, shape, nx, ny, bound,
                              grid, scale, rect, return_tractions)


def _flexibilities(a, b, xi, eta, phi, normal_force, mu, g_mod, nu, blended):
    """Kalker's three flexibilities L1, L2, L3 [m^3/N], optionally blended (CONTACT 2023)."""
    a_over_b = a / b
    c11, c22, c23, _ = kalker_coefficients(a_over_b, nu)
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
