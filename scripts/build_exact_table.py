"""Build the table of the fast exact model (``railadhesion/data/exact_table.npz``).

Usage::

    PYTHONPATH=src python3 scripts/build_exact_table.py [--grid 24] [--out PATH] [--jobs 2]

Solves Kalker's exact theory (:func:`railadhesion.contact.exact.exact_rolling`, nu = 0.28)
at every node of :func:`railadhesion.contact.table.table_axes` in normalised form (Fz, mu, G
and c chosen so that tau = mu p0/G = 1e-3 and c = 1 cm; the results depend only on the
normalised creepages), on the build grid :func:`railadhesion.contact.table.build_grid` of
each a/b (``--grid`` n: n x n up to a/b = 1, up to 2n x n/2 for long contacts). The
Kalker-scaled node creepages are converted with the linear coefficients of the build grid
itself (solved first, stored as ``cgrid``). The 6,699 cases of a row are solved to the
tolerance ``TOL`` by ``exact_rolling``'s ``method="auto"``: on the default grids (576
elements), by semismooth Newton, together (dense products; docs/exact-solver.md); on grids of
``--grid`` 33 to 39, by Gauss-Seidel warm-started along the row; from 40 x 40, by Newton case
by case. ``--jobs 2`` solves two a/b rows at a time, each process on one core (its BLAS
limited to one thread). Runtime with ``--jobs 2`` on a
two-core Intel Xeon at 2.5 GHz (2026-11-28, load average 0.9-1.2): 96-103 s at the default
``--grid 24``; by Gauss-Seidel, warm-started along the rows, it was 347 s. The two builds'
node values agree within 2.5e-5 mu Fz.
"""

from __future__ import annotations

import os

# one core per process (``--jobs`` processes): set before NumPy loads its BLAS, hence the
# imports below this (ruff: E402 allowed in this file)
# ruff: noqa: E402
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import math
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.contact.kalker import kalker_coefficients
from railadhesion.contact.table import (
    BUILD_N,
    COORDINATES,
    TABLE_POISSON,
    build_grid,
    node_creepages,
    spin_weight,
    table_axes,
)
from railadhesion.plausibility import PlausibilityWarning

G = 8.2e10
MU = 0.3
C = 0.01  # m
TAU = 1e-3
#: The solver's tolerance (exact_rolling's ``tol``, default 1e-6): 1e-4 changes the node
#: values by about 1e-5 mu Fz (measured with Gauss-Seidel on the a/b = 0.3 and 5 rows),
#: against the table's 0.01 mu Fz error.
TOL = 1e-4
DEFAULT_OUT = (
    Path(__file__).resolve().parents[1] / "src" / "railadhesion" / "data" / "exact_table.npz"
)


def solve_row(ratio: float, n: int):
    """The table's nodes at one a/b: (outputs (3, t, theta, u), the grid's coefficients,
    the grid (nx, ny))."""
    _, tmag, theta, uspin = table_axes()
    T, TH, U = np.meshgrid(tmag, theta, uspin, indexing="ij")
    xs, ys, ss = node_creepages(T, TH, U, spin_weight(ratio))
    nx, ny = build_grid(ratio, n)
    a = C * math.sqrt(ratio)
    b = C / math.sqrt(ratio)
    fz = TAU * G / MU * 2.0 * math.pi * a * b / 3.0  # p0 = 3Fz/(2 pi a b) = tau G / mu
    with warnings.catch_warnings():  # mu = 1000 on purpose: no slip, Kalker's linear limit
        warnings.simplefilter("ignore", PlausibilityWarning)
        lin = exact_rolling(
            [1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-4], fz, a, b, 1e3,
            shear_modulus=G, poisson=TABLE_POISSON, nx=nx, ny=ny,
        )  # fmt: skip
    cg = (
        -lin.fx[0] / (G * C * C * 1e-6),
        -lin.fy[1] / (G * C * C * 1e-6),
        -lin.fy[2] / (G * C**3 * 1e-4),
    )
    # Kalker-scaled (X, Y, S) -> creepages with the grid's own coefficients
    f = 2.0 * math.pi / 3.0 * TAU
    with warnings.catch_warnings():  # normalised creepages out to "infinity", on purpose
        warnings.simplefilter("ignore", PlausibilityWarning)
        r = exact_rolling(
            xs * f / cg[0], ys * f / cg[1], ss * f / (cg[2] * C), fz, a, b, MU,
            shear_modulus=G, poisson=TABLE_POISSON, nx=nx, ny=ny, tol=TOL, warm_start=True,
        )  # fmt: skip
    values = np.stack([r.fx / (MU * fz), r.fy / (MU * fz), r.mz / (MU * fz * C)])
    return values, np.array(cg), (nx, ny)


