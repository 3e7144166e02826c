"""The default WSP (railadhesion.braking.wsp): settings with sources, the compiled-code
contract of ``wsp_update``, the reference speed, the watchdog, and the issue-20 targets on the
hardest cases (every axle on a poor rail, 200 km/h, with and without sensor noise)."""

import contextlib
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst
from numba import njit

from railadhesion.braking import APPLY, HOLD, VENT, BrakeCylinders, load_vehicle
from railadhesion.braking.bench import (
    AdhesionCase,
    BenchCase,
    load_controller,
    run_wsp_case,
)
from railadhesion.braking.metrics import slide_metrics
from railadhesion.braking.wsp import (
    WheelSlideProtection,
    WSPSettings,
    settings_file_keys,
    wsp_update,
)
from railadhesion.models.parameters import PolachParameters
from railadhesion.plausibility import AlteredResultWarning

COACH = load_vehicle("coach_default")
R = COACH.wheel_radius


def beyond_wilac_speeds():
    """WILAC run from above its calibrated 40 m/s (160 and 200 km/h, the hardest cases):
    reported as an extrapolation (docs/checks.md)."""
    return pytest.warns(AlteredResultWarning, match=r"initial_speed = \S+ m/s is outside the "
                        r"calibrated range \[2, 40\] m/s of the WILAC set")


def test_every_setting_has_a_default_and_a_source_or_says_assumption():
    for name, (_default, _unit, source) in WSPSettings.sources().items():
        assert source, name
        assert ("assumption" in source or "vehicle" in source or "seed 002" in source
                or "sensor" in source or "cylinders" in source), name
    assert set(WSPSettings.sources()) == {f for f in WSPSettings().as_dict()}
    keys = settings_file_keys()
    assert keys["hold_slip_min_m_s"][0] == "hold_slip_min"
    assert keys["watchdog_time_s"] == ("watchdog_time", 0.01, 600.0)


def test_settings_are_checked_and_the_old_name_is_deprecated():
    with pytest.raises(ValueError, match="hold_slip_min must be in"):
        WSPSettings(hold_slip_min=-1.0)
    with pytest.raises(ValueError, match="unknown WSP setting"):
        WSPSettings(hold_slip=0.1)
    with pytest.raises(ValueError, match="reapply_slip_ratio <= hold_slip_ratio"):
        WSPSettings(hold_slip_ratio=0.2, vent_slip_ratio=0.1)
    with pytest.warns(DeprecationWarning, match="sliding_reference_deceleration"):
        s = WSPSettings(sliding_reference_deceleration=1.0, period=0.01)
    assert s.period == 0.01


def test_configure_takes_radius_brake_rate_and_valves_from_the_vehicle():
    w = WheelSlideProtection().configure(COACH, BrakeCylinders(valves="bogie"))
    s = w.settings
    assert s.wheel_radius == R and s.valves == "bogie"
    # seed 002 eq. 8: d = n c p / (R M_eff) per Pa of mean cylinder pressure
    assert s.deceleration_per_pressure == pytest.approx(
        4 * COACH.brake_coefficient / (R * COACH.effective_mass), rel=1e-12)
    with pytest.raises(ValueError, match="wheel radius"):
        WheelSlideProtection().settings_record()


def test_wsp_update_runs_inside_compiled_code():
    """The contract with the integrator: an njit step calls wsp_update with the records."""
    w = WheelSlideProtection().configure(COACH, BrakeCylinders())
    s, state = w.settings_record(), w.state_record(4)

    @njit
    def loop(s, state, n_steps):
        omega = np.full(4, 120.0)
        p = np.full(4, 2e5)
        cmd = np.full(4, 5.5e5)
        out = np.zeros(4, np.int64)
        total = 0
        for k in range(n_steps):
            omega[2] = 120.0 - 0.5 * k if k < 100 else 70.0 + 0.3 * (k - 100)
            wsp_update(s, state, k * 5e-3, omega, p, cmd, math.nan, out)
            total += out[2]
        return total, out

    total, out = loop(s, state, 300)
    assert total > 0  # axle 3 was released
    assert state[0]["vent_commands"] >= 1


