"""The simulator's traction-torque input (issue 23: traction cases with wheel spin):
``J dω/dt = R T − c p + τ``. Closed forms, spin limited by adhesion, energy balance, both code
paths, the static hold of a stopped wheel, and bad values named."""

import math

import numpy as np
import pytest

from railadhesion.braking import (
    BrakeCylinders,
    BrakingSimulator,
    CallableAdhesion,
    PolachAdhesion,
    Vehicle,
)
from railadhesion.braking.vehicle import GRAVITY
from railadhesion.models.parameters import PolachParameters

VEHICLE = Vehicle(name="test coach")  # no running resistance, level track


def low(mu0, a=1.0, b=0.0):
    return PolachAdhesion(PolachParameters(k_A=1.0, k_S=0.4, mu0=mu0, A=a, B=b, name="low",
                                           source="test"))


def ample(creep, speed):
    """Ample adhesion: a steep, smooth curve saturating at 0.6 (odd in the creepage)."""
    return 0.6 * np.tanh(300.0 * creep)


def _run(adhesion, torque, seconds, v0=10.0, compiled=True, pressure=0.0, dt=1e-3):
    sim = BrakingSimulator(VEHICLE, adhesion, v0, compiled=compiled, max_step=dt)
    sim.inputs.torque[:] = torque
    sim.inputs.pressure_command[:] = pressure
    for _ in range(int(round(seconds / dt))):
        sim.advance(dt)
    return sim


def test_rolling_traction_gives_the_closed_form_acceleration():
    # rolling wheels: M_eff dv/dt = Σ τ / R (seed 002 eq. 8 with the sign of the torque turned)
    tau = 1500.0
    sim = _run(CallableAdhesion(ample), tau, 2.0)
    a = VEHICLE.n_axles * tau / (VEHICLE.wheel_radius * VEHICLE.effective_mass)
    assert sim.live.train_speed == pytest.approx(10.0 + 2.0 * a, rel=1e-5)
    creep = sim.live.creep
    assert np.all(creep < 0) and np.all(creep > -1e-3)  # driving: wheels slightly faster


@pytest.mark.parametrize("mu0", [0.03, 0.08])
def test_spin_is_limited_by_adhesion_and_the_wheels_run_ahead(mu0):
    # torque twice the adhesion torque on a saturating curve (A = 1): the wheels spin up at
    # (τ − R N μ)/J and the train accelerates at about μ0 g
    n_load = VEHICLE.total_mass * GRAVITY / VEHICLE.n_axles
    tau = 2.0 * VEHICLE.wheel_radius * n_load * mu0
    sim = _run(low(mu0), tau, 3.0)
    h = sim.histories()
    late = h[h.time > 2.0]
    accel = np.polyfit(late.time, late.train_speed, 1)[0]
    assert accel == pytest.approx(mu0 * GRAVITY, rel=0.02)
    wheel = sim.live.wheel_speeds * VEHICLE.wheel_radius
    assert np.all(wheel > sim.live.train_speed + 5.0)
    assert np.all(sim.live.creep < -0.3)


def test_energy_balance_with_traction_closes():
    # brake_work is the work of the brake torque net of the traction torque
    n_load = VEHICLE.total_mass * GRAVITY / VEHICLE.n_axles
    sim = _run(low(0.05, 0.4, 0.6), 1.6 * VEHICLE.wheel_radius * n_load * 0.05, 4.0)
    h = sim.histories()
    gained = h.kinetic_energy.iloc[-1] - h.kinetic_energy.iloc[0]
    lost = h.brake_work.iloc[-1] + h.creep_work.iloc[-1] + h.resistance_work.iloc[-1]
    assert gained > 1e5
    assert abs(gained + lost) < 1e-3 * gained


def test_compiled_and_python_paths_agree_under_spin_and_braking():
    n_load = VEHICLE.total_mass * GRAVITY / VEHICLE.n_axles
    tau = np.array([1.0, 1.5, 2.0, 0.5]) * VEHICLE.wheel_radius * n_load * 0.05
    runs = []
    for compiled in (True, False):
        sim = BrakingSimulator(VEHICLE, low(0.05, 0.4, 0.6), 15.0, compiled=compiled,
                               max_step=1e-3)
        sim.inputs.torque[:] = tau
        for _ in range(1500):
            sim.advance(1e-3)
        sim.inputs.torque[:] = 0.0
        sim.inputs.pressure_command[:] = 3e5
        for _ in range(1500):
            sim.advance(1e-3)
        runs.append(sim.histories())
    a, b = runs
    for col in ("train_speed", "distance", "wheel_speed_1", "wheel_speed_3", "brake_work"):
        np.testing.assert_allclose(a[col], b[col], rtol=1e-9, atol=1e-9)


def test_stopped_wheel_turns_when_the_torque_beats_the_brake():
    # a locked wheel (ω = 0) held by c p starts turning only when τ exceeds c p - R N μ(1)
    cyl = BrakeCylinders(fill_time_constant=1e-9, vent_time_constant=1e-9)
    sim = BrakingSimulator(VEHICLE, low(0.03), 30.0, cylinders=cyl, max_step=1e-3)
    sim.inputs.pressure_command[:] = 4e5
    for _ in range(2000):
        sim.advance(1e-3)
    assert np.all(sim.live.wheel_speeds == 0.0)
    n_load = sim.live.normal_loads
    hold = VEHICLE.brake_coefficient * 4e5 - VEHICLE.wheel_radius * n_load * 0.03
    sim.inputs.torque[:] = 0.9 * hold  # less than the margin: still held
    for _ in range(200):
        sim.advance(1e-3)
    assert np.all(sim.live.wheel_speeds == 0.0)
    sim.inputs.torque[:] = 1.2 * hold + 500.0
    for _ in range(200):
        sim.advance(1e-3)
    assert np.all(sim.live.wheel_speeds > 0.0)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_bad_torque_is_named_and_the_step_not_taken(value):
    sim = BrakingSimulator(VEHICLE, low(0.05), 10.0)
    sim.advance(1e-3)
    t = sim.live.time
    sim.inputs.torque[2] = value
    with pytest.raises(ValueError, match=r"torque .* axle 3 has"):
        sim.advance(1e-3)
    assert sim.live.time == t
    sim.inputs.torque[2] = 0.0
    sim.advance(1e-3)
    assert sim.live.time > t


def test_step_mapping_accepts_torque():
    sim = BrakingSimulator(VEHICLE, CallableAdhesion(ample), 10.0)
    state = sim.step(0.5, {"torque": 1000.0})
    assert state.train_speed > 10.0
    np.testing.assert_array_equal(sim.inputs.torque, 1000.0)
    with pytest.raises(ValueError, match="torque"):
        sim.step(0.1, {"torque": [1.0, 2.0]})
    with pytest.raises(ValueError, match="allowed: pressure_command, valves, torque"):
        sim.step(0.1, {"traction": 1.0})
