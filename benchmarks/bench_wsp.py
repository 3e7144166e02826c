"""WSP bench benchmarks (issue 20). Prints its figures; run from the repo root:

    PYTHONPATH=src python3 benchmarks/bench_wsp.py [--quick]

1. The whole default programme (31 stops, 40-200 km/h, 2.5 h of simulated braking at a 1 ms
   step) on the default WSP, as ``railadhesion wsp-test default --out DIR`` runs it: JSON/CSV
   after every case and one figure per case; beside the same programme without figures
   (ratio), after a warm-up run of one case (numba compiles or loads its cache once per
   process). Target: under a minute.
2. Per control period: the default controller (``wsp_update``) and the sensor models
   (``measure``, noisy encoders), each against one ``BrakingSimulator.advance(1e-3)`` call of
   the same process (ratio): what the WSP adds to a 1 kHz stepping loop once the compiled
   step calls it every 5 ms.

Timings are wall clock, minimum of the repeats for (2); the machine is shared: the load
average is printed, compare ratios within one run.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import time

import numpy as np

from railadhesion.braking import BrakeCylinders, BrakingSimulator, WilacAdhesion, load_vehicle
from railadhesion.braking.adhesion import WaterFlowProfile
from railadhesion.braking.bench import load_wsp_programme, run_wsp_programme
from railadhesion.braking.sensors import measure, noisy_sensors
from railadhesion.braking.wsp import WheelSlideProtection, wsp_update


def _load() -> str:
    try:
        return ", ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:  # pragma: no cover
        return "n/a"


def programme(quick: bool) -> None:
    prog = load_wsp_programme("default")
    if quick:
        prog = prog.select([c.name for c in prog.cases[::5]])
    run_wsp_programme(prog.select([prog.cases[0].name]), figures=False)  # warm-up
    simulated = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = run_wsp_programme(prog, out=os.path.join(tmp, "a"))
        with_figures = time.perf_counter() - t0
        t0 = time.perf_counter()
        run_wsp_programme(prog, out=os.path.join(tmp, "b"), figures=False)
        without = time.perf_counter() - t0
    simulated = sum(c.get("stopping_time_s", 0.0) for c in res.cases)
    o = res.overall
    print(f"1. default programme, {len(prog.cases)} cases, {simulated:.0f} s simulated "
          f"(load {_load()}):")
    print(f"   with outputs and figures    {with_figures:7.1f} s  (the wsp-test command)")
    print(f"   outputs without figures     {without:7.1f} s  (ratio {with_figures / without:.2f})")
    print(f"   {o['passed']}/{o['cases']} passed, worst longest lock "
          f"{o['worst_longest_lock_s']:.2f} s, worst distance ratio "
          f"{o['worst_distance_ratio']:.3f}, mean utilisation "
          f"{o['mean_adhesion_utilisation']:.3f}")


def per_call(n: int) -> None:  # n <= 30000 (the stop lasts 35 s)
    coach = load_vehicle("coach_default")
    cyl = BrakeCylinders(max_pressure=6e5)
    damp = WaterFlowProfile.sections([(50.0, 1e4, 25.0)])

    def fresh():  # a 55 m/s stop on the damp rail lasts about 35 s: still moving after n steps
        sim = BrakingSimulator(coach, WilacAdhesion(damp), 55.0, cylinders=cyl, max_step=1e-3,
                               record=False)
        sim.inputs.pressure_command[:] = 5.5e5
        return sim

    sim = fresh()
    wsp = WheelSlideProtection().configure(coach, cyl)
    s, st = wsp.settings_record(), wsp.state_record(4)
    sens = noisy_sensors(4, seed=1)
    ss, sst = sens.settings_record(4), sens.state_record(4)
    w = np.zeros(4)
    p = np.zeros(4)
    cmd = np.full(4, 5.5e5)
    out = np.zeros(4, np.int64)
    live = sim.live

    def loop_advance():
        sim = fresh()
        advance = sim.advance
        sim.advance(1e-3)  # compiled or loaded once per simulator
        t0 = time.perf_counter()
        for _ in range(n):
            advance(1e-3)
        assert not sim.stopped
        return time.perf_counter() - t0

    def loop_wsp():
        for k in range(n):
            wsp_update(s, st, k * 5e-3, live.wheel_speeds, live.brake_pressures, cmd, math.nan,
                       out)

    def loop_measure():
        for k in range(n):
            measure(ss, sst, k * 5e-3, live.wheel_speeds, live.brake_pressures, 50.0, 0.0, w, p)

    loop_advance()
    loop_wsp()
    loop_measure()
    times = {}
    for name, fn in (("advance(1e-3)", loop_advance), ("wsp_update", loop_wsp),
                     ("measure (noisy)", loop_measure)):
        best = math.inf
        for _ in range(5):
            t0 = time.perf_counter()
            inner = fn()
            best = min(best, inner if inner is not None else time.perf_counter() - t0)
        times[name] = best / n * 1e6
    base = times["advance(1e-3)"]
    print(f"2. per call from Python, min of 5 x {n} (load {_load()}):")
    for name, us in times.items():
        print(f"   {name:18s} {us:6.2f} µs  ({us / base:.2f} x one simulator step)")
    per_ms = (times["wsp_update"] + times["measure (noisy)"]) / 5
    print(f"   WSP + sensors every 5 ms add {per_ms:.2f} µs per 1 ms step from Python "
          f"({per_ms / base:.2f} x a step); inside the compiled step the dispatch "
          "(about 1 µs of each call) goes away")


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    programme(quick)
    per_call(2000 if quick else 20000)
