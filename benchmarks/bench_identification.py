"""Benchmark: identification of 1 hour of a 4-axle braking log at 2.4 ms (1.5 M samples).

End to end = what ``railadhesion identify`` produces except the figures: read the log,
identify_adhesion (filters, eq. 14, loads, mu, windows), the 40 x 40 surfaces against absolute
and relative slip, the fitted curves (4 speed bands + all speeds against both slips; loss and
recovery windows), and writing summary.json, the two NetCDF surfaces, the two law files and
windows.csv (:func:`railadhesion.identification.pipeline.run_identification`).

The log is synthetic and continuous: a 104 s cycle (three brakings with wheel-slide-protection
venting, coasting, re-acceleration back to the first speed) simulated once with a small
simulator written here (semi-implicit Euler, a falling adhesion law), repeated to one hour with
time running on and sensor noise (0.01 m/s, 0.02 rad/s, 0.01 bar).

Prints, per stage and end to end (from Parquet and from CSV), the median of ``--repeat`` runs
(wall and process CPU time) with one thread and with every core, after one warm-up run (numba
kernels loaded); then the whole CLI command in a fresh process (imports, kernel loading,
page faults included) with and without figures. The machine is shared: the load average is
printed beside the figures.

Run: ``PYTHONPATH=src python3 benchmarks/bench_identification.py [--repeat 3] [--keep DIR]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from railadhesion.braking import Vehicle
from railadhesion.identification import (
    adhesion_surface,
    fit_adhesion_curves,
    identify_adhesion,
    read_braking_log,
)
from railadhesion.identification.brake_tests import worker_count
from railadhesion.identification.pipeline import run_identification

PERIOD = 2.4e-3
VEH = Vehicle(name="bench coach", body_mass=32600.0, bogie_mass=3200.0, wheelset_mass=1500.0,
              wheel_radius=0.46, wheelset_inertia=150.0, brake_coefficient=0.02)


def _law(w):
    """The falling law mu(slip velocity) of the synthetic log, odd in the slip."""
    s = np.abs(w)
    return np.sign(w) * 0.12 * -np.expm1(-s / 0.15) * (0.45 + 0.55 * np.exp(-0.35 * s))


#: One cycle of the synthetic test run: braking (with WSP) for a time, coasting while the
#: cylinders empty, then accelerating (a traction force on the body, wheels rolling) up to the
#: speed the next braking starts from. The last acceleration returns to the first speed, so
#: cycles repeat without a jump.
CYCLE = (("brake", 20.0), ("coast", 3.0), ("accel", 28.0), ("brake", 15.0), ("coast", 3.0),
         ("accel", 20.0), ("brake", 10.0), ("coast", 3.0), ("accel", 35.0))


def _cycle(v0=35.0, substeps=4):
    """One cycle sampled every 2.4 ms: columns v, omega_1..4, p_1..4 [Pa] (semi-implicit Euler,
    loads with pitch transfer, bang-bang WSP venting above 3 m/s of slip, refilling below 0.8)."""
    r, j, c, m = VEH.wheel_radius, VEH.wheelset_inertia, VEH.brake_coefficient, VEH.total_mass
    h = PERIOD / substeps
    v, om, p, vent = v0, np.full(4, v0 / r), np.zeros(4), np.zeros(4, bool)
    rows, d = [], 0.0
    for kind, until in CYCLE:
        k = 0
        while (v < until) if kind == "accel" else (k * PERIOD < until):
            rows.append(np.r_[v, om, p])
            k += 1
            for _ in range(substeps):
                w = v - r * om
                f = _law(w) * VEH.axle_normal_loads(d)
                om = np.maximum(om + h * (f * r - np.where(om > 0, c * p, 0.0)) / j, 0.0)
                traction = 0.8 * m if kind == "accel" else 0.0
                d = (f.sum() - traction) / m
                v = max(v - h * d, 0.0)
                if kind == "brake":
                    vent = np.where(w > 3.0, True, np.where(w < 0.8, False, vent))
                else:
                    vent[:] = False
                target = np.where(vent | (kind != "brake"), 0.0, 3.8e5)
                tau = np.where(vent, 0.15, 0.6)
                p = p + (target - p) * (1 - np.exp(-h / tau))
    return np.array(rows)


def make_log(path: Path, hours: float = 1.0, seed: int = 0) -> int:
    """Write ``hours`` of log (cycles repeated, time running on, sensor noise 0.01 m/s,
    0.02 rad/s, 0.01 bar) as ``path``.parquet and ``path``.csv; the number of samples."""
    base = _cycle()
    n = int(round(hours * 3600 / PERIOD))
    data = np.tile(base, (int(np.ceil(n / base.shape[0])), 1))[:n]
    rng = np.random.default_rng(seed)
    cols = {"time": np.arange(n) * PERIOD,
            "train_speed": data[:, 0] + rng.normal(0, 0.01, n)}
    for i in range(4):
        cols[f"wheel_speed_{i + 1}"] = data[:, 1 + i] + rng.normal(0, 0.02, n)
    for i in range(4):
        cols[f"brake_pressure_{i + 1}"] = data[:, 5 + i] / 1e5 + rng.normal(0, 0.01, n)
    frame = pd.DataFrame(cols)
    frame.to_parquet(path.with_suffix(".parquet"), index=False)
    frame.to_csv(path.with_suffix(".csv"), index=False, float_format="%.9g")
    return n


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.2f} (1 min), {five:.2f} (5 min)"


def _timed(fn):
    """fn(), its wall time and the process's user and system CPU time [s]."""
    t, c = time.perf_counter(), os.times()
    out = fn()
    d = os.times()
    return out, time.perf_counter() - t, d.user - c.user, d.system - c.system


