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
