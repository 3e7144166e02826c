"""Figures of a braking run: speeds, slips, pressures, adhesion used vs available."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["braking_figures", "wsp_case_figure", "wsp_summary_figure"]


def _axle_columns(h, name):
    n = sum(c.startswith("wheel_speed_") for c in h.columns)
    return [f"{name}_{i}" for i in range(1, n + 1)]


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
    figs = {}

    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    ax.plot(xv, h["train_speed"] * 3.6, "k", lw=2, label="train")
    for i, c in enumerate(wheels, 1):
        ax.plot(xv, h[c] * radius * 3.6, lw=0.8, label=f"wheel ωR, axle {i}")
    ax.set(xlabel=xlabel, ylabel="speed [km/h]", title="Train and wheel speeds")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    figs["speeds"] = fig

    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    for i, c in enumerate(_axle_columns(h, "creep"), 1):
        ax.plot(xv, h[c] * 100, lw=0.8, label=f"axle {i}")
    ax.set(xlabel=xlabel, ylabel="creepage (V − ωR)/V [%]", title="Wheel slip")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    figs["slips"] = fig

    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    ax.plot(xv, h["pressure_command"] / 1e5, "k--", lw=1.2, label="command")
    for i, c in enumerate(_axle_columns(h, "brake_pressure"), 1):
        ax.plot(xv, h[c] / 1e5, lw=0.8, label=f"axle {i}")
    ax.set(xlabel=xlabel, ylabel="brake-cylinder pressure [bar]", title="Brake pressures")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    figs["pressures"] = fig

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
