"""Tables of settings: each setting's allowed range, unit and source, in one TOML file.

The settings classes of the default WSP (:class:`railadhesion.braking.WSPSettings`), the
reference odometry (:class:`~railadhesion.braking.odometry.OdometrySettings`) and the adhesion
monitor (:class:`railadhesion.monitor.MonitorSettings`) are ordinary frozen dataclasses: their
fields, with their types and defaults, are written in Python, in the class. What is data about
them is in the class's table ``railadhesion/data/<name>.toml``: one section per field, in the
order of the fields, with

``range = [low, high]``
    the allowed range (absent: not a number checked by range);
``open``
    the open ends of the range, ``"low"``, ``"high"`` or ``"both"`` (absent: closed);
``unit`` and ``source``
    the unit, and the source of the default or the word *assumption* (the monitor's table
    has neither: its docstring gives them).

No table holds a default: a class's ``sources()`` takes each default from its field
(:func:`settings_sources`), so each default is written once. ``tests/io/test_settings_table.py``
holds each table to its class: the same names in the same order, and a range for every
setting whose default is a number.
"""

from __future__ import annotations

import tomllib
from dataclasses import fields
from importlib import resources
from typing import NamedTuple

from railadhesion._validate import check_number

__all__ = [
    "SettingRange",
    "read_settings_table",
    "settings_ranges",
    "settings_sources",
]

# the ``open`` entry of a range: (low end open, high end open)
_OPEN_ENDS = {None: (False, False), "low": (True, False), "high": (False, True),
              "both": (True, True)}


class SettingRange(NamedTuple):
    """The allowed range of a setting, from its table: ``low`` to ``high`` in ``unit`` (the
    ends included unless ``low_open`` or ``high_open``)."""

    low: float
    high: float
    unit: str = ""
    low_open: bool = False
    high_open: bool = False

    def check(self, name: str, value, *, finite_message: bool = True) -> None:
        """Raise ``ValueError`` naming the setting ``name`` unless ``value`` is a finite
        number in the range (the package's one range check, ``check_number``)."""
        check_number(value, name, self.low, self.high, unit=self.unit, low_open=self.low_open,
                     high_open=self.high_open, finite_message=finite_message)


def read_settings_table(name: str) -> dict:
    """The table ``railadhesion/data/<name>.toml``: ``{setting: entry}`` in the file's order,
    each entry the mapping of its section (``range``, ``open``, ``unit``, ``source``)."""
    text = (resources.files("railadhesion.data") / f"{name}.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def settings_ranges(table: dict) -> dict[str, SettingRange]:
    """``{setting: SettingRange}`` of the settings of ``table`` (:func:`read_settings_table`)
    that have a range, in the table's order."""
    ranges = {}
    for name, entry in table.items():
        if "range" not in entry:
            continue
        if entry.get("open") not in _OPEN_ENDS:
            raise ValueError(f"setting {name}: open must be 'low', 'high' or 'both', got "
                             f"{entry['open']!r}")
        low, high = entry["range"]
        ranges[name] = SettingRange(low, high, entry.get("unit", ""),
                                    *_OPEN_ENDS[entry.get("open")])
    return ranges


def settings_sources(cls, table: dict) -> dict:
    """Each setting of the dataclass ``cls``: ``(default, unit, source or 'assumption')``, the
    default from its field, the unit and source from ``table``, in the order of the fields."""
    return {f.name: (f.default, table[f.name]["unit"], table[f.name]["source"])
            for f in fields(cls)}
