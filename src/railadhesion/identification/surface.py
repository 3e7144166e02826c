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

from railadhesion._validate import check_choice

__all__ = ["adhesion_surface", "surface_section", "save_surface", "PHASES"]

#: Phases of the surface: all usable samples, loss-of-adhesion windows, recovery windows.
PHASES = ("all", "loss", "recovery")


def _edges(edges, name):
    e = np.asarray(edges, dtype=float).reshape(-1)
    if e.size < 2 or not np.all(np.isfinite(e)) or np.any(np.diff(e) <= 0):
        raise ValueError(f"{name} must be at least 2 finite, strictly increasing values")
    return e


def _bin(x, edges):
    """Cell index of each x (-1 outside the edges; the last edge belongs to the last cell)."""
    k = np.searchsorted(edges, x, side="right") - 1
    k = np.where(x == edges[-1], edges.size - 2, k)
    return np.where((x >= edges[0]) & (x <= edges[-1]) & np.isfinite(x), k, -1)


def adhesion_surface(ident, *, speed_edges=None, slip_edges=None, slip: str = "absolute"):
    """Mean, variance and count of mu per (speed, slip) cell, per phase (seed 002 §5).

    Parameters
    ----------
    ident : BrakingIdentification
        From :func:`~railadhesion.identification.braking.identify_adhesion`.
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
    ns, nl = se.size - 1, le.size - 1
    means = np.full((3, ns, nl), np.nan)
    vars_ = np.full((3, ns, nl), np.nan)
    counts = np.zeros((3, ns, nl), np.int64)
    for k, phase in enumerate(PHASES):
        v, dv, rel, mu, _ax = ident.samples(phase)
        x = dv if slip == "absolute" else rel
        i = _bin(v, se)
        j = _bin(x, le)
        ok = (i >= 0) & (j >= 0)
        cell = i[ok] * nl + j[ok]
        m = mu[ok]
        cnt = np.bincount(cell, minlength=ns * nl)
        s1 = np.bincount(cell, weights=m, minlength=ns * nl)
        # variance about a provisional centre: numerically safe sums of squares
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = s1 / cnt
            dev = m - mean[cell]
            s2 = np.bincount(cell, weights=dev * dev, minlength=ns * nl)
            var = np.where(cnt > 1, s2 / (cnt - 1), np.nan)
        means[k] = np.where(cnt > 0, mean, np.nan).reshape(ns, nl)
        vars_[k] = var.reshape(ns, nl)
        counts[k] = cnt.reshape(ns, nl)
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
