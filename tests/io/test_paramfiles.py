"""Tests of the parameter-file format (docs/parameter-files.md)."""

from __future__ import annotations

import copy
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from railadhesion.io.paramfiles import (
    FORMAT_VERSION,
    POLACH_FORMAT,
    WILAC_FORMAT,
    ParameterFileError,
    load_parameter_file,
    load_polach_parameters,
    load_wilac_parameters,
    polach_parameters_to_toml,
    read_provenance,
    save_polach_parameters,
    save_wilac_parameters,
    wilac_parameters_to_toml,
)
from railadhesion.models.parameters import PolachParameters, polach_parameters
from railadhesion.models.regression import ParameterRegression, candidate_terms
from railadhesion.models.wilac import (
    PAPER_TRANSITIONS,
    WILAC_CONDITIONS,
    WaterTransition,
    WilacCondition,
    WilacParameters,
)

DATA = Path(__file__).parent / "data"
WILAC_EXAMPLE = DATA / "wilac_example.toml"
POLACH_EXAMPLE = DATA / "polach_example.toml"
DOCS = Path(__file__).resolve().parents[2] / "docs" / "parameter-files.md"


def example_doc() -> dict:
    with open(WILAC_EXAMPLE, "rb") as fh:
        return tomllib.load(fh)


def polach_doc() -> dict:
    with open(POLACH_EXAMPLE, "rb") as fh:
        return tomllib.load(fh)


# --- reading the examples ---------------------------------------------------------------------


def test_load_wilac_example():
    p = load_wilac_parameters(WILAC_EXAMPLE)
    assert isinstance(p, WilacParameters)
    assert p.name == "example"
    assert p.normal_force_ref == 120000.0 and p.speed_ref == 40.0
    assert p.normal_force_range == (4000.0, 120000.0)
    assert p.speed_range == (1.0, 40.0)
    assert p.transitions == PAPER_TRANSITIONS
    mu0 = p.conditions["dry"].mu0
    assert mu0.terms == ("1", "v", "1/v") and mu0.coefficients == (0.52, -0.08, 0.002)
    assert mu0.r_squared == 0.998
    assert p.conditions["damp2"].B == ParameterRegression.constant(0.9)
    assert p.provenance["reconstruction"] is True
    assert p.provenance["created"] == "2026-11-21"
    assert set(p.provenance) == {
        "source", "reconstruction", "description", "created", "script", "licence", "notes"
    }  # fmt: skip
    # mu0 = 0.52 - 0.08 v' + 0.002 / v' at v = 20 m/s (v' = 0.5)
    assert float(p.polach_parameters("dry", 1e4, 20.0)["mu0"]) == pytest.approx(0.484)


def test_load_polach_example():
    p = load_polach_parameters(POLACH_EXAMPLE)
    assert p == polach_parameters("polach2005_dry").replace(source=p.source, notes=p.notes)
    assert p.name == "polach2005_dry"
    assert p.source.startswith("Polach O., Wear 258")
    assert p.notes.startswith("Identical values")
    prov = read_provenance(POLACH_EXAMPLE)
    assert prov["description"] == "Dry rail" and prov["reconstruction"] is False


def test_dispatch_on_format():
    assert isinstance(load_parameter_file(WILAC_EXAMPLE), WilacParameters)
    assert isinstance(load_parameter_file(POLACH_EXAMPLE), PolachParameters)


def test_loading_the_wrong_kind_is_an_error():
    with pytest.raises(ParameterFileError, match="format: this is a 'railadhesion-polach'"):
        load_wilac_parameters(POLACH_EXAMPLE)
    with pytest.raises(ParameterFileError, match="format: this is a 'railadhesion-wilac'"):
        load_polach_parameters(WILAC_EXAMPLE)


@pytest.mark.skipif(not DOCS.is_file(), reason="documentation not present")
def test_documentation_examples_are_valid(tmp_path):
    blocks = re.findall(r"```toml\n(.*?)```", DOCS.read_text(encoding="utf-8"), flags=re.S)
    assert len(blocks) == 2
    kinds = []
    for i, block in enumerate(blocks):
        path = tmp_path / f"block{i}.toml"
        path.write_text(block, encoding="utf-8")
        kinds.append(type(load_parameter_file(path)))
    assert kinds == [WilacParameters, PolachParameters]
    assert blocks[0] == WILAC_EXAMPLE.read_text(encoding="utf-8")


