"""The table model of Kalker's exact theory as the braking axles' creep-force law
(ExactTableAdhesion, compiled in the step as the TABLE family)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.braking import (
    BrakeCylinders,
    BrakingSimulator,
    ContactGeometry,
    ExactTableAdhesion,
    PolachAdhesion,
    Vehicle,
    WheelSlideProtection,
    largest_stable_step,
    simulate,
)
from railadhesion.braking.scenario import load_scenario
from railadhesion.contact import exact_table_forces
from railadhesion.models.parameters import polach_parameters

VEHICLE = Vehicle(name="test coach")
LOADS = np.array([30e3, 55e3, 62e3, 80e3])


def prepared(model, speed=25.0, loads=LOADS):
    model.bind(loads.size, VEHICLE.wheel_radius)
    model.prepare(speed, loads, np.zeros(loads.size), 0.0)
    return model


def reference(model, creep, speed, loads):
    """μ = −Fx/Q of exact_table_forces at each wheel's Hertz contact (the public function)."""
    c = model.contact
    a, b = c.semi_axes(loads)
    fx, _, _ = exact_table_forces(creep, 0.0, 0.0, loads, a, b, model.mu,
                                  shear_modulus=c.shear_modulus, poisson=c.poisson,
                                  speed=speed, friction_ratio=model.friction_ratio,
                                  friction_decay=model.friction_decay)
    return -fx / loads


@pytest.mark.parametrize("law", [(0.3, 1.0, 0.0), (0.25, 0.4, 0.6), (0.12, 0.2, 2.0)])
@pytest.mark.parametrize("crown", [0.3, 0.05, 5.0])  # a/b = 1.3, 4.3, 0.21
def test_equals_exact_table_forces_at_each_axle(law, crown):
    model = prepared(ExactTableAdhesion(*law, contact=ContactGeometry(rail_lateral_radius=crown)))
    for creep in (1e-5, 3e-4, 2e-3, 0.02, 0.3, 1.0):
        xi = np.full(LOADS.size, creep)
        mu, _ = model.evaluate(xi, 25.0)
        np.testing.assert_allclose(mu, reference(model, xi, 25.0, LOADS), rtol=1e-12, atol=1e-15)


def test_slopes_are_the_curve_derivatives():
    model = prepared(ExactTableAdhesion(0.25, 0.4, 0.6))
    for creep in (0.0, 2e-4, 3e-3, 0.05):
        xi = np.full(LOADS.size, creep)
        mu, dmu, dmv = model.slopes(xi, 25.0)
        h = 1e-6 * max(creep, 1e-3)
        up = reference(model, xi + h, 25.0, LOADS)
        down = reference(model, xi - h, 25.0, LOADS)
        np.testing.assert_allclose(dmu, (up - down) / (2 * h), rtol=1e-5)
        fast = reference(model, xi, 25.0 + 1e-3, LOADS)
        np.testing.assert_allclose(dmv, (fast - mu) / 1e-3, rtol=1e-3, atol=1e-9)
    # Coulomb friction: the curve does not depend on the speed
    mu, dmu, dmv = prepared(ExactTableAdhesion(0.3)).slopes(np.full(4, 0.01), 25.0)
    assert np.all(dmv == 0.0)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=4, max_size=4),
       st.floats(0.0, 80.0), st.sampled_from([(0.3, 1.0, 0.0), (0.2, 0.3, 1.5)]))
def test_odd_in_creepage(creeps, speed, law):
    model = prepared(ExactTableAdhesion(*law))
    xi = np.array(creeps)
    mu, dmu, dmv = model.slopes(xi, speed)
    mu2, dmu2, dmv2 = model.slopes(-xi, speed)
    np.testing.assert_array_equal(mu2, -mu)
    np.testing.assert_array_equal(dmu2, dmu)
    np.testing.assert_array_equal(dmv2, -dmv)
    # (the table's value at zero creepage is ~1e-13 N, not exactly 0: mu ~ -1e-17 at
    # vanishing creepage)
    assert np.all(mu >= -1e-15) and np.all(mu <= law[0] * (1 + 1e-12))


