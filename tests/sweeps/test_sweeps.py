"""Sweeps: values equal direct model calls, failing points recorded, resume, derived
quantities, NetCDF output (all in-process; the cluster tests are in test_cluster.py)."""

import json

import numpy as np
import pytest
import xarray as xr

import railadhesion as ra
from railadhesion.contact.geometry import contact_semi_axes
from railadhesion.sweeps import (
    FunctionSweep,
    PolachSweep,
    TwoDSweep,
    WilacSweep,
    adhesion_at_creep,
    full_factorial,
    max_adhesion,
    min_adhesion_water_flow,
    monte_carlo,
    plan_sweep,
    run_sweep,
    sweep_errors,
)
from railadhesion.sweeps import plan as plan_module

WILAC_GRID = {
    "creep_long": np.geomspace(0.001, 0.9, 12),
    "speed": [2.5, 5.0, 20.0],
    "normal_force": [4200.0, 5600.0, 7000.0],  # within the default set's range (from 4.2 kN)
    "water_flow": [0.0, 15.0, 25.0, 35.0, 60.0, 350.0],
}


def _close(got, want):
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * max(1.0, abs(want)))


def test_wilac_map_equals_direct_calls():
    res = run_sweep(WilacSweep(geometry="tram"), WILAC_GRID, chunk_points=50,
                    scheduler="synchronous")  # fmt: skip
    ds = res.dataset
    assert res.chunks_total > 10 and res.failed_points == 0
    assert ds.adhesion.dims == tuple(WILAC_GRID)
    assert ds.water_flow.attrs["units"] == "µl/s" and ds.fx.attrs["units"] == "N"
    params = ra.default_wilac_parameters()
    rng = np.random.default_rng(1)
    for _ in range(25):
        idx = {d: int(rng.integers(len(v))) for d, v in WILAC_GRID.items()}
        c, v, q, w = (float(WILAC_GRID[d][idx[d]]) for d in WILAC_GRID)
        a, b = contact_semi_axes("tram", q)
        fx, fy = ra.wilac_forces(c, 0.0, 0.0, q, v, a, b, w, params)  # scalar path
        point = ds.isel(idx)
        _close(float(point.fx), fx)
        _close(float(point.fy), fy)
        _close(float(point.adhesion), np.hypot(fx, fy) / q)
    desc = json.loads(ds.attrs["parameters"])
    assert "reconstruction = true" in desc["parameters_toml"]
    assert ds.attrs["model"] == "wilac" and "Trummer" in ds.attrs["model_description"]


def test_polach_parameter_sets_and_lateral_creep_equal_direct_calls():
    grid = {"creep_long": [-0.05, 0.002, 0.01, 0.2], "creep_lat": [0.0, 0.003],
            "parameter_set": ["polach2005_dry", "polach2005_wet"]}  # fmt: skip
    ds = run_sweep(PolachSweep(geometry=(6.304e-3, 12.61e-3)), grid, chunks={"creep_long": 3},
                   fixed={"normal_force": 106.7e3, "speed": 10.0, "spin": 0.5}).dataset
    for i, c in enumerate(grid["creep_long"]):
        for j, e in enumerate(grid["creep_lat"]):
            for k, name in enumerate(grid["parameter_set"]):
                p = ra.polach_parameters(name)
                fx, fy = ra.polach_forces(c, e, 0.5, 106.7e3, 10.0, 6.304e-3, 12.61e-3,
                                          **p.as_dict())  # fmt: skip
                _close(float(ds.fx[i, j, k]), fx)
                _close(float(ds.fy[i, j, k]), fy)
    assert list(ds.parameter_set.values) == grid["parameter_set"]


def test_fletcher_conditions_equal_direct_calls():
    creep = np.linspace(-0.01, 0.01, 9)
    ds = run_sweep(TwoDSweep(), {"condition": ["W1", "D3", "O1"], "creep_long": creep}).dataset
    assert ds.fx.attrs["units"] == "N/m"
    for k, code in enumerate(["W1", "D3", "O1"]):
        want = ra.fletcher_condition(code).adhesion(creep)
        np.testing.assert_allclose(ds.adhesion[k].values, want, rtol=1e-12, atol=0)


def test_failing_points_are_recorded_not_fatal(tmp_path):
    grid = {"creep_long": [0.01, 0.1, 0.3], "normal_force": [50e3, -1.0, 110e3],
            "speed": [5.0, 10.0]}  # fmt: skip
    res = run_sweep(PolachSweep(), grid, tmp_path / "m.zarr", chunk_points=4,
                    scheduler="synchronous")  # fmt: skip
    ds = res.dataset
    bad = ds.normal_force == -1.0
    assert res.failed_points == 6
    assert (ds.error.where(bad, 0) == bad).all() and int(ds.error.sum()) == 6
    assert ds.adhesion.where(bad).isnull().all()
    assert ds.adhesion.where(~bad).notnull().sum() == 12
    errors = sweep_errors(tmp_path / "m.zarr")
    assert len(errors) == 6 and (errors.normal_force == -1.0).all()
    assert errors.message.str.contains("normal_force must be in").all()
    quoted = json.loads(ds.attrs["failures"])
    assert quoted[0]["point"]["normal_force"] == -1.0
    assert ds.attrs["failed_points"] == 6 and ds.attrs["complete"] == 1


