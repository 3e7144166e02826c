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

The table is solved with Coulomb friction at nu = 0.28 (steel); Poisson's ratios 0.25-0.30 are
served by scaling with Kalker's coefficients at that nu, and falling friction by one
coefficient per contact at Polach's global slip velocity (see :func:`exact_table_forces` for
both and for where they are accurate). When all contacts share one a/b (the usual case) the
table is first interpolated to that a/b and the lookup is 3-D.
"""

from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources

import numba
import numpy as np

from railadhesion._validate import (
    as_float_array,
    check_finite,
    check_nonnegative,
    check_positive,
)
from railadhesion.contact.exact import _check_friction_law
from railadhesion.contact.kalker import kalker_coefficients

__all__ = ["exact_table_forces", "table_axes"]

#: Poisson's ratio of the table.
TABLE_POISSON = 0.28
#: Range of Poisson's ratio accepted (creepages scaled with Kalker's coefficients at that nu;
#: error against the exact solver measured in docs/validation/exact_models.md).
POISSON_MIN, POISSON_MAX = 0.25, 0.30
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
    # outputs last and contiguous, as rows of 3: one memory access per node
    last = np.ascontiguousarray(np.moveaxis(data["values"], 0, -1), dtype=float)
    data["flat"] = last.reshape(-1, 3)
    axes = (np.log(data["aob"]), data["tmag"], data["theta"], data["uspin"])
    data["dims"] = np.array([ax.size for ax in axes], dtype=np.int64)
    data["origin"] = np.array([ax[0] for ax in axes])
    data["inv_step"] = np.array([(ax.size - 1) / (ax[-1] - ax[0]) for ax in axes])
    for ax in axes:  # the interpolation assumes uniform axes
        if not np.allclose(np.diff(ax), (ax[-1] - ax[0]) / (ax.size - 1), rtol=1e-9, atol=1e-12):
            raise RuntimeError("exact_table.npz: table axes are not uniform")
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


#: Contacts per task of the parallel interpolation, and the number of contacts from which
#: the parallel kernel is used (below, thread start-up costs more than it saves; as the
#: package's Polach kernels).
_CHUNK = 4096
_PARALLEL_MIN = 100_000


_TAN_PI_8 = math.sqrt(2.0) - 1.0


@numba.njit(cache=True, inline="always")
def _at(arr, k):
    """arr[k], or arr[0] for a value shared by all contacts (length-1 array)."""
    return arr[k] if arr.size > 1 else arr[0]


@numba.njit(cache=True, inline="always")
def _atan_pos(x):
    """atan(x) for x >= 0 to about 1e-9 (faster than libm): reduced to |z| <= tan(pi/8)
    by atan(x) = pi/2 - atan(1/x) and atan(x) = pi/4 + atan((x - 1)/(x + 1)), then the odd
    Taylor series to z^17 (remainder below 0.4143^19/19 < 3e-9)."""
    inverted = x > 1.0
    if inverted:
        x = 1.0 / x
    off = 0.0
    if x > _TAN_PI_8:
        x = (x - 1.0) / (x + 1.0)
        off = 0.25 * math.pi
    z2 = x * x
    p = 1.0 / 17.0
    p = 1.0 / 15.0 - z2 * p
    p = 1.0 / 13.0 - z2 * p
    p = 1.0 / 11.0 - z2 * p
    p = 1.0 / 9.0 - z2 * p
    p = 1.0 / 7.0 - z2 * p
    p = 1.0 / 5.0 - z2 * p
    p = 1.0 / 3.0 - z2 * p
    p = 1.0 - z2 * p
    at = off + x * p
    return 0.5 * math.pi - at if inverted else at


@numba.njit(cache=True, inline="always")
def _locate_uniform(v, v0, inv_h, n):
    """Index i and weight w with v between the uniform nodes i and i+1 (clipped)."""
    q = (v - v0) * inv_h
    if q <= 0.0:
        return 0, 0.0
    if q >= n - 1:
        return n - 2, 1.0
    i = int(q)
    if i > n - 2:
        i = n - 2
    return i, q - i


def _interp_py(flat, dims, origin, inv_step, laob, xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb,
               out):  # fmt: skip
    """Cubic (Catmull-Rom) interpolation, per axis, of the 3 outputs at Kalker-scaled
    creepages (X, Y, S). ``flat`` holds the table as rows of 3 outputs, node (ia, it, id, iu)
    at row ``((ia n_t + it) n_theta + id) n_u + iu``; the four axes (log a/b, t, theta, u)
    are uniform with first node ``origin`` and inverse spacing ``inv_step``. The spin axis
    (innermost in memory) is summed first, then scaled by the product of the other weights.

    Inputs per contact (arrays of length n, or 1 for a value shared by all): the creepages
    xi, eta, phi and their factors to Kalker-scaled creepages kx, ky, ks
    (``X = xi kx`` ...); the force and moment scales kf = mu Fz, km = mu Fz c. The
    interpolated |(Fx, Fy)| is capped at mu Fz (the cubic may overshoot it by a few 0.1 %
    near full sliding, the exact solution never does). Falling friction: speed lv, ratio la
    and decay lb; the coefficient is mu ((1 - A) exp(-B V |(xi, eta)|) + A), which divides
    the scaled creepages and multiplies the forces. ``out`` (3, n) receives Fx, Fy, Mz."""
    n = out.shape[1]
    na, nt, nd, nu = dims[0], dims[1], dims[2], dims[3]
    nchunk = (n + _CHUNK - 1) // _CHUNK
    for ch in numba.prange(nchunk):
        ia_ = np.empty(4, np.int64)
        wa_ = np.empty(4)
        it_ = np.empty(4, np.int64)
        wt_ = np.empty(4)
        id_ = np.empty(4, np.int64)
        wd_ = np.empty(4)
        iu_ = np.empty(4, np.int64)
        wu_ = np.empty(4)
        for k in range(ch * _CHUNK, min((ch + 1) * _CHUNK, n)):
            cx = _at(xi, k)
            cy = _at(eta, k)
            fac = 1.0
            ra = _at(la, k)
            bv = _at(lb, k) * _at(lv, k)
            if ra != 1.0 and bv > 0.0:  # Polach's global slip velocity V |(xi, eta)|
                fac = (1.0 - ra) * math.exp(-bv * math.sqrt(cx * cx + cy * cy)) + ra
            inv = 1.0 / fac if fac > 0.0 else 0.0
            x = cx * _at(kx, k) * inv
            y = cy * _at(ky, k) * inv
            p = _at(phi, k) * _at(ks, k) * inv
            sgn = 1.0
            if x < 0.0:  # point symmetry: all outputs change sign
                x, y, p, sgn = -x, -y, -p, -1.0
            sy = 1.0
            if y < 0.0:  # mirror in y: Fy and Mz change sign
                y, p, sy = -y, -p, -1.0
            r = math.sqrt(x * x + y * y)
            t = _TWO_PI * _atan_pos(r / R0)
            # direction in [0, pi/2] (x, y >= 0 here)
            if y <= x:
                th = _atan_pos(y / x) if x > 0.0 else 0.0
            else:
                th = 0.5 * math.pi - _atan_pos(x / y)
            u = _TWO_PI * (_atan_pos(p / S0) if p >= 0.0 else -_atan_pos(-p / S0))
            ia, wa = _locate_uniform(laob[k], origin[0], inv_step[0], na)
            it, wt = _locate_uniform(t, origin[1], inv_step[1], nt)
            idd, wd = _locate_uniform(th, origin[2], inv_step[2], nd)
            iu, wu = _locate_uniform(u, origin[3], inv_step[3], nu)
            _cubic(ia, wa, na, ia_, wa_)
            _cubic(it, wt, nt, it_, wt_)
            _cubic(idd, wd, nd, id_, wd_)
            _cubic(iu, wu, nu, iu_, wu_)
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            for qa in range(4):
                fa = wa_[qa]
                if fa == 0.0:
                    continue
                ba = ia_[qa] * nt
                for qt in range(4):
                    ft = fa * wt_[qt]
                    if ft == 0.0:
                        continue
                    bt = (ba + it_[qt]) * nd
                    for qd in range(4):
                        fd = ft * wd_[qd]
                        if fd == 0.0:
                            continue
                        bd = (bt + id_[qd]) * nu
                        s0 = 0.0
                        s1 = 0.0
                        s2 = 0.0
                        for qu in range(4):
                            w = wu_[qu]
                            row = bd + iu_[qu]
                            s0 += w * flat[row, 0]
                            s1 += w * flat[row, 1]
                            s2 += w * flat[row, 2]
                        a0 += fd * s0
                        a1 += fd * s1
                        a2 += fd * s2
            ft = math.sqrt(a0 * a0 + a1 * a1)
            if ft > 1.0:  # Coulomb's bound
                a0 /= ft
                a1 /= ft
            f = sgn * fac * _at(kf, k)
            out[0, k] = f * a0
            out[1, k] = f * sy * a1
            out[2, k] = sgn * sy * fac * _at(km, k) * a2


def _interp3_py(flat, dims, origin, inv_step, xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb,
                out):  # fmt: skip
    """As :func:`_interp_py` on a table already interpolated to one a/b (axes t, theta, u)."""
    n = out.shape[1]
    nt, nd, nu = dims[1], dims[2], dims[3]
    nchunk = (n + _CHUNK - 1) // _CHUNK
    for ch in numba.prange(nchunk):
        it_ = np.empty(4, np.int64)
        wt_ = np.empty(4)
        id_ = np.empty(4, np.int64)
        wd_ = np.empty(4)
        iu_ = np.empty(4, np.int64)
        wu_ = np.empty(4)
        for k in range(ch * _CHUNK, min((ch + 1) * _CHUNK, n)):
            cx = _at(xi, k)
            cy = _at(eta, k)
            fac = 1.0
            ra = _at(la, k)
            bv = _at(lb, k) * _at(lv, k)
            if ra != 1.0 and bv > 0.0:  # Polach's global slip velocity V |(xi, eta)|
                fac = (1.0 - ra) * math.exp(-bv * math.sqrt(cx * cx + cy * cy)) + ra
            inv = 1.0 / fac if fac > 0.0 else 0.0
            x = cx * _at(kx, k) * inv
            y = cy * _at(ky, k) * inv
            p = _at(phi, k) * _at(ks, k) * inv
            sgn = 1.0
            if x < 0.0:  # point symmetry: all outputs change sign
                x, y, p, sgn = -x, -y, -p, -1.0
            sy = 1.0
            if y < 0.0:  # mirror in y: Fy and Mz change sign
                y, p, sy = -y, -p, -1.0
            r = math.sqrt(x * x + y * y)
            t = _TWO_PI * _atan_pos(r / R0)
            # direction in [0, pi/2] (x, y >= 0 here)
            if y <= x:
                th = _atan_pos(y / x) if x > 0.0 else 0.0
            else:
                th = 0.5 * math.pi - _atan_pos(x / y)
            u = _TWO_PI * (_atan_pos(p / S0) if p >= 0.0 else -_atan_pos(-p / S0))
            it, wt = _locate_uniform(t, origin[1], inv_step[1], nt)
            idd, wd = _locate_uniform(th, origin[2], inv_step[2], nd)
            iu, wu = _locate_uniform(u, origin[3], inv_step[3], nu)
            _cubic(it, wt, nt, it_, wt_)
            _cubic(idd, wd, nd, id_, wd_)
            _cubic(iu, wu, nu, iu_, wu_)
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            for qt in range(4):
                ft = wt_[qt]
                if ft == 0.0:
                    continue
                bt = it_[qt] * nd
                for qd in range(4):
                    fd = ft * wd_[qd]
                    if fd == 0.0:
                        continue
                    bd = (bt + id_[qd]) * nu
                    s0 = 0.0
                    s1 = 0.0
                    s2 = 0.0
                    for qu in range(4):
                        w = wu_[qu]
                        row = bd + iu_[qu]
                        s0 += w * flat[row, 0]
                        s1 += w * flat[row, 1]
                        s2 += w * flat[row, 2]
                    a0 += fd * s0
                    a1 += fd * s1
                    a2 += fd * s2
            ft = math.sqrt(a0 * a0 + a1 * a1)
            if ft > 1.0:  # Coulomb's bound
                a0 /= ft
                a1 /= ft
            f = sgn * fac * _at(kf, k)
            out[0, k] = f * a0
            out[1, k] = f * sy * a1
            out[2, k] = sgn * sy * fac * _at(km, k) * a2


_interp_ser = numba.njit(cache=True, fastmath=True)(_interp_py)
_interp_par = numba.njit(cache=True, fastmath=True, parallel=True)(_interp_py)
_interp3_ser = numba.njit(cache=True, fastmath=True)(_interp3_py)
_interp3_par = numba.njit(cache=True, fastmath=True, parallel=True)(_interp3_py)


@lru_cache(maxsize=32)
def _slice_at(laob: float) -> np.ndarray:
    """The table interpolated (cubic, as in the kernel) to one log(a/b): rows of 3 outputs."""
    d = _load()
    na = int(d["dims"][0])
    ia, wa = _locate_uniform.py_func(laob, d["origin"][0], d["inv_step"][0], na)
    ids = np.empty(4, np.int64)
    wts = np.empty(4)
    _cubic.py_func(ia, wa, na, ids, wts)
    planes = d["flat"].reshape(na, -1, 3)
    out = np.zeros_like(planes[0])
    for i, w in zip(ids, wts, strict=True):
        if w != 0.0:
            out += w * planes[i]
    out.flags.writeable = False
    return out


def _interp(d, laob, shape, xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb):
    """Fx, Fy, Mz of the contacts (``shape``); every input broadcasts to ``shape``. One a/b
    for all contacts (the usual case) is looked up in a 3-D slice of the table."""
    n = math.prod(shape)

    def flat(v):  # length 1 (shared) or n; anything else is broadcast out
        v = np.asarray(v, dtype=float)
        if v.size == 1:
            return v.reshape(1)
        if v.shape != shape:
            v = np.broadcast_to(v, shape)
        return np.ascontiguousarray(v).reshape(-1)

    args = tuple(flat(v) for v in (xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb))
    out = np.empty((3, n))
    par = n >= _PARALLEL_MIN
    if laob.size == 1 or np.all(laob == laob.flat[0]):
        table = _slice_at(float(laob.flat[0]))
        kernel = _interp3_par if par else _interp3_ser
        kernel(table, d["dims"], d["origin"], d["inv_step"], *args, out)
    else:
        kernel = _interp_par if par else _interp_ser
        kernel(d["flat"], d["dims"], d["origin"], d["inv_step"], flat(laob), *args, out)
    return out.reshape(3, *shape)


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
    poisson=TABLE_POISSON,
    speed=None,
    friction_ratio=1.0,
    friction_decay=0.0,
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
        Coefficient of friction [-], >= 0: Coulomb's, or the static one mu0 of the falling
        friction law below.
    shear_modulus : array_like, optional
        Combined shear modulus G [Pa], > 0.
    poisson : array_like, optional
        Combined Poisson's ratio nu [-], in [0.25, 0.30] (ValueError outside). The table is
        solved at 0.28; at another nu the creepages are scaled with Kalker's coefficients at
        that nu (measured against the solver at 0.25 and 0.30: median <= 0.004 muQ, max
        0.026 and 0.032 muQ, as at 0.28).
    speed, friction_ratio, friction_decay : array_like, optional
        Falling friction ``mu(w) = mu [(1 - A) exp(-B w) + A]`` with ``A = friction_ratio``
        in [0, 1], ``B = friction_decay`` [s/m] >= 0 and the rolling speed V [m/s] (as in
        :func:`railadhesion.contact.exact.exact_rolling`). The table is then looked up with
        the single coefficient ``mu(V sqrt(xi^2 + eta^2))``, Polach's choice (see Notes for
        where this is meaningful). Defaults: Coulomb friction.
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

    **Falling friction.** The exact solution with a slip-velocity dependent coefficient has
    a coefficient that varies over the contact with the local slip velocity; the table
    knows one coefficient per contact. It is evaluated at the global slip velocity
    ``w = V sqrt(xi^2 + eta^2)`` (Polach 1999/2005, without his spin correction), which is
    exact at vanishing creepage (linear theory does not depend on mu) and in full sliding
    without spin (the local slip is then the creepage everywhere). Measured against the
    exact solver with the same law (``exact_rolling(..., speed=, friction_ratio=,
    friction_decay=)`` on 40 x 40; 135 cases each: a/b 0.2-5, creep 0.3-3 mu p0/G in three
    directions, spin 0 and +-2 mu p0/(G c); four laws from Polach's wet and dry sets to
    CONTACT's steep example; ``docs/validation/exact_models.md``): without spin within
    0.008 muQ median and 0.024 muQ at worst for all four laws; with spin the local slip
    velocity varies over the contact, which one coefficient cannot represent: median
    0.006-0.017 muQ and max 0.05-0.08 muQ for Polach's laws (worst on long contacts,
    a/b = 5, with large creepage and spin), median 0.03-0.05 and max 0.10-0.13 muQ for the
    steep laws (B V mu p0/G >= 0.7: the friction falls by half over a few creepage units;
    worst for small creepage with large spin). Meaningful for creepage-dominated
    slip; with large spin and steep laws use the exact solver.

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
    nu = as_float_array(poisson, "poisson")
    if not np.all((nu >= POISSON_MIN) & (nu <= POISSON_MAX)):
        raise ValueError(
            f"poisson must be in [{POISSON_MIN}, {POISSON_MAX}] for the table model (tabulated "
            f"at {TABLE_POISSON}, validated over that range), got {poisson!r}"
        )
    ratio, decay, v = _check_friction_law(speed, friction_ratio, friction_decay)
    aob = a_ / b_
    if not np.all((aob >= AOB_MIN * (1 - 1e-12)) & (aob <= AOB_MAX * (1 + 1e-12))):
        raise ValueError(f"a/b must be in [{AOB_MIN}, {AOB_MAX}] for the table model")
    # per-contact arrays only where needed: the geometry is often shared by all contacts
    shape = np.broadcast_shapes(xi.shape, eta.shape, phi.shape, fz.shape, a_.shape, b_.shape,
                                mu_.shape, g.shape, nu.shape, ratio.shape, decay.shape,
                                v.shape)  # fmt: skip
    c = np.sqrt(a_ * b_)
    tau = mu_ * (1.5 / np.pi) * fz / (a_ * b_ * g)  # mu p0 / G
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(tau > 0.0, (1.5 / np.pi) / tau, 0.0)
    d = _load()
    # a/b before broadcasting: one Kalker lookup when the geometry is shared by all contacts
    laob = np.log(aob)
    k = kalker_coefficients(aob, float(nu) if nu.ndim == 0 else nu)
    coef = (k.c11, k.c22, k.c23)
    if not kalker_correction:  # the build grid's own coefficients, interpolated in log(a/b)
        ln = np.log(d["aob"])
        k0 = kalker_coefficients(aob, TABLE_POISSON)
        coef = tuple(
            np.interp(laob, ln, d["cgrid"][:, j]) * cn / c0
            for j, cn, c0 in zip(range(3), coef, (k0.c11, k0.c22, k0.c23), strict=True)
        )

    scale = mu_ * fz
    # with falling friction the compiled lookup scales mu per contact by the law at Polach's
    # global slip velocity V |(xi, eta)| (spin not counted)
    fx, fy, mz = _interp(d, laob, shape, xi, eta, phi, f * coef[0], f * coef[1],
                         c * f * coef[2], scale, scale * c, v, ratio, decay)  # fmt: skip
    if fx.ndim == 0:
        return float(fx), float(fy), float(mz)
    return fx, fy, mz
