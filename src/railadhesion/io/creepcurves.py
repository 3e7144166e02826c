"""Measured creep curves in CSV files: reader, writer and the :class:`CreepCurve` record.

The format is documented in ``docs/creep-curve-csv.md``. In short::

    # normal_force_N = 4200
    # speed_m_s = 5
    # water_flow_ul_s = 25
    # a_m = 0.0041
    # b_m = 0.0032
    creep,adhesion
    -0.005,0.112
    -0.010,0.168

* ``creep``: longitudinal creepage, a fraction, signed as in ``docs/CONVENTIONS.md``
  (traction < 0, braking > 0), |creep| <= 1; or ``creep_percent`` in percent (one of the two).
* ``adhesion``: the magnitude |T|/Q >= 0 (for a curve at pure longitudinal creepage, |Tx|/Q).
* metadata, per file as ``# key = value`` comment lines and/or per row as columns of the same
  name (every non-empty cell must then agree): ``normal_force_N``, ``speed_m_s``,
  ``water_flow_ul_s``, ``a_m``, ``b_m``; text keys ``name`` and ``condition`` in the header.

Rows are never dropped silently: a row with a missing, unparseable or out-of-range value is
excluded, listed in :attr:`CreepCurve.excluded` (line number and reason) and summarised by a
:class:`CreepCurveWarning`. A malformed file raises ``ValueError`` naming the column and line.
"""

from __future__ import annotations

import csv
import difflib
import io
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.plausibility import AlteredResultWarning

__all__ = [
    "CreepCurve",
    "CreepCurveWarning",
    "ExcludedRow",
    "METADATA_KEYS",
    "read_creep_curve",
    "read_creep_curves",
    "write_creep_curve",
]

#: Numeric metadata: CSV key -> (CreepCurve attribute, unit, allowed range).
METADATA_KEYS: dict[str, tuple[str, str, str]] = {
    "normal_force_N": ("normal_force", "N", "(0, inf)"),
    "speed_m_s": ("speed", "m/s", "[0, inf)"),
    "water_flow_ul_s": ("water_flow", "µl/s", "[0, inf)"),
    "a_m": ("a", "m", "(0, inf)"),
    "b_m": ("b", "m", "(0, inf)"),
}
_TEXT_KEYS = ("name", "condition")
_DATA_COLUMNS = ("creep", "creep_percent", "adhesion")
_ALLOWED_COLUMNS = _DATA_COLUMNS + tuple(METADATA_KEYS)
_CANONICAL = {k.lower(): k for k in _ALLOWED_COLUMNS + _TEXT_KEYS}
#: Largest |creep| accepted (a fraction; xi = 1 is a locked wheel).
MAX_ABS_CREEP = 1.0
#: Largest adhesion accepted (|T|/Q); anything above is taken for a unit or column mistake.
MAX_ADHESION = 2.0


class CreepCurveWarning(AlteredResultWarning):
    """Rows of a creep-curve file were excluded (see :attr:`CreepCurve.excluded`): the data
    read differ from the file's (an :class:`~railadhesion.plausibility.AlteredResultWarning`)."""


@dataclass(frozen=True)
class ExcludedRow:
    """A data row left out of a :class:`CreepCurve`, with the reason.

    Attributes
    ----------
    line : int
        1-based line number in the file (comment and header lines counted).
    reason : str
        Why the row was excluded, naming the column.
    text : str
        The row as read (fields joined by commas).
    """

    line: int
    reason: str
    text: str = ""

    def __str__(self) -> str:
        return f"line {self.line}: {self.reason}"


def _metadata_ok(attr: str, value: float) -> bool:
    if not math.isfinite(value):
        return False
    return value > 0 if attr in ("normal_force", "a", "b") else value >= 0