class _Stop(Exception):
    pass


def test_resume_computes_only_missing_chunks(tmp_path, monkeypatch):
    computed = []
    original = plan_module.SweepPlan.evaluate_chunk

    def counting(self, index):
        computed.append(tuple(index))
        return original(self, index)

    monkeypatch.setattr(plan_module.SweepPlan, "evaluate_chunk", counting)
    model, out = WilacSweep(), tmp_path / "map.zarr"
    plan = plan_sweep(model, WILAC_GRID, chunk_points=100)
    total = plan.n_chunks
    assert total >= 8

    def stop_after_3(done, todo):
        if done == 3:
            raise _Stop

    with pytest.raises(_Stop):
        run_sweep(plan, out=out, scheduler="synchronous", on_chunk=stop_after_3)
    first = list(computed)
    assert len(first) == 3
    assert len(list((out / ".sweep" / "chunks").glob("*.json"))) == 3
    computed.clear()
    res = run_sweep(model, WILAC_GRID, out, chunk_points=100, scheduler="synchronous")
    assert (res.chunks_skipped, res.chunks_computed) == (3, total - 3)
    assert len(computed) == total - 3 and not set(computed) & set(first)
    assert res.dataset.attrs["complete"] == 1
    # A chunk whose data was written but whose marker was not (a crash in between) is redone,
    # with identical values; nothing else is recomputed.
    (out / ".sweep" / "chunks" / "0_0_0_0.json").unlink()
    computed.clear()
    again = run_sweep(plan, out=out, scheduler="threads")
    assert computed == [(0, 0, 0, 0)] and again.chunks_computed == 1
    direct = run_sweep(plan, scheduler="synchronous").dataset
    xr.testing.assert_equal(again.dataset[["fx", "fy", "adhesion", "error"]].compute(),
                            direct[["fx", "fy", "adhesion", "error"]])  # fmt: skip


def test_store_of_another_sweep_is_not_overwritten(tmp_path):
    out = tmp_path / "map.zarr"
    grid = {"creep_long": [0.01, 0.1], "water_flow": [0.0, 25.0]}
    fixed = {"normal_force": 4200.0, "speed": 5.0}
    run_sweep(WilacSweep(), grid, out, fixed=fixed)
    with pytest.raises(ValueError, match="holds a different sweep"):
        run_sweep(WilacSweep(), grid, out, fixed={**fixed, "speed": 10.0})
    res = run_sweep(WilacSweep(), grid, out, fixed={**fixed, "speed": 10.0}, overwrite=True)
    assert res.chunks_computed == 1 and json.loads(res.dataset.attrs["fixed_inputs"])["speed"] == 10
    (tmp_path / "other").mkdir()
    with pytest.raises(ValueError, match="not a sweep store"):
        run_sweep(WilacSweep(), grid, tmp_path / "other", fixed=fixed)


