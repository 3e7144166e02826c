"""Identification from braking logs: eq. 14, loads (eqs. 11-12), eq. 10, closed loop."""

import minisim
import numpy as np
import pandas as pd
import pytest

from railadhesion.braking import Vehicle
from railadhesion.identification.brake_tests import (
    brake_coefficient,
    brake_coefficient_per_sample,
    identify_adhesion,
)
from railadhesion.identification.curves import fit_adhesion_curves
from railadhesion.identification.logs import braking_log_from_frame

G = 9.80665


def analytic_log(vehicle, c_true, n=8000, dt=2.4e-3):
    """A noise-free log that satisfies eqs. 6-8 exactly at every sample.

    Pressures are ramps, angular speeds quadratics (angular accelerations linear), so the
    vehicle deceleration from eq. 8 is linear and the speed quadratic: central differences are
    exact. Returns the frame and the true angular accelerations and deceleration.
    """
    t = np.arange(n) * dt
    r, j, m = vehicle.wheel_radius, vehicle.wheelset_inertia, vehicle.total_mass
    p = np.stack([(2.5 + 0.05 * i + 0.02 * t) * 1e5 for i in range(4)], axis=1)  # Pa
    wdot = np.stack([-2.0 - 0.1 * i - 0.01 * t for i in range(4)], axis=1)
    w0 = 30.0 / r
    w = np.stack([w0 - (2.0 + 0.1 * i) * t - 0.005 * t**2 for i in range(4)], axis=1)
    d = (j * wdot.sum(axis=1) + c_true * p.sum(axis=1)) / (r * m)  # eq. 8, linear in t
    d0, d1 = np.polyfit(t, d, 1)[::-1]
    v = 30.0 + 0.5 - d0 * t - 0.5 * d1 * t**2
    frame = pd.DataFrame({"time": t, "train_speed": v})
    for i in range(4):
        frame[f"wheel_speed_{i + 1}"] = w[:, i]
    for i in range(4):
        frame[f"brake_pressure_{i + 1}"] = p[:, i] / 1e5
    return frame, wdot, d, p


@pytest.mark.parametrize("mode", ["zero-phase", "causal"])
def test_eq14_returns_the_true_c_on_a_noise_free_log(mode):
    veh = Vehicle()
    c_true = 0.0173
    frame, *_ = analytic_log(veh, c_true)
    res = identify_adhesion(braking_log_from_frame(frame), veh, filter_mode=mode)
    assert res.brake.mean == pytest.approx(c_true, rel=1e-7)
    assert res.brake.std < 1e-7 * c_true
    assert res.brake.n_samples > 5000


def test_eq14_per_sample_by_hand_with_running_resistance():
    # eq. 14 with F_res: c = (M_tot d - F_res - J sum w_dot / R) / (sum p / R)
    veh = Vehicle(davis_a=1500.0, davis_b=20.0, davis_c=3.0)
    r, j, m = veh.wheel_radius, veh.wheelset_inertia, veh.total_mass
    d = np.array([0.9, 1.1, 0.0])
    wsum = np.array([-8.0, -9.5, 0.0])
    psum = np.array([12e5, 14e5, 0.0])
    v = np.array([30.0, 20.0, 10.0])
    res = 1500.0 + 20.0 * v + 3.0 * v * v
    c = brake_coefficient_per_sample(d, wsum, psum, veh, resistance=res, where=psum > 0)
    hand = (m * d[:2] - res[:2] - j * wsum[:2] / r) / (psum[:2] / r)
    assert c[:2] == pytest.approx(hand, rel=1e-14)
    assert np.isnan(c[2])  # brake released: no c (no division by zero)
    # the window path subtracts the same resistance when given the speed
    wd = np.repeat(wsum[:2, None] / 4, 4, axis=1)
    p = np.repeat(psum[:2, None] / 4, 4, axis=1)
    got = brake_coefficient([0.0, 0.1], d[:2], wd, p, veh, speed=v[:2])
    assert got.per_sample == pytest.approx(hand, rel=1e-14)


