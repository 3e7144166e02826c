"""The shared range check of scalar settings (railadhesion._validate.check_number)."""

import math

import pytest

from railadhesion._validate import check_number


@pytest.mark.parametrize("value", [0.0, 0.5, 1, 1.0])
def test_numbers_in_the_closed_range_pass(value):
    check_number(value, "x", 0.0, 1.0, unit="s")


@pytest.mark.parametrize("value, message", [
    (math.nan, "x must be a finite number, got nan"),
    (math.inf, "x must be a finite number, got inf"),
    ("0.5", "x must be a finite number, got '0.5'"),
    (True, "x must be a finite number, got True"),
    (None, "x must be a finite number, got None"),
    (-0.1, "x must be in [0, 1] s, got -0.1"),
    (2, "x must be in [0, 1] s, got 2"),
])
def test_the_messages_name_the_setting_its_range_and_unit(value, message):
    with pytest.raises(ValueError) as info:
        check_number(value, "x", 0.0, 1.0, unit="s")
    assert str(info.value) == message


def test_open_ends_and_no_unit():
    with pytest.raises(ValueError) as info:
        check_number(0.0, "x", 0.0, 1.0, low_open=True)
    assert str(info.value) == "x must be in (0, 1], got 0.0"
    with pytest.raises(ValueError) as info:
        check_number(1.0, "x", 0.0, 1.0, high_open=True)
    assert str(info.value) == "x must be in [0, 1), got 1.0"
    check_number(0.5, "x", 0.0, 1.0, low_open=True, high_open=True)


def test_the_monitors_messages():
    """finite_message=False: a non-number 'must be a number', NaN and inf out of range."""
    with pytest.raises(ValueError) as info:
        check_number("0.1", "x", 0.0, math.inf, low_open=True, high_open=True,
                     finite_message=False)
    assert str(info.value) == "x must be a number, got '0.1'"
    for value in (math.nan, math.inf):
        with pytest.raises(ValueError) as info:
            check_number(value, "x", 0.0, math.inf, low_open=True, high_open=True,
                         finite_message=False)
        assert str(info.value) == f"x must be in (0, inf), got {value!r}"
