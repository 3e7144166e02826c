"""Tests of the WILAC model (Trummer et al., seed 000, section 5).

The paper does not publish its regression coefficients, so these tests use their own fixture
parameter sets: constant regressions built from Polach's (2005) typical dry and wet values and
from invented damp values. The published numbers checked are the transition parameters of
Table 1 and the structure of the blending (section 5.3).
"""

from __future__ import annotations

import math
from importlib import resources

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from railadhesion.models.parameters import PolachParameters, polach_parameters
from railadhesion.models.polach import polach_forces
from railadhesion.models.regression import ParameterRegression
from railadhesion.models.wilac import (
    PAPER_TRANSITIONS,
    PHYSICAL_BOUNDS,
    WILAC_CONDITIONS,
    WaterTransition,
    Wilac,
    WilacCondition,
    WilacParameters,
    default_wilac_parameters,
    wilac_forces,
    wilac_transitions,
    wilac_weights,
)
from railadhesion.plausibility import AlteredResultWarning

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

SETTINGS = settings(max_examples=80, deadline=None)

# Seed 000 (Trummer et al.), Table 1: (m, s) in µl/s for e_1 (Damp2–Dry), e_2 (Damp1–Damp2),
# e_3 (Wet–Damp1).
TABLE1 = ((15.0, 5.0), (30.0, 3.0), (50.0, 7.0))

# Polach 2005 typical values (MODELS.md §3 table): dry and wet.
DRY = polach_parameters("polach2005_dry")
WET = polach_parameters("polach2005_wet")
# Invented damp conditions for the fixtures (k_S <= k_A, A <= 1, so |T| <= mu0 Q).
DAMP2 = PolachParameters(k_A=0.35, k_S=0.12, mu0=0.3, A=0.2, B=0.9)
DAMP1 = PolachParameters(k_A=0.3, k_S=0.1, mu0=0.25, A=0.6, B=0.3)
FIXTURE = {"dry": DRY, "damp2": DAMP2, "damp1": DAMP1, "wet": WET}

Q_RANGE = (2.0e3, 1.2e5)
V_RANGE = (1.0, 40.0)
CONTACT = dict(a=3.0e-3, b=4.0e-3)


def make_params(conds=None, **kw) -> WilacParameters:
    conds = FIXTURE if conds is None else conds
    kwargs = dict(
        conditions={c: WilacCondition.from_polach(p) for c, p in conds.items()},
        normal_force_ref=Q_RANGE[1],
        speed_ref=V_RANGE[1],
        normal_force_range=Q_RANGE,
        speed_range=V_RANGE,
        name="fixture",
    )
    kwargs.update(kw)
    return WilacParameters(**kwargs)


PARAMS = make_params()
SAME = make_params({c: DRY for c in WILAC_CONDITIONS})

water = st.floats(0.0, 1.0e4, allow_nan=False)
water_arrays = hnp.arrays(np.float64, hnp.array_shapes(max_dims=3, max_side=5), elements=water)


# --- transitions and weights (section 5.3, Table 1) ------------------------------------------


def test_paper_transitions_are_table1():
    assert tuple(tuple(t) for t in PAPER_TRANSITIONS) == TABLE1


@pytest.mark.parametrize("i", [0, 1, 2])
def test_transition_is_half_at_its_midpoint(i):
    m = TABLE1[i][0]
    e = wilac_transitions(m)
    assert e.shape == (3,)
    assert e[i] == pytest.approx(0.5, abs=1e-15)


@pytest.mark.parametrize("w", [0.0, 7.5, 20.0, 31.0, 47.0, 100.0])
def test_transitions_match_the_erf_formula(w):
    # e_i = ½ (erf((w − m_i)/s_i) + 1), seed 000 §5.3, evaluated here with math.erf
    expected = [0.5 * (math.erf((w - m) / s) + 1.0) for m, s in TABLE1]
    np.testing.assert_allclose(wilac_transitions(w), expected, rtol=1e-13, atol=1e-15)


def test_dry_at_zero_water_and_wet_at_350():
    # 350 µl/s: the "Wet" data set of seed 000 (§5.4); 0 µl/s the "Dry" one.
    f0 = wilac_weights(0.0)
    f350 = wilac_weights(350.0)
    assert f0[0] > 0.9999 and f0[0] == pytest.approx(1 - 0.5 * (math.erf(-3.0) + 1))
    assert f350[3] == 1.0
    assert np.all(f350[:3] == 0.0)


