"""Cost of the plausibility checks (railadhesion.plausibility) in the model functions.

The public model functions check their inputs once their own errors are raised: two
comparisons per Python float, a minimum and a maximum per array. This times, side by side in
one run (interleaved, so both see the same machine load), ``polach_forces`` and
``wilac_forces`` with their checks and with the checks replaced by a no-op, on Python floats
and on arrays of 1e5 contacts, and prints the per-call times and their ratio. The budget of
issue 18: ``polach_forces`` with floats <= 4 µs, ``wilac_forces`` <= 5 µs.

    python3 benchmarks/bench_plausibility.py
"""

from __future__ import annotations

import os
import timeit

import numpy as np

import railadhesion.models.polach as polach_module
import railadhesion.models.wilac as wilac_module
from railadhesion import default_wilac_parameters, polach_forces, wilac_forces


def _noop(*_args):
    return ()


def _best(fn, number, repeat=5) -> float:
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6  # µs


def main() -> None:
    params = default_wilac_parameters()
    n = 100_000
    creep = np.linspace(-0.3, 0.3, n)
    cases = {
        "polach_forces, floats": (lambda: polach_forces(
            0.01, 0.0, 0.0, 1e5, 20.0, 6e-3, 6e-3, mu0=0.4), 20_000),
        "wilac_forces, floats": (lambda: wilac_forces(
            0.01, 0.0, 0.0, 1e5, 20.0, 6e-3, 6e-3, 10.0, params), 20_000),
        f"polach_forces, {n:.0e} contacts": (lambda: polach_forces(
            creep, 0.0, 0.0, 1e5, 20.0, 6e-3, 6e-3, mu0=0.4), 20),
        f"wilac_forces, {n:.0e} contacts": (lambda: wilac_forces(
            creep, 0.0, 0.0, 1e5, 20.0, 6e-3, 6e-3, 10.0, params), 10),
    }  # fmt: skip
    checks = (polach_module._PLAUSIBLE, wilac_module._check_inputs)
    for fn, _ in cases.values():
        fn()  # compile / load the kernels
    times = {name: {"on": [], "off": []} for name in cases}
    for _ in range(5):
        for state in ("on", "off"):
            polach_module._PLAUSIBLE = checks[0] if state == "on" else _noop
            wilac_module._check_inputs = checks[1] if state == "on" else _noop
            for name, (fn, number) in cases.items():
                times[name][state].append(_best(fn, number, repeat=1))
    polach_module._PLAUSIBLE, wilac_module._check_inputs = checks
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"plausibility checks, best of 5 interleaved runs (load average {load:.1f}):")
    for name, t in times.items():
        on, off = min(t["on"]), min(t["off"])
        print(f"  {name:<34} {on:10.2f} µs with the checks, {off:10.2f} µs without: "
              f"ratio {on / off:.2f}")


if __name__ == "__main__":
    main()
