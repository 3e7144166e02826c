"""Tests of the Polach and Fletcher fits (railadhesion.calibration.fitting).

Synthetic curves are generated with the models themselves (railadhesion.models.polach,
railadhesion.models.twod) from known parameters; the fits must recover them.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from railadhesion.calibration.fitting import FitResult, fit_fletcher, fit_polach
from railadhesion.models.parameters import PolachParameters
from railadhesion.models.polach import polach_forces
from railadhesion.models.twod import fletcher
from railadhesion.plausibility import UntrustedResultWarning

Q, V, A_SEMI, B_SEMI = 4200.0, 5.0, 4e-3, 3e-3  # tram-rig-like load and speed (seed 000 §4)
CREEP = -np.geomspace(5e-4, 0.6, 60)  # traction, 0.05 % to 60 %
NAMES = ("k_A", "k_S", "mu0", "A", "B")

# Fletcher (2013, seed 001): 47 mm discs, R = 11.75 mm; a = 0.204 mm at 1000 MPa (§2);
# Table 1 mu and Table 2 k_a (k_s = 1) of tests O1 (oil) and W1 (water).
FLETCHER_R, FLETCHER_A = 11.75e-3, 0.204e-3
FLETCHER_CASES = {"O1": (0.055, 0.193), "W1": (0.24, 0.805)}


def _adhesion(creep, **params):
    fx, fy = polach_forces(creep, 0.0, 0.0, Q, V, A_SEMI, B_SEMI, **params)
    return np.hypot(fx, fy) / Q


def _fit(creep, y, **kw):
    return fit_polach(creep, y, normal_force=Q, speed=V, a=A_SEMI, b=B_SEMI, **kw)


@pytest.mark.parametrize(
    "true",
    [
        dict(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6),  # Polach 2005 "dry" (MODELS.md §3)
        dict(k_A=0.3, k_S=0.1, mu0=0.3, A=0.4, B=0.2),  # Polach 2005 "wet"
        dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5),
    ],
)
def test_polach_noise_free_recovery(true):
    res = _fit(CREEP, _adhesion(CREEP, **true))
    assert res.success
    for name in NAMES:
        assert res.params[name] == pytest.approx(true[name], rel=1e-4, abs=1e-6), name
    assert res.rmse < 1e-6
    assert res.r_squared > 1 - 1e-9
    assert res.n_points == CREEP.size
    np.testing.assert_allclose(res.predict(), _adhesion(CREEP, **true), atol=1e-6)


@pytest.mark.parametrize(
    "true",
    [
        dict(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6),
        dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5),
    ],
)
def test_polach_noisy_recovery(true):
    """Noise sigma = 0.005 in adhesion (a quarter of the rig's 0.02 uncertainty, seed 000 §4).

    Reached over 20 seeds in development: k_A within 8 %, k_S within 5 %, mu0 within 1.5 %,
    A and B within 25 %; standard errors consistent (std of z-scores 0.7-1.2).
    Asserted here, seed 0: k_A, k_S within 10 %, mu0 within 3 %, A, B within 35 %, every
    parameter within 4 standard errors of the truth.
    """
    rng = np.random.default_rng(0)
    clean = _adhesion(CREEP, **true)
    for _ in range(3):
        y = np.abs(clean + 0.005 * rng.standard_normal(CREEP.size))
        res = _fit(CREEP, y)
        tol = {"k_A": 0.10, "k_S": 0.10, "mu0": 0.03, "A": 0.35, "B": 0.35}
        for name in NAMES:
            assert abs(res.params[name] / true[name] - 1) < tol[name], (name, res.params)
            z = (res.params[name] - true[name]) / res.stderr[name]
            assert abs(z) < 4, (name, z)
        # the optimum is at least as good as the truth
        assert np.sum(res.residuals**2) <= np.sum((clean - y) ** 2) * (1 + 1e-9)
        assert 0.004 < res.rmse < 0.006


def test_polach_subset_and_fixed_values():
    true = dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5)
    y = _adhesion(CREEP, **true)
    res = _fit(CREEP, y, fit=("mu0", "k_S"), initial={"k_A": 0.6, "A": 0.4, "B": 0.5})
    assert res.fitted == ("k_S", "mu0")
    assert set(res.stderr) == {"k_S", "mu0"}
    assert res.params["mu0"] == pytest.approx(0.4, rel=1e-5)
    assert res.params["k_S"] == pytest.approx(0.2, rel=1e-5)
    assert (res.params["k_A"], res.params["A"], res.params["B"]) == (0.6, 0.4, 0.5)
    assert res.covariance.shape == (2, 2)
    # A fixed parameter not given takes the model default: here B = 0 (constant friction).
    with pytest.warns(UntrustedResultWarning, match=r"R\^2 = 0.4\d+ is below 0.9"):
        res2 = _fit(CREEP, y, fit=("mu0",), initial={"k_A": 0.6, "k_S": 0.2, "A": 0.4})
    assert not res2.trusted
    assert res2.params["B"] == 0.0
    assert res2.rmse > 0.01  # the falling friction cannot be represented without B
    with pytest.raises(ValueError, match="mu0 is not fitted"):
        _fit(CREEP, y, fit=("k_A",))


def test_polach_initial_from_parameter_set_and_as_polach_parameters():
    dry = PolachParameters(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    y = _adhesion(CREEP, **dry.as_dict())
    res = _fit(CREEP, y, fit=("mu0",), initial=dry.replace(mu0=0.3))
    assert res.params["mu0"] == pytest.approx(0.55, rel=1e-6)
    p = res.as_polach_parameters(name="fitted")
    assert isinstance(p, PolachParameters)
    assert p.name == "fitted" and "fit_polach" in p.source
    assert p.as_dict() == pytest.approx(dry.as_dict(), rel=1e-6)


def test_polach_sign_of_creep_is_irrelevant_and_per_point_conditions():
    true = dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5)
    y = _adhesion(CREEP, **true)
    neg, pos = _fit(CREEP, y), _fit(-CREEP, y)
    for name in NAMES:
        assert neg.params[name] == pytest.approx(pos.params[name], rel=1e-6)
    # Two curves at different speeds fitted together, speed given per point.
    speeds = np.repeat([3.0, 8.0], CREEP.size)
    creep2 = np.tile(CREEP, 2)
    fx, _ = polach_forces(creep2, 0.0, 0.0, Q, speeds, A_SEMI, B_SEMI, **true)
    res = fit_polach(creep2, np.abs(fx) / Q, normal_force=Q, speed=speeds, a=A_SEMI, b=B_SEMI)
    for name in NAMES:
        assert res.params[name] == pytest.approx(true[name], rel=1e-4), name
    assert res.conditions["speed"].shape == (2 * CREEP.size,)


def test_polach_bounds_respected_and_reported():
    true = dict(k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5)
    y = _adhesion(CREEP, **true)
    fit = ("k_A", "k_S", "mu0")
    with pytest.warns(UntrustedResultWarning, match="mu0 = 0.3 is on a bound of the search"):
        res = _fit(CREEP, y, fit=fit, initial={"A": 0.4, "B": 0.5}, bounds={"mu0": (0.1, 0.3)})
    assert not res.trusted and "NOT TRUSTED" in res.summary()
    assert 0.1 <= res.params["mu0"] <= 0.3
    assert "mu0" in res.at_bound
    assert "at a bound" in res.message
    text = str(res)
    assert "Polach fit" in text and "mu0" in text and "(at bound)" in text


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        (dict(fit=("k_A", "C")), r"unknown Polach parameter 'C'"),
        (dict(fit=()), r"fit must name at least one"),
        (dict(fit=("mu0", "mu0")), r"twice"),
        (dict(bounds={"mu0": (0.5, 0.1)}), r"bounds\['mu0'\] must satisfy low < high"),
        (dict(bounds={"D": (0, 1)}), r"bounds: unknown parameter"),
        (dict(initial={"kA": 1.0}), r"initial: unknown parameter"),
        (dict(normal_force=-1.0), r"normal_force must be in"),
        (dict(speed=np.ones(3)), r"speed must be a scalar or hold one value per point"),
    ],
)
def test_polach_bad_input(kwargs, pattern):
    base = dict(normal_force=Q, speed=V, a=A_SEMI, b=B_SEMI)
    base.update(kwargs)
    with pytest.raises(ValueError, match=pattern):
        fit_polach(CREEP, _adhesion(CREEP, mu0=0.3), **base)


def test_polach_data_checks():
    with pytest.raises(ValueError, match="same number of points"):
        _fit(CREEP, np.ones(3))
    with pytest.raises(ValueError, match="adhesion must be in"):
        _fit(CREEP, -np.ones(CREEP.size))
    with pytest.raises(ValueError, match="more points than fitted parameters"):
        _fit(CREEP[:5], np.full(5, 0.1))


@settings(max_examples=25, deadline=None)
@given(
    k_A=st.floats(0.05, 1.0),
    ratio=st.floats(0.1, 1.0),
    mu0=st.floats(0.1, 0.6),
    A=st.floats(0.2, 0.9),
    B=st.floats(0.1, 2.0),
)
# found by hypothesis: k_S an eighth of k_A, a curve still rising at 60 % creep (a local
# minimum near k_S/k_A = 0.3 caught every start until the (0.05, 0.005) pair was added)
@example(k_A=0.0625, ratio=0.125, mu0=0.5, A=0.5, B=2.0)
# and: a slow rise (k_S = 0.11 k_A) that hides a fall to A = 0.5 (the tail/peak guess says A ~ 1)
@example(k_A=0.0508, ratio=0.109, mu0=0.5, A=0.5, B=1.5)
def test_polach_noise_free_curves_are_reproduced(k_A, ratio, mu0, A, B):
    """Property: a noise-free Polach curve is fitted to (near) zero residual (whether the gate
    trusts it, e.g. with few points before an early peak, is not what this checks)."""
    y = _adhesion(CREEP, k_A=k_A, k_S=ratio * k_A, mu0=mu0, A=A, B=B)
    res = _fit(CREEP, y, warn_untrusted=False)
    assert res.rmse < 1e-4 * mu0


# ---------------------------------------------------------------------------------------------
# Fletcher


def _fletcher_adhesion(xi, mu, k_a, k_s=1.0):
    return np.abs(fletcher(xi, 1.0, FLETCHER_A, FLETCHER_R, mu, k_a=k_a, k_s=k_s).traction)


@pytest.mark.parametrize("code", sorted(FLETCHER_CASES))
def test_fletcher_recovers_table2_k_a(code):
    """k_a of Fletcher's Table 2 (k_s = 1, mu from Table 1) recovered from noisy synthetic data.

    Creep 0-1 % as in his tests (§2); noise sigma = 0.02 mu. Reached: k_a within 4 %.
    """
    mu, k_a = FLETCHER_CASES[code]
    xi = np.linspace(1e-4, 0.01, 50)
    rng = np.random.default_rng(1)
    y = np.abs(_fletcher_adhesion(xi, mu, k_a) + 0.02 * mu * rng.standard_normal(xi.size))
    res = fit_fletcher(xi, y, half_width=FLETCHER_A, radius=FLETCHER_R, fit=("k_a",), mu=mu)
    assert isinstance(res, FitResult) and res.model == "fletcher"
    assert res.params["k_a"] == pytest.approx(k_a, rel=0.04)
    assert res.params["k_s"] == 1.0 and res.params["mu"] == mu
    assert abs(res.params["k_a"] - k_a) < 4 * res.stderr["k_a"]


def test_fletcher_recovers_k_a_and_k_s_beyond_full_slip():
    mu, k_a, k_s = 0.3, 0.5, 0.8
    xi = -np.linspace(1e-4, 0.01, 40)  # signed creep: magnitudes are compared
    y = _fletcher_adhesion(xi, mu, k_a, k_s)
    res = fit_fletcher(xi, y, half_width=FLETCHER_A, radius=FLETCHER_R, mu=mu)
    assert res.params["k_a"] == pytest.approx(k_a, rel=1e-5)
    assert res.params["k_s"] == pytest.approx(k_s, rel=1e-5)
    # Fitting mu instead of k_s (k_s fixed at 1) finds the identifiable product k_s * mu.
    res2 = fit_fletcher(xi, y, half_width=FLETCHER_A, radius=FLETCHER_R, fit=("k_a", "mu"))
    assert res2.params["mu"] == pytest.approx(k_s * mu, rel=1e-5)
    assert res2.params["k_a"] == pytest.approx(k_a, rel=1e-5)
    with pytest.raises(ValueError, match="needs a Polach fit"):
        res.as_polach_parameters()


def test_fletcher_bad_input():
    xi = np.linspace(1e-4, 0.01, 20)
    y = _fletcher_adhesion(xi, 0.2, 0.5)
    kw = dict(half_width=FLETCHER_A, radius=FLETCHER_R)
    with pytest.raises(ValueError, match="both 'k_s' and 'mu'"):
        fit_fletcher(xi, y, fit=("k_s", "mu"), **kw)
    with pytest.raises(ValueError, match="mu must be given"):
        fit_fletcher(xi, y, **kw)
    with pytest.raises(ValueError, match="unknown Fletcher parameter"):
        fit_fletcher(xi, y, fit=("k_A",), mu=0.2, **kw)
    with pytest.raises(ValueError, match="half_width must be in"):
        fit_fletcher(xi, y, mu=0.2, half_width=0.0, radius=FLETCHER_R)


# ---- degenerate data, bounds outside the model's domain, bad fixed/initial values (audit)


@pytest.mark.parametrize("fit_fn", ["polach", "fletcher"])
def test_degenerate_curves_are_value_errors(fit_fn):
    """No creepage or a flat adhesion cannot determine a curve: a clear ValueError, not a
    'converged' fit with R^2 = -5e31 (as before)."""
    def run(creep, y):
        if fit_fn == "polach":
            return _fit(creep, y)
        return fit_fletcher(creep, y, half_width=FLETCHER_A, radius=FLETCHER_R, mu=0.2)

    with pytest.raises(ValueError, match=r"creep is 0 at all 10 points"):
        run(np.zeros(10), np.full(10, 0.2))
    with pytest.raises(ValueError, match=r"adhesion is the same \(0\.2\) at all"):
        run(CREEP, np.full(CREEP.size, 0.2))
    with pytest.raises(ValueError, match=r"adhesion is the same \(0\) at all"):
        run(CREEP, np.zeros(CREEP.size))


@pytest.mark.parametrize(
    ("bounds", "pattern"),
    [
        ({"A": (-1.0, 1.0)}, r"bounds\['A'\]: low must be >= 0 \(A must be in \[0, inf\)"),
        ({"k_S": (-1.0, 1.0)}, r"bounds\['k_S'\]: low must be >= 0"),
        ({"B": (-np.inf, 10.0)}, r"bounds\['B'\]: low must be >= 0"),
    ],
)
def test_polach_bounds_outside_the_model_domain_are_rejected(bounds, pattern):
    # before: the optimiser stepped to A < 0 and the fit died with "A must be in [0, inf)"
    y = 0.5 * _adhesion(CREEP, k_A=0.6, k_S=0.2, mu0=0.4, A=0.0, B=5.0)
    with pytest.raises(ValueError, match=pattern):
        _fit(CREEP, y, bounds=bounds)


def test_polach_zero_lower_bound_of_a_positive_parameter_is_usable():
    y = _adhesion(CREEP, k_A=0.6, k_S=0.2, mu0=0.4, A=0.4, B=0.5)
    res = _fit(CREEP, y, bounds={"k_A": (0.0, 1.0), "mu0": (0.0, 2.0)})
    assert res.params["k_A"] == pytest.approx(0.6, rel=1e-3)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        (dict(fit=("k_A",), initial={"mu0": 0.4, "A": "x"}), r"initial\['A'\] must be a number"),
        (dict(fit=("k_A",), initial={"mu0": float("nan")}), r"initial\['mu0'\] must be finite"),
        (dict(initial={"mu0": float("nan")}), r"initial\['mu0'\] must be finite"),
        (dict(fit=("k_A",), initial={"mu0": -1.0}), r"initial\['mu0'\] must be in \(0, inf\)"),
        (dict(fit=("k_A",), initial={"mu0": 0.4, "B": -1.0}), r"initial\['B'\] must be in \[0"),
    ],
)
def test_polach_bad_initial_values_are_named(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        _fit(CREEP, _adhesion(CREEP, mu0=0.3), **kwargs)


def test_fletcher_fixed_k_s_zero_is_a_value_error():
    # before: ZeroDivisionError in the starting guess
    xi = np.linspace(1e-4, 0.01, 20)
    y = _fletcher_adhesion(xi, 0.2, 0.5)
    with pytest.raises(ValueError, match=r"initial\['k_s'\] must be in \(0, inf\)"):
        fit_fletcher(xi, y, half_width=FLETCHER_A, radius=FLETCHER_R, fit=("mu",),
                     initial={"k_s": 0.0, "k_a": 0.5})
    with pytest.raises(ValueError, match=r"bounds\['k_a'\]: low must be >= 0"):
        fit_fletcher(xi, y, half_width=FLETCHER_A, radius=FLETCHER_R, mu=0.2,
                     bounds={"k_a": (-1.0, 5.0)})


def test_polach_implausible_speed_is_checked_once_and_makes_the_fit_untrusted():
    """A curve at 'speed_m_s = 300' (km/h) gave trusted True, warnings (), B 100 x too small,
    and the same UnitWarning at each of ~780 optimiser evaluations."""
    import warnings as _warnings

    from railadhesion.plausibility import UnitWarning

    creep = -np.geomspace(2e-4, 0.6, 40)
    true = dict(k_A=1.0, k_S=0.4, mu0=0.45, A=0.4, B=0.6)
    fx, _ = polach_forces(creep, 0.0, 0.0, 4500.0, 3.0, 4.1e-3, 3.1e-3, **true)  # 3 m/s
    with _warnings.catch_warnings(record=True) as caught:
        _warnings.simplefilter("always")
        res = fit_polach(creep, fx / 4500.0, normal_force=4500.0, speed=300.0, a=4.1e-3,
                         b=3.1e-3)  # fmt: skip
    units = [w for w in caught if issubclass(w.category, UnitWarning)]
    assert len(units) == 1, [str(w.message) for w in caught]
    assert "speed = 300 m/s" in str(units[0].message) and "km/h" in str(units[0].message)
    assert not res.trusted
    assert res.warnings[0] == str(units[0].message) == res.implausible_inputs[0]
    untrusted = [w for w in caught if issubclass(w.category, UntrustedResultWarning)]
    assert len(untrusted) == 1 and "speed = 300 m/s" in str(untrusted[0].message)
    assert res.params["B"] == pytest.approx(0.006, rel=0.05)  # 100 x too small: 300 / 3
    # the same data at their true speed: trusted, no input finding, B recovered
    good = fit_polach(creep, fx / 4500.0, normal_force=4500.0, speed=3.0, a=4.1e-3, b=3.1e-3)
    assert good.trusted and good.implausible_inputs == ()
    assert good.params["B"] == pytest.approx(0.6, rel=1e-3)


def test_polach_adhesion_in_percent_and_fletcher_creep_in_percent_are_flagged_once():
    import warnings as _warnings

    from railadhesion.plausibility import UnitWarning

    creep = -np.geomspace(0.002, 0.3, 25)
    fx, _ = polach_forces(creep, 0.0, 0.0, 4200.0, 5.0, 4e-3, 3e-3, mu0=0.4, k_S=0.4)
    with pytest.warns(UnitWarning, match=r"^adhesion = from .* given in percent\?") as rec:
        res = fit_polach(creep, 100 * np.abs(fx) / 4200.0, normal_force=4200.0, speed=5.0,
                         a=4e-3, b=3e-3, fit=("k_A", "k_S"), initial={"mu0": 40.0 / 100},
                         warn_untrusted=False)  # fmt: skip
    assert sum(issubclass(w.category, UnitWarning) for w in rec) == 1
    assert not res.trusted and res.implausible_inputs[0].startswith("adhesion = ")
    xi = np.linspace(0.0002, 0.05, 30)  # 0.02 % to 5 %
    y = np.abs(fletcher(xi, 1.0, 0.204e-3, 11.75e-3, 0.055, k_a=0.193).traction)
    with _warnings.catch_warnings(record=True) as caught:
        _warnings.simplefilter("always")
        res = fit_fletcher(100 * xi, y, half_width=0.204e-3, radius=11.75e-3, fit=("k_a",),
                           mu=0.055, warn_untrusted=False)  # fmt: skip
    units = [w for w in caught if issubclass(w.category, UnitWarning)]
    assert len(units) == 1 and str(units[0].message).startswith("creep = from 0.02 to 5 is outside")
    assert not res.trusted and res.warnings[0] == str(units[0].message)