def test_per_bogie_valves_give_one_code_per_bogie():
    w = WheelSlideProtection().configure(COACH, BrakeCylinders(valves="bogie"))
    w.reset(4, R)
    for k in range(200):
        speeds = np.array([120.0, 120.0 - (k * 0.3 if k < 60 else 18), 120.0, 120.0]) - 0.01 * k
        out = w(k * 5e-3, speeds, 5.5e5, np.full(4, 2e5))
        assert out[0] == out[1] and out[2] == out[3]
        assert out[2] == APPLY
    assert w.vent_actions >= 1


def test_watchdog_limits_release_without_recovery_and_cuts_out_a_stuck_sensor():
    """Axle 3's sensor is stuck low (a fault: no re-acceleration ever shows): the safety
    timer ends each release after watchdog_time, refills, and after watchdog_cutout_trips
    trips the WSP of that axle is cut out (brake applied) until the command returns to 0."""
    wsp = WheelSlideProtection(period=0.01, watchdog_time=0.5, watchdog_refill_time=0.2,
                               watchdog_cutout_trips=3)
    wsp.reset(4, 0.5)
    states = []
    for k in range(400):
        w = np.array([40.0, 40.0, 10.0 if k > 5 else 40.0, 40.0]) - 0.002 * k
        cmd = 3e5 if k < 350 else 0.0
        states.append(wsp(k * 0.01, w, cmd, np.full(4, 1e5)))
    states = np.array(states)
    assert (states[:, 0] == APPLY).all()
    released = states[:, 2] != APPLY
    runs, cur = [], 0
    for r in released:
        cur = cur + 1 if r else 0
        runs.append(cur)
    assert VENT in states[:, 2]
    assert max(runs) * 0.01 <= 0.5 + 1e-9
    d = wsp.diagnostics()
    assert d["watchdog_trips"] == 3
    trip3 = np.flatnonzero(np.diff(released.astype(int)) == -1)[2]
    assert (states[trip3 + 1:350, 2] == APPLY).all()  # cut out: applied from then on
    assert d["cut_out_groups"] == []  # the command returned to 0: cut-out over


def test_watchdog_spares_a_wheel_that_is_recovering():
    """A deep slide recovering slowly (2 m/s² for 5 s, longer than watchdog_time): the
    watchdog must not re-apply it (that re-locked unrecovered wheels before)."""
    wsp = WheelSlideProtection(watchdog_time=1.0)
    wsp.configure(COACH, BrakeCylinders())
    wsp.reset(4, R)
    period = 5e-3
    trips = []
    for k in range(1400):
        t = k * period
        v = 40.0 - 0.3 * t
        u3 = v if t < 0.5 else max(v - 12.0, 0.0) if t < 1.0 else min(v, v - 12 + 2.0 * (t - 1))
        speeds = np.array([v, v, u3, v]) / R
        p = np.array([1e5, 1e5, 0.0 if t > 0.6 else 1e5, 1e5])
        out = wsp(t, speeds, 5.5e5, p)
        trips.append(wsp.diagnostics()["watchdog_trips"])
        if 1.2 < t < 6.0:
            assert out[2] != APPLY or u3 >= v - 0.5, t
    assert trips[-1] == 0


def test_reference_falls_no_faster_than_the_brakes_allow_when_every_axle_slides():
    """All four wheels slide together (falling at 20 m/s²) with the cylinders at 1 bar: the
    reference may not follow them down faster than the deceleration 1 bar can give (with its
    tolerance and offset) — the failure of the old reference (issue 20)."""
    wsp = WheelSlideProtection().configure(COACH, BrakeCylinders())
    wsp.reset(4, R)
    s = wsp.settings
    limit = (1 + s.brake_rate_tolerance) * s.deceleration_per_pressure * 1e5 + (
        s.reference_deceleration_offset)
    assert limit < 0.7
    v0 = 50.0
    for k in range(100):
        t = k * 5e-3
        u = max(v0 - 20.0 * t, 0.0)
        wsp(t, np.full(4, u / R), 5.5e5, np.full(4, 1e5))
        assert wsp.reference_speed >= v0 - limit * t - 0.1 * 5e-3 * 20  # one filter lag
    # without the brake rate, the old fixed limit lets it fall at 2.5 m/s²
    old = WheelSlideProtection(deceleration_per_pressure=0.0)
    old.reset(4, R)
    for k in range(100):
        old(k * 5e-3, np.full(4, max(v0 - 20.0 * k * 5e-3, 0) / R), 5.5e5, np.full(4, 1e5))
    assert old.reference_speed < wsp.reference_speed - 0.5


