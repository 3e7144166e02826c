"""Slide and lock accounting of a braking run, computed from its time histories.

One function, :func:`slide_metrics`, defines what the run summaries report about wheel slides
(:func:`railadhesion.braking.simulate`'s ``BrakingResult.summary``, the ``brake`` CLI and the
WSP bench use it); the definitions are those of ``docs/braking.md`` ("Slide and lock
accounting"):

* **locked**: the wheel's surface speed ωR is below ``lock_fraction`` (10 %) of the train speed
  while the train is faster than ``speed_floor`` (0.5 m/s). Per axle: the total time locked
  (``time_locked_s``) and the longest continuous such interval (``longest_lock_s``). Below the
  floor the same condition is counted apart (``time_locked_below_floor_s``): an 80-tooth
  encoder gives a pulse every 70 ms at 0.5 m/s, so no WSP resolves a slide quickly there, and
  such a slide lasts less than a metre; it is reported, not hidden.
* **deep slide**: creepage ``(v − ωR)/v`` at or above ``deep_creep`` (0.5: the wheel turns
  at less than half the train speed) while the train is faster than the floor; its time
  (``deep_slide_s``) and the rail length the tread slid over meanwhile,
  ``∫ (v − ωR) dt`` (``deep_slide_distance_m``).
* **mean braking creep**: the time mean of the creepage while the brake is commanded and the
  train is faster than the floor (``mean_creep``).
* **air**: vent actions (changes of an axle's valve to VENT) and the vented free air
  ``V_cyl Δp / p_atm`` [l], summed over the steps with the valve at VENT.

Each history row describes the step that ends at its time; a condition seen at a row counts
for the length of that step.
"""

from __future__ import annotations

import math

import numpy as np

from railadhesion.braking.cylinders import ATMOSPHERIC_PRESSURE, VENT

__all__ = ["slide_metrics", "longest_run", "LOCK_FRACTION", "SPEED_FLOOR", "DEEP_CREEP"]

#: A wheel counts as locked below this fraction of the train speed.
LOCK_FRACTION = 0.10
#: Locks and slides are counted while the train is faster than this [m/s].
SPEED_FLOOR = 0.5
#: A slide is deep at or above this creepage.
DEEP_CREEP = 0.5


def longest_run(mask: np.ndarray, dt: np.ndarray) -> float:
    """Longest total of ``dt`` over consecutive True entries of ``mask`` [s]."""
    mask = np.asarray(mask, bool)
    if not np.any(mask):
        return 0.0
    csum = np.cumsum(np.where(mask, dt, 0.0))
    base = np.maximum.accumulate(np.where(mask, 0.0, csum))  # running sum at the last False
    return float(np.max(csum - base))


def _check(name, value, low, high):
    if isinstance(value, bool) or not isinstance(value, int | float) or not (
            math.isfinite(value) and low <= value <= high):
        raise ValueError(f"{name} must be in [{low:g}, {high:g}], got {value!r}")


