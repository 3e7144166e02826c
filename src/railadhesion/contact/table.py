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
grid in polar coordinates of (r, S), ``r = sqrt(X^2 + Y^2)``: log(a/b), the magnitude
``rho = sqrt(r^2 + S^2)`` through ``t = (2/pi) atan(rho)``, the creep direction
``theta = atan2(Y, X)`` in [0, pi/2] and the spin's share ``psi = atan2(kappa S, r)``
(``kappa = sqrt(1 + (b/a)^2)``, :func:`spin_weight`) in
[-pi/2, pi/2] through ``u = (2/pi) psi``. Deep sliding (rho to infinity) is then one smooth
function of (theta, psi) on the last t nodes: with separate magnitude and spin axes, large
creepage and large spin met in a corner where the solution depends on the ratio S/r only,
which no interpolation along the two axes can carry. Other quadrants follow from the
symmetries (xi, eta, phi) -> -(xi, eta, phi) (all outputs change sign) and
(eta, phi) -> -(eta, phi) (Fy and Mz change sign). Interpolation in compiled code, cubic
(Catmull-Rom) along t, theta and u, with a ghost node beyond each end extrapolated
quadratically; along log(a/b) linear between the planes of a grid ``AOB_REFINE`` times
finer than the file's, on which the cubic through the file's planes (with its ghost planes)
is evaluated once, at load. The table as loaded holds the values in single precision, like
the file's nodes; the sums are in double precision. The nodes are solved with the build
grid's own linear coefficients and looked up with Kalker's
(:func:`railadhesion.contact.kalker.kalker_coefficients`, the compliances 1/C interpolated
between Kalker's rows, ``compliance=True``: C linear in b/a overshoots the exact theory's
coefficients of long contacts by up to 4.5 % between the rows), which removes most of the
grid's discretisation error (its excess stiffness).

The table is solved with Coulomb friction at nu = 0.28 (steel); Poisson's ratios 0.25-0.30 are
served by scaling with Kalker's coefficients at that nu, and falling friction by one
coefficient per contact at Polach's global slip velocity (see :func:`exact_table_forces` for
both and for where they are accurate). When all contacts share one a/b and nu (given once,
or as arrays of equal values) the table is first interpolated to that a/b and the lookup is
3-D.

One law, one implementation: the lookup of one contact is :func:`exact_table_law` (a
``jitable`` function for compiled code: drivers, integrators, FMUs), made of pieces that the
batch loop of :func:`exact_table_forces` calls in stages over chunks of contacts.
"""

from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources

import numpy as np

from railadhesion._validate import (
    as_float_array,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.contact.exact import check_friction_law
from railadhesion.contact.friction import falling_friction_factor
from railadhesion.contact.kalker import (
    check_creepages,
    kalker_coefficients,
    kalker_law,
    kalker_rows,
    kalker_scalar,
)
from railadhesion.numerics import (
    CHUNK,
    FINITE,
    NONNEGATIVE,
    POSITIVE,
    atan_nonneg,
    count_outside,
    fill,
    fill_row,
    flatten,
    jit,
    jitable,
    load_row,
    run_chunks,
)
from railadhesion.plausibility import input_checker
from railadhesion.simd import NOUT, contract_rows

__all__ = ["exact_table_arrays", "exact_table_forces", "exact_table_law", "table_axes"]

#: Poisson's ratio of the table.
TABLE_POISSON = 0.28
#: Range of Poisson's ratio accepted (creepages scaled with Kalker's coefficients at that nu;
#: error against the exact solver measured in docs/validation/exact_models.md).
POISSON_MIN, POISSON_MAX = 0.25, 0.30
#: Scale of the magnitude transform t = (2/pi) atan(rho/R0).
R0 = 1.0
#: Coordinates of the table's last three axes (``coordinates`` in the package data):
#: t of rho = |(X, Y, S)|, theta, u = psi/(pi/2) with psi = atan2(kappa S, |(X, Y)|).
COORDINATES = "polar-kappa"
_TWO_PI = 2.0 / math.pi
#: a/b range of the table (outside: ValueError).
AOB_MIN, AOB_MAX = 0.2, 5.0
#: Finite stand-in for an infinite normalised creepage / spin at the last nodes.
BIG = 1e4
#: Elements per axis of the packaged table's build grids up to a/b = 1 (:func:`build_grid`;
#: ``scripts/build_exact_table.py --grid``). 24 rather than 20 brings the worst cases (long
#: contacts, lateral creepage against spin) closer to the converged solution, for 1.5 times
#: the rebuild time (docs/validation/exact_models.md).
BUILD_N = 24

#: Planes of the table as loaded per interval of the file's a/b nodes: the cubic interpolation
#: along log(a/b) evaluated, once at load, on a grid this many times finer, between whose
#: planes a lookup interpolates linearly (2 planes a contact rather than the cubic's 4: the
#: lookup with a/b varying per contact waits mostly on its table rows). The linear step
#: departs from the cubic by at most 1.2e-3 mu Fz (|(Fx, Fy)|) and 8e-4 mu Fz c (Mz) at the
#: table's nodes (tests/contact/test_table_kernel.py), against the model's error budget of
#: 0.02 mu Fz; the table as loaded is then 3.9 MB in single precision.
AOB_REFINE = 4


def table_axes(n_aob=9, n_mag=29, n_dir=7, n_spin=33):
    """Node coordinates of the table: (a/b, t, theta, u); see :func:`node_creepages`. The
    node counts are integers >= 4 (the cubic lookup needs four nodes per axis); ValueError
    naming the count otherwise."""
    for name, count in (("n_aob", n_aob), ("n_mag", n_mag), ("n_dir", n_dir),
                        ("n_spin", n_spin)):  # fmt: skip
        _check_count(count, name, 4)
    aob = np.geomspace(AOB_MIN, AOB_MAX, n_aob)
    tmag = np.linspace(0.0, 1.0, n_mag)
    theta = np.linspace(0.0, 0.5 * math.pi, n_dir)
    uspin = np.linspace(-1.0, 1.0, n_spin)
    return aob, tmag, theta, uspin


def build_grid(aob, n=BUILD_N):
    """Elements (nx, ny) of the build grid at a/b: n x n up to a/b = 1; for long contacts
    more along the rolling direction, ``nx = min(2 n, round(n sqrt(a/b)))``,
    ``ny = round(n^2/nx)`` (48 x 12 at a/b = 5 for n = 24), about as many elements and
    closer to the solver on fine square-count grids (docs/validation/exact_models.md).
    ``aob`` in the table's range, ``n`` an integer >= 4 (ValueError naming them otherwise);
    the default is the packaged table's."""
    _check_count(n, "n", 4)
    aob = float(check_range(aob, "a/b", AOB_MIN, AOB_MAX))
    if aob <= 1.0:
        return n, n
    nx = min(2 * n, round(n * math.sqrt(aob)))
    return nx, round(n * n / nx)


