"""Benchmark runner: throughput and latency of the hot paths.

Run with ``python benchmarks/run.py`` (``--quick`` for smaller sizes). Prints contacts per
second for the vectorised kernels and the latency of single scalar calls (as made inside an
ODE right-hand side). Timings are best-of-N wall-clock on the current machine.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np


def best_of(func, repeat: int = 3) -> float:
    """Shortest wall-clock time [s] of ``repeat`` calls of ``func``."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        func()
        best = min(best, time.perf_counter() - t0)
    return best


def scalar_latency(func, n: int = 2000) -> float:
    """Mean time [s] of one call, over ``n`` calls (after a warm-up)."""
    for _ in range(50):
        func()
    t0 = time.perf_counter()
    for _ in range(n):
        func()
    return (time.perf_counter() - t0) / n


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="smaller sizes (CI smoke run)")
    args = parser.parse_args(argv)

    from railadhesion.contact.fastsim import fastsim
    from railadhesion.contact.hertz import hertz_3d
    from railadhesion.contact.kalker import kalker_coefficients
    from railadhesion.models.parameters import polach_parameters
    from railadhesion.models.polach import polach_forces
    from railadhesion.models.wilac import Wilac

    rng = np.random.default_rng(0)
    n = 10_000 if args.quick else 1_000_000
    q = rng.uniform(20e3, 120e3, n)
    v = rng.uniform(1.0, 40.0, n)
    xi = rng.uniform(-0.3, 0.3, n)
    eta = rng.uniform(-0.01, 0.01, n)
    phi = rng.uniform(-2.0, 2.0, n)
    a = rng.uniform(3e-3, 8e-3, n)
    b = rng.uniform(3e-3, 8e-3, n)
    w = rng.uniform(0.0, 100.0, n)
    dry = polach_parameters("polach2005_dry").as_dict()

    rows: list[tuple[str, str]] = []

    def throughput(label, func, count):
        t = best_of(func)
        rows.append((label, f"{count / t:,.0f} contacts/s  ({t * 1e3:.1f} ms for {count:,})"))

    def latency(label, func):
        t = scalar_latency(func)
        rows.append((label, f"{t * 1e6:.1f} µs per call"))

    throughput("Polach, vectorised (xi, eta, spin)",
               lambda: polach_forces(xi, eta, phi, q, v, a, b, **dry), n)
    throughput("Polach, vectorised (xi only)",
               lambda: polach_forces(xi, 0.0, 0.0, q, v, a, b, **dry), n)
    latency("Polach, one scalar call (same contact shape)",
            lambda: polach_forces(0.01, 0.001, 0.1, 100e3, 20.0, 6e-3, 5e-3, **dry))
    shapes = iter(np.tile(rng.uniform(3e-3, 8e-3, 4096), 64).tolist())
    latency("Polach, one scalar call (new a/b every call)",
            lambda: polach_forces(0.01, 0.001, 0.1, 100e3, 20.0, next(shapes), 5e-3, **dry))
    wilac = Wilac()
    throughput("WILAC, vectorised (array water flow)",
               lambda: wilac.forces(xi, eta, phi, q, v, a, b, w), n)
    latency("WILAC, one scalar call (w = 25 µl/s)",
            lambda: wilac.forces(0.01, 0.0, 0.0, 100e3, 20.0, 6e-3, 5e-3, 25.0))
    latency("Kalker coefficients, one scalar call", lambda: kalker_coefficients(0.7, 0.28))
    m = n // 10
    rail_lateral = rng.uniform(0.2, 0.6, m)
    throughput("Hertz 3D (exact elliptic integrals), vectorised, varied geometry",
               lambda: hertz_3d(q[:m], 0.46, np.inf, rail_lateral), m)
    for grid, count in ((20, 2000 if args.quick else 20_000), (40, 500 if args.quick else 5000)):
        throughput(f"FASTSIM {grid}x{grid}, batched",
                   lambda grid=grid, count=count: fastsim(
                       xi[:count] * 0.01, eta[:count], phi[:count], q[:count], a[:count],
                       b[:count], 0.3, nx=grid, ny=grid),
                   count)
        latency(f"FASTSIM {grid}x{grid}, one contact",
                lambda grid=grid: fastsim(0.001, 0.0, 0.0, 80e3, 6e-3, 5e-3, 0.3,
                                          nx=grid, ny=grid))

    print(f"railadhesion benchmarks on {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}, NumPy {np.__version__}")
    width = max(len(label) for label, _ in rows)
    for label, value in rows:
        print(f"  {label:<{width}}  {value}")


if __name__ == "__main__":
    main()