def _case(mu, noisy, A=1.0, B=0.0, valves="axle", speed=200 / 3.6, seed=0):
    params = PolachParameters(k_A=1.0, k_S=0.4, mu0=mu, A=A, B=B, name="test")
    return BenchCase(f"mu{mu}", AdhesionCase("polach", params), COACH, speed, 5.5e5, 6e5,
                     valves, "noisy" if noisy else "ideal", 0.01, False, seed)


@pytest.fixture(scope="module")
def hard_runs():
    runs = {}
    ctrl = load_controller()
    for mu in (0.03, 0.05):
        for noisy in (False, True):
            runs[(mu, noisy)] = run_wsp_case(_case(mu, noisy), ctrl)
    runs["falling"] = run_wsp_case(_case(0.05, False, A=0.4, B=0.6), ctrl)
    runs["falling noisy"] = run_wsp_case(_case(0.05, True, A=0.4, B=0.6), ctrl)
    return runs


@pytest.mark.parametrize("noisy", [False, True])
@pytest.mark.parametrize("mu", [0.03, 0.05])
def test_issue_20_every_axle_on_a_poor_rail_at_200_km_h(hard_runs, mu, noisy):
    """Default coach, 200 km/h, 5.5 bar emergency step, cylinders max 6 bar, Polach
    mu0 = mu, A = 1 on all four axles, with and without sensor noise and ±1 % diameters."""
    summary, h, _ = hard_runs[(mu, noisy)]
    assert summary["status"] == "ok"
    # no axle below 10 % of the train speed for more than 1 s: by the default accounting
    # (train above 0.5 m/s) and counting right down to the simulator's stop speed
    assert summary["longest_lock_s"] <= 1.0
    strict = slide_metrics(h, R, speed_floor=0.05)
    assert strict["longest_lock_s"] <= 1.0
    # mean braking creep well below a locked wheel's
    assert summary["mean_creep"] <= 0.3
    assert all(a["mean_creep"] <= 0.3 for a in summary["axles"])
    # within 1.15x the adhesion-limited distance (which is near v²/(2 g mu))
    assert summary["stopping_distance_m"] <= 1.15 * summary["adhesion_limited_distance_m"]
    assert summary["adhesion_limited_distance_m"] == pytest.approx(
        (200 / 3.6) ** 2 / (2 * 9.81 * mu), rel=0.01)
    # the reference came back to the train speed: probes or fixes found it again
    assert summary["controller_diagnostics"]["speed_fixes"] > 5


@pytest.mark.parametrize("key", ["falling", "falling noisy"])
def test_issue_20_falling_friction_no_lock_longer_than_1_s(hard_runs, key):
    summary, h, _ = hard_runs[key]
    assert summary["status"] == "ok"
    assert summary["longest_lock_s"] <= 1.0
    assert slide_metrics(h, R, speed_floor=0.05)["longest_lock_s"] <= 1.0


def test_reference_speed_stays_near_the_train_speed(hard_runs):
    """The controller never reads the train speed, yet its reference stays within a few
    per cent of it (the ±1 % wheel diameters included) all the way down."""
    for key in [(0.03, False), (0.03, True), (0.05, True)]:
        summary, h, trace = hard_runs[key]
        v = np.interp(trace["time"], h["time"], h["train_speed"])
        err = trace["reference_speed"] - v
        moving = v > 2.0
        assert np.max(np.abs(err[moving] / v[moving])) < 0.06, key
        assert np.mean(np.abs(err[moving])) < 0.5, key