def test_standstill_and_locked_wheel():
    model = prepared(ExactTableAdhesion(0.25, 0.4, 0.6))
    mu, dmu, _ = model.slopes(np.zeros(4), 0.0)
    assert np.all(mu == 0.0)
    assert np.all(dmu > 0.0)  # the initial slope (linear theory), not zero
    # a locked wheel at rest slides at creepage 1 with zero slip velocity: static friction
    mu, _, _ = model.slopes(np.ones(4), 0.0)
    np.testing.assert_allclose(mu, 0.25, rtol=1e-9)  # the table at creepage 1, not infinity
    # at speed it slides at mu0 (A + (1 - A) exp(-B V)) (full sliding, no spin: exact)
    mu, _, _ = model.slopes(np.ones(4), 20.0)
    np.testing.assert_allclose(mu, 0.25 * (0.4 + 0.6 * math.exp(-0.6 * 20.0)), rtol=1e-9)
    # an unloaded wheel has no adhesion
    mu, dmu, dmv = prepared(ExactTableAdhesion(0.3), loads=np.array([0.0, 5e4])).slopes(
        np.array([0.01, 0.01]), 10.0)
    assert mu[0] == dmu[0] == dmv[0] == 0.0 and mu[1] > 0.0


def test_available_is_the_peak():
    coulomb = prepared(ExactTableAdhesion(0.3))
    np.testing.assert_allclose(coulomb.available(25.0), 0.3, rtol=1e-8)
    falling = prepared(ExactTableAdhesion(0.25, 0.4, 0.6))
    grid = np.geomspace(1e-4, 1.0, 2000)
    best = np.max([falling.evaluate(np.full(4, x), 25.0)[0] for x in grid], axis=0)
    peak = falling.available(25.0)
    # the golden-section search finds the peak between the grid's points
    assert np.all(peak >= best - 1e-9) and np.all(peak <= best + 1e-5)


def test_full_stop_compiled_matches_python_path():
    # falling friction low enough that the axles slide, the built-in WSP releasing them
    def run(compiled):
        return simulate(VEHICLE, ExactTableAdhesion(0.1, 0.4, 0.6), 10.0, 5.5e5,
                        cylinders=BrakeCylinders(max_pressure=6e5), dt=4e-3, compiled=compiled,
                        wsp=WheelSlideProtection(period=8e-3))

    fast, slow = run(True), run(False)
    assert fast.success and fast.summary["vent_actions"] > 0
    assert fast.summary["max_slip"] > 0.01
    np.testing.assert_allclose(fast.histories.to_numpy(), slow.histories.to_numpy(),
                               rtol=1e-9, atol=1e-9)
    sim = BrakingSimulator(VEHICLE, ExactTableAdhesion(0.1, 0.4, 0.6), 10.0)
    assert sim.compiled and sim.runs_compiled


def test_stop_to_standstill_with_locked_axles():
    # no WSP, low friction: the wheels lock, the train slides to rest
    res = simulate(VEHICLE, ExactTableAdhesion(0.08), 6.0, 6e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), dt=4e-3)
    assert res.success and res.summary["max_slip"] > 0.9
    h = res.histories
    assert h["train_speed"].iloc[-1] <= 0.05
    # sliding at mu0 everywhere: the deceleration is about mu0 g
    assert res.stopping_distance == pytest.approx(6.0**2 / (2 * 0.08 * 9.81), rel=0.15)