@SETTINGS
@given(water_arrays)
def test_weights_sum_to_one_and_are_nonnegative(w):
    f = wilac_weights(w)
    assert f.shape == (4, *w.shape)
    np.testing.assert_allclose(f.sum(axis=0), 1.0, atol=1e-14)
    # Not exactly >= 0: the paper's f_Damp1 = e2 - e3 is truly negative, by ~1e-15, where the
    # wide e3 tail (s = 7 µl/s) exceeds the narrow e2 tail (s = 3), e.g. at w = 11 µl/s:
    # 0.5 erfc(19/3) - 0.5 erfc(39/7) = -1.7e-15; the most negative value is -2.35e-13 near
    # w = 14.56 µl/s. Such weights are negligible, not an error.
    assert np.all(f >= -2.5e-13)


@SETTINGS
@given(water)
def test_weights_sum_to_one_scalar(w):
    f = wilac_weights(w)
    assert f.shape == (4,)
    assert float(f.sum()) == pytest.approx(1.0, abs=1e-14)


@SETTINGS
@given(water, water)
def test_transitions_are_monotonic(w1, w2):
    lo, hi = min(w1, w2), max(w1, w2)
    assert np.all(wilac_transitions(lo) <= wilac_transitions(hi))


def test_weights_of_each_condition_peak_in_its_band():
    w = np.linspace(0.0, 400.0, 4001)
    f = wilac_weights(w)
    peaks = w[np.argmax(f, axis=1)]
    assert peaks[0] == 0.0  # dry
    assert 15.0 < peaks[1] < 30.0  # damp2 between e1 and e2 midpoints
    assert 30.0 < peaks[2] < 50.0  # damp1 between e2 and e3 midpoints
    assert peaks[3] > 50.0  # wet


def test_custom_transitions():
    t = [WaterTransition(10.0, 2.0), WaterTransition(20.0, 2.0), WaterTransition(40.0, 5.0)]
    e = wilac_transitions([10.0, 20.0, 40.0], t)
    np.testing.assert_allclose(np.diag(e), 0.5, atol=1e-15)


@pytest.mark.parametrize(
    ("transitions", "message"),
    [
        ([(15, 5), (30, 3)], "expected 3"),
        ([(15, 5), (10, 3), (50, 7)], "increase"),
        ([(15, 0.0), (30, 3), (50, 7)], "e1 width"),
        ([(15, 5), (30, -3), (50, 7)], "e2 width"),
        ([(15, 5), (30, 3), (float("nan"), 7)], "e3 midpoint"),
        ([(15, 5), (30, 3), (50,)], "e3"),
        # a narrow late transition overtakes a wide early one: f_Damp2 < 0 somewhere
        ([(15, 40.0), (30, 1.0), (50, 7)], "cross"),
        ("abc", "transitions"),
    ],
)
def test_bad_transitions(transitions, message):
    with pytest.raises(ValueError, match="transitions") as info:
        wilac_weights(10.0, transitions)
    assert message in str(info.value)


@pytest.mark.parametrize("w", [-1.0, float("nan"), float("inf"), [1.0, -0.5], [0.0, np.nan]])
def test_bad_water_flow(w):
    with pytest.raises(ValueError, match=r"water_flow must be in \[0, inf\)"):
        wilac_weights(w)
    with pytest.raises(ValueError, match=r"water_flow must be in \[0, inf\)"):
        wilac_forces(0.01, 0.0, 0.0, 1e4, 10.0, 3e-3, 4e-3, w, PARAMS)


# --- forces ----------------------------------------------------------------------------------


def polach_of(p: PolachParameters, sx, sy, psi, q, v):
    return polach_forces(sx, sy, psi, q, v, CONTACT["a"], CONTACT["b"], **p.as_dict())


creeps = st.floats(-0.5, 0.5, allow_nan=False)
forces_q = st.floats(1.0e3, 2.0e5)
speeds = st.floats(0.0, 60.0)


@ANY_INPUT
@SETTINGS
@given(creeps, creeps, st.floats(-2.0, 2.0), forces_q, speeds, water)
def test_identical_conditions_give_plain_polach(sx, sy, psi, q, v, w):
    fx, fy = wilac_forces(sx, sy, psi, q, v, CONTACT["a"], CONTACT["b"], w, SAME)
    px, py = polach_of(DRY, sx, sy, psi, q, v)
    assert fx == pytest.approx(float(px), rel=1e-12, abs=1e-9)
    assert fy == pytest.approx(float(py), rel=1e-12, abs=1e-9)


