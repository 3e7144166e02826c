"""Figures of a braking run: speeds, slips, pressures, adhesion used vs available."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["braking_figures", "wsp_case_figure", "wsp_summary_figure", "odometry_case_figure",
           "odometry_summary_figure"]


def _axle_columns(h, name):
    n = sum(c.startswith("wheel_speed_") for c in h.columns)
    return [f"{name}_{i}" for i in range(1, n + 1)]


def _axle_lines(x, lines, xlabel: str, ylabel: str, title: str, reference=None) -> Figure:
    """A figure of one curve per axle, ``lines`` = [(values, label)], drawn after the
    ``reference`` curve (values, style, line width, label) if given."""
    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    if reference is not None:
        values, style, width, label = reference
        ax.plot(x, values, style, lw=width, label=label)
    for values, label in lines:
        ax.plot(x, values, lw=0.8, label=label)
    ax.set(xlabel=xlabel, ylabel=ylabel, title=title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def braking_figures(result, x: str = "time") -> dict[str, Figure]:
    """Four figures of a :class:`~railadhesion.braking.BrakingResult`.

    ``x`` = ``"time"`` [s] or ``"distance"`` [m] for the horizontal axis. Returns
    ``{"speeds", "slips", "pressures", "adhesion"}`` → matplotlib Figures.
    """
    if x not in ("time", "distance"):
        raise ValueError(f"x must be 'time' or 'distance', got {x!r}")
    h = result.histories
    step = max(1, len(h) // 5000)  # plot at most ~5000 points per line
    h = h.iloc[::step]
    xv = h[x].to_numpy()
    xlabel = "time [s]" if x == "time" else "distance [m]"
    wheels = _axle_columns(h, "wheel_speed")
    radius = result.settings.get("wheel_radius_m")
    figs = {
        "speeds": _axle_lines(
            xv, [(h[c] * radius * 3.6, f"wheel ωR, axle {i}") for i, c in enumerate(wheels, 1)],
            xlabel, "speed [km/h]", "Train and wheel speeds",
            reference=(h["train_speed"] * 3.6, "k", 2, "train")),
        "slips": _axle_lines(
            xv, [(h[c] * 100, f"axle {i}") for i, c in enumerate(_axle_columns(h, "creep"), 1)],
            xlabel, "creepage (V − ωR)/V [%]", "Wheel slip"),
        "pressures": _axle_lines(
            xv, [(h[c] / 1e5, f"axle {i}")
                 for i, c in enumerate(_axle_columns(h, "brake_pressure"), 1)],
            xlabel, "brake-cylinder pressure [bar]", "Brake pressures",
            reference=(h["pressure_command"] / 1e5, "k--", 1.2, "command")),
    }  # fmt: skip

    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    used = _axle_columns(h, "adhesion_used")
    avail = _axle_columns(h, "adhesion_available")
    for i, (u, a) in enumerate(zip(used, avail, strict=True), 1):
        line = ax.plot(xv, h[u], lw=0.8, label=f"used, axle {i}")[0]
        ax.plot(xv, h[a], lw=0.8, ls=":", color=line.get_color(), label=f"available, axle {i}")
    ax.set(xlabel=xlabel, ylabel="adhesion coefficient [-]",
           title="Adhesion used (solid) vs available (dotted)")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    figs["adhesion"] = fig
    return figs


def wsp_case_figure(histories, trace, wheel_radius: float, title: str = "") -> Figure:
    """One WSP bench case: train, reference and wheel speeds; brake pressures; valve states.

    ``trace`` is the control-period record of :func:`railadhesion.braking.bench.run_wsp_case`
    (time, the controller's reference speed, NaN if it has none)."""
    h = histories
    step = max(1, len(h) // 4000)
    hs = h.iloc[::step]
    t = hs["time"].to_numpy()
    n = sum(c.startswith("wheel_speed_") for c in h.columns)
    fig = Figure(figsize=(8, 8.5))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True, height_ratios=[3, 2, 1.4])
    ax1.plot(t, hs["train_speed"] * 3.6, "k", lw=2, label="train")
    tr = trace["time"]
    ref = trace["reference_speed"]
    if len(tr) and np.any(np.isfinite(ref)):
        k = max(1, len(tr) // 4000)
        ax1.plot(tr[::k], ref[::k] * 3.6, "k--", lw=1, label="WSP reference")
    for i in range(1, n + 1):
        ax1.plot(t, hs[f"wheel_speed_{i}"] * wheel_radius * 3.6, lw=0.7, label=f"axle {i}")
    ax1.set(ylabel="speed [km/h]", title=title)
    ax1.legend(fontsize=7, ncol=3)
    ax1.grid(alpha=0.3)
    ax2.plot(t, hs["pressure_command"] / 1e5, "k--", lw=1, label="command")
    for i in range(1, n + 1):
        ax2.plot(t, hs[f"brake_pressure_{i}"] / 1e5, lw=0.7, label=f"axle {i}")
    ax2.set(ylabel="cylinder pressure [bar]")
    ax2.legend(fontsize=7, ncol=3)
    ax2.grid(alpha=0.3)
    full_t = h["time"].to_numpy()
    m = (len(h) // step) * step
    tb = full_t[:m:step]
    for i in range(1, n + 1):  # valve states as stacked bands; a bin shows its most severe
        v = h[f"valve_{i}"].to_numpy()[:m].reshape(-1, step).max(axis=1)
        ax3.fill_between(tb, i - 0.45, i - 0.45 + 0.45 * v, step="post", lw=0)
    ax3.set(xlabel="time [s]", ylabel="axle", yticks=range(1, n + 1),
            title="valves: band height 0 apply, half hold, full vent")
    ax3.title.set_fontsize(8)
    ax3.grid(alpha=0.3)
    return fig


def wsp_summary_figure(cases) -> Figure:
    """Across the cases of a WSP programme: stopping distance over the adhesion-limited one,
    longest lock per case, and vented air."""
    ran = [c for c in cases if c.get("status") != "error"]
    names = [c["name"] for c in ran]
    x = np.arange(len(ran))
    fig = Figure(figsize=(max(8, 0.32 * len(ran) + 2), 8))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ratio = [c.get("distance_ratio", np.nan) for c in ran]
    colors = ["tab:green" if c.get("passed") else "tab:red" for c in ran]
    ax1.bar(x, ratio, color=colors)
    ax1.axhline(1.0, color="k", lw=0.8)
    ax1.set(ylabel="distance / adhesion-limited",
            title="WSP programme: green passed every check, red failed one")
    lock = [c.get("longest_lock_s", np.nan) for c in ran]
    ax2.bar(x, lock, color=colors)
    limits = [c.get("checks", {}).get("longest_lock", {}).get("limit", np.nan) for c in ran]
    ax2.plot(x, limits, "k_", ms=12, label="limit")
    ax2.set(ylabel="longest lock [s]")
    ax2.legend(fontsize=7)
    ax3.bar(x, [c.get("vented_air_l", np.nan) for c in ran], color="tab:blue")
    ax3.set(ylabel="vented air [l]")
    ax3.set_xticks(x, names, rotation=70, ha="right", fontsize=7)
    for ax in (ax1, ax2, ax3):
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return fig


def _phases(ax, t, creep, threshold):
    """Shade the slide (red) and spin (blue) phases of the odometry axles (one collection
    each)."""
    for mask, color in ((np.any(creep > threshold, axis=1), "tab:red"),
                        (np.any(creep < -threshold, axis=1), "tab:blue")):
        if not np.any(mask):
            continue
        edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
        ends = np.minimum(edges[1::2], len(t) - 1)
        spans = [(t[a], max(t[b] - t[a], 1e-9)) for a, b in zip(edges[::2], ends, strict=True)]
        ax.broken_barh(spans, (0, 1), transform=ax.get_xaxis_transform(), color=color,
                       alpha=0.12, lw=0)


def odometry_case_figure(traces, summary, title: str = "", threshold: float = 0.02) -> Figure:
    """One odometry bench case: true and estimated speed; true and estimated distance; per
    fit, its interval and estimate against the true position (violations in red). Slide
    phases of the odometry axles are shaded red, spin phases blue (creepage beyond
    ``threshold``).

    ``traces`` and ``summary`` are those of
    :func:`railadhesion.braking.odometry_bench.run_odometry_case`."""
    t = traces["time"]
    step = max(1, len(t) // 2000)
    ts = t[::step]
    creep = traces["creep"][::step]
    fits = [f for f in summary.get("fits", []) if f.get("status") == "ok"]
    rows = 2 + len(fits)
    fig = Figure(figsize=(9, 2.0 * rows + 1.5))
    axes = fig.subplots(rows, 1, sharex=True, height_ratios=[2.2, 1.6] + [1.2] * len(fits))
    ax = axes[0]
    ax.plot(ts, traces["speed"][::step] * 3.6, "k", lw=2, label="true")
    x_true = traces["distance"][::step]
    axes[1].plot(ts, x_true / 1e3, "k", lw=2, label="true")
    for f in fits:
        out = traces["outputs"][f["fit"]][::step]
        ax.plot(ts, out[:, 0] * 3.6, lw=0.9, label=f["fit"])
        axes[1].plot(ts, out[:, 1] / 1e3, lw=0.9, label=f["fit"])
    ax.set(ylabel="speed [km/h]", title=title)
    ax.legend(fontsize=7, ncol=3)
    axes[1].set(ylabel="distance [km]")
    for k, f in enumerate(fits):
        a = axes[2 + k]
        out = traces["outputs"][f["fit"]][::step]
        lo = out[:, 2] - x_true
        hi = out[:, 3] - x_true
        a.fill_between(ts, np.where(np.isfinite(lo), lo, np.nan),
                       np.where(np.isfinite(hi), hi, np.nan), color="tab:green", alpha=0.25,
                       lw=0, label="interval")
        a.plot(ts, out[:, 1] - x_true, "tab:green", lw=0.9, label="estimate")
        a.axhline(0.0, color="k", lw=1)
        for e in f.get("violations", []):
            a.axvspan(e["start_s"], e["end_s"] + 1e-3, color="tab:red", alpha=0.6)
        start = f.get("fault_start_s")
        if isinstance(start, float) and np.isfinite(start) and start > 0:
            a.axvline(start, color="k", ls="--", lw=1)
        a.set_yscale("symlog", linthresh=1.0)
        a.set_ylabel("− true [m]", fontsize=7)
        inside = "inside" if f.get("inside") else f"{len(f.get('violations', []))} violation(s)"
        a.set_title(f"{f['fit']}: stop error {f['stop_error_m']:+.1f} m, {inside}", fontsize=8)
    for a in axes:
        _phases(a, ts, creep, threshold)
        a.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]; shaded: odometry axles sliding (red) or spinning (blue)")
    fig.subplots_adjust(left=0.1, right=0.97, top=1 - 0.5 / (2.0 * rows + 1.5),
                        bottom=0.8 / (2.0 * rows + 1.5), hspace=0.45)
    return fig


def odometry_summary_figure(cases) -> Figure:
    """Across the cases of an odometry programme: the distance error at the stop and the
    interval's width at the stop, both over the stopping distance, per fit."""
    rows = [(c["name"], f) for c in cases if c.get("status") != "error"
            for f in c.get("fits", []) if f.get("status") == "ok"]
    dist = {c["name"]: c.get("stopping_distance_m", np.nan) for c in cases}
    x = np.arange(len(rows))
    fig = Figure(figsize=(max(8, 0.22 * len(rows) + 2), 7))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    err = [abs(f["stop_error_m"]) / dist[n] * 100 for n, f in rows]
    width = [f["interval_width_at_stop_m"] / dist[n] * 100 for n, f in rows]
    colors = ["tab:green" if f.get("passed") else "tab:red" for _, f in rows]
    ax1.bar(x, err, color=colors)
    ax1.set(ylabel="|stop error| [% of stop]", yscale="log",
            title="Odometry programme: green passed every check, red failed one")
    ax2.bar(x, width, color=colors)
    ax2.set(ylabel="interval width at stop [%]", yscale="log")
    ax2.set_xticks(x, [f"{n} / {f['fit']}" for n, f in rows], rotation=80, ha="right",
                   fontsize=6)
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return fig
