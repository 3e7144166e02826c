"""Low-adhesion detection from creep-force data measured at low creep (Fletcher 2013's purpose).

Fletcher (2013, §1 and §5) built his 2D model so that the adhesion measured at small creep,
before a brake application, can be mapped to the friction coefficient available at full slip.
:func:`detect_low_adhesion` fits his model (k_a and mu, k_s = 1) to such data and returns the
estimate of mu with an uncertainty and a warning level against a threshold (0.14 by default:
the adhesion needed to sustain normal braking according to the RSSB guidance GM/GN2642 that
Fletcher cites, his ref. 2). Polach's model (k_A, k_S, mu0 with A = 1, B = 0) is the documented
alternative.

How much creep is needed
------------------------
In Fletcher's model (eqs. (8)-(12)) the adhesion is ``Q/P = mu (1 - (1 - x/mu)**3)`` with
``x = 2 k_a R xi / (3 a)`` up to full slip at ``x = mu``; expanded,
``Q/P = 3x - 3x**2/mu + x**3/mu**2``. Below full slip, mu shows only through the curvature of
the curve: the initial slope gives k_a, the bending gives mu. Data that stop well before the
creep of full slip, ``xi_sat = 3 a mu / (2 k_a R)``, therefore bound mu from below (the
adhesion never exceeds mu) but often not from above. The uncertainty is reported as a
profile-likelihood interval, whose upper end is ``inf`` when the data are consistent with an
arbitrarily large mu: then no warning can be given either way and the level says so.

When the fit itself cannot be trusted (the quality gate of ``docs/checks.md``: R^2 below 0.3
(:data:`railadhesion.plausibility.MIN_R_SQUARED_SCATTER`: at low creep the adhesion spans
little more than the measurement noise, CG1 to 0.2 % creep with noise 0.002 gives 0.83),
k_a not determined, fewer than 3 points below the creep of full slip, e.g. data that run to
20-60 % creep, far beyond it), the level is ``unknown``, never ``normal`` or ``low``, and
:attr:`DetectionResult.warnings` says why.
:func:`fletcher_detection_study` runs this on Fletcher's ten conditions (the table of
``docs/validation.md``, "Low-adhesion detection").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from railadhesion._validate import check_choice, check_positive, check_range
from railadhesion.plausibility import (
    MIN_R_SQUARED_SCATTER,
    UntrustedResultWarning,
    fit_warnings,
    warn,
)

__all__ = [
    "RSSB_BRAKING_ADHESION",
    "DetectionResult",
    "detect_low_adhesion",
    "fletcher_detection_study",
]

#: Adhesion needed to sustain normal braking [-]: RSSB GM/GN2642 (2008), as cited by
#: Fletcher (2013), §1.
RSSB_BRAKING_ADHESION = 0.14

#: Confidence level of the reported interval.
_LEVEL = 0.95
#: Largest friction coefficient considered by the profile [-].
_MU_MAX = 1.5


@dataclass(frozen=True)
class DetectionResult:
    """Estimate of the friction coefficient available at full slip, from low-creep data.

    Attributes
    ----------
    mu : float
        Best estimate of the friction coefficient at full slip [-].
    stderr : float
        Linearised standard error of ``mu`` [-] (``inf`` if not identifiable).
    interval : tuple of float
        95 % confidence interval of ``mu`` (Fletcher: profile likelihood, ``inf`` upper end
        when the data do not bound mu from above; Polach: ``mu +/- 1.96 stderr``).
    level : str
        ``"low"`` (the whole interval is below ``threshold``), ``"normal"`` (the whole interval
        is at or above it), ``"caution"`` (the interval straddles it: the data cannot tell) or
        ``"unknown"`` (the fit cannot be trusted, see :attr:`warnings`: no level is given).
    threshold : float
        Warning threshold [-] (default 0.14, RSSB GM/GN2642).
    model : str
        ``"fletcher"`` or ``"polach"``.
    max_creep : float
        Largest |creep| in the data [-].
    saturation_creep : float
        Creep at which the fitted model reaches full slip [-] (Fletcher: ``3 a mu/(2 k_a R)``;
        ``inf`` for Polach, whose curve saturates only asymptotically).
    params : dict
        All fitted and fixed parameters of the model.
    r_squared, rmse : float
        Goodness of fit of the adhesion [-].
    n_points : int
        Number of data points used.
    fit : FitResult
        The underlying fit (:mod:`railadhesion.calibration.fitting`).
    warnings : tuple of str
        Why the estimate cannot be trusted (then ``level == "unknown"``); empty otherwise.
    trusted : bool
        ``not warnings``.
    """

    mu: float
    stderr: float
    interval: tuple[float, float]
    level: str
    threshold: float
    model: str
    max_creep: float
    saturation_creep: float
    params: dict
    r_squared: float
    rmse: float
    n_points: int
    fit: object = field(repr=False, compare=False, default=None)
    warnings: tuple[str, ...] = ()

    @property
    def trusted(self) -> bool:
        """True when the fit passed the quality gate (:attr:`warnings` is empty)."""
        return not self.warnings

    @property
    def reached_full_slip(self) -> bool:
        """True if the data extend to the creep of full slip of the fitted model."""
        return self.max_creep >= self.saturation_creep

    def summary(self) -> str:
        """Readable multi-line report."""
        lo, hi = self.interval
        hi_txt = "inf (not bounded by the data)" if not math.isfinite(hi) else f"{hi:.4f}"
        sat = (
            f"{self.saturation_creep * 100:.3g} %"
            if math.isfinite(self.saturation_creep) else "asymptotic"
        )
        lines = [
            f"Low-adhesion detection ({self.model} model, {self.n_points} points up to "
            f"{self.max_creep * 100:.3g} % creep)",
            f"  friction at full slip mu = {self.mu:.4f} +/- {self.stderr:.2g} (1 s.e.)",
            f"  95 % interval: [{lo:.4f}, {hi_txt}]",
            f"  full slip of the fitted curve at {sat} creep"
            + ("" if self.reached_full_slip else " (beyond the data)"),
            f"  fit: R^2 = {self.r_squared:.4f}, RMSE = {self.rmse:.3g}",
            f"  warning level: {self.level.upper()} (threshold {self.threshold:g})",
        ]
        if self.warnings:
            lines.append("  no level: the fit cannot be trusted, so it cannot bound mu:")
            lines.extend(f"    ! {w}" for w in self.warnings)
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()


def _fletcher_curve(xi, k_a, mu, g):
    """Fletcher's Q/P with k_s = 1 (eqs. (8)-(12) in closed form), xi >= 0, g = 2R/(3a)."""
    x = g * k_a * xi
    u = np.maximum(1.0 - x / mu, 0.0)
    return mu * (1.0 - u * u * u)


