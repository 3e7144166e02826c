"""Benchmark: the on-board adhesion monitor (issue 21) — cost per sample and a 1 h replay.

Issue 21 asks for at most 20 us per sample for 4 axles and a 1 h log replayed in at most 5 s.
Timed side by side in one run, with ratios:

* per sample, 4 axles: the compiled step inside the replay loop (one sample per iteration,
  the estimator's block updates included), the Python call with the inputs written in place
  (``monitor.step``, the hardware-in-the-loop path), the convenience call
  (``monitor.update(t, v, w, p)``), beside the braking simulator's own ``advance(2.4e-3)`` on
  the same vehicle (WILAC damp rail, two 1.2 ms sub-steps) and the sample period itself;
* the 1 h log of ``bench_identification.py`` (1.5 M samples of a 4-axle coach at 2.4 ms,
  brakings with WSP, coasting and re-accelerations, sensor noise): read (Parquet), replay
  (:func:`railadhesion.monitor.replay_log`: the compiled loop and the output frame), write
  (Parquet), beside the off-line identification of the same log (read + ``identify_adhesion``).

Medians of ``--repeat`` runs after a warm-up (numba kernels loaded). The machine is shared:
the load average is printed beside the figures.

Run: ``PYTHONPATH=src python3 benchmarks/bench_monitor.py [--repeat 3] [--keep DIR]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PERIOD = 2.4e-3


def _median(fn, repeat):
    """Median wall time [s] of ``repeat`` runs (the CPU time of the same runs: _cpu)."""
    return _times(fn, repeat)[0]


def _times(fn, repeat):
    """(median wall time, median process CPU time) [s] of ``repeat`` runs."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def _per_sample(repeat):
    """Cost of one sample from Python (4 axles): step() with inputs in place, update(); the
    simulator's advance() beside them."""
    from railadhesion.braking import BrakingSimulator, WilacAdhesion, load_vehicle
    from railadhesion.monitor import AdhesionMonitor

    coach = load_vehicle("coach_default")
    n = 20000
    rng = np.random.default_rng(0)
    t = PERIOD * np.arange(1, n + 1)
    v = 40.0 - 0.4 * t
    mod = 1.0 + 0.25 * np.sin(2 * np.pi * 0.6 * t)
    w = (v * (1.0 - 0.004 * mod))[:, None] / coach.wheel_radius + rng.normal(0, 0.02, (n, 4))
    p = np.repeat((1.4e5 * mod)[:, None], 4, axis=1) + rng.normal(0, 1e3, (n, 4))
    mon = AdhesionMonitor(coach)
    mon.update(0.0, 40.0, np.full(4, 40.0 / coach.wheel_radius), np.zeros(4))  # compile/load
    inputs = mon.inputs

    def stepping():
        mon.reset()
        for k in range(n):
            inputs.train_speed = v[k]
            inputs.wheel_speeds[:] = w[k]
            inputs.brake_pressures[:] = p[k]
            mon.step(t[k])

    def updating():
        mon.reset()
        for k in range(n):
            mon.update(t[k], v[k], w[k], p[k])

    # traction only: the same wheel torque from a torque channel, no pressure channel
    tq = p * coach.brake_coefficient
    wt = 2.0 * v[:, None] / coach.wheel_radius - w
    mon_t = AdhesionMonitor(coach, pressure=False, torque=True)
    mon_t.update(0.0, 40.0, np.full(4, 40.0 / coach.wheel_radius), None, np.zeros(4))
    inputs_t = mon_t.inputs

    def traction():
        mon_t.reset()
        for k in range(n):
            inputs_t.train_speed = v[k]
            inputs_t.wheel_speeds[:] = wt[k]
            inputs_t.torques[:] = tq[k]
            mon_t.step(t[k])

    sim = BrakingSimulator(coach, WilacAdhesion(25.0), 44.0, record=False)
    sim.inputs.pressure_command[:] = 1.2e5
    sim.advance(PERIOD)

    def simulating():
        for _ in range(n):
            sim.advance(PERIOD)

    return {name: _times(fn, repeat)[1] / n for name, fn in
            (("step", stepping), ("update", updating), ("traction", traction),
             ("simulator", simulating))}


