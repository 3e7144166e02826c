"""Fast creep-force model: a table of Kalker's exact theory, interpolated (USETAB idea).

The exact solution of steady rolling with Coulomb friction on a Hertzian contact
(:func:`railadhesion.contact.exact.exact_rolling`) depends, for a given Poisson's ratio, only
on the ratio a/b and on three normalised creepages (Kalker 1990, section 5.4; the basis of
Kalker's USETAB table):

* ``tau = mu p0 / G`` with ``p0 = 3 Fz / (2 pi a b)``, ``c = sqrt(a b)``;
* ``xi' = xi / tau``, ``eta' = eta / tau``, ``phi' = phi c / tau``;
* ``Fx/(mu Fz)``, ``Fy/(mu Fz)`` and ``Mz/(mu Fz c)`` are functions of (a/b, xi', eta', phi').

The table (package data ``data/exact_table.npz``, built by ``scripts/build_exact_table.py``
with the exact solver) samples these functions in Kalker-scaled creepages
``X = 3 C11 xi'/(2 pi)``, ``Y = 3 C22 eta'/(2 pi)``, ``S = 3 C23 phi'/(2 pi)`` (linear theory
is then ``Fx/(mu Fz) = -X``, ``Fy/(mu Fz) = -Y - S``, nearly independent of a/b) on a 4-D
grid: log(a/b), the magnitude ``r = sqrt(X^2 + Y^2)`` through ``t = (2/pi) atan(r)``, the
direction ``theta = atan2(Y, X)`` in [0, pi/2] and the spin through ``u = (2/pi) atan(S)``;
other quadrants follow from the symmetries (xi, eta, phi) -> -(xi, eta, phi) (all outputs
change sign) and (eta, phi) -> -(eta, phi) (Fy and Mz change sign). Interpolation in compiled
code, cubic (Catmull-Rom) along every axis. The nodes are solved with the build grid's own
linear coefficients and looked up with Kalker's
(:func:`railadhesion.contact.kalker.kalker_coefficients`), which removes most of the grid's
discretisation error (its excess stiffness).

Friction is Coulomb's (one mu per contact). The table is for nu = 0.28 (steel).
"""

from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources

import numba
import numpy as np

from railadhesion._validate import check_finite, check_nonnegative, check_positive
from railadhesion.contact.kalker import kalker_coefficients

__all__ = ["exact_table_forces", "table_axes"]

#: Poisson's ratio of the table.
TABLE_POISSON = 0.28
#: Scale of the magnitude and spin transforms t = (2/pi) atan(r/R0), u = (2/pi) atan(S/S0).
R0 = 1.0
S0 = 1.0
_TWO_PI = 2.0 / math.pi
#: a/b range of the table (outside: ValueError).
AOB_MIN, AOB_MAX = 0.2, 5.0
#: Finite stand-in for an infinite normalised creepage / spin at the last nodes.
BIG = 1e4


def table_axes(n_aob=9, n_mag=29, n_dir=7, n_spin=33):
    """Node coordinates of the table: (a/b, t, theta, u); see :func:`node_creepages`."""
    aob = np.geomspace(AOB_MIN, AOB_MAX, n_aob)
    tmag = np.linspace(0.0, 1.0, n_mag)
    theta = np.linspace(0.0, 0.5 * math.pi, n_dir)
    uspin = np.linspace(-1.0, 1.0, n_spin)
    return aob, tmag, theta, uspin


def node_creepages(tmag, theta, uspin):
    """Kalker-scaled (X, Y, S) at table nodes (broadcasting); |t| = 1 or |u| = 1 -> BIG.

    Inverse of ``t = (2/pi) atan(r/R0)`` and ``u = (2/pi) atan(S/S0)`` (smooth and odd, so
    that the cubic interpolation keeps linear theory at vanishing creepage and spin, with
    nodes out to large creepages)."""
    tmag, theta, uspin = np.broadcast_arrays(tmag, theta, uspin)
    r = np.where(tmag >= 1.0, BIG, R0 * np.tan(0.5 * np.pi * np.minimum(tmag, 0.999)))
    ph = np.where(
        np.abs(uspin) >= 1.0,
        np.sign(uspin) * BIG,
        S0 * np.tan(0.5 * np.pi * np.clip(uspin, -0.999, 0.999)),
    )
    return r * np.cos(theta), r * np.sin(theta), ph


@lru_cache(maxsize=1)
def _load():
    with resources.files("railadhesion").joinpath("data/exact_table.npz").open("rb") as fh:
        z = np.load(fh)
        data = {k: np.array(z[k]) for k in z.files}
    # outputs last and contiguous: one memory access per node in the interpolation
    data["values_last"] = np.ascontiguousarray(np.moveaxis(data["values"], 0, -1))
    return data


