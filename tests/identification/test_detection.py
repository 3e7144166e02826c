"""Low-adhesion detection (Fletcher 2013's purpose) on his ten conditions."""

import math

import numpy as np
import pytest

from railadhesion.identification.detection import (
    RSSB_BRAKING_ADHESION,
    detect_low_adhesion,
    fletcher_detection_study,
)
from railadhesion.models.twod import fletcher_condition


def test_rssb_threshold_is_the_cited_value():
    # Fletcher 2013 §1: RSSB GM/GN2642 requires a CoA of 0.14 to sustain normal braking.
    assert RSSB_BRAKING_ADHESION == 0.14


@pytest.mark.parametrize("code", ["W1", "O1", "D3", "CG1"])
def test_exact_data_to_full_slip_recovers_mu_and_ka(code):
    cond = fletcher_condition(code)
    sat = 3 * cond.half_width * cond.mu / (2 * cond.k_a * cond.radius)
    xi = np.linspace(sat / 40, 1.5 * sat, 60)
    res = detect_low_adhesion(xi, cond.adhesion(xi), half_width=cond.half_width,
                              radius=cond.radius)
    assert res.mu == pytest.approx(cond.mu, rel=1e-4)
    assert res.params["k_a"] == pytest.approx(cond.k_a, rel=1e-4)
    assert res.saturation_creep == pytest.approx(sat, rel=1e-3)
    assert res.reached_full_slip
    assert res.level == ("low" if cond.mu < 0.14 else "normal")


def test_levels_follow_the_interval():
    w1 = fletcher_condition("W1")  # mu = 0.24
    xi = np.linspace(1e-4, 0.01, 50)
    assert detect_low_adhesion(xi, w1.adhesion(xi)).level == "normal"
    # the same curve against a higher threshold
    assert detect_low_adhesion(xi, w1.adhesion(xi), threshold=0.3).level == "low"


def test_straight_line_data_give_an_unbounded_interval():
    # data that show no curvature at all do not bound mu from above: no claim either way
    xi = np.linspace(1e-4, 1e-3, 30)
    rng = np.random.default_rng(1)
    y = 10.0 * xi + rng.normal(0, 1e-3, xi.size)
    res = detect_low_adhesion(np.abs(xi), np.abs(y))
    assert math.isinf(res.interval[1])
    assert res.interval[0] <= float(np.max(y)) + 0.01
    assert res.level == "caution"


def test_study_recovers_mu_at_one_percent_creep():
    df = fletcher_detection_study(truncations=(0.002, 0.01), seed=3)
    at1 = df[df.max_creep == 0.01]
    # at 1 % creep every condition's mu is recovered within 5 % or 0.003 (noise 0.002) and
    # classified correctly
    err = np.abs(at1.mu - at1.mu_true)
    assert np.all(err <= np.maximum(0.05 * at1.mu_true, 0.003))
    assert np.all(at1.level == at1.level_true)
    # coverage of the 95 % interval: at least 8 of 10 (finite-sample, one noise draw)
    assert at1.covered.sum() >= 8
    # at 0.2 % creep the intervals are much wider (mu is only bounded weakly)
    at02 = df[df.max_creep == 0.002]
    width = lambda d: (d.mu_high - d.mu_low).to_numpy()  # noqa: E731
    assert np.all(width(at02) > 3 * width(at1))


def test_polach_alternative_runs_and_reports_interval():
    from railadhesion.models.polach import polach_forces

    creep = np.linspace(2e-4, 0.01, 40)
    fx, _ = polach_forces(creep, 0.0, 0.0, 4200.0, 5.0, 4e-3, 3e-3, k_A=0.3, k_S=0.1,
                          mu0=0.1, A=1.0, B=0.0)
    res = detect_low_adhesion(creep, np.abs(fx) / 4200.0, model="polach", normal_force=4200.0,
                              speed=5.0, a=4e-3, b=3e-3)
    assert res.model == "polach"
    assert res.mu == pytest.approx(0.1, rel=0.02)
    assert res.interval[0] <= res.mu <= res.interval[1]
    assert "polach" in res.summary()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(model="carter"), "model"),
        (dict(threshold=-1.0), "threshold"),
        (dict(half_width=0.0), "half_width"),
        (dict(model="polach"), "normal_force"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    xi = np.linspace(1e-4, 0.01, 10)
    with pytest.raises(ValueError, match=match):
        detect_low_adhesion(xi, 5 * xi, **kwargs)


def test_too_few_points_and_nan():
    with pytest.raises(ValueError, match="at least 4"):
        detect_low_adhesion([0.001, 0.002], [0.01, 0.02])
    with pytest.raises(ValueError, match="finite"):
        detect_low_adhesion([0.001, 0.002, np.nan, 0.004], [0.01, 0.02, 0.03, 0.04])
