"""Fitted adhesion curves mu(slip) per speed band, and the adhesion-law file they make.

Functional form [our choice; the falling-friction idea is Polach's (2005) and WILAC's]::

    mu(s) = mu_s * (1 - exp(-s / s0)) * (A + (1 - A) * exp(-B s))

with ``s`` the absolute slip v - R omega [m/s] (or the relative slip (v - R omega)/v [-]):
``mu_s`` [-] the adhesion scale, ``s0`` the slip of the rising part (m/s or -), ``A`` [-] the
ratio of the adhesion at large slip to ``mu_s``, ``B`` [s/m or -] the rate of the fall. It
rises linearly from 0 (slope ``mu_s/s0``), peaks, and falls towards ``A mu_s``: the shape of
seed 002's Figs. 8-10 and of Polach's curves at large creep. Each speed band is fitted on the
samples of the log (all axles), by weighted least squares on 200 slip bins (equivalent to a
fit to the samples when the slip is constant within a bin); R^2 and RMSE use 2000 bins and the
spread of mu within each (exact up to the slip spread within a bin of width max/2000); the
slip range is the 1st to 99th percentile of the samples at that resolution. Samples are
collected in one compiled pass over the log.

The minimum is found by variable projection (Golub and Pereyra 1973): for fixed ``s0`` and
``B`` the law is linear in ``c1 = mu_s A`` and ``c2 = mu_s (1 - A)``, solved exactly, so the
search runs over (s0, B) only: a grid, then a pattern search after Hooke and Jeeves (1961),
then scipy's ``least_squares`` polishes all four parameters.

Uncertainty [our approximation]: the standard errors are the linearised ones
(``s^2 (J^T W J)^-1``) with the residual variance of the samples, inflated by
``sqrt(n / n_eff)`` where ``n_eff`` counts one independent sample per correlation time of the
filtered signals (``1/(2 f_c)``, f_c the wheel cut-off) and per axle: filtered samples 2.4 ms
apart are not independent.

References: G. H. Golub and V. Pereyra, "The differentiation of pseudo-inverses and nonlinear
least squares problems whose variables separate", SIAM J. Numer. Anal. 10 (1973) 413-432.
R. Hooke and T. A. Jeeves, "'Direct search' solution of numerical and statistical problems",
J. ACM 8 (1961) 212-229.

Quality gate (``docs/checks.md``; :attr:`CurveFit.warnings`, :attr:`AdhesionLaw.trusted`): a
curve is not trusted if R^2 < 0.3 (:data:`railadhesion.plausibility.MIN_R_SQUARED_SCATTER`:
identified adhesion scatters, a good fit to a braking log has R^2 of 0.5-0.8), a
parameter ends on a bound of the search that is not a limit of the law (``A`` = 0 or 1 and
``B = 0`` are), the standard error of ``mu_s`` or ``s0`` is not finite or above its value, the
standard error of the curve itself (delta method, over its slip range) exceeds
:data:`MAX_CURVE_STDERR` of its peak, or fewer than 3 independent samples (``n_eff``) lie
below the peak (``s0``) or, when the law falls by more than 1 %, beyond it (``A``, ``B``).
The shape parameters ``A`` and ``B`` trade off against each other; their own standard errors
are reported but the curve's is what is judged.

A fit is saved as a TOML parameter file (``format = "railadhesion-adhesion-law"``,
``version = 1``, docs/identification.md) and loaded by :func:`load_adhesion_law` as an
:class:`AdhesionLaw`: a callable ``law(creep, speed)`` that the braking simulator can take as
its adhesion model (mu interpolated linearly in speed between band centres). The law, the
curve and the file live in ``railadhesion.braking.adhesion_law`` (a braking scenario reads
the file) and are re-exported here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy import optimize

from railadhesion._validate import check_choice
from railadhesion.braking.adhesion_law import (
    LAW_FORMAT,
    LAW_VERSION,  # noqa: F401 - re-exported (the file format's version)
    PARAM_NAMES,
    AdhesionLaw,
    CurveFit,
    falling_adhesion,
    load_adhesion_law,
)
from railadhesion.identification.surface import cell_index
from railadhesion.plausibility import (
    MIN_R_SQUARED_SCATTER,
    UntrustedResultWarning,
    fit_warnings,
    warn,
)

__all__ = [
    "LAW_FORMAT",
    "CurveFit",
    "AdhesionLaw",
    "falling_adhesion",
    "fit_adhesion_curves",
    "load_adhesion_law",
]

#: Largest standard error of a fitted curve over its slip range, relative to its peak, in a
#: trusted law (an assumption: a tenth of the adhesion).
MAX_CURVE_STDERR = 0.1

#: Fine slip bins per curve (statistics); the fit itself uses groups of 10 of them.
_FINE = 2000
_GROUP = 10
#: Local minima of the coarse grid searched further, and the grid's size (per axis).
GLOBAL_CANDIDATES = 2
GLOBAL_GRID = 48


@njit(cache=True, nogil=True)
def _band_stats(speed, x, mu, use, phase, edges):  # pragma: no cover - compiled
    """For each phase (0 all usable samples, 1 loss windows, 2 recovery windows), speed band
    (last row: all bands together) and fine slip bin of width max/_FINE: count, sum of slip,
    sum of mu, sum of mu^2. Samples: usable, finite slip >= 0 and finite mu. Also, per phase
    and band (last: every row, whatever its speed), the number of rows with at least one such
    sample and the sum of their speeds (for the bands' mean speeds)."""
    n, na = mu.shape
    nb = edges.size - 1
    top = np.zeros((3, nb + 1))
    rows = np.zeros((3, nb + 1))
    vsum = np.zeros((3, nb + 1))
    band = np.empty(n, np.int64)
    for k in range(n):
        v = speed[k]
        b = cell_index(v, edges) if v < edges[nb] else -1  # bands are [low, high)
        band[k] = b
        h0 = False
        h1 = False
        h2 = False
        for a in range(na):
            xv = x[k, a]
            if not (use[k, a] and xv >= 0.0 and np.isfinite(xv) and np.isfinite(mu[k, a])):
                continue
            p = phase[k, a]
            h0 = True
            if b >= 0:
                if xv > top[0, b]:
                    top[0, b] = xv
                if xv > top[0, nb]:
                    top[0, nb] = xv
            if p != 0:
                q = 1 if p > 0 else 2
                if q == 1:
                    h1 = True
                else:
                    h2 = True
                if b >= 0:
                    if xv > top[q, b]:
                        top[q, b] = xv
                    if xv > top[q, nb]:
                        top[q, nb] = xv
        for q in range(3):
            if (h0, h1, h2)[q]:
                rows[q, nb] += 1.0
                vsum[q, nb] += v
                if b >= 0:
                    rows[q, b] += 1.0
                    vsum[q, b] += v
    width = np.empty((3, nb + 1))
    for q in range(3):
        for b in range(nb + 1):
            width[q, b] = (top[q, b] if top[q, b] > 0 else 1.0) * (1.0 + 1e-9) / _FINE
    acc = np.zeros((3, nb + 1, _FINE, 4))  # the four sums of a bin side by side
    for k in range(n):
        b = band[k]
        if b < 0:
            continue
        for a in range(na):
            xv = x[k, a]
            y = mu[k, a]
            if not (use[k, a] and xv >= 0.0 and np.isfinite(xv) and np.isfinite(y)):
                continue
            p = phase[k, a]
            q = 1 if p > 0 else (2 if p < 0 else 0)
            yy = y * y
            for bb in (b, nb):
                j = min(int(xv / width[0, bb]), _FINE - 1)
                acc[0, bb, j, 0] += 1.0
                acc[0, bb, j, 1] += xv
                acc[0, bb, j, 2] += y
                acc[0, bb, j, 3] += yy
                if q != 0:
                    j = min(int(xv / width[q, bb]), _FINE - 1)
                    acc[q, bb, j, 0] += 1.0
                    acc[q, bb, j, 1] += xv
                    acc[q, bb, j, 2] += y
                    acc[q, bb, j, 3] += yy
    stats = np.empty((3, nb + 1, 4, _FINE))
    for q in range(3):
        for b in range(nb + 1):
            for j in range(_FINE):
                for c in range(4):
                    stats[q, b, c, j] = acc[q, b, j, c]
    return stats, rows, vsum


def band_statistics(ident, slip: str = "absolute", speed_bands=None):
    """Fine-bin sums of mu per phase and speed band (:func:`_band_stats`), computed once per
    identification, slip kind and band edges and kept with the identification.

    Returns ``(edges, stats, rows, speed_sums)``; ``stats`` has shape
    ``(3 phases, bands + 1, 4, _FINE)`` (phases all, loss, recovery; last band: all speeds).
    """
    edges = np.asarray([0.0, 10.0, 20.0, 30.0, 40.0] if speed_bands is None else speed_bands,
                       dtype=float)
    if edges.size < 2 or np.any(np.diff(edges) <= 0):
        raise ValueError("speed_bands must be at least 2 strictly increasing speeds [m/s]")
    cache = getattr(ident, "_cache", None)
    key = ("band_stats", slip, tuple(edges.tolist()))
    if cache is not None and key in cache:
        return cache[key]
    x = ident.slip if slip == "absolute" else ident.relative_slip
    out = _band_stats(
        np.asarray(ident.speed, dtype=float), np.asarray(x, dtype=float),
        np.asarray(ident.mu, dtype=float), np.asarray(ident.use, dtype=np.bool_),
        np.asarray(ident.phase, dtype=np.int8), edges,
    )
    out = (edges, *out)
    if cache is not None:
        cache[key] = out
    return out


@njit(cache=True, nogil=True)
def _linear_part(suu, suv, svv, sut, svt, stt, top):  # pragma: no cover - compiled
    """min over c1, c2 >= 0, c1 + c2 <= top of |t - c1 u - c2 v|^2 from the sums of products
    (a convex quadratic on a triangle: the unconstrained minimum if it lies inside, else the
    best point of the three edges). Returns (cost, c1, c2)."""
    best = np.inf
    b1 = 0.0
    b2 = 0.0
    det = suu * svv - suv * suv
    cands = np.zeros((6, 2))
    m = 0
    if det > 1e-12 * suu * svv:
        c1 = (sut * svv - svt * suv) / det
        c2 = (svt * suu - sut * suv) / det
        if c1 >= 0.0 and c2 >= 0.0 and c1 + c2 <= top:
            cands[m, 0] = c1
            cands[m, 1] = c2
            m += 1
    if suu > 0.0:  # edge c2 = 0
        cands[m, 0] = min(max(sut / suu, 0.0), top)
        m += 1
    if svv > 0.0:  # edge c1 = 0
        cands[m, 1] = min(max(svt / svv, 0.0), top)
        m += 1
    # edge c1 + c2 = top: c1 = top - c2
    curv = suu - 2.0 * suv + svv
    if curv > 0.0:
        c2 = ((svt - sut) - top * (suv - suu)) / curv
        c2 = min(max(c2, 0.0), top)
        cands[m, 0] = top - c2
        cands[m, 1] = c2
        m += 1
    cands[m, 0] = top  # corners
    m += 1
    cands[m, 1] = top
    m += 1
    for k in range(m):
        c1 = cands[k, 0]
        c2 = cands[k, 1]
        cost = stt - 2.0 * (c1 * sut + c2 * svt) + c1 * c1 * suu + 2.0 * c1 * c2 * suv \
            + c2 * c2 * svv
        if cost < best:
            best = cost
            b1 = c1
            b2 = c2
    return best, b1, b2


@njit(cache=True, nogil=True)
def _grid_search(xb, yb, sw, s0_grid, b_grid, top):  # pragma: no cover - compiled
    """For each (s0, B) of the grid the linear parameters c1 = mu_s A and c2 = mu_s (1 - A) are
    solved exactly (variable projection, Golub and Pereyra 1973): half the cost and (mu_s, A)
    at every grid point, shape (len(s0_grid), len(b_grid), 3)."""
    m = xb.size
    ns = s0_grid.size
    nb = b_grid.size
    rise = np.empty((ns, m))
    fall = np.empty((nb, m))
    for i in range(m):
        s = max(xb[i], 0.0)
        for a in range(ns):
            rise[a, i] = -np.expm1(-s / s0_grid[a]) * sw[i]
        for b in range(nb):
            fall[b, i] = np.exp(-b_grid[b] * s)
    t = yb * sw
    stt = 0.0
    for i in range(m):
        stt += t[i] * t[i]
    out = np.empty((ns, nb, 3))
    for a in range(ns):
        suu = 0.0
        sut = 0.0
        for i in range(m):
            u = rise[a, i]
            suu += u * u
            sut += u * t[i]
        for b in range(nb):
            suv = 0.0
            svv = 0.0
            svt = 0.0
            for i in range(m):
                u = rise[a, i]
                v = u * fall[b, i]
                suv += u * v
                svv += v * v
                svt += v * t[i]
            cost, c1, c2 = _linear_part(suu, suv, svv, sut, svt, stt, top)
            mu_s = c1 + c2
            out[a, b, 0] = 0.5 * cost
            out[a, b, 1] = mu_s
            out[a, b, 2] = c1 / mu_s if mu_s > 0 else 0.5
    return out


@njit(cache=True, nogil=True)
def _projected(xb, yb, sw, s0, b_rate, top):  # pragma: no cover - compiled
    """Half the cost of the best linear pair at (s0, B), and that pair as (mu_s, A)."""
    suu = 0.0
    suv = 0.0
    svv = 0.0
    sut = 0.0
    svt = 0.0
    stt = 0.0
    for i in range(xb.size):
        s = max(xb[i], 0.0)
        u = -np.expm1(-s / s0) * sw[i]
        v = u * np.exp(-b_rate * s)
        t = yb[i] * sw[i]
        suu += u * u
        suv += u * v
        svv += v * v
        sut += u * t
        svt += v * t
        stt += t * t
    cost, c1, c2 = _linear_part(suu, suv, svv, sut, svt, stt, top)
    mu_s = c1 + c2
    return 0.5 * cost, mu_s, (c1 / mu_s if mu_s > 0 else 0.5)


@njit(cache=True, nogil=True)
def _pattern_search(xb, yb, sw, s0, b_rate, lo, hi, step, top, h_min):  # pragma: no cover
    """Local minimum of the projected cost over (log s0, log B) from a start: a pattern
    search after Hooke and Jeeves (1961) (exploratory moves in 8 directions; a successful
    direction is followed with doubled steps, our form of their pattern move; the step is
    halved when no direction improves, down to ``h_min``). B is kept >= 1e-9 (B = 0 and
    B = 1e-9 give the same curve to 1e-8). Returns (cost, mu_s, s0, A, B)."""
    b_min = 1e-9
    u_lo, u_hi = np.log(lo[1]), np.log(hi[1])
    w_lo, w_hi = np.log(b_min), np.log(hi[3])
    u = min(max(np.log(s0), u_lo), u_hi)
    w = min(max(np.log(max(b_rate, b_min)), w_lo), w_hi)
    f, mu_s, a_r = _projected(xb, yb, sw, np.exp(u), np.exp(w), top)
    dirs = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0],
                     [0.7071, 0.7071], [-0.7071, -0.7071], [0.7071, -0.7071], [-0.7071, 0.7071]])
    h = step
    while h > h_min:
        moved = False
        for k in range(8):
            du = dirs[k, 0] * h
            dw = dirs[k, 1] * h
            u2 = min(max(u + du, u_lo), u_hi)
            w2 = min(max(w + dw, w_lo), w_hi)
            f2, m2, a2 = _projected(xb, yb, sw, np.exp(u2), np.exp(w2), top)
            if f2 < f:
                u, w, f, mu_s, a_r = u2, w2, f2, m2, a2
                moved = True
                while True:  # keep going that way, faster
                    du *= 2.0
                    dw *= 2.0
                    u2 = min(max(u + du, u_lo), u_hi)
                    w2 = min(max(w + dw, w_lo), w_hi)
                    f2, m2, a2 = _projected(xb, yb, sw, np.exp(u2), np.exp(w2), top)
                    if not f2 < f:
                        break
                    u, w, f, mu_s, a_r = u2, w2, f2, m2, a2
                break
        if not moved:
            h *= 0.5
    return np.array([f, mu_s, np.exp(u), a_r, np.exp(w)])