def test_both_paths_compute_eq14_with_one_function(monkeypatch):
    from railadhesion.identification import brake_tests

    calls = []
    law = brake_tests.brake_coefficient_per_sample

    def counted(*args, **kwargs):
        calls.append(len(np.atleast_1d(args[0])))
        return law(*args, **kwargs)

    monkeypatch.setattr(brake_tests, "brake_coefficient_per_sample", counted)
    veh = Vehicle()
    frame, wdot, d, p = analytic_log(veh, 0.02, n=3000)
    ident = brake_tests.identify_adhesion(braking_log_from_frame(frame), veh)
    direct = brake_tests.brake_coefficient(frame["time"], d, wdot, p, veh)
    assert calls == [3000, 3000]
    assert direct.mean == pytest.approx(0.02, rel=1e-12)
    assert ident.brake.mean == pytest.approx(0.02, rel=1e-7)


def test_load_transfer_against_hand_calculation():
    veh = Vehicle()  # M_c 32600 kg, M_t 3200 kg, M_a 1500 kg, h 0.8 m, l 9.5 m
    frame, *_ = analytic_log(veh, 0.02)
    res = identify_adhesion(braking_log_from_frame(frame), veh)
    k = 4000
    d = res.deceleration[k]
    # by hand: each bogie carries M_c g / 2 = 159 848.4 N, the leading one gains
    # M_c h d / (2 l) = 32600 * 0.8 * d / 19 = 1372.63 d N; each axle carries half of its
    # bogie's share, half the bogie mass (15 690.6 N) and its wheelset (14 710.0 N).
    share = 32600 * G / 2
    transfer = 32600 * 0.8 * d / (2 * 9.5)
    lead = (share + transfer) / 2 + 3200 * G / 2 + 1500 * G
    trail = (share - transfer) / 2 + 3200 * G / 2 + 1500 * G
    assert share == pytest.approx(159848.4, abs=0.1)
    assert res.normal_load[k] == pytest.approx([lead, lead, trail, trail], rel=1e-12)
    assert res.normal_load[k].sum() == pytest.approx(veh.total_mass * G, rel=1e-12)


def test_eq10_adhesion_on_the_noise_free_log():
    veh = Vehicle()
    c_true = 0.02
    frame, wdot, d, p = analytic_log(veh, c_true)
    res = identify_adhesion(braking_log_from_frame(frame), veh)
    k = slice(1000, 7000)
    loads = veh.axle_normal_loads(d[k])
    mu = (veh.wheelset_inertia * wdot[k] + c_true * p[k]) / (veh.wheel_radius * loads)
    assert np.allclose(res.mu[k], mu, rtol=1e-6)
    # absolute and relative slip
    v = frame.train_speed.to_numpy()[k]
    w = frame[[f"wheel_speed_{i}" for i in range(1, 5)]].to_numpy()[k]
    # (filtered at 2 Hz: a quadratic is smoothed by ~1e-5 m/s)
    assert np.allclose(res.slip[k], v[:, None] - veh.wheel_radius * w, atol=1e-4)
    assert np.allclose(res.relative_slip[k], res.slip[k] / res.speed[k, None])


def _closed_loop(mini_run, vehicle, noise, mode="zero-phase"):
    t, v, om, p, _mu = mini_run
    frame = minisim.log_frame(t, v, om, p, noise=noise, seed=7)
    res = identify_adhesion(braking_log_from_frame(frame), vehicle, filter_mode=mode)
    law = fit_adhesion_curves(res)
    return res, law


@pytest.mark.parametrize("mode", ["zero-phase", "causal"])
def test_closed_loop_own_simulator_with_sensor_noise(mini_run, mini_vehicle, mode):
    # sensor noise of the issue: speed 0.01 m/s, wheel speed 0.02 rad/s, pressure 0.01 bar
    res, law = _closed_loop(mini_run, mini_vehicle, (0.01, 0.02, 0.01), mode)
    assert res.brake.mean == pytest.approx(minisim.VEHICLE["brake_coefficient"], rel=0.02)
    curve = law.overall
    s = np.linspace(*curve.slip_range, 400)
    rms = np.sqrt(np.mean((curve(s) - minisim.law(s)) ** 2))
    assert rms <= 0.01
    assert curve.slip_range[1] > 2.5  # the WSP cycles cover the slip range up to ~3 m/s
    # the per-band curves too
    for band in law.bands:
        s = np.linspace(*band.slip_range, 400)
        assert np.sqrt(np.mean((band(s) - minisim.law(s)) ** 2)) <= 0.01