def symmetrize(values):
    """Impose the theory's symmetries on the node values (3, a/b, t, theta, u) of (Fx, Fy, Mz),
    exact where the solver (to its tolerance) is not: on the plane eta = 0 (theta = 0) the
    mirror (eta, phi) -> -(eta, phi) maps u to -u with Fx even, Fy and Mz odd; on xi = 0
    (theta = pi/2) Fx = 0 (mirror and point symmetry together); pure spin (u = +-1, every
    theta the same point) is one value per t, odd in the spin, with Fx = 0."""
    v = values.copy()
    spin = 0.5 * (v[..., -1].mean(axis=3) - v[..., 0].mean(axis=3))  # (3, a/b, t)
    spin[0] = 0.0
    v[..., -1] = spin[..., None]
    v[..., 0] = -spin[..., None]
    rev = v[:, :, :, 0, ::-1]
    v[0, :, :, 0] = 0.5 * (v[0, :, :, 0] + rev[0])
    v[1:, :, :, 0] = 0.5 * (v[1:, :, :, 0] - rev[1:])
    v[0, :, :, -1] = 0.0
    return v


def _count(low):
    """argparse type: an integer >= low (the option is named in argparse's error)."""

    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be an integer >= {low}, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {value}")
        return value

    return parse


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--grid", type=_count(4), default=BUILD_N,
        help=f"elements per axis of the build grid up to a/b = 1 (default {BUILD_N})")  # fmt: skip
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--jobs", type=_count(1), default=1,
                    help="processes, one a/b row each at a time (default 1)")  # fmt: skip
    args = ap.parse_args(argv)
    n = args.grid
    aob, tmag, theta, uspin = table_axes()
    values = np.zeros((3, aob.size, tmag.size, theta.size, uspin.size))
    cgrid = np.zeros((aob.size, 3))
    grids = np.zeros((aob.size, 2), dtype=np.int64)
    t0 = time.perf_counter()
    # the longest contacts (slowest rows) first, so that two processes finish together
    order = np.argsort(-aob)
    pool = ProcessPoolExecutor(args.jobs) if args.jobs > 1 else None
    rows = (pool.map(solve_row, aob[order], [n] * aob.size) if pool else
            (solve_row(aob[i], n) for i in order))  # fmt: skip
    for ia, (row, cg, grid) in zip(order, rows, strict=True):
        values[:, ia] = row
        cgrid[ia] = cg
        grids[ia] = grid
        k = kalker_coefficients(aob[ia], TABLE_POISSON)
        print(f"a/b = {aob[ia]:.3f}: {row[0].size} cases on {grid[0]} x {grid[1]}, "
              f"grid/Kalker = {np.round(cg / (k.c11, k.c22, k.c23), 4)}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)  # fmt: skip
    if pool:
        pool.shutdown()
    print(f"symmetries imposed: largest change {np.abs(symmetrize(values) - values).max():.1e}")
    values = symmetrize(values)
    np.savez_compressed(
        args.out, values=values.astype(np.float32), aob=aob, tmag=tmag, theta=theta,
        uspin=uspin, cgrid=cgrid, grids=grids, coordinates=np.array(COORDINATES),
        grid=np.array([n, n]), poisson=np.array(TABLE_POISSON),
    )  # fmt: skip
    print(f"wrote {args.out} in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