def _grid_best(xb, yb, sw, s0_grid, b_grid, top, count=1):
    """The ``count`` best local minima of the grid (each better than its 8 neighbours), as
    rows (cost, mu_s, s0, A, B), best first."""
    g = _grid_search(xb, yb, sw, s0_grid, b_grid, top)
    cost = g[:, :, 0]
    if count == 1:
        a, b = np.unravel_index(int(np.argmin(cost)), cost.shape)
        picks = [(a, b)]
    else:
        pad = np.pad(cost, 1, constant_values=np.inf)
        lower = np.ones(cost.shape, bool)
        for da in (-1, 0, 1):
            for db in (-1, 0, 1):
                if da or db:
                    lower &= cost <= pad[1 + da:1 + da + cost.shape[0],
                                         1 + db:1 + db + cost.shape[1]]
        idx = np.flatnonzero(lower.ravel())
        idx = idx[np.argsort(cost.ravel()[idx], kind="stable")][:count]
        picks = [np.unravel_index(int(k), cost.shape) for k in idx]
    return [np.array([g[a, b, 0], g[a, b, 1], s0_grid[a], g[a, b, 2], b_grid[b]])
            for a, b in picks]


def _global_start(xb, yb, sw, lo_b, hi_b, candidates: int = GLOBAL_CANDIDATES,
                  grid: int = GLOBAL_GRID, h_min: float = 1e-6):
    """Parameters (mu_s, s0, A, B) near the global minimum of the weighted least squares.

    For fixed s0 and B the law is linear in c1 = mu_s A and c2 = mu_s (1 - A) (c1, c2 >= 0,
    c1 + c2 <= mu_s's bound), so the search runs over (s0, B) only with the linear pair solved
    exactly (variable projection, Golub and Pereyra 1973): a ``grid`` x ``grid`` log grid
    over the whole box, then a compiled pattern search (Hooke and Jeeves 1961) from each of
    its ``candidates`` best local minima (down to steps of ``h_min`` in log s0 and log B); the
    best point found."""
    s0_grid = np.geomspace(lo_b[1], hi_b[1], grid)
    b_grid = np.r_[0.0, np.geomspace(1e-3, hi_b[3], grid - 1)]
    starts = _grid_best(xb, yb, sw, s0_grid, b_grid, hi_b[0], candidates)
    step = float(np.log(s0_grid[1] / s0_grid[0]))
    found = [_pattern_search(xb, yb, sw, row[2], row[4], lo_b, hi_b, step, hi_b[0], h_min)
             for row in starts]
    best = min(found, key=lambda row: row[0])
    return best[1:]


