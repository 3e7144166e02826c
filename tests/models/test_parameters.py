"""Tests of the Polach parameter sets (railadhesion.models.parameters)."""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.models.parameters import (
    PARAMETER_RANGES,
    POLACH_PARAMETER_SETS,
    PolachParameters,
    polach_parameters,
)
from railadhesion.plausibility import PlausibilityWarning

FIELDS = ("k_A", "k_S", "mu0", "A", "B")


def test_polach2005_sets_match_the_quoted_table():
    # MODELS.md section 3, table "Parameter sets commonly quoted from Polach 2005 (labelled there
    # as typical locomotive values)": dry 1.00 0.40 0.55 0.40 0.60; wet 0.30 0.10 0.30 0.40 0.20
    assert polach_parameters("polach2005_dry").as_dict() == {
        "k_A": 1.0, "k_S": 0.4, "mu0": 0.55, "A": 0.4, "B": 0.6,
    }  # fmt: skip
    assert polach_parameters("polach2005_wet").as_dict() == {
        "k_A": 0.3, "k_S": 0.1, "mu0": 0.3, "A": 0.4, "B": 0.2,
    }  # fmt: skip


def test_contact_eurosprinter_set_matches_the_contact_input_file():
    # CONTACT examples/tractcurv.inp, 4th series: "0.1368  0.2232  990.  FKIN, FEXP1, SABSH1"
    # (mm/s): mu = 0.1368 + 0.2232 exp(-w / 0.99 m/s)
    p = polach_parameters("contact_eurosprinter")
    assert p.mu0 == pytest.approx(0.1368 + 0.2232)
    assert p.mu0 * p.A == pytest.approx(0.1368, rel=1e-3)
    assert p.B == pytest.approx(1.0 / 0.99)
    assert p.k_A == p.k_S == 1.0


@pytest.mark.parametrize("name", sorted(POLACH_PARAMETER_SETS))
def test_builtin_sets_are_consistent_and_documented(name):
    p = POLACH_PARAMETER_SETS[name]
    assert p.name == name
    assert p.source and p.notes
    assert p.k_S <= p.k_A <= 1.0  # Polach 2005's recommendation
    assert polach_parameters(name) is p


def test_polach2005_provenance_is_stated_honestly():
    for name in ("polach2005_dry", "polach2005_wet"):
        src = polach_parameters(name).source
        assert "not read in the paper" in src
        assert "third-party" in src


def test_unknown_name_lists_valid_names():
    with pytest.raises(ValueError) as info:
        polach_parameters("polach2005_icy")
    msg = str(info.value)
    for name in POLACH_PARAMETER_SETS:
        assert name in msg
    with pytest.raises(ValueError):
        polach_parameters(None)


def test_as_dict_replace_and_frozen():
    p = PolachParameters(k_A=0.5, k_S=0.2, mu0=0.3, A=0.4, B=0.3, name="x", source="s")
    assert list(p.as_dict()) == list(FIELDS)
    q = p.replace(mu0=0.25, name="y")
    assert q.mu0 == 0.25 and q.name == "y" and q.k_A == 0.5 and p.mu0 == 0.3
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.mu0 = 0.1  # type: ignore[misc]
    with pytest.raises(ValueError, match="k_A"):
        p.replace(k_A=0.0)
    # ints are accepted and stored as floats
    r = PolachParameters(k_A=1, k_S=1, mu0=1, A=1, B=0)
    assert all(isinstance(v, float) for v in r.as_dict().values())


GOOD = dict(k_A=0.5, k_S=0.2, mu0=0.3, A=0.4, B=0.3)


@pytest.mark.parametrize(
    ("field", "value", "range_text"),
    [
        ("k_A", 0.0, "(0, 1]"),
        ("k_A", -1.0, "(0, 1]"),
        ("k_A", 1.5, "(0, 1]"),
        ("k_S", 0.0, "(0, 1]"),
        ("mu0", 0.0, "(0, 1.5]"),
        ("mu0", float("nan"), "(0, 1.5]"),
        ("A", -0.1, "[0, 10]"),
        ("A", float("inf"), "[0, 10]"),
        ("B", -1.0, "[0, 100]"),
        ("B", "fast", "[0, 100]"),
        ("B", None, "[0, 100]"),
        ("mu0", True, "(0, 1.5]"),
    ],
)
def test_invalid_field_raises_naming_field_and_range(field, value, range_text):
    kw = dict(GOOD)
    kw[field] = value
    with pytest.raises(ValueError) as info:
        PolachParameters(**kw)
    assert field in str(info.value)
    assert range_text in str(info.value)


def test_text_fields_must_be_strings():
    with pytest.raises(ValueError, match="source"):
        PolachParameters(**GOOD, source=3)


@given(
    values=st.tuples(
        *(
            st.floats(lo, hi, exclude_min=not lo_c, exclude_max=not hi_c)
            for lo, hi, lo_c, hi_c in PARAMETER_RANGES.values()
        )
    )
)
@settings(max_examples=100, deadline=None)
def test_any_value_in_range_is_accepted(values):
    kw = dict(zip(PARAMETER_RANGES, values, strict=True))
    if kw["mu0"] > 1.0:  # possible, but no wheel-rail value: accepted with a warning
        with pytest.warns(PlausibilityWarning, match=r"mu0 = .* outside the plausible range"):
            p = PolachParameters(**kw)
    else:
        p = PolachParameters(**kw)
    assert all(math.isfinite(v) for v in p.as_dict().values())


@pytest.mark.parametrize("value", ["0.5", b"0.5", [0.5], (0.5,)])
def test_non_scalar_or_text_values_are_rejected(value):
    """float() accepts numeric strings and 1-element sequences/arrays: they used to pass."""
    import numpy as np

    for bad in (value, np.array(value) if not isinstance(value, str | bytes) else value):
        kw = dict(GOOD)
        kw["k_A"] = bad
        with pytest.raises(ValueError, match=r"^k_A must be a real number in \(0, 1\]"):
            PolachParameters(**kw)


def test_numpy_bool_rejected_and_numpy_scalars_accepted():
    import numpy as np

    with pytest.raises(ValueError, match="mu0"):
        PolachParameters(**{**GOOD, "mu0": np.True_})
    p = PolachParameters(**{**GOOD, "mu0": np.float32(0.25), "B": np.array(0.3)})
    assert p.mu0 == 0.25 and isinstance(p.mu0, float) and isinstance(p.B, float)
