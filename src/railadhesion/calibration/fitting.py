"""Fitting creep-force models to measured creep curves (Polach 3D, Fletcher 2D).

Both fits minimise the sum of squared adhesion residuals with
:func:`scipy.optimize.least_squares` (trust-region reflective, box bounds) and return a
:class:`FitResult` in the spirit of SciPy's result objects: the fitted and fixed parameters,
their standard errors from the Jacobian, residuals, R², RMSE and the data used.

The measured adhesion is the magnitude |T|/Q (``docs/creep-curve-csv.md``); the models' forces
are in Kalker's signs (``docs/CONVENTIONS.md``), so the fits compare magnitudes and the creep
may be given with either sign.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from railadhesion._docstrings import docstring_entries
from railadhesion._validate import check_finite, check_nonnegative, check_positive, check_range
from railadhesion.plausibility import (
    UntrustedResultWarning,
    check_plausible,
    fit_warnings,
    noise_rms,
    warn,
)

__all__ = [
    "FLETCHER_DEFAULT_BOUNDS",
    "POLACH_DEFAULT_BOUNDS",
    "FitResult",
    "fit_fletcher",
    "fit_polach",
]

POLACH_NAMES = ("k_A", "k_S", "mu0", "A", "B")
#: Default bounds of the Polach fit. Within the ranges of
#: :data:`railadhesion.models.parameters.PARAMETER_RANGES`; ``A <= 1`` (friction falling
#: with slip velocity, as Polach intends); ``B`` in s/m.
POLACH_DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "k_A": (1e-3, 1.0),
    "k_S": (1e-3, 1.0),
    "mu0": (1e-3, 1.5),
    "A": (0.0, 1.0),
    "B": (0.0, 100.0),
}
#: Values of Polach parameters that are neither fitted nor given in ``initial``
#: (the defaults of :func:`railadhesion.models.polach.polach_forces`; ``mu0`` has none).
_POLACH_FIXED_DEFAULTS = {"k_A": 1.0, "k_S": 1.0, "A": 1.0, "B": 0.0}
#: Domain of each Polach parameter in the model: True if it must be > 0, False if >= 0.
_POLACH_POSITIVE = {"k_A": True, "k_S": True, "mu0": True, "A": False, "B": False}
#: Bounds of the search that are limits of the model itself (a fitted value there is a
#: legitimate one: no slope reduction, constant or vanishing friction at large slip).
_POLACH_DOMAIN = {"k_A": (1.0,), "k_S": (1.0,), "A": (0.0, 1.0), "B": (0.0,)}

FLETCHER_NAMES = ("k_a", "k_s", "mu")
#: Fletcher's k_a, k_s and mu must all be > 0 in a fit (the model divides by k_s mu).
_FLETCHER_POSITIVE = {"k_a": True, "k_s": True, "mu": True}
#: Lower bound used in place of a given 0 for a parameter that must be > 0.
_POSITIVE_FLOOR = 1e-12
#: Default bounds of the Fletcher fit (k_a may exceed 1 with noisy dry data; k_s up to 2 so
#: that a ``mu`` given slightly below the measured saturation does not pin the fit).
FLETCHER_DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "k_a": (1e-4, 5.0),
    "k_s": (1e-4, 2.0),
    "mu": (1e-4, 1.5),
}


@dataclass(frozen=True, eq=False)
class FitResult:
    """Result of :func:`fit_polach` or :func:`fit_fletcher`.

    Attributes
    ----------
    model : str
        ``"polach"`` or ``"fletcher"``.
    params : dict of str to float
        Every model parameter, fitted or held fixed (Polach: k_A, k_S, mu0, A, B;
        Fletcher: k_a, k_s, mu).
    fitted : tuple of str
        Names of the fitted parameters, in the order of :attr:`covariance`.
    stderr : dict of str to float
        Standard error of each fitted parameter (``inf`` when not identifiable from the data).
    covariance : ndarray
        Covariance of the fitted parameters, ``s² (JᵀJ)⁻¹`` with ``s² = SSR/(n - p)``.
    residuals : ndarray
        Model minus measured adhesion at each point [-].
    r_squared : float
        ``1 - SSR/SST`` of the adhesion.
    rmse : float
        ``sqrt(SSR/n)`` [-].
    success : bool
        The optimiser's convergence flag.
    message : str
        The optimiser's message, with notes (parameters at a bound, non-identifiable ones).
    n_points : int
        Number of data points.
    creep, adhesion : ndarray
        The data the fit used (creep [-], adhesion |T|/Q [-]).
    conditions : dict
        The fixed inputs (Polach: normal_force [N], speed [m/s], a, b [m], creep_lat, spin,
        shear_modulus, poisson; Fletcher: half_width, radius [m]), scalars or arrays.
    at_bound : tuple of str
        Fitted parameters that ended on a bound.
    nfev : int
        Number of model evaluations (all starts together).
    warnings : tuple of str
        Why the fit should not be trusted (empty if nothing was found): first the implausible
        data or conditions (a speed of 300 m/s, adhesion in percent: each also warned once, a
        :class:`~railadhesion.plausibility.UnitWarning` or
        :class:`~railadhesion.plausibility.PlausibilityWarning`), then the quality gate
        :func:`railadhesion.plausibility.fit_warnings` (low R², a parameter on a bound of the
        search that is not a limit of the model, non-finite or very large standard errors, too
        few points where a parameter shows; ``docs/checks.md``).
    trusted : bool
        ``not warnings``.
    implausible_inputs : tuple of str
        The implausible data or conditions among :attr:`warnings` (empty if none).
    """

    model: str
    params: dict
    fitted: tuple[str, ...]
    stderr: dict
    covariance: np.ndarray
    residuals: np.ndarray
    r_squared: float
    rmse: float
    success: bool
    message: str
    n_points: int
    creep: np.ndarray
    adhesion: np.ndarray
    conditions: dict
    at_bound: tuple[str, ...] = ()
    nfev: int = 0
    warnings: tuple[str, ...] = ()
    _predict: Callable | None = field(default=None, repr=False, compare=False)
    implausible_inputs: tuple[str, ...] = ()

    @property
    def trusted(self) -> bool:
        """True when the quality gate found nothing (:attr:`warnings` is empty)."""
        return not self.warnings

    def predict(self, creep=None):
        """Model adhesion |T|/Q at ``creep`` (default: the fitted data's creep).

        With per-point conditions (arrays of normal force, speed...), ``creep`` must have the
        data's shape.
        """
        if self._predict is None:  # pragma: no cover - always set by the fit functions
            raise ValueError("this FitResult holds no model")
        return self._predict(self.creep if creep is None else np.asarray(creep, dtype=float))

    def as_polach_parameters(self, name: str = "", source: str = "", notes: str = ""):
        """The fitted set as :class:`~railadhesion.models.parameters.PolachParameters`.

        Raises ``ValueError`` for a Fletcher fit (its k_a, k_s are not Polach's k_A, k_S) or
        if a value is outside the ranges ``PolachParameters`` accepts.
        """
        if self.model != "polach":
            raise ValueError(
                f"as_polach_parameters needs a Polach fit, this is a {self.model!r} fit "
                "(Fletcher's k_a, k_s are not transferable to Polach's model, Fletcher 2013 §3.1)"
            )
        from railadhesion.models.parameters import PolachParameters

        if not source:
            source = (
                f"fit_polach to {self.n_points} points, R^2 = {self.r_squared:.4f}, "
                f"RMSE = {self.rmse:.4g}; fitted: {', '.join(self.fitted)}"
            )
        if self.warnings:  # a file written from it carries them (its provenance)
            flags = "NOT TRUSTED: " + "; ".join(self.warnings)
            notes = f"{notes} {flags}".strip() if flags not in notes else notes
        return PolachParameters(**self.params, name=name, source=source, notes=notes)

    def to_dataframe(self):
        """Data and fit as a :class:`pandas.DataFrame`: ``creep``, ``adhesion`` (measured),
        ``model`` and ``residual`` (model minus measured), all dimensionless; ``attrs`` holds
        the parameters, their standard errors, R², RMSE and ``units``."""
        import pandas as pd

        df = pd.DataFrame(
            {
                "creep": np.asarray(self.creep),
                "adhesion": np.asarray(self.adhesion),
                "model": np.asarray(self.adhesion) + np.asarray(self.residuals),
                "residual": np.asarray(self.residuals),
            }
        )
        df.attrs.update(
            {
                "model": self.model,
                "params": dict(self.params),
                "fitted": list(self.fitted),
                "stderr": dict(self.stderr),
                "r_squared": self.r_squared,
                "rmse": self.rmse,
                "trusted": self.trusted,
                "warnings": list(self.warnings),
                "units": {"creep": "1", "adhesion": "1", "model": "1", "residual": "1",
                          "B": "s/m"},
            }
        )  # fmt: skip
        return df

    def summary(self) -> str:
        """Readable multi-line report."""
        head = (
            f"{self.model.capitalize()} fit: {self.n_points} points, R^2 = {self.r_squared:.5f}, "
            f"RMSE = {self.rmse:.4g}, {'converged' if self.success else 'NOT converged'}"
        )
        lines = [head]
        for name, value in self.params.items():
            if name in self.fitted:
                err = self.stderr[name]
                note = "  (at bound)" if name in self.at_bound else ""
                lines.append(f"  {name:>4} = {value:.6g} +/- {err:.2g}{note}")
            else:
                lines.append(f"  {name:>4} = {value:.6g} (fixed)")
        lines.append(f"  {self.message}")
        if self.warnings:
            lines.append(f"  NOT TRUSTED ({len(self.warnings)} finding(s) of the quality gate):")
            lines.extend(f"    ! {w}" for w in self.warnings)
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()


# ---------------------------------------------------------------------------------------------
# shared machinery


def _check_fit_names(fit, allowed: Sequence[str], model: str) -> tuple[str, ...]:
    if isinstance(fit, str):
        fit = (fit,)
    names = tuple(fit)
    if not names:
        raise ValueError(f"fit must name at least one of {list(allowed)}, got none")
    for n in names:
        if n not in allowed:
            raise ValueError(f"fit: unknown {model} parameter {n!r}; allowed: {list(allowed)}")
    if len(set(names)) != len(names):
        raise ValueError(f"fit names a parameter twice: {list(names)}")
    return tuple(n for n in allowed if n in names)  # canonical order


def _as_mapping(value, allowed: Sequence[str], what: str) -> dict[str, float]:
    if value is None:
        return {}
    if hasattr(value, "as_dict") and not isinstance(value, Mapping):
        value = value.as_dict()
    if not isinstance(value, Mapping):
        raise ValueError(f"{what} must be a mapping of parameter name to value, got {value!r}")
    unknown = set(value) - set(allowed)
    if unknown:
        raise ValueError(
            f"{what}: unknown parameter(s) {sorted(unknown)}; allowed: {list(allowed)}"
        )
    return dict(value)


def _bounds(
    bounds, defaults: dict, allowed: Sequence[str], positive: Mapping[str, bool]
) -> dict[str, tuple[float, float]]:
    out = dict(defaults)
    for name, pair in _as_mapping(bounds, allowed, "bounds").items():
        try:
            lo, hi = (float(x) for x in pair)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"bounds[{name!r}] must be a pair (low, high), got {pair!r}") from exc
        if not lo < hi or np.isnan(lo) or np.isnan(hi):
            raise ValueError(f"bounds[{name!r}] must satisfy low < high, got ({lo}, {hi})")
        # The model rejects values outside its domain: a bound reaching there would make the
        # optimiser step into it and the fit stop with an error about the model's argument.
        if lo < 0:
            rng = "(0, inf)" if positive[name] else "[0, inf)"
            raise ValueError(
                f"bounds[{name!r}]: low must be >= 0 ({name} must be in {rng} in the model), "
                f"got ({lo}, {hi})"
            )
        if positive[name] and lo == 0:
            lo = _POSITIVE_FLOOR
        out[name] = (lo, hi)
    return out


def _parameter_value(value, name: str, what: str, positive: bool | None) -> float:
    """``value`` of parameter ``name`` as a finite float; ``positive``: True for > 0, False for
    >= 0, None for any finite number (a starting value, clipped into the bounds later)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what}[{name!r}] must be a number, got {value!r}") from None
    if not np.isfinite(x):
        raise ValueError(f"{what}[{name!r}] must be finite, got {x!r}")
    if positive is True and not x > 0:
        raise ValueError(f"{what}[{name!r}] must be in (0, inf) ({name} is fixed), got {x!r}")
    if positive is False and not x >= 0:
        raise ValueError(f"{what}[{name!r}] must be in [0, inf) ({name} is fixed), got {x!r}")
    return x


def _check_shape_information(s: np.ndarray, y: np.ndarray) -> None:
    """Reject data that cannot determine a creep curve: no creepage, or a flat adhesion."""
    if not np.any(s != 0):
        raise ValueError(
            f"creep is 0 at all {s.size} points: a creep curve needs points at non-zero "
            "creepage (the model's force is 0 there whatever its parameters)"
        )
    if float(np.ptp(y)) <= 1e-12 * float(np.max(y)):
        raise ValueError(
            f"adhesion is the same ({float(y[0]):g}) at all {y.size} points: a flat curve does "
            "not determine the model's parameters (no initial slope, no peak); check the "
            "adhesion column"
        )


def _data(creep, adhesion) -> tuple[np.ndarray, np.ndarray]:
    s = check_finite(creep, "creep").ravel()
    y = check_nonnegative(adhesion, "adhesion").ravel()
    if s.shape != y.shape:
        raise ValueError(
            f"creep and adhesion must have the same number of points, got {s.size} and {y.size}"
        )
    return s, y


def _through_origin_slope(x: np.ndarray, y: np.ndarray) -> float | None:
    """Least-squares slope of y = k x on the rising part of a creep curve, or None.

    The rising part: points before the peak (smaller ``x`` than at the largest ``y``) with
    ``y`` below 0.6 of the peak; at least two are needed.
    """
    peak_at = int(np.argmax(y))
    sel = (x > 0) & (x < x[peak_at]) & (y < 0.6 * y[peak_at])
    if np.count_nonzero(sel) < 2:
        return None
    return float(np.sum(x[sel] * y[sel]) / np.sum(x[sel] ** 2))


def _check_inputs(values: Mapping) -> tuple[str, ...]:
    """Check a fit's data and conditions once, before the optimiser (which evaluates the
    model unchecked): a :class:`~railadhesion.plausibility.PlausibilityWarning` or
    :class:`~railadhesion.plausibility.UnitWarning` for each implausible one
    (:func:`~railadhesion.plausibility.check_plausible`; ``docs/checks.md``), and their
    messages, which the fit records as reasons it is not trusted: a model fitted to data in a
    wrong unit has fitted its parameters to a wrong scale (B, the rate of the falling
    friction per slip velocity, 100 times too small for a speed in km/h read as m/s).

    ``values``: ``{argument name: value}``, ``adhesion`` checked as a coefficient of friction
    (measured |T|/Q, a fraction)."""
    found = []
    for name, value in values.items():
        if name == "adhesion":
            what = "measured adhesion coefficient |T|/Q (a fraction)"
            text = check_plausible(value, name, quantity="friction_coefficient", what=what)
        else:
            text = check_plausible(value, name)
        if text is not None:
            found.append(text)
    return tuple(found)


def _run_fit(model_name, names, residual, starts, lo, hi, fitted, fixed, s, y, conditions, predict,
             *, domain, gate=None, warn_untrusted=True, inputs=()):  # fmt: skip
    """Least squares from each start; keep the lowest cost; build the FitResult.

    ``domain``: ``{name: (low, high)}`` limits of each parameter in the model (a parameter
    ending on a bound of the search equal to one of them is a legitimate value, e.g.
    ``k_A = 1``; on any other bound the data push it out of the search: not trusted).
    ``gate(params)``: extra arguments of :func:`~railadhesion.plausibility.fit_warnings`
    (``region_points``, ``ignore_stderr``) for the fitted values. ``warn_untrusted``: issue
    an :class:`~railadhesion.plausibility.UntrustedResultWarning` when the gate finds
    anything. ``inputs``: the messages of :func:`_check_inputs` (implausible data or
    conditions), the first reasons the fit is not trusted.
    """

    def solve(x0, max_nfev):
        return least_squares(
            residual, x0, bounds=(lo, hi), x_scale="jac", method="trf",
            ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=max_nfev,
        )  # fmt: skip

    # Every start gets a short budget; the best one is then polished with a long one.
    best = None
    nfev = 0
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0)  # for nudging off a bound
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, dtype=float), lo, hi)
        # least_squares wants x0 strictly inside the bounds: nudge values on a bound inwards.
        x0 = np.where(x0 <= lo, lo + 1e-6 * span, x0)
        x0 = np.where(x0 >= hi, hi - 1e-6 * span, x0)
        res = solve(x0, 40 * len(x0))
        nfev += res.nfev
        if best is None or res.cost < best.cost:
            best = res
    if best is None:
        raise ValueError(f"{model_name} fit: no starting point")
    if best.status == 0:  # budget exhausted: continue from where it stopped
        x0 = np.clip(best.x, lo + 1e-9 * span, hi - 1e-9 * span)
        res = solve(x0, 200 * len(x0))
        nfev += res.nfev
        if res.cost <= best.cost:
            best = res
    x = best.x
    r = best.fun
    n, p = r.size, x.size
    ssr = float(r @ r)
    sst = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - ssr / sst if sst > 0 else (1.0 if ssr == 0 else 0.0)
    notes = []
    jac = best.jac
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    tol = np.finfo(float).eps * max(jac.shape) * (sv[0] if sv.size else 0.0)
    if sv.size and np.all(sv > tol) and n > p:
        cov = (vt.T / sv**2) @ vt * (ssr / (n - p))
    else:
        cov = np.full((p, p), np.inf)
        notes.append(
            "covariance not estimated: the data do not determine every fitted parameter"
            if n > p
            else "covariance not estimated: no residual degree of freedom"
        )
    stderr = {name: float(np.sqrt(cov[i, i])) for i, name in enumerate(fitted)}
    at_bound = tuple(
        name
        for i, name in enumerate(fitted)
        if x[i] <= lo[i] + 1e-6 * span[i] or x[i] >= hi[i] - 1e-6 * span[i]
    )
    if at_bound:
        notes.append(f"at a bound: {', '.join(at_bound)} (its standard error is not reliable)")
    values = {**fixed, **{name: float(v) for name, v in zip(fitted, x, strict=True)}}
    params = {name: values[name] for name in names}
    message = best.message.rstrip(".") + ("; " + "; ".join(notes) if notes else "")
    outside = tuple(
        name for i, name in enumerate(fitted) if name in at_bound
        and not any(abs(x[i] - lim) <= 1e-6 * span[i] for lim in domain.get(name, ()))
    )  # fmt: skip
    flags = tuple(inputs) + fit_warnings(
        r_squared=float(r2), params=params, fitted=fitted, stderr=stderr, at_bound=outside,
        success=bool(best.success), residual_rms=float(np.sqrt(ssr / n)),
        noise=noise_rms(np.abs(s), y), **(gate(params) if gate is not None else {}),
    )  # fmt: skip
    if flags and warn_untrusted:
        warn(f"{model_name} fit not trusted: " + "; ".join(flags), UntrustedResultWarning)
    return FitResult(
        model=model_name,
        params=params,
        fitted=tuple(fitted),
        stderr=stderr,
        covariance=cov,
        residuals=np.asarray(r, dtype=float),
        r_squared=float(r2),
        rmse=float(np.sqrt(ssr / n)),
        success=bool(best.success),
        message=message,
        n_points=int(n),
        creep=s,
        adhesion=y,
        conditions=conditions,
        at_bound=at_bound,
        nfev=int(nfev),
        warnings=flags,
        _predict=lambda c: predict(c, params),
        implausible_inputs=tuple(inputs),
    )


