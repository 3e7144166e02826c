"""Where the table model's error lives: the table against the exact solver on 60 x 60.

Usage::

    PYTHONPATH=src MPLBACKEND=Agg python3 scripts/table_accuracy.py [--jobs 2] [--figure]

Cases: a/b x creep direction x creep magnitude x spin (normalised by tau = mu p0/G and
c = sqrt(ab): xi' = xi/tau, eta' = eta/tau, phi' = phi c/tau), at nu = 0.25, 0.28 and 0.30.
Error: |(dFx, dFy)|/(mu Fz). It is split into

* **interpolation**: the table against the solver on the table's build grid at the creepages
  the table actually interpolates (the creepages scaled with Kalker's coefficients at nu and
  the build grid's own coefficients at the table's nu);
* **build grid**: that solver against the solver on 60 x 60 at the table's nu, creepages
  scaled with Kalker's coefficients at nu over those at the table's nu (discretisation);
* **nu scaling** (nu != the table's only): the latter against the solver at nu on 60 x 60.

The 60 x 60 reference is cached (``--cache``, default in the temporary directory), so that a
rebuilt table is measured again in seconds. ``--figure`` writes the map
``docs/figures/exact_table_error_map.png`` and prints the Markdown tables of the validation
page. Runtime: about 4 minutes on one core without the cache.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import math
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.contact.kalker import kalker_coefficients
from railadhesion.contact.table import TABLE_POISSON, _load, exact_table_forces
from railadhesion.plausibility import PlausibilityWarning

ROOT = Path(__file__).resolve().parents[1]
G, MU, FZ, C = 8.2e10, 0.3, 1e5, 6e-3
AOB = (0.2, 0.3, 0.5, 1.0, 2.0, 3.3, 5.0)
DIRECTIONS = (0.0, 30.0, 60.0, 90.0)  # degrees, of (xi', eta')
MAGNITUDES = (0.1, 0.3, 1.0, 3.0)  # |(xi', eta')|
SPINS = (-3.0, -1.0, -0.3, 0.0, 0.3, 1.0, 3.0)  # phi'
POISSONS = (0.25, 0.28, 0.30)
REF_GRID = 60


def cases():
    """(a/b, direction, magnitude, spin'), a, b, xi, eta, phi: one row per case."""
    rows = []
    for aob, th, r, ph in itertools.product(AOB, DIRECTIONS, MAGNITUDES, SPINS):
        a, b = C * math.sqrt(aob), C / math.sqrt(aob)
        tau = MU * 3 * FZ / (2 * math.pi * a * b) / G
        t = math.radians(th)
        rows.append((aob, th, r, ph, a, b, r * math.cos(t) * tau, r * math.sin(t) * tau,
                     ph * tau / C))  # fmt: skip
    return np.array(rows)


def _solve(args):
    xi, eta, phi, a, b, nu, grid = args
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        r = exact_rolling(xi, eta, phi, FZ, a, b, MU, shear_modulus=G, poisson=nu,
                          nx=grid, ny=grid)  # fmt: skip
    return np.stack([r.fx, r.fy])


def solve(xi, eta, phi, a, b, nu, grid, jobs=1):
    """(2, n) forces of the solver, in ``jobs`` processes."""
    if jobs <= 1:
        return _solve((xi, eta, phi, a, b, nu, grid))
    parts = np.array_split(np.arange(xi.size), 4 * jobs)
    with ProcessPoolExecutor(jobs) as pool:
        out = list(pool.map(_solve, [(xi[p], eta[p], phi[p], a[p], b[p], nu, grid)
                                     for p in parts]))  # fmt: skip
    return np.concatenate(out, axis=1)


def grid_coefficients(aob, nu, grid):
    """The solver's own linear coefficients (C11, C22, C23) on ``grid`` at each a/b: (3, n)."""
    out = np.empty((3, len(aob)))
    for i, q in enumerate(aob):
        a, b = C * math.sqrt(q), C / math.sqrt(q)
        lin = exact_rolling([1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-4], FZ, a, b, 1e3,
                            shear_modulus=G, poisson=nu, nx=grid, ny=grid)  # fmt: skip
        out[:, i] = (-lin.fx[0] / (G * C * C * 1e-6), -lin.fy[1] / (G * C * C * 1e-6),
                     -lin.fy[2] / (G * C**3 * 1e-4))  # fmt: skip
    return out


def reference(cs, nu, cache: Path, jobs):
    """Solver at 60 x 60 at nu; and at the table's nu with the creepages scaled by Kalker's
    coefficients at nu over those at the table's nu (the same when nu is the table's)."""
    key = hashlib.sha1(cs.tobytes() + repr((nu, REF_GRID, TABLE_POISSON)).encode()).hexdigest()
    path = cache / f"table_accuracy_{key[:16]}.npz"
    if path.exists():
        z = np.load(path)
        return z["ref"], z["scaled"]
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    ref = solve(xi, eta, phi, a, b, nu, REF_GRID, jobs)
    if nu == TABLE_POISSON:
        scaled = ref
    else:
        kn, k0 = kalker_coefficients(aob, nu), kalker_coefficients(aob, TABLE_POISSON)
        sx, sy, ss = kn.c11 / k0.c11, kn.c22 / k0.c22, kn.c23 / k0.c23
        scaled = solve(xi * sx, eta * sy, phi * ss, a, b, TABLE_POISSON, REF_GRID, jobs)
    np.savez(path, ref=ref, scaled=scaled)
    return ref, scaled


def build_grid_solution(cs, nu, d):
    """The solver on the table's build grid at the table's nu, at the creepages the table
    interpolates: creepages scaled by Kalker's coefficient at nu over the build grid's own."""
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    n = int(d["grid"][0])
    uq = np.unique(aob)
    cg = grid_coefficients(uq, float(d["poisson"]), n)
    kn = kalker_coefficients(uq, nu)
    s = [np.interp(aob, uq, k / cg[j]) for j, k in enumerate((kn.c11, kn.c22, kn.c23))]
    return _solve((xi * s[0], eta * s[1], phi * s[2], a, b, float(d["poisson"]), n))


def error(f, g):
    return np.hypot(f[0] - g[0], f[1] - g[1]) / (MU * FZ)


def measure(jobs=1, cache=None, split=True):
    """Errors per nu: dict nu -> dict(total, interp, grid, nuscale) of arrays over cases."""
    cache = Path(cache or tempfile.gettempdir())
    cs = cases()
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    d = _load()
    out = {}
    for nu in POISSONS:
        ref, scaled = reference(cs, nu, cache, jobs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlausibilityWarning)
            tab = np.stack(exact_table_forces(xi, eta, phi, FZ, a, b, MU, shear_modulus=G,
                                              poisson=nu)[:2])  # fmt: skip
        e = {"total": error(tab, ref)}
        if split:
            bg = build_grid_solution(cs, nu, d)
            e["interp"] = error(tab, bg)
            e["grid"] = error(bg, scaled)
            e["nuscale"] = error(scaled, ref)
        out[nu] = e
    return cs, out


def _stats(x):
    return f"{np.median(x):.4f} / {np.percentile(x, 95):.4f} / {x.max():.4f}"


def report(cs, errs):
    aob, th, r, ph = cs.T[:4]
    print(f"{len(cs)} cases per nu; errors in mu Fz: median / 95 % / max")
    for nu, e in errs.items():
        print(f"nu = {nu}:")
        for k, v in e.items():
            i = int(np.argmax(v))
            print(f"  {k:8s} {_stats(v)}   worst: a/b {aob[i]}, dir {th[i]:.0f}, "
                  f"|creep'| {r[i]}, spin' {ph[i]}")
    for nu, e in errs.items():
        print(f"nu = {nu}: max total error by a/b and spin' (rows a/b, columns spin')")
        print("        " + " ".join(f"{s:7.1f}" for s in SPINS))
        for q in AOB:
            row = [e["total"][(aob == q) & (ph == s)].max() for s in SPINS]
            print(f"  {q:5.2f} " + " ".join(f"{v:7.4f}" for v in row))
        print(f"nu = {nu}: max total error by a/b and |creep'| (rows a/b, columns |creep'|)")
        for q in AOB:
            row = [e["total"][(aob == q) & (r == m)].max() for m in MAGNITUDES]
            print(f"  {q:5.2f} " + " ".join(f"{v:7.4f}" for v in row))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--cache", type=Path, default=None)
    ap.add_argument("--no-split", action="store_true", help="the total error only")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    cs, errs = measure(args.jobs, args.cache, not args.no_split)
    report(cs, errs)
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