def test_dry_rail_no_wsp_action_and_same_stop_as_without_wsp():
    from railadhesion.braking import PolachAdhesion, simulate

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(COACH, PolachAdhesion("polach2005_dry"), 200 / 3.6, 5.5e5,
                       cylinders=BrakeCylinders(max_pressure=6e5), wsp=True, dt=1e-3)
    bare = simulate(COACH, PolachAdhesion("polach2005_dry"), 200 / 3.6, 5.5e5,
                    cylinders=BrakeCylinders(max_pressure=6e5), dt=1e-3)
    assert res.summary["vent_actions"] == 0
    assert res.stopping_distance == pytest.approx(bare.stopping_distance, rel=1e-12)
    assert (res.histories[[f"valve_{i}" for i in range(1, 5)]].to_numpy() == APPLY).all()
    assert HOLD == 1


def test_docs_list_every_setting():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "wsp.md").read_text(encoding="utf-8")
    for name in WSPSettings.sources():
        assert f"| `{name}` |" in text, name


# -- using the adhesion that is there (issue 20 follow-up) ----------------------------------
class _BandRecorder:
    """The default WSP in ``simulate``'s loop, recording its reference speed and slip bands."""

    def __init__(self, **settings):
        self.wsp = WheelSlideProtection(**settings)
        self.period = self.wsp.period
        self.trace = []

    def reset(self, n_axles, wheel_radius):
        self.wsp.configure(COACH, BrakeCylinders(max_pressure=6e5))
        self.wsp.reset(n_axles, wheel_radius)

    def __call__(self, time, wheel_speeds, pressure_command, brake_pressures=None,
                 external_speed=math.nan):
        out = self.wsp(time, wheel_speeds, pressure_command, brake_pressures, external_speed)
        d = self.wsp.diagnostics()
        self.trace.append((d["reference_speed_m_s"], *d["band_scales"]))
        return out


def _polach(mu, A=1.0, B=0.0):
    return PolachParameters(k_A=1.0, k_S=0.4, mu0=mu, A=A, B=B, name="test")


@pytest.mark.parametrize(
    ("rail", "rises"),
    [("flooded", True), ("constant", True), ("falling", False)])
def test_the_slip_band_rises_where_adhesion_does_not_fall_with_slip_and_falls_where_it_does(
        rail, rises):
    """Above 20 m/s: on WILAC at 350 µl/s (adhesion rising with slip to 15-20 %) and on a
    constant adhesion the bands sit raised (median 3x: hold 15 %); on a falling law
    (μ0 0.05, A 0.4, B 0.6: peak near 0.5-1 %) they sit at or below the settings' band
    more than 90 % of the time."""
    from railadhesion.braking import PolachAdhesion, WilacAdhesion, simulate

    adhesion = {"flooded": WilacAdhesion(350.0),
                "constant": PolachAdhesion(_polach(0.05)),
                "falling": PolachAdhesion(_polach(0.05, A=0.4, B=0.6))}[rail]
    rec = _BandRecorder()
    with beyond_wilac_speeds() if rail == "flooded" else contextlib.nullcontext():
        simulate(COACH, adhesion, 200 / 3.6, 5.5e5, cylinders=BrakeCylinders(max_pressure=6e5),
                 wsp=rec)
    trace = np.array(rec.trace)
    bands = trace[trace[:, 0] > 20.0, 1:]
    assert len(bands) > 500
    if rises:
        assert (np.median(bands, axis=0) >= 2.0).all()
    else:
        assert np.mean(bands <= 1.0) > 0.9
        assert (bands >= WSPSettings().band_scale_min).all()


def _wilac(flow, noisy=False, valves="axle", speed=200 / 3.6):
    return BenchCase(f"wilac{flow}", AdhesionCase("wilac", None, float(flow)), COACH, speed,
                     5.5e5, 6e5, valves, "noisy" if noisy else "ideal", 0.01, False, 0)


@pytest.fixture(scope="module")
def wet_runs():
    ctrl = load_controller()
    with beyond_wilac_speeds():
        return {"350": run_wsp_case(_wilac(350), ctrl),
                "350 noisy": run_wsp_case(_wilac(350, noisy=True), ctrl),
                "60 bogie 160": run_wsp_case(_wilac(60, valves="bogie", speed=160 / 3.6),
                                             ctrl)}


@pytest.mark.parametrize(
    "key", [(0.03, False), (0.05, False), (0.03, True), (0.05, True), "350", "350 noisy",
            "60 bogie 160"])