def _fits(ident):
    ident._cache.clear()  # the binning is part of the stage
    fit_adhesion_curves(ident)
    fit_adhesion_curves(ident, slip="relative")
    for phase in ("loss", "recovery"):
        fit_adhesion_curves(ident, phase=phase, per_band=False)


def _stages(base: Path, out: Path, threads: int, repeat: int) -> dict:
    """Median wall, user and system time [s] of each stage, run ``repeat`` times in a row."""
    rows: dict[str, list[tuple[float, float, float]]] = {}

    def record(name, fn):
        res = None
        for _ in range(repeat):
            res = None  # free the previous result first, as a fresh run would
            res, wall, user, system = _timed(fn)
            rows.setdefault(name, []).append((wall, user, system))
        return res

    csv, parquet = base.with_suffix(".csv"), base.with_suffix(".parquet")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        record("read CSV", lambda: read_braking_log(csv, warn=False))
        log = record("read Parquet", lambda: read_braking_log(parquet, warn=False))
    ident = record("identify (filters, eq. 14, loads, mu, windows)",
                   lambda: identify_adhesion(log, VEH, threads=threads))
    record("surfaces 40 x 40 x 3 phases, both slips", lambda: (
        adhesion_surface(ident), adhesion_surface(ident, slip="relative")))
    record("fits with their binning (4 bands + all, 2 slips; loss, recovery)",
           lambda: _fits(ident))
    ident = log = None  # noqa: F841 - free them before the end-to-end runs
    for src, path in (("Parquet", parquet), ("CSV", csv)):
        record(f"end to end from {src} (run_identification)",
               lambda p=path: run_identification(p, VEH, out, threads=threads))
    return {k: tuple(statistics.median(r[i] for r in v) for i in range(3))
            for k, v in rows.items()}


def _cli(log: Path, veh: Path, out: Path, figures: bool):
    """Wall, user and system time [s] of the CLI command in a fresh process."""
    cmd = [sys.executable, "-m", "railadhesion", "identify", str(log), "--vehicle", str(veh),
           "--out", str(out), "--figures" if figures else "--no-figures"]
    env = dict(os.environ, MPLBACKEND="Agg")
    c = os.times()
    t = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    wall = time.perf_counter() - t
    d = os.times()
    return wall, d.children_user - c.children_user, d.children_system - c.children_system


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--keep", type=Path, default=None,
                    help="Write the log here (log.csv/log.parquet) and reuse it if present.")
    ap.add_argument("--no-cli", action="store_true", help="Skip the CLI timings.")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = (args.keep or Path(tmp)) / "log"
        base.parent.mkdir(parents=True, exist_ok=True)
        t0 = time.perf_counter()
        if not (base.with_suffix(".parquet").exists() and base.with_suffix(".csv").exists()):
            make_log(base, args.hours)
        n = len(pd.read_parquet(base.with_suffix(".parquet"), columns=["time"]))
        print(f"log: {n} samples x 4 axles ({n * PERIOD / 3600:g} h at 2.4 ms), ready in "
              f"{time.perf_counter() - t0:.1f} s")
        out = Path(tmp) / "out"
        cores = worker_count(None)
        print(f"cores available: {cores}; {_load()}")
        warm, wall, _, _ = _timed(lambda: run_identification(base.with_suffix(".parquet"),
                                                              VEH, out))
        b = warm.ident.brake
        print(f"warm-up run (kernels loaded): {wall:.2f} s; c = {b.mean * 1e5:.1f} N m/bar "
              f"(true {VEH.brake_coefficient * 1e5:.0f}), fitted mu(slip) R^2 = "
              f"{warm.law.overall.r_squared:.3f}")
        del warm
        results = {}
        for threads in sorted({1, cores}):
            results[threads] = _stages(base, out, threads, args.repeat)
        print(f"\nmedian of {args.repeat} runs in a row: wall / user / system CPU [s]; "
              f"{_load()}")
        head = "".join(f"  {t} thread{'s' if t > 1 else ' '}: wall / user / sys" for t in results)
        print(f"  {'stage':<66}{head}")
        for name in results[1]:
            cells = "".join("  {:13.3f} / {:5.3f} / {:5.3f}".format(*results[t][name])
                            for t in results)
            print(f"  {name:<66}{cells}")
        if not args.no_cli:
            veh = Path(tmp) / "vehicle.toml"
            VEH.to_toml(veh)
            print(f"\nCLI 'railadhesion identify' in a fresh process (imports, kernel loading "
                  f"and first touch of memory included; every core), median of "
                  f"{args.repeat}: wall / user / sys [s]; {_load()}")
            for src in ("parquet", "csv"):
                for figures in (False, True):
                    runs = [_cli(base.with_suffix("." + src), veh, Path(tmp) / "cli", figures)
                            for _ in range(args.repeat)]
                    wall, user, system = (statistics.median(r[i] for r in runs)
                                          for i in range(3))
                    label = f"from {src} {'with' if figures else 'without'} figures"
                    print(f"  {label:<32} {wall:7.2f} / {user:5.2f} / {system:5.2f}")
            start = [sys.executable, "-c", "import railadhesion.cli, "
                     "railadhesion.identification.pipeline"]
            t = time.perf_counter()
            subprocess.run(start, check=True, env=dict(os.environ))
            print(f"  {'(imports alone)':<32} {time.perf_counter() - t:7.2f}")
        print(f"\n{_load()}")


if __name__ == "__main__":
    main()
