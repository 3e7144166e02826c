"""Braking-log reader: every defect reported with its rows, and handled as documented."""

import numpy as np
import pandas as pd
import pytest

from railadhesion.identification.logs import (
    BrakingLogWarning,
    braking_log_from_frame,
    read_braking_log,
)

R = 0.46


def clean_frame(n=2500, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 2.4e-3
    v = 20.0 - 1.0 * t + rng.normal(0, 0.01, n)
    cols = {"time": t, "train_speed": v}
    for i in range(1, 5):
        cols[f"wheel_speed_{i}"] = (20.0 - t) / R * (1 - 0.01 * i) + rng.normal(0, 0.02, n)
    for i in range(1, 5):
        cols[f"brake_pressure_{i}"] = 3.0 + 0.1 * np.sin(t + i) + rng.normal(0, 0.01, n)
    return pd.DataFrame(cols)


def messy_frame():
    df = clean_frame().astype(object)
    df.loc[10, "wheel_speed_2"] = np.nan               # short hole: interpolated, still valid
    df.loc[100:199, "brake_pressure_3"] = np.nan       # 0.24 s hole: interpolated, invalid
    df.loc[50, "train_speed"] = "abc"                  # unparseable
    df.loc[300, "time"] = np.nan                       # no time: removed
    df.loc[[400, 401], "time"] = df.loc[[401, 400], "time"].to_numpy()  # swapped
    df.loc[500, "time"] = df.loc[499, "time"]          # duplicate time
    df.loc[1200:1700, "wheel_speed_4"] = df.loc[1200, "wheel_speed_4"]  # stuck 1.2 s
    df = df.drop(index=range(1000, 1100)).reset_index(drop=True)  # gap of 0.24 s
    return df


def issues_by_kind(log):
    out = {}
    for issue in log.issues:
        out.setdefault((issue.kind, issue.channel), issue)
    return out


def test_clean_log_has_no_issue():
    log = braking_log_from_frame(clean_frame())
    assert log.issues == ()
    assert log.n_axles == 4
    assert log.valid.all()
    assert log.brake_pressure[0, 0] == pytest.approx(
        (3.0 + 0.1 * np.sin(1.0)) * 1e5, rel=0.01)  # bar -> Pa


def test_every_defect_is_reported_with_rows(tmp_path):
    df = messy_frame()
    path = tmp_path / "messy.csv"
    df.to_csv(path, index=False)
    with pytest.warns(BrakingLogWarning, match="defect"):
        log = read_braking_log(path)
    found = issues_by_kind(log)
    # unparseable cell: row 50, read as missing, then interpolated
    assert list(found[("unparseable", "train_speed")].rows) == [50]
    assert 50 in found[("missing-values", "train_speed")].rows
    # short hole interpolated and valid
    hole = found[("missing-values", "wheel_speed_2")]
    assert list(hole.rows) == [10]
    k = int(np.flatnonzero(log.rows == 10)[0])
    assert log.valid[k, 1]
    assert np.isfinite(log.wheel_speed[k, 1])
    # long hole: interpolated and marked invalid for axle 3 only
    long = found[("missing-values", "brake_pressure_3")]
    assert list(long.rows) == list(range(100, 200))
    ks = np.flatnonzero((log.rows >= 100) & (log.rows < 200))
    assert not log.valid[ks, 2].any() and log.valid[ks, 0].all()
    # missing time: removed
    assert list(found[("missing-time", "time")].rows) == [300]
    assert 300 not in log.rows
    # unsorted: the row found out of order is reported and the result is sorted
    assert list(found[("unsorted", "time")].rows) == [401]
    assert np.all(np.diff(log.time) > 0)
    # duplicate: the later row removed
    assert list(found[("duplicate-time", "time")].rows) == [500]
    assert 500 not in log.rows
    # gap: 100 rows were cut out after file row 999, so the jump is before row 1000
    gap = found[("gap", "time")]
    assert list(gap.rows) == [1000]
    assert log.segment.max() == 1
    # stuck wheel speed: rows 1200..1700 of the original = 1100..1600 after the cut
    stuck = found[("stuck-channel", "wheel_speed_4")]
    assert stuck.rows.min() == 1100 and stuck.rows.max() == 1600
    ks = np.flatnonzero((log.rows >= 1100) & (log.rows <= 1600))
    assert not log.valid[ks, 3].any()
    # the report names them all
    text = log.report()
    for kind in ("unparseable", "missing-time", "unsorted", "duplicate-time", "gap",
                 "stuck-channel", "missing-values"):
        assert kind in text


def test_rows_are_never_lost_silently():
    df = messy_frame()
    log = braking_log_from_frame(df, warn=False)
    removed = sum(i.rows.size for i in log.issues
                  if i.kind in ("missing-time", "duplicate-time"))
    assert log.n_samples + removed == len(df)


def test_missing_channel_is_substituted_for_eq14_only():
    df = clean_frame().drop(columns=["brake_pressure_2"])
    with pytest.warns(BrakingLogWarning):
        log = braking_log_from_frame(df)
    (issue,) = [i for i in log.issues if i.kind == "missing-channel"]
    assert issue.channel == "brake_pressure_2"
    assert "excluded" in issue.action
    assert not log.valid[:, 1].any() and log.valid[:, 0].all()
    assert log.substituted.tolist() == [False, True, False, False]
    others = df[["brake_pressure_1", "brake_pressure_3", "brake_pressure_4"]].mean(axis=1)
    assert np.allclose(log.brake_pressure[:, 1], others * 1e5)


def test_all_nan_channel_counts_as_missing():
    df = clean_frame()
    df["wheel_speed_3"] = np.nan
    log = braking_log_from_frame(df, warn=False)
    assert any(i.kind == "missing-channel" and i.channel == "wheel_speed_3" for i in log.issues)


def test_parquet_and_csv_agree(tmp_path):
    df = clean_frame(n=500)
    df.to_csv(tmp_path / "a.csv", index=False)
    df.to_parquet(tmp_path / "a.parquet", index=False)
    a = read_braking_log(tmp_path / "a.csv")
    b = read_braking_log(tmp_path / "a.parquet")
    assert np.allclose(a.wheel_speed, b.wheel_speed)
    assert np.allclose(a.brake_pressure, b.brake_pressure)


@pytest.mark.parametrize(
    "mutate, match",
    [
        (lambda d: d.drop(columns=["time"]), "time"),
        (lambda d: d.drop(columns=["train_speed"]), "train_speed"),
        (lambda d: d[["time", "train_speed"]], "wheel_speed_i"),
    ],
)
def test_malformed_logs_raise(mutate, match):
    with pytest.raises(ValueError, match=match):
        braking_log_from_frame(mutate(clean_frame(n=50)))


def test_missing_file(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        read_braking_log(tmp_path / "none.csv")


def test_parquet_reports_the_same_defects_as_csv(tmp_path):
    # the messy log without its text cell (a Parquet column holds one type)
    df = messy_frame()
    df.loc[df["train_speed"] == "abc", "train_speed"] = np.nan
    df = df.astype(float)
    df.to_csv(tmp_path / "m.csv", index=False)
    df.to_parquet(tmp_path / "m.parquet", index=False)
    a = read_braking_log(tmp_path / "m.csv", warn=False)
    b = read_braking_log(tmp_path / "m.parquet", warn=False)
    assert [str(i) for i in a.issues] == [str(i) for i in b.issues]
    kinds = {i.kind for i in b.issues}
    assert {"missing-time", "unsorted", "duplicate-time", "gap", "stuck-channel",
            "missing-values"} <= kinds
    assert np.array_equal(a.rows, b.rows) and np.array_equal(a.valid, b.valid)
    assert np.allclose(a.wheel_speed, b.wheel_speed)


def test_parquet_without_pyarrow_is_a_clear_error(tmp_path, monkeypatch):
    import sys

    clean_frame(n=50).to_parquet(tmp_path / "a.parquet", index=False)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)  # import fails
    with pytest.raises(ValueError, match="needs pyarrow"):
        read_braking_log(tmp_path / "a.parquet")


def test_columns_that_collide_after_stripping_spaces_are_an_error(tmp_path):
    """' wheel_speed_1' and 'wheel_speed_1' name the same channel: which one is meant would be
    a guess, so the reader refuses (CSV, Parquet and frames alike) rather than keep one."""
    df = clean_frame()
    df.insert(len(df.columns), " wheel_speed_1", df["wheel_speed_1"] + 1.0)
    with pytest.raises(ValueError, match=r"columns \d+ and \d+ are both named 'wheel_speed_1'"):
        braking_log_from_frame(df)
    df.to_csv(tmp_path / "dup.csv", index=False)
    with pytest.raises(ValueError, match="both named 'wheel_speed_1'"):
        read_braking_log(tmp_path / "dup.csv")
    pytest.importorskip("pyarrow")
    df.to_parquet(tmp_path / "dup.parquet")
    with pytest.raises(ValueError, match="both named 'wheel_speed_1'"):
        read_braking_log(tmp_path / "dup.parquet")
