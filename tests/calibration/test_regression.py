"""Tests of the WILAC regression builder (seed 000 §5.2: forward selection, R² gain >= 1e-4)."""

from __future__ import annotations

import numpy as np
import pytest
import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.calibration.regression import build_regression
from railadhesion.models.regression import ParameterRegression, candidate_terms

# Normalised grid: Q' = Q/Q_max, v' = v/v_max (seed 000 §5.2), 6 x 6 points.
Q_GRID, V_GRID = np.meshgrid(np.linspace(0.2, 1.0, 6), np.linspace(0.1, 1.0, 6))


def _known(q, v):
    return 0.3 + 0.2 * q - 0.1 / v + 0.05 * q * np.exp(v)


@pytest.mark.parametrize("method", ["forward", "floating"])
def test_recovers_known_sparse_formula(method):
    rng = np.random.default_rng(3)
    y = _known(Q_GRID, V_GRID) + 1e-6 * rng.standard_normal(Q_GRID.shape)
    fit = build_regression(Q_GRID, V_GRID, y, method=method)
    assert set(fit.terms) == {"1", "Q", "1/v", "Q*exp(v)"}
    assert fit.terms[0] == "1"
    coef = dict(zip(fit.terms, fit.coefficients, strict=True))
    expected = {"1": 0.3, "Q": 0.2, "1/v": -0.1, "Q*exp(v)": 0.05}
    for term, value in expected.items():
        assert abs(coef[term] - value) < 1e-3, term
    assert fit.r_squared > 1 - 1e-9
    assert fit.history[-1].accepted is False  # the selection stopped on the gain rule
    assert fit.history[-1].gain < 1e-4
    assert isinstance(fit.regression, ParameterRegression)
    np.testing.assert_allclose(fit(Q_GRID, V_GRID), _known(Q_GRID, V_GRID), atol=1e-5)


def test_history_and_residual_invariants():
    rng = np.random.default_rng(7)
    y = 0.5 + 0.1 * np.sin(3 * Q_GRID) * V_GRID + 0.01 * rng.standard_normal(Q_GRID.shape)
    fit = build_regression(Q_GRID, V_GRID, y)
    adds = [s for s in fit.history if s.action == "add"]
    assert all(s.gain >= 1e-4 for s in adds if s.accepted)
    assert all(s.gain < 1e-4 for s in adds if not s.accepted)
    r2 = [s.r_squared for s in adds if s.accepted]
    assert all(b >= a for a, b in zip(r2, r2[1:], strict=False))
    # the chosen terms are the accepted ones, in order
    assert list(fit.terms[1:]) == [s.term for s in adds if s.accepted]
    # R² and residuals recomputed independently
    resid = y.ravel() - np.asarray(fit(Q_GRID, V_GRID)).ravel()
    np.testing.assert_allclose(fit.residuals, resid, atol=1e-12)
    ss_tot = np.sum((y - y.mean()) ** 2)
    assert fit.r_squared == pytest.approx(1 - np.sum(resid**2) / ss_tot, abs=1e-9)
    assert fit.regression.r_squared == pytest.approx(fit.r_squared)
    assert fit.n_samples == y.size


def test_higher_threshold_gives_fewer_terms():
    y = _known(Q_GRID, V_GRID) + 0.002 * np.cos(7 * Q_GRID * V_GRID)
    loose = build_regression(Q_GRID, V_GRID, y, min_r2_gain=1e-6)
    strict = build_regression(Q_GRID, V_GRID, y, min_r2_gain=1e-2)
    assert len(strict.terms) < len(loose.terms)
    assert all(s.gain >= 1e-2 for s in strict.history if s.accepted and s.action == "add")


def test_atol_stops_before_modelling_noise():
    rng = np.random.default_rng(11)
    noise = 0.01 * rng.standard_normal(Q_GRID.shape)
    y = 0.4 + 0.1 * Q_GRID + noise
    plain = build_regression(Q_GRID, V_GRID, y)
    assert len(plain.terms) > 2  # the R² rule alone fits noise terms
    fit = build_regression(Q_GRID, V_GRID, y, atol=0.012)
    assert fit.terms == ("1", "Q")
    assert fit.stop_reason == "RMS residual <= atol"
    flat = build_regression(Q_GRID, V_GRID, 0.4 + noise, atol=0.02)
    assert flat.terms == ("1",)


def test_constant_y_gives_the_constant():
    fit = build_regression(Q_GRID, V_GRID, np.full(Q_GRID.shape, 0.37))
    assert fit.terms == ("1",)
    assert fit.coefficients[0] == pytest.approx(0.37)
    assert fit.r_squared == 1.0
    assert fit.stop_reason == "y is constant"


