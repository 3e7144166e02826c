"""Slide and lock accounting (railadhesion.braking.metrics): the stated definitions, checked on
hand-made histories, against an independent row-by-row count, and on a simulated run whose
summary must report exactly what its histories show."""

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.braking import BrakeCylinders, PolachAdhesion, load_vehicle, simulate
from railadhesion.braking.metrics import longest_run, slide_metrics
from railadhesion.models.parameters import PolachParameters

R = 0.5


def _frame(t, v, u, p=None, valve=None, command=3e5):
    """Histories of one axle: wheel rail speed u [m/s] as angular speed."""
    n = len(t)
    return pd.DataFrame({
        "time": t, "train_speed": v, "pressure_command": np.full(n, command),
        "wheel_speed_1": np.asarray(u) / R,
        "brake_pressure_1": np.zeros(n) if p is None else p,
        "valve_1": np.zeros(n, int) if valve is None else valve,
    })


def _by_loop(h, fraction=0.10, floor=0.5, deep=0.5):
    """The definitions of docs/braking.md, counted row by row (an independent reading)."""
    total = longest = run = below = deep_t = deep_x = 0.0
    prev_t = h["time"].iloc[0]
    for _, row in h.iterrows():
        dt = row["time"] - prev_t
        prev_t = row["time"]
        v, u = row["train_speed"], row["wheel_speed_1"] * R
        locked = u < fraction * v
        if v > floor and locked:
            total += dt
            run += dt
            longest = max(longest, run)
        else:
            run = 0.0
        if 0 < v <= floor and locked:
            below += dt
        if v > floor and (v - u) / v >= deep:
            deep_t += dt
            deep_x += (v - u) * dt
    return total, longest, below, deep_t, deep_x


def test_definitions_on_hand_made_histories():
    t = np.arange(0, 10.001, 0.1)
    v = np.maximum(10 - 1.0 * t, 0.0)
    u = v.copy()
    u[(t > 1.05) & (t < 1.75)] = 0.0  # locked 0.7 s (rows 1.1 ... 1.7)
    u[(t > 3.05) & (t < 3.35)] = 0.5 * v[(t > 3.05) & (t < 3.35)]  # a deep slide, not a lock
    u[(t > 5.05) & (t < 6.25)] = 0.05 * v[(t > 5.05) & (t < 6.25)]  # locked 1.2 s
    u[t > 9.55] = 0.0  # locked below the floor (v <= 0.5 m/s)
    valve = np.zeros(t.size, int)
    valve[[20, 21, 40, 60, 61, 62]] = 2
    p = np.full(t.size, 3e5)
    p[20:22] = [2e5, 1e5]
    p[22:] = 1e5
    m = slide_metrics(_frame(t, v, u, p, valve), R, cylinder_volume=2e-3)
    a = m["axles"][0]
    assert a["time_locked_s"] == pytest.approx(0.7 + 1.2, abs=1e-9)
    assert a["longest_lock_s"] == pytest.approx(1.2, abs=1e-9)
    assert a["time_locked_below_floor_s"] == pytest.approx(0.4, abs=1e-9)  # 9.6 ... 9.9
    assert a["deep_slide_s"] == pytest.approx(0.7 + 0.3 + 1.2, abs=1e-9)
    assert a["vent_actions"] == 3
    assert a["vented_air_l"] == pytest.approx(2e5 * 2e-3 / 101325 * 1e3, rel=1e-12)
    for got, want in zip((a["time_locked_s"], a["longest_lock_s"],
                          a["time_locked_below_floor_s"], a["deep_slide_s"],
                          a["deep_slide_distance_m"]), _by_loop(_frame(t, v, u)), strict=True):
        assert got == pytest.approx(want, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(mask=st.lists(st.booleans(), min_size=1, max_size=60),
       steps=st.lists(st.floats(0.0, 1.0), min_size=60, max_size=60))
def test_longest_run_equals_brute_force(mask, steps):
    m = np.array(mask)
    dt = np.array(steps[:m.size])
    best = 0.0
    for i in range(m.size):
        s = 0.0
        for j in range(i, m.size):
            if not m[j]:
                break
            s += dt[j]
            best = max(best, s)
    assert longest_run(m, dt) == pytest.approx(best, abs=1e-12)


def test_reported_lock_equals_the_lock_measured_from_the_histories():
    """A run without WSP on a poor rail (the wheels lock): BrakingResult.summary reports per
    axle exactly what a row-by-row count of its histories gives."""
    veh = load_vehicle("coach_default")
    low = PolachParameters(k_A=1.0, k_S=0.4, mu0=0.05, A=1.0, B=0.0, name="low")
    res = simulate(veh, PolachAdhesion("polach2005_dry", [(100.0, 400.0, low)]), 25.0, 3e5,
                   cylinders=BrakeCylinders(max_pressure=6e5), dt=2e-3)
    h = res.histories
    assert res.summary["longest_lock_s"] > 1.0  # it does lock
    for i in range(1, 5):
        one = h[["time", "train_speed", "pressure_command", f"wheel_speed_{i}"]].rename(
            columns={f"wheel_speed_{i}": "wheel_speed_1"})
        one["wheel_speed_1"] *= veh.wheel_radius / R
        total, longest, below, deep_t, deep_x = _by_loop(one.iloc[::1])
        ax = res.summary["axles"][i - 1]
        assert ax["time_locked_s"] == pytest.approx(total, abs=1e-9)
        assert ax["longest_lock_s"] == pytest.approx(longest, abs=1e-9)
        assert ax["time_locked_below_floor_s"] == pytest.approx(below, abs=1e-9)
        assert ax["deep_slide_s"] == pytest.approx(deep_t, abs=1e-9)
        assert ax["deep_slide_distance_m"] == pytest.approx(deep_x, rel=1e-9)
    assert res.summary["slide_definitions"] == {"lock_fraction": 0.1, "speed_floor_m_s": 0.5,
                                                "deep_creep": 0.5}


def test_a_lock_between_5_and_10_percent_of_the_train_speed_is_counted():
    """The old accounting (creep >= 0.95) missed slides between 5 % and 10 % (issue 20)."""
    t = np.arange(0, 5.001, 0.01)
    v = np.full(t.size, 30.0)
    u = np.where((t > 1) & (t < 3), 0.07 * 30.0, 30.0)
    m = slide_metrics(_frame(t, v, u), R)
    assert m["longest_lock_s"] == pytest.approx(2.0, abs=0.011)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [({"lock_fraction": 1.5}, "lock_fraction"), ({"speed_floor": -1.0}, "speed_floor"),
     ({"deep_creep": math.nan}, "deep_creep")],
)
def test_bad_definitions_are_refused(kwargs, message):
    t = np.arange(3.0)
    with pytest.raises(ValueError, match=message):
        slide_metrics(_frame(t, np.ones(3), np.ones(3)), R, **kwargs)
