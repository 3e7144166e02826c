"""CLI: railadhesion identify (outputs, summary, figures) and its errors."""

import json

import minisim
import numpy as np
import xarray as xr
from typer.testing import CliRunner

from railadhesion.cli import app
from railadhesion.identification import load_adhesion_law

runner = CliRunner()


def test_identify_writes_everything(tmp_path, mini_run, mini_vehicle):
    t, v, om, p, _ = mini_run
    k = slice(0, 4000)  # 9.6 s are enough here
    frame = minisim.log_frame(t[k], v[k], om[k], p[k], noise=(0.01, 0.02, 0.01))
    frame.loc[100, "wheel_speed_2"] = np.nan  # one defect, to be reported
    log = tmp_path / "log.csv"
    frame.to_csv(log, index=False)
    veh = tmp_path / "veh.toml"
    mini_vehicle.to_toml(veh)
    out = tmp_path / "out"
    res = runner.invoke(app, ["identify", str(log), "--vehicle", str(veh), "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "brake coefficient c" in res.output
    assert "missing-values wheel_speed_2" in res.output
    summary = json.loads((out / "summary.json").read_text())
    c = summary["brake_coefficient"]["mean_N_m_per_Pa"]
    assert abs(c / minisim.VEHICLE["brake_coefficient"] - 1) < 0.02
    assert summary["log_issues"] and summary["curves_absolute_slip"]
    ds = xr.load_dataset(out / "surface.nc")
    assert ds.sizes["speed"] == 40 and ds.sizes["slip"] == 40
    law = load_adhesion_law(out / "adhesion_law.toml")
    assert 0.05 < float(law(0.05, 20.0)) < 0.15
    for name in ("log", "brake_coefficient", "slip_adhesion_axle1", "adhesion_vs_slip",
                 "adhesion_vs_relative_slip", "surface"):
        assert (out / "figures" / f"{name}.png").stat().st_size > 1000
    assert (out / "windows.csv").exists()


def test_identify_errors(tmp_path):
    res = runner.invoke(app, ["identify", str(tmp_path / "x.csv"), "--vehicle", "coach_default",
                              "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "no such file" in res.output