def test_term_limits():
    y = _known(Q_GRID, V_GRID)
    assert len(build_regression(Q_GRID, V_GRID, y, max_terms=2).terms) == 2
    # 4 samples: at most 3 terms (one residual degree of freedom kept)
    q4, v4 = np.array([0.5, 1.0, 0.5, 1.0]), np.array([0.5, 0.5, 1.0, 1.0])
    fit = build_regression(q4, v4, _known(q4, v4))
    assert len(fit.terms) <= 3
    assert len(build_regression([1.0, 0.5], [1.0, 0.5], [0.2, 0.3]).terms) == 1
    assert len(build_regression(1.0, 1.0, 0.2).terms) == 1


def test_ill_conditioned_candidates_are_skipped():
    # Over a narrow range Q and exp(Q) are almost collinear with the intercept.
    q, v = np.meshgrid(np.linspace(0.99999, 1.0, 4), np.linspace(0.5, 1.0, 4))
    y = 1.0 + 0.3 * v + 1e-3 * np.sin(50 * v)
    fit = build_regression(q, v, y, candidates=["Q", "exp(Q)", "v"], max_condition=1e4)
    assert "Q" not in fit.terms and "exp(Q)" not in fit.terms
    assert "v" in fit.terms
    assert fit.history[0].n_skipped == 2
    assert fit.condition_number <= 1e4


def test_candidate_pool_is_the_models_grammar():
    # order 1: the six factors, nothing else
    fit = build_regression(Q_GRID, V_GRID, 0.2 + 0.1 * np.exp(Q_GRID), max_order=1)
    assert set(fit.terms) <= {"1", *candidate_terms(1)}
    assert "exp(Q)" in fit.terms


def test_to_dict_serialises_and_round_trips():
    fit = build_regression(Q_GRID, V_GRID, _known(Q_GRID, V_GRID))
    data = fit.to_dict()
    text = tomli_w.dumps(data)  # TOML-serialisable
    assert "history" in text
    back = ParameterRegression.from_dict(data["regression"])
    np.testing.assert_allclose(back(Q_GRID, V_GRID), fit(Q_GRID, V_GRID), rtol=1e-14)
    assert data["history"][0]["action"] == "add"
    assert "R^2" in str(fit)


@pytest.mark.parametrize(
    ("args", "kwargs", "pattern"),
    [
        ((0.0, 1.0, 1.0), {}, r"q_norm must be in \(0, inf\)"),
        ((1.0, -1.0, 1.0), {}, r"v_norm must be in \(0, inf\)"),
        ((1.0, 1.0, np.nan), {}, r"y must be finite"),
        (([1.0, 0.5], [1.0, 0.5, 0.2], 1.0), {}, r"must broadcast together"),
        ((1.0, 1.0, 1.0), {"min_r2_gain": -1}, r"min_r2_gain must be in"),
        ((1.0, 1.0, 1.0), {"method": "backward"}, r"method must be one of"),
        ((1.0, 1.0, 1.0), {"max_terms": 0}, r"max_terms must be an integer >= 1"),
        ((1.0, 1.0, 1.0), {"candidates": ["Q", "T"]}, r"unknown factor 'T'"),
    ],
)
def test_bad_input(args, kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        build_regression(*args, **kwargs)


@settings(max_examples=50, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(0.01, 100.0),
    offset=st.floats(-10.0, 10.0),
)
def test_affine_invariance(seed, scale, offset):
    """R² is invariant to y -> scale*y + offset: same terms; coefficients transform."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(0.2, 1.0, 20)
    v = rng.uniform(0.2, 1.0, 20)
    y = rng.uniform(0.0, 1.0, 20)
    base = build_regression(q, v, y, max_order=1, max_terms=4)
    moved = build_regression(q, v, scale * y + offset, max_order=1, max_terms=4)
    assert moved.terms == base.terms
    expected = np.array(base.coefficients) * scale
    expected[0] += offset
    np.testing.assert_allclose(moved.coefficients, expected, rtol=1e-6, atol=1e-8 * (1 + scale))
    assert moved.r_squared == pytest.approx(base.r_squared, abs=1e-9)


def test_unnormalised_regressors_do_not_warn():
    """exp(Q') of an unnormalised Q' overflows; the column is skipped without a warning
    (before: RuntimeWarning 'overflow encountered in exp', an error under the test config)."""
    import warnings

    q = np.array([1e3, 2e3, 3e3, 4e3, 5e3])
    v = np.array([0.5, 0.6, 0.7, 0.8, 0.9])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = build_regression(q, v, 0.1 + 0.2 * v)
    assert all("exp(Q)" not in t for t in fit.terms)
    assert fit(q, v) == pytest.approx(0.1 + 0.2 * v, abs=1e-9)
