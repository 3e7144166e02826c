"""Creep-force tables: values, NetCDF/CSV round trips and the stated interpolation error."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.interpolate import RegularGridInterpolator

import railadhesion
from railadhesion.export import (
    creep_force_table,
    interpolation_error,
    read_table_csv,
    write_table_csv,
    write_table_netcdf,
)
from railadhesion.models import PolachParameters, default_wilac_parameters, polach_parameters

# Small grids keep the tests fast; they still cross the creep-curve peak and the water
# transitions of the default WILAC set (15, 30, 50 µl/s).
SMALL = {
    "creep_long": [-0.3, -0.05, -0.01, -0.002, 0.0, 0.002, 0.01, 0.05, 0.3],
    "creep_lat": [-0.01, 0.0, 0.005, 0.02],
    "normal_force": [10e3, 50e3, 120e3],
    "speed": [2.0, 10.0, 30.0],
    "water_flow": [0.0, 15.0, 30.0, 60.0, 400.0],
}
GEOMETRY = {"wheel_radius": 0.625, "wheel_lateral_radius": np.inf, "rail_lateral_radius": 0.3}


@pytest.fixture(scope="module")
def wilac_table():
    return creep_force_table("wilac", spin=0.3, **SMALL)


def _model(model, params, pts, spin):
    """Direct library call at scattered points (dict of 1-D arrays)."""
    h = railadhesion.hertz_3d(pts["normal_force"], **GEOMETRY)
    args = (pts["creep_long"], pts["creep_lat"], spin, pts["normal_force"], pts["speed"],
            h.a, h.b)  # fmt: skip
    if model == "wilac":
        return railadhesion.wilac_forces(*args, pts["water_flow"], params)
    return railadhesion.polach_forces(
        *args, mu0=params.mu0, k_A=params.k_A, k_S=params.k_S, A=params.A, B=params.B
    )


def test_table_nodes_equal_direct_calls(wilac_table):
    t = wilac_table
    assert t["Fx"].dims == ("water_flow", "speed", "normal_force", "creep_lat", "creep_long")
    grids = np.meshgrid(*[t[d].values for d in t["Fx"].dims], indexing="ij")
    pts = {d: g.ravel() for d, g in zip(t["Fx"].dims, grids, strict=True)}
    fx, fy = _model("wilac", default_wilac_parameters(), pts, 0.3)
    q = pts["normal_force"]
    np.testing.assert_allclose(t["Fx"].values.ravel() / q, fx / q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(t["Fy"].values.ravel() / q, fy / q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(t["adhesion"].values.ravel(), np.hypot(fx, fy) / q, atol=1e-12)
    h = railadhesion.hertz_3d(t["normal_force"].values, **GEOMETRY)
    np.testing.assert_array_equal(t["a"].values, h.a)
    np.testing.assert_array_equal(t["b"].values, h.b)
    assert t.attrs["provenance_reconstruction"] == "true"
    assert t["Fx"].attrs["units"] == "N" and t["water_flow"].attrs["units"] == "uL s-1"


def test_polach_table_has_no_water_axis():
    t = creep_force_table("polach", parameter_set="polach2005_wet", **SMALL)
    assert "water_flow" not in t.dims
    assert t.attrs["parameter_set"] == "polach2005_wet"
    assert t.attrs["interpolation_max_error_Fx_over_Q"] > 0


def test_netcdf_round_trip_is_identical(wilac_table, tmp_path):
    path = write_table_netcdf(wilac_table, tmp_path / "t.nc")
    with xr.open_dataset(path, engine="netcdf4") as back:
        xr.testing.assert_identical(back.load(), wilac_table)


@pytest.mark.parametrize(("digits", "atol"), [(17, 0.0), (12, 1e-11)])
def test_csv_round_trip(wilac_table, tmp_path, digits, atol):
    path = write_table_csv(wilac_table, tmp_path / "t.csv", digits=digits)
    back = read_table_csv(path)
    for name in ("Fx", "Fy", "adhesion", "a", "b"):
        ref = wilac_table[name]
        got = back[name].transpose(*ref.dims).values
        np.testing.assert_allclose(got, ref.values, rtol=atol, atol=0)
    assert "parameter_set: wilac_default_reconstruction" in back.attrs["header"]


def test_csv_layout(wilac_table, tmp_path):
    """Comment lines, one header row, one row per node, creep_long varying fastest."""
    path = write_table_csv(wilac_table, tmp_path / "t.csv")
    lines = path.read_text(encoding="utf-8").splitlines()
    comments = [line for line in lines if line.startswith("#")]
    body = lines[len(comments):]
    assert all(line.startswith("# ") for line in lines[: len(comments)])  # comments first
    assert body[0].split(",") == [
        "water_flow_ul_s", "speed_m_s", "normal_force_N", "creep_lat", "creep_long",
        "a_m", "b_m", "Fx_N", "Fy_N", "adhesion",
    ]  # fmt: skip
    rows = np.array([[float(x) for x in line.split(",")] for line in body[1:]])
    assert len(rows) == wilac_table["Fx"].size
    n = len(SMALL["creep_long"])
    np.testing.assert_array_equal(rows[:n, 4], SMALL["creep_long"])
    np.testing.assert_array_equal(rows[:n, :4], np.broadcast_to(rows[0, :4], (n, 4)))
    # The metadata states the interpolation error.
    assert any(c.startswith("# interpolation_max_error_Fx_over_Q: ") for c in comments)


def test_stated_error_matches_an_independent_interpolation(wilac_table, tmp_path):
    """Round trip: read the CSV back, interpolate it with SciPy at every cell midpoint and
    compare with the model; the maximum and RMS equal those stated in the file's attrs."""
    back = read_table_csv(write_table_csv(wilac_table, tmp_path / "t.csv", digits=17))
    dims = list(wilac_table["Fx"].dims)
    mids = [0.5 * (back[d].values[1:] + back[d].values[:-1]) for d in dims]
    grids = np.meshgrid(*mids, indexing="ij")
    pts = {d: g.ravel() for d, g in zip(dims, grids, strict=True)}
    fx, fy = _model("wilac", default_wilac_parameters(), pts, 0.3)
    xi = np.column_stack([pts[d] for d in dims])
    q = pts["normal_force"]
    axes = [back[d].values for d in dims]
    ex = np.abs(RegularGridInterpolator(axes, back["Fx"].transpose(*dims).values)(xi) - fx) / q
    ey = np.abs(RegularGridInterpolator(axes, back["Fy"].transpose(*dims).values)(xi) - fy) / q
    a = wilac_table.attrs
    assert a["interpolation_check_points"] == ex.size
    assert a["interpolation_max_error_Fx_over_Q"] == pytest.approx(ex.max(), rel=1e-9)
    assert a["interpolation_rms_error_Fx_over_Q"] == pytest.approx(np.sqrt(np.mean(ex**2)), 1e-9)
    assert a["interpolation_max_error_Fy_over_Q"] == pytest.approx(ey.max(), rel=1e-9)
    # Stated for the record (this coarse test grid): a few per cent of Q at worst.
    assert 1e-3 < ex.max() < 0.2


