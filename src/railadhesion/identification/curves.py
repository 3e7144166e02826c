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

Uncertainty [our approximation]: the standard errors are the linearised ones
(``s^2 (J^T W J)^-1``) with the residual variance of the samples, inflated by
``sqrt(n / n_eff)`` where ``n_eff`` counts one independent sample per correlation time of the
filtered signals (``1/(2 f_c)``, f_c the wheel cut-off) and per axle: filtered samples 2.4 ms
apart are not independent.

A fit is saved as a TOML parameter file (``format = "railadhesion-adhesion-law"``,
``version = 1``, docs/identification.md) and loaded by :func:`load_adhesion_law` as an
:class:`AdhesionLaw`: a callable ``law(creep, speed)`` that the braking simulator can take as
its adhesion model (mu interpolated linearly in speed between band centres).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit
from scipy import optimize

from railadhesion._validate import check_choice

__all__ = [
    "LAW_FORMAT",
    "CurveFit",
    "AdhesionLaw",
    "falling_adhesion",
    "fit_adhesion_curves",
    "load_adhesion_law",
]

LAW_FORMAT = "railadhesion-adhesion-law"
LAW_VERSION = 1
PARAM_NAMES = ("mu_s", "s0", "A", "B")


def falling_adhesion(s, mu_s, s0, A, B):  # noqa: N803 - the law's own symbols
    """mu(s) = mu_s (1 - exp(-s/s0)) (A + (1 - A) exp(-B s)) for slip s >= 0 (0 below).

    Examples
    --------
    >>> round(float(falling_adhesion(100.0, 0.2, 0.1, 0.5, 1.0)), 6)
    0.1
    """
    s = np.maximum(np.asarray(s, dtype=float), 0.0)
    return mu_s * -np.expm1(-s / s0) * (A + (1.0 - A) * np.exp(-B * s))


@dataclass(frozen=True)
class CurveFit:
    """One fitted curve mu(slip) for one speed band.

    Attributes
    ----------
    speed_band : tuple of float
        Speeds [m/s] of the samples fitted, ``[low, high)``.
    slip_kind : str
        ``"absolute"`` (slip in m/s) or ``"relative"`` (-).
    params : dict
        ``mu_s``, ``s0``, ``A``, ``B``.
    stderr : dict
        Standard errors (see the module notes).
    slip_range : tuple of float
        1st and 99th percentiles of the slip of the samples: the range the fit is supported by.
    n_samples : int
        Samples fitted.
    r_squared, rmse : float
        Goodness of fit on the samples.
    speed_mean : float
        Mean speed of the samples [m/s].
    """

    speed_band: tuple[float, float]
    slip_kind: str
    params: dict
    stderr: dict
    slip_range: tuple[float, float]
    n_samples: int
    r_squared: float
    rmse: float
    speed_mean: float

    def __call__(self, slip):
        """mu at the given slip (the band's curve)."""
        return falling_adhesion(slip, **self.params)


#: Fine slip bins per curve (statistics); the fit itself uses groups of 10 of them.
_FINE = 2000
_GROUP = 10