@dataclass(frozen=True, eq=False)
class CreepCurve:
    """One measured creep curve: adhesion against longitudinal creepage, with its conditions.

    Parameters
    ----------
    creep : array_like
        Longitudinal creepage xi [-] (fraction; traction < 0, braking > 0), 1-D, finite.
    adhesion : array_like
        Adhesion |T|/Q [-], >= 0, same length as ``creep``.
    normal_force : float, optional
        Normal force Q [N], > 0.
    speed : float, optional
        Rolling speed V [m/s], >= 0.
    water_flow : float, optional
        Water flow rate w [µl/s], >= 0.
    a, b : float, optional
        Contact semi-axes [m], ``a`` in the rolling direction, > 0.
    name : str
        Label (default: the file name without suffix).
    condition : str, optional
        Explicit condition label (e.g. a WILAC condition ``"damp2"``), overriding any mapping
        from the water flow in :func:`railadhesion.calibration.pipeline.calibrate_wilac`.
    source : str
        Path of the file read ("" if built in memory).
    excluded : tuple of ExcludedRow
        Rows of the file that were left out, with reasons.
    info : dict
        Other ``# key = value`` header entries, as text.
    """

    creep: np.ndarray
    adhesion: np.ndarray
    normal_force: float | None = None
    speed: float | None = None
    water_flow: float | None = None
    a: float | None = None
    b: float | None = None
    name: str = ""
    condition: str | None = None
    source: str = ""
    excluded: tuple[ExcludedRow, ...] = ()
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        creep = np.array(self.creep, dtype=float).reshape(-1)
        adh = np.array(self.adhesion, dtype=float).reshape(-1)
        if creep.shape != adh.shape:
            raise ValueError(
                f"creep and adhesion must have the same length, got {creep.size} and {adh.size}"
            )
        if not np.all(np.isfinite(creep)):
            raise ValueError("creep must be finite (no NaN or inf)")
        if not np.all(np.isfinite(adh) & (adh >= 0)):
            raise ValueError("adhesion must be in [0, inf) (a magnitude |T|/Q)")
        creep.flags.writeable = False
        adh.flags.writeable = False
        object.__setattr__(self, "creep", creep)
        object.__setattr__(self, "adhesion", adh)
        for key, (attr, unit, rng) in METADATA_KEYS.items():
            value = getattr(self, attr)
            if value is None:
                continue
            try:
                value = float(value)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{attr} must be a number [{unit}], got {value!r}") from exc
            if not _metadata_ok(attr, value):
                raise ValueError(f"{attr} ({key}) must be in {rng} [{unit}], got {value!r}")
            object.__setattr__(self, attr, value)
        object.__setattr__(self, "excluded", tuple(self.excluded))
        object.__setattr__(self, "info", dict(self.info))

    def __len__(self) -> int:
        return int(self.creep.size)

    def _attrs(self) -> dict:
        attrs = {"name": self.name, "source": self.source}
        if self.condition is not None:
            attrs["condition"] = self.condition
        for key, (attr, _unit, _) in METADATA_KEYS.items():
            value = getattr(self, attr)
            if value is not None:
                attrs[key] = value  # the key carries the unit (normal_force_N, speed_m_s...)
        attrs["units"] = {"creep": "1", "adhesion": "1"}
        return attrs

    def to_dataframe(self):
        """The curve as a :class:`pandas.DataFrame` (columns ``creep``, ``adhesion``).

        ``attrs`` holds the metadata (keys with units as in the CSV header, e.g.
        ``normal_force_N``) and ``attrs["units"]`` the units of the columns ("1":
        dimensionless fractions).

        Examples
        --------
        >>> c = CreepCurve([-0.01, -0.02], [0.2, 0.25], normal_force=4200.0)
        >>> df = c.to_dataframe()
        >>> list(df.columns), df.attrs["normal_force_N"]
        (['creep', 'adhesion'], 4200.0)
        """
        import pandas as pd

        df = pd.DataFrame({"creep": np.asarray(self.creep), "adhesion": np.asarray(self.adhesion)})
        df.attrs.update(self._attrs())
        return df

    def to_dataset(self):
        """The curve as an :class:`xarray.Dataset`: ``adhesion`` over the coordinate ``creep``,
        units in each variable's ``attrs``, metadata in the dataset's ``attrs``."""
        import xarray as xr

        attrs = self._attrs()
        attrs.pop("units")
        ds = xr.Dataset(
            {"adhesion": ("creep", np.asarray(self.adhesion), {"units": "1",
                                                               "long_name": "|T|/Q"})},
            coords={"creep": ("creep", np.asarray(self.creep), {"units": "1",
                                                               "long_name": "creepage xi"})},
        )  # fmt: skip
        ds.attrs.update({k: v for k, v in attrs.items() if v is not None})
        return ds

    @property
    def metadata(self) -> dict[str, float | None]:
        """Numeric metadata by attribute name: normal_force, speed, water_flow, a, b."""
        return {attr: getattr(self, attr) for attr, _, _ in METADATA_KEYS.values()}

    def require(self, *names: str) -> None:
        """Raise ``ValueError`` naming the file and keys if any metadata in ``names`` is missing.

        ``names`` are attribute names (``"normal_force"``, ``"speed"``, ...).
        """
        key_of = {attr: key for key, (attr, _, _) in METADATA_KEYS.items()}
        missing = [n for n in names if getattr(self, n) is None]
        if missing:
            where = self.source or self.name or "creep curve"
            keys = ", ".join(f"{key_of.get(n, n)} ({n})" for n in missing)
            raise ValueError(
                f"{where}: missing metadata {keys}; give it as a '# key = value' header line "
                "or a column (docs/creep-curve-csv.md)"
            )


