"""Benchmark of the exact steady-rolling solver and of its table model.

Run with ``PYTHONPATH=src python3 benchmarks/bench_exact.py`` (``--quick``: fewer repeats;
``--table``: the table model only; ``--before REV``: the solver of this checkout beside the
solver of git revision REV, side by side).
Prints:

* the exact solver's wall-clock time per case (median of the repeats, after compilation) at
  30 x 30 and 60 x 60 elements, for CONTACT's ``fastsim`` example (a/b = 2, lateral creepage
  and spin, partial slip), a longitudinal creepage on a circular contact, and a long
  (a/b = 0.3) and a wide (a/b = 3) contact with lateral creepage and spin: with Coulomb
  and with falling friction (Polach's dry law at 30 m/s), by both solvers
  (``method="gauss-seidel"`` and ``"newton"``, taken in turns, with the ratio of their
  times), plus the iterations (sweeps or Newton steps, and friction updates).
  CONTACT (Fortran) needs about 26 ms and 0.6 s per case at these sizes (issue 12);
* the table model's cost per contact, vectorised over 100 000 and 1 000 000 contacts with
  spin, beside the package's vectorised Polach on the same inputs in the same run (issue 22
  target: at most 3x Polach): a/b (and Fz) varying per contact (the 4-D lookup, Kalker's
  coefficients per contact for both models; with one nu the table takes them from Kalker's
  rows at that nu, with nu per contact too it looks them up contact by contact as Polach
  does), a and b as arrays of equal values, a and b given once (the 3-D lookup); Coulomb
  friction, falling friction and nu = 0.25. Both run
  in parallel at these sizes (``NUMBA_NUM_THREADS=1`` for one thread).

* with ``--before REV`` (e.g. ``--before 2a7873f``, the solver before its influence sums were
  done by FFT): the time per case at 30 x 30 and 60 x 60 of both solvers, each run in its own
  process (``git archive REV src`` unpacked to a temporary directory), the two processes
  taking turns; per case the median over the rounds and the median of the per-round ratios.

Timings vary with the load of the machine: quote medians and ratios, with ``uptime``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.contact.table import exact_table_forces
from railadhesion.models.polach import polach_forces

CASES = {
    "fastsim example (a/b=2, eta+spin)": (0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3),
    "circle, xi = 1e-3": (1e-3, 0.0, 0.0, 1e5, 5e-3, 5e-3, 0.3),
    "long (a/b=0.3, eta+spin)": (0.0, 1e-3, 0.3, 1e5, 3e-3, 10e-3, 0.3),
    "wide (a/b=3, eta-spin)": (0.0, 3e-4, -0.5, 1e5, 9e-3, 3e-3, 0.3),
}
#: Polach's dry set (A = 0.4, B = 0.6 s/m) at 30 m/s
FALLING = dict(speed=30.0, friction_ratio=0.4, friction_decay=0.6)
#: The two solvers of ``exact_rolling`` (``method=``), timed in turns on each case
METHODS = ("gauss-seidel", "newton")


def bench_solver(repeat: int) -> None:
    """Time per case of both solvers, taken in turns, with Coulomb and with falling friction;
    ratio = Gauss-Seidel / Newton, the median of the per-repeat ratios."""
    for m in METHODS:  # compile / load the caches
        exact_rolling(*CASES["circle, xi = 1e-3"], nx=24, ny=24, method=m)
        exact_rolling(*CASES["circle, xi = 1e-3"], nx=24, ny=24, method=m, **FALLING)
    print(f"{'case':<36} {'friction':<9} {'grid':>7} {'method':<13} {'median [s]':>11} "
          f"{'min [s]':>9} {'iter.':>6} {'updates':>8} {'GS/Newton':>10}")  # fmt: skip
    for name, case in CASES.items():
        for law_name, law in (("Coulomb", {}), ("falling", FALLING)):
            for n in (30, 60):
                times: dict = {m: [] for m in METHODS}
                res = {}
                for _ in range(repeat):
                    for m in METHODS:
                        t0 = time.perf_counter()
                        res[m] = exact_rolling(*case, nx=n, ny=n, method=m, **law)
                        times[m].append(time.perf_counter() - t0)
                ratio = statistics.median(
                    g / w for g, w in zip(times["gauss-seidel"], times["newton"], strict=True)
                )
                for m in METHODS:
                    r = res[m]
                    print(
                        f"{name:<36} {law_name:<9} {n:>3}x{n:<3} {m:<13} "
                        f"{statistics.median(times[m]):>11.3f} {min(times[m]):>9.3f} "
                        f"{int(r.iterations):>6} {int(r.friction_iterations):>8} "
                        + (f"{ratio:>10.1f}" if m == "newton" else "")
                    )


#: The cases of ``--before``: (name, case, friction law, grid)
VERSUS = [(name, case, law_name, n) for name, case in CASES.items()
          for law_name in ("Coulomb", "falling") for n in (30, 60)]  # fmt: skip

_CHILD = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
from railadhesion.contact.exact import exact_rolling
cases, falling, repeat = json.loads(sys.argv[1])
exact_rolling(1e-3, 0.0, 0.0, 1e5, 5e-3, 5e-3, 0.3, nx=8, ny=8)
exact_rolling(1e-3, 0.0, 0.0, 1e5, 5e-3, 5e-3, 0.3, nx=8, ny=8, **falling)
out = []
for case, law, n in cases:
    law = falling if law == "falling" else {}
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = exact_rolling(*case, nx=n, ny=n, **law)
        best = min(best, time.perf_counter() - t0)
    out.append([best, int(r.iterations), float(r.fx), float(r.fy)])
print(json.dumps(out))
"""


