"""Closed loop with the package's braking simulator: law -> simulation -> log -> identification.

The log is written by ``railadhesion.braking.write_braking_log`` with the issue's sensor noise
(speed 0.01 m/s, wheel speed 0.02 rad/s, pressure 0.01 bar). The adhesion law is a low-adhesion
Polach set (not the identification's own functional form), so the fitted form must also be
flexible enough. The identified law is then run back through the simulator.
"""

import numpy as np
import pytest

from railadhesion.braking import Vehicle, write_braking_log
from railadhesion.braking.adhesion import CallableAdhesion, PolachAdhesion, polach_family_curve
from railadhesion.braking.run import simulate
from railadhesion.identification import (
    fit_adhesion_curves,
    identify_adhesion,
    load_adhesion_law,
    read_braking_log,
)
from railadhesion.models.parameters import PolachParameters

LOW = dict(k_A=0.3, k_S=0.1, mu0=0.13, A=0.4, B=0.3)
NOISE = {"train_speed": 0.01, "wheel_speed": 0.02, "brake_pressure": 0.01}


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    veh = Vehicle(name="coach")
    adhesion = PolachAdhesion(PolachParameters(**LOW, name="low adhesion"))
    result = simulate(veh, adhesion, 30.0, brake=3.8e5, wsp=True, dt=2.5e-3, max_time=10.0)
    path = tmp_path_factory.mktemp("loop") / "log.csv"
    write_braking_log(result, path, period=2.4e-3, noise=NOISE, seed=11)
    ident = identify_adhesion(read_braking_log(path), veh)
    return veh, adhesion, ident, fit_adhesion_curves(ident)


def _true_mu(adhesion, ident):
    rows, axles = np.nonzero(ident.use)
    v = ident.speed[rows]
    dv = ident.slip[rows, axles]
    stiff = adhesion.contact.stiffness_over_load(ident.normal_load[rows, axles] / 2)
    params = np.broadcast_to(np.array([[LOW[k] for k in ("k_A", "k_S", "mu0", "A", "B")]]),
                             (rows.size, 1, 5))
    mu, _ = polach_family_curve(dv / v, v[:, None], np.ones((rows.size, 1)), params, stiff)
    return v, dv, mu


def test_brake_coefficient_within_two_percent(loop):
    veh, _, ident, _ = loop
    assert ident.brake.mean == pytest.approx(veh.brake_coefficient, rel=0.02)
    assert ident.brake.std / ident.brake.mean < 0.05


def test_identified_law_matches_the_simulated_one(loop):
    _, adhesion, ident, law = loop
    v, dv, mu_true = _true_mu(adhesion, ident)
    assert dv.size > 5000
    # RMS over the slip range the log covers (every usable sample, all axles)
    rms = np.sqrt(np.mean((law.of_slip(dv, v) - mu_true) ** 2))
    assert rms <= 0.01
    # and the raw per-sample adhesion of eq. 10 is unbiased
    raw = ident.mu[ident.use]
    assert abs(np.mean(raw) - np.mean(mu_true)) < 0.002


def test_identified_law_drives_the_braking_simulator(loop, tmp_path):
    veh, _, _, law = loop
    path = law.save(tmp_path / "law.toml")
    loaded = load_adhesion_law(path)
    adhesion = CallableAdhesion(loaded, label=str(path))
    result = simulate(veh, adhesion, 25.0, brake=3.8e5, wsp=True, dt=2.5e-3, max_time=1.0)
    h = result.histories
    assert len(h) > 100 and np.all(np.isfinite(h.train_speed))
    assert h.train_speed.iloc[-1] < 25.0