def test_the_stop_is_not_longer_than_without_wsp_where_adhesion_does_not_fall_with_slip(
        hard_runs, wet_runs, key):
    """Where a locked wheel keeps the curve's adhesion (constant μ; WILAC at 60-350 µl/s,
    within 8 % of its peak at full slide), a WSP must not stop the train later than no WSP:
    at most 3 % longer with exact wheel speeds, 5 % with the noisy sensors' ±1 % wheel
    diameters (not calibrated). The WSP of issue 20 took 943.5 m against 864.2 m without WSP
    on WILAC at 350 µl/s from 200 km/h (+9.2 %)."""
    from railadhesion.braking import simulate

    summary, h, _ = hard_runs[key] if isinstance(key, tuple) else wet_runs[key]
    noisy = summary["sensors"] == "noisy"
    assert summary["status"] == "ok" and summary["longest_lock_s"] <= 1.0
    assert summary["mean_creep"] <= 0.3
    assert summary["distance_vs_no_wsp"] <= (1.05 if noisy else 1.03)
    if key == "350":  # the bench's reference stop is the simulator's stop without WSP
        with beyond_wilac_speeds():
            bare = simulate(COACH, AdhesionCase("wilac", None, 350.0).build(), 200 / 3.6,
                            5.5e5, cylinders=BrakeCylinders(max_pressure=6e5))
        assert summary["no_wsp_distance_m"] == pytest.approx(bare.stopping_distance, rel=1e-12)
        assert bare.stopping_distance == pytest.approx(864.2, abs=0.1)  # docs/validation.md


def test_the_damp_example_stops_where_the_earlier_wsp_did():
    """examples/brake_damp.toml (WILAC 25 µl/s on 50-900 m, 160 km/h): 643.5 m with the WSP
    of issue 20, 606.7 m with the WSP before it (docs/validation.md); now within 1 % of the
    latter."""
    from pathlib import Path

    from railadhesion.braking.scenario import load_scenario

    examples = Path(__file__).resolve().parents[2] / "examples"
    with beyond_wilac_speeds():
        res = load_scenario(examples / "brake_damp.toml").simulate()
    assert res.success and res.summary["longest_lock_s"] <= 1.0
    assert res.stopping_distance <= 1.01 * 606.7


def test_a_probe_vents_deeper_until_the_released_wheel_recovers():
    """A steeply falling law (μ0 0.05, A 0.25: a full slide needs a quarter of the peak's
    torque): a probed wheel vented to a fraction of its pressure can stay held in a deep
    slide; its speed is not a fix until it has re-accelerated (else the reference follows
    it down and every wheel locks)."""
    summary, h, trace = run_wsp_case(_case(0.05, False, A=0.25, B=0.6), load_controller())
    assert summary["status"] == "ok" and summary["longest_lock_s"] <= 1.0
    assert slide_metrics(h, R, speed_floor=0.05)["longest_lock_s"] <= 1.0
    v = np.interp(trace["time"], h["time"], h["train_speed"])
    moving = v > 2.0
    assert np.max(np.abs(trace["reference_speed"][moving] / v[moving] - 1)) < 0.06
    assert summary["controller_diagnostics"]["probes"] > 5


@pytest.mark.parametrize("brake_factor", [0.8, 1.2])
@pytest.mark.parametrize("noisy", [False, True])
def test_a_brake_20_percent_off_the_nominal_rate(brake_factor, noisy):
    """The WSP's brake rate (seed 002 eq. 8) is the vehicle's nominal one; real pad friction
    differs. With the brake 20 % weaker or stronger than the WSP assumes, μ = 0.03 at
    200 km/h still meets issue 20's targets (the learnt drift takes the rest)."""
    from dataclasses import replace

    nominal = WheelSlideProtection().configure(COACH, BrakeCylinders()).settings
    vehicle = replace(COACH, brake_coefficient=COACH.brake_coefficient * brake_factor)
    case = BenchCase("pads", AdhesionCase("polach", _polach(0.03)), vehicle, 200 / 3.6, 5.5e5,
                     6e5, "axle", "noisy" if noisy else "ideal", 0.01, False, 0)
    ctrl = load_controller(WheelSlideProtection(
        deceleration_per_pressure=nominal.deceleration_per_pressure,
        wheel_inertia_pressure=nominal.wheel_inertia_pressure))
    summary, _, _ = run_wsp_case(case, ctrl)
    assert summary["status"] == "ok" and summary["longest_lock_s"] <= 1.0
    assert summary["distance_ratio"] <= 1.15 and summary["mean_creep"] <= 0.3
    assert summary["distance_vs_no_wsp"] <= 1.05


