"""Tests of the creep-curve CSV reader (format: docs/creep-curve-csv.md)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.io.creepcurves import (
    CreepCurve,
    CreepCurveWarning,
    read_creep_curve,
    read_creep_curves,
    write_creep_curve,
)

DATA = Path(__file__).parent / "data"


def _write(tmp_path: Path, text: str, name: str = "creep_case.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_good_file_reads_values_and_header_metadata():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a clean file must not warn
        curve = read_creep_curve(DATA / "creep_good.csv")
    np.testing.assert_array_equal(curve.creep, [-0.002, -0.005, -0.010, -0.050])
    np.testing.assert_array_equal(curve.adhesion, [0.081, 0.142, 0.171, 0.120])
    assert curve.normal_force == 4200.0
    assert curve.speed == 5.0
    assert curve.water_flow == 25.0
    assert curve.a == 0.0041 and curve.b == 0.0032
    assert curve.name == "tram_damp2_demo"
    assert curve.info == {"rig": "Pardubice tram wheel rig (demo)"}
    assert curve.excluded == ()
    assert curve.source.endswith("creep_good.csv")
    assert len(curve) == 4


def test_percent_column_and_per_row_metadata():
    curve = read_creep_curve(DATA / "creep_percent_columns.csv")
    np.testing.assert_allclose(curve.creep, [-0.005, -0.01, -0.02, -0.05], rtol=1e-12)
    assert curve.normal_force == 4200.0  # the empty cell is allowed
    assert curve.speed == 5.0  # "5" and "5.0" agree
    assert curve.water_flow == 350.0
    assert curve.a is None and curve.b is None
    assert curve.name == "creep_percent_columns"


def test_bad_rows_are_excluded_reported_and_warned():
    with pytest.warns(CreepCurveWarning, match="6 of 8 data rows excluded"):
        curve = read_creep_curve(DATA / "creep_bad_rows.csv")
    np.testing.assert_array_equal(curve.creep, [-0.002, -0.040])
    np.testing.assert_array_equal(curve.adhesion, [0.081, 0.150])
    lines = [e.line for e in curve.excluded]
    assert lines == [4, 5, 6, 7, 8, 10]  # 1-based file lines, comment and header counted
    reasons = [e.reason for e in curve.excluded]
    assert "adhesion is empty" in reasons[0]
    assert "adhesion is nan" in reasons[1]
    assert "'abc'" in reasons[2] and "adhesion" in reasons[2]
    assert "creep = 1.5" in reasons[3] and "creep_percent" in reasons[3]
    assert "adhesion = -0.05" in reasons[4]
    assert "creep is empty" in reasons[5]
    assert curve.excluded[2].text == "-0.020,abc"


@pytest.mark.parametrize(
    ("name", "pattern"),
    [
        ("creep_unknown_column.csv", r"line 1: unknown column 'temperature'"),
        ("creep_inconsistent.csv", r"line 4: inconsistent metadata in column 'speed_m_s'"),
        ("creep_nonnumeric.csv", r"column 'adhesion' is not numeric \(line 2"),
    ],
)
def test_malformed_fixture_files_raise_naming_column_and_line(name, pattern):
    with pytest.raises(ValueError, match=pattern):
        read_creep_curve(DATA / name)


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("creep,force\n0.1,0.2\n", r"line 1: unknown column 'force'"),
        ("creep\n0.1\n", r"line 1: missing required column 'adhesion'"),
        ("adhesion\n0.1\n", r"line 1: missing required column 'creep'"),
        ("creep,creep_percent,adhesion\n0.1,10,0.2\n", r"'creep' and 'creep_percent'"),
        ("creep,adhesion,creep\n0.1,0.2,0.1\n", r"column 'creep' appears twice"),
        ("# only a comment\n", r"no header row"),
        ("creep,adhesion\n", r"no data rows"),
        ("creep,adhesion\n-0.01,0.1\n-0.02,0.1,7\n", r"line 3: expected 2 fields"),
        ("# normal_force_N = -5\ncreep,adhesion\n-0.01,0.1\n", r"line 1: metadata normal_force_N"),
        ("# normal_force = 4200\ncreep,adhesion\n-0.01,0.1\n", r"did you mean 'normal_force_N'"),
        (
            "# speed_m_s = 5\ncreep,adhesion,speed_m_s\n-0.01,0.1,6\n",
            r"line 3: inconsistent metadata in column 'speed_m_s'",
        ),
        ("creep,adhesion,a_m\n-0.01,0.1,wide\n-0.02,0.1,0.004\n", r"line 2: column 'a_m'"),
        ("# speed_m_s = 5\n# speed_m_s = 6\ncreep,adhesion\n-0.01,0.1\n", r"given twice"),
    ],
)
def test_malformed_text_raises(tmp_path, text, pattern):
    with pytest.raises(ValueError, match=pattern):
        read_creep_curve(_write(tmp_path, text))


def test_all_rows_excluded_is_an_error_after_the_warning(tmp_path):
    path = _write(tmp_path, "creep,adhesion\n-50,0.1\n-60,0.1\n")
    with pytest.warns(CreepCurveWarning), pytest.raises(ValueError, match="no valid data row"):
        read_creep_curve(path)


def test_read_folder_sorted_and_errors(tmp_path):
    for i, w in enumerate((350, 0, 25)):
        _write(tmp_path, f"# water_flow_ul_s = {w}\ncreep,adhesion\n-0.01,0.2\n", f"c{i}.csv")
    (tmp_path / "notes.txt").write_text("not a curve")
    curves = read_creep_curves(tmp_path)
    assert [c.water_flow for c in curves] == [350.0, 0.0, 25.0]  # c0, c1, c2
    with pytest.raises(ValueError, match="must be an existing directory"):
        read_creep_curves(tmp_path / "c0.csv")
    with pytest.raises(ValueError, match=r"no file matching '\*\.dat'"):
        read_creep_curves(tmp_path, pattern="*.dat")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError, match="holds no file"):
        read_creep_curves(empty)


def test_creep_curve_validation_and_require():
    with pytest.raises(ValueError, match="same length"):
        CreepCurve(creep=[0.1, 0.2], adhesion=[0.1])
    with pytest.raises(ValueError, match="adhesion must be in"):
        CreepCurve(creep=[0.1], adhesion=[-0.1])
    with pytest.raises(ValueError, match=r"normal_force \(normal_force_N\) must be in"):
        CreepCurve(creep=[0.1], adhesion=[0.1], normal_force=0.0)
    c = CreepCurve(creep=[0.1], adhesion=[0.1], speed=3.0, name="x")
    with pytest.raises(ValueError, match=r"x: missing metadata normal_force_N"):
        c.require("speed", "normal_force")
    c.require("speed")  # present: no error


@settings(max_examples=60, deadline=None)
@given(
    data=st.lists(
        st.tuples(
            st.floats(-1.0, 1.0, allow_nan=False),
            st.floats(0.0, 2.0, allow_nan=False),
        ),
        min_size=1,
        max_size=20,
    ),
    q=st.floats(1.0, 2e5),
    v=st.floats(0.0, 100.0),
    percent=st.booleans(),
)
def test_write_read_roundtrip(tmp_path_factory, data, q, v, percent):
    creep, adh = (np.array(x) for x in zip(*data, strict=True))
    curve = CreepCurve(creep, adh, normal_force=q, speed=v, a=0.004, name="rt")
    path = tmp_path_factory.mktemp("rt") / "creep_rt.csv"
    write_creep_curve(curve, path, percent=percent)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_creep_curve(path)
    np.testing.assert_allclose(back.creep, curve.creep, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(back.adhesion, curve.adhesion)
    assert back.metadata == curve.metadata
    assert back.name == "rt"


# ---- audit: rows of separators only, encodings, separators, line numbers


def test_rows_of_separators_only_are_reported_not_dropped(tmp_path):
    # spreadsheets write empty rows as ",,": before, they vanished without a trace
    path = _write(tmp_path, "creep,adhesion\n-0.01,0.2\n,\n-0.02,0.3\n , \n-0.03,0.31\n")
    with pytest.warns(CreepCurveWarning, match=r"2 of 5 data rows excluded \(line 3: row is"):
        curve = read_creep_curve(path)
    assert curve.creep.tolist() == [-0.01, -0.02, -0.03]
    assert [(e.line, e.reason) for e in curve.excluded] == [
        (3, "row is empty (separators only)"),
        (5, "row is empty (separators only)"),
    ]


def test_rows_of_separators_only_keep_the_order_of_excluded_rows(tmp_path):
    path = _write(tmp_path, "creep,adhesion\n-0.01,x\n,\n-0.02,0.3\n")
    with pytest.warns(CreepCurveWarning):
        curve = read_creep_curve(path)
    assert [e.line for e in curve.excluded] == [2, 3]


def test_blank_lines_are_still_skipped_silently(tmp_path):
    path = _write(tmp_path, "creep,adhesion\n\n-0.01,0.2\n   \n-0.02,0.3\n\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        curve = read_creep_curve(path)
    assert curve.excluded == () and len(curve) == 2


def test_not_utf8_names_the_file(tmp_path):
    path = tmp_path / "utf16.csv"
    path.write_text("creep,adhesion\n-0.01,0.2\n", encoding="utf-16")
    with pytest.raises(ValueError, match=r"utf16\.csv: not a UTF-8 text file"):
        read_creep_curve(path)


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("creep;adhesion\n-0.01;0.2\n", r"line 1: header 'creep;adhesion' is separated by semi"),
        ("creep\tadhesion\n-0.01\t0.2\n", r"line 1: .* is separated by tabs"),
        ("creep,adhesion,\n-0.01,0.2,\n", r"line 1: column 3 of the header has no name"),
    ],
)
def test_wrong_separators_are_explained(tmp_path, text, pattern):
    with pytest.raises(ValueError, match=pattern):
        read_creep_curve(_write(tmp_path, text))


def test_windows_line_endings_and_bom(tmp_path):
    path = tmp_path / "win.csv"
    path.write_bytes(b"\xef\xbb\xbf# speed_m_s = 5\r\nCreep , ADHESION\r\n-0.01,0.2\r\n-0.02,9\r\n")
    with pytest.warns(CreepCurveWarning):
        curve = read_creep_curve(path)
    assert curve.speed == 5.0 and curve.creep.tolist() == [-0.01]
    assert [e.line for e in curve.excluded] == [4]


def test_line_numbers_count_only_newlines(tmp_path):
    # a form feed inside a cell is not a line break: before, str.splitlines split there and
    # the file was refused ("line 3: expected 2 fields") / later lines were misnumbered
    path = _write(tmp_path, "creep,adhesion\n-0.01,0.2\n-0.02\x0c,0.3\n-0.03,5\n")
    with pytest.warns(CreepCurveWarning):
        curve = read_creep_curve(path)
    assert curve.creep.tolist() == [-0.01, -0.02]
    assert [e.line for e in curve.excluded] == [4]
