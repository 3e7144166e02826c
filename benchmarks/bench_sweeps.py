"""Benchmark: a WILAC adhesion map (creep x speed x load x water flow) to Zarr with Dask.

    PYTHONPATH=src python3 benchmarks/bench_sweeps.py                  # 10^8 points (minutes)
    PYTHONPATH=src python3 benchmarks/bench_sweeps.py --points 2e6     # quick run

Prints, for a LocalCluster of 1 and 2 single-threaded worker processes:
* the full sweep (``--points``, 2 workers): wall time, throughput, peak memory (resident set
  of the workers and this process, sampled every 0.1 s), size of the store;
* scaling from 1 to 2 workers on ``--scaling-points`` (median of ``--repeats`` runs):
  efficiency = T1 / (2 T2);
* where the time goes in one chunk: model evaluation against writing to Zarr.

The model is called through the public ``railadhesion.wilac_forces`` (via
``railadhesion.sweeps.WilacSweep``), so a faster WILAC kernel speeds this up unchanged.
Timings vary run to run on a shared machine: medians are printed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import psutil

import railadhesion
from railadhesion.sweeps import WilacSweep, plan_sweep, run_sweep


def wilac_grid(points: int) -> dict:
    """creep x speed x load x water flow with about ``points`` points (creep: 100 values)."""
    n_creep = min(100, max(2, int(round(points ** 0.25))))
    rest = points / n_creep
    side = max(2, int(round(rest ** (1 / 3))))
    n_water = max(2, int(round(rest / side**2)))
    return {
        "creep_long": np.geomspace(1e-3, 0.9, n_creep),
        "speed": np.linspace(2.5, 40.0, side),
        "normal_force": np.linspace(2000.0, 8000.0, side),
        "water_flow": np.linspace(0.0, 200.0, n_water),
    }


class PeakMemory:
    """Peak summed RSS of this process and its children, sampled in a thread."""

    def __init__(self, interval: float = 0.1):
        self.interval, self.peak, self._stop = interval, 0, threading.Event()

    def _sample(self) -> int:
        me = psutil.Process()
        total = 0
        for p in [me, *me.children(recursive=True)]:
            try:
                total += p.memory_info().rss
            except psutil.Error:
                pass
        return total

    def __enter__(self):
        self.baseline = self._sample()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        return self

    def _run(self):
        while not self._stop.is_set():
            self.peak = max(self.peak, self._sample())
            time.sleep(self.interval)

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()


def cluster(n_workers: int, memory_limit: str):
    from distributed import Client, LocalCluster

    src = str(Path(railadhesion.__file__).resolve().parents[1])
    env = {"PYTHONPATH": os.pathsep.join(filter(None, [src, os.environ.get("PYTHONPATH")]))}
    lc = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                      memory_limit=memory_limit, dashboard_address=None, env=env)  # fmt: skip
    return lc, Client(lc)


def _cpu_seconds() -> float:
    t = psutil.Process().cpu_times()
    return t.user + t.system


def one_run(plan, n_workers: int, out: Path, memory_limit: str):
    lc, client = cluster(n_workers, memory_limit)
    try:
        # Warm-up outside the timing: imports and the parameter set loaded on every worker.
        warm = plan_sweep(plan.model, {"creep_long": [0.01, 0.1], "water_flow": [0.0, 30.0]},
                          fixed={"normal_force": 4200.0, "speed": 5.0}, chunks={"water_flow": 1})
        run_sweep(warm, client=client)
        before = client.run(_cpu_seconds)
        with PeakMemory() as mem:
            res = run_sweep(plan, out=out, client=client, overwrite=True)
        after = client.run(_cpu_seconds)
        res.worker_cpu = sum(after[w] - before[w] for w in after if w in before)
        return res, mem
    finally:
        client.close()
        lc.close()


def store_size(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def chunk_breakdown(plan, out: Path, n: int = 3):
    """Seconds to evaluate and to write one chunk (median of ``n`` chunks)."""
    import zarr

    from railadhesion.sweeps.run import _init_store

    _init_store(plan, out, True, None)  # an empty store of the plan's layout
    evals, writes = [], []
    group = zarr.open_group(str(out), mode="r+")
    for index in list(plan.chunk_indices())[:n]:
        t0 = time.perf_counter()
        data, _ = plan.evaluate_chunk(index)
        t1 = time.perf_counter()
        for name in plan.variables:
            group[name][plan.chunk_slices(index)] = data[name]
        writes.append(time.perf_counter() - t1)
        evals.append(t1 - t0)
    return statistics.median(evals), statistics.median(writes)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=float, default=1e8, help="points of the full sweep")
    ap.add_argument("--scaling-points", type=float, default=None,
                    help="points of the 1- vs 2-worker runs (default: min(points, 1e7))")
    ap.add_argument("--repeats", type=int, default=3, help="runs per worker count (median)")
    ap.add_argument("--chunk-points", type=int, default=2**18, help="points per chunk")
    ap.add_argument("--memory-limit", default="1.5GiB", help="per worker")
    ap.add_argument("--dir", type=Path, default=None, help="where to write (default: a tmpdir)")
    ap.add_argument("--skip-full", action="store_true", help="only the scaling runs")
    args = ap.parse_args(argv)
    scaling_points = int(args.scaling_points or min(args.points, 1e7))
    work = args.dir or Path(tempfile.mkdtemp(prefix="bench_sweeps_"))
    work.mkdir(parents=True, exist_ok=True)
    model = WilacSweep(geometry="tram")
    print(f"railadhesion sweeps benchmark: WILAC, {os.cpu_count()} cores, "
          f"{psutil.virtual_memory().total / 2**30:.1f} GiB RAM; chunks of ~{args.chunk_points} "
          "points; timings vary run to run on a shared machine")  # fmt: skip
    try:
        small = plan_sweep(model, wilac_grid(scaling_points), chunk_points=args.chunk_points)
        ev, wr = chunk_breakdown(small, work / "breakdown.zarr")
        print(f"one chunk of {np.prod(small.chunk_shape):,} points: evaluate {ev * 1e3:.0f} ms, "
              f"write to Zarr {wr * 1e3:.0f} ms ({wr / (ev + wr):.0%} of the chunk's time)")
        times, cpu, peak = {1: [], 2: []}, {1: [], 2: []}, {1: [], 2: []}
        for _ in range(args.repeats):
            for k in (1, 2):
                res, mem = one_run(small, k, work / f"scaling{k}.zarr", args.memory_limit)
                times[k].append(res.elapsed)
                cpu[k].append(res.worker_cpu)
                peak[k].append(mem.peak)
        t1, t2 = statistics.median(times[1]), statistics.median(times[2])
        c1, c2 = statistics.median(cpu[1]), statistics.median(cpu[2])
        print(f"scaling on {small.size:,} points ({small.n_chunks} chunks), median of "
              f"{args.repeats}: 1 worker {t1:.1f} s ({small.size / t1 / 1e6:.2f} M points/s), "
              f"2 workers {t2:.1f} s ({small.size / t2 / 1e6:.2f} M points/s); "
              f"wall-clock efficiency T1/(2 T2) = {t1 / (2 * t2):.0%}")
        print(f"  runs [s]: 1 worker {[round(t, 1) for t in times[1]]}, "
              f"2 workers {[round(t, 1) for t in times[2]]}; load average now: "
              f"{os.getloadavg()[0]:.1f}; peak memory (all processes) 1 worker "
              f"{max(peak[1]) / 2**30:.2f} GiB, 2 workers {max(peak[2]) / 2**30:.2f} GiB")
        print(f"  worker CPU time (median): 1 worker {c1:.1f} s, 2 workers {c2:.1f} s in total; "
              f"work efficiency CPU1/CPU2 = {c1 / c2:.0%} (what 2 workers would reach on 2 "
              "free cores; insensitive to other jobs on the machine)")
        if not args.skip_full:
            plan = plan_sweep(model, wilac_grid(int(args.points)), chunk_points=args.chunk_points)
            out = work / "full.zarr"
            res, mem = one_run(plan, 2, out, args.memory_limit)
            dims = " x ".join(f"{d} {n}" for d, n in zip(plan.dims, plan.shape, strict=True))
            print(f"full sweep {dims} = {plan.size:,} points, {plan.n_chunks} chunks, 2 workers: "
                  f"{res.elapsed:.1f} s, {res.points_per_second / 1e6:.2f} M points/s "
                  f"(worker CPU {res.worker_cpu:.0f} s: {plan.size / res.worker_cpu / 1e6:.2f} "
                  f"M points per CPU-second; load average now {os.getloadavg()[0]:.1f}); "
                  f"peak memory {mem.peak / 2**30:.2f} GiB (all processes; "
                  f"{mem.baseline / 2**30:.2f} GiB before the sweep); store "
                  f"{store_size(out) / 2**30:.2f} GiB; failed points {res.failed_points}")
    finally:
        if args.dir is None:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
