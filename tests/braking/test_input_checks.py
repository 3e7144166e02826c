"""Careless inputs of the braking simulator (docs/checks.md): km/h for m/s, bar or kPa for Pa,
and the calibrated ranges of the adhesion model, each warned of and recorded on the result."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from railadhesion.braking import (
    BrakeCylinders,
    BrakeDemand,
    BrakingSimulator,
    PolachAdhesion,
    Vehicle,
    WaterFlowProfile,
    WilacAdhesion,
    simulate,
)
from railadhesion.braking.scenario import load_scenario
from railadhesion.models.wilac import default_wilac_parameters
from railadhesion.plausibility import AlteredResultWarning, PlausibilityWarning, UnitWarning

VEHICLE = Vehicle(name="test coach")  # 4 axles, 55.16 kN per wheel, no running resistance
WILAC_SET = "the WILAC set 'wilac_default_reconstruction'"


def caught_warnings(f):
    """(result of f(), the warnings it issued)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = f()
    return out, [w for w in caught if issubclass(w.category, PlausibilityWarning)
                 or issubclass(w.category, AlteredResultWarning)]


# -- initial speed in km/h --------------------------------------------------------------------


def test_simulate_sniffs_km_h_in_initial_speed_and_records_it_on_the_result():
    with pytest.warns(UnitWarning, match=r"initial_speed = 160 m/s is outside the plausible "
                      r"range \[0, 100\] m/s.*given in km/h\? \(160 km/h = 44.44 m/s"):
        res = simulate(VEHICLE, PolachAdhesion(), 160.0, 3e5, dt=4e-3)
    assert res.success
    assert any(w.startswith("initial_speed = 160 m/s") and "km/h" in w for w in res.warnings)
    assert res.summary["warnings"] == res.warnings
    # implausible, flagged; not untrusted (the stop from 160 m/s is computed as asked)
    assert res.trusted and res.summary["trusted"]


def test_the_stepping_api_sniffs_km_h_at_construction():
    with pytest.warns(UnitWarning, match=r"initial_speed = 200 m/s .*given in km/h\? "
                      r"\(200 km/h = 55.56 m/s"):
        sim = BrakingSimulator(VEHICLE, PolachAdhesion(), 200.0, max_step=4e-3)
    assert len(sim.warnings) == 1 and "km/h" in sim.warnings[0]


def test_plausible_speeds_and_pressures_give_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(VEHICLE, PolachAdhesion(), 30.0, 3e5, dt=4e-3)
        sim = BrakingSimulator(VEHICLE, WilacAdhesion(0.0), 30.0, max_step=4e-3)
        sim.step(0.01, {"pressure_command": 0.0})  # brakes released: no pressure to judge
        sim.step(0.01, {"pressure_command": 3e5})
        cylinders = BrakeCylinders(max_pressure=6e5)
    assert res.warnings == [] and res.trusted and sim.warnings == []
    assert cylinders.max_pressure_note() is None


# -- the calibrated ranges of WILAC -----------------------------------------------------------


def test_wilac_beyond_its_calibrated_speed_is_an_altered_result_on_the_result():
    with pytest.warns(AlteredResultWarning, match=rf"initial_speed = 44.44 m/s is outside the "
                      rf"calibrated range \[2, 40\] m/s of {WILAC_SET}: its parameters are held"):
        res = simulate(VEHICLE, WilacAdhesion(0.0), 160 / 3.6, 3e5, dt=4e-3)
    assert len(res.warnings) == 1 and "calibrated range [2, 40] m/s" in res.warnings[0]
    assert res.summary["warnings"] == res.warnings
    # altered, not untrusted: as a clipped pressure, and as Wilac.adhesion's extrapolation
    assert res.trusted and res.summary["trusted"]
    # 90 m/s: both the calibrated range and nothing else (90 m/s is a plausible speed)
    _, caught = caught_warnings(lambda: BrakingSimulator(VEHICLE, WilacAdhesion(0.0), 90.0,
                                                         max_step=4e-3))
    assert [w.category for w in caught] == [AlteredResultWarning]
    assert "initial_speed = 90 m/s is outside the calibrated range" in str(caught[0].message)
    # km/h and beyond the calibrated range: both said
    _, caught = caught_warnings(lambda: BrakingSimulator(VEHICLE, WilacAdhesion(0.0), 160.0,
                                                         max_step=4e-3))
    assert [w.category for w in caught] == [UnitWarning, AlteredResultWarning]


def test_the_calibrated_wheel_load_range_of_the_wilac_set_is_checked():
    params = default_wilac_parameters().replace(normal_force_range=(4200.0, 30000.0))
    with pytest.warns(AlteredResultWarning, match=r"test coach: static wheel load = 5.516e\+04 "
                      r"N is outside the calibrated range \[4200, 3e\+04\] N of the WILAC set"):
        sim = BrakingSimulator(VEHICLE, WilacAdhesion(0.0, params), 30.0, max_step=4e-3)
    assert len(sim.warnings) == 1 and "static wheel load" in sim.warnings[0]


def test_models_without_a_calibrated_range_are_not_flagged():
    assert PolachAdhesion().calibrated_ranges() == ()
    speed, load = WilacAdhesion(0.0).calibrated_ranges()
    assert speed[:4] == ("speed", 2.0, 40.0, "m/s") and load[:4] == ("wheel_load", 4200.0,
                                                                     150000.0, "N")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim = BrakingSimulator(VEHICLE, PolachAdhesion(), 60.0, max_step=4e-3)
    assert sim.warnings == []


# -- brake pressures in bar or kPa ------------------------------------------------------------


@pytest.mark.parametrize("brake, unit", [(5.5, r"bar\? \(5.5 bar = 5.5e\+05 Pa"),
                                         (550.0, r"kPa\? \(550 kPa = 5.5e\+05 Pa")])
