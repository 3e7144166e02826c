"""The CLI is a thin shell: each command runs, prints real numbers, writes its figure."""

from __future__ import annotations

import re
from pathlib import Path

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


def _write_synthetic_curve(path, params, q, v, w, a=4e-3, b=3e-3):
    """A noise-free creep curve from known Polach parameters, in the documented CSV format."""
    import numpy as np

    from railadhesion.io.creepcurves import CreepCurve, write_creep_curve
    from railadhesion.models.polach import polach_forces

    creep = -np.geomspace(1e-3, 0.6, 25)
    fx, _ = polach_forces(creep, 0.0, 0.0, q, v, a, b, **params)
    curve = CreepCurve(creep, abs(fx) / q, normal_force=q, speed=v, water_flow=w, a=a, b=b,
                       name=path.stem)
    write_creep_curve(curve, path)


def test_fit_polach_recovers_parameters_and_writes_file(tmp_path):
    from railadhesion.io.paramfiles import load_polach_parameters

    truth = dict(k_A=0.6, k_S=0.2, mu0=0.35, A=0.5, B=0.4)
    csv = tmp_path / "curve.csv"
    _write_synthetic_curve(csv, truth, 50e3, 10.0, 0.0)
    out = tmp_path / "fitted.toml"
    result = _run("fit", "polach", str(csv), "--out", str(out))
    assert result.exit_code == 0, result.output
    fitted = load_polach_parameters(out)
    for key, value in truth.items():
        assert getattr(fitted, key) == pytest.approx(value, rel=1e-3)


def test_fit_polach_names_missing_metadata(tmp_path):
    csv = tmp_path / "bare.csv"
    csv.write_text("creep,adhesion\n-0.01,0.2\n-0.02,0.25\n-0.05,0.3\n")
    result = _run("fit", "polach", str(csv))
    assert result.exit_code == 2
    assert "normal_force_N" in result.output


def test_fit_wilac_builds_a_loadable_file(tmp_path):
    from railadhesion.io.paramfiles import load_wilac_parameters

    sets = {0.0: dict(k_A=1.0, k_S=0.4, mu0=0.45, A=0.4, B=0.6),
            25.0: dict(k_A=0.3, k_S=0.1, mu0=0.15, A=0.4, B=0.3),
            35.0: dict(k_A=0.3, k_S=0.1, mu0=0.2, A=0.8, B=0.2),
            350.0: dict(k_A=0.2, k_S=0.1, mu0=0.15, A=0.9, B=0.1)}
    folder = tmp_path / "curves"
    folder.mkdir()
    for w, params in sets.items():
        for q in (3000.0, 6000.0):
            _write_synthetic_curve(folder / f"w{w:g}_q{q:g}.csv", params, q, 5.0, w)
    out = tmp_path / "wilac.toml"
    result = _run("fit", "wilac", str(folder), "--out", str(out), "--speed-range", "2,10")
    assert result.exit_code == 0, result.output
    assert "WILAC calibration from 8 creep curves" in result.output
    params = load_wilac_parameters(out)
    dry = params.polach_parameters("dry", 4500.0, 5.0)
    assert float(dry["mu0"]) == pytest.approx(0.45, rel=1e-3)


# ---- audit: user errors exit with code 2 and a message, never a traceback


def _assert_user_error(result, *fragments):
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    assert "Traceback" not in result.output
    assert not isinstance(result.exception, Exception) or isinstance(
        result.exception, SystemExit
    ), repr(result.exception)
    text = " ".join(result.output.split())  # Rich wraps long lines
    for fragment in fragments:
        assert fragment in text, (fragment, result.output)


@pytest.mark.parametrize(
    "args",
    [
        ["wilac", "curves"],
        ["wilac", "weights"],
        ["wilac", "water"],
        ["wilac", "speeds"],
        ["wilac", "table"],
    ],
)
def test_wilac_commands_with_a_missing_params_file(tmp_path, args):
    missing = tmp_path / "missing.toml"
    extra = [] if args[1] == "table" else ["--out", str(tmp_path / "x.png")]
    result = _run(*args, "--params", str(missing), *extra)
    _assert_user_error(result, "--params: cannot read", "missing.toml")


@pytest.mark.parametrize("name", ["no_such_dir/x.png", "x.unknownformat"])
def test_figure_that_cannot_be_written(tmp_path, name):
    blocker = tmp_path / "no_such_dir"
    blocker.write_text("a file where a folder is needed")
    result = _run("wilac", "weights", "--out", str(tmp_path / name))
    _assert_user_error(result, "cannot write the figure to")


def test_error_messages_keep_their_brackets(tmp_path):
    # Rich took "[low, high]" for markup and dropped it from the printed message
    bad = tmp_path / "bad.toml"
    bad.write_text(
        (Path(__file__).parent / "io" / "data" / "wilac_example.toml")
        .read_text(encoding="utf-8")
        .replace("speed_range_m_s = [1.0, 40.0]", "speed_range_m_s = [1.0, 40.0, 50.0]"),
        encoding="utf-8",
    )
    result = _run("params", "check", str(bad))
    _assert_user_error(result, "validity.speed_range_m_s: expected [low, high] (2 numbers)")


def test_fit_polach_on_a_degenerate_curve_names_the_file(tmp_path):
    csv = tmp_path / "flat.csv"
    csv.write_text(
        "# normal_force_N = 4200\n# speed_m_s = 5\n# a_m = 0.004\n# b_m = 0.003\n"
        "creep,adhesion\n" + "".join(f"{-0.01 * (i + 1)},0.1\n" for i in range(8))
    )
    result = _run("fit", "polach", str(csv))
    _assert_user_error(result, "flat.csv: adhesion is the same (0.1) at all 8 points")


def test_fit_polach_unreadable_csv(tmp_path):
    csv = tmp_path / "utf16.csv"
    csv.write_text("creep,adhesion\n-0.01,0.2\n", encoding="utf-16")
    _assert_user_error(_run("fit", "polach", str(csv)), "utf16.csv: not a UTF-8 text file")
    _assert_user_error(_run("fit", "polach", str(tmp_path / "nope.csv")), "cannot read")


def test_fit_output_that_cannot_be_written(tmp_path):
    truth = dict(k_A=0.6, k_S=0.2, mu0=0.35, A=0.5, B=0.4)
    csv = tmp_path / "curve.csv"
    _write_synthetic_curve(csv, truth, 50e3, 10.0, 0.0)
    out = tmp_path / "missing_dir" / "fitted.toml"
    result = _run("fit", "polach", str(csv), "--fit", "mu0", "--out", str(out))
    _assert_user_error(result, "cannot write the parameter file")


def test_demo_with_an_unusable_output_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    result = _run("demo", "--out", str(blocker / "sub"))
    _assert_user_error(result, "cannot write the demo figures")


@pytest.mark.parametrize(
    "command",
    [[], ["demo"], ["hertz"], ["polach"], ["wilac"], ["wilac", "curves"], ["wilac", "weights"],
     ["wilac", "water"], ["wilac", "speeds"], ["wilac", "table"], ["params"], ["params", "list"],
     ["params", "check"], ["fit"], ["fit", "polach"], ["fit", "wilac"]],
)  # fmt: skip
def test_help_of_every_command(command):
    result = _run(*command, "--help")
    assert result.exit_code == 0, result.output
    assert "Usage" in result.output
