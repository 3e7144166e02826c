"""Benchmark runner: throughput and latency of the hot paths, each beside a baseline.

Run with ``python3 benchmarks/run.py`` (``--quick`` for small sizes, ``--kernels-only`` to skip
the other ``benchmarks/bench_*.py`` scripts, ``--no-big`` to skip the 10^7-contact cases,
``--write-docs`` to write the figures to ``docs/performance.md``, the one place where benchmark
figures are kept).

Every figure is printed beside a baseline measured in the same run on the same inputs, and
their ratio:

* "plain NumPy": a straightforward NumPy Polach (Polach 2005, section 2) with Kalker's
  coefficients computed once (constant a/b) or per contact (varying a/b), the alternative a
  user would write;
* "NumPy reference": the package's own readable NumPy implementation that the compiled
  kernels are tested against (``_polach_reference``, ``_wilac_reference``, the NumPy FASTSIM
  march, the Python scalar path).

Timings are medians of several repeats (wall clock); the machine may be shared, so compare
ratios within one run rather than absolute figures across runs. Memory: the peak of the
allocations traced by ``tracemalloc`` during one call (NumPy arrays are traced, the outputs of
the compiled kernels included: NumPy allocates them; the kernels' scratch, about 150 KB per
thread whatever the size, is not). After the kernel
figures, every other ``benchmarks/bench_*.py`` script is run as a subprocess and its output
printed.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from functools import partial
from pathlib import Path

import numpy as np
from performance_page import DOCS_PAGE, Run, write_page

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src"


def median_time(func, repeat: int = 5) -> float:
    """Median wall-clock time [s] of ``repeat`` calls of ``func`` (after one warm-up call)."""
    func()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def scalar_latency(func, n: int = 20000, repeat: int = 5) -> float:
    """Median over ``repeat`` rounds of the mean time [s] of one call in a loop of ``n``."""
    for _ in range(200):
        func()
    rounds = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(n):
            func()
        rounds.append((time.perf_counter() - t0) / n)
    return statistics.median(rounds)


def traced_peak(func) -> int:
    """Peak bytes allocated (traced by tracemalloc) during one call of ``func``."""
    tracemalloc.start()
    try:
        func()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def plain_numpy_polach(sx, sy, psi, q, v, a, b, c11, c22, c23, mu0, k_a, k_s, big_a, big_b,
                       g=8.2e10):  # fmt: skip
    """Straightforward NumPy Polach (Polach 2005, section 2; spin as Polach 1999) in Kalker's
    signs, without input checks, caps or guards: the baseline a user would write."""
    syc = np.where(np.abs(sy + psi * a) > np.abs(sy), sy + psi * a, sy)
    sc = np.sqrt(sx * sx + syc * syc)
    s = np.sqrt(sx * sx + sy * sy)
    cjj = np.sqrt((c11 * sx) ** 2 + (c22 * sy) ** 2) / s
    mu = mu0 * ((1 - big_a) * np.exp(-big_b * sc * v) + big_a)
    eps = np.pi / 4 * g * a * b * cjj * sc / (q * mu)
    x = k_a * eps
    f = 2 / np.pi * q * mu * (x / (1 + x * x) + np.arctan(k_s * eps)) / sc
    k_psi = 1 + 6.3 * (1 - np.exp(-a / b))
    gc3 = g * a * b * np.sqrt(a * b) * c23
    eps_psi = 8 / 3 * gc3 / a * np.abs(syc) / (k_psi * q * mu)
    e2 = 1 + eps_psi * eps_psi
    fys = gc3 * psi / sc * np.abs(syc) / (e2 * e2)
    return -f * sx, -(f * sy + fys)


def plain_with_kalker(contact, coef, pars):
    """:func:`plain_numpy_polach` with Kalker's coefficients given (``coef``) or, if ``None``,
    looked up per contact (varying a/b)."""
    from railadhesion.contact.kalker import kalker_coefficients

    sx, sy, psi, q, v, a, b = contact
    if coef is None:
        coef = kalker_coefficients(a / b, 0.28)
    return plain_numpy_polach(sx, sy, psi, q, v, a, b, coef.c11, coef.c22, coef.c23, *pars)


class Table:
    """Rows of (what, ours, baseline, ratio, note) printed as aligned text."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, str, str, str, str]] = []

    def add(self, label, ours, base="", ratio="", note=""):
        self.rows.append((label, ours, base, ratio, note))
        print(f"  {label}: {ours}" + (f"  | baseline {base}  | {ratio}" if base else "")
              + (f"  ({note})" if note else ""), flush=True)  # fmt: skip

    def show(self) -> None:
        head = ("figure", "railadhesion", "baseline", "ratio", "note")
        widths = [max(len(r[i]) for r in [head, *self.rows]) for i in range(5)]
        print()
        for row in [head, tuple("-" * w for w in widths), *self.rows]:
            print("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())


def rate(n, t):
    return f"{n / t / 1e6:.2f} M/s"


def micro(t):
    return f"{t * 1e6:.2f} µs"


def compile_times() -> tuple[float, float, float, float, float]:
    """(import time, cold first-call time, cached first-call time, cold and cached first call
    of the parallel kernels) [s], in fresh processes; the cold ones with an empty numba cache
    directory. The first calls are small (serial kernels) and scalar; the parallel kernels
    (10^5 contacts and more) compile on their first call."""
    code = (
        "import time; t0 = time.perf_counter(); import railadhesion as ra;"
        "t1 = time.perf_counter();"
        "import numpy as np; x = np.linspace(-0.1, 0.1, 16);"
        "ra.polach_forces(x, 0.0, 0.1, 1e5, 10.0, 6e-3, 5e-3, mu0=0.3);"
        "ra.polach_forces(0.01, 0.0, 0.1, 1e5, 10.0, 6e-3, 5e-3, mu0=0.3);"
        "ra.wilac_forces(x, 0.0, 0.0, 4.2e3, 5.0, 3e-3, 4e-3, 25.0,"
        "                ra.default_wilac_parameters());"
        "ra.fastsim(0.001, 0.0, 0.0, 8e4, 6e-3, 5e-3, 0.3);"
        "t2 = time.perf_counter(); x = np.linspace(-0.1, 0.1, 200_000);"
        "ra.polach_forces(x, 0.0, 0.1, 1e5, 10.0, 6e-3, 5e-3, mu0=0.3);"
        "ra.wilac_forces(x, 0.0, 0.0, 4.2e3, 5.0, 3e-3, 4e-3, 25.0,"
        "                ra.default_wilac_parameters());"
        "ra.fastsim(np.full(1000, 1e-3), 0.0, 0.0, 8e4, 6e-3, 5e-3, 0.3);"
        "t3 = time.perf_counter(); print(t1 - t0, t2 - t1, t3 - t2)"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC))
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        cold = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, check=True).stdout.split()  # fmt: skip
        warm = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, check=True).stdout.split()  # fmt: skip
    return float(warm[0]), float(cold[1]), float(warm[1]), float(cold[2]), float(warm[2])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (CI smoke run)")
    parser.add_argument("--kernels-only", action="store_true",
                        help="only these kernel benchmarks, not the other bench_*.py scripts")
    parser.add_argument("--no-big", action="store_true", help="skip the 10^7-contact cases")
    parser.add_argument("--write-docs", nargs="?", type=Path, const=DOCS_PAGE, default=None,
                        metavar="PAGE", help=f"write the figures to PAGE (default {DOCS_PAGE})")
    args = parser.parse_args(argv)
    run = Run(command="benchmarks/run.py " + " ".join(argv if argv is not None else
                                                      sys.argv[1:]))
    sys.path.insert(0, str(SRC))

    import numba

    from railadhesion.contact.fastsim import fastsim
    from railadhesion.contact.kalker import kalker_coefficients
    from railadhesion.models import kernels
    from railadhesion.models.parameters import polach_parameters
    from railadhesion.models.polach import (
        PolachContact,
        _polach_reference,
        _polach_scalar,
        polach_forces,
    )
    from railadhesion.models.wilac import _wilac_reference, default_wilac_parameters, wilac_forces

    print(f"railadhesion kernel benchmarks on {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} CPUs, Python {platform.python_version()}, NumPy {np.__version__}, "
          f"numba {numba.__version__}; load average {os.getloadavg()[0]:.1f} at start")  # fmt: skip
    threads = numba.get_num_threads()
    run.versions = {"Python": platform.python_version(), "NumPy": np.__version__,
                    "numba": numba.__version__, "threads": str(threads)}
    table = Table()
    imp, cold, warm, cold_par, warm_par = compile_times()
    table.add("import railadhesion", f"{imp * 1e3:.0f} ms", note="numba not imported")
    table.add("first kernel calls, cold cache", f"{cold:.1f} s",
              note="compiles Polach, WILAC, FASTSIM; once per installation")  # fmt: skip
    table.add("first kernel calls, cached", f"{warm:.2f} s", note="numba import + cache load")
    table.add("first call of the parallel kernels, cold cache", f"{cold_par:.1f} s",
              note=f"10^5 contacts and more; cached: {warm_par:.2f} s")  # fmt: skip

    dry = polach_parameters("polach2005_dry").as_dict()
    pars = (dry["mu0"], dry["k_A"], dry["k_S"], dry["A"], dry["B"])
    sizes = [10_000] if args.quick else [1_000_000] + ([] if args.no_big else [10_000_000])
    rng = np.random.default_rng(0)
    for n in sizes:
        xi = rng.uniform(-0.3, 0.3, n)
        eta = rng.uniform(-0.01, 0.01, n)
        phi = rng.uniform(-2.0, 2.0, n)
        q = rng.uniform(20e3, 120e3, n)
        v = rng.uniform(1.0, 40.0, n)
        scale = rng.uniform(0.8, 1.25, n)
        a_c, b_c = 6e-3 * scale, 5e-3 * scale  # array a, b with constant a/b
        a_v, b_v = rng.uniform(3e-3, 8e-3, n), rng.uniform(3e-3, 8e-3, n)
        tag = f"10^{round(np.log10(n))}"
        c_const = kalker_coefficients(1.2, 0.28)
        cases = (("spin, array a, b (a/b constant)", a_c, b_c, phi, c_const),
                 ("spin, a/b varying per contact", a_v, b_v, phi, None),
                 ("no spin, array a, b (a/b constant)", a_c, b_c, 0.0, c_const))  # fmt: skip
        for label, aa, bb, sp, coef in cases:
            contact = (xi, eta, sp, q, v, aa, bb)
            ours = partial(polach_forces, *contact, **dry)
            plain = partial(plain_with_kalker, contact, coef, pars)
            t_ours = median_time(ours)
            t_plain = median_time(plain)
            numba.set_num_threads(1)
            t_one = median_time(ours)
            numba.set_num_threads(threads)
            mem = traced_peak(ours)
            mem_plain = traced_peak(plain)
            table.add(f"Polach {tag}, {label}", rate(n, t_ours), f"plain NumPy {rate(n, t_plain)}",
                      f"{t_plain / t_ours:.1f}x",
                      f"{threads} threads; 1 thread {rate(n, t_one)}; memory "
                      f"{mem / n:.0f} vs {mem_plain / n:.0f} B/contact")  # fmt: skip
            if n <= 1_000_000 and coef is None:
                arrays = [np.asarray(x, float) for x in (*contact, *pars, 8.2e10, 0.28)]
                t_ref = median_time(partial(_polach_reference, *arrays), 3)
                table.add(f"Polach {tag}, {label}", rate(n, t_ours),
                          f"NumPy reference {rate(n, t_ref)}", f"{t_ref / t_ours:.1f}x")

        params = default_wilac_parameters()
        w = rng.uniform(0.0, 100.0, n)
        contact = (xi, eta, phi, q, v, a_v, b_v, w, params)
        wilac = partial(wilac_forces, *contact)
        t_w = median_time(wilac, 3)
        numba.set_num_threads(1)
        t_w1 = median_time(wilac, 3)
        numba.set_num_threads(threads)
        mem = traced_peak(wilac) / n
        note = f"{threads} threads; 1 thread {rate(n, t_w1)}; memory {mem:.0f} B/contact"
        label = f"WILAC {tag}, array w 0-100 µl/s, spin, a/b varying"
        if n <= 1_000_000:
            t_wref = median_time(partial(_wilac_reference, *contact), 3)
            table.add(label, rate(n, t_w), f"NumPy reference {rate(n, t_wref)}",
                      f"{t_wref / t_w:.1f}x", note)  # fmt: skip
        else:
            table.add(label, rate(n, t_w), note=note)

    # scalar paths
    contact = PolachContact(100e3, 20.0, 6e-3, 5e-3, **dry)
    t_ref = scalar_latency(lambda: _polach_scalar(0.01, 0.001, 0.1, 100e3, 20.0, 6e-3, 5e-3,
                                                  *pars, 8.2e10, 0.28))  # fmt: skip
    t_empty = scalar_latency(lambda: None)
    t = scalar_latency(lambda: contact.forces(0.01, 0.001, 0.1))
    table.add("Polach, one call, PolachContact.forces (spin)", micro(t),
              f"Python reference {micro(t_ref)}", f"{t_ref / t:.1f}x",
              f"an empty Python call here: {micro(t_empty)}")  # fmt: skip
    t = scalar_latency(lambda: contact.forces(0.01))
    table.add("Polach, one call, PolachContact.forces (no spin)", micro(t))
    t = scalar_latency(lambda: contact.forces(0.01, 0.001, 0.1, speed=15.0))
    table.add("Polach, one call, PolachContact.forces (spin, new speed)", micro(t))
    t = scalar_latency(lambda: polach_forces(0.01, 0.001, 0.1, 100e3, 20.0, 6e-3, 5e-3, **dry))
    table.add("Polach, one call, polach_forces with Python floats", micro(t),
              f"Python reference {micro(t_ref)}", f"{t_ref / t:.1f}x")  # fmt: skip
    c11, c22, c23, _ = kernels.kalker_scalar(1.2, 0.28)
    kp = (dry["k_A"], dry["k_S"], dry["mu0"], dry["A"], dry["B"])
    t = scalar_latency(lambda: kernels.polach_scalar(0.01, 0.001, 0.1, 100e3, 20.0, 6e-3, 5e-3,
                                                     8.2e10, 0.28, c11, c22, c23, *kp))  # fmt: skip
    table.add("Polach, one call of kernels.polach_scalar from Python", micro(t),
              note="numba dispatch; from @njit code it is inlined")  # fmt: skip
    shapes = iter(np.tile(rng.uniform(3e-3, 8e-3, 4096), 64).tolist())
    t = scalar_latency(lambda: polach_forces(0.01, 0.001, 0.1, 100e3, 20.0, next(shapes), 5e-3,
                                             **dry), n=100_000, repeat=2)  # fmt: skip
    table.add("Polach, one call, new a/b every call", micro(t))

    params = default_wilac_parameters()
    packed = kernels.pack_wilac(params)
    from railadhesion.models.wilac import _wilac_scalar

    t_ref = scalar_latency(lambda: _wilac_scalar(0.01, 0.0, 0.1, 100e3, 20.0, 6e-3, 5e-3, 25.0,
                                                 params, 8.2e10, 0.28), 5000)  # fmt: skip
    t = scalar_latency(lambda: wilac_forces(0.01, 0.0, 0.1, 100e3, 20.0, 6e-3, 5e-3, 25.0,
                                            params), 5000)  # fmt: skip
    table.add("WILAC, one call, wilac_forces, w = 25 µl/s", micro(t),
              f"Python reference {micro(t_ref)}", f"{t_ref / t:.1f}x")  # fmt: skip
    t = scalar_latency(lambda: kernels.wilac_scalar(0.01, 0.0, 0.1, 100e3, 20.0, 6e-3, 5e-3,
                                                    25.0, 8.2e10, 0.28, c11, c22, c23, packed))
    table.add("WILAC, one call of kernels.wilac_scalar from Python", micro(t),
              note="numba dispatch")  # fmt: skip

    # FASTSIM
    m = 500 if args.quick else 5000
    fs = (xi[:m] * 0.01, eta[:m] * 0.3, phi[:m], q[:m], a_v[:m], b_v[:m], 0.3)
    for grid in (20, 40):
        t = median_time(lambda grid=grid: fastsim(*fs, nx=grid, ny=grid), 3)
        t_ref = median_time(lambda grid=grid: fastsim(*fs, nx=grid, ny=grid,
                                                      return_tractions=True), 3)  # fmt: skip
        table.add(f"FASTSIM {grid}x{grid}, batched ({m} contacts), per contact", micro(t / m),
                  f"NumPy march {micro(t_ref / m)}", f"{t_ref / t:.1f}x",
                  f"{threads} threads; the NumPy march also stores the tractions")  # fmt: skip
        t = scalar_latency(lambda grid=grid: fastsim(0.001, 0.0, 0.0, 80e3, 6e-3, 5e-3, 0.3,
                                                     nx=grid, ny=grid), 2000)  # fmt: skip
        t_ref = scalar_latency(lambda grid=grid: fastsim(0.001, 0.0, 0.0, 80e3, 6e-3, 5e-3, 0.3,
                                                         nx=grid, ny=grid,
                                                         return_tractions=True), 200)  # fmt: skip
        table.add(f"FASTSIM {grid}x{grid}, one contact", micro(t), f"NumPy march {micro(t_ref)}",
                  f"{t_ref / t:.1f}x")  # fmt: skip
    from railadhesion.contact.hertz import hertz_3d

    mh = m * 20
    t = median_time(lambda: hertz_3d(q[:mh], 0.46, np.inf, rng.uniform(0.2, 0.6, mh)), 3)
    table.add(f"Hertz 3D (exact elliptic integrals), {mh} contacts", rate(mh, t),
              note="NumPy/SciPy, no kernel")  # fmt: skip
    t = scalar_latency(lambda: kalker_coefficients(0.7, 0.28))
    table.add("Kalker coefficients, one call", micro(t))
    table.add("threads used by the parallel kernels", str(threads),
              note="numba.get_num_threads(): Polach, WILAC in a pool of Python threads; "
                   f"FASTSIM numba's threading layer {numba.threading_layer()}")  # fmt: skip
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end")
    table.show()

    if not args.kernels_only:
        others = sorted(HERE.glob("bench_*.py"))
        for script in others:
            print(f"\n=== {script.name} ===", flush=True)
            cmd = [sys.executable, str(script)] + (["--quick"] if args.quick else [])
            env = dict(os.environ, PYTHONPATH=str(SRC))
            proc = subprocess.run(cmd, env=env, text=True, capture_output=True)
            if proc.returncode != 0 and args.quick and "--quick" in proc.stderr:
                proc = subprocess.run(cmd[:2], env=env, text=True, capture_output=True)
            print(proc.stdout, end="")
            if proc.returncode != 0:
                print(f"{script.name} failed (exit {proc.returncode}):\n{proc.stderr}")
            run.scripts.append((script.name, proc.stdout, proc.returncode))
    if args.write_docs is not None:
        run.rows = table.rows
        run.load_end = os.getloadavg()
        print(f"\nwritten: {write_page(run, args.write_docs)}")


if __name__ == "__main__":
    main()
