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
code, cubic (Catmull-Rom) along every axis, with a ghost node beyond each end extrapolated
quadratically (stored in the table as loaded). The nodes are solved with the build grid's own
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

import numpy as np

from railadhesion._validate import (
    as_float_array,
    check_finite,
    check_nonnegative,
    check_positive,
)
from railadhesion.contact.exact import check_friction_law
from railadhesion.contact.friction import falling_friction_factor
from railadhesion.contact.kalker import kalker_coefficients, kalker_scalar
from railadhesion.numerics import atan_nonneg, chunk_of, fill, jit, run_chunks
from railadhesion.plausibility import input_checker
from railadhesion.simd import NOUT, contract_rows

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


def _with_ghosts(values, axes):
    """``values`` with one ghost node added before the first and after the last node of each
    of ``axes``, extrapolated quadratically: f[-1] = 3 f[0] - 3 f[1] + f[2] and
    f[n] = 3 f[n-1] - 3 f[n-2] + f[n-3]. The Catmull-Rom cubic then needs no special case at
    the ends, and its slope at an end node is second-order accurate (linear theory at
    vanishing creepage)."""
    for ax in axes:
        v = np.moveaxis(values, ax, 0)
        lo = 3.0 * v[0] - 3.0 * v[1] + v[2]
        hi = 3.0 * v[-1] - 3.0 * v[-2] + v[-3]
        values = np.moveaxis(np.concatenate([lo[None], v, hi[None]]), 0, ax)
    return values