def _run_child(src: str, repeat: int) -> list:
    env = dict(os.environ, PYTHONPATH=src)
    arg = json.dumps([[[list(c), law, n] for _, c, law, n in VERSUS], FALLING, repeat])
    res = subprocess.run([sys.executable, "-c", _CHILD, arg], env=env, capture_output=True,
                         text=True, check=True)  # fmt: skip
    return json.loads(res.stdout.strip().splitlines()[-1])


def bench_before(rev: str, repeat: int, rounds: int) -> None:
    """The solver of this checkout beside the solver of git revision ``rev``, side by side."""
    root = Path(__file__).resolve().parent.parent
    here = str(root / "src")
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "-C", str(root), "archive", rev, "src"],
                                 capture_output=True, check=True).stdout  # fmt: skip
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        before = str(Path(tmp) / "src")
        _run_child(before, 1)  # compile both (numba's cache), not timed
        _run_child(here, 1)
        runs = {"before": [], "now": []}
        for _ in range(rounds):
            runs["before"].append(_run_child(before, repeat))
            runs["now"].append(_run_child(here, repeat))
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"\nexact solver per case, revision {rev} ('before') beside this checkout ('now'): "
          f"best of {repeat} per round, median over {rounds} rounds taken in turn "
          f"(load average {load:.2f})")  # fmt: skip
    print(f"{'case':<36} {'friction':<9} {'grid':>7} {'before [s]':>11} {'now [s]':>9} "
          f"{'ratio':>6} {'sweeps':>7} {'max |dF|/Fz':>12}")  # fmt: skip
    for k, (name, case, law, n) in enumerate(VERSUS):
        tb = [r[k][0] for r in runs["before"]]
        tn = [r[k][0] for r in runs["now"]]
        ratio = statistics.median(b / a for a, b in zip(tn, tb, strict=True))
        rb, rn = runs["before"][0][k], runs["now"][0][k]
        df = max(abs(rb[2] - rn[2]), abs(rb[3] - rn[3])) / case[3]
        print(f"{name:<36} {law:<9} {n:>3}x{n:<3} {statistics.median(tb):>11.3f} "
              f"{statistics.median(tn):>9.3f} {ratio:>6.1f} {rn[1]:>3}/{rb[1]:<3} {df:>12.1e}")


def bench_table(repeat: int) -> None:
    for n in (100_000, 1_000_000):
        _bench_table(n, repeat)
    bench_table_scalar(repeat)


def bench_table_scalar(repeat: int, calls: int = 20_000) -> None:
    """One contact per call with Python floats (the fast scalar path), beside Polach's."""
    args = (1e-3, 2e-4, 0.3, 1e5)
    table = [exact_table_forces(*args, 5e-3, 6e-3, 0.3),
             exact_table_forces(*args, 5e-3, 6e-3, 0.3, **FALLING)]  # fmt: skip
    assert all(math.isfinite(x) for r in table for x in r)

    def per_call(fn):
        fn()
        out = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            for _ in range(calls):
                fn()
            out.append((time.perf_counter() - t0) / calls)
        return statistics.median(out)

    tt = per_call(lambda: exact_table_forces(*args, 5e-3, 6e-3, 0.3))
    tf = per_call(lambda: exact_table_forces(*args, 5e-3, 6e-3, 0.3, **FALLING))
    tp = per_call(lambda: polach_forces(*args, 30.0, 5e-3, 6e-3, mu0=0.3))
    print(f"\none contact per call, Python floats (median of {repeat} x {calls:,} calls): "
          f"table {tt * 1e6:.1f} us (falling friction {tf * 1e6:.1f} us), "
          f"polach_forces {tp * 1e6:.1f} us")