def test_stable_step_limit_sees_falling_friction():
    tau, where = largest_stable_step(VEHICLE, ExactTableAdhesion(0.25, 0.2, 2.0), 30.0)
    assert math.isfinite(tau) and where["condition"] == "table model"
    tau_coulomb, _ = largest_stable_step(VEHICLE, ExactTableAdhesion(0.3), 30.0)
    # Coulomb friction: the curve falls only by the table's interpolation ripple where the
    # contact saturates (a dip of ~2e-4 mu at creepage ~4e-3 on this coach), which limits the
    # step to ~0.02 s, ten times the default step
    assert tau_coulomb > tau and tau_coulomb > 0.01


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"mu": -0.1}, "mu"), ({"mu": 0.0}, "mu"), ({"mu": math.nan}, "mu"),
    ({"friction_ratio": 1.5}, "friction_ratio"), ({"friction_decay": -1.0}, "friction_decay"),
    ({"mu": "0.3"}, "mu"),
    ({"contact": ContactGeometry(poisson=0.35)}, "contact.poisson"),
    ({"contact": ContactGeometry(rail_lateral_radius=0.01)}, "contact a/b"),
])
def test_bad_parameters_name_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        ExactTableAdhesion(**kwargs)


def test_from_polach_takes_the_friction_of_the_set():
    p = polach_parameters("polach2005_wet")
    m = ExactTableAdhesion.from_polach("polach2005_wet")
    assert (m.mu, m.friction_ratio, m.friction_decay) == (p.mu0, p.A, p.B)
    assert m.describe()["model"] == "table"


SCENARIO = """
format = "railadhesion-brake-scenario"
version = 1
name = "table"
[vehicle]
file = "coach_default"
[run]
initial_speed_m_s = 8.0
time_step_s = 0.002
[brake]
pressure_Pa = 3e5
[adhesion]
model = "table"
{adhesion}
"""


def test_scenario_picks_the_table_model(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.format(adhesion='parameters = "polach2005_wet"'))
    sc = load_scenario(path)
    model = sc.adhesion()
    wet = polach_parameters("polach2005_wet")
    assert isinstance(model, ExactTableAdhesion)
    assert (model.mu, model.friction_ratio, model.friction_decay) == (wet.mu0, wet.A, wet.B)
    path.write_text(SCENARIO.format(adhesion="mu = 0.2\nfriction_ratio = 0.5\n"
                                             "friction_decay_s_per_m = 0.3"))
    model = load_scenario(path).adhesion()
    assert (model.mu, model.friction_ratio, model.friction_decay) == (0.2, 0.5, 0.3)
    assert isinstance(load_scenario(path).dry_adhesion(), ExactTableAdhesion)


@pytest.mark.parametrize(("adhesion", "field"), [
    ("mu = 3.0", "adhesion.mu"),
    ("friction_ratio = -1", "adhesion.friction_ratio"),
    ('parameters = "polach2005_wet"\nmu = 0.2', "adhesion.mu"),
    ("water_flow_ul_s = 3.0", "adhesion.water_flow_ul_s"),
    ("rail_lateral_radius_m = 0.05\n[[adhesion.sections]]\nstart_m = 1\nend_m = 2\n"
     "water_flow_ul_s = 1", "adhesion.sections"),
    ("rail_lateral_radius_m = 0.06", None),  # a/b = 3.9: in the table's range
    ("rail_lateral_radius_m = 0.02", "adhesion.rail_lateral_radius_m"),  # a/b = 7.5
])
def test_scenario_errors_name_the_field(tmp_path, adhesion, field):
    from railadhesion.braking import BrakingFileError

    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.format(adhesion=adhesion))
    if field is None:
        load_scenario(path)
        return
    with pytest.raises(BrakingFileError, match=field):
        load_scenario(path)


def test_mu_field_only_for_table_model(tmp_path):
    from railadhesion.braking import BrakingFileError

    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.replace('model = "table"', 'model = "polach"').format(
        adhesion="mu = 0.2"))
    with pytest.raises(BrakingFileError, match="adhesion.mu"):
        load_scenario(path)