def test_windows_tell_loss_from_recovery(mini_run, mini_vehicle):
    res, _ = _closed_loop(mini_run, mini_vehicle, (0.01, 0.02, 0.01))
    w = res.windows
    assert set(w.phase) == {"loss", "recovery"}
    assert np.all(w.slip_end[w.phase == "loss"] > w.slip_start[w.phase == "loss"])
    rec = w.phase == "recovery"
    assert np.all(w.slip_end[rec] < w.slip_start[rec])
    # speed nearly constant within each window (tolerance 1 m/s)
    assert np.all(w.speed_std < 0.5)
    # phase marks agree with the windows
    assert (res.phase == 1).sum() == w[w.phase == "loss"].n_samples.sum()


def test_axle_count_mismatch(mini_run):
    t, v, om, p, _ = mini_run
    frame = minisim.log_frame(t[:500], v[:500], om[:500], p[:500])
    veh = Vehicle(n_axles=6)
    with pytest.raises(ValueError, match="axles"):
        identify_adhesion(braking_log_from_frame(frame), veh)


def test_pitch_angle_eq13_when_the_secondary_stiffness_is_given():
    veh = Vehicle(secondary_stiffness=1.2e6)
    frame, *_ = analytic_log(veh, 0.02)
    res = identify_adhesion(braking_log_from_frame(frame), veh)
    k = 4000
    d = res.deceleration[k]
    # eq. 13 by hand: theta = -M_c h d / (2 k2 l^2) = -32600 * 0.8 * d / (2 * 1.2e6 * 9.5**2)
    assert res.pitch_angle[k] == pytest.approx(-32600 * 0.8 * d / (2 * 1.2e6 * 90.25))
    assert res.pitch_angle[k] < 0
    assert identify_adhesion(braking_log_from_frame(frame), Vehicle()).pitch_angle is None


def test_threads_do_not_change_the_results(mini_run, mini_vehicle):
    # the channels and axles run in threads; each is computed alone, so 1 or 2 threads give
    # the same bits; a gap makes two segments (jobs per segment)
    t, v, om, p, _ = mini_run
    frame = minisim.log_frame(t, v, om, p, noise=(0.01, 0.02, 0.01), seed=5)
    frame = frame.drop(index=range(3000, 3100)).reset_index(drop=True)
    log = braking_log_from_frame(frame, warn=False)
    assert log.segment.max() == 1
    one = identify_adhesion(log, mini_vehicle, threads=1)
    two = identify_adhesion(log, mini_vehicle, threads=2)
    for name in ("speed", "deceleration", "angular_acceleration", "pressure", "normal_load",
                 "mu", "slip", "relative_slip", "slip_rate", "relative_slip_rate", "use",
                 "phase"):
        assert np.array_equal(getattr(one, name), getattr(two, name), equal_nan=True), name
    assert one.brake.mean == two.brake.mean
    pd.testing.assert_frame_equal(one.windows, two.windows)
    with pytest.raises(ValueError, match="threads"):
        identify_adhesion(log, mini_vehicle, threads=0)


def test_default_threads_follow_numba():
    # the identification uses as many threads as the compiled kernels: numba's setting, not
    # the cores the process may run on
    import numba

    from railadhesion.identification.brake_tests import worker_count

    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert worker_count() == 1
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        assert worker_count() == numba.config.NUMBA_NUM_THREADS
    finally:
        numba.set_num_threads(before)
    assert worker_count(3) == 3


def test_loads_of_a_vehicle_that_is_not_affine_in_d(mini_run, mini_vehicle):
    # a vehicle whose loads are not affine in the deceleration is evaluated sample by sample
    class Curved:
        def __init__(self, veh):
            self.veh = veh

        def __getattr__(self, name):
            return getattr(self.veh, name)

        def axle_normal_loads(self, d):
            return self.veh.axle_normal_loads(d) * (1.0 + 0.01 * np.asarray(d)[..., None] ** 2)

    t, v, om, p, _ = mini_run
    log = braking_log_from_frame(minisim.log_frame(t, v, om, p), warn=False)
    ident = identify_adhesion(log, Curved(mini_vehicle))
    expected = Curved(mini_vehicle).axle_normal_loads(ident.deceleration)
    assert np.allclose(ident.normal_load, expected, rtol=1e-14)
    plain = identify_adhesion(log, mini_vehicle)
    assert np.allclose(plain.normal_load, mini_vehicle.axle_normal_loads(plain.deceleration),
                       rtol=1e-14)