def _check_count(value, name, low):
    """ValueError naming ``name`` unless ``value`` is an integer (not bool) >= ``low``."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")


@jitable(inline="always")
def spin_weight(aob):
    """Weight kappa of the Kalker-scaled spin S in the table's spin angle
    ``psi = atan2(kappa S, r)``: ``sqrt(1 + (b/a)^2)``, about 1 for long contacts and b/a for
    wide ones, smooth in log(a/b) (the table is interpolated along it at fixed psi). Wide
    contacts turn from creepage- to spin-dominated sliding at small S/r (the spin slip phi y
    reaches b while C23, hence S, is small); with kappa the spin nodes follow."""
    return math.sqrt(1.0 + 1.0 / (aob * aob))


def node_creepages(tmag, theta, uspin, kappa=1.0):
    """Kalker-scaled (X, Y, S) at table nodes (broadcasting) of a contact with spin weight
    ``kappa`` (:func:`spin_weight`); t = 1 -> rho = BIG.

    Inverse of ``t = (2/pi) atan(rho/R0)`` (smooth and odd, so that the cubic interpolation
    keeps linear theory at vanishing creepage and spin, with nodes out to large creepages)
    and ``psi = atan2(kappa S, r) = u pi/2`` with ``rho = sqrt(r^2 + S^2)`` (module
    docstring). ValueError naming the argument for coordinates outside the table: ``tmag``
    in [0, 1] (a negative creepage magnitude rho has no node), ``theta`` in [0, pi/2],
    ``uspin`` in [-1, 1], ``kappa`` >= 1."""
    tmag = check_range(tmag, "tmag", 0.0, 1.0)
    theta = check_range(theta, "theta", 0.0, 0.5 * math.pi)
    uspin = check_range(uspin, "uspin", -1.0, 1.0)
    kappa = check_range(kappa, "kappa", 1.0, math.inf, closed="left")
    tmag, theta, uspin = np.broadcast_arrays(tmag, theta, uspin)
    rho = np.where(tmag >= 1.0, BIG, R0 * np.tan(0.5 * np.pi * np.minimum(tmag, 0.999)))
    psi = 0.5 * np.pi * uspin
    ang = np.arctan2(np.sin(psi), kappa * np.where(np.abs(uspin) >= 1.0, 0.0, np.cos(psi)))
    r = rho * np.cos(ang)
    return r * np.cos(theta), r * np.sin(theta), rho * np.sin(ang)


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
    if str(data.get("coordinates", "")) != COORDINATES:
        raise RuntimeError(f"exact_table.npz: not a table in {COORDINATES} coordinates (rebuild "
                           "it with scripts/build_exact_table.py)")  # fmt: skip
    axes = (np.log(data["aob"]), data["tmag"], data["theta"], data["uspin"])
    for ax in axes:  # the interpolation assumes uniform axes of at least 4 nodes
        if ax.size < 4 or not np.allclose(np.diff(ax), (ax[-1] - ax[0]) / (ax.size - 1),
                                          rtol=1e-9, atol=1e-12):  # fmt: skip
            raise RuntimeError("exact_table.npz: table axes are not uniform")
    # along log(a/b) the planes of the finer grid (AOB_REFINE), without ghost nodes
    na = axes[0].size
    data["dims"] = np.array([(na - 1) * AOB_REFINE + 1] + [ax.size for ax in axes[1:]],
                            dtype=np.int64)  # fmt: skip
    data["origin"] = np.array([ax[0] for ax in axes])
    data["inv_step"] = np.array([(ax.size - 1) / (ax[-1] - ax[0]) for ax in axes])
    data["inv_step"][0] *= AOB_REFINE
    # outputs last, as rows of _NOUT (Fx, Fy, Mz): the 4 spin nodes of a (t, theta) pair
    # that a lookup needs are then 12 contiguous values, loaded as one SIMD vector; ghost
    # nodes on the axes t, theta, u (extrapolated in double precision)
    values = _with_ghosts(np.moveaxis(data["values"], 0, -1).astype(float), (0, 1, 2, 3))
    # the cubic along log(a/b) (the ghost planes its first and last intervals need) at the
    # finer grid's nodes: the file's planes at every AOB_REFINE-th, unchanged
    planes = np.zeros((int(data["dims"][0]),) + values.shape[1:-1] + (_NOUT,), np.float32)
    for j in range(planes.shape[0]):
        i, w = _locate_uniform(j / AOB_REFINE, 0.0, 1.0, na)
        planes[j, ..., :3] = sum(c * values[int(i) + q] for q, c in enumerate(_catmull_rom(w)))
    # held in single precision, as the file holds the nodes: the 4-D lookup waits mostly on
    # its table rows (a/b varying per contact), so half the bytes make it faster; the
    # interpolation itself is computed in double precision
    data["planes"] = _read_only(planes)
    data["padded_flat"] = data["planes"].reshape(-1)
    # distance in memory (values) between consecutive nodes along log(a/b), t, theta, u
    data["strides"] = np.array([planes.strides[j] // planes.itemsize for j in range(4)],
                               dtype=np.int64)  # fmt: skip
    for v in ("dims", "strides", "origin", "inv_step"):
        data[v] = _read_only(data[v])
    return data


def _read_only(x):
    """A read-only view of x (the kernel is compiled for read-only arrays only)."""
    x = x.view()
    x.flags.writeable = False
    return x


@jitable
def _catmull_rom(w):
    """Catmull-Rom weights of the nodes i-1 .. i+2 at the fraction w of [i, i+1]."""
    w2 = w * w
    w3 = w2 * w
    return (0.5 * (-w3 + 2.0 * w2 - w), 0.5 * (3.0 * w3 - 5.0 * w2 + 2.0),
            0.5 * (-3.0 * w3 + 4.0 * w2 + w), 0.5 * (w3 - w2))  # fmt: skip


@jitable
def _locate_uniform(v, v0, inv_h, n):
    """Index i and fraction w of v between the uniform nodes i and i+1 (clipped to the
    nodes; NaN goes to the first node): float i, w (vectorisable)."""
    q = (v - v0) * inv_h
    q = q if q > 0.0 else 0.0
    q = q if q < n - 1.0 else n - 1.0
    i = min(np.floor(q), n - 2.0)
    return i, q - i


@lru_cache(maxsize=32)
def _slice_at(laob: float) -> np.ndarray:
    """The table interpolated, as in the kernel (linearly between the planes of the finer
    grid along log(a/b)), to one log(a/b): a flat read-only array in double precision,
    layout of :func:`_load`'s ``planes`` without the a/b axis."""
    d = _load()
    ia, wa = _locate_uniform(laob, d["origin"][0], d["inv_step"][0], int(d["dims"][0]))
    planes = d["planes"]
    out = (1.0 - wa) * planes[int(ia)].astype(float) + wa * planes[int(ia) + 1].astype(float)
    return _read_only(out.reshape(-1))