def _parse_float(text: str) -> float | None:
    """Float of ``text``; None if empty/unparseable. 'nan' parses to NaN."""
    text = text.strip()
    if not text:
        return None
    try:
        return float(text)
    except ValueError:
        return None


def _header_entry(line: str, lineno: int, path: str, meta: dict, text_meta: dict, info: dict):
    body = line.lstrip()[1:].strip()
    if "=" not in body:
        return  # a plain comment
    key, _, value = body.partition("=")
    key, value = key.strip(), value.strip()
    key = _CANONICAL.get(key.lower(), key)
    if not key or " " in key:
        return  # prose containing '=' is a comment, not metadata
    if key in METADATA_KEYS:
        attr, unit, rng = METADATA_KEYS[key]
        number = _parse_float(value)
        if number is None or not _metadata_ok(attr, number):
            raise ValueError(
                f"{path}, line {lineno}: metadata {key} must be a number in {rng} [{unit}], "
                f"got {value!r}"
            )
        if key in meta and meta[key][0] != number:
            raise ValueError(
                f"{path}, line {lineno}: metadata {key} given twice with different values "
                f"({meta[key][0]!r} on line {meta[key][1]}, {number!r} here)"
            )
        meta[key] = (number, lineno)
    elif key in _TEXT_KEYS:
        text_meta[key] = value
    else:
        close = difflib.get_close_matches(key, list(METADATA_KEYS) + list(_TEXT_KEYS), n=1)
        if close:
            raise ValueError(
                f"{path}, line {lineno}: unknown metadata key {key!r}; did you mean "
                f"{close[0]!r}? Known keys: {', '.join(list(METADATA_KEYS) + list(_TEXT_KEYS))}"
            )
        info[key] = value