def _bench_table(n: int, repeat: int) -> None:
    rng = np.random.default_rng(0)
    xs = rng.uniform(-3e-3, 3e-3, n)
    ys = rng.uniform(-3e-3, 3e-3, n)
    ps = rng.uniform(-1, 1, n)
    fz, mu, v, a, b = 1e5, 0.3, 30.0, 5e-3, 6e-3
    # a/b varying per contact (as in a multibody run: every wheel its own ellipse), 0.4-2.7
    av = rng.uniform(3e-3, 8e-3, n)
    bv = rng.uniform(3e-3, 8e-3, n)
    fzv = rng.uniform(5e4, 1.2e5, n)
    nuv = rng.uniform(0.25, 0.30, n)  # nu per contact too (Kalker's coefficients per contact)
    ae, be = np.full(n, a), np.full(n, b)  # arrays of equal values

    def best(ft, fp):
        """Best times of the table and of Polach, run alternately (a change of the machine's
        load then hits both)."""
        ft()
        fp()
        times = ([], [])
        for _ in range(repeat):
            for f, out in zip((ft, fp), times, strict=True):
                t0 = time.perf_counter()
                f()
                out.append(time.perf_counter() - t0)
        return min(times[0]), min(times[1])

    rows = [
        ("Coulomb, a/b varying",
         lambda: exact_table_forces(xs, ys, ps, fzv, av, bv, mu),
         lambda: polach_forces(xs, ys, ps, fzv, v, av, bv, mu0=mu)),
        ("Coulomb, a/b and nu varying",
         lambda: exact_table_forces(xs, ys, ps, fzv, av, bv, mu, poisson=nuv),
         lambda: polach_forces(xs, ys, ps, fzv, v, av, bv, mu0=mu, poisson=nuv)),
        ("falling, a/b varying",
         lambda: exact_table_forces(xs, ys, ps, fzv, av, bv, mu, **FALLING),
         lambda: polach_forces(xs, ys, ps, fzv, v, av, bv, mu0=mu, A=0.4, B=0.6)),
        ("Coulomb, a, b equal arrays",
         lambda: exact_table_forces(xs, ys, ps, fz, ae, be, mu),
         lambda: polach_forces(xs, ys, ps, fz, v, ae, be, mu0=mu)),
        ("Coulomb, a, b given once",
         lambda: exact_table_forces(xs, ys, ps, fz, a, b, mu),
         lambda: polach_forces(xs, ys, ps, fz, v, a, b, mu0=mu)),
        ("falling (A 0.4, B 0.6), once",
         lambda: exact_table_forces(xs, ys, ps, fz, a, b, mu, **FALLING),
         lambda: polach_forces(xs, ys, ps, fz, v, a, b, mu0=mu, A=0.4, B=0.6)),
        ("Coulomb, nu = 0.25, once",
         lambda: exact_table_forces(xs, ys, ps, fz, a, b, mu, poisson=0.25),
         lambda: polach_forces(xs, ys, ps, fz, v, a, b, mu0=mu, poisson=0.25)),
    ]  # fmt: skip
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    threads = numba.get_num_threads()
    print(f"\ntable model vs Polach, {n:,} contacts with spin, the same inputs to both (best of "
          f"{repeat}, {threads} threads; load average {load:.2f}):")  # fmt: skip
    print(f"{'contacts':<30} {'table [us]':>11} {'Polach [us]':>12} {'ratio':>7}")
    for name, ft, fp in rows:
        tt, tp = best(ft, fp)
        print(f"{name:<30} {tt / n * 1e6:>11.3f} {tp / n * 1e6:>12.3f} {tt / tp:>7.1f}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="one repeat (smoke run)")
    parser.add_argument("--table", action="store_true", help="the table model only")
    parser.add_argument("--before", metavar="REV", help="solver of git revision REV beside "
                        "this checkout's, side by side (then nothing else)")  # fmt: skip
    args = parser.parse_args(argv)
    repeat = 1 if args.quick else 5
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"python {platform.python_version()}, {platform.machine()}, load average {load:.2f}")
    if args.before:
        bench_before(args.before, 1 if args.quick else 3, 1 if args.quick else 3)
        return
    if not args.table:
        bench_solver(repeat)
    bench_table(repeat)


if __name__ == "__main__":
    main()
