"""The adhesion surface mu(speed, slip) of seed 002 §5: mean and variance per grid cell.

Allotta, Malvezzi and Toni collect the mu samples of every axle on a 40 x 40 grid, speed
0-40 m/s (1 m/s cells) by absolute slip 0-10 m/s (0.25 m/s cells), and display the mean and
the variance of each cell; sections of that surface give mu against slip at fixed speed and
against speed at fixed slip. :func:`adhesion_surface` builds it as an :class:`xarray.Dataset`
(dimensions ``phase``, ``speed``, ``slip``; the grid is configurable and a relative-slip
surface is available), :func:`save_surface` writes NetCDF.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from railadhesion._validate import check_choice

__all__ = ["adhesion_surface", "surface_section", "save_surface", "PHASES"]

#: Phases of the surface: all usable samples, loss-of-adhesion windows, recovery windows.
PHASES = ("all", "loss", "recovery")


def _edges(edges, name):
    e = np.asarray(edges, dtype=float).reshape(-1)
    if e.size < 2 or not np.all(np.isfinite(e)) or np.any(np.diff(e) <= 0):
        raise ValueError(f"{name} must be at least 2 finite, strictly increasing values")
    return e


@njit(cache=True, nogil=True)
def cell_index(x, edges):  # pragma: no cover - compiled
    """Cell of x for increasing edges (-1 outside; the last edge belongs to the last cell):
    ``searchsorted(edges, x, "right") - 1``, found from the cell a uniform grid would give and
    corrected against the edges (exact for any increasing edges)."""
    m = edges.size - 1
    if not (x >= edges[0] and x <= edges[m]):  # also False for NaN
        return -1
    k = int((x - edges[0]) / (edges[m] - edges[0]) * m)
    k = min(max(k, 0), m - 1)
    while k > 0 and edges[k] > x:
        k -= 1
    while k < m - 1 and edges[k + 1] <= x:
        k += 1
    return k


@njit(cache=True, nogil=True)
def _accumulate(speed, slip, mu, use, phase, se, le, cells):  # pragma: no cover - compiled
    """Counts, sums and sums of squared deviations of mu per (phase, speed, slip) cell.

    Phase 0 = all usable samples, 1 = loss windows (phase +1), 2 = recovery (phase -1).
    Two passes: the sums give the means, the second pass the squared deviations from them
    (numerically safe); ``cells`` (integers, shape of ``mu``) keeps each sample's cell
    between the passes.
    """
    n, na = mu.shape
    ns, nl = se.size - 1, le.size - 1
    counts = np.zeros((3, ns, nl), np.int64)
    sums = np.zeros((3, ns, nl))
    sq = np.zeros((3, ns, nl))
    for k in range(n):
        i = cell_index(speed[k], se)
        for a in range(na):
            cells[k, a] = -1
        if i < 0:
            continue
        for a in range(na):
            if not use[k, a]:
                continue
            j = cell_index(slip[k, a], le)
            if j < 0:
                continue
            cells[k, a] = i * nl + j
            counts[0, i, j] += 1
            sums[0, i, j] += mu[k, a]
            p = phase[k, a]
            if p != 0:
                q = 1 if p > 0 else 2
                counts[q, i, j] += 1
                sums[q, i, j] += mu[k, a]
    for k in range(n):
        for a in range(na):
            c = cells[k, a]
            if c < 0:
                continue
            i = c // nl
            j = c - i * nl
            d = mu[k, a] - sums[0, i, j] / counts[0, i, j]
            sq[0, i, j] += d * d
            p = phase[k, a]
            if p != 0:
                q = 1 if p > 0 else 2
                d = mu[k, a] - sums[q, i, j] / counts[q, i, j]
                sq[q, i, j] += d * d
    return counts, sums, sq


def adhesion_surface(ident, *, speed_edges=None, slip_edges=None, slip: str = "absolute"):
    """Mean, variance and count of mu per (speed, slip) cell, per phase (seed 002 §5).

    Parameters
    ----------
    ident : BrakingIdentification
        From :func:`~railadhesion.identification.brake_tests.identify_adhesion`.
    speed_edges : array_like, optional
        Cell edges in speed [m/s]; default 0, 1, ..., 40 (the paper's 40 cells).
    slip_edges : array_like, optional
        Cell edges in slip; default 0, 0.25, ..., 10 m/s (absolute, the paper's 40 cells) or
        0, 0.025, ..., 1 (relative).
    slip : {"absolute", "relative"}
        Absolute slip v - R omega [m/s] or relative slip (v - R omega)/v [-].

    Returns
    -------
    xarray.Dataset
        Dimensions ``phase`` (``"all"``, ``"loss"``, ``"recovery"``), ``speed``, ``slip``
        (cell centres), coordinates ``speed_lower/upper``, ``slip_lower/upper``; variables
        ``mu_mean`` and ``mu_var`` (sample variance, ddof = 1; NaN with fewer than 2
        samples) [-] and ``count`` (samples per cell, all axles together). Units in attrs.
    """
    import xarray as xr

    check_choice(slip, "slip", ("absolute", "relative"))
    se = _edges(np.linspace(0.0, 40.0, 41) if speed_edges is None else speed_edges,
                "speed_edges")
    if slip_edges is None:
        slip_edges = np.linspace(0.0, 10.0, 41) if slip == "absolute" else np.linspace(0, 1, 41)
    le = _edges(slip_edges, "slip_edges")
    x = ident.slip if slip == "absolute" else ident.relative_slip
    mu = np.asarray(ident.mu, dtype=float)
    n_cells = (se.size - 1) * (le.size - 1)
    cells = np.empty(mu.shape, np.int16 if n_cells < 2**15 else np.int64)
    counts, sums, sq = _accumulate(
        np.asarray(ident.speed, dtype=float), np.asarray(x, dtype=float), mu,
        np.asarray(ident.use, dtype=np.bool_), np.asarray(ident.phase, dtype=np.int8), se, le,
        cells,
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
        vars_ = np.where(counts > 1, sq / np.maximum(counts - 1, 1), np.nan)
    slip_unit = "m/s" if slip == "absolute" else "1"
    slip_name = (
        "absolute slip v - R omega" if slip == "absolute" else "relative slip (v - R omega)/v"
    )
    ds = xr.Dataset(
        data_vars={
            "mu_mean": (("phase", "speed", "slip"), means,
                        {"units": "1", "long_name": "mean adhesion coefficient (eq. 10)"}),
            "mu_var": (("phase", "speed", "slip"), vars_,
                       {"units": "1", "long_name": "variance of the adhesion coefficient"}),
            "count": (("phase", "speed", "slip"), counts,
                      {"units": "1", "long_name": "samples per cell (all axles)"}),
        },
        coords={
            "phase": ("phase", list(PHASES)),
            "speed": ("speed", 0.5 * (se[1:] + se[:-1]),
                      {"units": "m/s", "long_name": "train speed (cell centre)"}),
            "slip": ("slip", 0.5 * (le[1:] + le[:-1]),
                     {"units": slip_unit, "long_name": slip_name + " (cell centre)"}),
            "speed_lower": ("speed", se[:-1], {"units": "m/s"}),
            "speed_upper": ("speed", se[1:], {"units": "m/s"}),
            "slip_lower": ("slip", le[:-1], {"units": slip_unit}),
            "slip_upper": ("slip", le[1:], {"units": slip_unit}),
        },
        attrs={
            "title": "Adhesion surface from a braking-test log",
            "source": "Allotta, Malvezzi, Toni, Adhesion models for wheel/rail contact in "
                      "railways, section 5 (grid 40 x 40, speed 0-40 m/s, slip 0-10 m/s)",
            "slip_kind": slip,
            "log": str(ident.settings.get("log", "")),
            "vehicle": str(ident.settings.get("vehicle", "")),
            "brake_coefficient_N_m_per_Pa": float(ident.brake_coefficient),
            "filter_mode": str(ident.settings.get("filter_mode", "")),
            "phase_meaning": "all: every usable sample; loss: windows of growing slip; "
                             "recovery: windows of falling slip",
        },
    )
    return ds


def surface_section(ds, *, speed=None, slip=None, phase: str = "all"):
    """A section of the surface: mu against slip at one speed, or against speed at one slip.

    Give exactly one of ``speed`` [m/s] or ``slip`` (the nearest cell is taken). Returns a
    Dataset with ``mu_mean``, ``mu_var``, ``count`` along the other dimension.
    """
    if (speed is None) == (slip is None):
        raise ValueError("give exactly one of speed or slip")
    check_choice(phase, "phase", PHASES)
    sub = ds.sel(phase=phase)
    if speed is not None:
        return sub.sel(speed=float(speed), method="nearest")
    return sub.sel(slip=float(slip), method="nearest")


def save_surface(ds, path) -> None:
    """Write the surface as NetCDF (netCDF4 engine; string coordinates as variable strings)."""
    ds.to_netcdf(path, engine="netcdf4")
