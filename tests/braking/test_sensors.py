"""Sensor models of the WSP bench (railadhesion.braking.sensors): encoders by period
measurement, wheel-diameter errors, pressure transducers, an external speed sensor with
latency, the seeded generator, and the compiled-code contract of ``measure``."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from railadhesion.braking.sensors import (
    EncoderSettings,
    ExternalSpeedSettings,
    SensorModel,
    measure,
    noisy_sensors,
    random_normal,
    random_uniform,
)

R = 0.46


def _readings(model, speeds, n=1, period=5e-3, pressures=None):
    """Feed a sequence of true rail speeds [m/s] (the same on every axle); return the readings
    as rail speeds and the external speeds."""
    s, state = model.settings_record(n), model.state_record(n)
    out, ext = [], []
    for k, v in enumerate(speeds):
        p = np.full(n, 1e5) if pressures is None else np.full(n, pressures[k])
        w, pm, e = model.read(s, state, k * period, np.full(n, v / R), p, v)
        out.append(w * R)
        ext.append(e)
    return np.array(out), np.array(ext)


def test_ideal_sensors_read_the_truth():
    w, e = _readings(SensorModel(), [30.0, 29.9, 29.7], n=4)
    np.testing.assert_allclose(w, [[30.0] * 4, [29.9] * 4, [29.7] * 4], rtol=1e-15)
    assert np.all(np.isnan(e))  # no external sensor


def test_diameter_error_scales_the_reading():
    model = SensorModel(EncoderSettings(0.0, 0.0, 0.0, (0.01, -0.01, 0.005, 0.0)))
    w, _ = _readings(model, [20.0, 20.0], n=4)
    np.testing.assert_allclose(w[-1], 20.0 * np.array([1.01, 0.99, 1.005, 1.0]), rtol=1e-14)


@settings(max_examples=40, deadline=None)
@given(v=st.floats(0.5, 100.0), teeth=st.integers(40, 300))
def test_period_measurement_is_exact_to_the_clock(v, teeth):
    """Without jitter, the reading over k pitches is k pitches over the time between two edges
    rounded to the clock: relative error at most 2 clock ticks over the edge span."""
    model = SensorModel(EncoderSettings(float(teeth), 0.0, 1e-6, 0.0))
    w, _ = _readings(model, [v] * 60)
    pitch_time = 2 * math.pi * R / teeth / v
    span = max(pitch_time, math.floor(5e-3 / pitch_time) * pitch_time)
    readings = w[-40:, 0]
    readings = readings[readings != readings[0]] if np.ptp(readings) else readings
    assert np.all(np.abs(readings / v - 1) <= 2.5e-6 / span)


def test_quantisation_at_low_speed_and_decay_at_standstill():
    """At 0.3 m/s an 80-tooth wheel (R = 0.46 m) gives a pulse every 120 ms: the reading
    changes only at edges; after the wheel stops it falls as one pitch over the time since
    the last edge, towards zero."""
    model = SensorModel(EncoderSettings(80.0, 0.0, 1e-6, 0.0))
    speeds = [0.3] * 200 + [0.0] * 200
    w, _ = _readings(model, speeds)
    r = w[:, 0]
    changes = np.count_nonzero(np.diff(r[:200]))
    assert 5 <= changes <= 9  # one new reading per edge: 1 s / 0.12 s
    pitch = 2 * math.pi * R / 80
    t_stop = 200 * 5e-3
    for k in (250, 300, 399):
        assert r[k] <= pitch / (k * 5e-3 - t_stop) + 1e-12
    assert r[399] < 0.04 and np.all(np.diff(r[210:]) <= 1e-15)


def test_edge_jitter_gives_noise_of_the_expected_size_and_is_seeded():
    base = EncoderSettings(80.0, 0.005, 1e-6, 0.0)
    a, _ = _readings(SensorModel(base, seed=1), [50.0] * 2000)
    b, _ = _readings(SensorModel(base, seed=1), [50.0] * 2000)
    c, _ = _readings(SensorModel(base, seed=2), [50.0] * 2000)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    # two edge times per reading, each 0.5 % of a pitch: sqrt(2) * 0.005 / 7.6 pitches = 0.09 %
    rel = np.std(a[100:, 0]) / 50.0
    assert 0.5e-3 < rel < 1.5e-3
    assert abs(np.mean(a[100:, 0]) / 50.0 - 1) < 1e-4  # unbiased


def test_pressure_transducer_noise_resolution_and_floor():
    model = SensorModel(EncoderSettings(0.0, 0.0, 0.0, 0.0, 2e3, 1e3), seed=3)
    s, state = model.settings_record(2), model.state_record(2)
    got = []
    for k in range(2000):
        p = 5e4 if k < 1000 else 0.0
        _, pm, _ = model.read(s, state, k * 5e-3, np.full(2, 40.0), np.full(2, p), 18.0)
        got.append(pm.copy())
    got = np.array(got)
    np.testing.assert_allclose(got % 1e3, 0.0, atol=1e-9)  # on the resolution
    assert np.all(got >= 0.0)  # a gauge never reads below 0
    assert abs(np.mean(got[:1000]) - 5e4) < 300 and 1.5e3 < np.std(got[:1000]) < 2.5e3


def test_external_speed_arrives_after_its_latency():
    ext = ExternalSpeedSettings(noise=0.0, latency=0.1, period=0.02, min_speed=0.5)
    model = SensorModel(external=ext)
    period = 5e-3
    speeds = [20.0 - 2.0 * k * period for k in range(400)]
    _, e = _readings(model, speeds)
    assert np.all(np.isnan(e[:20]))  # the first sample (t = 0) arrives at t = 0.1 s
    for k in range(20, 400):
        t = k * period
        sample_t = math.floor((t - 0.1) / 0.02 + 1e-9) * 0.02  # newest sample taken by t - L
        assert e[k] == pytest.approx(20.0 - 2.0 * sample_t, abs=1e-9)
    # low-speed loss and dropouts read NaN
    _, e = _readings(SensorModel(external=ExternalSpeedSettings(0.1, 0.0, 0.02, 1.0)),
                     [0.8] * 50)
    assert np.all(np.isnan(e))
    _, e = _readings(SensorModel(external=ExternalSpeedSettings(dropout_probability=1.0)),
                     [30.0] * 50)
    assert np.all(np.isnan(e))


def test_generator_uniform_and_normal_statistics():
    rec = np.zeros(1, np.dtype([("rng", "u8")]))[0:1]

    @njit
    def draw(r, n):
        u = np.empty(n)
        z = np.empty(n)
        for k in range(n):
            u[k] = random_uniform(r[0])
            z[k] = random_normal(r[0])
        return u, z

    u, z = draw(rec, 200_000)
    assert u.min() > 0.0 and u.max() < 1.0 and abs(u.mean() - 0.5) < 3e-3
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1.0) < 0.01
    assert abs(np.mean(z**4) - 3.0) < 0.1  # Gaussian tails


def test_measure_runs_inside_compiled_code_without_python_objects():
    """The contract of the integrator: measure is callable from an njit step."""
    model = noisy_sensors(4, seed=5, external=ExternalSpeedSettings())
    s, state = model.settings_record(4), model.state_record(4)

    @njit
    def loop(s, state, n_steps):
        w_true = np.full(4, 50.0)
        p_true = np.full(4, 2e5)
        w = np.zeros(4)
        p = np.zeros(4)
        last = 0.0
        for k in range(n_steps):
            last = measure(s, state, k * 5e-3, w_true, p_true, 23.0, -0.5, w, p)
        return w, p, last

    w, p, last = loop(s, state, 400)
    assert np.all(np.isfinite(w)) and np.all(p > 0) and abs(last - 23.0) < 1.0
    assert state[0]["pulses"][0] > 0  # pulse counts kept for odometry (issue 23)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: EncoderSettings(pulses_per_revolution=2.0), "pulses_per_revolution"),
        (lambda: EncoderSettings(edge_jitter=-0.1), "edge_jitter"),
        (lambda: EncoderSettings(diameter_errors=(0.01, 0.2)), "diameter_errors[1]"),
        (lambda: ExternalSpeedSettings(latency=2.0, period=0.02), "latency / period"),
        (lambda: ExternalSpeedSettings(period=0.0), "period"),
        (lambda: SensorModel(seed=-1), "seed"),
        (lambda: SensorModel(EncoderSettings(diameter_errors=(0.01, 0.0))).state_record(4),
         "diameter_errors has 2"),
        (lambda: SensorModel().state_record(13), "n_axles"),
    ],
)
def test_bad_sensor_settings_name_the_argument(make, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        make()