@lru_cache(maxsize=1)
def _load():
    with resources.files("railadhesion").joinpath("data/exact_table.npz").open("rb") as fh:
        z = np.load(fh)
        data = {k: np.array(z[k]) for k in z.files}
    axes = (np.log(data["aob"]), data["tmag"], data["theta"], data["uspin"])
    for ax in axes:  # the interpolation assumes uniform axes of at least 4 nodes
        if ax.size < 4 or not np.allclose(np.diff(ax), (ax[-1] - ax[0]) / (ax.size - 1),
                                          rtol=1e-9, atol=1e-12):  # fmt: skip
            raise RuntimeError("exact_table.npz: table axes are not uniform")
    data["dims"] = np.array([ax.size for ax in axes], dtype=np.int64)
    data["origin"] = np.array([ax[0] for ax in axes])
    data["inv_step"] = np.array([(ax.size - 1) / (ax[-1] - ax[0]) for ax in axes])
    # outputs last, as rows of _NOUT (Fx, Fy, Mz): the 4 spin nodes of a (t, theta) pair
    # that a lookup needs are then 12 contiguous doubles, loaded as one SIMD vector; ghost
    # nodes on every axis
    # (in double precision: the file holds single)
    values = _with_ghosts(np.moveaxis(data["values"], 0, -1).astype(float), (0, 1, 2, 3))
    padded = np.zeros(values.shape[:-1] + (_NOUT,))
    padded[..., :3] = values
    data["padded"] = _read_only(padded)
    data["padded_flat"] = data["padded"].reshape(-1)
    # distance in memory (doubles) between consecutive nodes along log(a/b), t, theta, u
    data["strides"] = np.array([padded.strides[j] // padded.itemsize for j in range(4)],
                               dtype=np.int64)  # fmt: skip
    for v in ("dims", "strides", "origin", "inv_step"):
        data[v] = _read_only(data[v])
    return data


def _read_only(x):
    """A read-only view of x (the kernel is compiled for read-only arrays only)."""
    x = x.view()
    x.flags.writeable = False
    return x


def _catmull_rom(w):
    """Catmull-Rom weights of the nodes i-1 .. i+2 at the fraction w of [i, i+1]."""
    w2 = w * w
    w3 = w2 * w
    return (0.5 * (-w3 + 2.0 * w2 - w), 0.5 * (3.0 * w3 - 5.0 * w2 + 2.0),
            0.5 * (-3.0 * w3 + 4.0 * w2 + w), 0.5 * (w3 - w2))  # fmt: skip


def _locate_uniform(v, v0, inv_h, n):
    """Index i and fraction w of v between the uniform nodes i and i+1 (clipped to the
    nodes; NaN goes to the first node): float i, w (vectorisable)."""
    q = (v - v0) * inv_h
    q = q if q > 0.0 else 0.0
    q = q if q < n - 1.0 else n - 1.0
    i = min(np.floor(q), n - 2.0)
    return i, q - i


_catmull_rom_jit = jit(inline="always")(_catmull_rom)
_locate_jit = jit(inline="always")(_locate_uniform)


@lru_cache(maxsize=32)
def _slice_at(laob: float) -> np.ndarray:
    """The table (with ghost nodes) interpolated cubically, as in the kernel, to one
    log(a/b): a flat read-only array, layout of :func:`_load`'s ``padded`` without the a/b
    axis."""
    d = _load()
    na = int(d["dims"][0])
    ia, wa = _locate_uniform(laob, d["origin"][0], d["inv_step"][0], na)
    planes = d["padded"]  # the a/b nodes ia - 1 .. ia + 2 are planes ia .. ia + 3
    out = np.zeros(planes.shape[1:])
    for q, w in enumerate(_catmull_rom(wa)):
        out += w * planes[int(ia) + q]
    return _read_only(out.reshape(-1))


#: Values per table node in memory: Fx, Fy, Mz (rows padded to 4 were measured slower: the
#: table is larger, and the lookup is bound by its memory accesses as much as by arithmetic).
_NOUT = NOUT  # values per node (Fx, Fy, Mz), as contract_rows reads them
#: Contacts per chunk of the kernel (its scratch rows stay in the level-2 cache).
_CHUNK = 512
#: Contacts from which the lookup runs in parallel (as the package's Polach kernels).
_PARALLEL_MIN = 100_000

# Rows of the kernel's scratch array (shape (_ROWS, _CHUNK)): the Kalker-scaled creepages
# (X, Y, S), turned in place into the table coordinates (t, theta, u); the signs of the
# symmetries; the friction coefficient's factor and its inverse; the first table row of the
# contact's 4^3 (or 4^4) nodes; the cubic weights along t, theta, u and log(a/b); the
# interpolated outputs; scratch.
_R_X, _R_Y, _R_S, _R_SGN, _R_SY, _R_FAC, _R_INV, _R_BASE = range(8)
_R_WT, _R_WD, _R_WU, _R_WA = 8, 12, 16, 20
_R_F0, _R_F1, _R_F2, _R_ARG, _R_TMP = range(24, 29)
_ROWS = 29


# Each stage below is one short loop over a chunk, with few arrays (few run-time aliasing
# checks) and no float -> int conversion, so that it compiles to SIMD code (as the package's
# Polach kernels, railadhesion.models.kernels).


@jit
def _friction_factor(xs, ys, lvs, las, lbs, rows, m):
    """Falling friction: the coefficient's factor mu/mu0 (:func:`falling_friction_factor`) at
    Polach's global slip velocity V |(xi, eta)|, and its inverse, into rows."""
    fac, inv = rows[_R_FAC], rows[_R_INV]
    for k in range(m):
        w = lvs[k] * math.sqrt(xs[k] * xs[k] + ys[k] * ys[k])
        fac[k] = falling_friction_factor(w, las[k], lbs[k])
    for k in range(m):
        f = fac[k]
        inv[k] = 1.0 / (f if f > 0.0 else 1.0) if f > 0.0 else 0.0


@jit
def _scaled(cs, factor, inv, out, m):
    """out = cs factor inv (Kalker-scaled creepage of the looked-up coefficient)."""
    for k in range(m):
        out[k] = cs[k] * factor[k] * inv[k]


@jit
def _coordinates(rows, m):
    """Kalker-scaled (X, Y, S) -> table coordinates (t, theta, u) in place, reflected into
    X >= 0, Y >= 0 (point symmetry: all outputs change sign; mirror in y: Fy and Mz change
    sign); the signs into their rows."""
    xr, yr, pr, sgr, syr = rows[_R_X], rows[_R_Y], rows[_R_S], rows[_R_SGN], rows[_R_SY]
    for k in range(m):
        x = xr[k]
        y = yr[k]
        p = pr[k]
        sgn = -1.0 if x < 0.0 else 1.0
        x = sgn * x
        y = sgn * y
        p = sgn * p
        sy = -1.0 if y < 0.0 else 1.0
        y = sy * y
        p = sy * p
        r = math.sqrt(x * x + y * y)
        xr[k] = _TWO_PI * atan_nonneg(r / R0)
        # direction in [0, pi/2] from the smaller over the larger of x, y (both >= 0 here)
        hi = max(x, y)
        lo = min(x, y)
        a = atan_nonneg(lo / (hi if hi > 0.0 else 1.0))
        yr[k] = 0.5 * math.pi - a if y > x else a
        u = _TWO_PI * atan_nonneg(abs(p) / S0)
        pr[k] = -u if p < 0.0 else u
        sgr[k] = sgn
        syr[k] = sy


@jit
def _weights(v, v0, inv_h, n, stride, base, w, m):
    """Cubic weights along one axis into w[0..3]; the axis' part of the contact's first
    table row (node index times ``stride``) added to base."""
    w0, w1, w2, w3 = w[0], w[1], w[2], w[3]
    for k in range(m):
        i, f = _locate_jit(v[k], v0, inv_h, n)
        c0, c1, c2, c3 = _catmull_rom_jit(f)
        w0[k] = c0
        w1[k] = c1
        w2[k] = c2
        w3[k] = c3
        base[k] = base[k] + i * stride


@jit
def _gather(tab, rows, m, st, sd, sa):
    """The interpolated outputs of each contact (sa > 0: also along log(a/b), the planes sa
    apart)."""
    base, f0, f1, f2 = rows[_R_BASE], rows[_R_F0], rows[_R_F1], rows[_R_F2]
    wt, wd, wu, wa = rows[_R_WT:_R_WT + 4], rows[_R_WD:_R_WD + 4], rows[_R_WU:_R_WU + 4], \
        rows[_R_WA:_R_WA + 4]  # fmt: skip
    for k in range(m):
        b = int(base[k])
        if sa == 0:
            a0, a1, a2 = contract_rows(tab, b, st, sd, wt[0, k], wt[1, k], wt[2, k], wt[3, k],
                                   wd[0, k], wd[1, k], wd[2, k], wd[3, k], wu[0, k], wu[1, k],
                                   wu[2, k], wu[3, k])  # fmt: skip
        else:
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            for qa in range(4):
                s0, s1, s2 = contract_rows(tab, b + qa * sa, st, sd, wt[0, k], wt[1, k], wt[2, k],
                                       wt[3, k], wd[0, k], wd[1, k], wd[2, k], wd[3, k],
                                       wu[0, k], wu[1, k], wu[2, k], wu[3, k])  # fmt: skip
                w = wa[qa, k]
                a0 += w * s0
                a1 += w * s1
                a2 += w * s2
        f0[k] = a0
        f1[k] = a1
        f2[k] = a2


@jit
def _cap(f0, f1, m):
    """|(Fx, Fy)| / (mu Fz) capped at 1 (Coulomb's bound)."""
    for k in range(m):
        a0 = f0[k]
        a1 = f1[k]
        ft = math.sqrt(a0 * a0 + a1 * a1)
        c = ft if ft > 1.0 else 1.0
        f0[k] = a0 / c
        f1[k] = a1 / c


@jit
def _forces(rows, kfs, kms, ox, oy, oz, m):
    """Forces and moment from the normalised outputs: signs, mu Fz and mu Fz c scales."""
    sgr, syr, fac = rows[_R_SGN], rows[_R_SY], rows[_R_FAC]
    f0, f1, f2 = rows[_R_F0], rows[_R_F1], rows[_R_F2]
    for k in range(m):
        sgn = sgr[k]
        sy = syr[k]
        f = sgn * fac[k] * kfs[k]
        ox[k] = f * f0[k]
        oy[k] = f * sy * f1[k]
        oz[k] = sgn * sy * fac[k] * kms[k] * f2[k]


@jit(nogil=True)
def _lookup_chunks(tab, dims, strides, origin, inv_step, laob, xi, eta, phi, kx, ky, ks, kf,
                   km, lv, la, lb, out, first, last):  # fmt: skip
    """Cubic (Catmull-Rom) interpolation, per axis, of the 3 outputs at Kalker-scaled
    creepages, for the chunks ``first`` to ``last - 1`` (of _CHUNK contacts) of ``out``.

    ``tab`` is the table with ghost nodes (:func:`_load`'s ``padded``, flat: rows of _NOUT
    values, node (ia, it, id, iu), counting the ghosts, at row ``ia strides[0] + it
    strides[1] + id strides[2] + iu strides[3]``, strides[3] = _NOUT), or its slice at one
    a/b (:func:`_slice_at`; then ``laob`` is empty). The four axes (log a/b, t, theta, u)
    have ``dims`` nodes (ghosts not counted), uniform, the first at ``origin`` and spaced
    1/``inv_step``.

    Inputs per contact (arrays of length n, or 1 for a value shared by all): log(a/b) (or
    empty), the creepages xi, eta, phi and their factors to Kalker-scaled creepages kx, ky, ks
    (``X = xi kx`` ...); the force and moment scales kf = mu Fz, km = mu Fz c. The
    interpolated |(Fx, Fy)| is capped at mu Fz (the cubic may overshoot it by a few 0.1 %
    near full sliding, the exact solution never does). Falling friction: speed lv, ratio la
    and decay lb; the coefficient is mu ((1 - A) exp(-B V |(xi, eta)|) + A), which divides
    the scaled creepages and multiplies the forces. ``out`` (3, n) receives Fx, Fy, Mz.

    Stages per chunk (each a short loop, SIMD code): the friction factor, the scaled
    creepages, the table coordinates, the weights and first row, the interpolation (LLVM
    vector code, :func:`_contract`), the cap, the forces.
    """
    n = out.shape[1]
    na, nt, nd, nu = dims[0], dims[1], dims[2], dims[3]
    sa = strides[0] if laob.size > 0 else 0
    st, sd, su = strides[1], strides[2], strides[3]
    m0 = max(min(_CHUNK, n), 1)
    single = np.empty((12, m0))  # values shared by all contacts, repeated over a chunk
    for j, x in enumerate((laob, xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb)):
        fill(single[j], x[0] if x.size > 0 else 0.0, m0)
    rows = np.empty((_ROWS, m0))
    # Coulomb friction for every contact (one test for the whole call)
    coulomb = (
        la.size == 1
        and lb.size == 1
        and lv.size == 1
        and not (la[0] != 1.0 and lb[0] * lv[0] > 0.0)
    )
    if coulomb:
        fill(rows[_R_FAC], 1.0, m0)
        fill(rows[_R_INV], 1.0, m0)
    for c in range(first, last):
        lo = c * _CHUNK
        hi = min(lo + _CHUNK, n)
        m = hi - lo
        xs = chunk_of(xi, single[1], lo, hi)
        ys = chunk_of(eta, single[2], lo, hi)
        if not coulomb:
            _friction_factor(xs, ys, chunk_of(lv, single[9], lo, hi),
                             chunk_of(la, single[10], lo, hi), chunk_of(lb, single[11], lo, hi),
                             rows, m)  # fmt: skip
        inv = rows[_R_INV]
        _scaled(xs, chunk_of(kx, single[4], lo, hi), inv, rows[_R_X], m)
        _scaled(ys, chunk_of(ky, single[5], lo, hi), inv, rows[_R_Y], m)
        _scaled(chunk_of(phi, single[3], lo, hi), chunk_of(ks, single[6], lo, hi), inv, rows[_R_S],
                m)  # fmt: skip
        _coordinates(rows, m)
        base = rows[_R_BASE]
        fill(base, 0.0, m)
        _weights(rows[_R_X], origin[1], inv_step[1], nt, st, base, rows[_R_WT : _R_WT + 4], m)
        _weights(rows[_R_Y], origin[2], inv_step[2], nd, sd, base, rows[_R_WD : _R_WD + 4], m)
        _weights(rows[_R_S], origin[3], inv_step[3], nu, su, base, rows[_R_WU : _R_WU + 4], m)
        if sa > 0:
            laobs = chunk_of(laob, single[0], lo, hi)
            _weights(laobs, origin[0], inv_step[0], na, sa, base, rows[_R_WA : _R_WA + 4], m)
        _gather(tab, rows, m, st, sd, sa)
        _cap(rows[_R_F0], rows[_R_F1], m)
        _forces(rows, chunk_of(kf, single[7], lo, hi), chunk_of(km, single[8], lo, hi),
                out[0, lo:hi], out[1, lo:hi], out[2, lo:hi], m)  # fmt: skip


@jit(nogil=True)
def _lookup_one(tab, dims, strides, origin, inv_step, laob, xi, eta, phi, kx, ky, ks, kf, km,
                lv, la, lb):  # fmt: skip
    """:func:`_lookup_chunks` for one contact given as floats, on the full 4-D table
    (``laob`` = log(a/b)): (Fx, Fy, Mz). The scalar path of :func:`exact_table_forces`."""
    out = np.empty((3, 1))
    _lookup_chunks(tab, dims, strides, origin, inv_step, np.array([laob]), np.array([xi]),
                   np.array([eta]), np.array([phi]), np.array([kx]), np.array([ky]),
                   np.array([ks]), np.array([kf]), np.array([km]), np.array([lv]),
                   np.array([la]), np.array([lb]), out, 0, 1)  # fmt: skip
    return out[0, 0], out[1, 0], out[2, 0]


def _is_real(x) -> bool:
    """A Python float (or NumPy float64 scalar) or int, not bool."""
    return isinstance(x, float) or type(x) is int


def _scalar_forces(xi, eta, phi, fz, a, b, mu, g, nu, speed, ratio, decay):
    """Fast path of :func:`exact_table_forces` for one contact given as Python numbers, all
    valid: (Fx, Fy, Mz). None when anything needs the general path (which validates and
    raises the errors), so the two never disagree on what is accepted."""
    inf = math.inf
    if not (
        -inf < xi < inf and -inf < eta < inf and -inf < phi < inf
        and 0.0 <= fz < inf and 0.0 < a < inf and 0.0 < b < inf and 0.0 <= mu < inf
        and 0.0 < g < inf and POISSON_MIN <= nu <= POISSON_MAX
        and 0.0 <= ratio <= 1.0 and 0.0 <= decay < inf
    ):  # fmt: skip
        return None
    if speed is None:
        if ratio != 1.0 and decay > 0.0:
            return None  # falling friction needs the speed: the general path says so
        speed = 0.0
    elif not (_is_real(speed) and 0.0 <= speed < inf):
        return None
    aob = a / b
    if not AOB_MIN * (1 - 1e-12) <= aob <= AOB_MAX * (1 + 1e-12):
        return None
    c11, c22, c23, _ = kalker_scalar(aob, nu)
    c = math.sqrt(a * b)
    tau = mu * (1.5 / math.pi) * fz / (a * b * g)
    f = (1.5 / math.pi) / tau if tau > 0.0 else 0.0
    scale = mu * fz
    d = _load()
    return _lookup_one(d["padded_flat"], d["dims"], d["strides"], d["origin"], d["inv_step"],
                       math.log(aob), xi, eta, phi, f * c11, f * c22, c * f * c23, scale,
                       scale * c, speed, ratio, decay)  # fmt: skip


def _interp(d, laob, shape, xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb):
    """Fx, Fy, Mz of the contacts (``shape``); every input broadcasts to ``shape``. One a/b
    for all contacts (the usual case) is looked up in a 3-D slice of the table.

    From _PARALLEL_MIN contacts on, the chunks run on ``numba.get_num_threads()`` threads
    (:func:`railadhesion.numerics.run_chunks`; the kernel releases the GIL)."""
    n = math.prod(shape)

    def flat(v):  # length 1 (shared) or n; anything else is broadcast out; read-only
        v = np.asarray(v, dtype=float)
        if v.size == 1:
            v = v.reshape(1)
        else:
            if v.shape != shape:
                v = np.broadcast_to(v, shape)
            v = np.ascontiguousarray(v).reshape(-1)
        return _read_only(v)

    args = tuple(flat(v) for v in (xi, eta, phi, kx, ky, ks, kf, km, lv, la, lb))
    out = np.empty((3, n))
    if laob.size == 1 or np.all(laob == laob.flat[0]):
        table, laobs = _slice_at(float(laob.flat[0])), _NO_AOB
    else:
        table, laobs = d["padded_flat"], flat(laob)
    head = (table, d["dims"], d["strides"], d["origin"], d["inv_step"], laobs, *args, out)
    nchunk = (n + _CHUNK - 1) // _CHUNK
    run_chunks(_lookup_chunks, head, nchunk, n >= _PARALLEL_MIN)
    return out.reshape(3, *shape)


_NO_AOB = _read_only(np.empty(0))


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "normal_force", "a", "b",
                            "speed", "shear_modulus", "poisson"))


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

    **Cost**: ``benchmarks/bench_exact.py --table`` (figures in ``docs/performance.md``). One
    contact given as Python floats takes a scalar path (checks in plain Python, one compiled
    call). Parallel from 1e5 contacts (``numba.get_num_threads()`` threads).

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
    if kalker_correction is True and all(
        _is_real(x) for x in (creep_long, creep_lat, spin, normal_force, a, b, mu,
                              shear_modulus, poisson, friction_ratio, friction_decay)
    ):  # fmt: skip
        # one contact in Python numbers (ODE right-hand sides): checks in plain Python; ints
        # become floats (the compiled lookup is typed for float64)
        res = _scalar_forces(*(float(x) for x in (creep_long, creep_lat, spin, normal_force, a,
                                                  b, mu, shear_modulus, poisson)),
                             float(speed) if _is_real(speed) else speed,
                             float(friction_ratio), float(friction_decay))  # fmt: skip
        if res is not None:
            # implausible inputs warn (docs/checks.md)
            _PLAUSIBLE((creep_long, creep_lat, spin, normal_force, a, b, speed, shear_modulus,
                        poisson))  # fmt: skip
            return res
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
    ratio, decay, v = check_friction_law(speed, friction_ratio, friction_decay)
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
    _PLAUSIBLE((xi, eta, phi, fz, a_, b_, speed, g, nu))  # implausible inputs warn
    if fx.ndim == 0:
        return float(fx), float(fy), float(mz)
    return fx, fy, mz
