"""The careless-input policy (issue 18): plausible ranges, unit sniffers, the fit quality gate.

Property-style tests over the table: every quantity, every unit a careless user may use
instead, every public model function and each of its checked arguments. The suite turns every
RailadhesionWarning into an error (pyproject.toml), so a test that wants one says so.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import railadhesion as ra
from railadhesion import plausibility as pl
from railadhesion.plausibility import (
    PLAUSIBLE,
    AlteredResultWarning,
    PlausibilityWarning,
    RailadhesionWarning,
    UnitWarning,
    UntrustedResultWarning,
)

DOCS = Path(__file__).resolve().parents[1] / "docs"
A, B = 6.3e-3, 12.6e-3  # CONTACT's Eurosprinter contact [m]


def _inside(rng, u):
    """A value inside the plausible range at fraction u."""
    return rng.low + u * (rng.high - rng.low)


# ----------------------------------------------------------------------------- the table


@pytest.mark.parametrize("key", sorted(PLAUSIBLE))
@settings(max_examples=30, deadline=None)
@given(u=st.floats(0.0, 1.0))
def test_values_inside_the_range_are_quiet(key, u):
    rng = PLAUSIBLE[key]
    assert pl.check_plausible(_inside(rng, u), "x", quantity=key) is None
    assert pl.check_plausible(np.array([rng.low, _inside(rng, u), rng.high]), "x",
                              quantity=key) is None  # fmt: skip


@pytest.mark.parametrize("key", sorted(PLAUSIBLE))
@settings(max_examples=30, deadline=None)
@given(factor=st.floats(1.5, 1e6), above=st.booleans())
def test_values_outside_the_range_warn_naming_the_field(key, factor, above):
    rng = PLAUSIBLE[key]
    span = rng.high - rng.low
    value = rng.high + factor * span if above else rng.low - factor * span
    with pytest.warns(PlausibilityWarning, match=re.escape("my.field = ")) as caught:
        text = pl.check_plausible(value, "x", quantity=key, where="my.field")
    assert text == str(caught[0].message)
    assert "plausible range" in text and "docs/checks.md" in text


@pytest.mark.parametrize(("key", "unit", "factor"), [
    (k, name, f) for k, r in sorted(PLAUSIBLE.items()) for name, f in r.other_units
])  # fmt: skip
@settings(max_examples=20, deadline=None)
@given(u=st.floats(0.05, 0.95))
def test_a_plausible_value_in_another_unit_names_that_unit(key, unit, factor, u):
    """Every unit slip the table lists: a plausible value written in that unit, if it falls
    outside the range, gives a UnitWarning that names the unit and the value converted."""
    rng = PLAUSIBLE[key]
    true = _inside(rng, u)
    careless = true / factor
    if rng.low <= careless <= rng.high:
        return  # indistinguishable from a plausible value: nothing to sniff
    guess = pl.likely_unit(rng, careless, careless)
    assert guess is not None  # some listed unit explains it (the first that does is named)
    with pytest.warns(UnitWarning, match=re.escape(f"given in {guess[0]}?")):
        pl.check_plausible(careless, "x", quantity=key)


def test_every_argument_has_a_quantity_of_the_table():
    assert set(pl.ARGUMENT_QUANTITY.values()) <= set(PLAUSIBLE)
    for rng in PLAUSIBLE.values():
        assert rng.low < rng.high and rng.source


def test_docs_table_lists_every_range():
    """docs/checks.md prints the table: each quantity with its key and bounds."""
    text = (DOCS / "checks.md").read_text(encoding="utf-8")
    for key, rng in PLAUSIBLE.items():
        row = next((line for line in text.splitlines() if f"(`{key}`)" in line), None)
        assert row is not None, key
        cells = row.split("|")
        numbers = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", cells[3])]
        assert numbers[:2] == [rng.low, rng.high], (key, cells[3])
        for unit, _ in rng.other_units:
            assert unit.split(" ")[0] in cells[4], (key, unit)


def test_nan_is_left_to_the_errors_and_ints_are_checked():
    assert pl.check_plausible(float("nan"), "speed") is None
    assert pl.check_plausible(np.array([np.nan, 10.0]), "speed") is None
    assert pl.check_plausible(np.zeros(0), "speed") is None
    with pytest.warns(UnitWarning, match="km/h"):
        pl.check_plausible(160, "speed")


def test_input_checker_fast_path_and_arrays():
    check = pl.input_checker(("creep_long", "mu0", "normal_force", "speed"))
    assert check((0.01, 5.0, 1e5, 20.0)) == ()  # mu0 has no quantity: not checked
    assert check((np.array([0.01, 0.2]), 0.3, np.float64(1e5), 20)) == ()
    with pytest.warns(UnitWarning) as caught:
        found = check((0.01, 0.3, 1e5, np.array([10.0, 160.0])))
    assert len(found) == 1 and "speed = from 10 to 160 m/s" in found[0]
    assert "km/h" in str(caught[0].message)
    with pytest.warns(PlausibilityWarning) as caught:
        found = check((5.0, 0.3, 1e300, 20.0))
    assert [m.split(" =")[0] for m in found] == ["creep_long", "normal_force"]


def test_warning_points_at_the_users_line():
    with pytest.warns(PlausibilityWarning) as caught:
        ra.polach_forces(0.01, 0.0, 0.0, 1e300, 10.0, A, B, mu0=0.3)
    assert caught[0].filename == __file__


def test_all_categories_share_one_base():
    for cat in (PlausibilityWarning, UnitWarning, AlteredResultWarning, UntrustedResultWarning):
        assert issubclass(cat, RailadhesionWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RailadhesionWarning)
        with pytest.raises(UnitWarning):
            pl.check_plausible(5.5, "brake_pressure")


# ----------------------------------------------------------------------------- the models

# (function of the tested argument's value, argument name, a plausible value)
MODEL_ARGUMENTS = {
    "polach_forces": (lambda **k: ra.polach_forces(
        k.get("creep_long", 0.01), k.get("creep_lat", 0.0), k.get("spin", 0.0),
        k.get("normal_force", 1e5), k.get("speed", 10.0), k.get("a", A), k.get("b", B),
        mu0=0.3, shear_modulus=k.get("shear_modulus", 8.2e10), poisson=k.get("poisson", 0.28)),
        ("creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b", "shear_modulus",
         "poisson")),
    "wilac_forces": (lambda **k: ra.wilac_forces(
        k.get("creep_long", 0.01), k.get("creep_lat", 0.0), k.get("spin", 0.0),
        k.get("normal_force", 1e5), k.get("speed", 10.0), k.get("a", A), k.get("b", B),
        k.get("water_flow", 10.0), ra.default_wilac_parameters()),
        ("creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b", "water_flow")),
    "fastsim": (lambda **k: ra.fastsim(
        k.get("creep_long", 1e-4), k.get("creep_lat", 0.0), k.get("spin", 0.0),
        k.get("normal_force", 1e5), k.get("a", A), k.get("b", B), 0.3, nx=8, ny=8),
        ("creep_long", "creep_lat", "spin", "normal_force", "a", "b")),
    "linear_creep_forces": (lambda **k: ra.linear_creep_forces(
        k.get("creep_long", 1e-4), k.get("creep_lat", 0.0), k.get("spin", 0.0), k.get("a", A),
        k.get("b", B), k.get("shear_modulus", 8.2e10), 0.28),
        ("creep_long", "creep_lat", "spin", "a", "b", "shear_modulus")),
    "exact_table_forces": (lambda **k: __import__(
        "railadhesion.contact.table", fromlist=["x"]).exact_table_forces(
        k.get("creep_long", 1e-3), k.get("creep_lat", 0.0), k.get("spin", 0.0),
        k.get("normal_force", 1e5), k.get("a", 6e-3), k.get("b", 6e-3), 0.3),
        ("creep_long", "normal_force", "spin")),
    "hertz_3d": (lambda **k: ra.hertz_3d(k.get("normal_force", 1e5),
                                         k.get("wheel_radius", 0.46), np.inf, 0.3,
                                         young=k.get("young", 2.1e11)),
                 ("normal_force", "wheel_radius", "young")),
    "fletcher": (lambda **k: ra.fletcher(k.get("creep", 1e-3), 1e6,
                                         k.get("half_width", 2e-4), k.get("radius", 0.0235),
                                         0.3),
                 ("creep", "half_width", "radius")),
}  # fmt: skip


@pytest.mark.parametrize(("function", "argument"), [
    (f, a) for f, (_, args) in MODEL_ARGUMENTS.items() for a in args
])  # fmt: skip
@settings(max_examples=8, deadline=None)
@given(factor=st.floats(1.5, 1e3))
def test_every_model_argument_is_checked_and_named(function, argument, factor):
    """The policy, not a list of patches: every checked argument of every model function,
    above its plausible range, gives a warning naming it; the number is still computed."""
    call, _ = MODEL_ARGUMENTS[function]
    rng = PLAUSIBLE[pl.ARGUMENT_QUANTITY[argument]]
    value = rng.high * factor if rng.high > 0 else rng.high + factor
    if argument == "poisson":  # implausible but possible: (0.35, 0.5]
        value = 0.35 + 0.15 * (1.0 - 1.0 / factor)
    if argument == "a":
        value = min(value, 5 * B)  # stay within the models' a/b range (errors otherwise)
        if value <= rng.high:
            value = rng.high * 1.2
            if function == "exact_table_forces":
                return  # a/b <= 5 of the table keeps a = 6e-3 * 5 = 0.03 below 0.05 m
    if argument == "b":
        value = min(value, 5 * A)
        if value <= rng.high:
            return  # cannot be implausible within the a/b range of the models
    with pytest.warns(RailadhesionWarning) as caught:  # WILAC also reports its clamp
        out = call(**{argument: value})
    assert out is not None
    assert any(issubclass(w.category, PlausibilityWarning)
               and re.search(rf"\b{argument} = ", str(w.message)) for w in caught)


def test_plausible_calls_are_quiet():
    for call, _ in MODEL_ARGUMENTS.values():
        call()  # the suite's filter turns any warning into an error


def test_polach_forces_normal_force_1e300_warns_but_computes():
    with pytest.warns(PlausibilityWarning, match=r"normal_force = 1e\+300 N"):
        fx, _ = ra.polach_forces(0.01, 0.0, 0.0, 1e300, 10.0, A, B, mu0=0.3)
    assert np.isfinite(fx)


def test_wilac_clamp_outside_calibrated_range_is_reported():
    p = ra.default_wilac_parameters()
    with pytest.warns(AlteredResultWarning, match=r"speed = 44 m/s .* calibrated range"):
        ra.wilac_forces(0.05, 0.0, 0.0, 1e5, 44.0, A, B, 0.0, p)
    with pytest.warns(AlteredResultWarning, match="normal_force = from 2000 to"):
        ra.wilac_forces(0.05, 0.0, 0.0, np.array([2000.0, 5000.0]), 10.0, A, B, 0.0, p)
    with pytest.warns(AlteredResultWarning, match="speed = 0 m/s"):
        p.polach_parameters("dry", 5e4, 0.0)
    ra.wilac_forces(0.05, 0.0, 0.0, 1e5, 40.0, A, B, 0.0, p)  # the range's end: quiet


def test_integer_and_mixed_inputs_work():
    from railadhesion.contact.table import exact_table_forces

    got = exact_table_forces(1e-5, 0, 0, 100000, 6e-3, 6e-3, 0.3)
    want = exact_table_forces(1e-5, 0.0, 0.0, 1e5, 6e-3, 6e-3, 0.3)
    assert got == want
    got = exact_table_forces(1e-5, 0, 0, 1e5, 6e-3, 6e-3, 0.3, speed=10, friction_ratio=1,
                             friction_decay=0)  # fmt: skip
    assert got == want
    arr = exact_table_forces(np.array([1e-5, 2e-5]), 0, 0, 100000, 6e-3, 6e-3, 0.3)
    assert arr[0][0] == want[0]
    assert ra.polach_forces(0, 0, 0, 100000, 10, A, B, mu0=1) == (0.0, -0.0)
    with pytest.raises(ValueError, match="creep_long"):
        exact_table_forces("x", 0, 0, 1e5, 6e-3, 6e-3, 0.3)


# ----------------------------------------------------------------------------- sniffers


def test_speed_ratio_finds_km_h_mph_and_rpm():
    v = np.linspace(40.0, 5.0, 200)
    omega = np.tile((v / 0.46)[:, None], (1, 4))
    assert pl.sniff_speed_ratio(v, omega) is None
    assert pl.sniff_speed_ratio(v, omega, 0.46) is None
    with pytest.warns(UnitWarning, match="train_speed in km/h"):
        pl.sniff_speed_ratio(v * 3.6, omega, 0.46)
    with pytest.warns(UnitWarning, match="km/h"):
        pl.sniff_speed_ratio(v * 3.6, omega)
    with pytest.warns(UnitWarning, match="mph"):
        pl.sniff_speed_ratio(v / 0.44704, omega, 0.46)
    with pytest.warns(UnitWarning, match="rpm"):
        pl.sniff_speed_ratio(v, omega * 30.0 / math.pi, 0.46)
    # sliding axles do not matter: the fastest axle rolls
    slid = omega.copy()
    slid[:, :3] *= 0.2
    assert pl.sniff_speed_ratio(v, slid, 0.46) is None
    assert pl.sniff_speed_ratio(np.zeros(5), omega[:5]) is None  # at standstill: no evidence


def test_sample_period_in_milliseconds():
    assert pl.sniff_sample_period(2.4e-3) is None
    with pytest.warns(UnitWarning, match="time in ms"):
        pl.sniff_sample_period(2.4)
    with pytest.warns(PlausibilityWarning, match="median sampling period"):
        pl.sniff_sample_period(500.0)


def test_sniff_ratio():
    units = {"Pa": 1e-5, "kPa": 1e-2}
    assert pl.sniff_ratio(1.2, "c", units) == (True, None)
    assert pl.sniff_ratio(1.1e-5, "c", units) == (False, "Pa")
    assert pl.sniff_ratio(0.012, "c", units) == (False, "kPa")
    assert pl.sniff_ratio(1e3, "c", units) == (False, None)
    assert pl.sniff_ratio(float("nan"), "c", units) == (False, None)


# ----------------------------------------------------------------------------- the gate


@settings(max_examples=50, deadline=None)
@given(r2=st.floats(-20.0, 1.0), rel=st.floats(0.0, 5.0), count=st.integers(0, 10))
def test_fit_gate_flags_each_finding(r2, rel, count):
    found = pl.fit_warnings(
        r_squared=r2, params={"p": 2.0, "q": 1.0}, fitted=("p", "q"),
        stderr={"p": 2.0 * rel, "q": 0.01}, region_points={"q": (count, "there")},
    )  # fmt: skip
    assert any("R^2" in f for f in found) == (r2 < pl.MIN_R_SQUARED)
    assert any(f.startswith("p = ") for f in found) == (rel > pl.MAX_RELATIVE_STDERR)
    assert any(f.startswith("q: ") for f in found) == (count < pl.MIN_REGION_POINTS)


def test_fit_gate_bounds_and_infinite_errors():
    found = pl.fit_warnings(r_squared=0.99, params={"p": 1.5, "q": 0.3}, fitted=("p", "q"),
                            stderr={"p": math.inf, "q": math.inf}, at_bound=("p",),
                            success=False)  # fmt: skip
    assert found[0] == "the optimiser did not converge"
    assert any("p = 1.5 is on a bound" in f for f in found)
    assert any("q: standard error not finite" in f for f in found)
    assert not any(f.startswith("p: standard error") for f in found)  # on a bound: judged so
    assert pl.fit_warnings(r_squared=0.99, params={"p": 1.0}, fitted=("p",),
                           stderr={"p": math.inf}, ignore_stderr=("p",)) == ()  # fmt: skip


def test_result_flag_helpers():
    class Flagged:
        trusted = False
        warnings = ("first reason", "second")

    assert not pl.is_trusted(Flagged()) and pl.first_reason(Flagged()) == "first reason"
    assert pl.is_trusted(object()) and pl.first_reason(object()) == ""


@settings(max_examples=30, deadline=None)
@given(r2=st.floats(-5.0, 0.899), ratio=st.floats(0.0, 3.0))
def test_a_low_r2_within_the_noise_is_not_flagged(r2, ratio):
    found = pl.fit_warnings(r_squared=r2, params={"p": 1.0}, fitted=("p",), stderr={"p": 0.1},
                            residual_rms=0.004 * ratio, noise=0.004)  # fmt: skip
    assert any("R^2" in f for f in found) == (ratio > pl.MAX_NOISE_RATIO)


def test_noise_rms_of_a_smooth_curve_with_noise():
    rng = np.random.default_rng(3)
    x = np.geomspace(0.002, 0.6, 400)
    y = 0.15 * (1.0 - np.exp(-x / 0.01)) + rng.normal(0.0, 0.004, x.size)
    assert pl.noise_rms(x, y) == pytest.approx(0.004, rel=0.15)
    assert pl.noise_rms(x[::-1], y[::-1]) == pl.noise_rms(x, y)  # order of x, not of input
    assert math.isnan(pl.noise_rms(x[:pl.MIN_NOISE_POINTS - 1], y[:pl.MIN_NOISE_POINTS - 1]))


def test_flat_wet_curve_fitted_by_the_right_model_is_trusted_and_a_wrong_one_is_not():
    """A wet-type curve (nearly flat, seed 000 §5) with the rig's noise: the right Polach
    parameters leave R^2 ~ 0.8 (the curve's variance is mostly noise) and must not be flagged;
    fitting mu0 alone to a dry-type curve leaves a residual far above the noise and must be."""
    from railadhesion.calibration import fit_polach
    from railadhesion.models import polach_forces

    rng = np.random.default_rng(2)
    creep = np.geomspace(0.002, 0.6, 20)
    q, v, a, b = 3000.0, 3.0, 3.6e-3, 2.7e-3
    wet = dict(k_A=0.2, k_S=0.1, mu0=0.15, A=0.9, B=0.1)
    fx, _ = polach_forces(creep, 0.0, 0.0, q, v, a, b, **wet)
    y = np.abs(fx) / q + rng.normal(0.0, 0.004, creep.size)
    res = fit_polach(creep, y, normal_force=q, speed=v, a=a, b=b, warn_untrusted=False)
    assert res.r_squared < pl.MIN_R_SQUARED  # the flat curve's R^2 is low ...
    assert not any("R^2" in w for w in res.warnings)  # ... and that is not held against it
    dry = dict(k_A=1.0, k_S=0.4, mu0=0.45, A=0.4, B=0.6)
    fx, _ = polach_forces(creep, 0.0, 0.0, q, v, a, b, **dry)
    y = np.abs(fx) / q + rng.normal(0.0, 0.004, creep.size)
    res = fit_polach(creep, y, normal_force=q, speed=v, a=a, b=b, fit=("mu0",),
                     initial={"k_A": 0.05, "k_S": 0.05, "A": 1.0, "B": 0.0},
                     warn_untrusted=False)  # fmt: skip
    assert any("R^2" in w for w in res.warnings)


def test_friction_coefficient_in_percent_is_sniffed():
    """mu = 30 meant 30 % (0.3): the exact solver, FASTSIM and the table model each say so;
    0.3 says nothing."""
    from railadhesion.contact import exact_rolling, exact_table_forces, fastsim

    args = (1e-3, 0.0, 0.0, 8e4, 6e-3, 5e-3)
    for call in (lambda mu: exact_rolling(*args, mu, nx=8, ny=8),
                 lambda mu: fastsim(*args, mu, nx=8, ny=8),
                 lambda mu: exact_table_forces(*args, mu)):  # fmt: skip
        with pytest.warns(UnitWarning, match="given in percent"):
            call(30.0)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            call(0.3)
