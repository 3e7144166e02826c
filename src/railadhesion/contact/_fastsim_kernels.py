"""Compiled (numba) FASTSIM marches, used by :func:`railadhesion.contact.fastsim.fastsim`.

Same algorithm and the same operations as the NumPy reference (``_march`` and
``_march_rect`` in :mod:`railadhesion.contact.fastsim`): each contact is marched from the
leading edge, all strips (or grid rows) advancing side by side in the inner loop. Contacts
run in parallel (numba ``prange``) for large batches. Imported on first use (numba is not
imported with the package); compiled code is cached on disk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from railadhesion._jit import serial_and_parallel

_TINY_TRACTION = 1e-30
_FACPHI = 1.0 / 6.0
#: Below this many contacts the serial kernels run (thread start-up, and on a busy machine
#: waiting for a descheduled thread, cost more than the work).
_PARALLEL_MIN = 500


@njit(cache=True, error_model="numpy")
def _strip_contact(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm, sq_sum):
    """FASTSIM on Kalker's strips for one contact: (fx, fy, mz, slip_fraction)."""
    ny = eta_j.size
    nx = tx.size
    px = np.empty(ny)
    py = np.empty(ny)
    dpx = np.empty(ny)
    dpy1 = np.empty(ny)
    inc = np.empty(ny)
    gfac = np.empty(ny)
    spx = np.zeros(ny)
    spy = np.zeros(ny)
    qpy = np.zeros(ny)
    nslip = np.zeros(ny)
    phi_l3 = phi / l3
    xi_l1 = xi / l1
    eta_l2 = eta / l2
    gf = mu * fz / (a * b * norm)
    for j in range(ny):
        dx = (2.0 / nx) * a * sq[j]
        y = b * eta_j[j]
        a_strip = a * sq[j]
        dpx[j] = -dx * (xi_l1 - phi_l3 * y)
        dpy0 = -dx * (eta_l2 + phi_l3 * a_strip)
        dpy1[j] = phi_l3 * dx * dx
        gfac[j] = gf * gy[j]
        px[j] = 0.5 * dpx[j]
        py[j] = 0.5 * dpy0 + 0.125 * dpy1[j]
        inc[j] = dpy0
    for i in range(nx):
        t = tx[i]
        if i > 0:
            for j in range(ny):
                inc[j] += dpy1[j]
                px[j] += dpx[j]
                py[j] += inc[j]
        for j in range(ny):
            pxj = px[j]
            pyj = py[j]
            g = gfac[j] * t
            r = math.sqrt(pxj * pxj + pyj * pyj)
            nslip[j] += 1.0 if r > g else 0.0
            f = min(g / (r + _TINY_TRACTION), 1.0)
            pxj *= f
            pyj *= f
            px[j] = pxj
            py[j] = pyj
            spx[j] += pxj
            spy[j] += pyj
            qpy[j] += spy[j]
    dy = (2.0 / ny) * b
    sfx = 0.0
    sfy = 0.0
    smz = 0.0
    sns = 0.0
    for j in range(ny):
        dx = (2.0 / nx) * a * sq[j]
        da = dx * dy
        y = b * eta_j[j]
        a_strip = a * sq[j]
        sfx += spx[j] * da
        sfy += spy[j] * da
        sum_xpy = a_strip * spy[j] - dx * (nx * spy[j] - qpy[j] + 0.5 * spy[j])
        smz += (sum_xpy - y * spx[j]) * da
        sns += nslip[j] * sq[j]
    return sfx, sfy, smz, min(sns / (nx * sq_sum), 1.0)


def _strips_py(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm):
    n = xi.size
    fx = np.empty(n)
    fy = np.empty(n)
    mz = np.empty(n)
    sf = np.empty(n)
    sq_sum = 0.0
    for j in range(sq.size):
        sq_sum += sq[j]
    for c in prange(n):
        fx[c], fy[c], mz[c], sf[c] = _strip_contact(xi[c], eta[c], phi[c], fz[c], a[c], b[c],
                                                    mu[c], l1[c], l2[c], l3[c], eta_j, sq, tx,
                                                    gy, norm, sq_sum)  # fmt: skip
    return fx, fy, mz, sf


@njit(cache=True, error_model="numpy")
def strips_one(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm):
    """FASTSIM on Kalker's strips for one contact given as floats."""
    return _strip_contact(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, norm,
                          np.sum(sq))  # fmt: skip


def _rect_py(xi, eta, phi, fz, a, b, mu, l1, l2, l3, scale, xh, yh, mask, shape, n_in):
    n = xi.size
    nx = xh.size
    ny = yh.size
    fx = np.empty(n)
    fy = np.empty(n)
    mz = np.empty(n)
    sf = np.empty(n)
    for c in prange(n):
        px = np.zeros(ny)
        py = np.zeros(ny)
        dpx = np.empty(ny)
        spx = np.zeros(ny)
        spy = np.zeros(ny)
        sxpy = np.zeros(ny)
        nslip = np.zeros(ny)
        ac = a[c]
        dx = (2.0 * scale / nx) * ac
        dy = (2.0 * scale / ny) * b[c]
        phi_l3 = phi[c] / l3[c]
        xi_l1 = xi[c] / l1[c]
        for j in range(ny):
            dpx[j] = -dx * (xi_l1 - phi_l3 * (b[c] * yh[j]))
        dpy0 = -dx * (eta[c] / l2[c] + phi_l3 * (_FACPHI * dx))
        dpy1 = -dx * phi_l3 * ac
        gfac = mu[c] * fz[c] / (ac * b[c])
        for i in range(nx):
            dpy = dpy0 + xh[i] * dpy1
            for j in range(ny):
                m = mask[i, j]
                pxj = (px[j] + dpx[j]) * m
                pyj = (py[j] + dpy) * m
                g = gfac * shape[i, j]
                r = math.sqrt(pxj * pxj + pyj * pyj)
                if r > g:
                    nslip[j] += 1.0
                f = min(g / (r + _TINY_TRACTION), 1.0)
                pxj *= f
                pyj *= f
                px[j] = pxj
                py[j] = pyj
                spx[j] += pxj
                spy[j] += pyj
                sxpy[j] += pyj * xh[i]
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
            syx += (b[c] * yh[j]) * spx[j]
            sns += nslip[j]
        fx[c] = sx * da
        fy[c] = sy * da
        mz[c] = (ac * sxy - syx) * da
        sf[c] = sns / n_in
    return fx, fy, mz, sf


_strips_par, _strips_ser = serial_and_parallel(_strips_py, error_model="numpy")
_rect_par, _rect_ser = serial_and_parallel(_rect_py, error_model="numpy")


def march_strips(xi, eta, phi, fz, a, b, mu, l1, l2, l3, pattern):
    """FASTSIM on Kalker's strips for n contacts (1-d float64 arrays of length n)."""
    eta_j, sq, tx, gy, norm = pattern
    kernel = _strips_par if xi.size >= _PARALLEL_MIN else _strips_ser
    return kernel(xi, eta, phi, fz, a, b, mu, l1, l2, l3, eta_j, sq, tx, gy, float(norm))


def march_rect(xi, eta, phi, fz, a, b, mu, l1, l2, l3, scale, rect):
    """FASTSIM on CONTACT's rectangular grid for n contacts (1-d float64 arrays)."""
    xh, yh, mask, shape, n_in = rect
    kernel = _rect_par if xi.size >= _PARALLEL_MIN else _rect_ser
    return kernel(xi, eta, phi, fz, a, b, mu, l1, l2, l3, float(scale), xh, yh, mask, shape,
                  float(n_in))  # fmt: skip