def slide_metrics(histories, wheel_radius: float, *, lock_fraction: float = LOCK_FRACTION,
                  speed_floor: float = SPEED_FLOOR, deep_creep: float = DEEP_CREEP,
                  cylinder_volume: float = 2e-3) -> dict:
    """Lock, deep-slide, creep and air figures of a run (definitions: module docstring).

    Parameters
    ----------
    histories : pandas.DataFrame
        ``BrakingResult.histories`` (columns ``time``, ``train_speed``, ``pressure_command``,
        ``wheel_speed_i``, ``brake_pressure_i``, ``valve_i`` for i = 1 … n).
    wheel_radius : float
        [m].
    lock_fraction : float
        [0, 1]; default 0.10.
    speed_floor : float
        [m/s], [0, 100]; default 0.5.
    deep_creep : float
        [0, 1]; default 0.5.
    cylinder_volume : float
        Brake-cylinder volume per axle [m³] (for the vented air).

    Returns
    -------
    dict
        ``axles``: one dict per axle (``axle``, ``time_locked_s``, ``longest_lock_s``,
        ``time_locked_below_floor_s``, ``deep_slide_s``, ``deep_slide_distance_m``,
        ``mean_creep``, ``max_creep``, ``vent_actions``, ``vented_air_l``), and the worst or
        total over the axles under the same names (``longest_lock_s`` the longest of any axle,
        ``time_locked_s`` and ``deep_slide_s`` the largest of any axle, ``mean_creep`` the
        largest axle mean, ``vent_actions`` and ``vented_air_l`` the sums), plus the
        definitions used (``lock_fraction``, ``speed_floor_m_s``, ``deep_creep``).
    """
    _check("wheel_radius", wheel_radius, 1e-3, 10.0)
    _check("lock_fraction", lock_fraction, 0.0, 1.0)
    _check("speed_floor", speed_floor, 0.0, 100.0)
    _check("deep_creep", deep_creep, 0.0, 1.0)
    _check("cylinder_volume", cylinder_volume, 0.0, 10.0)
    h = histories
    n = sum(1 for c in h.columns if c.startswith("wheel_speed_"))
    t = h["time"].to_numpy(float)
    dt = np.diff(t, prepend=t[0] if t.size else 0.0)
    v = h["train_speed"].to_numpy(float)
    moving = v > speed_floor
    below = (v > 0.0) & ~moving
    braking = moving & (h["pressure_command"].to_numpy(float) > 0.0)
    axles = []
    for i in range(1, n + 1):
        u = h[f"wheel_speed_{i}"].to_numpy(float) * wheel_radius
        locked = u < lock_fraction * v
        with np.errstate(divide="ignore", invalid="ignore"):
            creep = np.where(v > 0.0, (v - u) / np.where(v > 0.0, v, 1.0), 0.0)
        deep = moving & (creep >= deep_creep)
        valve = h[f"valve_{i}"].to_numpy()
        venting = valve == VENT
        starts = venting & ~np.concatenate([[False], venting[:-1]])
        p = h[f"brake_pressure_{i}"].to_numpy(float)
        drop = np.maximum(np.concatenate([[0.0], p[:-1] - p[1:]]), 0.0)
        vented = float(np.sum(drop[venting]))
        axles.append({
            "axle": i,
            "time_locked_s": float(np.sum(dt[locked & moving])),
            "longest_lock_s": longest_run(locked & moving, dt),
            "time_locked_below_floor_s": float(np.sum(dt[locked & below])),
            "deep_slide_s": float(np.sum(dt[deep])),
            "deep_slide_distance_m": float(np.sum(((v - u) * dt)[deep])),
            "mean_creep": float(np.sum((creep * dt)[braking]) / np.sum(dt[braking]))
            if np.any(braking) and np.sum(dt[braking]) > 0 else math.nan,
            "max_creep": float(np.max(creep[moving])) if np.any(moving) else math.nan,
            "vent_actions": int(np.sum(starts)),
            "vented_air_l": vented * cylinder_volume / ATMOSPHERIC_PRESSURE * 1e3,
        })

    def worst(key):
        values = [a[key] for a in axles if not math.isnan(a[key])]
        return max(values) if values else math.nan

    return {
        "lock_fraction": lock_fraction,
        "speed_floor_m_s": speed_floor,
        "deep_creep": deep_creep,
        "longest_lock_s": worst("longest_lock_s"),
        "time_locked_s": worst("time_locked_s"),
        "time_locked_below_floor_s": worst("time_locked_below_floor_s"),
        "deep_slide_s": worst("deep_slide_s"),
        "deep_slide_distance_m": worst("deep_slide_distance_m"),
        "mean_creep": worst("mean_creep"),
        "max_creep": worst("max_creep"),
        "vent_actions": int(sum(a["vent_actions"] for a in axles)),
        "vented_air_l": float(sum(a["vented_air_l"] for a in axles)),
        "axles": axles,
    }