def test_identical_conditions_give_plain_polach_arrays():
    sx = np.linspace(-0.3, 0.3, 13)[:, None]
    w = np.array([0.0, 20.0, 30.0, 45.0, 60.0, 350.0])
    fx, fy = wilac_forces(sx, 0.002, 0.1, 5e4, 12.0, CONTACT["a"], CONTACT["b"], w, SAME)
    px, py = polach_of(DRY, sx, 0.002, 0.1, 5e4, 12.0)
    assert fx.shape == (13, 6)
    np.testing.assert_allclose(fx, np.broadcast_to(px, (13, 6)), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(fy, np.broadcast_to(py, (13, 6)), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("w", [0.0, 10.0, 18.0, 25.0, 31.0, 40.0, 55.0, 60.0, 350.0])
@pytest.mark.parametrize("sx", [-0.6, -0.03, -0.001, 0.002, 0.2])
def test_forces_are_the_weighted_sum_of_the_conditions(w, sx):
    # seed 000 §5.3: T = f_Dry T_Dry + f_Damp2 T_Damp2 + f_Damp1 T_Damp1 + f_Wet T_Wet
    q, v, sy, psi = 4.2e3, 5.0, 0.001, 0.05
    f = [0.5 * (math.erf((w - m) / s) + 1.0) for m, s in TABLE1]
    weights = (1 - f[0], f[0] - f[1], f[1] - f[2], f[2])
    ex = ey = 0.0
    for fi, c in zip(weights, WILAC_CONDITIONS, strict=True):
        px, py = polach_of(FIXTURE[c], sx, sy, psi, q, v)
        ex += fi * float(px)
        ey += fi * float(py)
    fx, fy = wilac_forces(sx, sy, psi, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    assert fx == pytest.approx(ex, rel=1e-12, abs=1e-9)
    assert fy == pytest.approx(ey, rel=1e-12, abs=1e-9)


@ANY_INPUT
@pytest.mark.parametrize(("w", "cond"), [(350.0, "wet"), (1.0e4, "wet"), (0.0, "dry")])
def test_single_condition_far_from_transitions(w, cond):
    sx = np.linspace(-0.9, 0.9, 19)
    fx, fy = wilac_forces(sx, 0.0, 0.0, 4.2e3, 5.0, CONTACT["a"], CONTACT["b"], w, PARAMS)
    px, py = polach_of(FIXTURE[cond], sx, 0.0, 0.0, 4.2e3, 5.0)
    # w = 0 still carries f_Damp2 = ½(erf(−3) + 1) = 1.1e-5
    # (w > 100: the same model to rounding; the vectorised Polach kernel's arctan and exp
    # may differ from libm's by an ulp)
    tol = 1e-14 if w > 100 else 2.5e-5
    np.testing.assert_allclose(fx, px, rtol=tol, atol=tol * 4.2e3)
    np.testing.assert_allclose(fy, py, atol=1e-9)


def test_water_flow_broadcasts_against_creep():
    sx = np.linspace(-0.4, 0.1, 7)[None, :]
    w = np.array([0.0, 12.0, 25.0, 38.0, 350.0])[:, None]
    fx, fy = wilac_forces(sx, 0.0, 0.0, 4.2e3, 5.0, CONTACT["a"], CONTACT["b"], w, PARAMS)
    assert fx.shape == fy.shape == (5, 7)
    for i in range(5):
        for j in range(7):
            ex, ey = wilac_forces(
                float(sx[0, j]), 0.0, 0.0, 4.2e3, 5.0, CONTACT["a"], CONTACT["b"],
                float(w[i, 0]), PARAMS,
            )  # fmt: skip
            assert fx[i, j] == pytest.approx(float(ex), rel=1e-12, abs=1e-9)
            assert fy[i, j] == pytest.approx(float(ey), abs=1e-9)


@ANY_INPUT
def test_full_broadcast_of_all_inputs():
    sx = np.full((2, 1, 1, 1), -0.05)
    q = np.array([3e3, 6e4])[None, :, None, None]
    v = np.array([0.5, 10.0, 50.0])[None, None, :, None]
    w = np.array([0.0, 25.0, 40.0, 350.0])
    fx, fy = wilac_forces(sx, 0.0, 0.0, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    assert fx.shape == fy.shape == (2, 2, 3, 4)
    assert np.all(fx > 0)  # traction: the rail drives the wheel forward


@ANY_INPUT
@SETTINGS
@given(creeps, creeps, st.floats(-1.0, 1.0), forces_q, speeds, water)
def test_scalar_path_equals_array_path(sx, sy, psi, q, v, w):
    s = wilac_forces(sx, sy, psi, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    a = wilac_forces(
        np.array([sx]), sy, psi, np.array([q]), v, CONTACT["a"], CONTACT["b"], np.array([w]),
        PARAMS,
    )  # fmt: skip
    assert s[0] == pytest.approx(float(a[0][0]), rel=1e-12, abs=1e-9)
    assert s[1] == pytest.approx(float(a[1][0]), rel=1e-12, abs=1e-9)


@ANY_INPUT
@SETTINGS
@given(creeps, creeps, forces_q, speeds, water)
def test_force_bounded_by_max_mu0_q(sx, sy, q, v, w):
    # without spin, k_S <= k_A and A <= 1 in every fixture condition: |T| <= mu0 Q (Polach)
    fx, fy = wilac_forces(sx, sy, 0.0, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    mu_max = max(p.mu0 for p in FIXTURE.values())
    assert math.hypot(fx, fy) <= mu_max * q * (1 + 1e-12)


@ANY_INPUT
@SETTINGS
@given(st.floats(1e-5, 0.9), forces_q, speeds, water)
def test_sign_convention_and_antisymmetry(sx, q, v, w):
    # Kalker's convention (docs/CONVENTIONS.md): braking xi > 0 gives Fx < 0, traction Fx > 0
    fb, _ = wilac_forces(sx, 0.0, 0.0, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    ft, _ = wilac_forces(-sx, 0.0, 0.0, q, v, CONTACT["a"], CONTACT["b"], w, PARAMS)
    assert fb < 0 < ft
    assert ft == pytest.approx(-fb, rel=1e-12)


def test_low_adhesion_in_the_damp_band():
    # With these fixture conditions (damp2 the most slippery at large creep) adhesion at
    # -60 % creep has its minimum between 20 and 40 µl/s, the behaviour of seed 000 Fig. 8.
    w = np.linspace(0.0, 100.0, 201)
    mu = Wilac(PARAMS).adhesion(-0.6, 0.0, 0.0, 4.2e3, 5.0, CONTACT["a"], CONTACT["b"], w)
    assert 20.0 <= w[np.argmin(mu)] <= 40.0


# --- parameters: normalisation, clamping, clipping --------------------------------------------


def regression_params(**regs) -> WilacParameters:
    base = {name: getattr(DRY, name) for name in ("k_A", "k_S", "mu0", "A", "B")}
    base.update(regs)
    cond = WilacCondition(**base)
    return make_params().replace(conditions={c: cond for c in WILAC_CONDITIONS})


def test_regressors_are_normalised_by_the_references():
    p = regression_params(
        A=ParameterRegression(("Q",), (1.0,)), B=ParameterRegression(("v",), (1.0,))
    )
    q = np.array([5e3, 6e4, 1.2e5])
    v = np.array([2.0, 20.0, 40.0])
    out = p.polach_parameters("damp1", q, v)
    np.testing.assert_allclose(out["A"], q / Q_RANGE[1], rtol=1e-15)
    np.testing.assert_allclose(out["B"], v / V_RANGE[1], rtol=1e-15)


def test_inputs_are_clamped_into_the_validity_range():
    p = regression_params(
        mu0=ParameterRegression(("1", "1/v", "Q"), (0.3, 0.002, 0.05)),
    )
    at = p.polach_parameters
    lo_v = at("dry", 5e4, V_RANGE[0])["mu0"]  # the range's ends: no warning
    hi_v = at("dry", 5e4, V_RANGE[1])["mu0"]
    with pytest.warns(AlteredResultWarning) as caught:  # every clamp is reported
        assert at("dry", 5e4, 0.0)["mu0"] == lo_v  # standstill: lowest calibrated speed
        assert at("dry", 5e4, 0.2)["mu0"] == lo_v
        assert at("dry", 5e4, 400.0)["mu0"] == hi_v
        assert at("dry", 10.0, 10.0)["mu0"] == at("dry", Q_RANGE[0], 10.0)["mu0"]
        assert at("dry", 1e7, 10.0)["mu0"] == at("dry", Q_RANGE[1], 10.0)["mu0"]
        # the forces stay finite at standstill
        fx, _ = wilac_forces(0.1, 0.0, 0.0, 5e4, 0.0, CONTACT["a"], CONTACT["b"], 0.0, p)
    assert np.isfinite(fx) and fx < 0
    reported = [str(w.message).split(" is outside")[0] for w in caught]
    assert reported == ["speed = 0 m/s", "speed = 0.2 m/s", "speed = 400 m/s",
                        "normal_force = 10 N", "normal_force = 1e+07 N", "speed = 0 m/s"]
    assert all("calibrated range" in str(w.message) for w in caught)
    assert lo_v == pytest.approx(0.3 + 0.002 * V_RANGE[1] / V_RANGE[0] + 0.05 * 5e4 / Q_RANGE[1])


def test_outputs_are_clipped_to_physical_ranges():
    p = regression_params(
        k_A=1.7, k_S=-0.2, mu0=ParameterRegression(("1", "v"), (-0.3, 0.2)), A=-1.0, B=-3.0
    )
    v = np.array([1.0, 20.0, 40.0])  # mu0 = -0.3 + 0.2 v/40 < 0 everywhere
    out = p.polach_parameters("wet", 4e4, v)
    assert np.all(out["k_A"] == 1.0)
    assert np.all(out["k_S"] == PHYSICAL_BOUNDS["k_S"][0]) and PHYSICAL_BOUNDS["k_S"][0] > 0
    assert np.all(out["mu0"] == PHYSICAL_BOUNDS["mu0"][0]) and PHYSICAL_BOUNDS["mu0"][0] > 0
    assert np.all(out["A"] == 0.0) and np.all(out["B"] == 0.0)
    # the scalar path clips the same way
    fs = wilac_forces(-0.1, 0.0, 0.0, 4e4, 20.0, CONTACT["a"], CONTACT["b"], 5.0, p)
    fa = wilac_forces(-0.1, 0.0, 0.0, np.array(4e4), 20.0, CONTACT["a"], CONTACT["b"], 5.0, p)
    assert fs[0] == pytest.approx(float(fa[0]), rel=1e-12)


def test_polach_parameters_of_constant_set():
    out = PARAMS.polach_parameters("damp2", np.array([3e3, 9e4]), 7.0)
    for name, value in DAMP2.as_dict().items():
        np.testing.assert_array_equal(out[name], [value, value])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("moist", 1e4, 5.0), "condition must be one of"),
        (("dry", -1e4, 5.0), "normal_force must be in"),
        (("dry", np.nan, 5.0), "normal_force must be in"),
        (("dry", 1e4, -5.0), "speed must be in"),
        (("dry", 1e4, [5.0, np.nan]), "speed must be in"),
    ],
)
def test_polach_parameters_bad_input(args, message):
    with pytest.raises(ValueError, match=message):
        PARAMS.polach_parameters(*args)


@pytest.mark.parametrize(
    ("kwargs", "args", "message"),
    [
        ({}, (0.01, 0.0, 0.0, 0.0, 5.0), "normal_force must be in"),
        ({}, (0.01, 0.0, 0.0, np.array([1e4, np.nan]), 5.0), "normal_force must be in"),
        ({}, (0.01, 0.0, 0.0, 1e4, -1.0), "speed must be in"),
        ({}, (np.nan, 0.0, 0.0, 1e4, 5.0), "creep_long must be finite"),
        ({"poisson": 0.7}, (0.01, 0.0, 0.0, 1e4, 5.0), "poisson"),
    ],
)
def test_wilac_forces_bad_input(kwargs, args, message):
    with pytest.raises(ValueError, match=message):
        wilac_forces(*args, 3e-3, 4e-3, 10.0, PARAMS, **kwargs)


def test_wilac_forces_requires_parameters():
    with pytest.raises(ValueError, match="params must be a WilacParameters"):
        wilac_forces(0.01, 0.0, 0.0, 1e4, 5.0, 3e-3, 4e-3, 10.0, {"dry": DRY})


# --- parameter objects -----------------------------------------------------------------------


def test_condition_accepts_numbers_and_mappings():
    c = WilacCondition(
        k_A=0.5, k_S={"terms": ["1", "Q"], "coefficients": [0.1, 0.01]}, mu0=0.3, A=0.4, B=0.2
    )
    assert c.k_A == ParameterRegression.constant(0.5)
    assert c.k_S(2.0, 1.0) == pytest.approx(0.12)
    assert WilacCondition.from_polach(WET) == WilacCondition(**WET.as_dict())
    assert WilacCondition.from_polach(WET.as_dict()) == WilacCondition(**WET.as_dict())


@pytest.mark.parametrize(
    ("value", "message"), [("0.5", "k_A"), (float("nan"), "k_A"), (True, "k_A")]
)
def test_condition_rejects_bad_fields(value, message):
    with pytest.raises(ValueError, match=message):
        WilacCondition(k_A=value, k_S=0.1, mu0=0.3, A=0.4, B=0.2)


def _without(name):
    conds = {c: WilacCondition.from_polach(p) for c, p in FIXTURE.items()}
    del conds[name]
    return conds


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"conditions": _without("damp1")}, r"missing condition\(s\) \['damp1'\]"),
        (
            {"conditions": {**_without("wet"), "wet": WilacCondition.from_polach(WET),
                            "moist": WilacCondition.from_polach(WET)}},
            r"unknown condition\(s\) \['moist'\]",
        ),
        ({"conditions": {**_without("wet"), "wet": WET}}, "conditions.wet"),
        (
            {"conditions": {**_without("wet"), "wet": {"k_A": 0.3, "k_S": 0.1, "mu0": 0.3,
                                                       "A": 0.4}}},
            r"conditions.wet: missing parameter\(s\) \['B'\]",
        ),
        ({"normal_force_ref": 0.0}, "normal_force_ref must be in"),
        ({"speed_ref": np.inf}, "speed_ref must be in"),
        ({"normal_force_range": (5e4, 1e3)}, "normal_force_range"),
        ({"speed_range": (0.0, 40.0)}, "speed_range"),
        ({"speed_range": (1.0,)}, "speed_range"),
        ({"transitions": ((30, 3), (15, 5), (50, 7))}, "transitions"),
        ({"provenance": {"author": "me"}}, r"provenance: unknown field\(s\) \['author'\]"),
        ({"provenance": {"reconstruction": "yes"}}, "provenance.reconstruction"),
        ({"provenance": {"created": "last week"}}, "provenance.created"),
        ({"name": 3}, "name"),
    ],
)
def test_parameters_validation(changes, message):
    with pytest.raises(ValueError, match=message):
        make_params().replace(**changes)