#: The docstring entry of the ``warn_untrusted`` argument of the fits (:func:`_fit_docs`).
_WARN_UNTRUSTED_DOC = """warn_untrusted : bool, default True
        Issue an :class:`~railadhesion.plausibility.UntrustedResultWarning` when the quality
        gate flags the fit (its findings are in ``warnings`` either way)."""


#: Puts :data:`_WARN_UNTRUSTED_DOC` in place of ``{warn_untrusted}`` in a fit's docstring.
_fit_docs = docstring_entries(warn_untrusted=_WARN_UNTRUSTED_DOC)


# ---------------------------------------------------------------------------------------------
# Polach


@_fit_docs
def fit_polach(
    creep,
    adhesion,
    *,
    normal_force,
    speed,
    a,
    b,
    fit: Sequence[str] = POLACH_NAMES,
    initial=None,
    bounds: Mapping | None = None,
    creep_lat=0.0,
    spin=0.0,
    shear_modulus=8.2e10,
    poisson=0.28,
    warn_untrusted: bool = True,
) -> FitResult:
    """Fit parameters of Polach's creep-force model to a measured creep curve.

    Parameters
    ----------
    creep : array_like
        Longitudinal creepage xi [-] of each point (signed; the fit uses the force magnitude).
    adhesion : array_like
        Measured adhesion |T|/Q [-], >= 0, one per point.
    normal_force : array_like
        Normal force Q [N], > 0; scalar or one per point (several curves fitted together).
    speed : array_like
        Rolling speed V [m/s], >= 0; scalar or one per point.
    a, b : array_like
        Contact semi-axes [m] (``a`` in the rolling direction), > 0; scalar or per point.
    fit : sequence of str, default all five
        Parameters to fit, any subset of ``("k_A", "k_S", "mu0", "A", "B")``.
    initial : mapping or PolachParameters, optional
        Starting values of fitted parameters and values of fixed ones. A fixed parameter not
        given takes the model's default (k_A = k_S = A = 1, B = 0); a fixed ``mu0`` must be
        given. Fitted parameters not given start from a guess derived from the data (below).
    bounds : mapping of str to (low, high), optional
        Bounds overriding :data:`POLACH_DEFAULT_BOUNDS` (k_A, k_S in [1e-3, 1], mu0 in
        [1e-3, 1.5], A in [0, 1], B in [0, 100] s/m). Lower bounds must be >= 0 (the model's
        domain); a lower bound 0 of k_A, k_S or mu0 is used as 1e-12.
    creep_lat : array_like, default 0
        Lateral creepage eta [-] of the points.
    spin : array_like, default 0
        Spin creepage phi [rad/m].
    shear_modulus : float, default 8.2e10
        Combined shear modulus G [Pa].
    poisson : float, default 0.28
        Combined Poisson's ratio [-].
    {warn_untrusted}

    Returns
    -------
    FitResult
        ``params`` (all five), ``stderr`` of the fitted ones, residuals, R², RMSE, and the
        quality gate's ``trusted`` and ``warnings`` (see Notes);
        :meth:`FitResult.as_polach_parameters` gives a validated parameter set.

    Raises
    ------
    ValueError
        Bad arguments (named), no more points than fitted parameters, creep 0 at every
        point, or the same adhesion at every point (a flat curve determines no parameter).

    Notes
    -----
    Model: adhesion = sqrt(Fx² + Fy²)/Q with Fx, Fy from
    :func:`railadhesion.models.polach.polach_forces` (Polach 2005, Wear 258, section 2:
    F = (2Qmu/pi)[k_A eps/(1 + (k_A eps)²) + arctan(k_S eps)], mu = mu0[(1 - A)e^(-B w) + A]).

    Starting guess [derived here]: mu0 = 1.05 x the largest adhesion; A = mean adhesion of the
    10 % of points at the largest |creep| over the largest adhesion (in [0.05, 1]);
    (k_A + k_S)/2 = the ratio of the initial slope of the data (least squares through the
    origin on the points before the peak and below 0.6 x the peak) to Kalker's, since
    Polach's slope at small creep is (k_A + k_S)/2 times Kalker's (Polach 2005). The fit is
    started from a few variants (k_A above/at k_S with B = 1/w_max and 5/w_max, w_max the
    largest slip velocity |xi|V; and six fixed (k_A, k_S) pairs from (1, 1) to
    (0.05, 0.005)) and the lowest cost is kept. Standard errors: ``sqrt(diag(s² (JᵀJ)⁻¹))``,
    s² = SSR/(n - p), the Jacobian at the solution (as :func:`scipy.optimize.curve_fit`);
    they are unreliable for a parameter at a bound. With B = 0 (or A = 1) the other of the
    pair is not identifiable.

    Quality gate (:func:`railadhesion.plausibility.fit_warnings`, ``docs/checks.md``): the
    fit is not trusted if an input is implausible (the data's creep or adhesion, the normal
    force, speed, semi-axes... outside :data:`railadhesion.plausibility.PLAUSIBLE`: checked
    once, before the optimiser, which then evaluates the model without re-checking), R² < 0.9, a
    fitted parameter ends on a bound of the search that is not a limit of the model (k_A = 1,
    k_S = 1, A = 0 or 1 and B = 0 are legitimate values), a standard error is not finite or
    larger than its value, or fewer than 3 points lie where a parameter shows: k_A, k_S on the
    rising part (below the peak), A and B beyond the peak (not required when the fitted friction
    falls by less than 1 % over the data).

    References
    ----------
    O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit,
    Wear 258 (2005) 992-1000.

    Examples
    --------
    Synthetic curve from known parameters, recovered:

    >>> import numpy as np
    >>> from railadhesion.models.polach import polach_forces
    >>> creep = -np.geomspace(0.001, 0.3, 40)
    >>> true = dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5)
    >>> fx, _ = polach_forces(creep, 0.0, 0.0, 4200.0, 5.0, 4e-3, 3e-3, **true)
    >>> res = fit_polach(creep, fx / 4200.0, normal_force=4200.0, speed=5.0, a=4e-3, b=3e-3)
    >>> {k: round(v, 3) for k, v in res.params.items()}
    {'k_A': 0.6, 'k_S': 0.2, 'mu0': 0.4, 'A': 0.4, 'B': 0.5}
    """
    from railadhesion.models.polach import polach_forces_quiet

    fitted = _check_fit_names(fit, POLACH_NAMES, "Polach")
    s, y = _data(creep, adhesion)
    if s.size <= len(fitted):
        raise ValueError(
            f"creep must hold more points than fitted parameters ({len(fitted)}), got {s.size}"
        )
    _check_shape_information(s, y)
    q = check_positive(normal_force, "normal_force")
    v = check_nonnegative(speed, "speed")
    aa = check_positive(a, "a")
    bb = check_positive(b, "b")
    eta = check_finite(creep_lat, "creep_lat")
    phi = check_finite(spin, "spin")
    g = float(check_positive(shear_modulus, "shear_modulus"))
    nu = float(check_range(poisson, "poisson", 0.0, 0.5))
    per_point = []
    for name, arr in (("normal_force", q), ("speed", v), ("a", aa), ("b", bb),
                      ("creep_lat", eta), ("spin", phi)):  # fmt: skip
        if arr.ndim and arr.size != 1:
            if arr.size != s.size:
                raise ValueError(
                    f"{name} must be a scalar or hold one value per point ({s.size}), "
                    f"got {arr.size} values"
                )
            per_point.append(name)
    q, v, aa, bb, eta, phi = (x.ravel() if x.size > 1 else x.reshape(()) for x in
                              (q, v, aa, bb, eta, phi))  # fmt: skip
    init = _as_mapping(initial, POLACH_NAMES, "initial")
    init = {
        n: _parameter_value(x, n, "initial", None if n in fitted else _POLACH_POSITIVE[n])
        for n, x in init.items()
    }
    bnd = _bounds(bounds, POLACH_DEFAULT_BOUNDS, POLACH_NAMES, _POLACH_POSITIVE)
    fixed = {}
    for name in POLACH_NAMES:
        if name in fitted:
            continue
        if name in init:
            fixed[name] = init[name]
        elif name in _POLACH_FIXED_DEFAULTS:
            fixed[name] = _POLACH_FIXED_DEFAULTS[name]
        else:
            raise ValueError("mu0 is not fitted: give its value in initial, e.g. {'mu0': 0.4}")

    # implausible inputs warn once, here, and make the fit untrusted; the optimiser then
    # evaluates the model without re-checking them (it would warn at every evaluation)
    inputs = _check_inputs({"creep": s, "adhesion": y, "creep_lat": eta, "spin": phi,
                            "normal_force": q, "speed": v, "a": aa, "b": bb,
                            "shear_modulus": g, "poisson": nu})  # fmt: skip

    def model(c, params):
        fx, fy = polach_forces_quiet(c, eta, phi, q, v, aa, bb, shear_modulus=g, poisson=nu,
                                     **params)  # fmt: skip
        return np.hypot(fx, fy) / q

    def residual(x):
        params = dict(fixed)
        params.update(zip(fitted, x, strict=True))
        return model(s, params) - y

    # ---- data-driven starting guesses
    mag = np.abs(s)
    peak = float(np.max(y)) if y.size else 0.0
    peak = peak if peak > 0 else 0.1
    order = np.argsort(mag)
    tail = float(np.mean(y[order[-max(1, s.size // 10):]]))
    guess = {"mu0": 1.05 * peak, "A": float(np.clip(tail / peak, 0.05, 1.0))}
    # Kalker's small-creep adhesion slope per point (Polach with k_A = k_S = 1, mu0 large).
    tiny = 1e-7
    ref = np.broadcast_to(
        model(np.full(s.shape, tiny), {"k_A": 1.0, "k_S": 1.0, "mu0": 1.0, "A": 1.0, "B": 0.0})
        / tiny,
        s.shape,
    )
    k_mean = _through_origin_slope(mag * ref, y)
    w_max = float(np.max(mag * np.broadcast_to(v, s.shape)))
    b_lo, b_hi = bnd["B"]
    b_starts = [1.0 / w_max, 5.0 / w_max] if w_max > 0 else [b_lo]
    # Data-driven slope pairs with two B values, plus a fixed spread of slopes (for curves
    # whose first points are already past the k_A hump, or have no rising part at all).
    # k_S down to a tenth of k_A: a curve still rising at its largest creep (a small k_S)
    # has a second minimum near k_S/k_A ~ 0.3 that starts above it do not leave.
    spread = [(1.0, 1.0), (1.0, 0.2), (0.3, 0.1), (0.3, 0.03), (0.05, 0.02), (0.05, 0.005)]
    variants = [(1.5 * k_mean, 0.5 * k_mean, b0) for b0 in b_starts] if k_mean else []
    variants += [(k_mean, k_mean, b_starts[0])] if k_mean else []
    variants += [(ka, ks, b_starts[-1]) for ka, ks in spread]
    variants = [(*v, guess["A"]) for v in variants]
    # A curve that rises slowly (small k_S) hides its fall: the data's tail says A ~ 1 when
    # the friction has fallen by half. One start assumes the fall.
    variants.append((*spread[-1], b_starts[-1], 0.5))
    starts = []
    for ka, ks, b0, a0 in variants:
        cand = {**guess, "k_A": ka, "k_S": ks, "B": b0, "A": a0, **init}
        x0 = [cand[n] for n in fitted]
        if x0 not in starts:
            starts.append(x0)
    lo = np.array([bnd[n][0] for n in fitted])
    hi = np.array([bnd[n][1] for n in fitted])
    conditions = {
        "normal_force": q, "speed": v, "a": aa, "b": bb, "creep_lat": eta, "spin": phi,
        "shear_modulus": g, "poisson": nu,
    }  # fmt: skip
    conditions = {k: (float(x) if np.ndim(x) == 0 else x) for k, x in conditions.items()}

    def gate(params):
        # the fall of the friction over the data: A and B matter only if it shows
        fall = (1.0 - params["A"]) * -np.expm1(-params["B"] * w_max)
        quiet = ("A", "B") if abs(fall) < 0.01 else ()
        if per_point:  # several curves at once: no single peak to split the data at
            return {"ignore_stderr": quiet}
        k = int(np.argmax(y))
        rising = int(np.count_nonzero((mag > 0) & (mag < mag[k]) & (y < 0.9 * y[k])))
        beyond = int(np.count_nonzero(mag > mag[k]))
        regions = {"k_A": (rising, "on the rising part of the curve (below the peak)"),
                   "k_S": (rising, "on the rising part of the curve (below the peak)")}
        if not quiet:
            regions.update({n: (beyond, "beyond the peak (where the friction falls)")
                            for n in ("A", "B")})  # fmt: skip
        return {"region_points": regions, "ignore_stderr": quiet}

    return _run_fit(
        "polach", POLACH_NAMES, residual, starts, lo, hi, fitted, fixed, s, y, conditions, model,
        domain=_POLACH_DOMAIN, gate=gate, warn_untrusted=warn_untrusted, inputs=inputs,
    )


# ---------------------------------------------------------------------------------------------
# Fletcher


@_fit_docs
def fit_fletcher(
    creep,
    adhesion,
    *,
    half_width,
    radius,
    fit: Sequence[str] = ("k_a", "k_s"),
    mu=None,
    initial=None,
    bounds: Mapping | None = None,
    warn_untrusted: bool = True,
) -> FitResult:
    """Fit Fletcher's (2013) 2D reduction factors k_a, k_s (and/or mu) to twin-disc data.

    Parameters
    ----------
    creep : array_like
        Creep ratio xi [-] of each point (a fraction; Fletcher's eq. (1) gives percent, divide
        by 100). Signed or not: the fit compares magnitudes.
    adhesion : array_like
        Measured adhesion (traction) coefficient Q/P [-], >= 0.
    half_width : float
        Hertzian contact half-width a [m], > 0 (0.204 mm for Fletcher's discs at 1000 MPa).
    radius : float
        Reduced radius R [m], > 0 (11.75 mm for his 47 mm discs).
    fit : sequence of str, default ("k_a", "k_s")
        Parameters to fit, a subset of ``("k_a", "k_s", "mu")`` not holding both ``k_s`` and
        ``mu``: the model depends on them only through their product (see Notes).
    mu : float, optional
        Friction coefficient [-]. Required when ``"mu"`` is not fitted (Fletcher took it from
        the saturation adhesion, his Table 1); the starting value when it is.
    initial : mapping, optional
        Starting values (fitted) or values (fixed) of ``k_a``, ``k_s``; a fixed one not given
        is 1 (Fletcher fitted k_a alone with k_s = 1, his §4).
    bounds : mapping of str to (low, high), optional
        Overrides :data:`FLETCHER_DEFAULT_BOUNDS` (k_a in [1e-4, 5], k_s in [1e-4, 2],
        mu in [1e-4, 1.5]).
    {warn_untrusted}

    Returns
    -------
    FitResult
        With ``model == "fletcher"`` and ``params`` k_a, k_s, mu; ``trusted`` and ``warnings``
        of the quality gate: as :func:`fit_polach` (no bound of the search is a limit of the
        model), with k_a carried by the points below the creep of full slip and k_s or mu by
        the points from half that creep on.

    Notes
    -----
    Model: Q/P from :func:`railadhesion.models.twod.fletcher`, Fletcher (2013) eqs. (8)-(12),
    which reduce to Q/P = k_s mu (1 - (c/a)³) with c = max(a - 2 k_a xi R/(3 k_s mu), 0):
    only k_a and the product k_s mu are identifiable. The initial slope is 2 k_a R/a, which
    gives the starting k_a [derived here]; the largest adhesion gives the starting k_s (or mu).
    Fletcher's own fits (his Table 2) vary k_a alone with k_s = 1 by Levenberg-Marquardt in
    Gnuplot; ``fit=("k_a",)`` with ``mu`` from his Table 1 repeats that.

    References
    ----------
    D. I. Fletcher, A new two-dimensional model of rolling-sliding contact creep curves for a
    range of lubrication types, Proc. IMechE Part J 227(6) (2013) 529-537.

    Examples
    --------
    >>> import numpy as np
    >>> from railadhesion.models.twod import fletcher
    >>> xi = np.linspace(0.0002, 0.01, 30)
    >>> y = np.abs(fletcher(xi, 1.0, 0.204e-3, 11.75e-3, 0.055, k_a=0.193).traction)
    >>> res = fit_fletcher(xi, y, half_width=0.204e-3, radius=11.75e-3, fit=("k_a",), mu=0.055)
    >>> round(res.params["k_a"], 4), res.params["k_s"]
    (0.193, 1.0)
    """
    from railadhesion.models.twod import fletcher_quiet

    fitted = _check_fit_names(fit, FLETCHER_NAMES, "Fletcher")
    if "k_s" in fitted and "mu" in fitted:
        raise ValueError(
            "fit cannot hold both 'k_s' and 'mu': Fletcher's model depends on them only "
            "through k_s*mu (eq. (8) and (11)); fix one of them"
        )
    s, y = _data(creep, adhesion)
    if s.size <= len(fitted):
        raise ValueError(
            f"creep must hold more points than fitted parameters ({len(fitted)}), got {s.size}"
        )
    _check_shape_information(s, y)
    a = float(check_positive(half_width, "half_width"))
    r = float(check_positive(radius, "radius"))
    init = _as_mapping(initial, FLETCHER_NAMES, "initial")
    init = {
        n: _parameter_value(x, n, "initial", None if n in fitted else _FLETCHER_POSITIVE[n])
        for n, x in init.items()
    }
    if mu is not None:
        mu = float(check_positive(mu, "mu"))
        init.setdefault("mu", mu)
    elif "mu" not in fitted and "mu" not in init:
        raise ValueError("mu must be given (in (0, inf)) when it is not fitted")
    bnd = _bounds(bounds, FLETCHER_DEFAULT_BOUNDS, FLETCHER_NAMES, _FLETCHER_POSITIVE)
    fixed = {n: float(init.get(n, 1.0)) for n in FLETCHER_NAMES if n not in fitted}

    # checked once (warn, not trusted); the optimiser's evaluations are not re-checked
    inputs = _check_inputs({"creep": s, "adhesion": y, "half_width": a, "radius": r})

    def model(c, params):
        res = fletcher_quiet(c, 1.0, a, r, params["mu"], k_a=params["k_a"], k_s=params["k_s"])
        return np.abs(res.traction)

    def residual(x):
        params = dict(fixed)
        params.update(zip(fitted, x, strict=True))
        return model(s, params) - y

    mag = np.abs(s)
    peak = float(np.max(y)) if np.max(y) > 0 else 0.1
    slope = _through_origin_slope(mag, y)
    guess = {"k_a": slope * a / (2.0 * r) if slope else 0.5}
    mu_now = init.get("mu", fixed.get("mu"))
    ks_now = init.get("k_s", fixed.get("k_s", 1.0))
    if "k_s" in fitted:
        guess["k_s"] = peak / mu_now
    if "mu" in fitted:
        guess["mu"] = peak / ks_now
    x_guess = {**guess, **init}
    starts = [[x_guess[n] for n in fitted]]
    if "k_a" in fitted and "k_a" not in init:
        starts.append([0.5 * guess["k_a"] if n == "k_a" else x_guess[n] for n in fitted])
    lo = np.array([bnd[n][0] for n in fitted])
    hi = np.array([bnd[n][1] for n in fitted])
    conditions = {"half_width": a, "radius": r}

    def gate(params):
        # creep of full slip of the fitted curve (eqs. (8)-(12): c = 0)
        sat = 3.0 * a * params["k_s"] * params["mu"] / (2.0 * params["k_a"] * r)
        below = int(np.count_nonzero((mag > 0) & (mag < sat)))
        bend = int(np.count_nonzero(mag >= 0.5 * sat))
        return {"region_points": {
            "k_a": (below, f"below the creep of full slip ({sat * 100:.3g} %)"),
            "k_s": (bend, f"from half the creep of full slip ({sat * 50:.3g} %) on"),
            "mu": (bend, f"from half the creep of full slip ({sat * 50:.3g} %) on"),
        }}  # fmt: skip

    return _run_fit(
        "fletcher", FLETCHER_NAMES, residual, starts, lo, hi, fitted, fixed, s, y, conditions,
        model, domain={}, gate=gate, warn_untrusted=warn_untrusted, inputs=inputs,
    )