def _level(lo: float, hi: float, threshold: float) -> str:
    if hi < threshold:
        return "low"
    if lo >= threshold:
        return "normal"
    return "caution"


def _profile_interval(xi, y, g, mu_hat, ka_hat, ssr_min, dof):
    """95 % profile-likelihood interval of mu (k_a re-fitted at each mu).

    The interval holds the mu whose best SSR stays within ``s2 * chi2_1(0.95)`` of the
    minimum, ``s2 = ssr_min / dof``. The limit mu -> inf is the straight line ``3 x``.
    """
    # floor: exact (noise-free) data still get a finite, tiny interval
    s2 = max(ssr_min / dof, (1e-6 * float(np.max(y))) ** 2, 1e-300)
    from scipy import stats  # imported when needed (scipy.stats is slow to import)

    limit = ssr_min + s2 * stats.chi2.ppf(_LEVEL, 1)

    def profile(mu):
        def cost(log_ka):
            r = _fletcher_curve(xi, math.exp(log_ka), mu, g) - y
            return float(r @ r)

        centre = math.log(ka_hat)
        res = optimize.minimize_scalar(
            cost, bounds=(centre - 6.0, centre + 6.0), method="bounded",
            options={"xatol": 1e-7},
        )
        return res.fun

    # the straight-line limit (mu -> inf): y = 3 g k_a xi, least squares through the origin
    xs = 3.0 * g * xi
    slope = float(xs @ y) / float(xs @ xs)
    r_inf = slope * xs - y
    ssr_inf = float(r_inf @ r_inf)

    def crossing(a, b):
        fa = profile(a) - limit
        fb = profile(b) - limit
        if fa * fb > 0:
            return None
        return optimize.brentq(lambda m: profile(m) - limit, a, b, xtol=1e-6 * mu_hat)

    lo_end = 1e-4
    lo = crossing(lo_end, mu_hat) if mu_hat > lo_end else lo_end
    lo = lo_end if lo is None else lo
    if ssr_inf <= limit or profile(_MU_MAX) <= limit:
        hi = math.inf
    else:
        hi = crossing(mu_hat, _MU_MAX)
        hi = math.inf if hi is None else hi
    return float(lo), float(hi)