def test_cli_brake_runs_a_table_scenario(tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.format(adhesion="mu = 0.3"))
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["brake", str(path), "--out", str(out), "--no-figures",
                                   "--quiet"])
    assert res.exit_code == 0, res.output
    assert (out / "summary.json").exists() or any(out.iterdir())


def test_table_and_polach_agree_in_full_sliding():
    # same mu0, A, B: both slide at mu0 (A + (1 - A) exp(-B V)) at creepage 1
    table = prepared(ExactTableAdhesion.from_polach("polach2005_dry"))
    polach = prepared(PolachAdhesion("polach2005_dry"))
    a = table.evaluate(np.ones(4), 20.0)[0]
    b = polach.evaluate(np.ones(4), 20.0)[0]
    np.testing.assert_allclose(a, b, rtol=0.02)


def test_stepping_api_compiled_matches_python_path():
    # the buffer entry points of the TABLE family (advance_table) against the Python path
    def run(compiled):
        sim = BrakingSimulator(VEHICLE, ExactTableAdhesion(0.1, 0.4, 0.6), 10.0,
                               compiled=compiled, record=False)
        for k in range(300):
            valves = [0, 0, 0, 0] if (k // 100) % 2 == 0 else [2, 1, 0, 2]
            state = sim.step(2e-3, {"pressure_command": [6e5, 6e5, 5e5, 5e5],
                                    "valves": valves})
        return sim, state

    (fast, a), (slow, b) = run(True), run(False)
    assert fast.runs_compiled and not slow.runs_compiled
    np.testing.assert_allclose(a.wheel_speeds, b.wheel_speeds, rtol=1e-10)
    assert a.distance == pytest.approx(b.distance, rel=1e-12)
    assert max(a.creep) > 0.01  # the wheels slide
    np.testing.assert_allclose(fast.adhesion_available(), slow.adhesion_available(),
                               rtol=1e-12)


PROGRAMME = """
format = "railadhesion-wsp-programme"
version = 1
name = "table"
[defaults]
initial_speed_m_s = 8.0
time_step_s = 0.001
[[case]]
name = "t"
adhesion = {adhesion}
"""


def test_wsp_bench_case_with_the_table_model(tmp_path):
    from railadhesion.braking import load_wsp_programme, run_wsp_programme

    path = tmp_path / "p.toml"
    path.write_text(PROGRAMME.format(adhesion='{ model = "table", mu0 = 0.05, A = 0.5, '
                                              'B = 0.6 }'))
    case = load_wsp_programme(path).cases[0]
    assert case.adhesion.describe() == "table model mu0=0.05 A=0.5 B=0.6"
    model = case.adhesion.build()
    assert isinstance(model, ExactTableAdhesion)
    assert (model.mu, model.friction_ratio, model.friction_decay) == (0.05, 0.5, 0.6)
    res = run_wsp_programme(path)
    assert res.cases[0]["status"] == "ok"
    assert res.cases[0]["stopping_distance_m"] > res.cases[0]["dry_stopping_distance_m"]


@pytest.mark.parametrize(("adhesion", "field"), [
    ('{ model = "table", mu0 = 0.05, k_A = 0.5 }', "adhesion.k_A"),
    ('{ model = "table", mu0 = 0.05, start_m = 1.0, end_m = 9.0 }', "adhesion.start_m"),
    ('{ model = "table", parameters = "polach2005_wet", mu0 = 0.05 }', "adhesion.mu0"),
    ('{ model = "table", A = 0.5 }', "adhesion.mu0"),
    ('{ model = "table", mu0 = 0.05, A = 1.5 }', "adhesion.A"),
])
def test_wsp_bench_table_case_errors_name_the_field(tmp_path, adhesion, field):
    from railadhesion.braking import BrakingFileError, load_wsp_programme

    path = tmp_path / "p.toml"
    path.write_text(PROGRAMME.format(adhesion=adhesion))
    with pytest.raises(BrakingFileError, match=field):
        load_wsp_programme(path)
