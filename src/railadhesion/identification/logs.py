"""Braking-test logs: reader with defect reports (format: ``docs/braking-log.md``).

A log holds, per sample, the time [s], the train speed [m/s] and, per axle ``i = 1..N``, the
wheelset angular speed ``wheel_speed_i`` [rad/s] and the brake-cylinder pressure
``brake_pressure_i`` [bar in the file, Pa in memory], as recorded in the braking tests of
Allotta, Malvezzi and Toni (seed 002, §5: sampling period 2.4 ms). CSV (``.csv``, optionally
compressed) or Parquet (``.parquet``/``.pq``) with the same column names.

Real logs are messy. :func:`read_braking_log` repairs what it can and reports every defect as
a :class:`LogIssue` (kind, channel, rows, action); nothing is dropped silently. Row numbers are
0-based positions of the data rows in the file as read (CSV line = row + 2, the header being
line 1). The rules:

=================  =====================================================================
defect             action
=================  =====================================================================
unparseable cell   read as NaN, then treated as a missing value (below)
time missing       row removed
unsorted times     rows sorted by time (stable)
duplicate time     first row kept, later rows with the same time removed
missing value      interpolated linearly in time; runs longer than ``max_fill`` seconds
                   are also marked invalid (not used for identification)
time gap           sampling interval > ``gap_factor`` x the median: the log is split into
                   segments there (filters and derivatives never cross a gap)
stuck channel      a wheel speed exactly constant (and > 0) for ``stuck_time`` while the
                   train speed changes by more than 1 m/s, or a pressure exactly constant
                   for ``stuck_pressure_time`` while the mean of the other axles' pressures
                   changes by more than 0.5 bar: those samples are invalid for that axle
missing channel    column absent or all NaN: the axle is excluded from identification; for
                   the brake coefficient (eq. 14, which needs every axle) the mean of the
                   other axles' channel is substituted
=================  =====================================================================

Units are sniffed as well (``docs/checks.md``): pressures outside the plausible range of a
brake cylinder in bar (Pa, kPa or psi under the bar column names), a train speed that is not
the wheels' ``R omega`` while they roll (km/h, mph; wheel speeds in rpm), a sampling period
too long for a braking-test log (time in ms). Each gives a
:class:`~railadhesion.plausibility.UnitWarning` naming the column and the likely unit, and is
kept in :attr:`BrakingLog.warnings`; the values are not changed.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.io.axle_log import AxleLog
from railadhesion.plausibility import (
    AlteredResultWarning,
    check_plausible,
    sniff_sample_period,
    sniff_speed_ratio,
)

__all__ = [
    "BAR",
    "BrakingLog",
    "BrakingLogWarning",
    "LogIssue",
    "read_braking_log",
    "braking_log_from_frame",
]

#: One bar in pascal (log files hold pressures in bar; the library works in Pa).
BAR = 1.0e5

_WHEEL = re.compile(r"^wheel_speed_(\d+)$")
_PRESSURE = re.compile(r"^brake_pressure_(\d+)$")


class BrakingLogWarning(AlteredResultWarning):
    """A braking log had defects, repaired or marked (see :attr:`BrakingLog.issues`): the data
    differ from the file's (an :class:`~railadhesion.plausibility.AlteredResultWarning`)."""


@dataclass(frozen=True)
class LogIssue:
    """One defect found in a braking log and what was done about it.

    Attributes
    ----------
    kind : str
        ``"unparseable"``, ``"missing-time"``, ``"unsorted"``, ``"duplicate-time"``,
        ``"missing-values"``, ``"gap"``, ``"stuck-channel"``, ``"missing-channel"``.
    channel : str
        Column concerned (``""`` for whole rows).
    rows : ndarray of int
        0-based data rows of the file concerned (CSV line = row + 2).
    action : str
        What the reader did.
    """

    kind: str
    channel: str
    rows: np.ndarray
    action: str

    def __str__(self) -> str:
        rows = np.asarray(self.rows)
        shown = ", ".join(str(int(r)) for r in rows[:8]) + (" ..." if rows.size > 8 else "")
        where = f" rows [{shown}] ({rows.size})" if rows.size else ""
        chan = f" {self.channel}" if self.channel else ""
        return f"{self.kind}{chan}:{where} -> {self.action}"


