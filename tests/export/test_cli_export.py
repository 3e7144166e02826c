"""``railadhesion export fmu|table`` from the command line."""

from __future__ import annotations

import zipfile
from xml.etree import ElementTree as ET

import pytest
from typer.testing import CliRunner

from railadhesion.cli import app
from railadhesion.io.paramfiles import save_polach_parameters
from railadhesion.models import polach_parameters

pytest.importorskip("pythonfmu")
runner = CliRunner()


def test_export_fmu_writes_a_valid_fmu(tmp_path):
    out = tmp_path / "wet.fmu"
    result = runner.invoke(
        app, ["export", "fmu", "--python", "--model", "polach", "--set", "polach2005_wet",
              "--out", str(out)]
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "passes FMPy's validation" in result.output
    assert "Python FMU: the host needs a Python" in " ".join(result.output.split())
    assert "polach2005_wet" in result.output
    with zipfile.ZipFile(out) as z:
        assert "resources/parameters.toml" in z.namelist()
        description = ET.fromstring(z.read("modelDescription.xml")).get("description")
    assert "'polach2005_wet' (built-in named Polach set)" in description


def test_export_fmu_default_wilac_embeds_the_package_file(tmp_path):
    from importlib import resources

    out = tmp_path / "w.fmu"
    result = runner.invoke(app, ["export", "fmu", "--python", "--out", str(out)])
    assert result.exit_code == 0, result.output
    package_file = resources.files("railadhesion").joinpath("data", "wilac_default.toml")
    with zipfile.ZipFile(out) as z:
        assert z.read("resources/parameters.toml") == package_file.read_bytes()


def test_export_fmu_embeds_a_parameter_file(tmp_path):
    path = save_polach_parameters(polach_parameters("polach2005_dry").replace(name="mine"),
                                  tmp_path / "mine.toml")  # fmt: skip
    out = tmp_path / "mine.fmu"
    result = runner.invoke(
        app, ["export", "fmu", "--python", "--model", "polach", "--params", str(path),
              "--out", str(out)]
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    with zipfile.ZipFile(out) as z:
        assert z.read("resources/parameters.toml") == path.read_bytes()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--model", "fletcher"], "model must be one of"),
        (["--model", "polach", "--set", "nope"], "parameter_set must be one of"),
        (["--model", "wilac", "--params", "missing.toml"], "cannot read"),
        (["--model", "polach", "--out", "x.zip"], "ending in .fmu"),
    ],
)
def test_export_fmu_user_errors_exit_2(args, message, tmp_path):
    result = runner.invoke(app, ["export", "fmu", *args])
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())


def test_export_table_writes_netcdf_and_csv_and_reports_the_error(tmp_path):
    out = tmp_path / "t.nc"
    result = runner.invoke(
        app,
        ["export", "table", "--model", "wilac", "--out", str(out),
         "--creep-long-percent=-10,-1,0,1,10", "--creep-lat-percent", "0,1",
         "--normal-force", "20000,80000", "--speed", "10", "--water", "0,20,60"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "= 60 points" in text
    assert "interpolation error at 8 cell midpoints" in text and "Fx max" in text
    assert out.is_file() and out.with_suffix(".csv").is_file()


def test_export_table_rejects_bad_grids(tmp_path):
    result = runner.invoke(
        app, ["export", "table", "--model", "polach", "--speed", "10,5", "--no-csv",
              "--out", str(tmp_path / "t.nc")],
    )  # fmt: skip
    assert result.exit_code == 2
    assert "speed: grid values must be strictly increasing" in " ".join(result.output.split())
    result = runner.invoke(app, ["export", "table", "--speed", "ten"])
    assert result.exit_code == 2
    assert "--speed: expected numbers" in result.output


def _native_possible():
    import sys

    from railadhesion.export.native import find_c_compiler

    return sys.platform.startswith("linux") and find_c_compiler() is not None


@pytest.mark.skipif(not _native_possible(), reason="native FMUs need Linux and a C compiler")
def test_export_fmu_native_writes_a_valid_native_fmu(tmp_path):
    out = tmp_path / "n.fmu"
    result = runner.invoke(app, ["export", "fmu", "--native", "--model", "polach", "--out",
                                 str(out)])  # fmt: skip
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "passes FMPy's validation" in text and "needs no Python on the host" in text
    with zipfile.ZipFile(out) as z:
        names = z.namelist()
    assert "binaries/linux64/railadhesion_polach.so" in names
    assert "sources/railadhesion_polach.ll" in names and "sources/ra_fmi2.c" in names


@pytest.mark.skipif(not _native_possible(), reason="native FMUs need Linux and a C compiler")
def test_export_fmu_is_native_by_default(tmp_path):
    out = tmp_path / "d.fmu"
    result = runner.invoke(app, ["export", "fmu", "--model", "polach", "--set",
                                 "polach2005_dry", "--out", str(out)])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "needs no Python on the host" in " ".join(result.output.split())
    with zipfile.ZipFile(out) as z:
        assert "binaries/linux64/railadhesion_polach.so" in z.namelist()


def test_export_fmu_default_falls_back_to_the_python_fmu_and_says_why(tmp_path, monkeypatch):
    monkeypatch.setenv("CC", "/nonexistent/cc")
    out = tmp_path / "f.fmu"
    result = runner.invoke(app, ["export", "fmu", "--model", "polach", "--out", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "no native FMU:" in text and "writing the Python FMU instead" in text
    assert "Python FMU: the host needs a Python" in text
    with zipfile.ZipFile(out) as z:
        assert "resources/parameters.toml" in z.namelist()


def test_export_fmu_native_without_a_compiler_says_so(tmp_path, monkeypatch):
    monkeypatch.setenv("CC", "/nonexistent/cc")
    out = tmp_path / "n.fmu"
    result = runner.invoke(app, ["export", "fmu", "--native", "--out", str(out)])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "no C compiler found" in text and "the Python FMU remains available" in text
    assert not out.exists()