@numba.njit(cache=True)
def _locate(v, nodes):
    """Index i and weight w with v between nodes[i] and nodes[i+1] (clipped)."""
    n = nodes.size
    if v <= nodes[0]:
        return 0, 0.0
    if v >= nodes[n - 1]:
        return n - 2, 1.0
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if nodes[mid] <= v:
            lo = mid
        else:
            hi = mid
    return lo, (v - nodes[lo]) / (nodes[lo + 1] - nodes[lo])


@numba.njit(cache=True, inline="always")
def _cubic(i, w, n, ids, wts):
    """Catmull-Rom weights on nodes i-1 .. i+2 for the fraction w in [i, i+1]; beyond the
    ends, ghost nodes extrapolated quadratically (folded into the end weights), so that the
    slope at an end node is second-order accurate (linear theory at vanishing creepage)."""
    w2 = w * w
    w3 = w2 * w
    wts[0] = 0.5 * (-w3 + 2.0 * w2 - w)
    wts[1] = 0.5 * (3.0 * w3 - 5.0 * w2 + 2.0)
    wts[2] = 0.5 * (-3.0 * w3 + 4.0 * w2 + w)
    wts[3] = 0.5 * (w3 - w2)
    ids[0] = i - 1
    ids[1] = i
    ids[2] = i + 1
    ids[3] = i + 2
    if i - 1 < 0:  # ghost f[-1] = 3 f[0] - 3 f[1] + f[2]
        wg = wts[0]
        wts[0] = 0.0
        ids[0] = 0
        wts[1] += 3.0 * wg
        wts[2] -= 3.0 * wg
        if n > 2:
            wts[3] += wg  # ids[3] = 2 here (i = 0) unless n == 2
        else:
            wts[1] -= wg
            wts[2] += wg
    if i + 2 > n - 1:  # ghost f[n] = 3 f[n-1] - 3 f[n-2] + f[n-3]
        wg = wts[3]
        wts[3] = 0.0
        ids[3] = n - 1
        wts[2] += 3.0 * wg
        wts[1] -= 3.0 * wg
        if n > 2 and ids[0] == n - 3:
            wts[0] += wg
        elif n > 2:  # i - 1 was folded (n == 3): node n-3 is node 0 = ids[1]
            wts[1] += wg
        else:
            wts[2] -= wg
            wts[1] += wg


@numba.njit(cache=True, fastmath=True)
def _interp(values, laob_n, t_n, th_n, u_n, laob, xs, ys, ss, out):
    """Cubic (Catmull-Rom) interpolation, per axis, of the 3 outputs at Kalker-scaled
    creepages (X, Y, S); ``values`` has shape (n_aob, n_t, n_theta, n_u, 3)."""
    ia_ = np.empty(4, np.int64)
    wa_ = np.empty(4)
    it_ = np.empty(4, np.int64)
    wt_ = np.empty(4)
    id_ = np.empty(4, np.int64)
    wd_ = np.empty(4)
    iu_ = np.empty(4, np.int64)
    wu_ = np.empty(4)
    for k in range(xs.size):
        ia, wa = _locate(laob[k], laob_n)
        x = xs[k]
        y = ys[k]
        p = ss[k]
        sgn = 1.0
        if x < 0.0:  # point symmetry: all outputs change sign
            x, y, p, sgn = -x, -y, -p, -1.0
        sy = 1.0
        if y < 0.0:  # mirror in y: Fy and Mz change sign
            y, p, sy = -y, -p, -1.0
        r = math.sqrt(x * x + y * y)
        t = _TWO_PI * math.atan(r / R0)
        th = math.atan2(y, x) if r > 0.0 else 0.0
        u = _TWO_PI * math.atan(p / S0)
        it, wt = _locate(t, t_n)
        idd, wd = _locate(th, th_n)
        iu, wu = _locate(u, u_n)
        _cubic(ia, wa, laob_n.size, ia_, wa_)
        _cubic(it, wt, t_n.size, it_, wt_)
        _cubic(idd, wd, th_n.size, id_, wd_)
        _cubic(iu, wu, u_n.size, iu_, wu_)
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for qa in range(4):
            fa = wa_[qa]
            if fa == 0.0:
                continue
            for qt in range(4):
                ft = fa * wt_[qt]
                if ft == 0.0:
                    continue
                for qd in range(4):
                    fd = ft * wd_[qd]
                    if fd == 0.0:
                        continue
                    for qu in range(4):
                        f = fd * wu_[qu]
                        if f == 0.0:
                            continue
                        v = values[ia_[qa], it_[qt], id_[qd], iu_[qu]]
                        a0 += f * v[0]
                        a1 += f * v[1]
                        a2 += f * v[2]
        out[0, k] = sgn * a0
        out[1, k] = sgn * sy * a1
        out[2, k] = sgn * sy * a2


