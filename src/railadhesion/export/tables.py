"""Creep-force tables: a model evaluated on a grid, for table-driven force elements.

:func:`creep_force_table` evaluates WILAC or Polach on the grid
creep_long × creep_lat × normal force × speed (× water flow for WILAC) at fixed spin, with the
contact semi-axes a(Q), b(Q) from Hertz for a given wheel/rail geometry. It also measures how
well the table represents the model: the model is evaluated at the midpoints of all grid
cells (every coordinate half-way between two grid values: the points farthest from the
nodes) and compared with multilinear interpolation of the table there
(:func:`interpolation_error`). The result is an :class:`xarray.Dataset`, written as NetCDF by
:func:`write_table_netcdf` and as a plain CSV by :func:`write_table_csv`; the CSV layout is
documented in ``docs/creep-force-tables.md`` and read back by :func:`read_table_csv`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from railadhesion.export.fmu import resolve_parameters

__all__ = [
    "DEFAULT_GRID",
    "TABLE_AXES",
    "InterpolationError",
    "creep_force_table",
    "interpolation_error",
    "read_table_csv",
    "write_table_csv",
    "write_table_netcdf",
]

_creeps = [5e-4, 1e-3, 2e-3, 3e-3, 5e-3, 7.5e-3, 0.01, 0.015, 0.02, 0.03, 0.05, 0.075, 0.1,
           0.15, 0.2, 0.3, 0.5, 0.7, 1.0]  # fmt: skip

#: Default grid values per axis (SI; creepage as a fraction; water flow in µl/s). The
#: creepages are symmetric (traction and braking) and dense where creep curves bend; the water
#: flows are dense across the default WILAC set's transitions (15, 30 and 50 µl/s).
DEFAULT_GRID: dict[str, tuple[float, ...]] = {
    "creep_long": tuple([-c for c in reversed(_creeps)] + [0.0] + _creeps),
    "creep_lat": tuple([-c for c in reversed(_creeps[:11])] + [0.0] + _creeps[:11]),
    "normal_force": (5e3, 10e3, 25e3, 50e3, 100e3, 150e3),
    "speed": (1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 20.0, 40.0),
    "water_flow": (0.0, 5.0, 10.0, 12.5, 15.0, 17.5, 20.0, 25.0, 28.0, 30.0, 32.0, 35.0, 40.0,
                   45.0, 50.0, 55.0, 60.0, 70.0, 100.0, 400.0),
}  # fmt: skip

#: Table axes (slowest-varying first, as in the CSV): name, CSV column, units, long name.
TABLE_AXES = {
    "water_flow": ("water_flow_ul_s", "uL s-1", "water flow rate to the rail surface"),
    "speed": ("speed_m_s", "m s-1", "rolling speed V"),
    "normal_force": ("normal_force_N", "N", "normal force Q"),
    "creep_lat": ("creep_lat", "1", "lateral creepage eta"),
    "creep_long": ("creep_long", "1", "longitudinal creepage xi = (V - omega R)/V"),
}
_VALUES = {
    "a": ("a_m", "m", "contact semi-axis along the rolling direction (Hertz)"),
    "b": ("b_m", "m", "lateral contact semi-axis (Hertz)"),
    "Fx": ("Fx_N", "N", "longitudinal force of the rail on the wheel (Kalker's sign)"),
    "Fy": ("Fy_N", "N", "lateral force of the rail on the wheel (Kalker's sign)"),
    "adhesion": ("adhesion", "1", "adhesion coefficient sqrt(Fx^2 + Fy^2)/Q"),
}


@dataclass(frozen=True)
class InterpolationError:
    """Error of multilinear interpolation in a table against the model, at cell midpoints.

    Errors of Fx and Fy are divided by the normal force Q of each point (adhesion units:
    0.01 = 1 % of Q), so that light and heavy contacts count alike.

    Attributes
    ----------
    n_points : int
        Number of midpoints evaluated.
    max_fx, rms_fx, max_fy, rms_fy : float
        Maximum and root-mean-square of |interpolated - model|/Q for Fx and Fy [-].
    max_fx_newton : float
        Largest absolute error of Fx [N].
    worst : dict
        Coordinates of the midpoint with the largest Fx error.
    per_axis : dict
        For each axis with more than one value: the largest error of Fx or Fy (over Q) with
        only that axis at its midpoints, the others on grid values.
    """

    n_points: int
    max_fx: float
    rms_fx: float
    max_fy: float
    rms_fy: float
    max_fx_newton: float
    worst: dict
    per_axis: dict

    def attrs(self) -> dict:
        """Flat NetCDF/CSV attributes."""
        out = {
            "interpolation_check": "multilinear interpolation of the table vs the model at "
            "the midpoints of all grid cells; errors of Fx, Fy divided by Q",
            "interpolation_check_points": self.n_points,
            "interpolation_max_error_Fx_over_Q": self.max_fx,
            "interpolation_rms_error_Fx_over_Q": self.rms_fx,
            "interpolation_max_error_Fy_over_Q": self.max_fy,
            "interpolation_rms_error_Fy_over_Q": self.rms_fy,
            "interpolation_max_error_Fx_N": self.max_fx_newton,
        }
        for k, v in self.worst.items():
            out[f"interpolation_worst_Fx_at_{k}"] = v
        for k, v in self.per_axis.items():
            out[f"interpolation_max_error_over_Q_{k}_only"] = v
        return out

    def summary(self) -> str:
        """One line for the console."""
        where = ", ".join(f"{k} = {v:.6g}" for k, v in self.worst.items())
        return (
            f"interpolation error at {self.n_points} cell midpoints (|error|/Q): "
            f"Fx max {self.max_fx:.3g}, RMS {self.rms_fx:.3g}; "
            f"Fy max {self.max_fy:.3g}, RMS {self.rms_fy:.3g}; worst Fx at {where}; "
            "max with one axis at midpoints: "
            + ", ".join(f"{k} {v:.3g}" for k, v in self.per_axis.items())
        )


def _axis(values, name: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size == 0:
        raise ValueError(f"{name}: expected at least one grid value")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: grid values must be finite, got {arr.tolist()}")
    if arr.size > 1 and not np.all(np.diff(arr) > 0):
        raise ValueError(f"{name}: grid values must be strictly increasing, got {arr.tolist()}")
    return arr


def _evaluate(resolved, grid: dict, spin, geometry: dict, shear_modulus, poisson):
    """Model on the full product of ``grid`` (dims in TABLE_AXES order): a, b, Fx, Fy, |T|/Q."""
    import railadhesion

    dims = [d for d in TABLE_AXES if d in grid]
    shape = [len(grid[d]) for d in dims]

    def along(d):  # grid values of axis d, broadcast along its dimension
        s = [1] * len(dims)
        s[dims.index(d)] = len(grid[d])
        return grid[d].reshape(s)

    q = along("normal_force")
    h = railadhesion.hertz_3d(grid["normal_force"], **geometry)
    a = np.asarray(h.a, dtype=float).reshape(q.shape)
    b = np.asarray(h.b, dtype=float).reshape(q.shape)
    args = (along("creep_long"), along("creep_lat"), spin, q, along("speed"), a, b)
    p = resolved.params
    if resolved.model == "wilac":
        fx, fy = railadhesion.wilac_forces(
            *args, along("water_flow"), p, shear_modulus=shear_modulus, poisson=poisson
        )
    else:
        fx, fy = railadhesion.polach_forces(
            *args, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
            shear_modulus=shear_modulus, poisson=poisson,
        )  # fmt: skip
    fx = np.broadcast_to(fx, shape)
    fy = np.broadcast_to(fy, shape)
    return dims, h.a, h.b, fx, fy, railadhesion.adhesion(fx, fy, q)


def creep_force_table(
    model: str = "wilac",
    params=None,
    *,
    parameter_set: str | None = None,
    creep_long=DEFAULT_GRID["creep_long"],
    creep_lat=DEFAULT_GRID["creep_lat"],
    normal_force=DEFAULT_GRID["normal_force"],
    speed=DEFAULT_GRID["speed"],
    water_flow=DEFAULT_GRID["water_flow"],
    spin: float = 0.0,
    wheel_radius: float = 0.625,
    wheel_lateral_radius: float = math.inf,
    rail_lateral_radius: float = 0.3,
    rail_radius: float = math.inf,
    shear_modulus: float = 8.2e10,
    poisson: float = 0.28,
    check: bool = True,
) -> xr.Dataset:
    """Evaluate a creep-force model on a grid, as a table with its interpolation error.

    Parameters
    ----------
    model : {"wilac", "polach"}
    params, parameter_set :
        The parameter set (file, object or name), as for
        :func:`railadhesion.export.resolve_parameters`.
    creep_long, creep_lat : sequence of float
        Creepage grid values [-] (fractions, Kalker's sign: braking > 0), increasing.
    normal_force : sequence of float
        Normal force grid [N], > 0, increasing.
    speed : sequence of float
        Rolling speed grid [m/s], >= 0, increasing.
    water_flow : sequence of float
        Water flow grid [µl/s], >= 0, increasing (WILAC only; ignored for Polach).
    spin : float
        Spin creepage of the whole table [rad/m].
    wheel_radius, wheel_lateral_radius, rail_lateral_radius, rail_radius : float
        Geometry for the Hertz semi-axes a(Q), b(Q) [m] (:func:`railadhesion.hertz_3d`);
        default: locomotive wheel R 0.625 m, straight tread, rail head radius 0.3 m.
    shear_modulus, poisson : float
        Elastic constants of the creep-force model [Pa], [-].
    check : bool
        Measure the interpolation error (:func:`interpolation_error`) and store it in attrs.

    Returns
    -------
    xarray.Dataset
        ``Fx``, ``Fy`` [N] and ``adhesion`` [-] over the dims (``water_flow``,) ``speed``,
        ``normal_force``, ``creep_lat``, ``creep_long``; ``a``, ``b`` [m] over
        ``normal_force``; provenance, spin, geometry and the interpolation error in attrs.
    """
    import railadhesion

    if model == "table":  # an FMU model, not a table model: say so rather than fall to Polach
        raise ValueError("model must be wilac or polach for a creep-force table, got 'table' "
                         "(the table model is itself a table: exact_table_forces)")
    resolved = resolve_parameters(model, params, parameter_set)
    grid = {
        "creep_long": _axis(creep_long, "creep_long"),
        "creep_lat": _axis(creep_lat, "creep_lat"),
        "normal_force": _axis(normal_force, "normal_force"),
        "speed": _axis(speed, "speed"),
    }
    if model == "wilac":
        grid["water_flow"] = _axis(water_flow, "water_flow")
    if not math.isfinite(spin):
        raise ValueError(f"spin must be finite, got {spin!r}")
    geometry = {
        "wheel_radius": wheel_radius,
        "wheel_lateral_radius": wheel_lateral_radius,
        "rail_lateral_radius": rail_lateral_radius,
        "rail_radius": rail_radius,
    }
    dims, a, b, fx, fy, adh = _evaluate(resolved, grid, spin, geometry, shear_modulus, poisson)
    coords = {}
    for d in dims:
        column, units, long_name = TABLE_AXES[d]
        coords[d] = (d, grid[d], {"units": units, "long_name": long_name, "csv_column": column})

    def attrs(key):
        column, units, long_name = _VALUES[key]
        return {"units": units, "long_name": long_name, "csv_column": column}

    ds = xr.Dataset(
        {
            "Fx": (dims, np.array(fx), attrs("Fx")),
            "Fy": (dims, np.array(fy), attrs("Fy")),
            "adhesion": (dims, np.array(adh), attrs("adhesion")),
            "a": ("normal_force", np.asarray(a, dtype=float).ravel(), attrs("a")),
            "b": ("normal_force", np.asarray(b, dtype=float).ravel(), attrs("b")),
        },
        coords=coords,
    )
    ds.attrs.update(
        {
            "title": f"railadhesion {model} creep-force table",
            "railadhesion_version": railadhesion.__version__,
            "model": model,
            "parameter_set": resolved.name,
            "parameter_origin": resolved.origin,
            "parameter_file_sha256": resolved.sha256,
            "sign_convention": "Kalker/CONTACT: creepage (V - omega R)/V, braking > 0; Fx, Fy "
            "are forces of the rail on the wheel and oppose the creepages",
            "spin_rad_per_m": float(spin),
            "shear_modulus_Pa": float(shear_modulus),
            "poisson": float(poisson),
            **{f"hertz_{k}_m": float(v) for k, v in geometry.items()},
        }
    )
    for key, value in resolved.provenance.items():
        ds.attrs[f"provenance_{key}"] = str(value).lower() if isinstance(value, bool) else value
    if check:
        err = interpolation_error(ds, resolved=resolved)
        ds.attrs.update(err.attrs())
    return ds


def _midpoints(values: np.ndarray) -> np.ndarray:
    return values if values.size == 1 else 0.5 * (values[1:] + values[:-1])


def interpolation_error(table: xr.Dataset, params=None, *, resolved=None) -> InterpolationError:
    """Compare multilinear interpolation of ``table`` with the model at the cell midpoints.

    At the midpoint of a cell (every coordinate half-way between two grid values) multilinear
    interpolation is the mean of the cell's 2^d corner values; the model is evaluated there
    on the full midpoint grid (no sampling). The same is done with one axis at a time at its
    midpoints (the others on grid values), which tells which axis to refine.

    Parameters
    ----------
    table : xarray.Dataset
        A table from :func:`creep_force_table` (its attrs name the model, spin, geometry,
        elastic constants and the SHA-256 of the parameter set).
    params : path-like or parameter object, optional
        The parameter set the table was made with; needed unless it was a named set of the
        package. It must be the same set (checked by its SHA-256).
    resolved : ResolvedParameters, optional
        Alternative to ``params`` (used by :func:`creep_force_table`).

    Returns
    -------
    InterpolationError
    """
    attrs = table.attrs
    if resolved is None:
        resolved = _table_parameters(attrs, params)
    dims = [d for d in TABLE_AXES if d in table.dims]
    nodes = {d: table[d].values for d in dims}
    geometry = {k: attrs[f"hertz_{k}_m"] for k in
                ("wheel_radius", "wheel_lateral_radius", "rail_lateral_radius", "rail_radius")}
    args = (attrs["spin_rad_per_m"], geometry, attrs["shear_modulus_Pa"], attrs["poisson"])
    values = {k: table[k].transpose(*dims).values for k in ("Fx", "Fy")}

    def compare(axes):
        grid = {d: _midpoints(nodes[d]) if d in axes else nodes[d] for d in dims}
        _, _, _, fx, fy, _ = _evaluate(resolved, grid, *args)
        q = grid["normal_force"].reshape([-1 if d == "normal_force" else 1 for d in dims])
        out = {}
        for name, model_value in (("Fx", fx), ("Fy", fy)):
            interp = values[name]
            for i, d in enumerate(dims):
                if d in axes and nodes[d].size > 1:
                    interp = _midpoints_along(interp, i)
            out[name] = np.abs(interp - model_value)
        return grid, out["Fx"], out["Fy"], q

    grid, ex_n, ey_n, q = compare(set(dims))
    ex, ey = ex_n / q, ey_n / q
    worst = np.unravel_index(int(np.argmax(ex)), ex.shape)
    per_axis = {}
    for d in dims:
        if nodes[d].size > 1:
            _, ax, ay, qa = compare({d})
            per_axis[d] = float(max((ax / qa).max(), (ay / qa).max()))
    return InterpolationError(
        n_points=int(ex.size),
        max_fx=float(ex.max()),
        rms_fx=float(np.sqrt(np.mean(ex**2))),
        max_fy=float(ey.max()),
        rms_fy=float(np.sqrt(np.mean(ey**2))),
        max_fx_newton=float(ex_n.max()),
        worst={d: float(grid[d][i]) for d, i in zip(dims, worst, strict=True)},
        per_axis=per_axis,
    )


def _midpoints_along(values: np.ndarray, axis: int) -> np.ndarray:
    """Mean of neighbours along ``axis``: linear interpolation at the midpoints."""
    lo = np.take(values, np.arange(values.shape[axis] - 1), axis=axis)
    hi = np.take(values, np.arange(1, values.shape[axis]), axis=axis)
    return 0.5 * (lo + hi)


def _table_parameters(attrs, params):
    model = attrs["model"]
    if params is not None:
        resolved = resolve_parameters(model, params)
    elif attrs["parameter_origin"] == "package default WILAC set":
        resolved = resolve_parameters(model)
    elif attrs["parameter_origin"] == "built-in named Polach set":
        resolved = resolve_parameters(model, parameter_set=attrs["parameter_set"])
    else:
        raise ValueError(
            f"params: the table was made with {attrs['parameter_origin']}; pass that "
            "parameter set (file or object) to check it"
        )
    if resolved.sha256 != attrs["parameter_file_sha256"]:
        raise ValueError(
            f"params: parameter set {resolved.name!r} is not the one the table was made with "
            f"({attrs['parameter_set']!r}, SHA-256 differs)"
        )
    return resolved


def write_table_netcdf(table: xr.Dataset, path) -> Path:
    """Write ``table`` as NetCDF-4 (netCDF4 engine, zlib-compressed values); returns the path."""
    path = Path(path)
    encoding = {k: {"zlib": True, "complevel": 4} for k in ("Fx", "Fy", "adhesion")}
    table.to_netcdf(path, engine="netcdf4", encoding=encoding)
    return path


def _header_lines(table: xr.Dataset) -> list[str]:
    dims = [d for d in TABLE_AXES if d in table.dims]
    lines = [
        "railadhesion creep-force table (layout: docs/creep-force-tables.md)",
        "axes, slowest-varying first (values in column order): "
        + ", ".join(f"{TABLE_AXES[d][0]} ({table.sizes[d]})" for d in dims),
    ]
    for key, value in table.attrs.items():
        text = str(value).replace("\r", " ").replace("\n", " | ")
        lines.append(f"{key}: {text}")
    return lines


def write_table_csv(table: xr.Dataset, path, *, digits: int = 12) -> Path:
    """Write ``table`` as a plain CSV (one row per grid point); returns the path.

    Layout (``docs/creep-force-tables.md``): comment lines starting with ``#`` (metadata:
    model, parameter set, provenance, spin, geometry, interpolation error), then one header
    row, then one row per grid point with the axis columns (slowest-varying first, the last,
    ``creep_long``, fastest), ``a_m``, ``b_m``, ``Fx_N``, ``Fy_N``, ``adhesion``. Numbers are
    written with ``digits`` significant digits (17 gives an exact float64 round trip; the
    default 12 keeps files smaller at a relative rounding of 5e-13).
    """
    if not (isinstance(digits, int) and 1 <= digits <= 17):
        raise ValueError(f"digits must be an integer in [1, 17], got {digits!r}")
    path = Path(path)
    dims = [d for d in TABLE_AXES if d in table.dims]
    frame = table[["a", "b", "Fx", "Fy", "adhesion"]].transpose(*dims).to_dataframe()
    frame = frame.reset_index()[dims + ["a", "b", "Fx", "Fy", "adhesion"]]
    frame.columns = [TABLE_AXES[d][0] for d in dims] + [_VALUES[k][0] for k in _VALUES]
    with open(path, "w", encoding="utf-8", newline="") as fh:
        for line in _header_lines(table):
            fh.write(f"# {line}\n")
        frame.to_csv(fh, index=False, float_format=f"%.{digits}g", lineterminator="\n")
    return path


def read_table_csv(path) -> xr.Dataset:
    """Read a table written by :func:`write_table_csv` back into a Dataset (values only;
    the ``#`` metadata lines are returned as the ``header`` attribute)."""
    path = Path(path)
    with open(path, encoding="utf-8") as fh:
        header = [line[2:].rstrip("\n") for line in fh if line.startswith("#")]
    frame = pd.read_csv(path, comment="#")
    by_column = {v[0]: k for k, v in {**TABLE_AXES, **_VALUES}.items()}
    unknown = [c for c in frame.columns if c not in by_column]
    if unknown:
        raise ValueError(f"{path}: unknown column(s) {unknown}; see docs/creep-force-tables.md")
    frame = frame.rename(columns=by_column)
    dims = [d for d in TABLE_AXES if d in frame.columns]
    ds = frame.set_index(dims).to_xarray()
    expected = int(np.prod([ds.sizes[d] for d in dims]))
    if len(frame) != expected:
        raise ValueError(
            f"{path}: {len(frame)} rows do not fill the grid "
            f"({' x '.join(str(ds.sizes[d]) for d in dims)} = {expected})"
        )
    ds["a"] = ds["a"].isel({d: 0 for d in dims if d != "normal_force"}, drop=True)
    ds["b"] = ds["b"].isel({d: 0 for d in dims if d != "normal_force"}, drop=True)
    ds.attrs["header"] = "\n".join(header)
    return ds