# --- round trips ------------------------------------------------------------------------------


def test_wilac_round_trip_of_example(tmp_path):
    p = load_wilac_parameters(WILAC_EXAMPLE)
    path = save_wilac_parameters(p, tmp_path / "copy.toml")
    q = load_wilac_parameters(path)
    assert q == p
    assert q.provenance == p.provenance and q.name == p.name
    text = path.read_text(encoding="utf-8")
    assert 'format = "railadhesion-wilac"' in text and "format_version = 1" in text
    assert "normal_force_ref_N" in text and "µl/s" in text and "created = 2026-11-21" in text


awkward = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    st.lists(st.sampled_from(candidate_terms()), min_size=1, max_size=12, unique=True),
    st.data(),
)
def test_wilac_round_trip_full_precision(tmp_path, terms, data):
    coefs = data.draw(st.lists(awkward, min_size=len(terms), max_size=len(terms)))
    r2 = data.draw(st.none() | st.floats(-5.0, 1.0))
    reg = ParameterRegression(tuple(terms), tuple(coefs), r_squared=r2)
    cond = WilacCondition(k_A=reg, k_S=0.1, mu0=reg, A=0.2, B=ParameterRegression.constant(0.1))
    p = WilacParameters(
        {c: cond for c in WILAC_CONDITIONS},
        normal_force_ref=1.1e5,
        speed_ref=0.1 + 0.2,  # not exactly representable: must survive the round trip
        normal_force_range=(4.2e3, 1.1e5),
        speed_range=(1 / 3, 40.0),
        transitions=(WaterTransition(14.9, 5.1), WaterTransition(30.0, 3.0),
                     WaterTransition(50.5, 7.25)),  # fmt: skip
        name="round ✓ \"trip\"",
        provenance={"source": "line 1\nline 2", "reconstruction": False},
    )
    path = save_wilac_parameters(p, tmp_path / "rt.toml")
    q = load_wilac_parameters(path)
    assert q == p
    got = q.conditions["damp1"].mu0
    assert got.coefficients == tuple(coefs)  # exact, to the last bit
    assert got.r_squared == r2
    assert q.speed_ref == 0.1 + 0.2 and q.speed_range[0] == 1 / 3
    assert q.name == p.name and q.provenance == p.provenance


def test_polach_round_trip(tmp_path):
    p = PolachParameters(k_A=0.7, k_S=1 / 3, mu0=0.1 + 0.2, A=0.38, B=1 / 0.99, name="x",
                         source="CONTACT tractcurv", notes="n")  # fmt: skip
    extra = {"reconstruction": True, "created": "2026-11-21", "script": "fit.py",
             "licence": "Apache-2.0"}  # fmt: skip
    path = save_polach_parameters(p, tmp_path / "p.toml", provenance=extra)
    assert load_polach_parameters(path) == p
    assert load_parameter_file(path) == p
    assert read_provenance(path) == {"source": "CONTACT tractcurv", "notes": "n", **extra}
    assert polach_parameters_to_toml(p) != polach_parameters_to_toml(p, provenance=extra)


def test_save_without_provenance_has_no_table(tmp_path):
    p = PolachParameters(k_A=1.0, k_S=0.4, mu0=0.5, A=0.4, B=0.6)
    text = polach_parameters_to_toml(p)
    assert "[provenance]" not in text
    path = save_polach_parameters(p, tmp_path / "p.toml")
    assert read_provenance(path) == {}


def test_save_rejects_wrong_objects(tmp_path):
    with pytest.raises(ValueError, match="params must be a WilacParameters"):
        save_wilac_parameters(polach_parameters("polach2005_dry"), tmp_path / "x.toml")
    with pytest.raises(ValueError, match="params must be a PolachParameters"):
        save_polach_parameters(load_wilac_parameters(WILAC_EXAMPLE), tmp_path / "x.toml")
    with pytest.raises(ValueError, match=r"provenance: unknown field\(s\) \['author'\]"):
        save_polach_parameters(polach_parameters("polach2005_dry"), tmp_path / "x.toml",
                               provenance={"author": "me"})  # fmt: skip


