"""Braking simulator: closed forms, energy balance, lock logic, errors, both code paths."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from railadhesion.braking import (
    BrakeCylinders,
    BrakingSimulator,
    CallableAdhesion,
    PolachAdhesion,
    SimulationError,
    Vehicle,
    WaterFlowProfile,
    WilacAdhesion,
    simulate,
)
from railadhesion.models import polach_forces, wilac_forces
from railadhesion.models.wilac import default_wilac_parameters
from railadhesion.plausibility import AlteredResultWarning

VEHICLE = Vehicle(name="test coach")  # no running resistance, level track


def ample(creep, speed):
    """Ample adhesion: a steep, smooth curve saturating at 0.6."""
    return 0.6 * np.tanh(300.0 * creep)


def test_closed_form_step_pressure():
    # step pressure (instant fill), ample adhesion: d = n c p / (R M_eff) (seed 002 eq. 8)
    p = 2.5e5
    cyl = BrakeCylinders(fill_time_constant=1e-9)
    v0 = 12.0
    res = simulate(VEHICLE, CallableAdhesion(ample), v0, p, cylinders=cyl, dt=4e-3)
    d = VEHICLE.n_axles * VEHICLE.brake_coefficient * p / (
        VEHICLE.wheel_radius * VEHICLE.effective_mass)
    assert res.success
    assert res.stopping_distance == pytest.approx(v0**2 / (2 * d), rel=5e-3)
    assert res.stopping_time == pytest.approx(v0 / d, rel=5e-3)


def test_first_order_pressure_build_up_against_independent_integral():
    p, tau, v0 = 3.0e5, 0.8, 20.0
    cyl = BrakeCylinders(fill_time_constant=tau)
    res = simulate(VEHICLE, PolachAdhesion("polach2005_dry"), v0, p, cylinders=cyl, dt=2e-3)
    k = VEHICLE.n_axles * VEHICLE.brake_coefficient / (
        VEHICLE.wheel_radius * VEHICLE.effective_mass)

    def speed(t):  # v0 - k ∫ p (1 - exp(-s/tau)) ds
        return v0 - k * p * (t - tau * (1 - math.exp(-t / tau)))

    t_stop = brentq(speed, 0.0, 100.0)
    inner = t_stop - tau * (1 - math.exp(-t_stop / tau))
    dist = v0 * t_stop - k * p * (t_stop**2 / 2 - tau * inner)
    assert res.stopping_time == pytest.approx(t_stop, rel=5e-3)
    assert res.stopping_distance == pytest.approx(dist, rel=5e-3)


def test_energy_balance_from_histories_damp_with_wsp():
    profile = WaterFlowProfile.sections([(20.0, 200.0, 25.0)])
    res = simulate(VEHICLE, WilacAdhesion(profile), 20.0, 5.5e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), wsp=True, dt=1e-3)
    h = res.histories
    n = VEHICLE.n_axles
    omega = h[[f"wheel_speed_{i}" for i in range(1, n + 1)]].to_numpy()
    ke = 0.5 * VEHICLE.total_mass * h["train_speed"] ** 2 + 0.5 * VEHICLE.wheelset_inertia * (
        omega**2).sum(axis=1)
    lost = ke.iloc[0] - ke.iloc[-1]
    t = h["time"].to_numpy()
    pres = h[[f"brake_pressure_{i}" for i in range(1, n + 1)]].to_numpy()
    force = h[[f"creep_force_{i}" for i in range(1, n + 1)]].to_numpy()
    slip = h["train_speed"].to_numpy()[:, None] - omega * VEHICLE.wheel_radius
    brake = np.trapezoid((VEHICLE.brake_coefficient * pres * omega).sum(axis=1), t)
    creep = np.trapezoid((force * slip).sum(axis=1), t)
    assert res.summary["vent_actions"] > 0  # WSP was active
    assert creep > 0.001 * lost  # the creep work matters here
    assert brake + creep == pytest.approx(lost, rel=5e-3)
    assert abs(res.summary["energy"]["balance_error"]) < 5e-3


def test_python_path_matches_compiled_path(polach_curve):
    # the same Polach curve as a model in Python (an independent NumPy oracle, called back
    # by the step) and as the step's compiled law
    family = PolachAdhesion("polach2005_wet")

    class Wrapped(CallableAdhesion):
        def prepare(self, speed, normal_loads, positions, time, dissipation=None):
            family.prepare(speed, normal_loads, positions, time, dissipation)

        def evaluate(self, creep, speed):
            return polach_curve(creep, speed, family.weights, family.params,
                                family.stiffness)

        def available(self, speed):
            return family.available(speed)

    wrapped = Wrapped(lambda c, v: c)
    family.bind(4, VEHICLE.wheel_radius)
    kwargs = dict(cylinders=BrakeCylinders(max_pressure=9e5), dt=4e-3)
    a = simulate(VEHICLE, PolachAdhesion("polach2005_wet"), 8.0, 9e5, **kwargs)
    b = simulate(VEHICLE, wrapped, 8.0, 9e5, **kwargs)
    assert a.summary["max_slip"] > 0.9  # axles lock: the hard case
    assert b.stopping_distance == pytest.approx(a.stopping_distance, rel=1e-9)
    np.testing.assert_allclose(b.histories["wheel_speed_3"], a.histories["wheel_speed_3"],
                               atol=1e-7)


def test_family_curve_matches_library_models():
    q = np.array([40e3, 55e3, 60e3, 70e3])
    xi = np.array([1e-4, 0.01, 0.3, 1.0])
    pol = PolachAdhesion("polach2005_dry")
    pol.bind(4, 0.46)
    pol.prepare(30.0, q, np.zeros(4), 0.0)
    a, b = pol.contact.semi_axes(q)
    fx, _ = polach_forces(xi, 0.0, 0.0, q, 30.0, a, b, mu0=0.55, k_A=1.0, k_S=0.4, A=0.4, B=0.6)
    np.testing.assert_allclose(pol.evaluate(xi, 30.0)[0], -fx / q, rtol=1e-12)
    wil = WilacAdhesion(25.0)
    wil.bind(4, 0.46)
    wil.prepare(30.0, q, np.zeros(4), 0.0)
    fx, _ = wilac_forces(xi, 0.0, 0.0, q, 30.0, a, b, 25.0, default_wilac_parameters())
    np.testing.assert_allclose(wil.evaluate(xi, 30.0)[0], -fx / q, rtol=1e-12)
    mu, dmu = wil.evaluate(xi, 30.0)
    mu2, _ = wil.evaluate(xi + 1e-7, 30.0)
    np.testing.assert_allclose(dmu, (mu2 - mu) / 1e-7, rtol=1e-4, atol=1e-6)


def test_nan_from_user_callable_names_time_and_axle():
    def bad(creep, speed):
        out = 0.4 * np.tanh(100 * creep)
        if speed < 5.5:
            out = out.copy()
            out[2] = np.nan
        return out

    with pytest.raises(SimulationError, match=r"axle 3 at t = [0-9.]+ s") as info:
        simulate(VEHICLE, CallableAdhesion(bad), 6.0, 3e5, dt=4e-3)
    assert "distance" in str(info.value)


def test_stepping_api_is_fmi_like_and_deterministic():
    def run():
        sim = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_wet"), 20.0)
        states = [sim.step(1e-3, {"pressure_command": 3e5, "valves": [0, 0, 2, 2]})
                  for _ in range(500)]
        return sim, states

    sim, states = run()
    _, again = run()
    assert states[-1].train_speed == again[-1].train_speed
    # vent valves on axles 3-4: their cylinders stay empty, axles 1-2 fill
    assert states[-1].brake_pressures[2] == 0.0 and states[-1].brake_pressures[0] > 2e5
    with pytest.raises(AttributeError, match="parameter"):
        sim.vehicle = Vehicle()
    with pytest.raises(ValueError, match="valves"):
        sim.step(1e-3, {"valves": [0, 5, 0, 0]})
    with pytest.raises(ValueError, match="unknown input"):
        sim.step(1e-3, {"pressure": 1.0})
    # one long step is split into sub-steps no longer than max_step
    s2 = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_wet"), 20.0, max_step=1e-3)
    st = s2.step(0.5, {"pressure_command": 3e5, "valves": [0, 0, 2, 2]})
    assert st.time == pytest.approx(0.5)
    assert st.train_speed == pytest.approx(states[-1].train_speed, rel=1e-9)


def test_locked_wheel_stays_locked_without_wsp_and_static_brake_holds():
    # low adhesion at high creep: once locked, R T < c p keeps the wheel at rest
    res = simulate(VEHICLE, WilacAdhesion(25.0), 15.0, 6e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), dt=4e-3)
    h = res.histories
    assert res.summary["longest_lock_s"] > 0.8 * res.stopping_time
    assert (h["wheel_speed_1"] >= 0).all()


@pytest.mark.parametrize("case", ["wilac_wsp", "wilac_recovery_bogie", "polach_sections"])
def test_compiled_loop_matches_python_loop(case):
    from railadhesion.braking import AdhesionRecovery, WheelSlideProtection

    cyl = BrakeCylinders(max_pressure=6e5)
    if case == "wilac_wsp":
        make = lambda: WilacAdhesion(WaterFlowProfile.sections([(10.0, 500.0, 25.0)]))  # noqa: E731
    elif case == "wilac_recovery_bogie":
        cyl = BrakeCylinders(max_pressure=6e5, valves="bogie")
        make = lambda: WilacAdhesion(WaterFlowProfile([0.0, 30.0, 60.0], [0.0, 30.0, 25.0]),  # noqa: E731
                                     recovery=AdhesionRecovery())
    else:
        make = lambda: PolachAdhesion("polach2005_dry", [(10.0, 40.0, "polach2005_wet")])  # noqa: E731
    runs = [simulate(VEHICLE, make(), 12.0, 5.5e5, cylinders=cyl, dt=4e-3, compiled=flag,
                     wsp=None if case == "polach_sections" else WheelSlideProtection(period=8e-3))
            for flag in (True, False)]
    a, b = (r.histories for r in runs)
    assert a.shape == b.shape
    assert runs[0].summary["vent_actions"] == runs[1].summary["vent_actions"]
    np.testing.assert_allclose(a.to_numpy(), b.to_numpy(), rtol=1e-9, atol=1e-9)


def test_stepping_api_compiled_matches_python():
    def run(compiled):
        sim = BrakingSimulator(VEHICLE, WilacAdhesion(WaterFlowProfile.sections([(5, 50, 25.0)])),
                               15.0, compiled=compiled)
        for k in range(400):
            valves = [0, 0, 0, 0] if (k // 100) % 2 == 0 else [2, 1, 0, 2]
            state = sim.step(2e-3, {"pressure_command": [5e5, 5e5, 4e5, 4e5], "valves": valves})
        return sim, state

    (fast, a), (slow, b) = run(True), run(False)
    assert fast.compiled and fast.runs_compiled and not slow.runs_compiled
    np.testing.assert_allclose(a.wheel_speeds, b.wheel_speeds, rtol=1e-10)
    assert a.distance == pytest.approx(b.distance, rel=1e-12)
    np.testing.assert_allclose(fast.histories().to_numpy(), slow.histories().to_numpy(),
                               rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(fast.vent_actions, slow.vent_actions)


def test_fletcher_condition_as_user_callable_and_xarray_result():
    from railadhesion import fletcher_condition

    water = fletcher_condition("W1")  # Fletcher 2013 twin-disc, water

    def mu(creep, speed):
        return np.asarray(water.adhesion(creep), float)

    res = simulate(VEHICLE, CallableAdhesion(mu, label="Fletcher W1"), 8.0, 4e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), dt=5e-3)
    assert res.success and res.settings["adhesion"]["function"] == "Fletcher W1"
    ds = res.to_xarray()
    assert ds["wheel_speed"].dims == ("time", "axle") and ds.sizes["axle"] == 4
    np.testing.assert_allclose(ds["train_speed"].values, res.histories["train_speed"])
    # the slip adhesion used never exceeds the friction coefficient of the condition
    assert ds["adhesion_used"].max() <= water.mu + 1e-9


# --- careless inputs (issue 18): standstill, step size, pressure cap, unfinished stops --------

COACH_DAMP = WaterFlowProfile.sections([(50.0, 900.0, 25.0)])


@pytest.mark.parametrize("wsp", [False, True])
def test_speed_never_goes_negative_at_standstill(wsp):
    # the case: stop_speed 1e-6 made the train speed -1.7 mm/s and a creep of -1657
    from railadhesion.braking import WheelSlideProtection

    kwargs = dict(cylinders=BrakeCylinders(max_pressure=6e5), dt=2.5e-3,
                  wsp=WheelSlideProtection() if wsp else None)
    res = simulate(VEHICLE, WilacAdhesion(COACH_DAMP), 20.0, 5.5e5, stop_speed=1e-6, **kwargs)
    ref = simulate(VEHICLE, WilacAdhesion(COACH_DAMP), 20.0, 5.5e5, **kwargs)
    h = res.histories
    omega = h[[f"wheel_speed_{i}" for i in range(1, 5)]].to_numpy()
    creep = h[[f"creep_{i}" for i in range(1, 5)]].to_numpy()
    assert res.success and res.trusted
    assert h["train_speed"].min() >= 0.0 and omega.min() >= 0.0
    assert np.all(np.abs(creep) <= 1.0)  # braking creep in [0, 1]; never beyond
    last = h.iloc[-1]
    if last["train_speed"] == 0.0:  # at rest: the creepage is defined as 0, wheels at rest
        assert np.all(creep[-1] == 0.0) and np.all(omega[-1] == 0.0)
    # the last 5 cm/s add v²/(2d) to the default stop: the two stops agree to a few cm
    assert res.stopping_distance == pytest.approx(ref.stopping_distance, abs=0.05)
    assert res.stopping_time >= ref.stopping_time - 0.01


def test_train_at_rest_within_a_step_stops_where_friction_stops_it():
    # large steps, locked wheels, the train comes to rest inside a step: v = 0, not below
    res = simulate(VEHICLE, PolachAdhesion("polach2005_wet"), 3.0, 6e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), dt=0.05, stop_speed=1e-9)
    h = res.histories
    assert h["train_speed"].iloc[-1] == 0.0 and h["train_speed"].min() == 0.0
    assert res.stopping_time <= h["time"].iloc[-1] + 1e-12
    assert res.stopping_time > h["time"].iloc[-2]
    assert np.all(np.isfinite(h.to_numpy()[1:]))


def test_a_step_too_large_for_the_wheel_dynamics_is_refused_with_the_largest_stable_step():
    from railadhesion.braking.simulator import largest_stable_step

    coach = Vehicle(name="coach")
    tau, where = largest_stable_step(coach, WilacAdhesion(COACH_DAMP), 44.44)
    # the reported step is the slide time constant J v / (R² N |dμ/dξ|) at the reported point
    expected = coach.wheelset_inertia * where["speed_m_s"] / (
        coach.wheel_radius**2 * where["axle_load_N"] * abs(where["slope"]))
    assert tau == pytest.approx(expected, rel=1e-12)
    assert 0.005 < tau < 0.03 and where["condition"] == "WILAC at 25 µl/s"
    for dt in (0.04, 0.05):  # the steps: now refused up front, the cause named
        with pytest.raises(ValueError, match=rf"largest stable step is {tau:.3g} s"):
            simulate(coach, WilacAdhesion(COACH_DAMP), 44.44, 5.5e5, dt=dt)
    # just below it the stop is computed, and close to the 1 ms stop
    step = math.floor(tau * 1e3) / 1e3
    with pytest.warns(AlteredResultWarning, match="outside the calibrated range"):  # 160 km/h
        a = simulate(coach, WilacAdhesion(COACH_DAMP), 44.44, 5.5e5, dt=step,
                     cylinders=BrakeCylinders(max_pressure=6e5))
    with pytest.warns(AlteredResultWarning, match="outside the calibrated range"):
        b = simulate(coach, WilacAdhesion(COACH_DAMP), 44.44, 5.5e5, dt=1e-3,
                     cylinders=BrakeCylinders(max_pressure=6e5))
    assert a.stopping_distance == pytest.approx(b.stopping_distance, rel=2e-3)
    # a curve that never falls allows any step
    assert largest_stable_step(coach, CallableAdhesion(ample), 44.44)[0] == math.inf


def test_demand_above_the_cylinder_limit_is_reported_not_silently_clipped():
    import warnings

    from railadhesion.braking import WheelSlideProtection, load_vehicle
    from railadhesion.plausibility import AlteredResultWarning

    coach = load_vehicle("coach_default")
    with pytest.warns(AlteredResultWarning, match="outside the calibrated range"), \
            pytest.warns(AlteredResultWarning, match=r"550000 Pa \(5.5 bar\).*380000 Pa"):
        res = simulate(coach, WilacAdhesion(COACH_DAMP), 44.44, 5.5e5,
                       wsp=WheelSlideProtection())
    assert res.summary["pressure_clipped"] and res.summary["max_pressure_Pa"] == 3.8e5
    # the extrapolation beyond WILAC's calibrated 40 m/s (160 km/h), then the clipped demand
    assert len(res.warnings) == 2 and "outside the calibrated range" in res.warnings[0]
    assert "5.5 bar" in res.warnings[1] and res.summary["warnings"] == res.warnings
    assert res.trusted  # altered, not untrusted: the stop at 3.8 bar is computed correctly
    assert res.stopping_distance == pytest.approx(728.3, abs=0.05)  # the number
    # a function of time above the limit: reported after the run
    with pytest.warns(AlteredResultWarning, match="clipped to it in"):
        simulate(VEHICLE, PolachAdhesion(), 5.0, lambda t: 4e5 if t > 0.5 else 1e5,
                 dt=4e-3)
    # within the limit: no pressure warning, no flag; only the extrapolation of WILAC beyond
    # its calibrated 40 m/s (160 km/h = 44.44 m/s), reported as such
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = simulate(coach, WilacAdhesion(COACH_DAMP), 44.44, 5.5e5,
                       cylinders=BrakeCylinders(max_pressure=6e5), wsp=WheelSlideProtection())
    calibrated = ("initial_speed = 44.44 m/s is outside the calibrated range [2, 40] m/s of "
                  "the WILAC set 'wilac_default_reconstruction'")
    assert [type(w.message) for w in caught] == [AlteredResultWarning]
    assert not res.summary["pressure_clipped"] and len(res.warnings) == 1
    assert res.warnings[0].startswith(calibrated) and str(caught[0].message) == res.warnings[0]


def test_a_stop_that_does_not_end_is_untrusted():
    import warnings

    from railadhesion.plausibility import UntrustedResultWarning

    # a whole stop expected (max_time left at 600 s): flagged and warned
    with pytest.warns(UntrustedResultWarning, match="did not stop within max_time = 600 s"):
        res = simulate(VEHICLE, PolachAdhesion(), 40.0, 1e4, dt=4e-3)
    assert not res.trusted and not res.summary["trusted"] and res.status == 1
    assert math.isnan(res.stopping_distance)
    assert res.summary["warnings"] == res.warnings and len(res.warnings) == 1
    # the first seconds of a stop asked for: flagged, not warned
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(VEHICLE, PolachAdhesion(), 20.0, 2e5, dt=4e-3, max_time=2.0)
    assert not res.trusted and "did not stop within max_time = 2 s" in res.warnings[0]
