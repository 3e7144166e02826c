"""Overhead of the pandas/xarray decorator (railadhesion._labelled) on plain scalar calls.

Model functions are called millions of times in ODE right-hand sides; the decorator's fast
path (plain floats / NumPy arrays) must add well under 1 µs. Prints the median over repeats
of the per-call time of a trivial 8-argument function with and without the decorator, and
of polach_forces with and without it (``__wrapped__``). Timings on a shared machine vary run
to run; the overhead is the difference of medians.
"""

from __future__ import annotations

import statistics
import timeit

from railadhesion._labelled import labelled
from railadhesion.models.polach import polach_forces


def _trivial(a, b, c, d, e, f, g, h, *, mu0=0.3, k_A=1.0):
    return a


def _per_call(fn, number=100_000, repeat=5) -> float:
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6  # µs


def main() -> None:
    wrapped = labelled(units=("N", "N"))(_trivial)
    a, b, c, d, e, f, g, h = (-0.01, 0.0, 0.0, 4200.0, 5.0, 1.4e-3, 3.2e-3, 0.0)
    raw, dec = [], []
    for _ in range(10):  # interleaved: both see the same machine load
        raw.append(_per_call(lambda: _trivial(a, b, c, d, e, f, g, h, mu0=0.4, k_A=0.5)))
        dec.append(_per_call(lambda: wrapped(a, b, c, d, e, f, g, h, mu0=0.4, k_A=0.5)))
    overhead = [y - x for x, y in zip(raw, dec, strict=True)]
    print(f"trivial 10-argument function: {min(raw):.3f} µs plain, {min(dec):.3f} µs "
          f"decorated (best of 50 x 100k calls); overhead median {statistics.median(overhead):.3f}"
          f" µs, min {min(overhead):.3f} µs")
    call = (-0.01, 0.0, 0.0, 4200.0, 5.0, 1.4e-3, 3.2e-3)
    p_raw = _per_call(lambda: polach_forces.__wrapped__(*call, mu0=0.4, k_A=0.5), 20_000)
    p_wr = _per_call(lambda: polach_forces(*call, mu0=0.4, k_A=0.5), 20_000)
    print(f"polach_forces scalar call: {p_raw:.2f} µs undecorated, {p_wr:.2f} µs decorated")


if __name__ == "__main__":
    main()