#: Values per table node in memory: Fx, Fy, Mz.
_NOUT = NOUT  # values per node (Fx, Fy, Mz), as contract_rows reads them
#: Contacts from which the lookup runs in parallel (as the package's Polach kernels).
_PARALLEL_MIN = 100_000


# --- the law: one contact, in pieces that the batch loop calls in stages -----------------------


@jitable(inline="always")
def table_friction_factor(xi, eta, speed, ratio, decay):
    """The looked-up coefficient of friction over mu: the falling-friction law's factor
    (:func:`falling_friction_factor`) at Polach's global slip velocity V |(xi, eta)|; 1 for
    constant friction."""
    w = speed * math.sqrt(xi * xi + eta * eta)
    return falling_friction_factor(w, ratio, decay) if w > 0.0 else 1.0


@jitable(inline="always")
def table_scaled_creepages(xi, eta, phi, fz, a, b, mu, g, fac, c11, c22, c23):
    """Kalker-scaled creepages (X, Y, S) of the looked-up coefficient of friction
    ``fac mu`` (:func:`table_friction_factor`), the force scale ``kf = fac mu Fz`` and
    ``c = sqrt(a b)`` of one contact (module docstring); ``fac`` divides the creepages and
    scales the forces."""
    c = math.sqrt(a * b)
    tau = mu * (1.5 / math.pi) * fz / (a * b * g)  # mu p0 / G
    f = (1.5 / math.pi) / (tau * fac) if tau * fac > 0.0 else 0.0
    return xi * f * c11, eta * f * c22, phi * c * f * c23, fac * mu * fz, c