def test_simulate_sniffs_bar_and_kpa_in_the_brake_pressure(brake, unit):
    with pytest.warns(UnitWarning, match=rf"brake = {brake:g} Pa is outside the plausible range "
                      rf"\[5000, 2e\+06\] Pa of a brake demand .*given in {unit}"):
        res = simulate(VEHICLE, PolachAdhesion(), 30.0, brake, dt=4e-3, max_time=0.5)
    # no stop: the reason it is not trusted first, then the input it came from
    assert not res.trusted and "did not stop within max_time" in res.warnings[0]
    assert res.warnings[1].startswith(f"brake = {brake:g} Pa")


def test_a_brake_demand_and_a_demand_function_are_sniffed_too():
    with pytest.warns(UnitWarning, match=r"brake \(BrakeDemand.pressure\) = 5.5 Pa .*given in "
                      r"bar\?"):
        res = simulate(VEHICLE, PolachAdhesion(), 30.0, BrakeDemand(5.5, ramp_time=0.1),
                       dt=4e-3, max_time=0.5)
    assert "BrakeDemand.pressure" in res.warnings[1]
    # a function of time: its highest command, after the run
    with pytest.warns(UnitWarning, match=r"brake \(the highest command of the demand\) = 5.5 "
                      r"Pa .*given in bar\?"):
        res = simulate(VEHICLE, PolachAdhesion(), 30.0, lambda t: 5.5, dt=4e-3, max_time=0.5)
    assert any("highest command" in w for w in res.warnings)


def test_brake_cylinders_sniff_bar_in_max_pressure_recorded_on_the_result_once():
    with pytest.warns(UnitWarning, match=r"BrakeCylinders.max_pressure = 6 Pa is outside the "
                      r"plausible range \[5000, 2e\+06\] Pa .*given in bar\? \(6 bar = 6e\+05 Pa"):
        cylinders = BrakeCylinders(max_pressure=6.0)
    res, caught = caught_warnings(lambda: simulate(VEHICLE, PolachAdhesion(), 30.0, 5.0,
                                                   cylinders=cylinders, dt=4e-3, max_time=0.5))
    # warned once, when the cylinders were made; recorded on the result
    assert not any("max_pressure = 6 Pa" in str(w.message) for w in caught)
    assert any(w.startswith("BrakeCylinders.max_pressure = 6 Pa") for w in res.warnings)


def test_the_stepping_api_judges_a_too_high_command_of_step_once_and_not_in_advance():
    sim = BrakingSimulator(VEHICLE, PolachAdhesion(), 30.0, max_step=4e-3)
    with warnings.catch_warnings():  # a ramp passes through every small pressure: not judged
        warnings.simplefilter("error")
        for p in (0.0, 5.5, 2750.0, 3e5):
            sim.step(0.01, {"pressure_command": p})
    assert sim.warnings == []
    with pytest.warns(PlausibilityWarning, match=r"pressure_command = 5.5e\+07 Pa is outside "
                      r"the plausible range \[5000, 2e\+06\] Pa"):
        sim.step(0.01, {"pressure_command": 5.5e7})
    assert len(sim.warnings) == 1 and sim.warnings[0].startswith("pressure_command = 5.5e+07 Pa")
    with warnings.catch_warnings():  # the same command again: said once
        warnings.simplefilter("error")
        sim.step(0.01, {"pressure_command": [5.5e7] * 4})
        sim.inputs.pressure_command[:] = 5.5e8  # the fast path checks no plausibility
        sim.advance(0.01)
    assert len(sim.warnings) == 1
    np.testing.assert_array_equal(sim.inputs.pressure_command, 5.5e8)


# -- the routes agree -------------------------------------------------------------------------


def test_an_implausible_initial_speed_warns_on_every_route_the_file_refuses_beyond_150(
        tmp_path):
    """simulate and BrakingSimulator warn (never refuse) any positive speed; a study spec
    warns; a scenario file warns up to its field range 150 m/s and refuses beyond it."""
    text = (Path(__file__).resolve().parents[2] / "examples" / "brake_dry.toml").read_text()
    path = tmp_path / "fast.toml"
    path.write_text(text.replace("initial_speed_m_s = 44.44", "initial_speed_m_s = 120.0"))
    with pytest.warns(UnitWarning, match=r"run.initial_speed_m_s = 120 m/s .*km/h"):
        scenario = load_scenario(path)
    assert scenario.initial_speed == 120.0
    path.write_text(text.replace("initial_speed_m_s = 44.44", "initial_speed_m_s = 160.0"))
    with pytest.raises(ValueError, match=r"run.initial_speed_m_s.*\[0.1, 150\]"):
        load_scenario(path)
    with pytest.warns(UnitWarning, match="initial_speed = 160 m/s"):
        BrakingSimulator(VEHICLE, PolachAdhesion(), 160.0, max_step=4e-3)



def test_a_water_flow_profile_above_the_plausible_range_warns_once_and_is_recorded():
    # 25000 ul/s (seed 000 measured up to 350; the plausible range ends at 1000)
    with pytest.warns(PlausibilityWarning, match=r"WaterFlowProfile values = from 0 to "
                      r"2.5e\+04 .l/s is outside the plausible range \[0, 1000\]"):
        profile = WaterFlowProfile.sections([(50.0, 900.0, 25000.0)])
    res, caught = caught_warnings(lambda: simulate(VEHICLE, WilacAdhesion(profile), 30.0, 5.5e5,
                                                   dt=4e-3, max_time=0.5))
    assert not any("WaterFlowProfile" in str(w.message) for w in caught)  # said when made
    assert any(w.startswith("WaterFlowProfile values = from 0 to 2.5e+04") for w in res.warnings)
