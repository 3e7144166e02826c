"""The settings tables (railadhesion/data/*_settings.toml) against their classes: the fields
(with the defaults) are written in Python, the ranges, units and sources in the tables; these
tests keep the two from drifting apart."""

import dataclasses
import math

import pytest

from railadhesion.braking.odometry import OdometrySettings
from railadhesion.braking.wsp import WSPSettings
from railadhesion.io.settings_table import (
    SettingRange,
    read_settings_table,
    settings_ranges,
    settings_sources,
)
from railadhesion.monitor import MonitorSettings

CLASSES = {"wsp_settings": WSPSettings, "odometry_settings": OdometrySettings,
           "monitor_settings": MonitorSettings}
KEYS = {"range", "open", "unit", "source"}  # (no "default": the fields hold the defaults)


def _is_number(value):
    return isinstance(value, int | float) and not isinstance(value, bool)


@pytest.mark.parametrize("table, cls", CLASSES.items())
def test_the_table_names_the_fields_in_their_order(table, cls):
    assert list(read_settings_table(table)) == [f.name for f in dataclasses.fields(cls)]


@pytest.mark.parametrize("table, cls", CLASSES.items())
def test_every_number_has_a_range_holding_its_default(table, cls):
    ranges = settings_ranges(read_settings_table(table))
    for f in dataclasses.fields(cls):
        if _is_number(f.default):
            assert f.name in ranges, f.name
            ranges[f.name].check(f.name, f.default, finite_message=table != "monitor_settings")


@pytest.mark.parametrize("table", CLASSES)
def test_the_tables_hold_no_default_and_nothing_unknown(table):
    for name, entry in read_settings_table(table).items():
        assert set(entry) <= KEYS, name
        if table != "monitor_settings":  # (the monitor's docstring gives units and sources)
            assert {"unit", "source"} <= set(entry) and entry["source"], name
        if "range" in entry:
            low, high = entry["range"]
            assert low < high, name


@pytest.mark.parametrize("cls", [WSPSettings, OdometrySettings])
def test_sources_take_the_defaults_from_the_fields(cls):
    sources = cls.sources()
    assert list(sources) == [f.name for f in dataclasses.fields(cls)]
    for f in dataclasses.fields(cls):
        assert sources[f.name][0] is f.default or sources[f.name][0] == f.default, f.name


def test_ranges_read_the_open_ends():
    table = {"a": {"range": [0.0, math.inf], "open": "both"}, "b": {"range": [1, 2]},
             "c": {"range": [0.0, 1.0], "open": "low", "unit": "s"}, "d": {}}
    assert settings_ranges(table) == {"a": SettingRange(0.0, math.inf, "", True, True),
                                      "b": SettingRange(1, 2),
                                      "c": SettingRange(0.0, 1.0, "s", True, False)}
    with pytest.raises(ValueError, match="open must be"):
        settings_ranges({"a": {"range": [0, 1], "open": "left"}})


def test_sources_of_a_dataclass():
    @dataclasses.dataclass(frozen=True)
    class Two:
        x: float = 1.0
        y: str | None = None

    table = {"x": {"unit": "s", "source": "assumption"}, "y": {"unit": "", "source": "s"}}
    assert settings_sources(Two, table) == {"x": (1.0, "s", "assumption"), "y": (None, "", "s")}