def _fit_one(stats, n_eff, slip_kind):
    """Weighted least squares of the law on slip bins; fine-bin sums (count, sum x, sum y,
    sum y^2) in, parameters, standard errors, R^2, RMSE and the 1-99 % slip range out."""
    cnt_f, sx_f, sy_f, syy_f = stats
    n = float(cnt_f.sum())
    # coarse bins for the fit
    cnt = cnt_f.reshape(-1, _GROUP).sum(axis=1)
    sx = sx_f.reshape(-1, _GROUP).sum(axis=1)
    sy = sy_f.reshape(-1, _GROUP).sum(axis=1)
    ok = cnt > 0
    xb = sx[ok] / cnt[ok]
    yb = sy[ok] / cnt[ok]
    sw = np.sqrt(cnt[ok])
    cum = np.cumsum(cnt_f) / n
    okf = cnt_f > 0
    xf = sx_f[okf] / cnt_f[okf]
    cf = cum[okf]
    lo_x = float(xf[np.searchsorted(cf, 0.01)])
    hi_x = float(xf[min(np.searchsorted(cf, 0.99), xf.size - 1)])
    s0_hi = 5.0 if slip_kind == "absolute" else 1.0
    b_hi = 50.0 if slip_kind == "absolute" else 500.0
    lo_b = np.array([1e-4, 1e-5, 0.0, 0.0])
    hi_b = np.array([2.0, s0_hi, 1.0, b_hi])

    def resid(p):
        return sw * (falling_adhesion(xb, *p) - yb)

    x0 = _global_start(np.ascontiguousarray(xb), np.ascontiguousarray(yb),
                       np.ascontiguousarray(sw), lo_b, hi_b)
    best = optimize.least_squares(resid, np.clip(x0, lo_b + 1e-12, hi_b - 1e-12),
                                  bounds=(lo_b, hi_b), x_scale="jac")
    p = best.x
    # goodness of fit on the fine bins: between-bin residuals + within-bin spread of mu
    yf = sy_f[okf] / cnt_f[okf]
    ssr = float(np.sum(cnt_f[okf] * (falling_adhesion(xf, *p) - yf) ** 2)
                + np.sum(syy_f[okf] - sy_f[okf] ** 2 / cnt_f[okf]))
    ybar = float(sy_f.sum() / n)
    sst = float(syy_f.sum() - n * ybar * ybar)
    dof = max(n - 4.0, 1.0)
    s2 = max(ssr, 0.0) / dof
    jac = best.jac
    try:
        cov = np.linalg.pinv(jac.T @ jac) * s2 * max(n / max(n_eff, 1.0), 1.0)
        err = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:  # pragma: no cover
        cov = np.full((4, 4), np.inf)
        err = np.full(4, np.inf)
    params = dict(zip(PARAM_NAMES, (float(v) for v in p), strict=True))
    stderr = dict(zip(PARAM_NAMES, (float(v) for v in err), strict=True))
    r2 = 1.0 - ssr / sst if sst > 0 else float("nan")
    flags = _gate(p, cov, params, stderr, r2, (lo_x, hi_x), xf, cnt_f[okf], n, n_eff, lo_b,
                  hi_b)  # fmt: skip
    return params, stderr, r2, math.sqrt(max(ssr, 0.0) / n), (lo_x, hi_x), flags


