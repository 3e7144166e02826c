"""The monitor in closed loop with the braking simulator (railadhesion.monitor.evaluation).

The coach brakes lightly, with a varying demand, onto a low-adhesion section; sensors noisy
as issue 21 says (encoder 0.02 rad/s, speed 0.01 m/s, pressure 0.01 bar, wheel diameters
+-0.5 %); the WSP in the loop; the monitor fed every 2.4 ms by its per-sample call.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from railadhesion.monitor import layout
from railadhesion.monitor.evaluation import (
    MonitorCase,
    NoisySensors,
    SensorNoise,
    run_case,
    run_dry_distance,
    run_traction_case,
)

# cases at 42-45 m/s on WILAC leave its set's calibrated 40 m/s: the simulator warns of it
# (docs/checks.md), which is not what these tests check
pytestmark = pytest.mark.filterwarnings(
    "ignore:initial_speed = .* is outside the calibrated range"
    ":railadhesion.plausibility.AlteredResultWarning")


@pytest.fixture(scope="module")
def low_case():
    return run_case(MonitorCase(condition="polach_wet_0.08", speed=40.0, creep=0.005, seed=3))


def test_low_section_found_within_two_seconds(low_case):
    """Polach wet-type set at friction 0.08 (available 0.066 at 40 m/s), 0.5 % creep: every
    axle low within 2 s of its entry, estimate within 0.02 of the truth and the truth inside
    the band once low, nothing low before the section."""
    res = low_case
    s = res.summary
    assert res.expected == "low" and s["truth"] == pytest.approx(0.066, abs=0.003)
    assert 0.003 < s["section_creep_median"] < 0.007
    delays = np.array(s["delays_s"], dtype=float)
    assert np.all(delays < 2.0), delays
    assert s["error_abs_max"] <= 0.02
    assert not s["false_low_before_section"]
    h = res.history
    low = h["level"] == layout.LOW
    inside = (h["lower"][low] <= h["truth"][low] + 1e-3) & (h["truth"][low] <= h["upper"][low])
    assert inside.mean() > 0.95


def test_leaving_the_section_ends_low(low_case):
    """Back on the dry rail the estimate restarts: no low 1.5 s after an axle leaves."""
    h = low_case.history
    for i in range(4):
        after = h["time"] > low_case.exit_time[i] + 1.5
        assert not (h["level"][after, i] == layout.LOW).any()


def test_damp_wilac_section_is_not_called_low():
    """WILAC at 25 ul/s with the package's reconstructed set peaks at 0.16-0.18 for this
    coach (2-5 % creep): not below 0.14. Light braking sees its plateau (0.12-0.13 up to
    0.7 % creep), which could saturate there or rise: caution, not low."""
    res = run_case(MonitorCase(condition="wilac_25", speed=45.0, creep=0.005, seed=4))
    assert res.truth > 0.14
    assert not (res.history["level"] == layout.LOW).any()
    k = np.searchsorted(res.history["time"], res.exit_time[0] - 0.5)
    assert (res.history["level"][k] == layout.CAUTION).all()


def test_steady_braking_onto_the_section_claims_only_what_it_sees():
    """No modulation of the demand. Entering the section, each wheel settles to its new creep
    over a few tenths of a second, and the force dips meanwhile (eq. 10's J omega_dot term
    measures it): that sweeps part of the new curve. What is claimed from it must hold: a
    band that holds the truth, low only where the truth is low."""
    res = run_case(MonitorCase(condition="polach_wet_0.08", speed=40.0, creep=0.005,
                               modulation=0.0, seed=5))
    h = res.history
    low = h["level"] == layout.LOW
    assert res.truth < 0.14
    truth = h["truth"][low]
    assert np.all((h["lower"][low] <= truth + 1e-3) & (truth <= h["upper"][low]))
    assert not res.summary["false_low_before_section"]


@pytest.mark.parametrize("traction", [False, True])
def test_dry_rail_gives_no_false_low(traction):
    out = run_dry_distance(3.0e3, seed=2, traction=traction)
    assert out["distance_km"] >= 3.0
    assert out["low_episodes"] == 0 and out["low_axle_seconds"] == 0.0
    # the runs used the rail's curve, not only its straight part: the level was not all unknown
    assert out["level_share"]["normal"] > 0.01


def test_sensor_noise_of_the_issue():
    class Live:
        train_speed = 40.0
        wheel_speeds = np.full(4, 40.0 / 0.46)
        brake_pressures = np.full(4, 1e5)

    sensors = NoisySensors(4, SensorNoise(), seed=1)
    assert np.all(np.abs(sensors.factor - 1.0) <= 0.005)
    reads = np.array([np.concatenate(([r[0]], r[1], r[2]))
                      for r in (sensors.read(Live) for _ in range(4000))])
    assert np.std(reads[:, 0]) == pytest.approx(0.01, rel=0.1)
    w = reads[:, 1:5] / sensors.factor
    assert np.std(w - Live.wheel_speeds, axis=0) == pytest.approx(np.full(4, 0.02), rel=0.1)
    assert np.std(reads[:, 5:], axis=0) == pytest.approx(np.full(4, 1e3), rel=0.1)
    tq = np.array([sensors.read(Live, torque=np.full(4, 2.5e3))[3] for _ in range(4000)])
    assert np.std(tq, axis=0) == pytest.approx(np.full(4, 50.0), rel=0.1)
    assert np.mean(tq) == pytest.approx(2.5e3, abs=5.0)
    again = NoisySensors(4, SensorNoise(), seed=1)
    assert np.array_equal(again.factor, NoisySensors(4, SensorNoise(), seed=1).factor)


@pytest.mark.parametrize(("condition", "speed", "creep"),
                         [("polach_wet_0.08", 30.0, 0.005), ("polach_wet_0.055", 55.0, 0.002)])
def test_traction_only_case(condition, speed, creep):
    """No brake, traction torque with the same varying demand onto the low section."""
    res = run_traction_case(MonitorCase(condition=condition, speed=speed, creep=creep, seed=6))
    s = res.summary
    delays = np.array(s["delays_s"], dtype=float)
    assert np.all(np.isfinite(delays) & (delays < 2.0))
    assert s["error_abs_max"] <= 0.02
    assert not s["false_low_before_section"]
    assert math.isfinite(res.truth) and res.truth < 0.14
    h = res.history
    low = h["level"] == layout.LOW
    assert (h["creep"][low] < 0).all()  # traction: xi < 0 (docs/CONVENTIONS.md)
    inside = (h["lower"][low] <= h["truth"][low] + 1e-3) & (h["truth"][low] <= h["upper"][low])
    assert inside.mean() > 0.95
    assert s["mean_torque_N_m"] > 1e3 and "mean_pressure_Pa" not in s


def test_traction_onto_damp_wilac_is_not_called_low():
    """As under braking: WILAC at 25 ul/s peaks above 0.14 for this coach, so never low."""
    res = run_traction_case(MonitorCase(condition="wilac_25", speed=42.0, creep=0.005, seed=7))
    assert res.truth > 0.14
    assert not (res.history["level"] == layout.LOW).any()
