"""Figures of a braking run: speeds, slips, pressures, adhesion used vs available."""

from __future__ import annotations

from matplotlib.figure import Figure

__all__ = ["braking_figures"]


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
