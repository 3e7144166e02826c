"""Braking studies: stops of the braking simulator over factorial and Monte Carlo designs."""

import math

import numpy as np
import pytest
from typer.testing import CliRunner

braking = pytest.importorskip("railadhesion.braking")

from railadhesion.cli import app  # noqa: E402
from railadhesion.sweeps import SpecError, monte_carlo, run_sweep  # noqa: E402
from railadhesion.sweeps.study import (  # noqa: E402
    BrakingStudy,
    load_study_spec,
    plot_extension_distribution,
)

FAST = {"dt": 5e-3, "max_time": 60.0}  # the WSP period (5 ms) is a multiple of dt


def _direct(speed, water, pressure=5.5e5, wsp=True):
    veh = braking.load_vehicle("coach_default")
    ctrl = braking.WheelSlideProtection() if wsp else None
    res = braking.simulate(veh, braking.WilacAdhesion(water), speed, pressure, wsp=ctrl,
                           cylinders=braking.BrakeCylinders(max_pressure=6e5),  # the study's
                           **FAST)  # fmt: skip
    return res.stopping_distance, res.summary["longest_lock_s"]


def test_study_values_equal_direct_simulations():
    model = BrakingStudy(**FAST)
    grid = {"water_flow": [0.0, 25.0], "initial_speed": [4.0, 6.0]}
    d0 = {v: _direct(v, 0.0)[0] for v in grid["initial_speed"]}
    ds = run_sweep(model, grid, fixed={"wsp": 1.0}, chunk_points=2).dataset
    assert ds.stopping_distance.attrs["units"] == "m" and ds.initial_speed.attrs["units"] == "m/s"
    for w in grid["water_flow"]:
        for v in grid["initial_speed"]:
            d, lock = _direct(v, w)
            point = ds.sel(water_flow=w, initial_speed=v)
            assert float(point.stopping_distance) == pytest.approx(d, rel=1e-12)
            assert float(point.longest_lock) == pytest.approx(lock, rel=1e-12, abs=1e-12)
            assert float(point.extension) == pytest.approx(d - d0[v], rel=1e-9, abs=1e-9)
            assert float(point.stopped) == 1.0
    # the dry stop is its own reference
    np.testing.assert_array_equal(ds.extension.sel(water_flow=0.0).values, 0.0)
    # a longer stop from a higher speed
    assert (ds.stopping_distance.sel(initial_speed=6.0) > ds.stopping_distance.sel(
        initial_speed=4.0)).all()


def test_monte_carlo_study_is_reproducible_and_failures_are_recorded():
    model = BrakingStudy(**FAST)
    design = monte_carlo(4, seed=3, initial_speed=("uniform", 3.0, 6.0),
                         water_flow=("choice", [0.0, 25.0]))  # fmt: skip
    again = monte_carlo(4, seed=3, initial_speed=("uniform", 3.0, 6.0),
                        water_flow=("choice", [0.0, 25.0]))  # fmt: skip
    np.testing.assert_array_equal(design["sample"]["initial_speed"],
                                  again["sample"]["initial_speed"])  # fmt: skip
    ds = run_sweep(model, {**design, "wsp": [1.0, 2.0]}, chunk_points=3).dataset
    assert ds.stopping_distance.dims == ("sample", "wsp")
    assert ds.error.sel(wsp=2.0).all() and not ds.error.sel(wsp=1.0).any()
    assert ds.stopping_distance.sel(wsp=2.0).isnull().all()
    fig = plot_extension_distribution(ds.sel(wsp=[1.0]), bins=2)
    assert fig.axes[0].get_ylabel().startswith("stopping-distance extension")


GOOD = """
format = "railadhesion-study"
format_version = 1
title = "tiny"

[study]
vehicle = "coach_default"
dt = 0.005
max_time = 60.0

[design]
kind = "factorial"

[grid]
water_flow = [0.0, 25.0]
initial_speed = [4.0]

[fixed]
brake_pressure = 5.5e5
"""


@pytest.mark.parametrize(
    "old, new, field",
    [
        ('kind = "factorial"', 'kind = "random"', "design.kind"),
        ('kind = "factorial"', 'kind = "monte_carlo"', "design.n"),
        ('kind = "factorial"', 'kind = "factorial"\nseed = 1', "design.seed"),
        ("dt = 0.005", "dt = -1.0", "study.dt"),
        ('vehicle = "coach_default"', 'vehicle = "tram9"', "study"),
        ("initial_speed = [4.0]", "initial_sped = [4.0]", "grid.initial_sped"),
        ("brake_pressure = 5.5e5", "brake_pressure = 'high'", "fixed.brake_pressure"),
        ("[fixed]", "[fixed]\ncreep_long = 0.1", "fixed.creep_long"),
    ],
)
def test_bad_study_specs_name_the_field(tmp_path, old, new, field):
    path = tmp_path / "study.toml"
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(SpecError) as info:
        load_study_spec(path)
    assert str(info.value).startswith("study.toml: ") and field in str(info.value)


def test_monte_carlo_spec(tmp_path):
    text = GOOD.replace('kind = "factorial"', 'kind = "monte_carlo"\nn = 5\nseed = 2').replace(
        "initial_speed = [4.0]", "").replace("water_flow = [0.0, 25.0]", "") + (
        '\n[distributions]\ninitial_speed = ["uniform", 3.0, 6.0]\n'
        'water_flow = ["choice", [0.0, 15.0, 25.0]]\n')  # fmt: skip
    path = tmp_path / "mc.toml"
    path.write_text(text)
    spec = load_study_spec(path)
    assert spec.plan().dims == ("sample",) and spec.plan().size == 5
    bad = text.replace('["uniform", 3.0, 6.0]', '["uniform", 3.0]')
    path.write_text(bad)
    with pytest.raises(SpecError, match="distributions.initial_speed"):
        load_study_spec(path)


def test_cli_study_writes_results_and_figure(tmp_path):
    spec = tmp_path / "study.toml"
    spec.write_text(GOOD)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["study", str(spec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "failed stops: 0" in result.output and "Stopping-distance extension" in result.output
    for name in ("study.zarr", "study.csv", "extension.png"):
        assert (out / name).exists()
    import pandas as pd

    table = pd.read_csv(out / "study.csv")
    assert len(table) == 2 and math.isclose(table.extension[table.water_flow == 0].item(), 0.0)


def test_example_study_spec_loads():
    from pathlib import Path

    spec = load_study_spec(Path(__file__).resolve().parents[2] / "examples" /
                           "braking_study.toml")  # fmt: skip
    assert spec.plan().dims == ("water_flow", "initial_speed")