@jitable(inline="always")
def table_coordinates(x, y, s, kappa):
    """Table coordinates (t, theta, u) of Kalker-scaled creepages (X, Y, S), reflected into
    X, Y >= 0 (module docstring: t of rho = |(X, Y, S)|, theta = atan2(Y, X),
    u = atan2(kappa S, |(X, Y)|)/(pi/2), ``kappa``: :func:`spin_weight`), and the signs
    (sgn, sy) of the symmetries: (xi, eta, phi) -> -(xi, eta, phi) changes every output's
    sign, (eta, phi) -> -(eta, phi) those of Fy and Mz."""
    sgn = -1.0 if x < 0.0 else 1.0
    x = sgn * x
    y = sgn * y
    s = sgn * s
    sy = -1.0 if y < 0.0 else 1.0
    y = sy * y
    s = sy * s
    r = math.sqrt(x * x + y * y)
    sa = abs(s)
    t = _TWO_PI * atan_nonneg(math.sqrt(r * r + sa * sa) / R0)
    sa *= kappa
    hi = max(x, y)
    lo = min(x, y)  # direction in [0, pi/2] from the smaller over the larger
    ang = atan_nonneg(lo / (hi if hi > 0.0 else 1.0))
    th = 0.5 * math.pi - ang if y > x else ang
    hi = max(r, sa)
    lo = min(r, sa)  # spin angle in [0, pi/2], likewise
    ang = atan_nonneg(lo / (hi if hi > 0.0 else 1.0))
    u = _TWO_PI * (0.5 * math.pi - ang if sa > r else ang)
    return t, th, -u if s < 0.0 else u, sgn, sy


@jitable(inline="always")
def table_forces(f0, f1, f2, sgn, sy, kf, c):
    """(Fx, Fy, Mz) from the interpolated normalised outputs: |(Fx, Fy)| capped at mu Fz
    (the cubic may overshoot it by a few 0.1 % near full sliding; the exact solution never
    does), the signs of the symmetries, the scales mu Fz and mu Fz c."""
    ft = math.sqrt(f0 * f0 + f1 * f1)
    scale = kf / (ft if ft > 1.0 else 1.0)
    return sgn * scale * f0, sgn * sy * scale * f1, sgn * sy * kf * c * f2


@jitable
def _two_planes(tab, o, sa, st, sd, w0, w1, w2, w3, w4, w5, w6, w7, w8, w9, w10, w11, wa, wb):
    """The interpolation along log(a/b): ``wa`` times the cubic sums
    (:func:`~railadhesion.simd.contract_rows`, weights ``w0 .. w11`` along t, theta, u) of
    the plane at ``o`` plus ``wb`` times those of the next plane, ``sa`` further on."""
    p0, p1, p2 = contract_rows(tab, o, st, sd, w0, w1, w2, w3, w4, w5, w6, w7, w8, w9, w10,
                               w11)  # fmt: skip
    q0, q1, q2 = contract_rows(tab, o + sa, st, sd, w0, w1, w2, w3, w4, w5, w6, w7, w8, w9,
                               w10, w11)  # fmt: skip
    return wa * p0 + wb * q0, wa * p1 + wb * q1, wa * p2 + wb * q2


@jitable
def table_sums(tab, dims, strides, origin, inv_step, laob, t, th, u):
    """The interpolation of the normalised (Fx, Fy, Mz/c)/(mu Fz) at table coordinates
    (log a/b, t, theta, u): cubic (Catmull-Rom) along t, theta, u, linear between the planes
    of the finer grid along log(a/b) (``AOB_REFINE``). ``tab``: the table as loaded,
    flat (:func:`_load`'s ``padded_flat``), its four axes' ``dims``, ``strides``,
    ``origin``, ``inv_step``; or its slice at one a/b (:func:`_slice_at`,
    ``strides[0] = 0``; ``laob`` unused)."""
    it, ft = _locate_uniform(t, origin[1], inv_step[1], dims[1])
    id_, fd = _locate_uniform(th, origin[2], inv_step[2], dims[2])
    iu, fu = _locate_uniform(u, origin[3], inv_step[3], dims[3])
    t0, t1, t2, t3 = _catmull_rom(ft)
    d0, d1, d2, d3 = _catmull_rom(fd)
    u0, u1, u2, u3 = _catmull_rom(fu)
    st = strides[1]
    sd = strides[2]
    sa = strides[0]
    o = int(it) * st + int(id_) * sd + int(iu) * strides[3]
    if sa == 0:
        return contract_rows(tab, o, st, sd, t0, t1, t2, t3, d0, d1, d2, d3, u0, u1, u2, u3)
    ia, fa = _locate_uniform(laob, origin[0], inv_step[0], dims[0])
    return _two_planes(tab, o + int(ia) * sa, sa, st, sd, t0, t1, t2, t3, d0, d1, d2, d3, u0,
                       u1, u2, u3, 1.0 - fa, fa)  # fmt: skip