def test_long_regressions_are_written_readably(tmp_path):
    terms = ["1", *candidate_terms()[:40]]
    coefs = list(np.random.default_rng(1).normal(size=len(terms)) * 1e-3)
    reg = ParameterRegression(tuple(terms), tuple(coefs))
    p = load_wilac_parameters(WILAC_EXAMPLE)
    cond = WilacCondition(k_A=0.5, k_S=0.1, mu0=0.3, A=reg, B=0.2)
    p = p.replace(conditions={**p.conditions, "wet": cond})
    text = wilac_parameters_to_toml(p)
    assert max(len(line) for line in text.splitlines() if not line.startswith("source")) <= 100
    assert load_wilac_parameters(save_wilac_parameters(p, tmp_path / "l.toml")) == p


# --- malformed files --------------------------------------------------------------------------


def _set(doc, dotted, value):
    *parents, last = dotted.split(".")
    for key in parents:
        doc = doc[key]
    if value is _DELETE:
        del doc[last]
    else:
        doc[last] = value


class _Delete:
    """Marks a field to delete; its repr names it, so test ids are the same in every process."""

    def __repr__(self):
        return "DELETE"


_DELETE = _Delete()
EXP_Q = {"terms": ["exp(Q)"], "coefficients": [1.0]}

# (dotted field to change, new value, substrings the message must contain)
WILAC_CASES = [
    ("conditions.damp2.k_S.coefficients", "0.1",
     ["conditions.damp2.k_S.coefficients: expected a list of numbers"]),
    ("conditions.damp2.k_S.coefficients", [0.1, "x"],
     ["conditions.damp2.k_S.coefficients: expected a list of numbers"]),
    ("conditions.dry.k_A.coefficients", [True],
     ["conditions.dry.k_A.coefficients: expected a list of numbers"]),
    ("conditions.dry.k_A.coefficients", [math.nan],
     ["conditions.dry.k_A.coefficients[0]: expected a finite number"]),
    ("conditions.dry.k_A.coefficients", [1.0, 2.0],
     ["conditions.dry.k_A: 'terms' has 1 entries but 'coefficients' has 2"]),
    ("conditions.dry.k_A.coefficients", _DELETE,
     ["conditions.dry.k_A: missing required field(s) conditions.dry.k_A.coefficients"]),
    ("conditions.wet.B.terms", ["1", "v*w"],
     ["conditions.wet.B.terms[1]", "unknown factor 'w'", "allowed factors"]),
    ("conditions.wet.B.terms", ["Q*Q*Q*Q"], ["conditions.wet.B.terms[0]", "at most 3"]),
    ("conditions.wet.B.terms", "1", ["conditions.wet.B.terms: expected a list of strings"]),
    ("conditions.wet.B.terms", [1], ["conditions.wet.B.terms: expected a list of strings"]),
    ("conditions.wet.B.terms", [], ["conditions.wet.B.terms: expected at least one term"]),
    ("conditions.dry.mu0.terms", ["1", "v*Q", "Q*v"],
     ["conditions.dry.mu0.terms[2]", "repeats terms[1]"]),
    ("conditions.dry.mu0.r_squared", 1.5, ["conditions.dry.mu0.r_squared: must be <= 1"]),
    ("conditions.dry.mu0.r_squared", "high", ["conditions.dry.mu0.r_squared: expected a number"]),
    ("conditions.dry.k_A.offset", 0.1,
     ["conditions.dry.k_A: unknown field(s) conditions.dry.k_A.offset"]),
    ("conditions.damp1", _DELETE, ["conditions: missing required field(s) conditions.damp1"]),
    ("conditions.moist", {}, ["conditions: unknown field(s) conditions.moist"]),
    ("conditions.wet.B", _DELETE, ["conditions.wet: missing required field(s) conditions.wet.B"]),
    ("conditions.wet.mu", EXP_Q, ["conditions.wet: unknown field(s) conditions.wet.mu"]),
    ("conditions.dry", 1, ["conditions.dry: expected a table, got an integer"]),
    ("conditions.dry.k_S", [0.4], ["conditions.dry.k_S: expected a table, got a list"]),
    ("conditions", _DELETE, ["missing required top-level field(s) conditions"]),
    ("format", "railadhesion-fastsim", ["format: expected one of"]),
    ("format", _DELETE, ["format: missing"]),
    ("format_version", 2, ["format_version: version 2 is not supported", "format_version = 1"]),
    ("format_version", "1", ["format_version: expected an integer"]),
    ("format_version", True, ["format_version: expected an integer"]),
    ("format_version", _DELETE, ["format_version: missing"]),
    ("comment", "hello", ["unknown top-level field(s) comment"]),
    ("name", 3, ["name: expected a string"]),
    ("normalisation", _DELETE, ["missing required top-level field(s) normalisation"]),
    ("normalisation.normal_force_ref_N", 0.0,
     ["normalisation.normal_force_ref_N: must be in (0, inf)"]),
    ("normalisation.speed_ref_m_s", "40", ["normalisation.speed_ref_m_s: expected a number"]),
    ("normalisation.speed_ref_m_s", math.nan,
     ["normalisation.speed_ref_m_s: expected a finite number"]),
    ("normalisation.speed_ref", 40.0,
     ["normalisation: unknown field(s) normalisation.speed_ref"]),
    ("validity.normal_force_range_N", [1.2e5, 4e3],
     ["validity.normal_force_range_N: expected 0 < low < high"]),
    ("validity.speed_range_m_s", [0.0, 40.0], ["validity.speed_range_m_s: expected 0 < low"]),
    ("validity.speed_range_m_s", [1.0, 2.0, 3.0],
     ["validity.speed_range_m_s: expected [low, high] (2 numbers)"]),
    ("validity.speed_range_m_s", 40.0, ["validity.speed_range_m_s: expected a list of numbers"]),
    ("validity.speed_range_m_s", _DELETE,
     ["validity: missing required field(s) validity.speed_range_m_s"]),
    ("transitions.e2", _DELETE, ["transitions: missing required field(s) transitions.e2"]),
    ("transitions.e4", {"midpoint_ul_s": 60.0, "width_ul_s": 1.0},
     ["transitions: unknown field(s) transitions.e4"]),
    ("transitions.e1.width_ul_s", 0.0, ["transitions.e1.width_ul_s: must be in (0, inf)"]),
    ("transitions.e3.midpoint_ul_s", 20.0, ["transitions: midpoints must increase"]),
    ("transitions.e1.midpoint", 15.0, ["transitions.e1: unknown field(s) transitions.e1.midpoint"]),
    ("transitions.e1", 15.0, ["transitions.e1: expected a table"]),
    ("provenance.reconstruction", "yes", ["provenance.reconstruction: expected true or false"]),
    ("provenance.created", "yesterday", ["provenance.created: expected a date"]),
    ("provenance.author", "me", ["provenance: unknown field(s) provenance.author"]),
    ("provenance.source", 3, ["provenance.source: expected a string"]),
    ("provenance", "me", ["provenance: expected a table, got a string"]),
]  # fmt: skip