def test_random_off_grid_points_error_is_bounded_by_the_grid_scale(wilac_table):
    """At random off-grid points the interpolation error stays of the size reported."""
    rng = np.random.default_rng(3)
    dims = list(wilac_table["Fx"].dims)
    pts = {d: rng.uniform(wilac_table[d].values[0], wilac_table[d].values[-1], 2000)
           for d in dims}  # fmt: skip
    fx, _ = _model("wilac", default_wilac_parameters(), pts, 0.3)
    axes = [wilac_table[d].values for d in dims]
    interp = RegularGridInterpolator(axes, wilac_table["Fx"].values)
    err = np.abs(interp(np.column_stack([pts[d] for d in dims])) - fx) / pts["normal_force"]
    assert err.max() < 2 * wilac_table.attrs["interpolation_max_error_Fx_over_Q"]


def test_refining_the_creep_grid_reduces_the_error():
    base = dict(SMALL, speed=[10.0], normal_force=[50e3], creep_lat=[0.0])
    creep = np.asarray(SMALL["creep_long"])
    errors = []
    for _ in range(3):
        t = creep_force_table("polach", **dict(base, creep_long=creep))
        errors.append(t.attrs["interpolation_max_error_Fx_over_Q"])
        creep = np.sort(np.r_[creep, 0.5 * (creep[1:] + creep[:-1])])  # halve the spacing
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.3 * errors[0]