def detect_low_adhesion(
    creep,
    adhesion,
    *,
    model: str = "fletcher",
    half_width: float = 0.204e-3,
    radius: float = 11.75e-3,
    threshold: float = RSSB_BRAKING_ADHESION,
    normal_force: float | None = None,
    speed: float | None = None,
    a: float | None = None,
    b: float | None = None,
    warn_untrusted: bool = True,
) -> DetectionResult:
    """Estimate the friction coefficient at full slip from adhesion measured at low creep.

    Parameters
    ----------
    creep : array_like
        Creep ratio xi [-] of each point (a fraction, signed or not; magnitudes are used).
        Typically below 1 % (before full slip).
    adhesion : array_like
        Measured adhesion coefficient |Q|/P [-], >= 0, one per point.
    model : {"fletcher", "polach"}
        ``"fletcher"`` (default): Fletcher (2013) eqs. (8)-(12), k_a and mu fitted, k_s = 1 (as
        in all his fits). ``"polach"``: Polach (2005) with k_A, k_S, mu0 fitted and A = 1,
        B = 0 (a falling friction is not visible at low creep); needs ``normal_force``,
        ``speed``, ``a``, ``b``.
    half_width : float, default 0.204e-3
        Contact half-width a [m] for Fletcher's model (default: his twin discs at 1000 MPa).
    radius : float, default 11.75e-3
        Reduced radius R [m] for Fletcher's model (default: his 47 mm discs).
    threshold : float, default 0.14
        Warning threshold on mu [-] (RSSB GM/GN2642, cited by Fletcher 2013 §1).
    normal_force, speed, a, b : float, optional
        Polach's contact: normal force Q [N], rolling speed [m/s], semi-axes [m].
    warn_untrusted : bool, default True
        Issue an :class:`~railadhesion.plausibility.UntrustedResultWarning` when the fit cannot
        be trusted (the level is then ``"unknown"`` either way).

    Returns
    -------
    DetectionResult
        ``mu``, its standard error and 95 % interval, the warning ``level``, the creep of full
        slip of the fitted curve and the goodness of fit.

    Raises
    ------
    ValueError
        Bad arguments (named), fewer than 4 points, or a model not in the list.

    Notes
    -----
    Fletcher: the interval is a profile-likelihood interval (k_a re-fitted at each mu, the
    limit ``SSR_min (1 + chi2_1(0.95)/(n - 2))``), honest when mu is bounded only from below;
    ``stderr`` is the linearised one of :func:`~railadhesion.calibration.fitting.fit_fletcher`.
    Polach: linearised interval ``mu0 +/- 1.96 stderr`` (may be optimistic, see the module
    notes).

    Examples
    --------
    Oil-lubricated test O1 (mu = 0.055) measured up to 1 % creep, exact data:

    >>> import numpy as np
    >>> from railadhesion.models.twod import fletcher_condition
    >>> o1 = fletcher_condition("O1")
    >>> xi = np.linspace(2e-4, 0.01, 50)
    >>> res = detect_low_adhesion(xi, o1.adhesion(xi))
    >>> round(res.mu, 4), res.level
    (0.055, 'low')
    """
    from railadhesion.calibration.fitting import fit_fletcher, fit_polach

    check_choice(model, "model", ("fletcher", "polach"))
    thr = float(check_range(threshold, "threshold", 0.0, 2.0, closed="right"))
    s = np.abs(np.asarray(creep, dtype=float).reshape(-1))
    y = np.asarray(adhesion, dtype=float).reshape(-1)
    if s.shape != y.shape:
        raise ValueError(
            f"creep and adhesion must have the same length, got {s.size} and {y.size}"
        )
    if s.size < 4:
        raise ValueError(f"creep must hold at least 4 points, got {s.size}")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(y))):
        raise ValueError("creep and adhesion must be finite (no NaN or inf)")
    if np.any(y < 0):
        raise ValueError("adhesion must be in [0, inf) (the magnitude |Q|/P)")
    max_creep = float(np.max(s))
    if model == "fletcher":
        a_ = float(check_positive(half_width, "half_width"))
        r_ = float(check_positive(radius, "radius"))
        g = 2.0 * r_ / (3.0 * a_)
        peak = float(np.max(y))
        fits = []
        for mu0 in {max(1.05 * peak, 1e-3), max(2.0 * peak, 1e-3), 0.5}:
            try:
                fits.append(fit_fletcher(
                    s, y, half_width=a_, radius=r_, fit=("k_a", "mu"), mu=mu0,
                    initial={"k_s": 1.0}, bounds={"mu": (1e-4, _MU_MAX)}, warn_untrusted=False,
                ))
            except ValueError:
                continue
        if not fits:
            raise ValueError("Fletcher's model could not be fitted to these data")
        fit = min(fits, key=lambda f: float(f.residuals @ f.residuals))
        mu_hat = fit.params["mu"]
        ka_hat = fit.params["k_a"]
        ssr = float(fit.residuals @ fit.residuals)
        lo, hi = _profile_interval(s, y, g, mu_hat, ka_hat, ssr, max(s.size - 2, 1))
        lo = min(lo, mu_hat)
        hi = max(hi, mu_hat)
        sat = mu_hat / (g * ka_hat)
        stderr = float(fit.stderr.get("mu", math.inf))
        # the gate on what the profile interval rests on: the model describes the data and
        # they determine the initial slope k_a (mu itself is bounded by the profile interval,
        # honestly unbounded above when the data do not bend)
        below = int(np.count_nonzero((s > 0) & (s < sat)))
        flags = fit_warnings(
            r_squared=float(fit.r_squared), params=fit.params, fitted=("k_a",),
            stderr=fit.stderr, success=fit.success, min_r_squared=MIN_R_SQUARED_SCATTER,
            at_bound=tuple(n for n in fit.at_bound if n == "k_a"),
            region_points={"k_a": (below, f"below the creep of full slip ({sat * 100:.3g} %)")},
        )  # fmt: skip
    else:
        missing = [n for n, v in (("normal_force", normal_force), ("speed", speed), ("a", a),
                                  ("b", b)) if v is None]  # fmt: skip
        if missing:
            raise ValueError(f"model='polach' needs {', '.join(missing)} (the contact)")
        fit = fit_polach(
            s, y, normal_force=normal_force, speed=speed, a=a, b=b, fit=("k_A", "k_S", "mu0"),
            initial={"A": 1.0, "B": 0.0}, warn_untrusted=False,
        )
        mu_hat = fit.params["mu0"]
        stderr = float(fit.stderr.get("mu0", math.inf))
        # the linearised interval rests on a fit that describes the data, a finite and
        # moderate standard error of mu0, and data on the rising part of the curve (low creep)
        k = int(np.argmax(y))
        rising = int(np.count_nonzero((s > 0) & (s < s[k]) & (y < 0.9 * y[k])))
        flags = fit_warnings(
            r_squared=float(fit.r_squared), params=fit.params, fitted=("k_A", "mu0"),
            stderr=fit.stderr, success=fit.success, min_r_squared=MIN_R_SQUARED_SCATTER,
            at_bound=tuple(n for n in fit.at_bound if n == "mu0"), ignore_stderr=("k_A",),
            region_points={"k_A": (rising, "on the rising part of the curve (below its peak)")},
        )  # fmt: skip
        from scipy import stats

        z = stats.norm.ppf(0.5 + _LEVEL / 2)
        lo = max(mu_hat - z * stderr, 0.0) if math.isfinite(stderr) else 0.0
        hi = mu_hat + z * stderr if math.isfinite(stderr) else math.inf
        sat = math.inf
    if flags and warn_untrusted:
        warn(f"low-adhesion detection ({model}): no warning level, the fit cannot be trusted: "
             + "; ".join(flags), UntrustedResultWarning)  # fmt: skip
    return DetectionResult(
        mu=float(mu_hat), stderr=stderr, interval=(float(lo), float(hi)),
        level="unknown" if flags else _level(lo, hi, thr), threshold=thr, model=model,
        max_creep=max_creep, saturation_creep=float(sat), params=dict(fit.params),
        r_squared=float(fit.r_squared), rmse=float(fit.rmse), n_points=int(s.size), fit=fit,
        warnings=flags,
    )


