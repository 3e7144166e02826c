"""CLI: railadhesion monitor LOG --vehicle V --out DIR (outputs, figures, messages, errors)."""

import json

import pandas as pd
from typer.testing import CliRunner

from railadhesion.cli import app

runner = CliRunner()


def _csv(sig, path, stop=None):
    stop = stop or sig["time"].size
    data = {"time": sig["time"][:stop], "train_speed": sig["train_speed"][:stop]}
    for i in range(4):
        data[f"wheel_speed_{i + 1}"] = sig["wheel_speed"][:stop, i]
        data[f"brake_pressure_{i + 1}"] = sig["brake_pressure"][:stop, i] / 1e5
    pd.DataFrame(data).to_csv(path, index=False)


def test_monitor_writes_series_events_summary_and_figures(tmp_path, low_run):
    log = tmp_path / "log.csv"
    _csv(low_run, log)
    out = tmp_path / "out"
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default",
                              "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "axle 1:" in res.output and "low episode(s), first at" in res.output
    assert "radius 0.4" in res.output and "learned" in res.output
    frame = pd.read_parquet(out / "monitor.parquet")
    assert len(frame) == low_run["time"].size
    assert frame["level_1"].iloc[-1] == "low"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["axles"][0]["low_episodes"] >= 1
    assert summary["settings"]["threshold"] == 0.14
    events = pd.read_csv(out / "events.csv")
    assert (events["level"] == "low").any()
    for name in ("estimate_along_track", "levels"):
        assert (out / "figures" / f"{name}.png").stat().st_size > 5000


def test_monitor_without_coasting_says_why(tmp_path, low_run):
    """A log that starts braking: the radii cannot be learned, every level stays unknown, and
    the command says so (and how to take the vehicle's radius instead)."""
    sub = {k: (v[1200:] if hasattr(v, "shape") and v.shape[:1] == low_run["time"].shape
               else v) for k, v in low_run.items()}
    sub["time"] = sub["time"] - sub["time"][0] + 2.4e-3
    log = tmp_path / "braking.csv"
    _csv(sub, log)
    out = tmp_path / "out"
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default", "--out",
                              str(out), "--no-figures", "--threshold", "0.1"])
    assert res.exit_code == 0, res.output
    assert "no wheel radius was learned" in res.output
    assert not (out / "figures").exists()
    frame = pd.read_parquet(out / "monitor.parquet")
    assert (frame["level_2"] == "unknown").all()
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default", "--out",
                              str(out), "--no-figures", "--no-learn-radius"])
    assert res.exit_code == 0 and "no wheel radius was learned" not in res.output


def test_monitor_errors(tmp_path):
    res = runner.invoke(app, ["monitor", str(tmp_path / "none.csv"), "--vehicle",
                              "coach_default"])
    assert res.exit_code == 2 and "no such file" in res.output
    log = tmp_path / "x.csv"
    pd.DataFrame({"time": [0.0, 0.1], "train_speed": [1.0, 1.0],
                  "wheel_speed_1": [1.0, 1.0]}).to_csv(log, index=False)
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default", "--out",
                              str(tmp_path / "o")])
    assert res.exit_code == 2 and "1 axles but the vehicle" in res.output
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default", "--threshold",
                              "-1"])
    assert res.exit_code == 2 and "threshold must be in" in res.output


def test_monitor_sniffs_units_and_exits_3(tmp_path, low_run):
    """A train speed in km/h: the warning identify gives, the replay not trusted (exit 3,
    outputs written), --allow-untrusted accepts it."""
    log = tmp_path / "kmh.csv"
    sub = dict(low_run, train_speed=low_run["train_speed"] * 3.6)
    _csv(sub, log, stop=3000)
    out = tmp_path / "out"
    args = ["monitor", str(log), "--vehicle", "coach_default", "--out", str(out), "--no-figures"]
    res = runner.invoke(app, args)
    assert res.exit_code == 3, res.output
    assert "train_speed in km/h" in res.stderr and "warning" not in res.stdout
    assert "monitor replay not trusted: " in res.stderr and "kmh.csv: train_speed" in res.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["trusted"] is False and "km/h" in summary["warnings"][0]
    res = runner.invoke(app, [*args, "--allow-untrusted"])
    assert res.exit_code == 0 and "accepted with --allow-untrusted" in res.stderr


def test_monitor_time_in_ms_and_empty_log(tmp_path, low_run):
    log = tmp_path / "ms.csv"
    _csv(dict(low_run, time=low_run["time"] * 1e3), log, stop=3000)
    res = runner.invoke(app, ["monitor", str(log), "--vehicle", "coach_default", "--out",
                              str(tmp_path / "o"), "--no-figures"])
    assert res.exit_code == 3 and "time in ms?" in res.stderr
    empty = tmp_path / "empty.csv"
    empty.write_text("time,train_speed,wheel_speed_1,brake_pressure_1\n")
    res = runner.invoke(app, ["monitor", str(empty), "--vehicle", "coach_default", "--out",
                              str(tmp_path / "e")])
    assert res.exit_code == 2
    assert res.stderr.startswith("error: ") and "the log has no samples" in res.stderr