@dataclass(frozen=True, eq=False)
class BrakingLog(AxleLog):
    """A braking-test log, sorted and repaired, in SI units.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Time [s], strictly increasing.
    train_speed : ndarray, shape (n,)
        Train (vehicle) speed v [m/s].
    wheel_speed : ndarray, shape (n, N)
        Wheelset angular speeds omega_i [rad/s], axle 1 leading.
    brake_pressure : ndarray, shape (n, N)
        Brake-cylinder pressures p_i [Pa].
    valid : ndarray of bool, shape (n, N)
        Samples usable for identification, per axle (False: interpolated over a long run of
        missing values, stuck or missing channel).
    segment : ndarray of int, shape (n,)
        Index of the contiguous segment of each sample (segments are separated by time gaps).
    issues : tuple of LogIssue
        Every defect found, with rows and action.
    source : str
        File read ("" if built in memory).
    rows : ndarray of int, shape (n,)
        For each sample, its 0-based data row in the file.
    substituted : ndarray of bool, shape (N,)
        Axles with a missing channel replaced by the mean of the others' (used only in the
        brake coefficient, eq. 14; the axle itself is not identified).
    warnings : tuple of str
        Columns whose values look as if they were in another unit (module notes); a log with
        such findings should not be identified from until they are explained.
    """

    valid: np.ndarray
    segment: np.ndarray
    issues: tuple = ()
    source: str = ""
    rows: np.ndarray = field(default=None)
    substituted: np.ndarray = field(default=None)
    warnings: tuple = ()

    @property
    def period(self) -> float:
        """Median sampling period [s]."""
        return float(np.median(np.diff(self.time))) if self.time.size > 1 else float("nan")

    def report(self) -> str:
        """The defects, one per line ("no defects" if none)."""
        if not self.issues:
            return "no defects"
        return "\n".join(str(i) for i in self.issues)


def _channel_columns(columns):
    wheels, pressures = {}, {}
    for col in columns:
        m = _WHEEL.match(col)
        if m:
            wheels[int(m.group(1))] = col
        m = _PRESSURE.match(col)
        if m:
            pressures[int(m.group(1))] = col
    n = max([*wheels, *pressures, 0])
    return n, wheels, pressures


def _runs(mask: np.ndarray):
    """(start, stop) index pairs of the runs of True in a 1-D boolean array."""
    if not mask.any():
        return np.zeros((0, 2), dtype=np.int64)
    d = np.diff(np.concatenate(([0], mask.view(np.int8), [0])))
    starts = np.flatnonzero(d == 1)
    stops = np.flatnonzero(d == -1)
    return np.stack([starts, stops], axis=1)


def _constant_runs(x: np.ndarray, min_len: int):
    """Runs of at least ``min_len`` samples over which ``x`` does not change at all."""
    same = np.diff(x) == 0
    runs = _runs(same)
    if runs.size == 0:
        return runs
    runs = runs.copy()
    runs[:, 1] += 1  # a run of k equal differences covers k + 1 samples
    return runs[(runs[:, 1] - runs[:, 0]) >= min_len]


def braking_log_from_frame(
    frame,
    *,
    source: str = "",
    max_fill: float = 0.05,
    gap_factor: float = 3.0,
    stuck_time: float = 1.0,
    stuck_pressure_time: float = 5.0,
    warn: bool = True,
) -> BrakingLog:
    """Build a :class:`BrakingLog` from a pandas DataFrame holding the log columns.

    Parameters
    ----------
    frame : pandas.DataFrame
        Columns ``time`` [s], ``train_speed`` [m/s], ``wheel_speed_1..N`` [rad/s],
        ``brake_pressure_1..N`` [bar]; other columns are ignored (reported).
    source : str
        Name of the file, for messages.
    max_fill : float, default 0.05
        Longest run of missing values [s] interpolated and still used for identification.
    gap_factor : float, default 3
        A sampling interval longer than ``gap_factor`` x the median starts a new segment.
    stuck_time, stuck_pressure_time : float, default 1 s and 5 s
        Shortest constant run reported as a stuck wheel-speed / pressure channel [s].
    warn : bool, default True
        Emit one :class:`BrakingLogWarning` summarising the defects.

    Returns
    -------
    BrakingLog

    Raises
    ------
    ValueError
        No ``time`` or ``train_speed`` column, no axle channel, fewer than 3 usable rows.
    """
    names = [str(c).strip() for c in frame.columns]
    _check_unique(names, source)
    columns = dict(zip(names, frame.columns, strict=True))
    return _log_from_columns(
        names, lambda name: frame[columns[name]], len(frame), source=source,
        max_fill=max_fill, gap_factor=gap_factor, stuck_time=stuck_time,
        stuck_pressure_time=stuck_pressure_time, warn=warn, stacklevel=4,
    )