@njit(cache=True)
def _band_stats(speed, x, mu, mask, edges):  # pragma: no cover - compiled
    """Per speed band (last row: all bands together) and fine slip bin of width max/_FINE:
    count, sum of slip, sum of mu, sum of mu^2; and the largest slip per band."""
    n, na = mu.shape
    nb = edges.size - 1
    top = np.zeros(nb + 1)
    for k in range(n):
        v = speed[k]
        if not (v >= edges[0] and v < edges[nb]):
            continue
        b = np.searchsorted(edges, v, side="right") - 1
        for a in range(na):
            if mask[k, a]:
                xv = x[k, a]
                if xv > top[b]:
                    top[b] = xv
                if xv > top[nb]:
                    top[nb] = xv
    width = np.empty(nb + 1)
    for b in range(nb + 1):
        width[b] = (top[b] if top[b] > 0 else 1.0) * (1.0 + 1e-9) / _FINE
    stats = np.zeros((nb + 1, 4, _FINE))
    for k in range(n):
        v = speed[k]
        if not (v >= edges[0] and v < edges[nb]):
            continue
        b = np.searchsorted(edges, v, side="right") - 1
        for a in range(na):
            if not mask[k, a]:
                continue
            xv = x[k, a]
            y = mu[k, a]
            for bb in (b, nb):
                j = min(int(xv / width[bb]), _FINE - 1)
                stats[bb, 0, j] += 1.0
                stats[bb, 1, j] += xv
                stats[bb, 2, j] += y
                stats[bb, 3, j] += y * y
    return stats


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
    med = float(xf[min(np.searchsorted(cf, 0.5), xf.size - 1)])
    hi_x = float(xf[min(np.searchsorted(cf, 0.99), xf.size - 1)])
    peak_i = int(np.argmax(yb))
    peak = float(yb[peak_i])
    s0_hi = 5.0 if slip_kind == "absolute" else 1.0
    b_hi = 50.0 if slip_kind == "absolute" else 500.0
    lo_b = np.array([1e-4, 1e-5, 0.0, 0.0])
    hi_b = np.array([2.0, s0_hi, 1.0, b_hi])

    def resid(p):
        return sw * (falling_adhesion(xb, *p) - yb)

    best = None
    s_peak = max(float(xb[peak_i]), 1e-4)
    for s0 in (0.2 * s_peak, 0.05 * s_peak, 0.5 * s_peak):
        for a_r, b in ((0.5, 1.0 / max(med, 1e-4)), (0.8, 0.3 / max(med, 1e-4)),
                       (0.2, 3.0 / max(med, 1e-4))):
            p0 = np.clip([1.2 * peak, s0, a_r, b], lo_b + 1e-9, hi_b - 1e-9)
            try:
                res = optimize.least_squares(resid, p0, bounds=(lo_b, hi_b), x_scale="jac")
            except ValueError:
                continue
            if best is None or res.cost < best.cost:
                best = res
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
        err = np.full(4, np.inf)
    params = dict(zip(PARAM_NAMES, (float(v) for v in p), strict=True))
    stderr = dict(zip(PARAM_NAMES, (float(v) for v in err), strict=True))
    r2 = 1.0 - ssr / sst if sst > 0 else float("nan")
    return params, stderr, r2, math.sqrt(max(ssr, 0.0) / n), (lo_x, hi_x)