def read_creep_curve(path) -> CreepCurve:
    """Read one creep curve from a CSV file (format: ``docs/creep-curve-csv.md``).

    Parameters
    ----------
    path : str or path-like
        The CSV file.

    Returns
    -------
    CreepCurve
        Creep as a fraction (``creep_percent`` is divided by 100), adhesion, metadata, and
        :attr:`CreepCurve.excluded` listing every data row left out.

    Raises
    ------
    ValueError
        Malformed file: no header row, unknown or duplicated column, neither or both of
        ``creep``/``creep_percent``, no ``adhesion`` column, a row with the wrong number of
        fields, a column without any numeric value, metadata out of range or inconsistent
        (between rows, or between a column and the header), or no valid row left. The
        message names the file, the column and the line.

    Warns
    -----
    CreepCurveWarning
        When rows were excluded (missing/NaN, unparseable or out-of-range creep or adhesion):
        one summary warning per file.

    Examples
    --------
    >>> import tempfile, os
    >>> text = "# normal_force_N = 4200\\n# speed_m_s = 5\\n"
    >>> text += "creep_percent,adhesion\\n-1,0.2\\n-2,0.25\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "creep_demo.csv")
    ...     with open(p, "w") as f:
    ...         _ = f.write(text)
    ...     curve = read_creep_curve(p)
    >>> curve.creep.tolist(), curve.adhesion.tolist(), curve.normal_force, curve.speed
    ([-0.01, -0.02], [0.2, 0.25], 4200.0, 5.0)
    """
    path = Path(path)
    where = str(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise ValueError(f"cannot read creep-curve file {where}: {exc}") from exc
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"{where}: not a UTF-8 text file (byte {exc.start}: {exc.reason}); save the CSV "
            "as UTF-8"
        ) from None

    meta: dict[str, tuple[float, int]] = {}
    text_meta: dict[str, str] = {}
    info: dict[str, str] = {}
    header: list[str] | None = None
    header_line = 0
    rows: list[tuple[int, list[str]]] = []
    blank_rows: list[tuple[int, str]] = []
    # Split on "\n" only (read_text has already turned "\r\n" and "\r" into "\n"):
    # str.splitlines would also split at form feeds and other separators, shifting the line
    # numbers reported below.
    for lineno, line in enumerate(text.split("\n"), start=1):
        if line.lstrip().startswith("#"):
            _header_entry(line, lineno, where, meta, text_meta, info)
            continue
        fields = next(csv.reader([line])) if line.strip() else []
        if all(not f.strip() for f in fields):
            if header is not None and line.strip():
                # separators only (",,"; spreadsheets write these): a data row without data,
                # reported below rather than dropped silently
                blank_rows.append((lineno, line))
            continue  # blank line
        if header is None:
            header = [_CANONICAL.get(f.strip().lower(), f.strip()) for f in fields]
            header_line = lineno
            if len(header) == 1:
                for sep, label in ((";", "semicolons"), ("\t", "tabs")):
                    if sep in header[0]:
                        raise ValueError(
                            f"{where}, line {lineno}: header {line.strip()!r} is separated by "
                            f"{label}; the separator must be a comma (docs/creep-curve-csv.md)"
                        )
            _check_header(header, where, lineno)
            continue
        if len(fields) != len(header):
            raise ValueError(
                f"{where}, line {lineno}: expected {len(header)} fields "
                f"({', '.join(header)}), found {len(fields)}"
            )
        rows.append((lineno, fields))
    if header is None:
        raise ValueError(
            f"{where}: no header row; expected columns 'creep' (or 'creep_percent') and "
            "'adhesion'"
        )
    if not rows:
        empty = f" ({len(blank_rows)} rows hold separators only)" if blank_rows else ""
        raise ValueError(f"{where}: no data rows after the header (line {header_line}){empty}")

    col = {name: i for i, name in enumerate(header)}
    creep_name = "creep" if "creep" in col else "creep_percent"
    factor = 1.0 if creep_name == "creep" else 0.01

    # A column is non-numeric if none of its non-empty cells parses as a number.
    for name, i in col.items():
        cells = [(ln, f[i].strip()) for ln, f in rows if f[i].strip()]
        if cells and all(_parse_float(c) is None for _, c in cells):
            ln, c = cells[0]
            raise ValueError(
                f"{where}: column '{name}' is not numeric (line {ln}: {c!r})"
            )

    # Per-row metadata columns: every non-empty cell must agree with the others and the header.
    for key in METADATA_KEYS:
        if key not in col:
            continue
        attr, unit, rng = METADATA_KEYS[key]
        ref: tuple[float, int] | None = meta.get(key)
        for ln, f in rows:
            cell = f[col[key]].strip()
            if not cell:
                continue
            number = _parse_float(cell)
            if number is None or not _metadata_ok(attr, number):
                raise ValueError(
                    f"{where}, line {ln}: column '{key}' must be a number in {rng} [{unit}], "
                    f"got {cell!r}"
                )
            if ref is None:
                ref = (number, ln)
            elif not math.isclose(number, ref[0], rel_tol=1e-9, abs_tol=0.0):
                raise ValueError(
                    f"{where}, line {ln}: inconsistent metadata in column '{key}': {number!r} "
                    f"differs from {ref[0]!r} (line {ref[1]}); a file holds one curve at "
                    "one condition"
                )
        if ref is not None:
            meta[key] = ref

    creep_vals, adh_vals, excluded = [], [], []
    limit_c = MAX_ABS_CREEP / factor
    for ln, line in blank_rows:
        excluded.append(ExcludedRow(ln, "row is empty (separators only)", line))
    for ln, f in rows:
        raw_c, raw_a = f[col[creep_name]].strip(), f[col["adhesion"]].strip()
        c, a = _parse_float(raw_c), _parse_float(raw_a)
        reason = None
        if c is None and not raw_c:
            reason = f"{creep_name} is empty"
        elif c is None:
            reason = f"{creep_name} cannot be parsed as a number: {raw_c!r}"
        elif not math.isfinite(c):
            reason = f"{creep_name} is {raw_c}"
        elif abs(c) > limit_c:
            hint = " (a fraction; use a 'creep_percent' column for percent)" if factor == 1 else ""
            reason = f"{creep_name} = {c:g} is outside [-{limit_c:g}, {limit_c:g}]{hint}"
        elif a is None and not raw_a:
            reason = "adhesion is empty"
        elif a is None:
            reason = f"adhesion cannot be parsed as a number: {raw_a!r}"
        elif not math.isfinite(a):
            reason = f"adhesion is {raw_a}"
        elif not 0.0 <= a <= MAX_ADHESION:
            reason = f"adhesion = {a:g} is outside [0, {MAX_ADHESION:g}] (a magnitude |T|/Q)"
        if reason is not None:
            excluded.append(ExcludedRow(ln, reason, ",".join(f)))
            continue
        creep_vals.append(c * factor)
        adh_vals.append(a)

    if excluded:
        excluded.sort(key=lambda e: e.line)
        shown = "; ".join(str(e) for e in excluded[:5])
        more = f"; ... ({len(excluded) - 5} more)" if len(excluded) > 5 else ""
        n_rows = len(rows) + len(blank_rows)
        warnings.warn(
            f"{where}: {len(excluded)} of {n_rows} data rows excluded ({shown}{more}); "
            "see CreepCurve.excluded",
            CreepCurveWarning,
            stacklevel=2,
        )
    if not creep_vals:
        raise ValueError(
            f"{where}: no valid data row (all {len(rows) + len(blank_rows)} rows excluded)"
        )

    kwargs = {METADATA_KEYS[k][0]: v[0] for k, v in meta.items()}
    return CreepCurve(
        creep=np.array(creep_vals),
        adhesion=np.array(adh_vals),
        name=text_meta.get("name") or path.stem,
        condition=text_meta.get("condition") or None,
        source=where,
        excluded=tuple(excluded),
        info=info,
        **kwargs,
    )


