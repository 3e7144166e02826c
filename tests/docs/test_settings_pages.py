"""The settings table of docs/wsp.md says what ``WSPSettings.sources()`` says.

The page's table was written by hand; one row once kept an old default (``probe_accuracy`` 0.5
and "1.5 %" where the code had 1.0 and "3 %"). This test reads every row naming a setting and
compares its default, unit and source with the class's.
"""

import re
from pathlib import Path

from railadhesion.braking import WSPSettings

PAGE = Path(__file__).resolve().parents[2] / "docs" / "wsp.md"
ROW = re.compile(r"^\| `(\w+)` \| ([^|]*) \| ([^|]*) \| (.*) \|$")


def _rows():
    sources = WSPSettings.sources()
    rows = {}
    for line in PAGE.read_text(encoding="utf-8").splitlines():
        m = ROW.match(line.rstrip())
        if m and m.group(1) in sources:
            rows[m.group(1)] = tuple(v.strip() for v in m.groups()[1:])
    return sources, rows


def test_every_number_setting_has_its_row():
    sources, rows = _rows()
    missing = [k for k, (default, _, _) in sources.items()
               if k not in rows and isinstance(default, int | float)]  # fmt: skip
    assert not missing, f"docs/wsp.md has no row for {missing}"


def test_rows_equal_the_sources():
    sources, rows = _rows()
    wrong = []
    for name, (default, unit, source) in rows.items():
        want_default, want_unit, want_source = sources[name]
        if want_default is None:
            ok_default = default in ("from the vehicle", "None", "-", "")
        else:
            try:
                ok_default = float(default) == float(want_default)
            except ValueError:
                ok_default = default == str(want_default)
        if not ok_default or unit != want_unit or source != want_source:
            wrong.append(name)
    assert not wrong, f"docs/wsp.md rows differ from WSPSettings.sources(): {wrong}"
