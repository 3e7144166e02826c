"""Figures of the monitor: the estimate with its band, the level and the truth along the track;
the level of every axle over time; the distribution of detection delays."""

from __future__ import annotations

import numpy as np

from railadhesion.monitor import layout

__all__ = ["LEVEL_COLOURS", "plot_estimate", "plot_levels", "plot_delays", "replay_figures",
           "track_distance"]

#: Colours of the levels (unknown grey, normal green, caution amber, low red).
LEVEL_COLOURS = {"unknown": "#d9d9d9", "normal": "#b7e1b0", "caution": "#ffd98a",
                 "low": "#f4a3a3"}
_MAX_POINTS = 20000


def track_distance(time, speed):
    """Distance run [m] from the speed reference (trapezoids; missing values bridged)."""
    t = np.asarray(time, float)
    v = np.asarray(speed, float)
    ok = np.isfinite(t) & np.isfinite(v)
    x = np.full(t.size, np.nan)
    if ok.sum() < 2:
        return np.zeros(t.size)
    tk, vk = t[ok], v[ok]
    step = np.diff(tk)
    step[step < 0] = 0.0  # times out of order add nothing
    x[ok] = np.concatenate(([0.0], np.cumsum(0.5 * (vk[1:] + vk[:-1]) * step)))
    idx = np.arange(t.size)
    return np.interp(idx, idx[ok], x[ok])


def _spans(axis, x, levels):
    """Shade the level of each stretch of ``x`` (level codes or names)."""
    lv = np.asarray([layout.LEVELS.index(v) if isinstance(v, str) else int(v) for v in levels])
    if lv.size == 0:
        return
    cut = np.flatnonzero(np.diff(lv)) + 1
    starts = np.concatenate(([0], cut))
    stops = np.concatenate((cut, [lv.size]))
    for a, b in zip(starts, stops, strict=True):
        name = layout.LEVELS[lv[a]]
        axis.axvspan(x[a], x[min(b, x.size - 1)], color=LEVEL_COLOURS[name], lw=0, zorder=0)