@jitable
def exact_table_law(xi, eta, phi, fz, a, b, mu, g, nu, speed, ratio, decay, tab, dims, strides,
                    origin, inv_step):  # fmt: skip
    """Creep forces (Fx, Fy, Mz) of one contact by the table model: the law of
    :func:`exact_table_forces` (its Notes), without validation (inputs in its ranges), for
    compiled code (``numba``; a :func:`~railadhesion.numerics.jitable` function).

    ``tab, dims, strides, origin, inv_step``: the 4-D table with its axes (the package data
    as loaded by ``railadhesion.contact.table._load``: ``padded_flat``, ``dims``,
    ``strides``, ``origin``, ``inv_step``). Kalker's coefficients at (a/b, nu)
    (:func:`~railadhesion.contact.kalker.kalker_law`) scale the creepages; then the pieces
    ``table_friction_factor``, ``table_scaled_creepages``, ``table_coordinates``,
    ``table_sums`` and ``table_forces`` of the same module, which the batch loop of
    :func:`exact_table_forces` calls in stages.
    """
    c11, c22, c23, _ = kalker_law(a / b, nu, True)
    fac = table_friction_factor(xi, eta, speed, ratio, decay)
    x, y, s, kf, c = table_scaled_creepages(xi, eta, phi, fz, a, b, mu, g, fac, c11, c22, c23)
    t, th, u, sgn, sy = table_coordinates(x, y, s, spin_weight(a / b))
    f0, f1, f2 = table_sums(tab, dims, strides, origin, inv_step, math.log(a / b), t, th, u)
    return table_forces(f0, f1, f2, sgn, sy, kf, c)


# --- the batch loop (stages over chunks of contacts) and the scalar entry point ----------------

#: Bounds (numerics.count_outside) of Poisson's ratio for the table and of the ratio A.
_POISSON_TABLE = (POISSON_MIN, POISSON_MIN, POISSON_MAX, POISSON_MAX)
_UNIT = (0.0, 0.0, 1.0, 1.0)
# Rows of the chunk buffer (rows of CHUNK values): the 12 inputs in the order of the kernel's
# arguments, a/b, Kalker's coefficients, then the stages' results.
_NIN = 12
_R_RATIO, _R_C11 = 12, 13  # C11, C22, C23 in rows 13-15
_R_T, _R_TH, _R_U, _R_SGN, _R_SY, _R_KF, _R_C, _R_BASE, _R_FAC = range(16, 25)
_R_W = 25  # 12 rows of cubic weights (t, theta, u), 2 of linear ones (log(a/b))
_R_F = 39  # the 3 interpolated outputs
_TROWS = 42


@jit
def _stage_friction(buf, m):
    """Row _R_FAC of the chunk: :func:`table_friction_factor`."""
    for k in range(m):
        buf[_R_FAC * CHUNK + k] = table_friction_factor(
            buf[k], buf[CHUNK + k], buf[9 * CHUNK + k], buf[10 * CHUNK + k],
            buf[11 * CHUNK + k])  # fmt: skip


@jit
def _stage_scaled(buf, m):
    """Rows of the chunk: :func:`table_scaled_creepages` and :func:`table_coordinates`."""
    for k in range(m):
        x, y, s, kf, c = table_scaled_creepages(
            buf[k], buf[CHUNK + k], buf[2 * CHUNK + k], buf[3 * CHUNK + k], buf[4 * CHUNK + k],
            buf[5 * CHUNK + k], buf[6 * CHUNK + k], buf[7 * CHUNK + k], buf[_R_FAC * CHUNK + k],
            buf[_R_C11 * CHUNK + k], buf[(_R_C11 + 1) * CHUNK + k],
            buf[(_R_C11 + 2) * CHUNK + k])  # fmt: skip
        t, th, u, sgn, sy = table_coordinates(
            x, y, s, spin_weight(buf[4 * CHUNK + k] / buf[5 * CHUNK + k]))
        buf[_R_T * CHUNK + k] = t
        buf[_R_TH * CHUNK + k] = th
        buf[_R_U * CHUNK + k] = u
        buf[_R_SGN * CHUNK + k] = sgn
        buf[_R_SY * CHUNK + k] = sy
        buf[_R_KF * CHUNK + k] = kf
        buf[_R_C * CHUNK + k] = c


@jit
def _stage_weights(v, v0, inv_h, n, stride, base, w, m):
    """Cubic weights along one axis (coordinates ``v``) into the rows of ``w`` (4, CHUNK);
    the axis' part of each contact's first table row (node index times ``stride``) added to
    ``base`` (views of the chunk buffer: few arrays, so that the loop is SIMD code)."""
    w0, w1, w2, w3 = w[0], w[1], w[2], w[3]
    for k in range(m):
        i, f = _locate_uniform(v[k], v0, inv_h, n)
        c0, c1, c2, c3 = _catmull_rom(f)
        w0[k] = c0
        w1[k] = c1
        w2[k] = c2
        w3[k] = c3
        base[k] = base[k] + i * stride


@jit
def _stage_linear(v, v0, inv_h, n, stride, base, w, m):
    """Linear weights along log(a/b) (coordinates ``v``) into the rows of ``w`` (2, CHUNK), the
    axis' part of each contact's first table row added to ``base`` (as
    :func:`_stage_weights`)."""
    w0, w1 = w[0], w[1]
    for k in range(m):
        i, f = _locate_uniform(v[k], v0, inv_h, n)
        w0[k] = 1.0 - f
        w1[k] = f
        base[k] = base[k] + i * stride


