"""Sensor models added for odometry (issue 23): the longitudinal accelerometer (bias, noise,
the gradient's gravity component, saturation), encoder pulse dropouts and faults, the
wheel-diameter drift with wear, the radar's scale error and outage; all seeded, all callable
from compiled code, all off by default (the WSP's readings do not change)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from railadhesion.braking.sensors import (
    AccelerometerSettings,
    EncoderFault,
    EncoderSettings,
    ExternalSpeedSettings,
    SensorModel,
    accelerometer,
    measure,
)
from railadhesion.braking.vehicle import GRAVITY

R = 0.46
PERIOD = 5e-3


def _run(model, speeds, n=1, accel=0.0, gradient=0.0, radius=None):
    """Feed true rail speeds [m/s] (the same on every axle); return readings [m/s], pulse
    counts, accelerometer readings and external speeds per period."""
    s = model.settings_record(n, gradient=gradient, wheel_radius=radius)
    state = model.state_record(n)
    w_out, pulses, acc, ext = [], [], [], []
    for k, v in enumerate(speeds):
        w, _, e = model.read(s, state, k * PERIOD, np.full(n, v / R), np.zeros(n), v, accel)
        w_out.append(w * R)
        pulses.append(state[0]["pulses"][:n].copy())
        acc.append(accelerometer(state))
        ext.append(e)
    return np.array(w_out), np.array(pulses), np.array(acc), np.array(ext)


@settings(max_examples=25, deadline=None)
@given(a=st.floats(-2.0, 1.5), gradient=st.floats(-0.04, 0.04), bias=st.floats(-0.05, 0.05))
def test_accelerometer_reads_specific_force_plus_bias(a, gradient, bias):
    """Without noise the reading is a + g sin(atan(gradient)) + bias exactly."""
    model = SensorModel(accelerometer=AccelerometerSettings(bias=bias, noise=0.0))
    _, _, acc, _ = _run(model, [20.0] * 3, accel=a, gradient=gradient)
    expected = a + GRAVITY * math.sin(math.atan(gradient)) + bias
    np.testing.assert_allclose(acc, expected, rtol=0, atol=1e-12)


def test_accelerometer_noise_is_seeded_white_and_saturates():
    model = SensorModel(accelerometer=AccelerometerSettings(bias=0.01, noise=0.05), seed=4)
    _, _, a1, _ = _run(model, [20.0] * 4000, accel=-0.8)
    _, _, a2, _ = _run(model, [20.0] * 4000, accel=-0.8)
    np.testing.assert_array_equal(a1, a2)
    assert abs(a1.mean() - (-0.79)) < 0.003 and abs(a1.std() - 0.05) < 0.003
    assert abs(np.corrcoef(a1[:-1], a1[1:])[0, 1]) < 0.05  # white
    # a ±1 m/s² sensor under a 2.1 m/s² brake reads its full scale, never more
    small = SensorModel(accelerometer=AccelerometerSettings(noise=0.05, range=1.0))
    _, _, a3, _ = _run(small, [20.0] * 200, accel=-2.1)
    assert np.all(a3 == -1.0)
    _, _, none, _ = _run(SensorModel(), [20.0] * 3)
    assert np.all(np.isnan(none))


def test_pulse_dropouts_lower_the_count_and_only_lower_the_reading():
    ideal = SensorModel(EncoderSettings(80.0, 0.0, 1e-6))
    lossy = SensorModel(EncoderSettings(80.0, 0.0, 1e-6, dropout_probability=0.05), seed=9)
    w0, p0, _, _ = _run(ideal, [30.0] * 2000)
    w1, p1, _, _ = _run(lossy, [30.0] * 2000)
    ratio = p1[-1, 0] / p0[-1, 0]
    assert 0.94 < ratio < 0.96  # 5 % of the pulses lost
    low = w1[10:, 0] < 30.0 * (1 - 1e-3)
    assert 0.2 < low.mean() < 0.45  # a period of about 6.6 pulses loses one in 1 - 0.95^6.6
    assert np.all(w1[10:, 0] <= 30.0 * (1 + 1e-3))  # a lost pulse never reads high
    assert np.all(w0[10:, 0] == pytest.approx(30.0, rel=1e-3))


def test_stuck_and_dead_encoders():
    speeds = [30.0 - 0.01 * k for k in range(800)]  # 2 m/s² for 4 s
    t_fault = 1.0
    k_fault = int(t_fault / PERIOD)
    faults = (EncoderFault(1, "stuck", t_fault), EncoderFault(2, "dead", t_fault))
    model = SensorModel(EncoderSettings(80.0, 0.005, 1e-6), faults=faults, seed=2)
    w, p, _, _ = _run(model, speeds, n=3)
    # stuck: the last reading before the fault and the count stay
    assert np.all(w[k_fault:, 0] == w[k_fault - 1, 0])
    assert np.all(p[k_fault:, 0] == p[k_fault - 1, 0])
    # dead: no pulses; the reading falls as one pitch over the time since the last edge
    assert np.all(p[k_fault + 1:, 1] == p[k_fault, 1])
    pitch = 2 * math.pi * R / 80
    for k in (k_fault + 40, k_fault + 200, 799):
        assert w[k, 1] <= pitch / (k * PERIOD - t_fault) + 1e-9
    # the healthy axle goes on
    assert w[-1, 2] == pytest.approx(speeds[-1], rel=0.02) and p[-1, 2] > p[k_fault, 2] + 1000


def test_diameter_drift_grows_with_the_distance_rolled():
    # 1e-3 per km (exaggerated wear): after rolling 1 km the wheel reads 0.1 % high
    model = SensorModel(EncoderSettings(0.0, 0.0, 0.0, 0.01, diameter_drift=1e-3))
    v = 40.0
    steps = int(1000.0 / v / PERIOD) + 1
    w, _, _, _ = _run(model, [v] * steps, radius=R)
    rolled = (steps - 1) * PERIOD * v
    assert w[-1, 0] / v == pytest.approx(1.01 + 1e-6 * rolled, rel=1e-9)
    with pytest.raises(ValueError, match="wheel_radius"):
        model.settings_record(1)


def test_radar_scale_error_and_outage():
    ext = ExternalSpeedSettings(noise=0.0, latency=0.0, period=0.02, scale_error=0.03,
                                outage=(0.5, 1.0))
    _, _, _, e = _run(SensorModel(external=ext), [25.0] * 400)
    t = np.arange(400) * PERIOD
    sample_t = np.floor(t / 0.02 + 1e-9) * 0.02
    lost = (sample_t >= 0.5) & (sample_t < 1.0)
    assert np.all(np.isnan(e[lost]))
    np.testing.assert_allclose(e[~lost], 25.0 * 1.03, rtol=1e-12)


def test_odometry_additions_run_in_compiled_code():
    model = SensorModel(EncoderSettings(80.0, 0.005, 1e-6, 0.01, dropout_probability=0.01),
                        ExternalSpeedSettings(), 3, AccelerometerSettings(),
                        (EncoderFault(2, "dead", 0.5),))
    s, state = model.settings_record(4, gradient=0.01), model.state_record(4)

    @njit
    def loop(s, state, n_steps):
        w_true = np.full(4, 50.0)
        p_true = np.zeros(4)
        w = np.zeros(4)
        p = np.zeros(4)
        acc = 0.0
        for k in range(n_steps):
            measure(s, state, k * 5e-3, w_true, p_true, 23.0, -0.5, w, p)
            acc += accelerometer(state)
        return w, acc / n_steps

    w, acc = loop(s, state, 400)
    assert acc == pytest.approx(-0.5 + GRAVITY * math.sin(math.atan(0.01)) + 0.005, abs=0.01)
    assert w[1] < 0.5 and w[0] > 40.0  # axle 2 dead since 0.5 s


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: EncoderSettings(dropout_probability=0.7), "dropout_probability"),
        (lambda: EncoderSettings(diameter_drift=-1e-6), "diameter_drift"),
        (lambda: ExternalSpeedSettings(scale_error=0.5), "scale_error"),
        (lambda: ExternalSpeedSettings(outage=(2.0, 1.0)), "outage end"),
        (lambda: ExternalSpeedSettings(outage=(1.0,)), "outage"),
        (lambda: AccelerometerSettings(range=0.0), "range"),
        (lambda: AccelerometerSettings(noise=math.nan), "noise"),
        (lambda: EncoderFault(0), "axle"),
        (lambda: EncoderFault(1, "broken"), "kind"),
        (lambda: SensorModel(faults=(EncoderFault(1), EncoderFault(1, "dead"))),
         "one fault per axle"),
        (lambda: SensorModel(faults=(EncoderFault(5),)).settings_record(4), "axle 5"),
        (lambda: SensorModel().settings_record(4, gradient=0.3), "gradient"),
    ],
)
def test_bad_odometry_sensor_settings_name_the_argument(make, message):
    with pytest.raises(ValueError, match=message):
        make()