def _thin(n):
    return slice(None, None, max(1, n // _MAX_POINTS))


def plot_estimate(x, estimate, lower, upper, levels, *, adhesion_used=None, truth=None,
                  threshold=0.14, xlabel="distance [m]", title="", axis=None, section=None):
    """One axle: the available adhesion estimated (line) with its band, the adhesion in use,
    the truth if known, the threshold, and the level as the background colour.

    ``x``: positions (or times) of the samples; the other arrays per sample. ``section``:
    optional (start, end) of a low-adhesion section to mark.
    """
    import matplotlib.pyplot as plt

    if axis is None:
        _, axis = plt.subplots(figsize=(9, 4))
    x = np.asarray(x, float)
    _spans(axis, x, levels)
    s = _thin(x.size)
    hi = np.asarray(upper, float)[s]
    top = 0.45
    axis.fill_between(x[s], np.asarray(lower, float)[s], np.where(np.isfinite(hi), hi, top),
                      color="#4a78b5", alpha=0.25, lw=0, label="band (inf: no bound)")
    axis.plot(x[s], np.asarray(estimate, float)[s], color="#1f4e8c", lw=1.4,
              label="available adhesion, estimated")
    if adhesion_used is not None:
        axis.plot(x[s], np.abs(np.asarray(adhesion_used, float)[s]), color="#555555", lw=0.6,
                  alpha=0.8, label="adhesion in use")
    if truth is not None:
        axis.plot(x[s], np.asarray(truth, float)[s], "k--", lw=1.2,
                  label="available adhesion, truth")
    axis.axhline(threshold, color="#b22222", lw=1.0, ls=":", label=f"threshold {threshold:g}")
    if section is not None:
        for edge in section:
            axis.axvline(edge, color="k", lw=0.6)
    axis.set_ylim(0.0, top)
    axis.set_xlim(x[0], x[-1])
    axis.set_xlabel(xlabel)
    axis.set_ylabel("adhesion [-]")
    if title:
        axis.set_title(title)
    handles, labels = axis.get_legend_handles_labels()
    from matplotlib.patches import Patch

    handles += [Patch(color=c, label=name) for name, c in LEVEL_COLOURS.items()]
    axis.legend(handles=handles, fontsize=7, ncol=3, loc="upper right")
    return axis.figure


def plot_levels(x, levels_by_axle, *, xlabel="time [s]", title="", axis=None):
    """The level of every axle (one row each) along ``x``."""
    import matplotlib.pyplot as plt

    n = len(levels_by_axle)
    if axis is None:
        _, axis = plt.subplots(figsize=(9, 0.5 + 0.45 * n))
    x = np.asarray(x, float)
    for row, lv in enumerate(levels_by_axle):
        codes = np.asarray([layout.LEVELS.index(v) if isinstance(v, str) else int(v)
                            for v in lv])
        cut = np.flatnonzero(np.diff(codes)) + 1
        starts = np.concatenate(([0], cut))
        stops = np.concatenate((cut, [codes.size]))
        for a, b in zip(starts, stops, strict=True):
            axis.barh(row, x[min(b, x.size - 1)] - x[a], left=x[a], height=0.8,
                      color=LEVEL_COLOURS[layout.LEVELS[codes[a]]], lw=0)
    axis.set_yticks(range(n), [f"axle {i + 1}" for i in range(n)])
    axis.invert_yaxis()
    axis.set_xlim(x[0], x[-1])
    axis.set_xlabel(xlabel)
    from matplotlib.patches import Patch

    axis.legend(handles=[Patch(color=c, label=k) for k, c in LEVEL_COLOURS.items()],
                fontsize=7, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.35 if n < 3
                                                                        else -0.15))
    if title:
        axis.set_title(title)
    axis.figure.tight_layout()
    return axis.figure


def plot_delays(delays, *, limit=2.0, title="", axis=None, labels=None):
    """Histogram of detection delays [s] (missed detections counted apart); one series per
    entry of ``delays`` (a dict label -> array, NaN for a miss) or one array."""
    import matplotlib.pyplot as plt

    if axis is None:
        _, axis = plt.subplots(figsize=(6, 3.6))
    series = delays if isinstance(delays, dict) else {labels or "delay": delays}
    bins = np.linspace(0.0, max(limit * 1.5, 0.1), 31)
    for name, d in series.items():
        d = np.asarray(d, float)
        found = d[np.isfinite(d)]
        missed = int(np.sum(~np.isfinite(d)))
        axis.hist(found, bins=bins, alpha=0.6,
                  label=f"{name}: {found.size} found, {missed} not")
    axis.axvline(limit, color="#b22222", ls=":", lw=1.0, label=f"{limit:g} s")
    axis.set_xlabel("delay after entering the section [s]")
    axis.set_ylabel("axles")
    axis.legend(fontsize=7)
    if title:
        axis.set_title(title)
    axis.figure.tight_layout()
    return axis.figure


def replay_figures(rep, folder) -> list:
    """The figures of a :class:`~railadhesion.monitor.MonitorReplay` in ``folder``:
    ``estimate_along_track.png`` (per axle: the estimate with its band, the adhesion in use
    and the level along the track, distance from the speed reference) and ``levels.png``
    (every axle's level over time)."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    f = rep.frame
    n = rep.log.n_axles
    x = track_distance(f["time"].to_numpy(), rep.log.train_speed)
    fig, axes = plt.subplots(n, 1, figsize=(10, 2.6 * n), sharex=True, squeeze=False)
    for i in range(n):
        k = i + 1
        plot_estimate(x, f[f"estimate_{k}"], f[f"lower_{k}"], f[f"upper_{k}"],
                      f[f"level_{k}"].cat.codes.to_numpy(),
                      adhesion_used=f[f"adhesion_used_{k}"],
                      threshold=rep.summary["settings"]["threshold"], title=f"axle {k}",
                      axis=axes[i, 0], xlabel="distance [m]" if i == n - 1 else "")
    fig.tight_layout()
    paths = [folder / "estimate_along_track.png", folder / "levels.png"]
    fig.savefig(paths[0], dpi=110)
    plt.close(fig)
    fig = plot_levels(f["time"].to_numpy(),
                      [f[f"level_{i + 1}"].cat.codes.to_numpy() for i in range(n)],
                      title="level per axle")
    fig.savefig(paths[1], dpi=110)
    plt.close(fig)
    return paths