@jit
def _stage_sums(tab, buf, m, st, sd, sa):
    """The interpolated outputs of each contact (:func:`~railadhesion.simd.contract_rows`;
    sa > 0: also along log(a/b), linearly between the planes sa apart) into rows _R_F to
    _R_F + 2."""
    for k in range(m):
        o = int(buf[_R_BASE * CHUNK + k])
        r = _R_W * CHUNK + k  # the 12 weights along t, theta, u, CHUNK apart
        w0, w1, w2, w3 = buf[r], buf[r + CHUNK], buf[r + 2 * CHUNK], buf[r + 3 * CHUNK]
        r += 4 * CHUNK
        w4, w5, w6, w7 = buf[r], buf[r + CHUNK], buf[r + 2 * CHUNK], buf[r + 3 * CHUNK]
        r += 4 * CHUNK
        w8, w9, w10, w11 = buf[r], buf[r + CHUNK], buf[r + 2 * CHUNK], buf[r + 3 * CHUNK]
        if sa == 0:
            f0, f1, f2 = contract_rows(tab, o, st, sd, w0, w1, w2, w3, w4, w5, w6, w7, w8,
                                          w9, w10, w11)  # fmt: skip
        else:
            f0, f1, f2 = _two_planes(tab, o, sa, st, sd, w0, w1, w2, w3, w4, w5, w6, w7, w8,
                                     w9, w10, w11, buf[(_R_W + 12) * CHUNK + k],
                                     buf[(_R_W + 13) * CHUNK + k])  # fmt: skip
        buf[_R_F * CHUNK + k] = f0
        buf[(_R_F + 1) * CHUNK + k] = f1
        buf[(_R_F + 2) * CHUNK + k] = f2


@jit
def _stage_forces(buf, m, fx, fy, mz):
    """:func:`table_forces` of the chunk into the outputs (views of the chunk)."""
    for k in range(m):
        fx[k], fy[k], mz[k] = table_forces(
            buf[_R_F * CHUNK + k], buf[(_R_F + 1) * CHUNK + k], buf[(_R_F + 2) * CHUNK + k],
            buf[_R_SGN * CHUNK + k], buf[_R_SY * CHUNK + k], buf[_R_KF * CHUNK + k],
            buf[_R_C * CHUNK + k])  # fmt: skip


@jit(nogil=True)
def _table_chunks(xi, eta, phi, fz, a, b, mu, g, nu, v, la, lb, kc, tab, dims, strides, origin,
                  inv_step, fx, fy, mz, first, last):  # fmt: skip
    """:func:`exact_table_law` of the contacts of chunks ``first`` to ``last - 1`` (of CHUNK
    contacts) into fx, fy, mz (length n); the inputs are 1-d float64 arrays of length n or 1
    (one value for every contact). ``kc`` (3, m): Kalker's (C11, C22, C23), m = 1 (shared by
    every contact) or n, or m = 0: looked up per contact at its a/b and nu
    (:func:`kalker_law`, through :func:`kalker_rows`). ``tab`` with ``strides[0] = 0`` is the
    table's slice at the one a/b of every contact. The pieces of the law run in stages over
    a chunk (short loops, SIMD code; the sums contact by contact). Validates in the same
    pass; returns the number of chunks with an input out of range (their forces are NaN)."""
    n = fx.size
    count = min(CHUNK, n)
    buf = np.zeros(_TROWS * CHUNK)
    inputs = (xi, eta, phi, fz, a, b, mu, g, nu, v, la, lb)
    for j in range(_NIN):
        fill_row(buf, j, inputs[j], count)
    nkc = kc.shape[1]
    if nkc == 1:
        for j in range(3):
            fill(buf[(_R_C11 + j) * CHUNK :], kc[j, 0], count)
    sa = strides[0]
    # constant friction for every contact (A = 1 or B V = 0, values shared by all)
    coulomb = la.size == 1 and lb.size == 1 and v.size == 1 and not (la[0] != 1.0
                                                                      and lb[0] * v[0] > 0.0)
    if coulomb:
        fill(buf[_R_FAC * CHUNK :], 1.0, count)
    nbad = 0
    for c in range(first, last):
        lo = c * CHUNK
        m = min(CHUNK, n - lo)
        bad = (count_outside(xi, FINITE, lo, m) + count_outside(eta, FINITE, lo, m)
               + count_outside(phi, FINITE, lo, m) + count_outside(fz, NONNEGATIVE, lo, m)
               + count_outside(a, POSITIVE, lo, m) + count_outside(b, POSITIVE, lo, m)
               + count_outside(mu, NONNEGATIVE, lo, m) + count_outside(g, POSITIVE, lo, m)
               + count_outside(nu, _POISSON_TABLE, lo, m)
               + count_outside(v, NONNEGATIVE, lo, m) + count_outside(la, _UNIT, lo, m)
               + count_outside(lb, NONNEGATIVE, lo, m))  # fmt: skip
        for j in range(_NIN):
            load_row(buf, j, inputs[j], lo, m)
        if bad == 0 and sa > 0:
            for k in range(m):
                r = buf[4 * CHUNK + k] / buf[5 * CHUNK + k]
                buf[_R_RATIO * CHUNK + k] = r
                bad += 0 if AOB_MIN * (1 - 1e-12) <= r <= AOB_MAX * (1 + 1e-12) else 1
        ox, oy, oz = fx[lo : lo + m], fy[lo : lo + m], mz[lo : lo + m]
        if bad > 0:
            nbad += 1
            fill(ox, math.nan, m)
            fill(oy, math.nan, m)
            fill(oz, math.nan, m)
            continue
        if nkc == 0:
            kalker_rows(buf, _R_RATIO, 8, _R_C11, CHUNK, m, True)
        elif nkc > 1:
            for j in range(3):
                dst = buf[(_R_C11 + j) * CHUNK :]
                for k in range(m):
                    dst[k] = kc[j, lo + k]
        if not coulomb:
            _stage_friction(buf, m)
        _stage_scaled(buf, m)
        rows = buf.reshape(_TROWS, CHUNK)
        base = rows[_R_BASE]
        fill(base, 0.0, m)
        _stage_weights(rows[_R_T], origin[1], inv_step[1], dims[1], strides[1], base,
                       rows[_R_W : _R_W + 4], m)  # fmt: skip
        _stage_weights(rows[_R_TH], origin[2], inv_step[2], dims[2], strides[2], base,
                       rows[_R_W + 4 : _R_W + 8], m)  # fmt: skip
        _stage_weights(rows[_R_U], origin[3], inv_step[3], dims[3], strides[3], base,
                       rows[_R_W + 8 : _R_W + 12], m)  # fmt: skip
        if sa > 0:
            laob = rows[_R_RATIO]
            for k in range(m):
                laob[k] = math.log(laob[k])
            _stage_linear(laob, origin[0], inv_step[0], dims[0], sa, base,
                          rows[_R_W + 12 : _R_W + 14], m)  # fmt: skip
        _stage_sums(tab, buf, m, strides[1], strides[2], sa)
        _stage_forces(buf, m, ox, oy, oz)
    return nbad