def test_parameters_reject_regressions_that_blow_up_in_range():
    bad = WilacCondition(k_A=ParameterRegression(("exp(Q)",), (1.0,)), k_S=0.1, mu0=0.3,
                         A=0.4, B=0.2)  # fmt: skip
    conds = {**{c: WilacCondition.from_polach(p) for c, p in FIXTURE.items()}, "damp1": bad}
    with pytest.raises(ValueError, match="conditions.damp1.k_A: the regression is not finite"):
        make_params().replace(conditions=conds, normal_force_ref=1.0)


def test_parameters_store_conditions_in_order_and_compare_by_value():
    shuffled = {c: WilacCondition.from_polach(FIXTURE[c]) for c in reversed(WILAC_CONDITIONS)}
    p = make_params().replace(conditions=shuffled)
    assert tuple(p.conditions) == WILAC_CONDITIONS
    assert p == PARAMS
    assert p != PARAMS.replace(speed_ref=41.0)
    assert PARAMS.replace(provenance={"created": "2026-01-02"}).provenance == {
        "created": "2026-01-02"
    }


# --- object layer and default set -------------------------------------------------------------


def test_wilac_class_delegates():
    model = Wilac(PARAMS, poisson=0.3)
    args = (np.array([-0.2, 0.01]), 0.003, 0.1, 2e4, 8.0, 3e-3, 4e-3, 28.0)
    fx, fy = model.forces(*args)
    ex, ey = wilac_forces(*args, PARAMS, poisson=0.3)
    np.testing.assert_array_equal(fx, ex)
    np.testing.assert_array_equal(fy, ey)
    np.testing.assert_allclose(model.adhesion(*args), np.hypot(ex, ey) / 2e4, rtol=1e-15)
    np.testing.assert_array_equal(model.weights(28.0), wilac_weights(28.0))
    with pytest.raises(ValueError, match="params must be a WilacParameters"):
        Wilac(DRY)


