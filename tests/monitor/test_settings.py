"""MonitorSettings: defaults with their sources, every impossible value named."""

from __future__ import annotations

import pytest

from railadhesion.identification import RSSB_BRAKING_ADHESION
from railadhesion.monitor import MonitorSettings
from railadhesion.monitor.settings import RSSB_BRAKING_ADHESION as MONITOR_RSSB


def test_defaults_are_the_sourced_values():
    s = MonitorSettings()
    assert s.threshold == 0.14 == RSSB_BRAKING_ADHESION == MONITOR_RSSB  # RSSB GM/GN2642
    assert s.sample_period == 2.4e-3  # seed 002 §5
    assert (s.wheel_cutoff, s.vehicle_cutoff) == (2.0, 0.5)  # seed 002 §5
    # issue 21's sensor noise and wheel-diameter tolerance
    assert (s.wheel_speed_noise, s.speed_noise, s.pressure_noise) == (0.02, 0.01, 1e3)
    assert s.radius_tolerance == 0.005


@pytest.mark.parametrize("name, value", [
    ("threshold", 0.0), ("threshold", -0.1), ("threshold", float("nan")),
    ("confidence", 1.0), ("sample_period", 0.0), ("block_time", 5.0), ("memory", 0.0),
    ("min_speed", 0.0), ("max_fit_creep", 0.0), ("speed_noise", 0.0),
    ("radius_tolerance", 0.5), ("change_blocks", 1.5), ("gap_factor", 1.0),
    ("threshold", "0.14"), ("learn_radius", 1), ("brake_coefficient", "pads"),
    ("shapes", "carter"),
])
def test_impossible_values_name_the_setting(name, value):
    with pytest.raises(ValueError, match=name):
        MonitorSettings(**{name: value})


def test_cutoffs_must_be_below_half_the_sampling_rate():
    with pytest.raises(ValueError, match="wheel_cutoff"):
        MonitorSettings(sample_period=0.1, wheel_cutoff=6.0)


def test_block_needs_three_samples():
    with pytest.raises(ValueError, match="block_time"):
        MonitorSettings(sample_period=0.05, block_time=0.1, wheel_cutoff=1.0,
                        vehicle_cutoff=0.5)


def test_round_trip_and_unknown_names():
    s = MonitorSettings(threshold=0.15, shapes="fletcher")
    assert MonitorSettings.from_dict(s.to_dict()) == s
    assert s.replace(threshold=0.1).threshold == 0.1
    with pytest.raises(ValueError, match="treshold"):
        MonitorSettings.from_dict({"treshold": 0.1})


def test_slope_bound_is_twice_kalkers_linear_theory():
    """Default max_slope: 2 x G a b C11 / Q of the coach's wheel (Hertz on a 0.3 m crown)."""
    import math

    from railadhesion.braking import ContactGeometry, load_vehicle
    from railadhesion.contact import hertz_3d, kalker_coefficients
    from railadhesion.monitor.estimator import max_slope

    coach = load_vehicle("coach_default")
    q = 0.5 * float(coach.axle_normal_loads(0.0).mean())
    h = hertz_3d(q, coach.wheel_radius, math.inf, 0.3)
    c11 = float(kalker_coefficients(h.a / h.b, 0.28)[0])
    kalker = 8.2e10 * h.a * h.b * c11 / q
    assert max_slope(coach, MonitorSettings()) == pytest.approx(2.0 * kalker, rel=1e-9)
    assert 170.0 < kalker < 185.0  # 177 for this contact
    assert ContactGeometry(coach.wheel_radius).shear_modulus == 8.2e10
    assert max_slope(coach, MonitorSettings(max_slope=250.0)) == 250.0
    with pytest.raises(ValueError, match="max_slope"):
        MonitorSettings(max_slope=0.5)