def _compiled_per_sample(log, repeat):
    """The compiled loop alone: seconds per sample."""
    from railadhesion.braking import load_vehicle
    from railadhesion.monitor import AdhesionMonitor, kernel

    coach = load_vehicle("coach_default")
    mon = AdhesionMonitor(coach)
    n, n_ax = log.n_samples, log.n_axles
    outs = [np.empty(n, np.int8), np.empty(n, np.int8)] + [
        np.empty((n, n_ax), np.float32)] * 5 + [np.empty((n, n_ax), np.int8)] * 2 + [
        np.empty((n, n_ax), np.float32)] * 2
    args = [np.ascontiguousarray(a, float) for a in (log.time, log.train_speed,
                                                     log.wheel_speed, log.brake_pressure,
                                                     log.torque)]

    def run():
        mon.reset()
        kernel.replay(*mon.records, *args, *outs)

    run()
    return _times(run, repeat)[1] / n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--keep", type=Path, default=None,
                    help="Write the log here (log.parquet) and reuse it if present.")
    args = ap.parse_args()
    sys.path.insert(0, str(HERE))
    from bench_identification import VEH, make_log

    from railadhesion.identification import identify_adhesion, read_braking_log
    from railadhesion.monitor import read_monitor_log, replay_log

    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores, shared)")
    with tempfile.TemporaryDirectory() as tmp:
        base = (args.keep or Path(tmp)) / "log"
        base.parent.mkdir(parents=True, exist_ok=True)
        parquet = base.with_suffix(".parquet")
        if not parquet.exists():
            n = make_log(base)
            print(f"log written: {n} samples ({n * PERIOD / 3600:.2f} h)")
        out = Path(tmp) / "out"
        log = read_monitor_log(parquet)
        rep = replay_log(log, VEH)  # warm-up: kernels loaded
        t_read = _times(lambda: read_monitor_log(parquet), args.repeat)
        t_replay = _times(lambda: replay_log(log, VEH), args.repeat)
        t_write = _times(lambda: rep.write(out), args.repeat)
        total = _times(lambda: replay_log(read_monitor_log(parquet), VEH).write(out),
                       args.repeat)
        identify_adhesion(read_braking_log(parquet, warn=False), VEH, threads=1)
        t_ident = _times(lambda: identify_adhesion(read_braking_log(parquet, warn=False), VEH,
                                                   threads=1), args.repeat)
        compiled = _compiled_per_sample(log, args.repeat)
    per = _per_sample(args.repeat)
    n = log.n_samples
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print(f"\n1 h log, {n} samples, 4 axles (medians of {args.repeat}; wall / CPU [s]):")
    for label, (w, c) in (("read Parquet", t_read), ("replay (compiled loop, columns, events)",
                                                      t_replay),
                          ("write (Parquet, events.csv, summary.json)", t_write),
                          ("end to end", total)):
        print(f"  {label:42s} {w:6.2f} / {c:5.2f}")
    print("  (issue 21: <= 5 s)")
    print(f"  identify_adhesion, read + identify, 1 thread {t_ident[0]:6.2f} / "
          f"{t_ident[1]:5.2f}: monitor end to end / identification = "
          f"{total[1] / t_ident[1]:.2f} (CPU)")
    print("\nper sample, 4 axles (process CPU time):")
    print(f"  compiled step in the replay loop  {compiled * 1e6:7.2f} us  "
          f"({PERIOD / compiled:,.0f} x real time at 2.4 ms)")
    print(f"  monitor.step(t), inputs in place  {per['step'] * 1e6:7.2f} us  "
          f"(issue 21: <= 20 us)")
    print(f"  monitor.update(t, v, w, p)        {per['update'] * 1e6:7.2f} us")
    print(f"  monitor.step(t), traction torques {per['traction'] * 1e6:7.2f} us")
    print(f"  simulator advance(2.4 ms), WILAC  {per['simulator'] * 1e6:7.2f} us: "
          f"monitor.step / advance = {per['step'] / per['simulator']:.2f}")


if __name__ == "__main__":
    main()
