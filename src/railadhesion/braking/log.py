"""Braking-test log writer: the channels a test train records, from a simulation.

Format (documented in ``docs/braking-log.md``): a plain CSV file, one header line

``time,train_speed,wheel_speed_1,…,wheel_speed_N,brake_pressure_1,…,brake_pressure_N``

then one row per sample, no comment lines. Units: time [s], train speed [m/s], wheelset
angular speeds [rad/s], brake-cylinder pressures [bar] (as test trains record them; the library
itself works in Pa). Axle 1 is the leading axle. A ``.parquet`` suffix writes the same columns
to Parquet. Sampling period 2.4 ms by default, as in Allotta et al. (seed 002 §5).
"""

from __future__ import annotations

import os
from collections.abc import Mapping

import numpy as np
import pandas as pd

__all__ = ["write_braking_log", "braking_log_frame", "LOG_CHANNELS", "PA_PER_BAR"]

PA_PER_BAR = 1e5
#: Channel groups of the log and their units.
LOG_CHANNELS = {"train_speed": "m/s", "wheel_speed": "rad/s", "brake_pressure": "bar"}


def _histories(result) -> pd.DataFrame:
    frame = getattr(result, "histories", result)
    if not isinstance(frame, pd.DataFrame):
        raise ValueError(
            "result must be a BrakingResult (with .histories) or a pandas DataFrame, "
            f"got {type(result).__name__}"
        )
    for column in ("time", "train_speed", "wheel_speed_1", "brake_pressure_1"):
        if column not in frame.columns:
            raise ValueError(f"result histories lack the column {column!r}")
    return frame


def _channel_values(spec, name: str) -> dict[str, float]:
    if spec is None:
        return {}
    if not isinstance(spec, Mapping):
        raise ValueError(
            f"{name} must be None or a mapping of {sorted(LOG_CHANNELS)} to values in the "
            f"log's units, got {spec!r}"
        )
    out = {}
    for key, value in spec.items():
        if key not in LOG_CHANNELS:
            raise ValueError(f"{name}: unknown channel {key!r}; allowed: {sorted(LOG_CHANNELS)}")
        x = float(value)
        if not (np.isfinite(x) and x >= 0):
            unit = LOG_CHANNELS[key]
            raise ValueError(f"{name}[{key!r}] must be in [0, inf) ({unit}), got {x!r}")
        out[key] = x
    return out


def braking_log_frame(result, period: float = 2.4e-3, noise=None, quantisation=None,
                      seed: int = 0) -> pd.DataFrame:
    """The log as a DataFrame (see :func:`write_braking_log` for the arguments)."""
    frame = _histories(result)
    period = float(period)
    if not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be in (0, inf) s, got {period!r}")
    noise = _channel_values(noise, "noise")
    quantisation = _channel_values(quantisation, "quantisation")
    n = sum(1 for c in frame.columns if c.startswith("wheel_speed_"))
    t = frame["time"].to_numpy(float)
    samples = t[0] + period * np.arange(int(np.floor((t[-1] - t[0]) / period + 1e-9)) + 1)
    rng = np.random.default_rng(seed)
    out = {"time": samples}
    groups = {
        "train_speed": ["train_speed"],
        "wheel_speed": [f"wheel_speed_{i}" for i in range(1, n + 1)],
        "brake_pressure": [f"brake_pressure_{i}" for i in range(1, n + 1)],
    }
    for group, columns in groups.items():
        scale = 1.0 / PA_PER_BAR if group == "brake_pressure" else 1.0
        for column in columns:
            values = np.interp(samples, t, frame[column].to_numpy(float)) * scale
            if noise.get(group, 0.0) > 0:
                values = values + rng.normal(0.0, noise[group], samples.size)
            step = quantisation.get(group, 0.0)
            if step > 0:
                values = np.round(values / step) * step
            out[column] = values
    return pd.DataFrame(out)


def write_braking_log(result, path, period: float = 2.4e-3, noise=None, quantisation=None,
                      seed: int = 0) -> pd.DataFrame:
    """Write a braking-test log (CSV, or Parquet for a ``.parquet`` path) from a simulation.

    Parameters
    ----------
    result : BrakingResult or pandas.DataFrame
        A simulation result (its ``histories``: time [s], train_speed [m/s],
        wheel_speed_i [rad/s], brake_pressure_i [Pa]).
    path : str or path-like
        Output file; ``.parquet`` writes Parquet, anything else CSV.
    period : float
        Sampling period [s] (default 2.4 ms, seed 002 §5). Histories are linearly
        interpolated at ``t0 + k·period``.
    noise : mapping, optional
        Standard deviation of additive Gaussian sensor noise per channel group, in the log's
        units: ``{"train_speed": m/s, "wheel_speed": rad/s, "brake_pressure": bar}``.
    quantisation : mapping, optional
        Sensor resolution per channel group (same keys and units); values are rounded to the
        nearest multiple, after the noise.
    seed : int
        Seed of the noise generator (the log is reproducible).

    Returns
    -------
    pandas.DataFrame
        The rows written.
    """
    log = braking_log_frame(result, period, noise, quantisation, seed)
    text = os.fspath(path)
    if text.lower().endswith(".parquet"):
        log.to_parquet(text, index=False)
    else:
        log.to_csv(text, index=False, float_format="%.9g")
    return log
