"""Sweep spec files: the shipped example, field-by-field validation, and the CLI."""

import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from railadhesion.cli import app
from railadhesion.sweeps import SpecError, WilacSweep, load_sweep_spec, run_sweep

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "wilac_map.toml"

GOOD = """
format = "railadhesion-sweep"
format_version = 1
title = "small"

[model]
name = "wilac"
parameters = "default"
geometry = "tram"

[grid]
creep_long = { start = 0.01, stop = 0.5, num = 4, spacing = "log" }
water_flow = { start = 0.0, stop = 50.0, step = 25.0 }
speed = [5.0, 10.0]

[fixed]
normal_force = 4200.0

[chunks]
water_flow = 1
"""


def _write(tmp_path, text, name="spec.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_example_spec_is_a_wilac_map_over_creep_speed_load_water():
    spec = load_sweep_spec(EXAMPLE)
    plan = spec.plan()
    assert plan.dims == ("creep_long", "speed", "normal_force", "water_flow")
    assert isinstance(plan.model, WilacSweep) and plan.n_chunks > 1
    assert plan.coords[0][0] == pytest.approx(0.001) and plan.coords[3][-1] == 100.0


def test_spec_ranges_and_run_equal_python_api(tmp_path):
    spec = load_sweep_spec(_write(tmp_path, GOOD))
    np.testing.assert_allclose(spec.grid["creep_long"], np.geomspace(0.01, 0.5, 4))
    assert spec.grid["water_flow"] == [0.0, 25.0, 50.0]
    res = spec.run(tmp_path / "m.zarr")
    assert res.dataset.attrs["title"] == "small" and res.chunks_computed == 3
    direct = run_sweep(WilacSweep(), spec.grid, fixed={"normal_force": 4200.0}).dataset
    xr.testing.assert_equal(res.dataset.adhesion.load(), direct.adhesion)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ('format_version = 1', 'format_version = 2', "format_version"),
        ('name = "wilac"', 'name = "wilak"', "model.name"),
        ('geometry = "tram"', 'geometry = "bus"', "model.geometry"),
        ('geometry = "tram"', 'geometry = [0.001, -1.0]', "model.geometry"),
        ('geometry = "tram"', 'condition = "W1"', "model.condition"),
        ('parameters = "default"', 'parameters = "missing.toml"', "model.parameters"),
        ("num = 4,", 'num = "ten",', "grid.creep_long.num"),
        ('spacing = "log"', 'spacing = "cubic"', "grid.creep_long.spacing"),
        ("start = 0.01", "start = 0.0", "grid.creep_long.start"),
        ("step = 25.0", "step = -25.0", "grid.water_flow.step"),
        ("speed = [5.0, 10.0]", 'speed = [5.0, "fast"]', "grid.speed[1]"),
        ("speed = [5.0, 10.0]", "speed = [5.0, 5.0]", "grid.speed"),
        ("speed = [5.0, 10.0]", "sped = [5.0, 10.0]", "grid.sped"),
        ("normal_force = 4200.0", "normal_force = true", "fixed.normal_force"),
        ("normal_force = 4200.0", "", "normal_force"),
        ("water_flow = 1", "water_flow = 0", "chunks.water_flow"),
        ("water_flow = 1", "creep = 2", "chunks.creep"),
        ('title = "small"', 'titel = "small"', "titel"),
    ],
)
def test_bad_spec_errors_name_the_field(tmp_path, old, new, field):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(SpecError) as info:
        load_sweep_spec(path)
    message = str(info.value)
    assert message.startswith("spec.toml: ")
    assert field in message, message


def test_spec_that_is_not_toml(tmp_path):
    with pytest.raises(SpecError, match="not valid TOML"):
        load_sweep_spec(_write(tmp_path, "[model\nname = 1"))


def test_parameter_file_relative_to_the_spec(tmp_path):
    from railadhesion.io.paramfiles import save_polach_parameters
    from railadhesion.models.parameters import polach_parameters

    (tmp_path / "sets").mkdir()
    save_polach_parameters(polach_parameters("polach2005_wet"), tmp_path / "sets" / "wet.toml")
    text = GOOD.replace('name = "wilac"', 'name = "polach"').replace(
        'parameters = "default"', 'parameters = "sets/wet.toml"').replace(
        "water_flow = { start = 0.0, stop = 50.0, step = 25.0 }", "").replace(
        "water_flow = 1", "speed = 1")  # fmt: skip
    spec = load_sweep_spec(_write(tmp_path, text))
    assert spec.model.resolve("parameter_set", spec.model.parameters).k_A == 0.3


runner = CliRunner()


def test_cli_sweep_writes_and_resumes(tmp_path):
    spec = _write(tmp_path, GOOD)
    out = tmp_path / "map.zarr"
    result = runner.invoke(app, ["sweep", str(spec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "3 chunks computed" in result.output and "failed points: 0" in result.output
    # interrupted run: one marker lost -> only that chunk is recomputed
    next((out / ".sweep" / "chunks").glob("*.json")).unlink()
    result = runner.invoke(app, ["sweep", str(spec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "resuming: 2 of 3 chunks" in result.output and "1 chunks computed" in result.output
    assert xr.open_zarr(out).attrs["complete"] == 1


def test_cli_sweep_bad_spec_names_the_field(tmp_path):
    spec = _write(tmp_path, GOOD.replace('spacing = "log"', 'spacing = "cubic"'))
    result = runner.invoke(app, ["sweep", str(spec), "--out", str(tmp_path / "m.zarr")])
    assert result.exit_code == 2
    assert "grid.creep_long.spacing" in result.output
    assert not (tmp_path / "m.zarr").exists()


def test_cli_sweep_refuses_a_different_store(tmp_path):
    out = tmp_path / "map.zarr"
    assert runner.invoke(app, ["sweep", str(_write(tmp_path, GOOD)), "--out", str(out)]
                         ).exit_code == 0  # fmt: skip
    other = _write(tmp_path, GOOD.replace("speed = [5.0, 10.0]", "speed = [5.0, 20.0]"), "b.toml")
    result = runner.invoke(app, ["sweep", str(other), "--out", str(out)])
    assert result.exit_code == 2 and "different sweep" in result.output
    result = runner.invoke(app, ["sweep", str(other), "--out", str(out), "--overwrite"])
    assert result.exit_code == 0, result.output
    shutil.rmtree(out)