def _check_unique(names, source) -> None:
    """ValueError if two columns have the same name once surrounding spaces are stripped (which
    one is the channel would be a guess)."""
    seen: dict[str, int] = {}
    for k, name in enumerate(names):
        if name in seen:
            raise ValueError(
                f"{source}: columns {seen[name] + 1} and {k + 1} are both named {name!r} "
                "(after stripping spaces): keep one"
            )
        seen[name] = k


def _as_float(col, name, rows, issues):
    """A column as float64 (a view when it already is): numbers as they are; anything else
    converted, with the cells that are not numbers reported as unparseable."""
    import pandas as pd

    if isinstance(col, np.ndarray) and col.dtype.kind in "fiu":
        return col.astype(float, copy=False)
    if not isinstance(col, pd.Series):
        col = pd.Series(col)
    if col.dtype.kind in "fiu":
        return col.to_numpy(dtype=float)
    num = pd.to_numeric(col, errors="coerce")
    arr = num.to_numpy(dtype=float)
    bad = np.flatnonzero(np.isnan(arr) & col.notna().to_numpy()
                         & (col.astype(str).str.strip() != "").to_numpy())
    if bad.size:
        issues.append(LogIssue("unparseable", name, rows[bad], "read as missing"))
    return arr


def _log_from_columns(
    cols, get, n_rows, *, source="", max_fill=0.05, gap_factor=3.0, stuck_time=1.0,
    stuck_pressure_time=5.0, warn=True, stacklevel=3,
) -> BrakingLog:
    """The reader's rules (module notes) on columns: ``cols`` the column names (stripped),
    ``get(name)`` one column (NumPy array or pandas Series), ``n_rows`` the number of rows."""
    where = f"{source}: " if source else ""
    for req in ("time", "train_speed"):
        if req not in cols:
            raise ValueError(f"{where}the log has no {req!r} column (columns: {cols[:12]})")
    n_ax, wheels, pressures = _channel_columns(cols)
    if n_ax == 0:
        raise ValueError(
            f"{where}the log has no wheel_speed_i or brake_pressure_i column (columns: "
            f"{cols[:12]})"
        )
    issues: list[LogIssue] = []
    extra = [c for c in cols if c not in ("time", "train_speed") and not _WHEEL.match(c)
             and not _PRESSURE.match(c)]  # fmt: skip
    if extra:
        issues.append(LogIssue("unknown-columns", ", ".join(extra), np.zeros(0, int),
                               "ignored"))  # fmt: skip
    rows = np.arange(n_rows)
    names = ["time", "train_speed"]
    names += [wheels.get(i, f"wheel_speed_{i}") for i in range(1, n_ax + 1)]
    names += [pressures.get(i, f"brake_pressure_{i}") for i in range(1, n_ax + 1)]
    present = set(cols)
    data = {}
    for name in names:
        if name not in present:
            data[name] = None
            continue
        data[name] = _as_float(get(name), name, rows, issues)
    t = data["time"]
    # -- missing time: the row cannot be placed
    bad_t = ~np.isfinite(t)
    any_bad_t = bool(bad_t.any())
    if any_bad_t:
        issues.append(LogIssue("missing-time", "time", rows[bad_t], "rows removed"))
        keep = ~bad_t
        kept_rows = rows[keep]
        tk = t[keep]
    else:
        kept_rows = rows
        tk = t
    # -- unsorted: sort by time (stable)
    steps = np.diff(tk)
    unsorted = bool(np.any(steps < 0))
    if unsorted:
        back = np.flatnonzero(steps < 0) + 1
        issues.append(LogIssue("unsorted", "time", kept_rows[back],
                               "rows sorted by time"))  # fmt: skip
        idx = kept_rows[np.argsort(tk, kind="stable")]
        ts = t[idx]
        dup = np.concatenate(([False], np.diff(ts) == 0))
    else:
        idx = kept_rows
        dup = np.concatenate(([False], steps == 0))
    has_dup = bool(dup.any())
    if has_dup:
        issues.append(LogIssue("duplicate-time", "time", rows[idx[dup]],
                               "first row kept, these rows removed"))  # fmt: skip
        idx = idx[~dup]
    if idx.size < 3:
        raise ValueError(f"{where}fewer than 3 rows with a valid time ({idx.size})")
    identity = not (any_bad_t or unsorted or has_dup)  # every row, in the file's order

    def take(x):
        return x if identity else x[idx]

    t = np.array(take(t), dtype=float)  # an array of its own (not a view of the file's)
    src_rows = rows if identity else rows[idx]
    n = t.size
    valid = np.ones((n_ax, n), dtype=bool).T
    channels = {}
    for name in names[1:]:
        if data[name] is None:
            channels[name] = None
            continue
        x = take(data[name])
        ok = np.isfinite(x)
        if not ok.any():
            channels[name] = None
            continue
        if not ok.all():
            miss = np.flatnonzero(~ok)
            x = x.copy()
            x[miss] = np.interp(t[miss], t[ok], x[ok])
            long_rows = []
            for a, b in _runs(~ok):
                lo = t[a - 1] if a > 0 else t[a]
                hi = t[b] if b < n else t[b - 1]
                if hi - lo > max_fill or a == 0 or b == n:
                    long_rows.append(np.arange(a, b))
            action = "interpolated linearly in time"
            long_rows = np.concatenate(long_rows) if long_rows else np.zeros(0, int)
            if long_rows.size:
                action += f"; {long_rows.size} sample(s) in runs longer than {max_fill:g} s " \
                          "or at the ends also marked invalid"
                if name == "train_speed":
                    valid[long_rows, :] = False
                else:
                    valid[long_rows, int(name.rsplit("_", 1)[1]) - 1] = False
            issues.append(LogIssue("missing-values", name, src_rows[miss], action))
        channels[name] = x
    if channels["train_speed"] is None:
        raise ValueError(f"{where}the train_speed column holds no numeric value")
    v = np.array(channels["train_speed"], dtype=float)  # its own array
    # -- time gaps: split into segments
    dt = np.diff(t)
    med = float(np.median(dt))
    gap = dt > gap_factor * med
    segment = np.concatenate(([0], np.cumsum(gap)))
    if gap.any():
        g = np.flatnonzero(gap)
        issues.append(LogIssue(
            "gap", "time", src_rows[g + 1],
            f"sampling interval > {gap_factor:g} x median ({med:.4g} s) before these rows "
            f"(longest {float(dt[g].max()):.4g} s): log split into {int(segment[-1]) + 1} "
            "segments, processed separately",
        ))
    # -- missing channels, substitutes for eq. 14 (axle columns contiguous in memory)
    wheel = np.empty((n_ax, n)).T
    press = np.empty((n_ax, n)).T
    substituted = np.zeros(n_ax, bool)
    for kind, arr, unit in (("wheel_speed", wheel, 1.0), ("brake_pressure", press, BAR)):
        present_ax = [i for i in range(n_ax) if channels[f"{kind}_{i + 1}"] is not None]
        for i in range(n_ax):
            x = channels[f"{kind}_{i + 1}"]
            if x is None:
                if not present_ax:
                    raise ValueError(f"{where}no {kind}_i channel holds a numeric value")
                others = [f"{kind}_{j + 1}" for j in present_ax]
                arr[:, i] = np.mean([channels[o] for o in others], axis=0) * unit
                valid[:, i] = False
                substituted[i] = True
                issues.append(LogIssue(
                    "missing-channel", f"{kind}_{i + 1}", np.zeros(0, int),
                    f"axle {i + 1} excluded from identification; mean of {', '.join(others)} "
                    "substituted for the brake coefficient (eq. 14)",
                ))
            else:
                np.multiply(x, unit, out=arr[:, i])
    # -- stuck channels
    min_w = max(int(round(stuck_time / med)), 3)
    min_p = max(int(round(stuck_pressure_time / med)), 3)
    def stuck(i, column, flagged, why):  # the flagged runs of axle i: invalid, one issue
        if flagged:
            r = np.concatenate(flagged)
            valid[r, i] = False
            issues.append(LogIssue("stuck-channel", column, src_rows[r],
                                   f"{why}: samples invalid for axle {i + 1}"))

    for i in range(n_ax):
        if channels[f"wheel_speed_{i + 1}"] is not None:
            flagged = [np.arange(a, b) for a, b in _constant_runs(wheel[:, i], min_w)
                       if wheel[a, i] > 0 and np.ptp(v[a:b]) > 1.0]
            stuck(i, f"wheel_speed_{i + 1}", flagged, f"constant for >= {stuck_time:g} s "
                  "while the train speed changed by > 1 m/s")
        if channels[f"brake_pressure_{i + 1}"] is not None and n_ax > 1:
            runs = _constant_runs(press[:, i], min_p)
            flagged = []
            if runs.size:  # the other axles' mean pressure, over the constant runs only
                others = [j for j in range(n_ax) if j != i]
                flagged = [np.arange(a, b) for a, b in runs
                           if np.ptp(press[a:b, others].mean(axis=1)) > 0.5 * BAR]
            stuck(i, f"brake_pressure_{i + 1}", flagged, f"constant for >= "
                  f"{stuck_pressure_time:g} s while the other pressures changed by > 0.5 bar")
    # -- units (each finding a UnitWarning naming the column; values left as they are)
    found = (
        check_plausible(np.array([press.min(), press.max()]) / BAR, "brake_pressure",
                        quantity="log_pressure", where=f"{where}brake_pressure_i (columns)"),
        sniff_speed_ratio(v, wheel, where=f"{where}train_speed"),
        sniff_sample_period(med, where=f"{where}time"),
    )  # fmt: skip
    log = BrakingLog(
        time=t, train_speed=v, wheel_speed=wheel, brake_pressure=press, valid=valid,
        segment=segment, issues=tuple(issues), source=source, rows=src_rows,
        substituted=substituted, warnings=tuple(w for w in found if w),
    )
    if warn and issues:
        warnings.warn(
            f"{where}{len(issues)} defect(s) in the braking log:\n{log.report()}",
            BrakingLogWarning, stacklevel=stacklevel,
        )
    return log