def exact_table_forces(
    creep_long,
    creep_lat,
    spin,
    normal_force,
    a,
    b,
    mu,
    *,
    shear_modulus=8.2e10,
    kalker_correction: bool = True,
):
    """Creep forces of Kalker's exact theory from the precomputed table (fast).

    Parameters
    ----------
    creep_long, creep_lat : array_like
        Longitudinal and lateral creepage [-].
    spin : array_like
        Spin creepage [rad/m].
    normal_force : array_like
        Normal force Fz [N], >= 0.
    a, b : array_like
        Hertzian semi-axes along x (rolling) and y [m], with 0.2 <= a/b <= 5.
    mu : array_like
        Coefficient of (Coulomb) friction [-], >= 0.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa]. Poisson's ratio is the table's, 0.28.
    kalker_correction : bool, optional
        Scale the creepages with Kalker's coefficients (default), which corrects the build
        grid's excess stiffness (2-4 % on 20 x 20); with False, with the build grid's own
        coefficients, so that the table reproduces the solver on its build grid.

    Returns
    -------
    fx, fy, mz : ndarray or float
        Forces [N] and spin moment [N m], Kalker's sign convention (rail on wheel), of the
        broadcast shape of the inputs.

    Notes
    -----
    Kalker's exact theory (Kalker 1990, chapter 5) tabulated with
    :func:`railadhesion.contact.exact.exact_rolling`; normalisation and interpolation in the
    module docstring. |F| is capped at mu Fz (the cubic interpolation may overshoot it by
    up to about 0.4 % near full sliding). Accuracy against the exact solver:
    ``docs/validation/exact_models.md``.

    Examples
    --------
    Small longitudinal creepage recovers Kalker's linear theory, Fx = -G c^2 C11 xi
    (C11 = 4.2262 for a/b = 1, nu = 0.28), within 1 %:

    >>> fx, fy, mz = exact_table_forces(1e-6, 0.0, 0.0, 1e5, 6e-3, 6e-3, 0.3)
    >>> round(-fx / (8.2e10 * 36e-6 * 1e-6), 2)
    4.26
    """
    xi = check_finite(creep_long, "creep_long")
    eta = check_finite(creep_lat, "creep_lat")
    phi = check_finite(spin, "spin")
    fz = check_nonnegative(normal_force, "normal_force")
    a_ = check_positive(a, "a")
    b_ = check_positive(b, "b")
    mu_ = check_nonnegative(mu, "mu")
    g = check_positive(shear_modulus, "shear_modulus")
    aob = a_ / b_
    if not np.all((aob >= AOB_MIN * (1 - 1e-12)) & (aob <= AOB_MAX * (1 + 1e-12))):
        raise ValueError(f"a/b must be in [{AOB_MIN}, {AOB_MAX}] for the table model")
    xi, eta, phi, fz, a_, b_, mu_, g = np.broadcast_arrays(xi, eta, phi, fz, a_, b_, mu_, g)
    shape = xi.shape
    c = np.sqrt(a_ * b_)
    p0 = 3.0 * fz / (2.0 * np.pi * a_ * b_)
    tau = mu_ * p0 / g
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(tau > 0.0, 1.0 / tau, 0.0)
    d = _load()
    laob = np.log(a_ / b_)
    if kalker_correction:
        k = kalker_coefficients(a_ / b_, TABLE_POISSON)
        coef = (k.c11, k.c22, k.c23)
    else:  # the build grid's own coefficients, interpolated in log(a/b)
        ln = np.log(d["aob"])
        coef = tuple(np.interp(laob, ln, d["cgrid"][:, j]) for j in range(3))
    f = 3.0 / (2.0 * np.pi) * inv
    out = np.empty((3, xi.size))
    _interp(
        d["values_last"],
        np.log(d["aob"]),
        d["tmag"],
        d["theta"],
        d["uspin"],
        np.ascontiguousarray(laob.ravel()),
        np.ascontiguousarray((xi * f * coef[0]).ravel()),
        np.ascontiguousarray((eta * f * coef[1]).ravel()),
        np.ascontiguousarray((phi * c * f * coef[2]).ravel()),
        out,
    )
    # Coulomb's bound |F| <= mu Fz holds for the exact solution; the cubic interpolation can
    # overshoot it by a few 0.1 % near full sliding: scale such results back onto it
    ft = np.hypot(out[0], out[1])
    over = ft > 1.0
    if np.any(over):
        out[:2, over] /= ft[over]
    scale = (mu_ * fz).ravel()
    fx = (out[0] * scale).reshape(shape)
    fy = (out[1] * scale).reshape(shape)
    mz = (out[2] * scale * c.ravel()).reshape(shape)
    if fx.ndim == 0:
        return float(fx), float(fy), float(mz)
    return fx, fy, mz
