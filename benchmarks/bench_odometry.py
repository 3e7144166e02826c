"""Odometry bench benchmarks (issue 23). Prints its figures; run from the repo root:

    PYTHONPATH=src python3 benchmarks/bench_odometry.py [--quick]

1. The whole default odometry programme (13 runs, 54 fits) on the reference odometry, as
   ``railadhesion odometry-test default --out DIR`` runs it: JSON/CSV after every case and one
   figure per case; beside the same programme without figures (ratio), after a warm-up run of
   one case (numba compiles or loads its cache once per process). Target: under a minute.
2. Per odometry cycle: the reference odometry (``odometry_update`` through
   ``ReferenceOdometry.step_record``) and the odometry's sensors (``measure`` with 80-tooth
   encoders, a radar and an accelerometer), each against one ``BrakingSimulator.advance(1e-3)``
   call of the same process (ratio).

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

from railadhesion.braking import BrakeCylinders, BrakingSimulator, PolachAdhesion, load_vehicle
from railadhesion.braking.odometry import ReferenceOdometry
from railadhesion.braking.odometry_bench import load_odometry_programme, run_odometry_programme
from railadhesion.braking.sensors import (
    AccelerometerSettings,
    EncoderSettings,
    ExternalSpeedSettings,
    SensorModel,
    accelerometer,
    measure,
)


def _load() -> str:
    try:
        return ", ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:  # pragma: no cover
        return "n/a"


def programme(quick: bool) -> None:
    prog = load_odometry_programme("default")
    if quick:
        prog = prog.select([c.name for c in prog.cases[::4]])
    run_odometry_programme(prog.select([prog.cases[-1].name]), figures=False)  # warm-up
    cpu0 = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = run_odometry_programme(prog, out=os.path.join(tmp, "a"))
        with_figures = time.perf_counter() - t0
        cpu = time.process_time() - cpu0
        t0 = time.perf_counter()
        run_odometry_programme(prog, out=os.path.join(tmp, "b"), figures=False)
        without = time.perf_counter() - t0
    simulated = sum(c.get("stopping_time_s", 0.0) for c in res.cases)
    o = res.overall
    print(f"1. default programme, {len(prog.cases)} runs, {o['fits_run']} fits, "
          f"{simulated:.0f} s simulated (load {_load()}):")
    print(f"   with outputs and figures    {with_figures:7.1f} s  (the odometry-test command; "
          f"{cpu:.1f} s CPU)")
    print(f"   outputs without figures     {without:7.1f} s  (ratio {with_figures / without:.2f})")
    print(f"   {o['passed']}/{o['cases']} passed, inside every interval: "
          f"{o['inside_everywhere']}, worst stop error with an accelerometer "
          f"{100 * o['worst_stop_error_fraction_with_accelerometer']:.2f} %, without "
          f"{100 * o['worst_stop_error_fraction_without_accelerometer']:.2f} %")


def per_call(n: int) -> None:
    coach = load_vehicle("coach_default")
    cyl = BrakeCylinders(max_pressure=6e5)

    def fresh():  # 55 m/s on μ = 0.05 with the brake: moving for much longer than n steps
        sim = BrakingSimulator(coach, PolachAdhesion("polach2005_dry"), 55.0, cylinders=cyl,
                               max_step=1e-3, record=False)
        sim.inputs.pressure_command[:] = 1e5
        return sim

    sim = fresh()
    live = sim.live
    sens = SensorModel(EncoderSettings(80.0, 0.005, 1e-6, (0.01, -0.01, 0.01, -0.01)),
                       ExternalSpeedSettings(), 1, AccelerometerSettings())
    ss, sst = sens.settings_record(4), sens.state_record(4)
    odo = ReferenceOdometry()
    odo.reset((1, 4), coach.wheel_radius, 80.0, 0.0)
    w = np.zeros(4)
    p = np.zeros(4)
    speeds = np.full(2, 50.0 / coach.wheel_radius)

    def loop_advance():
        sim = fresh()
        advance = sim.advance
        sim.advance(1e-3)
        t0 = time.perf_counter()
        for _ in range(n):
            advance(1e-3)
        assert not sim.stopped
        return time.perf_counter() - t0

    def loop_odometry():
        step = odo.step_record
        for k in range(n):
            step(k * 5e-3, speeds, math.nan, -0.5, -1.0)

    def loop_measure():
        for k in range(n):
            measure(ss, sst, k * 5e-3, live.wheel_speeds, live.brake_pressures, 50.0, -0.5, w, p)
            accelerometer(sst)

    loop_advance()
    loop_odometry()
    loop_measure()
    times = {}
    for name, fn in (("advance(1e-3)", loop_advance), ("odometry_update", loop_odometry),
                     ("measure + accel.", loop_measure)):
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


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    programme(quick)
    per_call(2000 if quick else 20000)
