"""The table model of Kalker's exact theory as a sweep model (ExactTableSweep)."""

import numpy as np
import pytest

import railadhesion as ra
from railadhesion.contact import exact_table_forces
from railadhesion.contact.geometry import contact_semi_axes
from railadhesion.sweeps import ExactTableSweep, SpecError, load_sweep_spec, run_sweep, sweep_model

GRID = {"creep_long": [-0.05, 0.0, 3e-4, 0.002, 0.2], "creep_lat": [0.0, 0.003],
        "spin": [0.0, 0.4], "parameter_set": ["polach2005_dry", "polach2005_wet"]}


def _close(got, want):
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize(("options", "coulomb"), [({}, False), ({"friction": "coulomb"}, True)])
def test_table_map_equals_exact_table_forces(options, coulomb):
    model = sweep_model("table", geometry="locomotive", **options)
    assert isinstance(model, ExactTableSweep) and model.name == "table"
    assert model.inputs == sweep_model("polach").inputs  # the inputs of the Polach map
    fixed = {"normal_force": 106.7e3, "speed": 12.0}
    ds = run_sweep(model, GRID, fixed=fixed, chunks={"creep_long": 2}).dataset
    a, b = contact_semi_axes("locomotive", 106.7e3)
    for i, c in enumerate(GRID["creep_long"]):
        for j, e in enumerate(GRID["creep_lat"]):
            for k, s in enumerate(GRID["spin"]):
                for m, name in enumerate(GRID["parameter_set"]):
                    p = ra.polach_parameters(name)
                    law = dict(friction_ratio=1.0, friction_decay=0.0) if coulomb else dict(
                        friction_ratio=p.A, friction_decay=p.B)
                    fx, fy, _ = exact_table_forces(c, e, s, 106.7e3, a, b, p.mu0, speed=12.0,
                                                   **law)
                    point = ds.isel(creep_long=i, creep_lat=j, spin=k, parameter_set=m)
                    _close(float(point.fx), fx)
                    _close(float(point.fy), fy)
                    _close(float(point.adhesion), np.hypot(fx, fy) / 106.7e3)
    assert ds.attrs["model"] == "table" and "Kalker" in ds.attrs["model_description"]


def test_given_friction_replaces_the_sets():
    model = sweep_model("table", geometry=(6e-3, 8e-3), mu=0.2, friction_ratio=0.5,
                        friction_decay=1.0)
    values = {"creep_long": np.array([1e-3, 0.05]), "creep_lat": 0.0, "spin": 0.0,
              "normal_force": 5e4, "speed": 20.0}
    fx, fy, adh = model.evaluate(values, {"parameter_set": "polach2005_dry"})
    want = exact_table_forces(values["creep_long"], 0.0, 0.0, 5e4, 6e-3, 8e-3, 0.2,
                              speed=20.0, friction_ratio=0.5, friction_decay=1.0)
    _close(fx, want[0])
    assert model.describe()["mu"] == 0.2


@pytest.mark.parametrize(("options", "name"), [
    ({"friction": "dry"}, "friction"), ({"mu": -0.3}, "mu"), ({"friction_ratio": 2.0},
                                                               "friction_ratio"),
    ({"friction_decay": -1.0}, "friction_decay"), ({"poisson": 0.35}, "poisson"),
    ({"geometry": (0.02, 0.002)}, "geometry"),
    ({"friction": "coulomb", "friction_decay": 0.5}, "friction_ratio"),
])
def test_bad_options_name_the_option(options, name):
    with pytest.raises(ValueError, match=f"^{name}:"):
        sweep_model("table", **options)


SPEC = """
format = "railadhesion-sweep"
format_version = 1
[model]
name = "table"
parameters = "polach2005_wet"
geometry = "tram"
{extra}
[grid]
creep_long = {{ start = 0.001, stop = 0.5, num = 4, spacing = "log" }}
speed = [5.0, 10.0]
[fixed]
normal_force = 4200.0
"""


def test_spec_file_picks_the_table_model(tmp_path):
    path = tmp_path / "t.toml"
    path.write_text(SPEC.format(extra='friction = "coulomb"\nmu = 0.25'))
    spec = load_sweep_spec(path)
    assert isinstance(spec.model, ExactTableSweep) and spec.model.law(None) == (0.25, 1.0, 0.0)
    path.write_text(SPEC.format(extra="friction_ratio = 7.0"))
    with pytest.raises(SpecError, match="model.friction_ratio"):
        load_sweep_spec(path)
