"""pandas Series and xarray DataArray through every public model function (issue 9, item 6).

Each function is called once with NumPy arrays and once with labelled inputs; the labelled
results must be Series (index kept) or DataArrays (dims and coords kept), with the NumPy
values, and units in attrs where the function declares them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import railadhesion as ra
from railadhesion.contact import (
    combined_elastic_constants,
    contact_semi_axes,
    hertz_3d_from_curvatures,
    line_contact_from_pressure,
)
from railadhesion.models import creep_from_surface_speeds, wilac_transitions

CREEP = np.array([-0.002, -0.01, -0.05, -0.2])
INDEX = pd.Index([0.0, 0.5, 1.0, 1.5], name="time_s")
A, B = contact_semi_axes("tram", 4200.0)
WILAC = ra.default_wilac_parameters()

# name -> (function of one varying array argument x, x values, result fields to compare)
CASES = {
    "adhesion": (lambda x: ra.adhesion(x, 0.5 * x, 1e4), np.array([1.0, 2.0, 3.0, 4.0])),
    "polach_forces": (lambda x: ra.polach_forces(x, 0.0, 0.0, 4200.0, 5.0, A, B, mu0=0.4),
                      CREEP),
    "polach_forces_mu0": (lambda x: ra.polach_forces(-0.05, 0.0, 0.0, 4200.0, 5.0, A, B, mu0=x),
                          np.array([0.1, 0.2, 0.3, 0.4])),
    "wilac_forces": (lambda x: ra.wilac_forces(x, 0.0, 0.0, 4200.0, 5.0, A, B, 25.0, WILAC),
                     CREEP),
    "wilac_forces_water": (
        lambda x: ra.wilac_forces(-0.05, 0.0, 0.0, 4200.0, 5.0, A, B, x, WILAC),
        np.array([0.0, 25.0, 35.0, 350.0]),
    ),
    "Wilac.adhesion": (lambda x: ra.Wilac().adhesion(x, 0.0, 0.0, 4200.0, 5.0, A, B, 25.0),
                       CREEP),
    "Polach.forces": (lambda x: ra.Polach("polach2005_dry").forces(x, 0, 0, 1e5, 10.0, A, B),
                      CREEP),
    "wilac_weights": (lambda x: ra.wilac_weights(x), np.array([0.0, 25.0, 35.0, 350.0])),
    "wilac_transitions": (lambda x: wilac_transitions(x), np.array([0.0, 25.0, 35.0, 350.0])),
    "carter": (lambda x: ra.carter(x, 1e6, 2e-4, 0.0235, 0.3), CREEP / 10),
    "fletcher": (lambda x: ra.fletcher(x, 1e6, 2e-4, 0.0235, 0.3, 0.5, 0.8), CREEP / 10),
    "elastic_foundation": (lambda x: ra.elastic_foundation(x, 1e6, 2e-4, 0.0235, 0.3),
                           CREEP / 10),
    "creep_from_surface_speeds": (lambda x: creep_from_surface_speeds(x, 10.0),
                                  np.array([9.0, 9.5, 10.0, 10.5])),
    "linear_creep_forces": (lambda x: ra.linear_creep_forces(x, 0.0, 0.0, A, B, 8e10, 0.28),
                            CREEP / 10),
    "kalker_coefficients": (lambda x: ra.kalker_coefficients(x, 0.28),
                            np.array([0.3, 0.5, 1.0, 2.0])),
    "hertz_3d": (lambda x: ra.hertz_3d(x, 0.625, np.inf, 0.3),
                 np.array([5e4, 8e4, 1e5, 1.2e5])),
    "hertz_3d_from_curvatures": (lambda x: hertz_3d_from_curvatures(x, 0.8, 1.7),
                                 np.array([5e4, 8e4, 1e5, 1.2e5])),
    "line_contact": (lambda x: ra.line_contact(x, 0.0235), np.array([1e5, 2e5, 3e5, 4e5])),
    "line_contact_from_pressure": (lambda x: line_contact_from_pressure(x, 0.0235),
                                   np.array([5e8, 8e8, 1e9, 1.3e9])),
    "combined_elastic_constants": (lambda x: combined_elastic_constants(x, 0.28, 2.0e11, 0.3),
                                   np.array([1.9e11, 2.0e11, 2.1e11, 2.2e11])),
    "fastsim": (lambda x: ra.fastsim(x, 0.0, 0.0, 8e4, 8e-3, 4e-3, 0.3, nx=10, ny=10),
                CREEP / 100),
}  # fmt: skip


def _leaves(result):
    """(name, value) of every array-like part of a result (tuples, named tuples, objects)."""
    if isinstance(result, tuple) and hasattr(result, "_fields"):
        return list(zip(result._fields, result, strict=True))
    if isinstance(result, tuple):
        return [(str(i), v) for i, v in enumerate(result)]
    if hasattr(result, "__dataclass_fields__"):
        return [(f, getattr(result, f)) for f in result.__dataclass_fields__]
    return [("", result)]


@pytest.mark.parametrize("name", sorted(CASES))
def test_series_round_trip(name):
    func, x = CASES[name]
    plain = _leaves(func(x))
    labelled = _leaves(func(pd.Series(x, index=INDEX, name="x")))
    n_labelled = 0
    for (field, want), (_, got) in zip(plain, labelled, strict=True):
        if not isinstance(want, np.ndarray) or want.shape[-1:] != x.shape:
            continue  # grid fields etc. stay NumPy
        n_labelled += 1
        assert isinstance(got, pd.Series | pd.DataFrame), (name, field, type(got))
        assert got.index.equals(INDEX), (name, field)
        np.testing.assert_allclose(got.to_numpy().T, want, rtol=1e-12, err_msg=field)
    assert n_labelled >= 1, name


@pytest.mark.parametrize("name", sorted(CASES))
def test_dataarray_round_trip(name):
    func, x = CASES[name]
    plain = _leaves(func(x))
    arr = xr.DataArray(x, dims="sample", coords={"sample": ["p", "q", "r", "s"]})
    labelled = _leaves(func(arr))
    n_labelled = 0
    for (field, want), (_, got) in zip(plain, labelled, strict=True):
        if not isinstance(want, np.ndarray) or want.shape[-1:] != x.shape:
            continue
        n_labelled += 1
        assert isinstance(got, xr.DataArray), (name, field, type(got))
        assert got.dims[-1] == "sample"
        assert list(got.coords["sample"].values) == ["p", "q", "r", "s"]
        np.testing.assert_allclose(got.to_numpy(), want, rtol=1e-12, err_msg=field)
    assert n_labelled >= 1, name


def test_units_and_leading_axes():
    w = pd.Series([0.0, 25.0, 350.0], index=pd.Index(["a", "b", "c"], name="site"))
    weights = ra.wilac_weights(w)
    assert isinstance(weights, pd.DataFrame)
    assert list(weights.columns) == ["dry", "damp2", "damp1", "wet"]
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-12)
    fx, fy = ra.polach_forces(pd.Series(CREEP), 0, 0, 4200.0, 5.0, A, B, mu0=0.4)
    assert fx.attrs["units"] == "N" and fy.attrs["units"] == "N"
    da = ra.wilac_weights(xr.DataArray([0.0, 30.0], dims="w"))
    assert da.dims == ("condition", "w")
    assert list(da.coords["condition"].values) == ["dry", "damp2", "damp1", "wet"]
    res = ra.fletcher(xr.DataArray(CREEP / 10, dims="c"), 1e6, 2e-4, 0.0235, 0.3)
    assert res.traction.attrs["units"] == "N/m" and res.stick_half_width.attrs["units"] == "m"
    h = ra.hertz_3d(pd.Series([5e4, 1e5]), 0.625, np.inf, 0.3)
    assert h.max_pressure.attrs["units"] == "Pa" and h.a.name == "a"


def test_dataarrays_broadcast_by_dimension_name():
    creep = xr.DataArray(CREEP, dims="creep")
    water = xr.DataArray([0.0, 25.0, 350.0], dims="water")
    fx, _ = ra.wilac_forces(creep, 0.0, 0.0, 4200.0, 5.0, A, B, water, WILAC)
    assert fx.dims == ("creep", "water") and fx.shape == (4, 3)
    want, _ = ra.wilac_forces(CREEP[:, None], 0, 0, 4200.0, 5.0, A, B,
                              np.array([0.0, 25.0, 350.0])[None, :], WILAC)  # fmt: skip
    np.testing.assert_allclose(fx.to_numpy(), want)


def test_scalars_and_arrays_unchanged():
    fx, _ = ra.polach_forces(-0.01, 0.0, 0.0, 4200.0, 5.0, A, B, mu0=0.4)
    assert isinstance(fx, float | np.floating)
    fx, _ = ra.polach_forces(CREEP, 0.0, 0.0, 4200.0, 5.0, A, B, mu0=0.4)
    assert type(fx) is np.ndarray


def test_mismatched_labels_are_refused():
    s1 = pd.Series(CREEP, index=[0, 1, 2, 3])
    s2 = pd.Series([4e3] * 4, index=[1, 2, 3, 4])
    with pytest.raises(ValueError, match="share one index"):
        ra.polach_forces(s1, 0.0, 0.0, s2, 5.0, A, B, mu0=0.4)
    with pytest.raises(ValueError, match="do not mix"):
        ra.polach_forces(s1, 0.0, 0.0, xr.DataArray(4e3), 5.0, A, B, mu0=0.4)
    d1 = xr.DataArray(CREEP, dims="x", coords={"x": [0, 1, 2, 3]})
    d2 = xr.DataArray(CREEP, dims="x", coords={"x": [5, 6, 7, 8]})
    with pytest.raises(ValueError, match="same coordinates"):
        ra.polach_forces(d1, d2, 0.0, 4200.0, 5.0, A, B, mu0=0.4)
    with pytest.raises(ValueError, match="DataFrame is not accepted"):
        ra.adhesion(pd.DataFrame({"fx": [1.0]}), 0.0, 1.0)
    with pytest.raises(ValueError, match="normal_force"):  # validation still names the argument
        ra.adhesion(pd.Series([1.0, 2.0]), 0.0, pd.Series([1.0, -1.0]))


def test_signature_and_doc_kept():
    import inspect

    assert "mu0" in inspect.signature(ra.polach_forces).parameters
    assert "Polach" in ra.polach_forces.__doc__
    assert ra.polach_forces.__wrapped__.__name__ == "polach_forces"


def test_creep_curve_and_fit_as_dataframe_and_dataset():
    from railadhesion.calibration import fit_polach
    from railadhesion.io import CreepCurve

    fx, _ = ra.polach_forces(CREEP, 0, 0, 4200.0, 5.0, A, B, mu0=0.4, k_A=0.6, k_S=0.2)
    curve = CreepCurve(CREEP, np.abs(fx) / 4200.0, normal_force=4200.0, speed=5.0,
                       water_flow=25.0, a=A, b=B, name="rig")  # fmt: skip
    df = curve.to_dataframe()
    np.testing.assert_array_equal(df["creep"], CREEP)
    assert df.attrs["normal_force_N"] == 4200.0 and df.attrs["units"]["adhesion"] == "1"
    ds = curve.to_dataset()
    np.testing.assert_array_equal(ds["adhesion"].to_numpy(), curve.adhesion)
    assert ds["creep"].attrs["units"] == "1" and ds.attrs["speed_m_s"] == 5.0
    fit = fit_polach(curve.creep, curve.adhesion, normal_force=4200.0, speed=5.0, a=A, b=B,
                     fit=("mu0",), initial={"k_A": 0.6, "k_S": 0.2})  # fmt: skip
    fdf = fit.to_dataframe()
    np.testing.assert_allclose(fdf["model"], fit.predict(), atol=1e-12)
    np.testing.assert_allclose(fdf["model"] - fdf["adhesion"], fdf["residual"])
    assert fdf.attrs["params"]["mu0"] == pytest.approx(0.4, rel=1e-6)


# ---- units in attrs: one table over every labelled output of every public function (issue 18)

_TWOD = {"traction": "N/m", "stick": "N/m", "slip": "N/m", "stick_half_width": "m"}
_HERTZ = {"a": "m", "b": "m", "max_pressure": "Pa", "approach": "m", "curvature_A": "1/m",
          "curvature_B": "1/m", "mean_radius": "m", "c": "m", "normal_force": "N",
          "effective_modulus": "Pa"}  # fmt: skip
_LINE = {"half_width": "m", "max_pressure": "Pa", "load_per_length": "N/m",
         "reduced_radius": "m", "effective_modulus": "Pa"}  # fmt: skip
W1 = ra.fletcher_condition("W1")

# qualified name -> (call with the varying labelled argument x, x, expected units by field:
# "" for a single result, the index for plain tuples, the field name otherwise)
UNITS = {
    "railadhesion.contact.traction.adhesion": (*CASES["adhesion"], {"": "1"}),
    "railadhesion.models.polach.polach_forces": (*CASES["polach_forces"], {"0": "N", "1": "N"}),
    "railadhesion.models.polach.Polach.forces": (*CASES["Polach.forces"], {"0": "N", "1": "N"}),
    "railadhesion.models.polach.Polach.adhesion": (
        lambda x: ra.Polach("polach2005_dry").adhesion(x, 0, 0, 1e5, 10.0, A, B), CREEP,
        {"": "1"}),
    "railadhesion.models.wilac.wilac_forces": (*CASES["wilac_forces"], {"0": "N", "1": "N"}),
    "railadhesion.models.wilac.Wilac.forces": (
        lambda x: ra.Wilac().forces(x, 0, 0, 4200.0, 5.0, A, B, 25.0), CREEP,
        {"0": "N", "1": "N"}),
    "railadhesion.models.wilac.Wilac.adhesion": (*CASES["Wilac.adhesion"], {"": "1"}),
    "railadhesion.models.wilac.Wilac.weights": (
        lambda x: ra.Wilac().weights(x), np.array([0.0, 25.0, 35.0, 350.0]), {"": "1"}),
    "railadhesion.models.wilac_parameters.wilac_weights": (*CASES["wilac_weights"], {"": "1"}),
    "railadhesion.models.wilac_parameters.wilac_transitions": (*CASES["wilac_transitions"],
                                                               {"": "1"}),
    "railadhesion.models.twod.carter": (*CASES["carter"], _TWOD),
    "railadhesion.models.twod.fletcher": (*CASES["fletcher"], _TWOD),
    "railadhesion.models.twod.elastic_foundation": (*CASES["elastic_foundation"], _TWOD),
    "railadhesion.models.twod.creep_from_surface_speeds": (*CASES["creep_from_surface_speeds"],
                                                           {"": "1"}),
    "railadhesion.models.twod.FletcherCondition.traction": (lambda x: W1.traction(x),
                                                            CREEP / 10, _TWOD),
    "railadhesion.models.twod.FletcherCondition.adhesion": (lambda x: W1.adhesion(x),
                                                            CREEP / 10, {"": "1"}),
    "railadhesion.models.twod.FletcherCondition.elastic_foundation_adhesion": (
        lambda x: W1.elastic_foundation_adhesion(x), CREEP / 10, {"": "1"}),
    "railadhesion.contact.kalker.kalker_coefficients": (
        *CASES["kalker_coefficients"], {"c11": "1", "c22": "1", "c23": "1", "c33": "1"}),
    "railadhesion.contact.kalker.linear_creep_forces": (
        *CASES["linear_creep_forces"], {"0": "N", "1": "N", "2": "N m"}),
    "railadhesion.contact.hertz.hertz_3d": (*CASES["hertz_3d"], _HERTZ),
    "railadhesion.contact.hertz.hertz_3d_from_curvatures": (*CASES["hertz_3d_from_curvatures"],
                                                            _HERTZ),
    "railadhesion.contact.hertz.line_contact": (*CASES["line_contact"], _LINE),
    "railadhesion.contact.hertz.line_contact_from_pressure": (
        *CASES["line_contact_from_pressure"], _LINE),
    "railadhesion.contact.hertz.combined_elastic_constants": (
        *CASES["combined_elastic_constants"], {"0": "Pa", "1": "Pa", "2": "1"}),
    "railadhesion.contact.fastsim.fastsim": (
        *CASES["fastsim"], {"fx": "N", "fy": "N", "mz": "N m", "slip_fraction": "1"}),
}  # fmt: skip


def _labelled_outputs(result):
    """(field, value) of every labelled part of a result."""
    out = []
    for name, value in _leaves(result):
        if isinstance(value, pd.Series | pd.DataFrame | xr.DataArray):
            out.append(("" if name == "" else name, value))
    return out


@pytest.mark.parametrize("kind", ["pandas", "xarray"])
@pytest.mark.parametrize("name", sorted(UNITS))
def test_units_in_attrs_of_every_labelled_output(name, kind):
    """Every labelled output of every public function carries the right units, on the pandas
    path as on the xarray one (the fields a call does not label, e.g. grids, are skipped)."""
    func, x, units = UNITS[name]
    if kind == "pandas":
        arg = pd.Series(x, index=INDEX)
    else:
        arg = xr.DataArray(x, dims="sample", coords={"sample": ["p", "q", "r", "s"]})
    outputs = _labelled_outputs(func(arg))
    assert outputs, name
    for field, value in outputs:
        assert value.attrs.get("units") == units[field], (name, kind, field, value.attrs)


def _labelled_functions():
    """Qualified names of every function and method that the ``labelled`` decorator wraps,
    found by walking the package (the wrappers' code is generated as ``<labelled ...>``)."""
    import importlib
    import inspect
    import pkgutil

    found = set()
    for info in pkgutil.walk_packages(ra.__path__, "railadhesion."):
        if info.name.rsplit(".", 1)[-1].startswith("_") or "export.railadhesion_" in info.name:
            continue
        module = importlib.import_module(info.name)
        for obj_name, obj in vars(module).items():
            if getattr(obj, "__module__", None) != module.__name__ or obj_name.startswith("_"):
                continue
            members = [(obj_name, obj)]
            if inspect.isclass(obj):
                members = [(f"{obj_name}.{k}", v) for k, v in vars(obj).items()
                           if callable(v) and not k.startswith("_")]  # fmt: skip
            for qual, fn in members:
                code = getattr(fn, "__code__", None)
                if code is not None and code.co_filename.startswith("<labelled "):
                    found.add(f"{module.__name__}.{qual}")
    return found


def test_the_units_table_covers_every_labelled_function():
    missing = _labelled_functions() - set(UNITS)
    assert not missing, f"add these to UNITS with their units: {sorted(missing)}"