@pytest.mark.parametrize(("field", "value", "expected"), WILAC_CASES, ids=lambda x: str(x)[:40])
def test_malformed_wilac_files(tmp_path, field, value, expected):
    doc = copy.deepcopy(example_doc())
    _set(doc, field, value)
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    with pytest.raises(ParameterFileError) as info:
        load_wilac_parameters(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    for part in expected:
        assert part in message
    assert isinstance(info.value, ValueError)


def test_regression_must_be_finite_over_the_calibrated_range(tmp_path):
    doc = example_doc()
    doc["conditions"]["damp1"]["k_A"] = EXP_Q
    doc["normalisation"]["normal_force_ref_N"] = 1.0  # Q' up to 1.2e5: exp overflows
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    with pytest.raises(ParameterFileError, match="conditions.damp1.k_A: the regression is not"):
        load_wilac_parameters(path)


def test_transitions_are_optional(tmp_path):
    doc = example_doc()
    del doc["transitions"]
    path = tmp_path / "t.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    assert load_wilac_parameters(path).transitions == PAPER_TRANSITIONS


def test_created_may_be_a_string(tmp_path):
    doc = example_doc()
    doc["provenance"]["created"] = "2025-02-03"
    path = tmp_path / "t.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    assert load_wilac_parameters(path).provenance["created"] == "2025-02-03"


POLACH_CASES = [
    ("parameters.k_A", 1.5, ["parameters: k_A must be in (0, 1]"]),
    ("parameters.mu0", "0.3", ["parameters.mu0: expected a number"]),
    ("parameters.B", _DELETE, ["parameters: missing required field(s) parameters.B"]),
    ("parameters.mu", 0.3, ["parameters: unknown field(s) parameters.mu"]),
    ("parameters", _DELETE, ["missing required top-level field(s) parameters"]),
    ("format_version", 0, ["format_version: version 0 is not supported"]),
    ("provenance.licence", ["CC0"], ["provenance.licence: expected a string"]),
    ("extra", {}, ["unknown top-level field(s) extra"]),
]  # fmt: skip


@pytest.mark.parametrize(("field", "value", "expected"), POLACH_CASES, ids=lambda x: str(x)[:40])
def test_malformed_polach_files(tmp_path, field, value, expected):
    doc = copy.deepcopy(polach_doc())
    _set(doc, field, value)
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    for loader in (load_polach_parameters, load_parameter_file):
        with pytest.raises(ParameterFileError) as info:
            loader(path)
        assert str(info.value).startswith(f"{path}: ")
        for part in expected:
            assert part in str(info.value)


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (b"format = \"railadhesion-wilac\"\nformat_version = \n", "not valid TOML"),
        (b"format = \"railadhesion-wilac\"\n[a]\nx = 1\n[a]\nx = 2\n", "not valid TOML"),
        (b"name = \"\xff\xfe\"\n", "not UTF-8"),
        (b"format_version = 1\n", "format: missing"),
    ],
)
def test_unreadable_files(tmp_path, content, expected):
    path = tmp_path / "bad.toml"
    path.write_bytes(content)
    for loader in (load_wilac_parameters, load_parameter_file, read_provenance):
        with pytest.raises(ParameterFileError, match=re.escape(expected)):
            loader(path)


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_wilac_parameters(tmp_path / "nope.toml")


