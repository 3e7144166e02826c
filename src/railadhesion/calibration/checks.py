"""Guards of the WILAC calibration: joint refinement of the regressions and the check of a
calibrated set *between* the data points.

A regression that passes through every fitted value can still swing wildly between them (few
curves, many terms), and separately regressed Polach parameters can combine into curves no
measurement supports. :func:`refine_condition` refits all regression coefficients of one
condition together against the measured adhesion (the parameters' physical bounds enter as a
penalty on a grid); :func:`check_condition` evaluates the calibrated set on a grid over the
calibrated (Q, v) range and reports parameters that leave their physical bounds, parameters
that vary far beyond the range of the per-curve fits, and adhesion curves outside the envelope
of the measured ones; it also notes regressions on Q and v of a parameter the curves hardly
determine (:class:`UndeterminedParameterWarning`). Both are used by
:func:`railadhesion.calibration.pipeline.run_wilac_calibration`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from railadhesion.models.regression import ParameterRegression, design_matrix
from railadhesion.plausibility import (
    MAX_RELATIVE_STDERR,
    RailadhesionWarning,
    UntrustedResultWarning,
)

__all__ = [
    "CalibrationWarning",
    "ConditionCheck",
    "UndeterminedParameterWarning",
    "check_condition",
    "refine_condition",
]

_NAMES = ("k_A", "k_S", "mu0", "A", "B")


class CalibrationWarning(UntrustedResultWarning):
    """A calibrated parameter set that should not be trusted somewhere in its range (an
    :class:`~railadhesion.plausibility.UntrustedResultWarning`)."""


class UndeterminedParameterWarning(RailadhesionWarning):
    """A calibrated parameter that the measured curves hardly determine, regressed on Q and v
    all the same: the dependence its regression shows is not supported by the data (the
    calibrated adhesion may still reproduce the curves; the set stays trusted)."""


@dataclass(frozen=True, eq=False)
class ConditionCheck:
    """Result of :func:`check_condition` for one WILAC condition.

    Attributes
    ----------
    condition : str
    q_norm, v_norm : ndarray
        The normalised grid [-] (2-D, ``n_grid x n_grid``) over the calibrated ranges.
    raw : dict of str to ndarray
        Each regression on the grid, *before* clipping to the physical bounds.
    fitted_range : dict of str to (float, float)
        Smallest and largest per-curve fitted value of each parameter.
    out_of_bounds : dict of str to float
        Fraction of grid points where a parameter leaves its physical bounds (only > 0 listed).
    excursion : dict of str to float
        How far each parameter leaves the range of its per-curve fits on the grid, in units of
        that range's width (floored at 5 % of the parameter's typical value); 0 inside.
    adhesion_excursion : float
        Largest distance [-] of the calibrated adhesion, at grid points over the (Q, v) box of
        the condition's curves and over the measured creep range, outside the envelope (min to
        max) of the per-curve fitted curves.
    adhesion_worst : tuple
        ``(Q [N], v [m/s], |creep| [-])`` where ``adhesion_excursion`` occurs.
    problems : tuple of str
        Readable findings; empty when the set passed every check.
    undetermined : dict of str to int
        Per parameter, the number of the condition's curves whose own fit hardly determines
        it (standard error not finite or above :data:`~railadhesion.plausibility.
        MAX_RELATIVE_STDERR` times the value; only with ``fitted_stderr``).
    notes : tuple of str
        Parameters the curves hardly determine (in at least half of them) whose regression
        depends on Q or v all the same: the dependence is not supported by the data. Not a
        reason to distrust the set's adhesion, which the checks above compare with the curves.
    """

    condition: str
    q_norm: np.ndarray
    v_norm: np.ndarray
    raw: dict
    fitted_range: dict
    out_of_bounds: dict
    excursion: dict
    adhesion_excursion: float
    adhesion_worst: tuple
    problems: tuple[str, ...] = field(default=())
    undetermined: dict = field(default_factory=dict)
    notes: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """True when nothing was found."""
        return not self.problems


def _clip(values: Mapping[str, np.ndarray], bounds) -> dict:
    return {n: np.clip(values[n], *bounds[n]) for n in _NAMES}


def _semi_axes_law(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> Callable:
    """Hertz scaling a, b ∝ Q^(1/3), its factor fitted to the curves' semi-axes (log mean)."""
    ca = float(np.exp(np.mean(np.log(a) - np.log(q) / 3)))
    cb = float(np.exp(np.mean(np.log(b) - np.log(q) / 3)))
    return lambda qq: (ca * np.cbrt(qq), cb * np.cbrt(qq))