def test_dry_rail_no_wsp_action_with_a_brake_25_percent_stronger_than_nominal():
    from dataclasses import replace

    from railadhesion.braking import PolachAdhesion, simulate

    nominal = WheelSlideProtection().configure(COACH, BrakeCylinders()).settings
    strong = replace(COACH, brake_coefficient=COACH.brake_coefficient * 1.25)
    wsp = WheelSlideProtection(deceleration_per_pressure=nominal.deceleration_per_pressure,
                               wheel_inertia_pressure=nominal.wheel_inertia_pressure)
    res = simulate(strong, PolachAdhesion("polach2005_dry"), 200 / 3.6, 5.5e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), wsp=wsp)
    assert res.summary["vent_actions"] == 0


@given(seed=hst.integers(0, 2**32 - 1), speed=hst.floats(0.5, 80.0),
       slip=hst.floats(0.0, 1.0), pressure=hst.floats(0.0, 6e5),
       noise=hst.floats(0.0, 0.05), pressures_known=hst.booleans(),
       bogie=hst.booleans())
@settings(max_examples=40, deadline=None)
def test_wsp_update_keeps_its_invariants_on_any_readings(seed, speed, slip, pressure, noise,
                                                          pressures_known, bogie):
    """Random wheel-speed and pressure readings (sliding, recovering, noisy, pressures
    unknown): valve codes stay 0-2 (the same for the axles of a bogie), the reference finite
    and >= 0, the band scales within their bounds, the learnt drift within [0,
    reference_deceleration] and the probe interval within its bounds."""
    rng = np.random.default_rng(seed)
    w = WheelSlideProtection(valves="bogie" if bogie else "axle").configure(COACH)
    s = w.settings
    rec, state = w.settings_record(), w.state_record(4)
    out = np.zeros(4, np.int64)
    v = speed
    cmd = np.full(4, 5.5e5)
    for k in range(400):
        t = k * s.period
        v = max(v - 0.5 * s.period, 0.0)
        depth = slip * (0.5 + 0.5 * np.sin(0.02 * k + rng.uniform(0, 6.3, 4)))
        omega = v * (1 - depth) * (1 + noise * rng.standard_normal(4)) / R
        p = (pressure * rng.uniform(0.0, 1.0, 4) if pressures_known else np.full(4, np.nan))
        wsp_update(rec, state, t, np.maximum(omega, 0.0), p, cmd, math.nan, out)
        r = state[0]
        assert set(out.tolist()) <= {APPLY, HOLD, VENT}
        if bogie:
            assert out[0] == out[1] and out[2] == out[3]
        assert math.isfinite(r["v_ref"]) and r["v_ref"] >= 0.0
        ng = int(r["n_groups"])
        assert (r["scale"][:ng] >= s.band_scale_min - 1e-12).all()
        assert (r["scale"][:ng] <= s.band_scale_max + 1e-12).all()
        assert 0.0 <= r["excess"] <= s.reference_deceleration
        assert s.probe_interval <= r["probe_gap"] <= s.probe_interval_max


def test_free_pressure_given_in_bar_is_sniffed():
    """0.2 (bar meant, the default is 0.2 bar = 2e4 Pa) passes the range [0, 1e6] Pa: it gets a
    UnitWarning naming bar; the default, 0 (no free pressure) and 0.3 bar in Pa do not."""
    from railadhesion.plausibility import UnitWarning

    with pytest.warns(UnitWarning, match=r"free_pressure = 0.2 Pa .* given in bar\?"):
        WSPSettings(free_pressure=0.2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for value in (2e4, 0.0, 3e4):
            assert WSPSettings(free_pressure=value).free_pressure == value