@jit(nogil=True)
def _constant(x):
    """True if every value of x equals the first (stops at the first that does not)."""
    first = x[0]
    for k in range(1, x.size):
        if x[k] != first:
            return False
    return True


@jit
def _table_one(xi, eta, phi, fz, a, b, mu, g, nu, speed, ratio, decay, tab, dims, strides,
               origin, inv_step):  # fmt: skip
    """:func:`exact_table_law` for one contact given as floats (the scalar path of
    :func:`exact_table_forces`)."""
    return exact_table_law(xi, eta, phi, fz, a, b, mu, g, nu, speed, ratio, decay, tab, dims,
                           strides, origin, inv_step)  # fmt: skip


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
    d = _load()
    return _table_one(xi, eta, phi, fz, a, b, mu, g, nu, speed, ratio, decay, d["padded_flat"],
                      d["dims"], d["strides"], d["origin"], d["inv_step"])  # fmt: skip


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "normal_force", "a", "b", "mu",
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
        that nu (measured against the solver on 60 x 60 at 0.25, 0.28 and 0.30; the figures
        are in docs/validation/exact_models.md).
    speed, friction_ratio, friction_decay : array_like, optional
        Falling friction ``mu(w) = mu [(1 - A) exp(-B w) + A]`` with ``A = friction_ratio``
        in [0, 1], ``B = friction_decay`` [s/m] >= 0 and the rolling speed V [m/s] (as in
        :func:`railadhesion.contact.exact.exact_rolling`). The table is then looked up with
        the single coefficient ``mu(V sqrt(xi^2 + eta^2))``, Polach's choice (see Notes for
        where this is meaningful). Defaults: Coulomb friction.
    kalker_correction : bool, optional
        Scale the creepages with Kalker's coefficients (default), which corrects the build
        grids' linear coefficients (-1.4 to +0.4 % on 24 x 24, -0.9 to +2.2 % on the long
        contacts' grids); with False, with the build grids' own coefficients (interpolated in
        a/b), so that the table reproduces the solver on its build grid at the a/b nodes.

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
    0.008 muQ median and 0.023 muQ at worst for all four laws; with spin the local slip
    velocity varies over the contact, which one coefficient cannot represent: median
    0.004-0.015 muQ and max 0.014-0.045 muQ for Polach's laws (worst on long contacts,
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
    4.27
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
            # implausible inputs warn (docs/checks.md); no speed: nothing to check (0.0 keeps
            # the checker's fast test for floats)
            _PLAUSIBLE((creep_long, creep_lat, spin, normal_force, a, b, mu,
                        0.0 if speed is None else speed, shear_modulus, poisson))  # fmt: skip
            return res
    names = ("creep_long", "creep_lat", "spin", "normal_force", "a", "b", "mu",
             "shear_modulus", "poisson", "speed", "friction_ratio", "friction_decay")  # fmt: skip
    if speed is None:  # Coulomb friction unless the law says otherwise (then an error)
        check_friction_law(speed, friction_ratio, friction_decay)
    values = (creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus, poisson,
              0.0 if speed is None else speed, friction_ratio, friction_decay)  # fmt: skip
    arrays = [as_float_array(x, name) for x, name in zip(values, names, strict=True)]
    shape, n, flat = flatten(arrays)
    xi, eta, phi, fz, a_, b_, mu_, g, nu, v, ratio, decay = flat
    d = _load()
    tab, strides = d["padded_flat"], d["strides"]
    # one a/b and nu for every contact (values given once, or arrays of equal values): the
    # table's slice at that a/b and one Kalker lookup
    shared = all(x.size == 1 or _constant(x) for x in (a_, b_, nu))
    kc = np.empty((3, 0))
    if shared:
        a0, b0, nu0 = float(a_[0]), float(b_[0]), float(nu[0])
        if a0 > 0.0 and b0 > 0.0 and AOB_MIN * (1 - 1e-12) <= a0 / b0 <= AOB_MAX * (1 + 1e-12):
            tab, strides = _slice_at(math.log(a0 / b0)), _slice_strides(strides)
            if POISSON_MIN <= nu0 <= POISSON_MAX:
                kc = np.array(kalker_scalar(a0 / b0, nu0, True)[:3], dtype=float).reshape(3, 1)
    if not kalker_correction:  # the build grid's own coefficients, interpolated in log(a/b)
        kc = _grid_coefficients(d, a_, b_, nu, shared)
    fx, fy, mz = np.empty(n), np.empty(n), np.empty(n)
    nbad = run_chunks(_table_chunks, (xi, eta, phi, fz, a_, b_, mu_, g, nu, v, ratio, decay, kc,
                                      tab, d["dims"], strides, d["origin"], d["inv_step"], fx,
                                      fy, mz), -(-n // CHUNK), n >= _PARALLEL_MIN)  # fmt: skip
    if sum(nbad):
        _check_inputs(values)
        raise AssertionError("table kernel flagged an input the checks accept")
    # implausible inputs warn (docs/checks.md)
    _PLAUSIBLE((creep_long, creep_lat, spin, normal_force, a, b, mu, speed, shear_modulus,
                poisson))  # fmt: skip
    if not shape:
        return float(fx[0]), float(fy[0]), float(mz[0])
    return fx.reshape(shape), fy.reshape(shape), mz.reshape(shape)


def _slice_strides(strides):
    """Strides of :func:`_slice_at`'s slice: those of the table, none along a/b."""
    out = np.array(strides)
    out[0] = 0
    return _read_only(out)


def _grid_coefficients(d, a, b, nu, shared):
    """Kalker's coefficients scaled to the build grid's own (``kalker_correction=False``),
    interpolated in log(a/b): (3, 1) if ``shared``, else (3, n)."""
    if shared:
        a, b, nu = a[:1], b[:1], nu[:1]
    aob = np.broadcast_to(a / b, np.broadcast_shapes(a.shape, b.shape, nu.shape))
    laob = np.log(aob)
    k = kalker_coefficients(aob, nu, compliance=True)
    k0 = kalker_coefficients(aob, TABLE_POISSON, compliance=True)
    ln = np.log(d["aob"])
    return np.array([np.interp(laob, ln, d["cgrid"][:, j]) * cn / c0
                     for j, cn, c0 in zip(range(3), (k.c11, k.c22, k.c23),
                                          (k0.c11, k0.c22, k0.c23), strict=True)])  # fmt: skip


def _check_inputs(values):
    """Raise the ValueError naming the first input of :func:`exact_table_forces` out of its
    range (the compiled loop validates in the same pass and calls this to raise)."""
    xi, eta, phi, fz, a, b, mu, g, nu, v, ratio, decay = values
    check_creepages(xi, eta, phi)
    check_nonnegative(fz, "normal_force")
    a_ = check_positive(a, "a")
    b_ = check_positive(b, "b")
    check_nonnegative(mu, "mu")
    check_positive(g, "shear_modulus")
    nu_ = as_float_array(nu, "poisson")
    if not np.all((nu_ >= POISSON_MIN) & (nu_ <= POISSON_MAX)):
        raise ValueError(
            f"poisson must be in [{POISSON_MIN}, {POISSON_MAX}] for the table model (tabulated "
            f"at {TABLE_POISSON}, validated over that range), got {nu!r}"
        )
    check_friction_law(v, ratio, decay)
    aob = a_ / b_
    if not np.all((aob >= AOB_MIN * (1 - 1e-12)) & (aob <= AOB_MAX * (1 + 1e-12))):
        bad = aob[~((aob >= AOB_MIN * (1 - 1e-12)) & (aob <= AOB_MAX * (1 + 1e-12)))]
        raise ValueError(f"a/b (a over b) must be in [{AOB_MIN}, {AOB_MAX}] for the table "
                         f"model, got {bad.ravel()[:3].tolist()}")  # fmt: skip



def exact_table_arrays(aob=None):
    """The table as :func:`exact_table_law` takes it: ``(tab, dims, strides, origin,
    inv_step)``, its last five arguments (read-only arrays), for compiled code elsewhere in
    the package (the braking step, FMUs).

    ``aob=None``: the 4-D table (a/b looked up per contact). A float a/b in [0.2, 5]: the
    table interpolated to that a/b as :func:`exact_table_forces` does when every contact
    shares it (3-D lookup, ``strides[0] = 0``); the law then ignores the a/b of a contact
    in the interpolation (Kalker's coefficients still use it), so give it contacts of that
    a/b only."""
    d = _load()
    if aob is None:
        return d["padded_flat"], d["dims"], d["strides"], d["origin"], d["inv_step"]
    aob = float(aob)
    if not AOB_MIN * (1 - 1e-12) <= aob <= AOB_MAX * (1 + 1e-12):
        raise ValueError(f"aob (a/b) must be in [{AOB_MIN}, {AOB_MAX}] for the table model, "
                         f"got {aob!r}")
    return (_slice_at(math.log(aob)), d["dims"], _slice_strides(d["strides"]), d["origin"],
            d["inv_step"])
