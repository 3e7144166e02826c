"""The braking integrator (Newton on the arrow-shaped backward-Euler system, the safeguarded
solve it falls back on, the adhesion-available tracking, the WILAC parameter program) and the
hardware-in-the-loop stepping API (``advance``, in-place inputs, live state)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.braking import (
    BrakeCylinders,
    BrakingSimulator,
    PolachAdhesion,
    Vehicle,
    WaterFlowProfile,
    WheelSlideProtection,
    WilacAdhesion,
)
from railadhesion.braking.run import BrakeDemand

VEHICLE = Vehicle(name="test coach")
CYL = BrakeCylinders(max_pressure=6e5)
DAMP = WaterFlowProfile.sections([(10.0, 400.0, 25.0)])


def _stop(newton_tol, compiled=True, v0=15.0, dt=2e-3):
    """A damp-rail stop with WSP; ``newton_tol`` 0 forces the safeguarded solve every step."""
    sim = BrakingSimulator(VEHICLE, WilacAdhesion(DAMP), v0, cylinders=CYL, max_step=dt,
                           compiled=compiled, wsp=WheelSlideProtection(period=4e-3))
    sim._machine[0]["settings"]["newton_tol"] = newton_tol
    sim.configure_run(BrakeDemand(5.5e5))
    sim.run_compiled(int(100 / dt), dt)
    return sim


def test_newton_and_safeguarded_solve_reach_the_same_backward_euler_solution():
    newton = _stop(5e-6)
    safe = _stop(0.0)  # no Newton update is ever accepted: every step by the nested solve
    cn, cs = newton.solver_counts, safe.solver_counts
    assert cs["safeguarded_steps"] == cs["steps"]
    assert cn["safeguarded_steps"] < 0.01 * cn["steps"]
    assert cn["newton_iterations"] < 1.5 * cn["steps"]  # mostly one iteration per step
    assert np.sum(newton.vent_actions) > 3  # WSP at work: slides and recoveries
    a, b = newton.histories(), safe.histories()
    assert a.shape == b.shape
    # the solvers' tolerances differ (accepted Newton update 5e-6 v, nested solve 1e-10 m/s);
    # a sliding wheel on the falling branch of its curve amplifies such differences: here axle
    # 4 slides to 60 % creep at 2.3 m/s (7.3-7.6 s; the wheel's time constant J v / (R² N
    # |dμ/dξ|) is about 0.05 s there), the valve sequences stay identical and the difference
    # grows from 1e-8 to 1.1e-4 m/s and decays again (stop: 1.8e-9 relative)
    assert newton.stop_distance == pytest.approx(safe.stop_distance, rel=5e-9)
    speeds = [f"wheel_speed_{i}" for i in range(1, 5)] + ["train_speed"]
    np.testing.assert_allclose(a[speeds].to_numpy(), b[speeds].to_numpy(), rtol=0, atol=2e-4)
    valves = [f"valve_{i}" for i in range(1, 5)]
    assert (a[valves].to_numpy() == b[valves].to_numpy()).all()


def test_one_newton_iteration_per_step_on_a_smooth_stop():
    res = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_dry"), 30.0, max_step=1e-3)
    res.inputs.pressure_command[:] = 3e5
    while not res.stopped:
        res.advance(1e-3)
    c = res.solver_counts
    assert c["safeguarded_steps"] == 0
    assert c["newton_iterations"] <= 1.05 * c["steps"]


def test_advance_equals_step_and_its_live_state_is_a_read_only_view():
    def make():
        return BrakingSimulator(VEHICLE, WilacAdhesion(DAMP), 12.0, cylinders=CYL,
                                max_step=1e-3, record=False)

    a, b = make(), make()
    live = a.advance(1e-3)  # nothing commanded yet: coasting
    b.step(1e-3)
    for k in range(1, 600):
        valves = [0, 0, 0, 0] if (k // 150) % 2 == 0 else [2, 1, 0, 2]
        a.inputs.pressure_command[:] = [5e5, 5e5, 4e5, 4e5]
        a.inputs.valves[:] = valves
        state = a.advance(1e-3)
        snap = b.step(1e-3, {"pressure_command": [5e5, 5e5, 4e5, 4e5], "valves": valves})
        assert state is live
        assert state.train_speed == snap.train_speed and state.distance == snap.distance
        np.testing.assert_array_equal(state.wheel_speeds, snap.wheel_speeds)
        np.testing.assert_array_equal(state.valves, snap.valves)
    kept = live.snapshot()
    a.advance(1e-3)
    assert live.time > kept.time and kept.time == pytest.approx(0.6)  # the view moved on
    with pytest.raises(ValueError, match="read-only"):
        live.wheel_speeds[0] = 0.0
    np.testing.assert_array_equal(a.vent_actions, b.vent_actions)


def test_advance_binds_the_compiled_entry_point_on_its_first_call():
    """advance() calls the step's compiled entry point (railadhesion._jit.kernel_entry), found
    on the first call by a call with dt = NaN that the step refuses: that first call must
    advance exactly once, recorded or not."""
    from railadhesion._jit import compiled_entry
    from railadhesion.braking import step

    for record, name, dispatcher in ((False, "_advance", step.advance_builtin),
                                     (True, "_advance_recorded",
                                      step.advance_builtin_recorded)):
        sim = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_dry"), 10.0,
                               record=record)
        stand_in = sim.__dict__[name]
        sim.advance(1e-3)
        assert sim.time == pytest.approx(1e-3) and sim.solver_counts["steps"] == 1
        bound = sim.__dict__[name]
        assert bound is not stand_in
        args = (sim._buffer, sim._rows, 1e-3) if record else (sim._buffer, 1e-3)
        assert bound is compiled_entry(dispatcher, args)
        sim.advance(1e-3)
        assert sim.time == pytest.approx(2e-3) and sim.__dict__[name] is bound


def test_advance_checks_its_inputs_and_names_the_axle():
    sim = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_dry"), 10.0)
    sim.advance(1e-3)
    t = sim.time
    sim.inputs.pressure_command[2] = np.nan
    with pytest.raises(ValueError, match="pressure_command.*axle 3"):
        sim.advance(1e-3)
    sim.inputs.pressure_command[2] = 1e5
    sim.inputs.valves[1] = 3
    with pytest.raises(ValueError, match="valves.*axle 2"):
        sim.advance(1e-3)
    sim.inputs.valves[1] = 1
    with pytest.raises(ValueError, match="dt"):
        sim.advance(-1e-3)
    assert sim.time == t  # a refused step changes nothing
    sim.advance(1e-3)
    assert sim.time == pytest.approx(t + 1e-3)


def test_python_path_takes_the_same_newton_iterations():
    runs = []
    for compiled in (True, False):
        sim = BrakingSimulator(VEHICLE, WilacAdhesion(DAMP), 8.0, cylinders=CYL, max_step=2e-3,
                               compiled=compiled)
        for k in range(300):
            sim.step(2e-3, {"pressure_command": 5.5e5,
                            "valves": [0, 0, 0, 0] if (k // 60) % 2 == 0 else [2, 2, 1, 0]})
        runs.append(sim)
    fast, slow = runs
    assert fast.runs_compiled and not slow.runs_compiled
    assert fast.solver_counts == slow.solver_counts
    assert fast.solver_counts["newton_iterations"] > fast.solver_counts["steps"]
    np.testing.assert_allclose(fast.omega, slow.omega, rtol=1e-10)
    assert fast.distance == pytest.approx(slow.distance, rel=1e-12)


def test_adhesion_available_tracking_matches_a_full_search(polach_curve):
    # slowly changing conditions: the tracked peak stays within 1e-7 of a fresh full search
    q = np.array([31e3, 31e3, 26e3, 26e3])
    tracked = WilacAdhesion(25.0)
    tracked.bind(4, 0.46)
    for k in range(30):
        speed, loads = 40.0 - 0.05 * k, q * (1.0 + 0.002 * k)
        tracked.prepare(speed, loads, np.zeros(4), 0.01 * k)
        got = tracked.available(speed)
        fresh = WilacAdhesion(25.0)
        fresh.bind(4, 0.46)
        fresh.prepare(speed, loads, np.zeros(4), 0.01 * k)
        np.testing.assert_allclose(got, fresh.available(speed), rtol=1e-7)
    assert tracked._workspace[0]["peak_calls"] == 30  # 29 of 30 calls tracked
    # and a brute-force maximum on a fine grid agrees
    grid = np.geomspace(1e-4, 1.0, 20001)
    mu, _ = polach_curve(np.repeat(grid, 4), speed, np.tile(fresh.weights, (grid.size, 1)),
                         np.tile(fresh.params, (grid.size, 1, 1)),
                         np.tile(fresh.stiffness, grid.size))
    np.testing.assert_allclose(got, mu.reshape(grid.size, 4).max(axis=0), rtol=1e-6)


def test_wilac_axle_parameters_equal_the_library_regressions():
    """Per axle, exactly the WILAC kernel's weights and regressions: axles evaluated four at
    once (a vehicle of 1, 4, 5 or 12 axles: the padding of the last block must not leak), a
    bogie pair (same load) and equal water flows (the weights reused from the axle before)."""
    from railadhesion.braking.curves import wilac_axle_parameters
    from railadhesion.braking.records import MAX_AXLES
    from railadhesion.models.kernels import (
        pack_wilac,
        wilac_condition_parameters,
        wilac_weights_scalar,
    )
    from railadhesion.models.wilac import default_wilac_parameters

    packed = pack_wilac(default_wilac_parameters())
    rng = np.random.default_rng(7)
    cases = [(np.array([36e3, 36e3, 21e3, 52e3]), np.array([12.0, 12.0, 25.0, 60.0]), 31.0),
             (np.array([2e3]), np.array([0.0]), 0.0),  # below the calibrated ranges
             (np.array([36e3, 36e3, 21e3, 21e3, 3e5]), np.array([12.0, 30.0, 30.0, 50.0, 80.0]),
              70.0),  # above them; five axles: one in a padded block
             (rng.uniform(1e4, 8e4, MAX_AXLES), rng.uniform(0.0, 80.0, MAX_AXLES), 17.0)]
    for loads, water, speed in cases:
        n = loads.size
        weights, params = np.empty((n, 4)), np.empty((n, 4, 5))
        scratch = np.full((8, MAX_AXLES), np.nan)
        wilac_axle_parameters(packed, loads, speed, water, weights, params, scratch)
        ref = np.empty(20)
        for a in range(n):
            wilac_condition_parameters(loads[a], speed, packed, np.empty(7), ref)
            np.testing.assert_array_equal(params[a].ravel(), ref)
            np.testing.assert_array_equal(weights[a], wilac_weights_scalar(water[a], packed))


def test_wilac_axle_parameters_of_weighted_conditions_only():
    """weighted_only (the braking step's refresh): the conditions some axle of a block of four
    weights get exactly the full computation's parameters; a condition no axle of a block
    weights is left as it was there."""
    from railadhesion.braking.curves import wilac_axle_parameters
    from railadhesion.braking.records import MAX_AXLES
    from railadhesion.models.kernels import pack_wilac
    from railadhesion.models.wilac import default_wilac_parameters

    packed = pack_wilac(default_wilac_parameters())
    loads = np.array([36e3, 36e3, 21e3, 21e3, 52e3, 52e3])
    water = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 5.0])  # dry, then a padded block, damper
    full, weights = np.empty((6, 4, 5)), np.empty((6, 4))
    wilac_axle_parameters(packed, loads, 31.0, water, weights, full,
                          np.empty((8, MAX_AXLES)))
    part = np.full((6, 4, 5), -1.0)
    wilac_axle_parameters(packed, loads, 31.0, water, np.empty((6, 4)), part,
                          np.empty((8, MAX_AXLES)), True)
    for block in (slice(0, 4), slice(4, 6)):
        used = (weights[block] != 0.0).any(axis=0)
        assert 0 < used.sum() < 4
        np.testing.assert_array_equal(part[block][:, used], full[block][:, used])
        assert (part[block][:, ~used] == -1.0).all()


def test_new_parameters_before_the_first_step_rebuild_the_simulator():
    sim = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_dry"), 10.0)
    sim.max_step = 1e-3
    sim.adhesion = PolachAdhesion("polach2005_wet")
    sim.step(0.01, {"pressure_command": 3e5})
    assert sim.solver_counts["steps"] == 10
    with pytest.raises(AttributeError, match="parameter"):
        sim.max_step = 2e-3


def test_numba_adhesion_function_runs_compiled_with_the_python_path_numbers():
    from numba import njit

    from railadhesion.braking import CallableAdhesion, SimulationError, simulate

    @njit
    def mu(creep, speed, load):  # a smooth law with a maximum, falling with speed and load
        return 0.3 * np.tanh(200.0 * creep) * (1.0 - 0.5 * creep) / (1.0 + 0.01 * speed) * (
            1.2 - load / 1.5e5)

    runs = [simulate(VEHICLE, CallableAdhesion(mu, needs_load=True), 15.0, 6e5, cylinders=CYL,
                     wsp=WheelSlideProtection(period=4e-3), dt=2e-3, compiled=flag)
            for flag in (True, False)]
    assert BrakingSimulator(VEHICLE, CallableAdhesion(mu, needs_load=True), 15.0).compiled
    a, b = (r.histories.to_numpy() for r in runs)
    assert runs[0].summary["vent_actions"] > 0
    assert a.shape == b.shape
    np.testing.assert_allclose(a[1:], b[1:], rtol=1e-9, atol=1e-9)  # row 0: NaN available

    @njit
    def bad(creep, speed):
        return np.nan if speed < 5.5 else 0.4 * np.tanh(100.0 * creep)

    with pytest.raises(SimulationError, match=r"axle 1 at t = [0-9.]+ s"):
        simulate(VEHICLE, CallableAdhesion(bad), 6.0, 3e5, dt=4e-3)

    @njit
    def arrays_only(creep, speed):
        return 0.3 * np.tanh(200.0 * creep) + 0.0 * creep.sum()

    with pytest.warns(UserWarning, match="Python path"):
        sim = BrakingSimulator(VEHICLE, CallableAdhesion(arrays_only), 10.0)
    assert not sim.runs_compiled


def test_builtin_wsp_in_the_stepping_api_equals_the_whole_stop():
    """The WSP runs inside the step for the stepping API too (valve inputs then ignored)."""
    from railadhesion.braking import simulate

    wsp = WheelSlideProtection(period=4e-3)
    ref = simulate(VEHICLE, WilacAdhesion(DAMP), 15.0, 5.5e5, cylinders=CYL, wsp=wsp, dt=2e-3)
    sim = BrakingSimulator(VEHICLE, WilacAdhesion(DAMP), 15.0, cylinders=CYL, max_step=2e-3,
                           wsp=WheelSlideProtection(period=4e-3))
    sim.inputs.pressure_command[:] = 5.5e5
    sim.inputs.valves[:] = 2.0  # ignored: the built-in WSP commands the valves
    while not sim.stopped:
        sim.advance(4e-3)  # two sub-steps per call, the WSP every 4 ms
    assert ref.summary["vent_actions"] > 3
    assert sim.stop_distance == pytest.approx(ref.stopping_distance, rel=1e-12)
    np.testing.assert_array_equal(sim.vent_actions, [a["vent_actions"] for a in
                                                    ref.summary["axles"]])
    np.testing.assert_allclose(sim.histories().to_numpy(), ref.histories.to_numpy(),
                               rtol=1e-12, atol=1e-12)


def test_the_step_runs_as_a_c_function_on_the_records():
    """The native-FMU route: the step compiled as a C callback over record pointers gives the
    stepping API's numbers (same code, no Python in between)."""
    import ctypes

    from numba import carray, cfunc, types
    from numba.np.numpy_support import from_dtype

    from railadhesion.braking import step

    machine_type = from_dtype(step.MACHINE)
    sig = types.int64(types.CPointer(machine_type), types.CPointer(types.float64),
                      types.int64, types.float64)

    @cfunc(sig, error_model="numpy")
    def c_step(machine_ptr, tables_ptr, n_tables, dt):
        m = carray(machine_ptr, (1,))[0]
        return step.step(m.state, m.settings, m.inputs, m.wsp_settings, m.wsp_state,
                         m.sensor_settings, m.sensor_state, carray(tables_ptr, (n_tables,)),
                         None, dt, 0)

    call = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int64,
                            ctypes.c_double)(c_step.address)
    a, b = (BrakingSimulator(VEHICLE, WilacAdhesion(DAMP), 12.0, cylinders=CYL, max_step=1e-3,
                             record=False) for _ in range(2))
    for sim in (a, b):
        sim.inputs.pressure_command[:] = 5.5e5
    for k in range(2000):
        valves = 2.0 if (k // 150) % 3 == 2 else 0.0
        a.inputs.valves[:] = b.inputs.valves[:] = valves
        status = call(a._machine.ctypes.data, a._tables.ctypes.data, a._tables.size, 1e-3)
        b.advance(1e-3)
        assert status in (0, 1)
    assert a.distance == b.distance and a.speed == b.speed
    np.testing.assert_array_equal(a.omega, b.omega)
    np.testing.assert_array_equal(a.vent_actions, b.vent_actions)


def test_stale_compiled_code_is_refused():
    """A machine built for other sources than the compiled step's is refused (numba's cache
    keys the step on step.py alone), not run with other offsets."""
    sim = BrakingSimulator(VEHICLE, PolachAdhesion("polach2005_dry"), 10.0)
    sim._machine[0]["fingerprint"] += 1
    with pytest.raises(RuntimeError, match="stale cache"):
        sim.advance(1e-3)
    assert sim.time == 0.0


def test_errors_of_a_python_adhesion_model_reach_the_caller():
    def law(creep, speed):
        if speed < 9.9:
            raise ZeroDivisionError("the user's law failed")
        return 0.3 * np.tanh(100.0 * creep)

    from railadhesion.braking import CallableAdhesion, simulate

    with pytest.raises(ZeroDivisionError, match="user's law"):
        simulate(VEHICLE, CallableAdhesion(law), 10.0, 3e5, dt=2e-3)


def test_records_name_every_input_of_the_c_interface():
    """The records a C host fills: fixed sizes, C layout, the fingerprint first."""
    from railadhesion.braking import records, step

    assert step.MACHINE.names[:4] == ("fingerprint", "state", "settings", "inputs")
    assert step.MACHINE.fields["fingerprint"][1] == 0
    assert step.MACHINE.isalignedstruct
    for dtype in (records.STATE, records.SETTINGS, records.INPUTS, records.CURVE):
        assert dtype.isalignedstruct and dtype.itemsize % 8 == 0
    assert records.INPUTS.names == ("pressure_command", "valves", "torque")
    assert records.STATE["omega"].shape == (records.MAX_AXLES,)


@pytest.mark.parametrize("n_axles", [2, 6, 12])
def test_every_axle_count_up_to_the_record_size(n_axles):
    """12 axles under WILAC's four conditions fill every lane of the records."""
    from railadhesion.braking import simulate

    veh = Vehicle(name=f"{n_axles} axles", n_axles=n_axles)
    cyl = BrakeCylinders(max_pressure=6e5, valves="bogie" if n_axles == 2 else "axle")
    res = simulate(veh, WilacAdhesion(WaterFlowProfile.constant(18.0)), 12.0, 5.5e5,
                   cylinders=cyl, wsp=WheelSlideProtection(period=4e-3), dt=2e-3)
    assert res.success and len(res.summary["axles"]) == n_axles
    h = res.histories
    assert np.all(np.isfinite(h.to_numpy()[1:]))
    assert abs(res.summary["energy"]["balance_error"]) < 5e-3
    # the stepping API and its Python-model path give the same stop
    sims = [BrakingSimulator(veh, WilacAdhesion(WaterFlowProfile.constant(18.0)), 12.0,
                             cylinders=cyl, max_step=2e-3, compiled=flag, record=False)
            for flag in (True, False)]
    for sim in sims:
        sim.inputs.pressure_command[:] = 5.5e5
        for _ in range(300):
            sim.advance(2e-3)
    np.testing.assert_allclose(sims[0].omega, sims[1].omega, rtol=1e-9)
    assert sims[0].speed == pytest.approx(sims[1].speed, rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(n_axles=st.sampled_from([2, 4, 8]), mu0=st.floats(0.05, 0.6),
       big_a=st.floats(0.2, 1.0), big_b=st.floats(0.0, 1.0),
       commands=st.lists(st.tuples(st.floats(0.0, 8e5), st.integers(0, 2)), min_size=4,
                         max_size=12),
       dt=st.sampled_from([5e-4, 1e-3, 2.5e-3]), v0=st.floats(1.0, 40.0))  # fmt: skip
def test_step_invariants_under_any_valve_and_command_sequence(n_axles, mu0, big_a, big_b,
                                                              commands, dt, v0):
    """Speeds never negative, distance never decreasing, and the kinetic energy of train and
    wheels never rising (brakes and creep only dissipate on a level track), whatever the
    inputs; a long call equals the same sub-steps called one by one."""
    from railadhesion.models.parameters import PolachParameters

    veh = Vehicle(name="v", n_axles=n_axles)
    law = PolachParameters(mu0=mu0, A=big_a, B=big_b, k_A=0.6, k_S=0.3, name="random")
    make = lambda: BrakingSimulator(veh, PolachAdhesion(law), v0, max_step=dt,  # noqa: E731
                                    cylinders=BrakeCylinders(max_pressure=9e5), record=False)
    a, b = make(), make()
    ke = a.kinetic_energy
    distance = 0.0
    for command, valve in commands:
        for sim in (a, b):
            sim.inputs.pressure_command[:] = command
            sim.inputs.valves[:] = valve
        a.advance(25 * dt)
        for _ in range(25):
            b.advance(dt)
        assert a.speed >= 0.0 and np.all(a.omega >= 0.0)
        assert a.distance >= distance
        assert a.kinetic_energy <= ke * (1 + 1e-12) + 1e-9
        ke, distance = a.kinetic_energy, a.distance
        assert a.distance == b.distance and a.speed == b.speed
        np.testing.assert_array_equal(a.omega, b.omega)
