"""Shared docstring entries: a decorator that fills ``{key}`` fields of a docstring.

Several public functions document the same arguments (the creepages of the creep-force
functions, the quality gate of the fits); each entry is written once and put in place by
:func:`docstring_entries`.
"""

from __future__ import annotations

__all__ = ["docstring_entries"]


def docstring_entries(**entries: str):
    """A decorator that puts ``entries[key]`` in place of each ``{key}`` in the docstring of
    the function it decorates (and returns that function). The entries are inserted as they
    are: indent their continuation lines for where they go (a module-level function's
    parameters: four spaces, continuations eight)."""

    def fill(func):
        if func.__doc__:  # None under python -OO
            doc = func.__doc__
            for key, text in entries.items():
                doc = doc.replace("{" + key + "}", text)
            func.__doc__ = doc
        return func

    return fill
