"""The synthetic-folder experiment of issue 9: a WILAC calibration must not overfit.

36 synthetic creep curves from the package's default WILAC set (w = 0/25/40/350 µl/s x
Q = 3/4.2/6 kN x v = 2/5/10 m/s, tram rig contact, adhesion noise sigma = 0.004; 10 creep
points per curve to keep the run time modest). Between the data points (Q = 3.6 and 5 kN,
v = 3.5 and 7.5 m/s, all four flow rates, creep 0.5-30 %) the calibrated set must stay within
0.03 of the generating model in adhesion, or the calibration must say loudly (a
CalibrationWarning naming the condition) that it cannot be trusted there. Before the fix the
paper's R² rule put 8-term regressions through 9 points and the set deviated by up to 0.8.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from railadhesion.calibration import (
    CalibrationWarning,
    UndeterminedParameterWarning,
    run_wilac_calibration,
)
from railadhesion.calibration.regression import build_regression
from railadhesion.contact import contact_semi_axes
from railadhesion.io import CreepCurve
from railadhesion.models.wilac import (
    WILAC_CONDITIONS,
    default_wilac_parameters,
    wilac_forces,
    wilac_weights,
)

#: The synthetic truth is the default WILAC set evaluated at 3 kN, below its calibrated loads
#: (from 4.2 kN), where it holds its parameters at 4.2 kN with an AlteredResultWarning: that is
#: the truth the calibration is asked to recover here, not a careless input.
pytestmark = pytest.mark.filterwarnings("ignore::railadhesion.plausibility.AlteredResultWarning")

FLOWS = (0.0, 25.0, 40.0, 350.0)  # µl/s
LOADS = (3e3, 4.2e3, 6e3)  # N
SPEEDS = (2.0, 5.0, 10.0)  # m/s
BETWEEN_LOADS = (3.6e3, 5e3)
BETWEEN_SPEEDS = (3.5, 7.5)
TOLERANCE = 0.03  # adhesion, issue 9


def _synthetic_curves(seed: int = 1, n_creep: int = 10) -> list[CreepCurve]:
    rng = np.random.default_rng(seed)
    truth = default_wilac_parameters()
    creep = -np.geomspace(0.003, 0.6, n_creep)
    curves = []
    for w in FLOWS:
        for q in LOADS:
            for v in SPEEDS:
                a, b = contact_semi_axes("tram", q)
                fx, _ = wilac_forces(creep, 0.0, 0.0, q, v, a, b, w, truth)
                mu = np.abs(np.abs(fx) / q + rng.normal(0.0, 0.004, creep.size))
                curves.append(CreepCurve(creep, mu, normal_force=q, speed=v, water_flow=w,
                                         a=a, b=b, name=f"w{w:g}_Q{q:g}_v{v:g}"))  # fmt: skip
    return curves


def _deviations(params) -> list[tuple[float, float, float, float]]:
    """(w, Q, v, max |adhesion difference|) at the points between the data."""
    truth = default_wilac_parameters()
    creep = -np.geomspace(0.005, 0.3, 12)
    out = []
    for w in FLOWS:
        for q in BETWEEN_LOADS:
            for v in BETWEEN_SPEEDS:
                a, b = contact_semi_axes("tram", q)
                f0, _ = wilac_forces(creep, 0.0, 0.0, q, v, a, b, w, truth)
                f1, _ = wilac_forces(creep, 0.0, 0.0, q, v, a, b, w, params)
                out.append((w, q, v, float(np.max(np.abs(f1 - f0)) / q)))
    return out


def _check_trusted_or_loud(result) -> float:
    """Every deviation > TOLERANCE must be announced for its dominant condition."""
    worst = 0.0
    for w, q, v, dev in _deviations(result.parameters):
        worst = max(worst, dev)
        if dev > TOLERANCE:
            cond = WILAC_CONDITIONS[int(np.argmax(wilac_weights(w)))]
            assert any(msg.startswith(cond) for msg in result.warnings), (w, q, v, dev)
    return worst


@pytest.fixture(scope="module")
def curves():
    return _synthetic_curves()


def test_default_calibration_stays_close_between_the_data(curves):
    with warnings.catch_warnings():
        warnings.simplefilter("error", CalibrationWarning)  # a warning would fail loudly too
        # damp1's B is hardly determined by these curves (A near 1 hides it): noted, not a
        # reason to distrust the set
        warnings.simplefilter("ignore", UndeterminedParameterWarning)
        try:
            result = run_wilac_calibration(curves)
        except CalibrationWarning:  # pragma: no cover - allowed by the issue, then checked
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", CalibrationWarning)
                result = run_wilac_calibration(curves)
    assert all(note.split(" ")[0] == "damp1.B" for note in result.notes)
    worst = _check_trusted_or_loud(result)
    # measured here: 0.004-0.011 over seeds 1-3 (0.09 before the fix, 20-point curves)
    if result.trusted:
        assert worst <= TOLERANCE
    # never more terms than one per three curves (9 curves per condition -> at most 3)
    for cond in WILAC_CONDITIONS:
        for name, reg in result.parameters.conditions[cond].regressions().items():
            assert len(reg.terms) <= 3, (cond, name, reg.terms)
    # the per-curve reproduction report: every curve, both errors, in the summary
    table = result.curve_table()
    assert len(table) == 36
    assert all(row["calibrated_max_error"] >= row["calibrated_rmse"] > 0 for row in table)
    assert all(row["calibrated_rmse"] < 0.02 for row in table)
    text = result.summary()
    assert "w40_Q4200_v5" in text and "calibrated set RMSE" in text


def test_paper_rule_overfits_and_the_check_says_so(curves):
    """The paper's R² rule without the guards (many terms, no refinement) goes wrong between
    the data; the check must announce it."""
    with pytest.warns(UndeterminedParameterWarning, match=r"^damp1\.B is hardly determined"), \
            pytest.warns(CalibrationWarning, match="cannot be trusted"):  # fmt: skip
        result = run_wilac_calibration(
            curves, criterion="r2", max_terms=8, refine=False, regression_atol=None
        )
    assert not result.trusted
    worst = _check_trusted_or_loud(result)
    assert worst > TOLERANCE  # it really is wrong somewhere (measured: 0.14)
    assert "do NOT trust" in result.summary()
    checks = result.checks
    assert set(checks) == set(WILAC_CONDITIONS)
    assert any(chk.out_of_bounds for chk in checks.values())
    assert max(chk.adhesion_excursion for chk in checks.values()) > 0.02


def test_progress_is_reported(curves):
    seen = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationWarning)  # 2-3 curves per condition
        run_wilac_calibration(
            curves[::4], check_grid=3, progress=lambda *step: seen.append(step)
        )
    assert ("fit", 0, 9) in seen and ("fit", 9, 9) in seen
    assert ("regress", 4, 4) in seen and ("check", 4, 4) in seen
    with pytest.raises(ValueError, match="progress must be callable"):
        run_wilac_calibration(curves, progress=3)


def test_cross_validation_refuses_noise_terms():
    rng = np.random.default_rng(0)
    q, v = np.meshgrid([0.5, 0.7, 1.0], [0.2, 0.5, 1.0])
    y = 0.4 + 0.01 * rng.standard_normal(q.shape)  # a constant with noise, 9 points
    paper = build_regression(q, v, y, criterion="r2")
    assert len(paper.terms) >= 4  # the R² rule models the noise
    for criterion in ("cv", "aicc", "bic"):
        fit = build_regression(q, v, y, criterion=criterion)
        assert len(fit.terms) < len(paper.terms), criterion
    # a real trend is still found
    trend = build_regression(q, v, 0.3 + 0.2 * q + 1e-4 * rng.standard_normal(q.shape),
                             criterion="cv")  # fmt: skip
    assert "Q" in trend.terms
    with pytest.raises(ValueError, match="criterion"):
        build_regression(q, v, y, criterion="adjusted")
