"""Build the table of the fast exact model (``railadhesion/data/exact_table.npz``).

Usage::

    PYTHONPATH=src python3 scripts/build_exact_table.py [--grid 20] [--out PATH]

Solves Kalker's exact theory (:func:`railadhesion.contact.exact.exact_rolling`, nu = 0.28)
at every node of :func:`railadhesion.contact.table.table_axes` in normalised form (Fz, mu, G
and c chosen so that tau = mu p0/G = 1e-3 and c = 1 cm; the results depend only on the
normalised creepages). The Kalker-scaled node creepages are converted with the linear
coefficients of the build grid itself (solved first, stored as ``cgrid``). Runtime: about
3.6 minutes on one core of the project machine (about 60 000 cases; 215 s CPU, compilation
included, issue 22), 7 minutes before the solver's influence sums were done by FFT.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.contact.kalker import kalker_coefficients
from railadhesion.contact.table import TABLE_POISSON, node_creepages, table_axes

G = 8.2e10
MU = 0.3
C = 0.01  # m
TAU = 1e-3
DEFAULT_OUT = (
    Path(__file__).resolve().parents[1] / "src" / "railadhesion" / "data" / "exact_table.npz"
)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--grid", type=int, default=20, help="elements per semi-axis pair (n x n)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    n = args.grid
    aob, tmag, theta, uspin = table_axes()
    values = np.zeros((3, aob.size, tmag.size, theta.size, uspin.size))
    cgrid = np.zeros((aob.size, 3))
    T, TH, U = np.meshgrid(tmag, theta, uspin, indexing="ij")
    xs, ys, ss = node_creepages(T, TH, U)
    t0 = time.perf_counter()
    for ia, ratio in enumerate(aob):
        a = C * math.sqrt(ratio)
        b = C / math.sqrt(ratio)
        fz = TAU * G / MU * 2.0 * math.pi * a * b / 3.0  # p0 = 3Fz/(2 pi a b) = tau G / mu
        lin = exact_rolling(
            [1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-4], fz, a, b, 1e3,
            shear_modulus=G, poisson=TABLE_POISSON, nx=n, ny=n,
        )  # fmt: skip
        cg = (
            -lin.fx[0] / (G * C * C * 1e-6),
            -lin.fy[1] / (G * C * C * 1e-6),
            -lin.fy[2] / (G * C**3 * 1e-4),
        )
        cgrid[ia] = cg
        # Kalker-scaled (X, Y, S) -> creepages with the grid's own coefficients
        f = 2.0 * math.pi / 3.0 * TAU
        r = exact_rolling(
            xs * f / cg[0], ys * f / cg[1], ss * f / (cg[2] * C), fz, a, b, MU,
            shear_modulus=G, poisson=TABLE_POISSON, nx=n, ny=n, warm_start=True,
        )  # fmt: skip
        values[0, ia] = r.fx / (MU * fz)
        values[1, ia] = r.fy / (MU * fz)
        values[2, ia] = r.mz / (MU * fz * C)
        k = kalker_coefficients(ratio, TABLE_POISSON)
        print(f"a/b = {ratio:.3f}: {r.fx.size} cases, grid/Kalker = "
              f"{np.round(np.array(cg) / (k.c11, k.c22, k.c23), 4)}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)  # fmt: skip
    np.savez_compressed(
        args.out, values=values.astype(np.float32), aob=aob, tmag=tmag, theta=theta,
        uspin=uspin, cgrid=cgrid,
        grid=np.array([n, n]), poisson=np.array(TABLE_POISSON),
    )  # fmt: skip
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