def _gate(p, cov, params, stderr, r2, slip_range, xf, cf, n, n_eff, lo_b, hi_b):
    """The quality gate of one fitted curve (module notes): its findings."""
    span = hi_b - lo_b
    limits = {"A": (0.0, 1.0), "B": (0.0,)}  # bounds that are limits of the law itself
    on_bound = [k for k, name in enumerate(PARAM_NAMES)
                if p[k] <= lo_b[k] + 1e-6 * span[k] or p[k] >= hi_b[k] - 1e-6 * span[k]]
    outside = tuple(PARAM_NAMES[k] for k in on_bound
                    if not any(abs(p[k] - lim) <= 1e-6 * span[k]
                               for lim in limits.get(PARAM_NAMES[k], ())))  # fmt: skip
    at_limit = tuple(PARAM_NAMES[k] for k in on_bound if PARAM_NAMES[k] not in outside)
    # the curve's own standard error over its slip range (delta method)
    xs = np.linspace(slip_range[0], slip_range[1], 41)
    step = 1e-7 * np.maximum(np.abs(p), 1e-3)
    grad = np.stack([(falling_adhesion(xs, *(p + step[k] * np.eye(4)[k]))
                      - falling_adhesion(xs, *(p - step[k] * np.eye(4)[k]))) / (2 * step[k])
                     for k in range(4)], axis=1)  # fmt: skip
    with np.errstate(invalid="ignore", over="ignore"):
        var = np.einsum("ij,jk,ik->i", grad, cov, grad)
    curve = falling_adhesion(xs, *p)
    peak_at = float(xs[int(np.argmax(curve))])
    independent = max(n_eff, 1.0) / max(n, 1.0)  # independent samples per sample
    below = int(np.sum(cf[xf < peak_at]) * independent)
    beyond = int(np.sum(cf[xf > peak_at]) * independent)
    fall = (1.0 - params["A"]) * -math.expm1(-params["B"] * slip_range[1])
    regions = {"s0": (below, "below the peak of the curve (independent samples)")}
    if fall >= 0.01:
        regions.update({k: (beyond, "beyond the peak of the curve (independent samples)")
                        for k in ("A", "B")})  # fmt: skip
    flags = list(fit_warnings(
        r_squared=float(r2), params=params, fitted=PARAM_NAMES, stderr=stderr,
        at_bound=outside, region_points=regions, min_r_squared=MIN_R_SQUARED_SCATTER,
        ignore_stderr=("A", "B", *at_limit),
    ))  # fmt: skip
    rel = float(np.sqrt(np.max(var)) / np.max(curve)) if np.max(curve) > 0 else math.inf
    if not rel <= MAX_CURVE_STDERR:  # NaN too
        flags.append(f"the curve's standard error reaches {rel:.2g} of its peak (above "
                     f"{MAX_CURVE_STDERR:g}): the samples do not determine it")  # fmt: skip
    return tuple(flags)