def test_axes_the_model_is_linear_or_constant_in_have_zero_error():
    """Polach with B = 0 does not depend on speed; WILAC with four equal conditions does not
    depend on water flow: interpolating along those axes is exact."""
    flat = PolachParameters(k_A=1.0, k_S=0.4, mu0=0.4, A=0.4, B=0.0, name="no_speed")
    t = creep_force_table("polach", flat, **SMALL)
    assert t.attrs["interpolation_max_error_over_Q_speed_only"] < 1e-15
    assert t.attrs["interpolation_max_error_over_Q_creep_long_only"] > 1e-3
    p = default_wilac_parameters()
    same = p.replace(conditions={c: p.conditions["dry"] for c in p.conditions})
    t = creep_force_table("wilac", same, **SMALL)
    assert t.attrs["interpolation_max_error_over_Q_water_flow_only"] < 1e-14
    assert interpolation_error(t, same).max_fx == t.attrs["interpolation_max_error_Fx_over_Q"]


def test_single_value_axes_are_allowed():
    t = creep_force_table("polach", **dict(SMALL, speed=[10.0], normal_force=[80e3]))
    assert t.sizes["speed"] == 1
    assert "interpolation_max_error_over_Q_speed_only" not in t.attrs
    assert t.attrs["interpolation_check_points"] == (9 - 1) * (4 - 1)


def test_bad_grids_and_mismatched_parameters_are_refused():
    with pytest.raises(ValueError, match="creep_long: grid values must be strictly increasing"):
        creep_force_table("polach", creep_long=[0.1, 0.0])
    with pytest.raises(ValueError, match="speed: expected at least one grid value"):
        creep_force_table("polach", speed=[])
    with pytest.raises(ValueError, match="normal_force"):
        creep_force_table("polach", normal_force=[-1.0, 1e3])
    t = creep_force_table("polach", **dict(SMALL, speed=[10.0]))
    with pytest.raises(ValueError, match="not the one the table was made with"):
        interpolation_error(t, polach_parameters("polach2005_wet"))
    custom = creep_force_table("polach", polach_parameters("polach2005_wet").replace(mu0=0.2),
                               check=False, **dict(SMALL, speed=[10.0]))  # fmt: skip
    with pytest.raises(ValueError, match="pass that parameter set"):
        interpolation_error(custom)
    with pytest.raises(ValueError, match="digits"):
        write_table_csv(t, "unused.csv", digits=30)


def test_symmetric_grid_gives_odd_forces():
    """Kalker's signs: with no spin, Fx is odd in creep_long and Fy odd in creep_lat; the
    table, on grids symmetric about zero, keeps that symmetry exactly."""
    grid = dict(SMALL, creep_lat=[-0.01, -0.002, 0.0, 0.002, 0.01])
    t = creep_force_table("polach", spin=0.0, check=False, **grid)
    fx = t["Fx"].transpose(..., "creep_lat", "creep_long").values
    fy = t["Fy"].transpose(..., "creep_lat", "creep_long").values
    assert np.abs(fy).max() > 1e3  # not trivially zero
    np.testing.assert_allclose(fx, -fx[..., ::-1], rtol=1e-13, atol=1e-9)
    np.testing.assert_allclose(fy, -fy[..., ::-1, :], rtol=1e-13, atol=1e-9)
