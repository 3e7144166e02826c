"""Replay of a CSV or Parquet log through the monitor: rows as recorded, nothing dropped."""

from __future__ import annotations

import json
import warnings

import monitor_signals as ms
import numpy as np
import pandas as pd
import pytest

from railadhesion.monitor import AdhesionMonitor, read_monitor_log, replay_log
from railadhesion.monitor.replay import monitor_log_frame
from railadhesion.plausibility import UnitWarning


def _frame(sig, stop=None, torque=False):
    stop = stop or sig["time"].size
    data = {"time": sig["time"][:stop], "train_speed": sig["train_speed"][:stop]}
    for i in range(4):
        data[f"wheel_speed_{i + 1}"] = sig["wheel_speed"][:stop, i]
    for i in range(4):
        if torque:
            data[f"torque_{i + 1}"] = sig["torque"][:stop, i]
        else:
            data[f"brake_pressure_{i + 1}"] = sig["brake_pressure"][:stop, i] / 1e5  # bar
    return pd.DataFrame(data)


@pytest.fixture(scope="module")
def log_files(low_run, tmp_path_factory):
    folder = tmp_path_factory.mktemp("logs")
    frame = _frame(low_run)
    frame.to_csv(folder / "log.csv", index=False, float_format="%.17g")
    frame.to_parquet(folder / "log.parquet", index=False)
    return folder, frame


def test_replay_is_the_per_sample_monitor(low_run, log_files):
    """The compiled replay loop and the per-sample call run the same step: same outputs."""
    folder, frame = log_files
    rep = replay_log(folder / "log.csv", "coach_default")
    mon = AdhesionMonitor("coach_default")
    ref = ms.feed(mon, {"time": frame["time"].to_numpy(),
                        "train_speed": frame["train_speed"].to_numpy(),
                        "wheel_speed": frame[[f"wheel_speed_{i}" for i in range(1, 5)]].to_numpy(),
                        "brake_pressure": frame[[f"brake_pressure_{i}" for i in range(1, 5)]]
                        .to_numpy() * 1e5, "torque": np.full((len(frame), 4), np.nan)})
    for i in range(4):
        np.testing.assert_array_equal(rep.frame[f"level_{i + 1}"].cat.codes.to_numpy(),
                                      ref["level"][:, i])
        np.testing.assert_array_equal(rep.frame[f"estimate_{i + 1}"].to_numpy(),
                                      ref["estimate"][:, i].astype(np.float32))
    assert (rep.frame["level_1"].iloc[-1]) == "low"
    assert len(rep.frame) == len(frame)


def test_csv_and_parquet_give_the_same_replay(log_files):
    folder, _ = log_files
    a = replay_log(folder / "log.csv", "coach_default")
    b = replay_log(folder / "log.parquet", "coach_default")
    pd.testing.assert_frame_equal(a.frame, b.frame)
    assert a.summary["axles"] == b.summary["axles"]


def test_torque_columns_for_traction(tmp_path):
    sig = ms.make_signals(ms.braking_profile(level=0.045), duration=10.0, shape="polach",
                          slope=40.0, mu=0.07, traction=True, seed=7)
    path = tmp_path / "traction.csv"
    _frame(sig, torque=True).to_csv(path, index=False)
    log = read_monitor_log(path)
    assert log.has_torque.all() and not log.has_pressure.any()
    rep = replay_log(log, "coach_default")
    assert rep.frame["level_2"].iloc[-1] == "low"
    assert rep.frame["adhesion_used_2"].iloc[-1] < 0
    assert rep.summary["channels"]["torque"] == [True] * 4


def test_missing_channel_unknown_columns_and_bad_cells(low_run, tmp_path):
    frame = _frame(low_run, stop=3000).drop(columns=["brake_pressure_3"])
    frame["comment"] = "x"
    frame["train_speed"] = frame["train_speed"].astype(object)
    frame.loc[2000, "train_speed"] = "fast"
    path = tmp_path / "messy.csv"
    frame.to_csv(path, index=False)
    log = read_monitor_log(path)
    text = " | ".join(log.issues)
    assert "comment" in text and "ignored" in text
    assert "axle 3 has neither brake_pressure_3 nor torque_3" in text
    assert "train_speed: 1 cell(s) not numbers (rows 2000)" in text
    rep = replay_log(log, "coach_default")
    reasons_3 = rep.frame["reason_3"].iloc[800:1990]  # (the speed is missing at row 2000)
    assert (reasons_3 == "no force channel").all()
    assert (rep.frame["level_3"] == "unknown").all()
    assert (rep.frame.loc[2000, ["level_1", "level_2", "level_4"]] == "unknown").all()
    assert rep.frame.loc[2000, "reason_1"] == "speed missing"
    assert rep.summary["log_issues"] == list(log.issues)


def test_rows_out_of_order_and_repeated_are_kept_and_flagged(low_run, tmp_path):
    frame = _frame(low_run, stop=3000)
    frame.loc[2000, "time"] = frame.loc[1999, "time"]  # repeated
    frame = pd.concat([frame.iloc[:2500], frame.iloc[[2400]], frame.iloc[2500:]],
                      ignore_index=True)  # an old row again, out of order
    path = tmp_path / "order.csv"
    frame.to_csv(path, index=False, float_format="%.17g")
    rep = replay_log(path, "coach_default")
    assert len(rep.frame) == len(frame)
    assert rep.summary["rejected_samples"] == 2
    assert rep.frame.loc[2000, "reason_1"] == "time not increasing"
    assert rep.frame.loc[2500, "status"] == 1