def test_constants():
    assert FORMAT_VERSION == 1
    assert (WILAC_FORMAT, POLACH_FORMAT) == ("railadhesion-wilac", "railadhesion-polach")


@pytest.mark.parametrize("r_squared", [math.nan, math.inf, 1.5])
def test_regression_r_squared_that_a_file_cannot_hold_is_rejected(r_squared):
    """Before, ParameterRegression took any r_squared, and save_wilac_parameters wrote a file
    that load_wilac_parameters then refused (r_squared must be finite and <= 1)."""
    with pytest.raises(ValueError, match="r_squared must be finite and <= 1"):
        ParameterRegression(("1",), (0.5,), r_squared=r_squared)
    with pytest.raises(ValueError, match=r"k_A: r_squared must be finite"):
        ParameterRegression.from_dict(
            {"terms": ["1"], "coefficients": [0.5], "r_squared": r_squared}, where="k_A"
        )


def test_save_load_round_trip_with_r_squared_and_odd_text(tmp_path):
    cond = WilacCondition(
        k_A=ParameterRegression(("1", "Q", "1/v*exp(Q)"), (0.4, 1e-3, -2e-4), r_squared=-0.25),
        k_S=ParameterRegression(("1",), (0.1,), r_squared=1.0),
        mu0=0.3, A=0.4, B=0.2,
    )  # fmt: skip
    params = WilacParameters(
        {c: cond for c in WILAC_CONDITIONS}, 1.2345678901234567e5, 40.1, (1e-3, 1.5e5),
        (0.1, 40.0), transitions=((10.1, 2.0), (30.0, 3.0), (50.5, 7.0)),
        name='we"ird\n[name]', provenance={"notes": 'ä ß \\ "', "reconstruction": True},
    )  # fmt: skip
    path = save_wilac_parameters(params, tmp_path / "odd.toml")
    assert load_wilac_parameters(path) == params