def fletcher_detection_study(
    truncations=(0.002, 0.005, 0.01),
    *,
    noise: float = 0.002,
    n_points: int = 50,
    seed: int = 0,
    threshold: float = RSSB_BRAKING_ADHESION,
    conditions=None,
):
    """Detection on Fletcher's ten conditions: synthetic curves, noise, truncated creep ranges.

    For each condition of Fletcher's Tables 1-2 (his mu, k_a, k_s = 1, half-width from the
    contact pressure, R = 11.75 mm) and each truncation, ``n_points`` creep values evenly
    spaced in ``(0, truncation]`` are generated, Gaussian noise of standard deviation
    ``noise`` (absolute, in adhesion) is added, and :func:`detect_low_adhesion` is run.

    Parameters
    ----------
    truncations : sequence of float, default (0.002, 0.005, 0.01)
        Largest creep of the data [-] (0.2 %, 0.5 %, 1 %).
    noise : float, default 0.002
        Standard deviation of the adhesion noise [-].
    n_points : int, default 50
        Points per curve.
    seed : int, default 0
        Seed of the noise generator (reproducible table).
    threshold : float, default 0.14
        Warning threshold [-].
    conditions : sequence of str, optional
        Fletcher test codes (default: all ten).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, truncation): ``test_code``, ``lubricant``, ``mu_true``,
        ``max_creep``, ``saturation_creep_true``, ``mu``, ``stderr``, ``mu_low``, ``mu_high``,
        ``level``, ``level_true`` (the level the true mu would give), ``covered`` (the
        interval holds the true mu) and ``trusted`` (the fit passed the quality gate).
    """
    import pandas as pd

    from railadhesion.models.twod import FLETCHER_CONDITIONS, fletcher_condition

    rng = np.random.default_rng(seed)
    codes = list(FLETCHER_CONDITIONS) if conditions is None else list(conditions)
    rows = []
    for code in codes:
        cond = fletcher_condition(code)
        sat_true = 3.0 * cond.half_width * cond.mu / (2.0 * cond.k_a * cond.radius)
        for trunc in truncations:
            xi = np.linspace(trunc / n_points, trunc, n_points)
            y = np.abs(cond.adhesion(xi) + rng.normal(0.0, noise, xi.size))
            res = detect_low_adhesion(
                xi, y, half_width=cond.half_width, radius=cond.radius, threshold=threshold,
                warn_untrusted=False,
            )
            lo, hi = res.interval
            rows.append({
                "test_code": cond.test_code, "lubricant": cond.lubricant, "mu_true": cond.mu,
                "max_creep": trunc, "saturation_creep_true": sat_true, "mu": res.mu,
                "stderr": res.stderr, "mu_low": lo, "mu_high": hi, "level": res.level,
                "level_true": _level(cond.mu, cond.mu, threshold),
                "covered": bool(lo <= cond.mu <= hi), "trusted": res.trusted,
            })
    return pd.DataFrame(rows)