def _check_header(header: list[str], where: str, lineno: int) -> None:
    seen = set()
    for name in header:
        if name in seen:
            raise ValueError(f"{where}, line {lineno}: column '{name}' appears twice")
        seen.add(name)
        if not name:
            raise ValueError(
                f"{where}, line {lineno}: column {len(seen)} of the header has no name (a "
                "trailing or doubled comma?); allowed columns: "
                f"{', '.join(_ALLOWED_COLUMNS)}"
            )
        if name not in _ALLOWED_COLUMNS:
            raise ValueError(
                f"{where}, line {lineno}: unknown column '{name}'; allowed columns: "
                f"{', '.join(_ALLOWED_COLUMNS)}"
            )
    if "adhesion" not in seen:
        raise ValueError(f"{where}, line {lineno}: missing required column 'adhesion'")
    has_c, has_p = "creep" in seen, "creep_percent" in seen
    if not (has_c or has_p):
        raise ValueError(
            f"{where}, line {lineno}: missing required column 'creep' (or 'creep_percent')"
        )
    if has_c and has_p:
        raise ValueError(
            f"{where}, line {lineno}: columns 'creep' and 'creep_percent' are both present; "
            "give one"
        )


def read_creep_curves(folder, pattern: str = "*.csv") -> list[CreepCurve]:
    """Read every creep-curve CSV file in ``folder`` (sorted by file name).

    Parameters
    ----------
    folder : str or path-like
        Directory holding the files (not searched recursively).
    pattern : str, default ``"*.csv"``
        Glob pattern of the files to read.

    Returns
    -------
    list of CreepCurve

    Raises
    ------
    ValueError
        If ``folder`` is not a directory, holds no matching file, or a file is malformed (the
        message of :func:`read_creep_curve`, naming the file).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     for i, w in enumerate((0, 350)):
    ...         with open(os.path.join(d, f"creep_{i}.csv"), "w") as f:
    ...             _ = f.write(f"# water_flow_ul_s = {w}\\ncreep,adhesion\\n-0.01,0.2\\n")
    ...     [c.water_flow for c in read_creep_curves(d)]
    [0.0, 350.0]
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"folder must be an existing directory, got {str(folder)!r}")
    files = sorted(p for p in folder.glob(pattern) if p.is_file())
    if not files:
        raise ValueError(f"folder {str(folder)!r} holds no file matching {pattern!r}")
    return [read_creep_curve(p) for p in files]


def write_creep_curve(curve: CreepCurve, path, *, percent: bool = False) -> Path:
    """Write ``curve`` as a CSV file readable by :func:`read_creep_curve`.

    Metadata go into ``# key = value`` header lines; excluded rows are not written.

    Parameters
    ----------
    curve : CreepCurve
        The curve.
    path : str or path-like
        Output file (overwritten).
    percent : bool, default False
        Write a ``creep_percent`` column instead of ``creep``.

    Returns
    -------
    pathlib.Path
        The path written.

    Examples
    --------
    >>> import tempfile, os
    >>> c = CreepCurve(creep=[-0.01, -0.05], adhesion=[0.2, 0.18], normal_force=4200.0)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_creep_curve(c, os.path.join(d, "creep_x.csv"))
    ...     back = read_creep_curve(p)
    >>> back.adhesion.tolist(), back.normal_force
    ([0.2, 0.18], 4200.0)
    """
    buf = io.StringIO()
    if curve.name:
        buf.write(f"# name = {curve.name}\n")
    if curve.condition:
        buf.write(f"# condition = {curve.condition}\n")
    for key, (attr, _, _) in METADATA_KEYS.items():
        value = getattr(curve, attr)
        if value is not None:
            buf.write(f"# {key} = {value!r}\n")
    for key, value in curve.info.items() if isinstance(curve.info, Mapping) else ():
        buf.write(f"# {key} = {value}\n")
    name = "creep_percent" if percent else "creep"
    buf.write(f"{name},adhesion\n")
    scale = 100.0 if percent else 1.0
    for c, a in zip(curve.creep, curve.adhesion, strict=True):
        buf.write(f"{float(c) * scale!r},{float(a)!r}\n")
    path = Path(path)
    path.write_text(buf.getvalue(), encoding="utf-8")
    return path
