"""Quantities derived from an adhesion map: maximum adhesion and where, adhesion at a creep,
the water flow rate of minimum adhesion.

All work on a Dataset from :func:`railadhesion.sweeps.run_sweep` (lazy or in memory) and stay
lazy on Dask-backed maps. Points flagged in ``error`` are left out.
"""

from __future__ import annotations

import xarray as xr

__all__ = ["max_adhesion", "adhesion_at_creep", "min_adhesion_water_flow"]


def _adhesion(ds: xr.Dataset, dim: str) -> xr.DataArray:
    if dim not in ds["adhesion"].dims:
        raise ValueError(f"dim: {dim!r} is not a dimension of the map; dimensions: "
                         f"{list(ds['adhesion'].dims)}")  # fmt: skip
    adh = ds["adhesion"]
    if "error" in ds:
        adh = adh.where(ds["error"] == 0)
    return adh


def max_adhesion(ds: xr.Dataset, dim: str = "creep_long") -> xr.Dataset:
    """Maximum adhesion over ``dim`` and the value of ``dim`` where it occurs, per condition.

    Returns a Dataset with ``adhesion_max`` and ``<dim>_at_max`` over the other dimensions
    (the creep of the peak of each creep curve, on the map's grid: refine the grid near the
    peak for more precision). All-failed curves give NaN.
    """
    adh = _adhesion(ds, dim)
    peak = adh.max(dim)
    where = adh.fillna(-1.0).idxmax(dim).where(peak.notnull())
    where.attrs = dict(ds[dim].attrs)
    peak.attrs = {"units": "1", "long_name": f"maximum adhesion over {dim}"}
    return xr.Dataset({"adhesion_max": peak, f"{dim}_at_max": where})


def adhesion_at_creep(ds: xr.Dataset, creep, dim: str = "creep_long") -> xr.DataArray:
    """Adhesion at creepage ``creep`` (scalar or list) [-], linear between grid values.

    Exact at grid values; between them, linear interpolation along ``dim``.
    """
    adh = _adhesion(ds, dim)
    lo, hi = float(ds[dim].min()), float(ds[dim].max())
    values = [creep] if isinstance(creep, int | float) else list(creep)
    bad = [c for c in values if not lo <= float(c) <= hi]
    if bad:
        raise ValueError(f"creep: {bad} outside the map's {dim} range [{lo}, {hi}]")
    if len(ds[dim]) == 1:
        return adh.sel({dim: creep})
    return adh.chunk({dim: -1}).interp({dim: creep}) if adh.chunks else adh.interp({dim: creep})


def min_adhesion_water_flow(ds: xr.Dataset, dim: str = "water_flow") -> xr.Dataset:
    """Minimum adhesion over the water flow rate and the flow rate where it occurs [µl/s].

    WILAC's low-adhesion point (seed 000, Fig. 8: minima between 20 and 40 µl/s on the tram
    rig). Returns ``adhesion_min`` and ``<dim>_at_min`` over the other dimensions.
    """
    adh = _adhesion(ds, dim)
    low = adh.min(dim)
    where = adh.fillna(10.0).idxmin(dim).where(low.notnull())
    where.attrs = dict(ds[dim].attrs)
    low.attrs = {"units": "1", "long_name": f"minimum adhesion over {dim}"}
    return xr.Dataset({"adhesion_min": low, f"{dim}_at_min": where})