def test_default_parameters_load_or_fail_clearly():
    resource = resources.files("railadhesion").joinpath("data", "wilac_default.toml")
    if resource.is_file():
        p = default_wilac_parameters()
        assert isinstance(p, WilacParameters)
        assert default_wilac_parameters() is p  # cached
        assert isinstance(Wilac().params, WilacParameters)
    else:
        with pytest.raises(FileNotFoundError, match="wilac_default.toml"):
            default_wilac_parameters()
        with pytest.raises(FileNotFoundError, match="wilac_default.toml"):
            Wilac()


# issue 9 item 3: every argument broadcasts, shear_modulus and poisson included --------------


@ANY_INPUT
def test_array_poisson_is_not_aligned_with_the_condition_axis():
    """Issue 9: ``poisson=[0, .2, .3, .5]`` with ``speed=np.array(5.0)`` returned one number
    (537.36 N), its four values mixed up with the four conditions; element-wise calls give
    [532.81, 537.34, 539.60, 544.09] N (default set, tram rig)."""
    p = default_wilac_parameters()
    args = (-0.05, 0, 0, 4.2e3, np.array(5.0), 1.4e-3, 3.15e-3, 25.0, p)
    nus = [0.0, 0.2, 0.3, 0.5]
    fx, fy = wilac_forces(*args, poisson=nus)
    assert fx.shape == (4,) and fy.shape == (4,)
    each = [float(wilac_forces(*args, poisson=nu)[0]) for nu in nus]
    np.testing.assert_allclose(fx, each, rtol=1e-12)
    np.testing.assert_allclose(fx, [532.81, 537.34, 539.60, 544.09], atol=0.006)
    gs = [7e10, 8.2e10, 9e10, 2e11]
    fx, _ = wilac_forces(*args, shear_modulus=np.array(gs))
    each = [float(wilac_forces(*args, shear_modulus=g)[0]) for g in gs]
    np.testing.assert_allclose(fx, each, rtol=1e-12)


