"""Compare the exact solver's two methods on random cases: same forces, same stick/slip maps.

Usage::

    PYTHONPATH=src python3 scripts/compare_exact_solvers.py [cases] [seed]

Draws ``cases`` (default 40) random Coulomb cases: a/b 0.2-5 (log-uniform), creepage magnitude
3e-5 to 1e-2 (log-uniform) in any direction, spin 0 or up to 2 rad/m, grids of 36-63 x 36-63
elements, scale 1 or 1.1. Solves each by ``method="gauss-seidel"`` and ``method="newton"``
(:func:`railadhesion.contact.exact.exact_rolling`, default tolerance) and prints the largest
force and moment differences (over mu Fz, and mu Fz c for the moment), the largest number of
elements whose stick/slip state differs, and the total time of each method. Several minutes.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.plausibility import PlausibilityWarning

FZ, MU, C = 1e5, 0.3, 6e-3


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    cases = int(argv[0]) if argv else 40
    rng = np.random.default_rng(int(argv[1]) if len(argv) > 1 else 1)
    worst_f = worst_m = 0.0
    worst_state = 0
    times = {"gauss-seidel": 0.0, "newton": 0.0}
    for k in range(cases):
        aob = np.exp(rng.uniform(np.log(0.2), np.log(5.0)))
        a, b = C * np.sqrt(aob), C / np.sqrt(aob)
        mag = 10 ** rng.uniform(-4.5, -2.0)
        th = rng.uniform(0.0, 2.0 * np.pi)
        phi = rng.choice([0.0, rng.uniform(-2.0, 2.0)])
        nx, ny = int(rng.integers(36, 64)), int(rng.integers(36, 64))
        scale = float(rng.choice([1.0, 1.1]))
        args = (mag * np.cos(th), mag * np.sin(th), phi, FZ, a, b, MU)
        res = {}
        for method in times:
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PlausibilityWarning)
                res[method] = exact_rolling(*args, nx=nx, ny=ny, scale=scale, method=method,
                                            return_fields=True)  # fmt: skip
            times[method] += time.perf_counter() - t0
        g, n = res["gauss-seidel"], res["newton"]
        df = max(abs(float(g.fx - n.fx)), abs(float(g.fy - n.fy))) / (MU * FZ)
        dm = abs(float(g.mz - n.mz)) / (MU * FZ * C)
        ds = int((g.state != n.state).sum())
        worst_f, worst_m, worst_state = max(worst_f, df), max(worst_m, dm), max(worst_state, ds)
        print(f"{k:3d} a/b {aob:5.2f} creepage {mag:.1e} spin {phi:+.2f} {nx}x{ny} scale "
              f"{scale}: dF {df:.1e} dMz {dm:.1e} states differing {ds} ({n.method})")  # fmt: skip
    print(f"\n{cases} cases: largest |dF|/(mu Fz) {worst_f:.1e}, |dMz|/(mu Fz c) {worst_m:.1e}, "
          f"elements in a different state at most {worst_state}; total time Gauss-Seidel "
          f"{times['gauss-seidel']:.1f} s, Newton {times['newton']:.1f} s")  # fmt: skip


if __name__ == "__main__":
    main()
