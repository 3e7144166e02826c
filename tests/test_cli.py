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


# ---- issue 9, item 8: help texts, output files, warnings, geometry, params, version, exports


def test_help_texts_keep_units_in_brackets():
    result = _run("hertz", "--help")
    text = " ".join(result.output.split())
    assert "Wheel rolling radius [m]" in text
    assert "Rail (or roller) rolling radius [m]" in text
    result = _run("wilac", "curves", "--help")
    assert "[m/s]" in result.output


def test_version():
    import railadhesion

    result = _run("--version")
    assert result.exit_code == 0
    assert result.output.strip() == f"railadhesion {railadhesion.__version__}"


def test_out_without_extension_names_the_file_written(tmp_path):
    out = tmp_path / "noext"
    result = _run("wilac", "weights", "--out", str(out))
    assert result.exit_code == 0, result.output
    assert (tmp_path / "noext.png").stat().st_size > 1000
    assert "noext.png" in " ".join(result.output.split()).replace(" ", "")


def _write_curve_with_bad_row(path):
    path.write_text(
        "# normal_force_N = 4200\n# speed_m_s = 5\n# a_m = 0.004\n# b_m = 0.003\n"
        "creep,adhesion\n-0.001,0.05\n-0.01,0.2\nabc,0.3\n-0.02,0.25\n-0.05,0.27\n"
        "-0.1,0.26\n-0.2,0.24\n-0.3,0.23\n",
        encoding="utf-8",
    )


def test_warnings_are_plain_lines_without_source_location(tmp_path):
    csv_path = tmp_path / "curve.csv"
    _write_curve_with_bad_row(csv_path)
    result = _run("fit", "polach", str(csv_path), "--fit", "mu0,k_A", "--allow-untrusted")
    assert result.exit_code == 0, result.output
    assert "warning:" in result.output
    assert ".py:" not in result.output and "warnings.warn" not in result.output
    assert "creepcurves" not in result.output


def test_polach_geometry_is_settable_and_printed():
    loco = _run("polach", "--creep-percent", "1", "--format", "csv")
    tram = _run("polach", "--creep-percent", "1", "--geometry", "tram", "--format", "csv")
    given = _run("polach", "--creep-percent", "1", "--a", "0.004", "--b", "0.003",
                 "--format", "csv")  # fmt: skip
    values = [float(r.output.strip().splitlines()[1].split(",")[2]) for r in (loco, tram, given)]
    assert len(set(values)) == 3  # three contacts, three adhesions
    table = _run("polach", "--creep-percent", "1", "--geometry", "tram")
    text = " ".join(table.output.split())
    assert "contact: tram" in text and "a = " in text and "b = " in text
    bad = _run("polach", "--geometry", "metro")
    assert bad.exit_code == 2 and "locomotive" in bad.output
    half = _run("polach", "--a", "0.004")
    assert half.exit_code == 2 and "--b" in half.output


def test_polach_rejects_creep_beyond_100_percent():
    result = _run("polach", "--creep-percent", "1,150")
    assert result.exit_code == 2
    assert "[-100, 100]" in result.output


def test_params_check_on_wilac_prints_provenance(tmp_path):
    from importlib import resources

    path = resources.files("railadhesion").joinpath("data", "wilac_default.toml")
    result = _run("params", "check", str(path))
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "reconstruction: YES" in text
    assert "source:" in text and "speed range:" in text


def test_params_list_lists_wilac_sets_and_fletcher_conditions():
    result = _run("params", "list")
    assert result.exit_code == 0, result.output
    text = result.output
    assert "polach2005_dry" in text and "WILAC" in text and "default" in text
    for code in ("W1", "D3", "O1"):
        assert code in text
    fletcher = _run("params", "list", "--kind", "fletcher", "--format", "csv")
    rows = fletcher.output.strip().splitlines()
    assert rows[0].startswith("test_code,lubricant") and len(rows) == 11
    both = _run("params", "list", "--format", "csv")
    assert both.exit_code == 2 and "--kind" in both.output