def test_netcdf_output_equals_in_memory(tmp_path):
    grid = {"creep_long": [0.01, 0.1, 0.5], "water_flow": [0.0, 25.0, 60.0]}
    fixed = {"normal_force": 4200.0, "speed": 5.0}
    mem = run_sweep(WilacSweep(), grid, fixed=fixed, chunks={"water_flow": 1}).dataset
    calls = []
    nc = run_sweep(WilacSweep(), grid, tmp_path / "m.nc", fixed=fixed, chunks={"water_flow": 1},
                   on_chunk=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    xr.testing.assert_identical(nc.dataset.load().drop_attrs(), mem.drop_attrs())
    nc.dataset.close()


def test_derived_quantities_match_numpy():
    ds = run_sweep(WilacSweep(), WILAC_GRID, chunk_points=200).dataset
    adh = ds.adhesion.values
    peak = max_adhesion(ds)
    np.testing.assert_array_equal(peak.adhesion_max.values, adh.max(axis=0))
    np.testing.assert_array_equal(peak.creep_long_at_max.values,
                                  WILAC_GRID["creep_long"][adh.argmax(axis=0)])  # fmt: skip
    low = min_adhesion_water_flow(ds)
    w = np.asarray(WILAC_GRID["water_flow"])
    np.testing.assert_array_equal(low.water_flow_at_min.transpose(*ds.adhesion.dims[:3]).values,
                                  w[adh.argmin(axis=3)])  # fmt: skip
    c = WILAC_GRID["creep_long"]
    at = adhesion_at_creep(ds, [c[4], 0.5 * (c[4] + c[5])])
    np.testing.assert_array_equal(at.isel(creep_long=0).values, adh[4])
    np.testing.assert_allclose(at.isel(creep_long=1).values, 0.5 * (adh[4] + adh[5]),
                               rtol=1e-12)  # fmt: skip
    with pytest.raises(ValueError, match="outside"):
        adhesion_at_creep(ds, 2.0)


def test_water_flow_of_minimum_adhesion_on_the_tram_rig():
    """The flow rate of minimum adhesion lies in 20-40 µl/s (seed 000, Fig. 8)."""
    ds = run_sweep(WilacSweep(), {"creep_long": [0.1, 0.3, 0.6],
                                  "water_flow": np.arange(0.0, 101.0, 1.0)},
                   fixed={"normal_force": 4200.0, "speed": 5.0}).dataset  # fmt: skip
    where = min_adhesion_water_flow(ds).water_flow_at_min.values
    assert np.all((where >= 20) & (where <= 40))


@pytest.mark.parametrize(
    "grid, fixed, match",
    [
        ({"creep": [0.1]}, {}, "grid.creep: not an input"),
        ({"creep_long": [0.1, 0.1]}, {"speed": 5, "normal_force": 4e3}, "creep_long: .*unique"),
        ({"creep_long": [0.1]}, {"speed": 5}, r"needs \['normal_force'\]"),
        ({"creep_long": [np.nan]}, {"speed": 5, "normal_force": 4e3}, "grid.creep_long: .*finite"),
        ({"creep_long": [0.1]}, {"speed": "x", "normal_force": 4e3}, "fixed.speed"),
        ({"parameter_set": ["nope"]}, {"speed": 5, "normal_force": 4e3, "creep_long": 0.1},
         "grid.parameter_set: unknown Polach parameter set"),
    ],
)
def test_bad_grids_name_the_field(grid, fixed, match):
    with pytest.raises(ValueError, match=match):
        plan_sweep(PolachSweep(), grid, fixed=fixed)


def test_default_chunks_keep_leading_dimensions_whole():
    plan = plan_sweep(WilacSweep(), WILAC_GRID, chunk_points=12 * 3 * 2)
    assert plan.chunk_shape == (12, 3, 2, 1)
    assert sum(1 for _ in plan.chunk_indices()) == plan.n_chunks == 2 * 6


def test_monte_carlo_design_equals_direct_calls(tmp_path):
    design = monte_carlo(40, seed=7, speed=("uniform", 2.5, 20.0),
                         normal_force=("choice", [4200.0, 7000.0]),
                         water_flow=("lognormal", 3.0, 1.0))  # fmt: skip
    again = monte_carlo(40, seed=7, speed=("uniform", 2.5, 20.0),
                        normal_force=("choice", [4200.0, 7000.0]),
                        water_flow=("lognormal", 3.0, 1.0))  # fmt: skip
    for name in ("speed", "normal_force", "water_flow"):
        np.testing.assert_array_equal(design["sample"][name], again["sample"][name])
    grid = {"creep_long": [0.02, 0.3], **design}
    res = run_sweep(WilacSweep(), grid, tmp_path / "mc.zarr", chunks={"sample": 7})
    ds = res.dataset.load()
    assert ds.adhesion.dims == ("creep_long", "sample") and res.chunks_total == 6
    assert ds.speed.dims == ("sample",) and ds.speed.attrs["units"] == "m/s"
    params = ra.default_wilac_parameters()
    for i in range(40):
        v, q, w = (float(design["sample"][k][i]) for k in ("speed", "normal_force", "water_flow"))
        a, b = contact_semi_axes("tram", q)
        fx, _ = ra.wilac_forces(0.3, 0.0, 0.0, q, v, a, b, w, params)
        _close(float(ds.fx.sel(creep_long=0.3, sample=i)), fx)


def _stop_task(speed, mu):
    """A stand-in task: the stopping distance v^2/(2 mu g) of a stop at constant mu."""
    if mu <= 0:
        raise ValueError(f"mu must be > 0, got {mu}")
    return speed**2 / (2 * mu * 9.81), speed / (mu * 9.81)


def test_task_function_over_a_scenario_design_records_failures():
    model = FunctionSweep(_stop_task, {"speed": None, "mu": None},
                          {"stopping_distance": "m", "stopping_time": "s"}, name="stop")
    ds = run_sweep(model, full_factorial(speed=[10.0, 20.0], mu=[0.0, 0.05, 0.1]),
                   chunk_points=4).dataset  # fmt: skip
    np.testing.assert_allclose(ds.stopping_distance.sel(mu=0.1).values,
                               [100 / 1.962, 400 / 1.962], rtol=1e-12)  # fmt: skip
    assert ds.stopping_time.attrs["units"] == "s"
    np.testing.assert_array_equal(ds.error.values, [[1, 0, 0], [1, 0, 0]])
    assert ds.attrs["model"] == "stop"
    with pytest.raises(ValueError, match="grid.sample.mu: 2 values"):
        plan_sweep(model, {"sample": {"speed": [1.0, 2.0, 3.0], "mu": [0.1, 0.2]}})