def fit_adhesion_curves(ident, *, slip: str = "absolute", speed_bands=None, phase: str = "all",
                        min_samples: int = 200, per_band: bool = True,
                        warn_untrusted: bool = True):  # fmt: skip
    """Fit mu(slip) per speed band (and over all speeds) to an identification's samples.

    Parameters
    ----------
    ident : BrakingIdentification
        From :func:`~railadhesion.identification.brake_tests.identify_adhesion` (its ``speed``,
        ``slip`` or ``relative_slip``, ``mu``, ``use`` and ``phase`` arrays).
    slip : {"absolute", "relative"}
        Fit against the absolute slip [m/s] or the relative slip [-].
    speed_bands : sequence of float, optional
        Band edges [m/s]; default 0, 10, 20, 30, 40 (bands without ``min_samples`` samples
        are skipped).
    phase : {"all", "loss", "recovery"}
        Samples used (windows of growing or falling slip, or all).
    min_samples : int, default 200
        Smallest number of samples a band needs.
    per_band : bool, default True
        Fit each speed band; ``False``: only the curve over all speeds (``bands`` empty).
    warn_untrusted : bool, default True
        Issue an :class:`~railadhesion.plausibility.UntrustedResultWarning` when the quality
        gate flags a curve (the findings are in ``law.warnings`` either way).

    Returns
    -------
    AdhesionLaw
        ``bands`` (one :class:`CurveFit` per band with data) and ``overall`` (all speeds);
        ``trusted`` and ``warnings`` from the quality gate of every curve (module notes).

    Raises
    ------
    ValueError
        Fewer than ``min_samples`` usable samples in the whole log.
    """
    check_choice(slip, "slip", ("absolute", "relative"))
    check_choice(phase, "phase", ("all", "loss", "recovery"))
    edges, all_stats, all_rows, all_vsum = band_statistics(ident, slip, speed_bands)
    q = {"all": 0, "loss": 1, "recovery": 2}[phase]
    stats, rows, vsum = all_stats[q], all_rows[q], all_vsum[q]
    total = int(stats[-1, 0].sum())
    if total < min_samples:
        raise ValueError(
            f"only {total} usable samples with slip >= 0 (phase {phase!r}) within the speed "
            f"bands; at least {min_samples} are needed to fit a curve"
        )
    cache = getattr(ident, "_cache", None)
    if cache is not None and "period" in cache:
        dt = cache["period"]
    else:
        dt = float(np.median(np.diff(ident.time))) if ident.time.size > 1 else 1.0
        if cache is not None:
            cache["period"] = dt
    fc = float(ident.settings.get("wheel_cutoff_Hz", 2.0))
    corr = max(1.0 / (2.0 * fc) / dt, 1.0)  # samples per correlation time

    def fit(st, band, vmean):
        nb = int(st[0].sum())
        params, stderr, r2, rmse, rng, flags = _fit_one(st, nb / corr, slip)
        return CurveFit(
            speed_band=band, slip_kind=slip, params=params, stderr=stderr, slip_range=rng,
            n_samples=nb, r_squared=r2, rmse=rmse, speed_mean=vmean, warnings=flags,
        )

    def mean_speed(b):
        return float(vsum[b] / rows[b]) if rows[b] > 0 else float("nan")

    bands = []
    if per_band:
        for b, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
            if stats[b, 0].sum() >= min_samples:
                bands.append(fit(stats[b], (float(lo), float(hi)), mean_speed(b)))
    overall = fit(stats[-1], (float(edges[0]), float(edges[-1])), mean_speed(-1))
    law = AdhesionLaw(
        slip_kind=slip, bands=tuple(bands), overall=overall, phase=phase,
        provenance={
            "source": "identified from a braking-test log (railadhesion.identification)",
            "log": str(ident.settings.get("log", "")),
            "vehicle": str(ident.settings.get("vehicle", "")),
            "brake_coefficient_N_m_per_Pa": float(ident.brake_coefficient),
            "filter_mode": str(ident.settings.get("filter_mode", "")),
            "phase": phase,
        },
    )
    if warn_untrusted and law.warnings:
        warn(f"identified adhesion law ({slip} slip, phase {phase}) not trusted: "
             + "; ".join(law.warnings), UntrustedResultWarning)  # fmt: skip
    return law
