"""Tables of settings: each setting's default, allowed range, unit and source, in one TOML file.

The settings classes of the default WSP (:class:`railadhesion.braking.WSPSettings`), the
reference odometry (:class:`~railadhesion.braking.odometry.OdometrySettings`) and the adhesion
monitor (:class:`railadhesion.monitor.MonitorSettings`) each read their table from
``railadhesion/data/<name>.toml``: one section per setting, in the order of the class's fields,
with its ``default`` (absent: None), ``range = [low, high]`` (absent: not a number checked by
range), ``unit`` and ``source`` (the source, or the word *assumption*; the monitor's table has
neither, its docstring gives them, and ``open`` names the open ends of a range). The class's
dataclass fields, the ranges it checks and its ``sources()`` come from that table, so each
default is written once.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields
from importlib import resources

__all__ = [
    "read_settings_table",
    "settings_spec",
    "settings_dataclass",
    "sourced_settings",
]


def read_settings_table(name: str) -> dict:
    """The table ``railadhesion/data/<name>.toml``: ``{setting: entry}`` in the file's order,
    each entry the mapping of its section (``default``, ``range``, ``unit``, ``source``, ...)."""
    text = (resources.files("railadhesion.data") / f"{name}.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def settings_spec(name: str) -> dict:
    """The table ``name`` as ``{setting: (default, low, high, unit, source)}`` (None where the
    table has no default or no range)."""
    spec = {}
    for key, entry in read_settings_table(name).items():
        low, high = entry.get("range", (None, None))
        spec[key] = (entry.get("default"), low, high, entry["unit"], entry["source"])
    return spec


def _annotation(default) -> str:
    if default is None:
        return "float | None"
    return type(default).__name__


def settings_dataclass(defaults: dict, types: dict | None = None):
    """Class decorator: a frozen dataclass whose fields are ``defaults``' names, in its order,
    with those defaults; annotated by the default's type (``float | None`` for None) unless
    ``types`` names another. The class's own methods (``__init__``, ``__post_init__``, ...)
    are kept."""
    types = types or {}

    def make(cls):
        cls.__annotations__ = {
            name: types.get(name, _annotation(default)) for name, default in defaults.items()
        }
        for name, default in defaults.items():
            setattr(cls, name, default)
        return dataclass(frozen=True)(cls)

    return make


def sourced_settings(spec: dict, types: dict | None = None):
    """Class decorator: :func:`settings_dataclass` of a :func:`settings_spec` table, with
    ``as_dict()`` (the settings by name) and ``sources()`` (each setting's default, unit and
    source) made from it."""

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def sources() -> dict:
        """Each setting: ``(default, unit, source or 'assumption')``."""
        return {k: (v[0], v[3], v[4]) for k, v in spec.items()}

    def make(cls):
        for function in (as_dict, sources):
            function.__qualname__ = f"{cls.__qualname__}.{function.__name__}"
            function.__module__ = cls.__module__
        cls.as_dict = as_dict
        cls.sources = staticmethod(sources)
        return settings_dataclass({name: entry[0] for name, entry in spec.items()}, types)(cls)

    return make
