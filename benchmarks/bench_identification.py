"""Benchmark: identification of 1 hour of a 4-axle braking log at 2.4 ms (1.5 M samples).

End to end = read the log + identify_adhesion (filters, eq. 14, loads, mu, windows) + the
40 x 40 surface + the fitted mu(slip) curves per speed band. Figures are not included (they
thin long logs and take about a second on their own).

The log is synthetic: 3 minutes of braking with wheel-slide-protection cycles, simulated once
with a small simulator written here (semi-implicit Euler, a falling adhesion law), repeated to
one hour with time running on and small sensor noise. Prints the median of ``--repeat`` runs
per stage. The machine is shared: quote medians and say so.

Run: ``PYTHONPATH=src python3 benchmarks/bench_identification.py [--repeat 3]``
"""

from __future__ import annotations

import argparse
import statistics
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

PERIOD = 2.4e-3
VEH = Vehicle(name="bench coach", body_mass=32600.0, bogie_mass=3200.0, wheelset_mass=1500.0,
              wheel_radius=0.46, wheelset_inertia=150.0, brake_coefficient=0.02)


def _law(w):
    w = np.maximum(w, 0.0)
    return 0.12 * -np.expm1(-w / 0.15) * (0.45 + 0.55 * np.exp(-0.35 * w))


def _braking(v0, duration, seed):
    """One braking from v0 with WSP cycles, vectorised over nothing: a plain Euler loop."""
    r, j, c, m = VEH.wheel_radius, VEH.wheelset_inertia, VEH.brake_coefficient, VEH.total_mass
    sub = 4
    h = PERIOD / sub
    v, om, p, vent = v0, np.full(4, v0 / r), np.zeros(4), np.zeros(4, bool)
    n = int(duration / PERIOD)
    out = np.empty((n, 9))
    d = 0.0
    for k in range(n):
        out[k, 0], out[k, 1:5], out[k, 5:] = v, om, p
        for _ in range(sub):
            w = v - r * om
            f = _law(w) * VEH.axle_normal_loads(d)
            om = np.maximum(om + h * (f * r - np.where(om > 0, c * p, 0.0)) / j, 0.0)
            d = f.sum() / m
            v = max(v - h * d, 0.0)
            vent = np.where(w > 3.0, True, np.where(w < 0.8, False, vent))
            p = p + (np.where(vent, 0.0, 3.8e5) - p) * (1 - np.exp(-h / np.where(vent, 0.15,
                                                                                   0.6)))
    return out


def make_log(path: Path, hours: float = 1.0, seed: int = 0) -> int:
    base = np.concatenate([_braking(v0, 20.0, seed) for v0 in (35.0, 28.0, 20.0)])
    reps = int(np.ceil(hours * 3600 / PERIOD / base.shape[0]))
    data = np.tile(base, (reps, 1))[: int(hours * 3600 / PERIOD)]
    rng = np.random.default_rng(seed)
    n = data.shape[0]
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


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--keep", type=Path, default=None,
                    help="Write the log here (log.csv/log.parquet) and reuse it if present.")
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
        times: dict[str, list[float]] = {}
        cpu: dict[str, list[float]] = {}

        def timed(name, fn):
            t, c = time.perf_counter(), time.process_time()
            out = fn()
            times.setdefault(name, []).append(time.perf_counter() - t)
            cpu.setdefault(name, []).append(time.process_time() - c)
            return out

        for _ in range(args.repeat):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                timed("read CSV", lambda: read_braking_log(base.with_suffix(".csv"), warn=False))
                log = timed("read Parquet",
                            lambda: read_braking_log(base.with_suffix(".parquet"), warn=False))
            ident = timed("identify (filters, eq. 14, mu, windows)",
                          lambda: identify_adhesion(log, VEH))  # noqa: B023
            timed("surface 40 x 40 x 3 phases", lambda: adhesion_surface(ident))  # noqa: B023
            timed("fit mu(slip), 4 bands + all", lambda: fit_adhesion_curves(ident))  # noqa: B023
        med = {k: statistics.median(v) for k, v in times.items()}
        mcpu = {k: statistics.median(v) for k, v in cpu.items()}
        print(f"median of {args.repeat} runs, wall and process CPU time [s] "
              "(machine shared with other jobs: noisy)")
        for k in med:
            print(f"  {k:<42} {med[k]:7.3f} {mcpu[k]:7.3f}")
        core = sum(med[k] for k in med if not k.startswith("read"))
        ccore = sum(mcpu[k] for k in mcpu if not k.startswith("read"))
        print(f"  {'processing (identify + surface + fit)':<42} {core:7.3f} {ccore:7.3f}")
        print(f"  {'end to end from Parquet':<42} {core + med['read Parquet']:7.3f} "
              f"{ccore + mcpu['read Parquet']:7.3f}")
        print(f"  {'end to end from CSV':<42} {core + med['read CSV']:7.3f} "
              f"{ccore + mcpu['read CSV']:7.3f}")


if __name__ == "__main__":
    main()
