"""What the command line prints where: output on stdout, messages on stderr, each once; a
closed pipe; tables that fit a narrow terminal; short help lines."""

from __future__ import annotations

import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from rich.console import Console
from typer.testing import CliRunner

from railadhesion.cli import app

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[1]


def _run(*args: str):
    return runner.invoke(app, list(args))


def test_warnings_go_to_stderr_so_csv_output_parses():
    result = _run("polach", "--speed", "200", "--creep-percent", "1", "--format", "csv")
    assert result.exit_code == 0, result.output
    rows = list(csv.reader(io.StringIO(result.stdout)))
    assert rows[0] == ["creep_percent", "fx_kN", "adhesion"] and len(rows) == 2
    assert "warning" not in result.stdout
    assert result.stderr.startswith("warning: speed = 200 m/s is outside")


def test_warnings_go_to_stderr_so_json_output_parses():
    result = _run("polach", "--speed", "200", "--creep-percent", "1,2", "--format", "json")
    assert result.exit_code == 0, result.output
    assert [r["creep_percent"] for r in json.loads(result.stdout)] == [1.0, 2.0]
    assert "given in km/h?" in result.stderr


def test_errors_go_to_stderr_on_one_line():
    result = _run("polach", "--set", "no_such_set")
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1


def test_each_warning_is_printed_once():
    result = _run("wilac", "table", "--normal-force", "4.2", "--format", "csv")
    assert result.exit_code == 0, result.output
    assert result.stderr.count("normal_force = 4.2 N is outside the plausible range") == 1
    assert "warning" not in result.stdout
    # the next run of the same command (same process) prints its warning again
    again = _run("wilac", "table", "--normal-force", "4.2", "--format", "csv")
    assert again.stderr.count("normal_force = 4.2 N is outside the plausible range") == 1


def _polach_curve_csv(path, q, a, b, speed_in_file):
    """A creep-curve file of Polach's dry set at 10 m/s, whose header gives ``speed_in_file``."""
    from railadhesion.models.parameters import polach_parameters
    from railadhesion.models.polach import Polach

    creep = -np.geomspace(0.002, 0.4, 20)
    fx, _ = Polach(polach_parameters("polach2005_dry")).forces(creep, 0.0, 0.0, q, 10.0, a, b)
    path.write_text(f"# normal_force_N = {q}\n# speed_m_s = {speed_in_file}\n# a_m = {a}\n"
                    f"# b_m = {b}\ncreep,adhesion\n"
                    + "".join(f"{c},{abs(f) / q}\n" for c, f in zip(creep, fx, strict=True)))
    return path


def test_fit_polach_warns_once_of_an_implausible_speed_in_the_file(tmp_path):
    path = _polach_curve_csv(tmp_path / "kmh.csv", 4500.0, 0.004, 0.003, 300)
    result = _run("fit", "polach", str(path), "--format", "csv", "--allow-untrusted")
    assert result.exit_code == 0, result.output
    # once as a warning (the "not trusted" line then quotes it as the first reason)
    assert result.stderr.count("warning: speed = 300 m/s is outside") == 1
    assert list(csv.reader(io.StringIO(result.stdout)))[0] == ["parameter", "value", "stderr",
                                                                "fitted"]


def test_brake_error_has_no_blank_line_before_it(tmp_path):
    scenario = ROOT / "examples" / "brake_dry.toml"
    result = _run("brake", str(scenario), "--out", str(tmp_path / "o"), "--dt", "0.1")
    assert result.exit_code == 2, result.output
    assert "error: the control period" in result.stderr
    assert "\n\n" not in "\n" + result.output and not result.output.startswith("\n")


def test_a_closed_pipe_ends_quietly_with_code_141():
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "railadhesion", "params", "list"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.close()  # the reader goes away before the first line (| head -0)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 141, err
    assert "Traceback" not in err and "Exception ignored" not in err


