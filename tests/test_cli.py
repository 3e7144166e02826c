"""The CLI is a thin shell: each command runs, prints real numbers, writes its figure."""

from __future__ import annotations

import re

import pytest
from typer.testing import CliRunner

from railadhesion.cli import app

runner = CliRunner()


def _run(*args):
    result = runner.invoke(app, list(args))
    return result


def test_hertz_prints_semi_axes():
    result = _run("hertz", "--normal-force", "82000")
    assert result.exit_code == 0, result.output
    assert "a (rolling direction)" in result.output
    numbers = re.findall(r"\d+\.\d+", result.output)
    assert numbers


def test_hertz_rejects_negative_force():
    result = _run("hertz", "--normal-force", "-1")
    assert result.exit_code == 2
    assert "normal_force" in result.output


def test_polach_curve_table_and_figure(tmp_path):
    out = tmp_path / "polach.png"
    result = _run(
        "polach", "--set", "polach2005_wet", "--creep-percent", "0.5,5", "--out", str(out)
    )
    assert result.exit_code == 0, result.output
    assert out.stat().st_size > 1000
    assert "polach2005_wet" in result.output


def test_polach_unknown_set_names_valid_ones():
    result = _run("polach", "--set", "nonsense")
    assert result.exit_code == 2
    assert "polach2005_dry" in result.output


def test_bad_number_list_is_reported():
    result = _run("polach", "--creep-percent", "1,abc")
    assert result.exit_code != 0
    assert "--creep-percent" in result.output


@pytest.mark.parametrize("command", ["curves", "weights", "water", "speeds"])
def test_wilac_figures(tmp_path, command):
    out = tmp_path / f"{command}.png"
    result = _run("wilac", command, "--out", str(out))
    assert result.exit_code == 0, result.output
    assert out.stat().st_size > 1000


def test_wilac_curves_with_water_list(tmp_path):
    out = tmp_path / "fig.png"
    result = _run("wilac", "curves", "--water", "0,25,35,350", "--out", str(out))
    assert result.exit_code == 0, result.output
    assert out.exists()


def test_wilac_table_prints_low_adhesion_at_25_ul_s():
    result = _run("wilac", "table", "--water", "25", "--creep-percent", "60,90")
    assert result.exit_code == 0, result.output
    values = [float(x) for x in re.findall(r"0\.\d{3}", result.output)]
    assert values and all(0.03 < v < 0.1 for v in values)


def test_params_list_shows_sources():
    result = _run("params", "list")
    assert result.exit_code == 0, result.output
    assert "polach2005_dry" in result.output


def test_params_check_reports_bad_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('format = "railadhesion-wilac"\nformat_version = 99\n')
    result = _run("params", "check", str(bad))
    assert result.exit_code == 2
    assert "format_version" in result.output


def test_demo_runs(tmp_path):
    result = _run("demo", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    assert "CONTACT" in result.output
    assert sorted(p.name for p in tmp_path.glob("*.png"))