def fit_adhesion_curves(ident, *, slip: str = "absolute", speed_bands=None, phase: str = "all",
                        min_samples: int = 200):
    """Fit mu(slip) per speed band (and over all speeds) to an identification's samples.

    Parameters
    ----------
    ident : BrakingIdentification
        From :func:`~railadhesion.identification.braking.identify_adhesion` (its ``speed``,
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

    Returns
    -------
    AdhesionLaw
        ``bands`` (one :class:`CurveFit` per band with data) and ``overall`` (all speeds).

    Raises
    ------
    ValueError
        Fewer than ``min_samples`` usable samples in the whole log.
    """
    check_choice(slip, "slip", ("absolute", "relative"))
    check_choice(phase, "phase", ("all", "loss", "recovery"))
    edges = np.asarray([0.0, 10.0, 20.0, 30.0, 40.0] if speed_bands is None else speed_bands,
                       dtype=float)
    if edges.size < 2 or np.any(np.diff(edges) <= 0):
        raise ValueError("speed_bands must be at least 2 strictly increasing speeds [m/s]")
    x = np.ascontiguousarray(ident.slip if slip == "absolute" else ident.relative_slip,
                             dtype=float)
    mu = np.ascontiguousarray(ident.mu, dtype=float)
    mask = ident.use & np.isfinite(x) & np.isfinite(mu) & (x >= 0)
    if phase == "loss":
        mask &= ident.phase == 1
    elif phase == "recovery":
        mask &= ident.phase == -1
    speed = np.ascontiguousarray(ident.speed, dtype=float)
    stats = _band_stats(speed, x, mu, np.ascontiguousarray(mask), edges)
    total = int(stats[-1, 0].sum())
    if total < min_samples:
        raise ValueError(
            f"only {total} usable samples with slip >= 0 (phase {phase!r}) within the speed "
            f"bands; at least {min_samples} are needed to fit a curve"
        )
    dt = float(np.median(np.diff(ident.time))) if ident.time.size > 1 else 1.0
    fc = float(ident.settings.get("wheel_cutoff_Hz", 2.0))
    corr = max(1.0 / (2.0 * fc) / dt, 1.0)  # samples per correlation time
    rows = np.flatnonzero(mask.any(axis=1))
    vm_all = float(speed[rows].mean()) if rows.size else float("nan")

    def fit(st, band, vmean):
        nb = int(st[0].sum())
        params, stderr, r2, rmse, rng = _fit_one(st, nb / corr, slip)
        return CurveFit(
            speed_band=band, slip_kind=slip, params=params, stderr=stderr, slip_range=rng,
            n_samples=nb, r_squared=r2, rmse=rmse, speed_mean=vmean,
        )

    bands = []
    for b, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        if stats[b, 0].sum() >= min_samples:
            sel = rows[(speed[rows] >= lo) & (speed[rows] < hi)]
            vmean = float(speed[sel].mean()) if sel.size else float("nan")
            bands.append(fit(stats[b], (float(lo), float(hi)), vmean))
    overall = fit(stats[-1], (float(edges[0]), float(edges[-1])), vm_all)
    return AdhesionLaw(
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


@dataclass(frozen=True)
class AdhesionLaw:
    """An identified adhesion law mu(slip, speed): curves per speed band.

    Call it as ``law(creep, speed)`` with the creepage xi = (v - R omega)/v [-] (braking
    positive; its magnitude is used) and the speed v [m/s]: it returns mu >= 0, broadcasting.
    Between band centres mu is interpolated linearly in speed; outside, the nearest band's
    curve is used; with no band, the overall curve.

    Attributes
    ----------
    slip_kind : str
        ``"absolute"``: the curves are functions of the slip velocity |xi| v [m/s];
        ``"relative"``: of |xi| [-].
    bands : tuple of CurveFit
        One curve per speed band, in increasing speed.
    overall : CurveFit
        The curve fitted to all speeds together.
    phase : str
        Samples the curves were fitted to.
    provenance : dict
        Where the law comes from.
    """

    slip_kind: str
    bands: tuple
    overall: CurveFit
    phase: str = "all"
    provenance: dict = field(default_factory=dict, compare=False)

    def of_slip(self, slip, speed):
        """mu at the slip (in this law's kind: m/s or -) and speed [m/s]."""
        s = np.abs(np.asarray(slip, dtype=float))
        v = np.asarray(speed, dtype=float)
        if len(self.bands) < 2:
            curve = self.bands[0] if self.bands else self.overall
            return curve(s) * np.ones(np.broadcast_shapes(s.shape, v.shape))
        centres = np.array([0.5 * (b.speed_band[0] + b.speed_band[1]) for b in self.bands])
        vals = np.stack([b(s) * np.ones(np.broadcast_shapes(s.shape, v.shape))
                         for b in self.bands])
        vb = np.broadcast_to(v, vals.shape[1:])
        k = np.clip(np.searchsorted(centres, vb) - 1, 0, centres.size - 2)
        w = np.clip((vb - centres[k]) / (centres[k + 1] - centres[k]), 0.0, 1.0)
        lo = np.take_along_axis(vals, k[None], 0)[0]
        hi = np.take_along_axis(vals, (k + 1)[None], 0)[0]
        return lo * (1.0 - w) + hi * w

    def __call__(self, creep, speed):
        """mu at creepage xi [-] (magnitude used) and speed v [m/s]."""
        xi = np.abs(np.asarray(creep, dtype=float))
        v = np.asarray(speed, dtype=float)
        slip = xi * np.abs(v) if self.slip_kind == "absolute" else xi
        return self.of_slip(slip, v)

    def to_frame(self):
        """One row per curve (bands, then ``overall``): band, parameters, errors, fit quality."""
        import pandas as pd

        rows = []
        for label, c in [*((f"{b.speed_band[0]:g}-{b.speed_band[1]:g} m/s", b)
                           for b in self.bands), ("all speeds", self.overall)]:
            row = {"band": label, "n_samples": c.n_samples, "speed_mean": c.speed_mean}
            row.update(c.params)
            row.update({f"{k}_stderr": v for k, v in c.stderr.items()})
            row.update({"slip_min": c.slip_range[0], "slip_max": c.slip_range[1],
                        "r_squared": c.r_squared, "rmse": c.rmse})
            rows.append(row)
        return pd.DataFrame(rows)

    def save(self, path) -> Path:
        """Write the law as a ``railadhesion-adhesion-law`` TOML file."""
        import tomli_w

        def curve(c):
            return {
                "speed_min_m_s": c.speed_band[0], "speed_max_m_s": c.speed_band[1],
                "speed_mean_m_s": c.speed_mean,
                **{k: v for k, v in c.params.items()},
                **{f"{k}_stderr": v for k, v in c.stderr.items()},
                "slip_min": c.slip_range[0], "slip_max": c.slip_range[1],
                "n_samples": c.n_samples, "r_squared": c.r_squared, "rmse": c.rmse,
            }

        doc = {
            "format": LAW_FORMAT, "version": LAW_VERSION,
            "provenance": {k: v for k, v in self.provenance.items() if v is not None},
            "law": {
                "form": "mu_s * (1 - exp(-s/s0)) * (A + (1 - A) * exp(-B*s))",
                "slip": self.slip_kind,
                "slip_unit": "m/s" if self.slip_kind == "absolute" else "1",
                "phase": self.phase,
                "overall": curve(self.overall),
                "band": [curve(b) for b in self.bands],
            },
        }
        p = Path(path)
        p.write_text(tomli_w.dumps(doc), encoding="utf-8")
        return p


def _curve_from(tab, kind, where):
    try:
        params = {k: float(tab[k]) for k in PARAM_NAMES}
    except KeyError as exc:
        raise ValueError(f"{where}: missing {exc.args[0]!r}") from None
    except (TypeError, ValueError):
        raise ValueError(f"{where}: parameters must be numbers") from None
    checks = {"mu_s": (0, 2), "s0": (0, math.inf), "A": (0, 1), "B": (0, math.inf)}
    for k, (lo, hi) in checks.items():
        x = params[k]
        ok = math.isfinite(x) and lo <= x <= hi and (k not in ("mu_s", "s0") or x > 0)
        if not ok:
            raise ValueError(f"{where}.{k} must be in [{lo}, {hi}] (s0, mu_s > 0), got {x!r}")
    get = lambda k, d=math.nan: float(tab.get(k, d))  # noqa: E731
    return CurveFit(
        speed_band=(get("speed_min_m_s", 0.0), get("speed_max_m_s", math.inf)),
        slip_kind=kind, params=params,
        stderr={k: get(f"{k}_stderr") for k in PARAM_NAMES},
        slip_range=(get("slip_min"), get("slip_max")), n_samples=int(tab.get("n_samples", 0)),
        r_squared=get("r_squared"), rmse=get("rmse"),
        speed_mean=get("speed_mean_m_s"),
    )


def load_adhesion_law(path) -> AdhesionLaw:
    """Read a ``railadhesion-adhesion-law`` TOML file written by :meth:`AdhesionLaw.save`.

    Returns an :class:`AdhesionLaw`, callable as ``law(creep, speed)``. Raises ``ValueError``
    naming the file and the field for a malformed file.
    """
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ValueError(f"{p}: cannot read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{p}: not valid TOML: {exc}") from None
    if doc.get("format") != LAW_FORMAT:
        raise ValueError(f"{p}: format must be {LAW_FORMAT!r}, got {doc.get('format')!r}")
    if doc.get("version") != LAW_VERSION:
        raise ValueError(f"{p}: version must be {LAW_VERSION}, got {doc.get('version')!r}")
    law = doc.get("law")
    if not isinstance(law, dict) or "overall" not in law:
        raise ValueError(f"{p}: missing [law] table with [law.overall]")
    kind = law.get("slip")
    if kind not in ("absolute", "relative"):
        raise ValueError(f"{p}: law.slip must be 'absolute' or 'relative', got {kind!r}")
    overall = _curve_from(law["overall"], kind, f"{p}: law.overall")
    bands = tuple(_curve_from(b, kind, f"{p}: law.band[{i}]")
                  for i, b in enumerate(law.get("band", [])))
    return AdhesionLaw(slip_kind=kind, bands=bands, overall=overall,
                       phase=str(law.get("phase", "all")),
                       provenance=dict(doc.get("provenance", {})))
