"""Braking-test log writer (docs/braking-log.md)."""

import numpy as np
import pandas as pd
import pytest

from railadhesion.braking import write_braking_log


def _frame(n=4):
    t = np.linspace(0.0, 1.0, 1001)
    data = {"time": t, "train_speed": 30 - t}
    for i in range(1, n + 1):
        data[f"wheel_speed_{i}"] = (30 - t) / 0.46
    for i in range(1, n + 1):
        data[f"brake_pressure_{i}"] = 3e5 * t
    return pd.DataFrame(data)


def test_csv_header_units_and_sampling(tmp_path):
    path = tmp_path / "log.csv"
    write_braking_log(_frame(), path)
    lines = path.read_text().splitlines()
    assert lines[0] == (
        "time,train_speed,wheel_speed_1,wheel_speed_2,wheel_speed_3,wheel_speed_4,"
        "brake_pressure_1,brake_pressure_2,brake_pressure_3,brake_pressure_4"
    )
    log = pd.read_csv(path)
    np.testing.assert_allclose(np.diff(log["time"]), 2.4e-3, atol=1e-9)
    np.testing.assert_allclose(log["brake_pressure_1"], 3.0 * log["time"], atol=1e-6)  # bar
    np.testing.assert_allclose(log["wheel_speed_2"], (30 - log["time"]) / 0.46, rtol=1e-8)


def test_noise_and_quantisation_reproducible(tmp_path):
    kw = dict(noise={"wheel_speed": 0.05}, quantisation={"brake_pressure": 0.01}, seed=3)
    a = write_braking_log(_frame(), tmp_path / "a.csv", **kw)
    b = write_braking_log(_frame(), tmp_path / "b.csv", **kw)
    pd.testing.assert_frame_equal(a, b)
    clean = write_braking_log(_frame(), tmp_path / "c.csv")
    resid = a["wheel_speed_1"] - clean["wheel_speed_1"]
    assert 0.03 < resid.std() < 0.07
    steps = a["brake_pressure_3"] / 0.01
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)


def test_parquet_same_columns(tmp_path):
    log = write_braking_log(_frame(2), tmp_path / "log.parquet")
    back = pd.read_parquet(tmp_path / "log.parquet")
    assert list(back.columns) == list(log.columns)


def test_bad_arguments():
    with pytest.raises(ValueError, match="period"):
        write_braking_log(_frame(), "x.csv", period=0)
    with pytest.raises(ValueError, match="noise"):
        write_braking_log(_frame(), "x.csv", noise={"speed": 1})