@pytest.mark.parametrize(
    "args",
    [["hertz"], ["polach", "--creep-percent", "1,2"], ["wilac", "table", "--water", "0,25"],
     ["params", "list", "--kind", "polach"]],
)  # fmt: skip
def test_every_table_command_exports_csv_and_json(tmp_path, args):
    import csv as csvmod
    import json

    as_json = _run(*args, "--format", "json")
    assert as_json.exit_code == 0, as_json.output
    records = json.loads(as_json.output)
    assert isinstance(records, list) and records and isinstance(records[0], dict)
    out = tmp_path / "table.csv"
    written = _run(*args, "--out", str(out))
    assert written.exit_code == 0, written.output
    rows = list(csvmod.DictReader(out.open(encoding="utf-8")))
    assert len(rows) == len(records)
    assert set(rows[0]) == set(records[0])


def test_fit_polach_states_fixed_values_sets_them_and_writes_figure(tmp_path):
    csv_path = tmp_path / "c.csv"
    params = dict(k_A=0.6, k_S=0.2, mu0=0.35, A=0.4, B=0.5)
    _write_synthetic_curve(csv_path, params, 4200.0, 5.0, 0.0)
    fig = tmp_path / "fit.png"
    result = _run("fit", "polach", str(csv_path), "--fit", "k_A,k_S,mu0", "--figure", str(fig))
    # constant friction (A = 1, B = 0 held) cannot follow the falling curve: not trusted
    assert result.exit_code == 3, result.output
    assert "Polach fit not trusted" in result.output
    result = _run("fit", "polach", str(csv_path), "--fit", "k_A,k_S,mu0", "--figure", str(fig),
                  "--allow-untrusted")  # fmt: skip
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "not fitted, held at A = 1, B = 0 (model defaults" in text
    assert fig.stat().st_size > 1000
    good = _run("fit", "polach", str(csv_path), "--fit", "k_A,k_S,mu0", "--fixed", "A=0.4,B=0.5",
                "--format", "json")  # fmt: skip
    assert good.exit_code == 0, good.output
    import json

    table = {r["parameter"]: r for r in json.loads(good.output.split("\nnote:")[0])}
    assert table["A"]["value"] == 0.4 and table["A"]["fitted"].startswith("no")
    assert table["mu0"]["value"] == pytest.approx(0.35, rel=1e-3)
    clash = _run("fit", "polach", str(csv_path), "--fit", "A,mu0", "--fixed", "A=0.4")
    assert clash.exit_code == 2 and "fitted or fixed" in clash.output


def test_fit_wilac_knobs_and_per_curve_csv(tmp_path):
    sets = {0.0: dict(k_A=1.0, k_S=0.4, mu0=0.45, A=0.4, B=0.6),
            25.0: dict(k_A=0.3, k_S=0.1, mu0=0.15, A=0.4, B=0.3),
            35.0: dict(k_A=0.3, k_S=0.1, mu0=0.2, A=0.8, B=0.2),
            350.0: dict(k_A=0.2, k_S=0.1, mu0=0.15, A=0.9, B=0.1)}  # fmt: skip
    folder = tmp_path / "curves"
    folder.mkdir()
    for w, params in sets.items():
        for q in (3000.0, 6000.0):
            _write_synthetic_curve(folder / f"w{w:g}_q{q:g}.csv", params, q, 5.0, w)
    table = tmp_path / "curves.csv"
    result = _run("fit", "wilac", str(folder), "--out", str(tmp_path / "w.toml"),
                  "--speed-range", "2,10", "--criterion", "bic", "--max-terms", "2",
                  "--no-refine", "--table", str(table))  # fmt: skip
    assert result.exit_code == 0, result.output
    lines = table.read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("curve,condition,normal_force_N") and len(lines) == 9
    bad = _run("fit", "wilac", str(folder), "--criterion", "adjusted")
    assert bad.exit_code == 2 and "criterion" in bad.output