def test_wsp_results_table_keeps_every_number_at_80_columns():
    from railadhesion.cli_wsp import results_tables

    case = {"name": "mu050-040-noisy", "status": "ok", "stopping_distance_m": 126.8637,
            "distance_ratio": 0.99642, "distance_vs_no_wsp": 1.00315,
            "extension_vs_dry_percent": 271.85, "longest_lock_s": 1.114,
            "deep_slide_s": 15.872, "mean_creep": 0.64115, "vented_air_l": 746.23,
            "passed": False}
    longer = dict(case, name="a-much-longer-case-name-of-a-user-programme",
                  stopping_distance_m=12345.67)
    error = {"name": "broken", "status": "error", "message": "x"}
    for width in (80, 60):
        console = Console(file=io.StringIO(), width=width)
        for table in results_tables("default — ThresholdWSP", [case, longer, error], console):
            console.print(table)
        text = console.file.getvalue()
        assert "…" not in text
        for number in ("126.9", "12345.7", "0.996", "1.003", "272", "1.11", "15.87", "0.641",
                       "746"):
            assert number in text, (width, number, text)
        assert max(len(line) for line in text.splitlines()) <= width
    wide = Console(file=io.StringIO(), width=200)
    assert len(results_tables("t", [case], wide)) == 1


def test_wilac_help_lists_whole_summaries():
    result = _run("wilac", "--help")
    assert result.exit_code == 0
    text = " ".join(result.output.split())
    assert "(paper Fig." + " " not in text.replace("(paper Fig. 7)", "").replace(
        "(paper Fig. 8)", "")
    for summary in ("Creep curves at several water flow rates (paper Fig. 7).",
                    "Blending weights f_i(w) and transitions e_i(w) (paper Figs. 5, 6).",
                    "Adhesion against water flow rate at fixed creepages (paper Fig. 8).",
                    "Creep curves at several speeds (paper Figs. 9 and 11).",
                    "WILAC adhesion over water flow rate and creep (tram rig)."):
        assert summary in text, (summary, result.output)


def test_polach_set_takes_the_file_fit_polach_writes(tmp_path):
    from railadhesion.io.paramfiles import save_polach_parameters
    from railadhesion.models.parameters import polach_parameters

    mine = polach_parameters("polach2005_wet").replace(name="", mu0=0.2)
    path = tmp_path / "fitted.toml"
    save_polach_parameters(mine, path)
    result = _run("polach", "--set", str(path), "--creep-percent", "40", "--format", "json")
    assert result.exit_code == 0, result.output
    named = _run("polach", "--set", "polach2005_wet", "--creep-percent", "40", "--format",
                 "json")
    mu_file = json.loads(result.stdout)[0]["adhesion"]
    mu_named = json.loads(named.stdout)[0]["adhesion"]
    assert mu_file < mu_named  # mu0 0.2 against the wet set's own
    table = _run("polach", "--set", str(path), "--creep-percent", "40")
    assert "Polach 'fitted.toml' at Q = 110000 N" in table.stdout


def test_polach_set_errors_say_how_to_give_ones_own_parameters(tmp_path):
    unknown = _run("polach", "--set", "my_set")
    assert unknown.exit_code == 2
    assert "or give a Polach parameter file" in unknown.stderr
    missing = _run("polach", "--set", str(tmp_path / "missing.toml"))
    assert missing.exit_code == 2 and "--set: cannot read" in missing.stderr
    wilac = tmp_path / "w.toml"
    wilac.write_text((ROOT / "tests" / "io" / "data" / "wilac_example.toml").read_text())
    wrong = _run("polach", "--set", str(wilac))
    assert wrong.exit_code == 2 and "expected 'railadhesion-polach'" in wrong.stderr


def test_files_written_are_said_on_stderr_so_stdout_stays_csv(tmp_path):
    curve = _polach_curve_csv(tmp_path / "curve.csv", 50e3, 0.006, 0.005, 10)
    params, figure = tmp_path / "fitted.toml", tmp_path / "fit.png"
    result = _run("fit", "polach", str(curve), "--format", "csv", "--out", str(params),
                  "--figure", str(figure), "--allow-untrusted")
    assert result.exit_code == 0, result.output
    rows = list(csv.reader(io.StringIO(result.stdout)))
    assert rows[0] == ["parameter", "value", "stderr", "fitted"] and len(rows) == 6
    assert "figure written to" in result.stderr and figure.is_file()
    assert "parameters written to" in result.stderr and params.is_file()