def _read_parquet(path: Path):
    """Column names and a getter from a Parquet file (pyarrow: numbers straight to NumPy)."""
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise ValueError(
            f"{path}: reading Parquet needs pyarrow (pip install pyarrow), or convert the log "
            "to CSV"
        ) from None
    table = pq.read_table(path)
    names = [str(c).strip() for c in table.column_names]
    _check_unique(names, path)
    index = {name: k for k, name in enumerate(names)}

    def get(name):
        col = table.column(index[name])
        import pyarrow as pa

        if pa.types.is_floating(col.type) or pa.types.is_integer(col.type):
            return col.to_numpy()  # nulls become NaN
        return col.to_pandas()

    return names, get, table.num_rows


def read_braking_log(path, **kwargs) -> BrakingLog:
    """Read a braking-test log from CSV or Parquet (format: ``docs/braking-log.md``).

    Parameters
    ----------
    path : str or path-like
        ``.parquet``/``.pq`` (read with pyarrow) or a CSV file (anything else; compression is
        inferred from the suffix). Columns ``time`` [s], ``train_speed`` [m/s],
        ``wheel_speed_1..N`` [rad/s], ``brake_pressure_1..N`` [bar].
    **kwargs
        Options of :func:`braking_log_from_frame` (``max_fill``, ``gap_factor``,
        ``stuck_time``, ``stuck_pressure_time``, ``warn``).

    Returns
    -------
    BrakingLog
        Pressures converted to Pa; defects in :attr:`BrakingLog.issues`.

    Raises
    ------
    ValueError
        Unreadable or malformed file (the message names it), Parquet without pyarrow.
    """
    import pandas as pd

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{p}: no such file")
    try:
        if p.suffix.lower() in (".parquet", ".pq"):
            names, get, n_rows = _read_parquet(p)
            return _log_from_columns(names, get, n_rows, source=str(p), **kwargs)
        try:
            frame = pd.read_csv(p, engine="pyarrow", comment=None)
        except Exception:  # noqa: BLE001 - pyarrow refuses some messy files: use the C engine
            frame = pd.read_csv(p, skipinitialspace=True)
    except (OSError, pd.errors.ParserError) as exc:
        raise ValueError(f"{p}: cannot read the log: {exc}") from exc
    except ValueError as exc:
        if str(exc).startswith(str(p)):
            raise
        raise ValueError(f"{p}: cannot read the log: {exc}") from exc
    return braking_log_from_frame(frame, source=str(p), **kwargs)