def refine_condition(
    regressions: Mapping[str, ParameterRegression],
    curves: Sequence,
    *,
    q_ref: float,
    v_ref: float,
    q_range: tuple[float, float],
    v_range: tuple[float, float],
    bounds: Mapping[str, tuple[float, float]],
    shear_modulus: float,
    poisson: float,
    n_grid: int = 9,
    penalty: float = 1.0,
) -> tuple[dict, float, float]:
    """Refit every regression coefficient of one condition jointly to the measured adhesion.

    The terms of each regression are kept; their coefficients are fitted together, by
    :func:`scipy.optimize.least_squares`, to the adhesion of all the condition's curves, the
    parameters clipped to ``bounds`` as in the model. Leaving the bounds anywhere on an
    ``n_grid x n_grid`` grid over the calibrated range costs ``penalty`` x the excess (in
    units of the parameter's typical value) per grid point, so the refined regressions stay physical
    between the data points.

    Parameters
    ----------
    regressions : mapping of str to ParameterRegression
        Starting regressions of k_A, k_S, mu0, A, B.
    curves : sequence of (creep, adhesion, Q, v, a, b)
        The condition's measured curves.
    q_ref, v_ref, q_range, v_range
        Normalisation and calibrated ranges [N], [m/s].
    bounds : mapping
        Physical bounds of each parameter (``PHYSICAL_BOUNDS`` of the WILAC model).
    shear_modulus, poisson : float
        Elastic constants [Pa], [-].

    Returns
    -------
    (dict, float, float)
        The refined regressions, and the RMS adhesion residual before and after.
    """
    # quiet: the curves' inputs were checked once, by their fits (no warning per evaluation)
    from railadhesion.models.polach import polach_forces_quiet as polach_forces

    creep = np.concatenate([np.asarray(c[0], float) for c in curves])
    y = np.concatenate([np.asarray(c[1], float) for c in curves])
    per = [np.concatenate([np.full(len(c[0]), float(c[k])) for c in curves]) for k in (2, 3, 4, 5)]
    q, v, a, b = per
    qn, vn = q / q_ref, v / v_ref
    gq, gv = np.meshgrid(
        np.linspace(q_range[0], q_range[1], n_grid) / q_ref,
        np.linspace(v_range[0], v_range[1], n_grid) / v_ref,
    )
    gq, gv = gq.ravel(), gv.ravel()
    design = {n: design_matrix(regressions[n].terms, qn, vn) for n in _NAMES}
    gdesign = {n: design_matrix(regressions[n].terms, gq, gv) for n in _NAMES}
    sizes = [len(regressions[n].terms) for n in _NAMES]
    splits = np.cumsum(sizes)[:-1]
    x0 = np.concatenate([np.asarray(regressions[n].coefficients, float) for n in _NAMES])
    # Penalty scale: the typical size of each parameter (its start on the grid), so that a
    # small excursion of a small parameter (A = -0.005 where A ~ 0.3) is not free.
    width = {
        n: max(float(np.median(np.abs(gdesign[n] @ np.asarray(regressions[n].coefficients)))),
               1e-3)
        for n in _NAMES
    }  # fmt: skip
    # Scale each coefficient by its start (or by 1) so that the optimiser sees O(1) unknowns.
    scale = np.where(np.abs(x0) > 1e-3, np.abs(x0), 1e-3)

    def unpack(x):
        return dict(zip(_NAMES, np.split(x * scale, splits), strict=True))

    def residual(x):
        coefs = unpack(x)
        raw = {n: design[n] @ coefs[n] for n in _NAMES}
        p = _clip(raw, bounds)
        with np.errstate(all="ignore"):
            fx, fy = polach_forces(
                creep, 0.0, 0.0, q, v, a, b, shear_modulus=shear_modulus, poisson=poisson, **p
            )
        model = np.hypot(fx, fy) / q
        pen = []
        for n in _NAMES:
            g = gdesign[n] @ coefs[n]
            lo, hi = bounds[n]
            pen.append(penalty * (np.maximum(lo - g, 0) + np.maximum(g - hi, 0)) / width[n])
        out = np.concatenate([model - y] + pen)
        return np.where(np.isfinite(out), out, 1e3)

    start = x0 / scale
    r0 = residual(start)
    rms0 = float(np.sqrt(np.mean(r0[: y.size] ** 2)))
    res = least_squares(residual, start, method="trf", x_scale="jac", max_nfev=200 * start.size)
    if not (res.cost < 0.5 * float(r0 @ r0)):
        return dict(regressions), rms0, rms0
    coefs = unpack(res.x)
    out = {
        n: ParameterRegression(regressions[n].terms, tuple(float(c) for c in coefs[n]))
        for n in _NAMES
    }
    rms1 = float(np.sqrt(np.mean(res.fun[: y.size] ** 2)))
    return out, rms0, rms1