_ARG_NAMES = ("creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b",
              "water_flow", "shear_modulus", "poisson")  # fmt: skip
_ARG_VALUES = dict(creep_long=(-0.3, 0.3), creep_lat=(-0.05, 0.05), spin=(-2.0, 2.0),
                   normal_force=(1e3, 1.5e5), speed=(0.0, 50.0), a=(1e-3, 1e-2),
                   b=(1e-3, 1e-2), water_flow=(0.0, 120.0), shear_modulus=(5e10, 1e11),
                   poisson=(0.0, 0.5))  # fmt: skip


@ANY_INPUT
@given(
    name=st.sampled_from(_ARG_NAMES),
    fractions=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=5),
    shape=st.sampled_from(["flat", "column", "0d"]),
)
@settings(max_examples=60, deadline=None)
def test_any_argument_as_array_equals_elementwise_calls(name, fractions, shape):
    """Issue 9 item 3, as a property: any one argument given as an array (1-d, a column or
    0-d) gives the element-wise scalar calls, in the argument's shape."""
    p = make_params()
    base = dict(creep_long=-0.02, creep_lat=0.003, spin=0.2, normal_force=2e4, speed=8.0,
                a=4e-3, b=3e-3, water_flow=28.0, shear_modulus=8.2e10, poisson=0.28)  # fmt: skip
    lo, hi = _ARG_VALUES[name]
    values = np.array([lo + f * (hi - lo) for f in fractions])
    if shape == "0d":
        values = np.array(values[0])
    elif shape == "column":
        values = values[:, None]

    def call(value):
        kw = dict(base, **{name: value})
        return wilac_forces(*(kw[n] for n in _ARG_NAMES[:8]), p,
                            shear_modulus=kw["shear_modulus"], poisson=kw["poisson"])  # fmt: skip

    fx, fy = call(values)
    assert np.shape(fx) == values.shape and np.shape(fy) == values.shape
    for idx in np.ndindex(values.shape):
        ex, ey = call(float(values[idx]))
        assert np.asarray(fx)[idx] == pytest.approx(ex, rel=1e-12, abs=1e-9)
        assert np.asarray(fy)[idx] == pytest.approx(ey, rel=1e-12, abs=1e-9)
