"""Benchmark of the exact steady-rolling solver (``railadhesion.contact.exact_rolling``).

Run with ``PYTHONPATH=src python3 benchmarks/bench_exact.py`` (``--quick``: fewer repeats).
Prints the wall-clock time per case (median of the repeats, after compilation) at 30 x 30 and
60 x 60 elements, for CONTACT's ``fastsim`` example (a/b = 2, lateral creepage and spin,
partial slip) and for a longitudinal creepage on a circular contact, plus the number of
Gauss-Seidel sweeps. CONTACT (Fortran) needs about 26 ms and 0.6 s per case at these sizes
(issue 12). Timings vary with the load of the machine: quote medians.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import time

from railadhesion.contact.exact import exact_rolling

CASES = {
    "fastsim example (a/b=2, eta+spin)": (0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3),
    "circle, xi = 1e-3": (1e-3, 0.0, 0.0, 1e5, 5e-3, 5e-3, 0.3),
}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="one repeat (smoke run)")
    args = parser.parse_args(argv)
    repeat = 1 if args.quick else 5
    print(f"python {platform.python_version()}, {platform.machine()}")
    exact_rolling(*CASES["circle, xi = 1e-3"], nx=8, ny=8)  # compile / load the cache
    print(f"{'case':<36} {'grid':>7} {'median [s]':>11} {'min [s]':>9} {'sweeps':>7}")
    for name, case in CASES.items():
        for n in (30, 60):
            times = []
            for _ in range(repeat):
                t0 = time.perf_counter()
                r = exact_rolling(*case, nx=n, ny=n)
                times.append(time.perf_counter() - t0)
            print(
                f"{name:<36} {n:>3}x{n:<3} {statistics.median(times):>11.3f} "
                f"{min(times):>9.3f} {int(r.iterations):>7}"
            )


if __name__ == "__main__":
    main()