def test_pressure_in_pascal_warns_and_is_implausible(low_run, tmp_path):
    frame = _frame(low_run, stop=2000)
    frame["brake_pressure_2"] *= 1e5  # Pa written where bar is expected
    path = tmp_path / "pa.csv"
    frame.to_csv(path, index=False)
    with pytest.warns(UnitWarning, match="brake_pressure_2 reaches"):
        log = read_monitor_log(path)
    rep = replay_log(log, "coach_default")
    braking = rep.frame["time"] > 3.0
    assert (rep.frame.loc[braking, "level_2"] == "unknown").all()
    assert "pressure implausible" in set(rep.frame.loc[braking, "reason_2"])


def test_events_summary_and_files(log_files, tmp_path):
    folder, _ = log_files
    rep = replay_log(folder / "log.parquet", "coach_default")
    ev = rep.events
    assert list(ev.columns) == ["time", "axle", "level", "reason"]
    low = ev[ev["level"] == "low"]
    assert not low.empty and "below the threshold 0.14" in low["reason"].iloc[0]
    ax = rep.summary["axles"][0]
    assert ax["radius_learned"] and ax["low_episodes"] >= 1
    assert sum(ax["level_share"].values()) == pytest.approx(1.0)
    out = rep.write(tmp_path / "out")
    assert out.name == "monitor.parquet"
    back = pd.read_parquet(out)
    assert len(back) == len(rep.frame)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["samples"] == len(rep.frame)
    assert (tmp_path / "out" / "events.csv").is_file()
    csv = rep.write(tmp_path / "flat.csv")
    assert csv.is_file()


def test_bad_files_and_vehicles(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        read_monitor_log(tmp_path / "none.csv")
    pd.DataFrame({"time": [0.0], "wheel_speed_1": [1.0]}).to_csv(tmp_path / "a.csv", index=False)
    with pytest.raises(ValueError, match="'train_speed'"):
        read_monitor_log(tmp_path / "a.csv")
    # sampled every 2.4 ms: a step of 1 s would (rightly) be sniffed as a time in ms
    frame = pd.DataFrame({"time": [0.0, 0.0024], "train_speed": [1.0, 1.0],
                          "wheel_speed_1": [1.0, 1.0], "brake_pressure_1": [0.0, 0.0]})
    with pytest.raises(ValueError, match="log has 1 axles but the vehicle"):
        replay_log(monitor_log_frame(frame), "coach_default")
    bad = frame.rename(columns={"brake_pressure_1": " wheel_speed_1"})
    with pytest.raises(ValueError, match="both named 'wheel_speed_1'"):
        monitor_log_frame(bad)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert monitor_log_frame(frame).n_axles == 1


def test_clean_log_is_trusted(log_files):
    folder, _ = log_files
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rep = replay_log(folder / "log.csv", "coach_default")
    assert rep.trusted and rep.warnings == () and rep.log.warnings == ()
    assert rep.summary["trusted"] is True and rep.summary["warnings"] == []


@pytest.mark.parametrize(("column", "factor", "match"), [
    ("train_speed", 3.6, "train_speed in km/h"),
    ("time", 1e3, "time in ms"),
])  # fmt: skip
def test_units_are_sniffed_as_identify_does(low_run, tmp_path, column, factor, match):
    """A train speed in km/h, a time in ms: a UnitWarning naming the column at reading, on
    the log and on the replay (not trusted), as the identification's reader does."""
    frame = _frame(low_run, stop=3000)
    frame[column] *= factor
    path = tmp_path / "log.csv"
    frame.to_csv(path, index=False)
    with pytest.warns(UnitWarning, match=match):
        log = read_monitor_log(path)
    assert any(match.split(" in ")[0] in w for w in log.warnings)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = replay_log(log, "coach_default")
    assert not rep.trusted and rep.warnings == log.warnings
    assert rep.summary["trusted"] is False and rep.summary["warnings"] == list(log.warnings)
    with pytest.warns(UnitWarning, match=match):  # the file given straight to the replay
        assert not replay_log(path, "coach_default").trusted


def test_speed_against_the_vehicle_wheel_radius(low_run):
    """A rolling radius v / omega of 0.69 m is plausible for a railway wheel but not for the
    vehicle's 0.46 m: replay_log checks the speed against the vehicle's wheel radius too."""
    from railadhesion.plausibility import PlausibilityWarning

    frame = _frame(low_run, stop=3000)
    frame["train_speed"] *= 1.5
    log = monitor_log_frame(frame)
    assert log.warnings == ()
    with pytest.warns(PlausibilityWarning, match="not the vehicle's wheel radius 0.46 m"):
        rep = replay_log(log, "coach_default")
    assert not rep.trusted and "train_speed" in rep.warnings[0]


def test_log_without_samples_is_an_error(tmp_path):
    path = tmp_path / "empty.csv"
    path.write_text("time,train_speed,wheel_speed_1,wheel_speed_2,wheel_speed_3,"
                    "wheel_speed_4,brake_pressure_1,brake_pressure_2,brake_pressure_3,"
                    "brake_pressure_4\n")
    with pytest.raises(ValueError, match="empty.csv: the log has no samples"):
        read_monitor_log(path)
    with pytest.raises(ValueError, match="no samples"):
        monitor_log_frame(pd.read_csv(path))
