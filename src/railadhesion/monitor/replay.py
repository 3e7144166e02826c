"""Replay of a recorded log through the monitor: :func:`replay_log`.

The log is the braking-log format (``docs/braking-log.md``: ``time`` [s], ``train_speed``
[m/s], ``wheel_speed_i`` [rad/s], ``brake_pressure_i`` [bar]) with optional ``torque_i``
columns [N m, traction positive], CSV or Parquet. Unlike the identification reader
(:func:`railadhesion.identification.read_braking_log`, which repairs a log for off-line use),
the replay feeds the rows **as recorded, in the file's order**, one sample at a time, as a
train would: missing values, times out of order or repeated, gaps and stuck channels reach
the monitor, which reports them in its levels and reasons. No row is dropped; what the reader
itself notices (missing channels, cells that are not numbers, unknown columns) is listed in
:attr:`MonitorLog.issues` and the replay's summary.

Units are sniffed as the identification's reader does (``docs/checks.md``): a train speed in
km/h or mph (against the wheels' angular speeds, and in :func:`replay_log` against the
vehicle's wheel radius), a time in ms, pressures in Pa. Each finding is a
:class:`~railadhesion.plausibility.UnitWarning` (or a
:class:`~railadhesion.plausibility.PlausibilityWarning`), recorded in
:attr:`MonitorLog.warnings` and :attr:`MonitorReplay.warnings`: a replay with findings is not
trusted. A log without samples is an error.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.io.axle_log import AxleLog
from railadhesion.monitor import layout
from railadhesion.monitor.estimator import AdhesionMonitor
from railadhesion.monitor.settings import MonitorSettings
from railadhesion.plausibility import (
    UnitWarning,
    sniff_sample_period,
    sniff_speed_ratio,
    warn,
)

__all__ = ["MonitorLog", "MonitorReplay", "read_monitor_log", "replay_log", "monitor_log_frame"]

BAR = 1e5
_CHANNEL = re.compile(r"^(wheel_speed|brake_pressure|torque)_(\d+)$")
#: A pressure column whose values exceed this many bar is probably in Pa.
_BAR_LIMIT = 50.0


@dataclass(frozen=True, eq=False)
class MonitorLog(AxleLog):
    """A log as recorded (rows in the file's order, nothing repaired), SI units.

    Attributes
    ----------
    time : ndarray (n,)
        Time [s] as recorded (NaN where not a number).
    train_speed : ndarray (n,)
        Speed reference [m/s].
    wheel_speed : ndarray (n, N)
        Wheelset angular speeds [rad/s] (NaN for a missing channel).
    brake_pressure : ndarray (n, N)
        Brake-cylinder pressures [Pa] (converted from bar).
    torque : ndarray (n, N)
        Torques [N m] (traction positive).
    has_pressure, has_torque : ndarray of bool (N,)
        Which channels the log has.
    issues : tuple of str
        What the reader noticed (missing channels, cells not numbers, unknown columns).
    source : str
        The file read ("" if built in memory).
    warnings : tuple of str
        Columns that look like another unit (a train speed in km/h, a time in ms, pressures
        in Pa): the messages of the warnings issued (``docs/checks.md``).
    """

    torque: np.ndarray
    has_pressure: np.ndarray
    has_torque: np.ndarray
    issues: tuple = ()
    source: str = ""
    warnings: tuple = ()


def _numbers(col, name, issues):
    import pandas as pd

    if isinstance(col, np.ndarray) and col.dtype.kind in "fiu":
        return col.astype(float)
    series = col if isinstance(col, pd.Series) else pd.Series(col)
    if series.dtype.kind in "fiu":
        return series.to_numpy(dtype=float)
    num = pd.to_numeric(series, errors="coerce").to_numpy(dtype=float)
    text = series.astype(str).str.strip()
    bad = np.isnan(num) & series.notna().to_numpy() & (text != "").to_numpy() & (
        text.str.lower() != "nan").to_numpy()
    if bad.any():
        rows = np.flatnonzero(bad)
        shown = ", ".join(str(int(r)) for r in rows[:5]) + (" ..." if rows.size > 5 else "")
        issues.append(f"{name}: {rows.size} cell(s) not numbers (rows {shown}): read as missing")
    return num


def _column_names(columns, source):
    """The log's column names (stripped) and name -> position; two columns of one name are an
    error naming both."""
    names = [str(c).strip() for c in columns]
    index = {}
    for k, name in enumerate(names):
        if name in index:
            raise ValueError(f"{source or 'log'}: columns {index[name] + 1} and {k + 1} are both "
                             f"named {name!r}: keep one")
        index[name] = k
    return names, index


def monitor_log_frame(frame, *, source: str = "") -> MonitorLog:
    """A :class:`MonitorLog` from a pandas DataFrame with the log's columns (see the module)."""
    names, _ = _column_names(frame.columns, source)
    columns = dict(zip(names, frame.columns, strict=True))
    return _from_columns(names, lambda name: frame[columns[name]], len(frame), source)


def _median_period(t) -> float:
    """Median step between successive finite, increasing times (NaN if there is none)."""
    t = np.asarray(t, dtype=float)
    dt = np.diff(t[np.isfinite(t)])
    dt = dt[dt > 0]
    return float(np.median(dt)) if dt.size else math.nan


def _from_columns(names, get, n_rows, source) -> MonitorLog:
    where = f"{source}: " if source else ""
    for req in ("time", "train_speed"):
        if req not in names:
            raise ValueError(f"{where}the log has no {req!r} column (columns: {names[:12]})")
    if n_rows == 0:
        raise ValueError(f"{where}the log has no samples (a header only)")
    channels = {}
    unknown = []
    for name in names:
        m = _CHANNEL.match(name)
        if m:
            channels[(m.group(1), int(m.group(2)))] = name
        elif name not in ("time", "train_speed"):
            unknown.append(name)
    n_ax = max([k for _, k in channels] + [0])
    if not any(kind == "wheel_speed" for kind, _ in channels):
        raise ValueError(f"{where}the log has no wheel_speed_i column (columns: {names[:12]})")
    if n_ax > layout.MAX_AXLES:
        raise ValueError(f"{where}the log has axle {n_ax}; at most {layout.MAX_AXLES} axles")
    issues: list[str] = []
    found: list[str | None] = []  # unit findings (warnings issued)
    if unknown:
        issues.append(f"columns {', '.join(unknown)} ignored (not channels of the log format)")
    t = _numbers(get("time"), "time", issues)
    v = _numbers(get("train_speed"), "train_speed", issues)
    wheel = np.full((n_rows, n_ax), np.nan)
    press = np.full((n_rows, n_ax), np.nan)
    torque = np.full((n_rows, n_ax), np.nan)
    has_p = np.zeros(n_ax, bool)
    has_t = np.zeros(n_ax, bool)
    for i in range(1, n_ax + 1):
        name = channels.get(("wheel_speed", i))
        if name is None:
            issues.append(f"wheel_speed_{i} missing: axle {i} stays unknown")
        else:
            wheel[:, i - 1] = _numbers(get(name), name, issues)
        name = channels.get(("brake_pressure", i))
        if name is not None:
            x = _numbers(get(name), name, issues)
            top = np.nanmax(np.abs(x)) if np.isfinite(x).any() else 0.0
            if top > _BAR_LIMIT:
                found.append(warn(
                    f"{where}{name} reaches {top:.4g}: the log format has bar; values this "
                    "large look like Pa (the monitor will call them implausible)", UnitWarning,
                    stacklevel=4))
                issues.append(found[-1])
            press[:, i - 1] = x * BAR
            has_p[i - 1] = True
        name = channels.get(("torque", i))
        if name is not None:
            torque[:, i - 1] = _numbers(get(name), name, issues)
            has_t[i - 1] = True
        if not (has_p[i - 1] or has_t[i - 1]):
            issues.append(f"axle {i} has neither brake_pressure_{i} nor torque_{i}: its adhesion "
                          "in use is unknown")
    # units, as the identification's reader sniffs them (the speed against the wheels' angular
    # speeds; replay_log checks it again against the vehicle's wheel radius)
    found += [sniff_speed_ratio(v, wheel, where=f"{where}train_speed"),
              sniff_sample_period(_median_period(t), where=f"{where}time")]
    return MonitorLog(time=t, train_speed=v, wheel_speed=wheel, brake_pressure=press,
                      torque=torque, has_pressure=has_p, has_torque=has_t, issues=tuple(issues),
                      source=source, warnings=tuple(w for w in found if w))


def read_monitor_log(path) -> MonitorLog:
    """Read a log for the monitor (CSV, or Parquet for ``.parquet``/``.pq``), rows as recorded.

    Raises
    ------
    ValueError
        No such file, unreadable file, no ``time``/``train_speed``/``wheel_speed_i`` column,
        two columns of the same name.
    """
    import pandas as pd

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{p}: no such file")
    try:
        if p.suffix.lower() in (".parquet", ".pq"):
            import pyarrow.parquet as pq

            table = pq.read_table(p)
            names, index = _column_names(table.column_names, str(p))

            def get(name):
                col = table.column(index[name])
                import pyarrow as pa

                if pa.types.is_floating(col.type) or pa.types.is_integer(col.type):
                    return col.to_numpy()
                return col.to_pandas()

            return _from_columns(names, get, table.num_rows, str(p))
        try:
            frame = pd.read_csv(p, engine="pyarrow")
        except Exception:  # noqa: BLE001 - pyarrow refuses some messy files: the C engine
            frame = pd.read_csv(p, skipinitialspace=True)
    except (OSError, pd.errors.ParserError) as exc:
        raise ValueError(f"{p}: cannot read the log: {exc}") from exc
    return monitor_log_frame(frame, source=str(p))


@dataclass(eq=False)
class MonitorReplay:
    """Result of :func:`replay_log`.

    Attributes
    ----------
    columns : dict
        The time series, column name -> array (levels and reasons as category codes, see
        :attr:`frame`): ``time``, ``status`` (1: sample rejected), ``vehicle_level``; per axle
        ``creep_i``, ``adhesion_used_i``, ``estimate_i``, ``lower_i``, ``upper_i`` (the
        available adhesion and its band; float32), ``level_i`` and ``reason_i`` (the reason's
        label).
    events : pandas.DataFrame
        One row per change of an axle's level or reason: ``time``, ``axle``, ``level``,
        ``reason`` (the sentence with its values).
    summary : dict
        Samples, rejected samples, time share of each level per axle, low episodes, learned
        radii, brake coefficient (vehicle's and eq. 14's), the log's issues, the settings.
    log : MonitorLog
    monitor : AdhesionMonitor
        The monitor after the last sample.
    warnings : tuple of str
        Why the replay is not trusted: the log's columns that look like another unit
        (:attr:`MonitorLog.warnings`, and a train speed that does not fit the vehicle's wheel
        radius). Also in the summary, with ``trusted``.
    """

    columns: dict = field(repr=False)
    events: object
    summary: dict
    log: MonitorLog = field(repr=False)
    monitor: AdhesionMonitor = field(repr=False)
    warnings: tuple = ()
    _frame: object = field(default=None, repr=False)

    @property
    def trusted(self) -> bool:
        """False when the log's units look wrong (:attr:`warnings`)."""
        return not self.warnings

    @property
    def frame(self):
        """The time series as a pandas DataFrame (levels and reasons categorical), built on
        first use."""
        if self._frame is None:
            import pandas as pd

            data = {}
            for name, col in self.columns.items():
                if isinstance(col, tuple):
                    data[name] = pd.Categorical.from_codes(col[0], col[1])
                else:
                    data[name] = col
            self._frame = pd.DataFrame(data)
        return self._frame

    def table(self):
        """The time series as a pyarrow Table (levels and reasons dictionary-encoded)."""
        import pyarrow as pa

        arrays, names = [], []
        for name, col in self.columns.items():
            if isinstance(col, tuple):
                arrays.append(pa.DictionaryArray.from_arrays(pa.array(col[0]),
                                                             pa.array(list(col[1]))))
            else:
                arrays.append(pa.array(col))
            names.append(name)
        return pa.Table.from_arrays(arrays, names=names)

    def write(self, out) -> Path:
        """Write ``monitor.parquet`` (or ``monitor.csv`` when ``out`` ends in .csv: then that
        file), ``events.csv`` and ``summary.json`` into the folder ``out``."""
        out = Path(out)
        if out.suffix.lower() == ".csv":
            out.parent.mkdir(parents=True, exist_ok=True)
            self.frame.to_csv(out, index=False, float_format="%.9g")
            return out
        import pyarrow.parquet as pq

        out.mkdir(parents=True, exist_ok=True)
        pq.write_table(self.table(), out / "monitor.parquet")
        self.events.to_csv(out / "events.csv", index=False, float_format="%.6g")
        (out / "summary.json").write_text(json.dumps(self.summary, indent=2, default=_json),
                                          encoding="utf-8")
        return out / "monitor.parquet"


def _json(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"not JSON: {type(x).__name__}")


def _finite_or_none(x):
    x = float(x)
    return x if math.isfinite(x) else None


def replay_log(log, vehicle, settings: MonitorSettings | None = None) -> MonitorReplay:
    """Run the monitor over a recorded log, sample by sample, and collect what it says.

    Parameters
    ----------
    log : MonitorLog, str or path-like
        A log (:func:`read_monitor_log`) or its file (CSV or Parquet).
    vehicle : Vehicle or str
        The vehicle (a :class:`~railadhesion.braking.Vehicle`, a TOML file or a shipped name);
        its axle count must be the log's.
    settings : MonitorSettings, optional

    Returns
    -------
    MonitorReplay
        The time series (``frame``), the changes of level and reason (``events``) and a
        ``summary``.
    """
    from railadhesion.braking import Vehicle, load_vehicle
    from railadhesion.monitor import kernel

    if not isinstance(log, MonitorLog):
        log = read_monitor_log(log)
    if not isinstance(vehicle, Vehicle):
        vehicle = load_vehicle(vehicle)
    if vehicle.n_axles != log.n_axles:
        raise ValueError(f"the log has {log.n_axles} axles but the vehicle {vehicle.name!r} has "
                         f"{vehicle.n_axles}")
    if log.n_samples == 0:
        raise ValueError(f"{log.source or 'log'}: the log has no samples")
    findings = list(log.warnings)
    if not any("train_speed" in w for w in findings):  # against the vehicle's own radius
        found = sniff_speed_ratio(log.train_speed, log.wheel_speed, vehicle.wheel_radius,
                                  where=f"{log.source or 'log'}: train_speed")  # fmt: skip
        findings += [found] if found else []
    settings = settings if settings is not None else MonitorSettings()
    mon = AdhesionMonitor(vehicle, settings, pressure=log.has_pressure, torque=log.has_torque)
    n, n_ax = log.n_samples, log.n_axles

    def per_axle(dtype=np.float32):
        return np.empty((n, n_ax), dtype=dtype)

    # float32 (7 digits: ample for adhesion and creep) and int8 codes: a 1 h log at 2.4 ms
    # gives 1.5 M rows, and memory traffic is what the replay costs beyond its arithmetic
    status = np.empty(n, np.int8)
    vehicle_level = np.empty(n, np.int8)
    creep, used, est, lo, hi, v1, v2 = (per_axle() for _ in range(7))
    level = per_axle(np.int8)
    reason = per_axle(np.int8)
    mon.reset()
    kernel.replay(*mon.records, np.ascontiguousarray(log.time, float),
                  np.ascontiguousarray(log.train_speed, float),
                  np.ascontiguousarray(log.wheel_speed, float),
                  np.ascontiguousarray(log.brake_pressure, float),
                  np.ascontiguousarray(log.torque, float), status, vehicle_level, creep, used,
                  est, lo, hi, level, reason, v1, v2)
    codes = sorted(layout.REASONS)
    dense = np.zeros(max(codes) + 1, np.int8)
    dense[codes] = np.arange(len(codes))
    labels = tuple(layout.reason_label(c) for c in codes)
    columns = {"time": log.time, "status": status, "vehicle_level": (vehicle_level, layout.LEVELS)}
    for i in range(n_ax):
        k = i + 1
        columns[f"creep_{k}"] = creep[:, i]
        columns[f"adhesion_used_{k}"] = used[:, i]
        columns[f"estimate_{k}"] = est[:, i]
        columns[f"lower_{k}"] = lo[:, i]
        columns[f"upper_{k}"] = hi[:, i]
        columns[f"level_{k}"] = (level[:, i], layout.LEVELS)
        columns[f"reason_{k}"] = (dense[reason[:, i]], labels)
    events = _events(log.time, level, reason, v1, v2, settings.threshold)
    summary = _summary(log, mon, level, status, events, settings, vehicle)
    summary["trusted"] = not findings
    summary["warnings"] = findings
    return MonitorReplay(columns=columns, events=events, summary=summary, log=log, monitor=mon,
                         warnings=tuple(findings))


def _events(time, level, reason, v1, v2, threshold):
    """Rows where an axle's level or reason changes (the first sample included)."""
    import pandas as pd

    rows = []
    n, n_ax = level.shape
    for i in range(n_ax):
        key = level[:, i].astype(np.int32) * 1000 + reason[:, i]
        at = np.flatnonzero(np.concatenate(([True], key[1:] != key[:-1]))) if n else []
        for k in at:
            rows.append((float(time[k]), i + 1, layout.LEVELS[int(level[k, i])],
                         layout.reason_text(int(reason[k, i]), float(v1[k, i]), float(v2[k, i]),
                                            threshold)))
    rows.sort(key=lambda r: (r[0] if r[0] == r[0] else math.inf, r[1]))
    return pd.DataFrame(rows, columns=["time", "axle", "level", "reason"])


def _summary(log, mon, level, status, events, settings, vehicle) -> dict:
    t = log.time
    ok = np.isfinite(t)
    duration = float(np.nanmax(t) - np.nanmin(t)) if ok.sum() > 1 else 0.0
    axles = []
    out = mon.live
    for i in range(log.n_axles):
        lv = level[:, i]
        is_low = lv == layout.LOW
        starts = np.flatnonzero(is_low & np.concatenate(([True], ~is_low[:-1])))
        axles.append({
            "axle": i + 1,
            "level_share": {name: float(np.mean(lv == k)) if lv.size else 0.0
                            for k, name in enumerate(layout.LEVELS)},
            "low_episodes": int(starts.size),
            "first_low_time_s": float(t[starts[0]]) if starts.size else None,
            "radius_m": float(out.radius[i]),
            "radius_learned": bool(mon.state["radius_state"][0, i] == 1),
        })
    return {
        "source": log.source,
        "vehicle": vehicle.name,
        "samples": log.n_samples,
        "rejected_samples": int(np.sum(status == 1)),
        "duration_s": duration,
        "channels": {"brake_pressure": log.has_pressure.tolist(),
                     "torque": log.has_torque.tolist()},
        "axles": axles,
        "events": int(len(events)),
        "brake_coefficient_vehicle_N_m_per_Pa": float(vehicle.brake_coefficient),
        "brake_coefficient_eq14_N_m_per_Pa": _finite_or_none(out.brake_coefficient_identified),
        "log_issues": list(log.issues),
        "settings": settings.to_dict(),
    }
