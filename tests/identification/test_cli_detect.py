"""CLI: railadhesion detect."""

import numpy as np
from typer.testing import CliRunner

from railadhesion.cli import app
from railadhesion.io.creepcurves import CreepCurve, write_creep_curve
from railadhesion.models.twod import fletcher_condition

runner = CliRunner()


def _curve(tmp_path, code, top):
    cond = fletcher_condition(code)
    xi = np.linspace(top / 40, top, 40)
    curve = CreepCurve(xi, cond.adhesion(xi), a=cond.half_width, name=code)
    return write_creep_curve(curve, tmp_path / f"{code}.csv")


def test_detect_low_adhesion_oil(tmp_path):
    path = _curve(tmp_path, "O1", 0.01)
    res = runner.invoke(app, ["detect", str(path)])
    assert res.exit_code == 0, res.output
    assert "mu = 0.055" in res.output
    assert "LOW" in res.output


def test_detect_normal_dry(tmp_path):
    path = _curve(tmp_path, "D3", 0.02)
    res = runner.invoke(app, ["detect", str(path)])
    assert res.exit_code == 0, res.output
    assert "NORMAL" in res.output


def test_detect_bad_file(tmp_path):
    res = runner.invoke(app, ["detect", str(tmp_path / "missing.csv")])
    assert res.exit_code == 2
    assert "error" in res.output