def check_condition(
    condition: str,
    regressions: Mapping[str, ParameterRegression],
    fitted_values: Mapping[str, np.ndarray],
    curves: Sequence,
    *,
    q_ref: float,
    v_ref: float,
    q_range: tuple[float, float],
    v_range: tuple[float, float],
    bounds: Mapping[str, tuple[float, float]],
    shear_modulus: float,
    poisson: float,
    n_grid: int = 9,
    max_excursion: float = 1.0,
    adhesion_tolerance: float = 0.02,
    contact: Callable | None = None,
    fitted_stderr: Mapping[str, np.ndarray] | None = None,
) -> ConditionCheck:
    """Check one calibrated condition on a grid between the data points.

    Parameters
    ----------
    condition : str
    regressions : mapping of str to ParameterRegression
        The calibrated regressions of k_A, k_S, mu0, A, B.
    fitted_values : mapping of str to array
        The per-curve fitted values of each parameter.
    curves : sequence of (creep, adhesion, Q, v, a, b, predict)
        The condition's curves; ``predict(creep)`` is the curve's own Polach fit.
    q_ref, v_ref, q_range, v_range, bounds, shear_modulus, poisson
        As in :func:`refine_condition`.
    n_grid : int, default 9
        Grid points per axis.
    max_excursion : float, default 1.0
        A parameter is reported when it leaves the range of its per-curve fits by more than
        this fraction of that range's width and spreads over more than ``1 + max_excursion``
        times that width on the grid.
    adhesion_tolerance : float, default 0.02
        The adhesion [-] is reported when it leaves the envelope of the per-curve fitted
        curves (at the same creep) by more than this, on a grid over the (Q, v) box of the
        condition's own curves (outside it the set extrapolates; no curve to compare with).
    contact : callable, optional
        ``contact(Q) -> (a, b)`` [m]; default the Hertz scaling a, b ∝ Q^(1/3) of the curves.
    fitted_stderr : mapping of str to array, optional
        The standard errors of the per-curve fitted values (``inf`` where a fit does not
        estimate one, NaN where the parameter was not fitted): a parameter whose standard
        error is infinite or above
        :data:`~railadhesion.plausibility.MAX_RELATIVE_STDERR` times its value in at least
        half of the curves (e.g. B when A is near 1: the friction hardly falls) and whose
        regression has a Q or v term gets a note (:attr:`ConditionCheck.notes`).

    Returns
    -------
    ConditionCheck
    """
    # quiet: the curves' inputs were checked once, by their fits (no warning per evaluation)
    from railadhesion.models.polach import polach_forces_quiet as polach_forces

    gq, gv = np.meshgrid(
        np.linspace(q_range[0], q_range[1], n_grid) / q_ref,
        np.linspace(v_range[0], v_range[1], n_grid) / v_ref,
    )
    raw = {n: np.asarray(regressions[n](gq, gv), float) * np.ones_like(gq) for n in _NAMES}
    problems = []
    fitted_range, out_of_bounds, excursion = {}, {}, {}
    for n in _NAMES:
        vals = np.asarray(fitted_values[n], float)
        lo_f, hi_f = float(np.min(vals)), float(np.max(vals))
        fitted_range[n] = (lo_f, hi_f)
        lo, hi = bounds[n]
        # tolerance: 2 % of the parameter's typical size (rounding-level excursions are harmless)
        tol = 0.02 * max(abs(lo_f), abs(hi_f), 1e-6)
        frac = float(np.mean((raw[n] < lo - tol) | (raw[n] > hi + tol)))
        if frac > 0:
            out_of_bounds[n] = frac
            problems.append(
                f"{condition}.{n} leaves its physical bounds [{lo:g}, {hi:g}] at "
                f"{100 * frac:.0f} % of the grid (raw {raw[n].min():.4g} to {raw[n].max():.4g};"
                " the model clips it)"
            )
        width = max(hi_f - lo_f, 0.05 * max(abs(lo_f), abs(hi_f)), 1e-6 * (hi - lo))
        exc = max(float(raw[n].max()) - hi_f, lo_f - float(raw[n].min()), 0.0) / width
        excursion[n] = exc
        spread = float(raw[n].max() - raw[n].min()) / width
        # "wild": beyond the fitted range *and* spread wider than the fits (a constant moved
        # by the joint refinement is a trade-off between parameters, not a swing)
        if exc > max_excursion and spread > 1 + max_excursion:
            problems.append(
                f"{condition}.{n} varies wildly between the data: {raw[n].min():.4g} to "
                f"{raw[n].max():.4g} on the grid, per-curve fits {lo_f:.4g} to {hi_f:.4g}"
            )
    # parameters the curves hardly determine, regressed on Q and v all the same
    undetermined, notes = {}, []
    for n in _NAMES if fitted_stderr is not None else ():
        vals = np.asarray(fitted_values[n], float)
        err = np.asarray(fitted_stderr[n], float)
        with np.errstate(invalid="ignore"):  # NaN: not fitted, not judged
            loose = np.isinf(err) | (err > MAX_RELATIVE_STDERR * np.abs(vals))
        count = int(np.count_nonzero(loose))
        undetermined[n] = count
        if vals.size >= 2 and 2 * count >= vals.size and tuple(regressions[n].terms) != ("1",):
            lo_f, hi_f = fitted_range[n]
            notes.append(
                f"{condition}.{n} is hardly determined by the data (standard error above "
                f"{MAX_RELATIVE_STDERR:g} x the value in {count} of {vals.size} curves; per-curve "
                f"fits {lo_f:.4g} to {hi_f:.4g}), yet regressed on Q and v: "
                f"{regressions[n].formula()} gives {raw[n].min():.4g} to "
                f"{raw[n].max():.4g} over the calibrated range, a dependence the data do not "
                "support; the adhesion is checked against the curves, the parameter's values "
                "are not physical information"
            )
    # adhesion against the envelope of the measured (per-curve fitted) curves
    mags = np.concatenate([np.abs(np.asarray(c[0], float)) for c in curves])
    mags = mags[mags > 0]
    creep = -np.geomspace(max(mags.min(), 1e-4), mags.max(), 12)
    env = np.array([np.asarray(c[6](creep), float) for c in curves])
    env_lo, env_hi = env.min(axis=0), env.max(axis=0)
    q_arr = np.array([float(c[2]) for c in curves])
    law = contact or _semi_axes_law(
        q_arr, np.array([float(c[4]) for c in curves]), np.array([float(c[5]) for c in curves])
    )
    # Adhesion: on a grid over the box of this condition's own curves (outside it the set is
    # extrapolated and measured curves give no envelope to compare with).
    v_arr = np.array([float(c[3]) for c in curves])
    bq, bv = np.meshgrid(
        np.unique(np.linspace(q_arr.min(), q_arr.max(), n_grid)),
        np.unique(np.linspace(v_arr.min(), v_arr.max(), n_grid)),
    )
    gqf, gvf = bq.ravel(), bv.ravel()
    pars = _clip(
        {n: np.asarray(regressions[n](gqf / q_ref, gvf / v_ref), float) * np.ones_like(gqf)
         for n in _NAMES},
        bounds,
    )  # fmt: skip
    ab = [law(qq) for qq in gqf]
    aa = np.array([float(x[0]) for x in ab])[:, None]
    bb = np.array([float(x[1]) for x in ab])[:, None]
    with np.errstate(all="ignore"):
        fx, fy = polach_forces(
            creep[None, :], 0.0, 0.0, gqf[:, None], gvf[:, None], aa, bb,
            shear_modulus=shear_modulus, poisson=poisson,
            **{n: pars[n][:, None] for n in _NAMES},
        )  # fmt: skip
    mu = np.hypot(fx, fy) / gqf[:, None]
    outside = np.maximum(env_lo[None, :] - mu, 0) + np.maximum(mu - env_hi[None, :], 0)
    k = int(np.argmax(outside))
    i, j = np.unravel_index(k, outside.shape)
    adh_exc = float(outside.ravel()[k])
    worst = (float(gqf[i]), float(gvf[i]), float(-creep[j]))
    if adh_exc > adhesion_tolerance:
        problems.append(
            f"{condition}: between the data the calibrated adhesion leaves the envelope of the "
            f"measured curves by {adh_exc:.3f} (at Q = {worst[0]:.4g} N, v = {worst[1]:.3g} "
            f"m/s, creep {100 * worst[2]:.2g} %: {mu[i, j]:.3f} against "
            f"{env_lo[j]:.3f} to {env_hi[j]:.3f})"
        )
    return ConditionCheck(
        condition=condition,
        q_norm=gq,
        v_norm=gv,
        raw=raw,
        fitted_range=fitted_range,
        out_of_bounds=out_of_bounds,
        excursion=excursion,
        adhesion_excursion=adh_exc,
        adhesion_worst=worst,
        problems=tuple(problems),
        undetermined=undetermined,
        notes=tuple(notes),
    )
