"""Figures of an identification, after seed 002 (Allotta, Malvezzi, Toni) Figs. 4 and 6-10.

Each function returns a matplotlib Figure. Long logs are thinned for drawing; the statistics
are always computed on every sample. Time histories are drawn as their envelope: the log is
cut into ``max_points / 2`` buckets of consecutive samples and each bucket is drawn as a
vertical stroke from its smallest to its largest value (NaN ignored), which keeps every peak
(a WSP cycle, a spike) that plain decimation would drop, at a few thousand points per line.
Scatter plots of mu against slip take every k-th sample row so that at most ``max_points``
points are drawn.
"""

from __future__ import annotations

import warnings

import numpy as np

from railadhesion.identification.logs import BAR

__all__ = [
    "plot_log",
    "plot_brake_coefficient",
    "plot_slip_and_adhesion",
    "plot_adhesion_vs_slip",
    "plot_relative_slip",
    "plot_surface",
    "save_identification_figures",
]


def _envelope(t, y, max_points):
    """(x, y) to draw ``y(t)`` with at most ``max_points`` points: per bucket of consecutive
    samples its smallest and largest value at the bucket's middle time (``y`` as it is when
    short enough)."""
    t = np.asarray(t)
    y = np.asarray(y, dtype=float)
    n = t.size
    buckets = max(max_points // 2, 1)
    if n <= max_points or n < 2 * buckets:
        return t, y
    starts = np.linspace(0, n, buckets + 1).astype(np.int64)[:-1]
    stops = np.r_[starts[1:], n]
    mid = 0.5 * (t[starts] + t[stops - 1])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        lo = np.fmin.reduceat(y, starts)
        hi = np.fmax.reduceat(y, starts)
    return np.repeat(mid, 2), np.column_stack([lo, hi]).ravel()


def _sample_rows(ident, phase, max_points):
    """(speed, slip, relative slip, mu, number of samples) of the usable samples of a phase,
    every k-th row taken so that at most about ``max_points`` are returned."""
    mask = ident.use
    if phase == "loss":
        mask = mask & (ident.phase == 1)
    elif phase == "recovery":
        mask = mask & (ident.phase == -1)
    total = int(np.count_nonzero(mask))
    step = max(1, int(np.ceil(total / max_points)))
    rows, axles = np.nonzero(mask[::step])
    rows = rows * step
    return (ident.speed[rows], ident.slip[rows, axles], ident.relative_slip[rows, axles],
            ident.mu[rows, axles], total)


def _finish(fig, ax, xlabel: str, ylabel: str, title: str, legend_size: float):
    """Label, grid, legend (font size ``legend_size``) and title of a one-panel figure, laid
    out; returns ``fig``."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=legend_size)
    ax.set_title(title)
    fig.tight_layout()
    return fig


def _plot_curve(ax, curve, slip_floor: float, *style, **kwargs) -> None:
    """Draw a fitted ``curve`` over slip 0 to the end of its data (at least ``slip_floor``)."""
    s = np.linspace(0.0, max(curve.slip_range[1], slip_floor), 300)
    ax.plot(s, curve(s), *style, **kwargs)


def plot_log(ident, max_points: int = 2000):
    """Train speed, wheel peripheral speeds R omega and brake pressures over time (Fig. 4)."""
    import matplotlib.pyplot as plt

    log = ident.log
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ax1.plot(*_envelope(log.time, log.train_speed, max_points), color="k", lw=1.2,
             label="train speed")
    r = ident.vehicle.wheel_radius
    for i in range(log.n_axles):
        ax1.plot(*_envelope(log.time, r * log.wheel_speed[:, i], max_points), lw=0.7,
                 label=f"axle {i + 1} R omega")
        ax2.plot(*_envelope(log.time, log.brake_pressure[:, i] / BAR, max_points), lw=0.8,
                 label=f"axle {i + 1}")
    ax1.set_ylabel("speed [m/s]")
    ax1.legend(fontsize=7, ncol=2)
    ax2.set_ylabel("brake-cylinder pressure [bar]")
    ax2.set_xlabel("time [s]")
    ax2.legend(fontsize=7, ncol=2)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    fig.suptitle("Braking-test log (cf. seed 002 Fig. 4)")
    fig.tight_layout()
    return fig


def plot_brake_coefficient(ident, max_points: int = 2000):
    """Brake coefficient c per sample (eq. 14) and its mean over the window (Fig. 6)."""
    import matplotlib.pyplot as plt

    b = ident.brake
    fig, ax = plt.subplots(figsize=(8, 4))
    c = b.per_sample * BAR
    ax.plot(*_envelope(ident.time, c, max_points), lw=0.7, color="0.5",
            label="c evaluated (eq. 14)")
    inw = np.where(b.in_window, c, np.nan)
    ax.plot(*_envelope(ident.time, inw, max_points), lw=0.9, color="C0", label="in the window")
    ax.axhline(b.mean * BAR, color="C3", lw=1.5,
               label=f"mean {b.mean * BAR:.0f} N m/bar (sd {b.std * BAR:.0f})")
    finite = c[b.in_window]
    if finite.size:
        lo, hi = np.percentile(finite, [1, 99])
        pad = 0.5 * (hi - lo) + 0.05 * abs(b.mean * BAR)
        ax.set_ylim(lo - pad, hi + pad)
    return _finish(fig, ax, "time [s]", "c [N m/bar]", "Brake coefficient (cf. seed 002 Fig. 6)",
                   8)  # fmt: skip


def plot_slip_and_adhesion(ident, axle: int = 1, max_points: int = 2000):
    """Absolute slip and adhesion coefficient of one axle over time (Fig. 7)."""
    import matplotlib.pyplot as plt

    i = int(axle) - 1
    if not 0 <= i < ident.n_axles:
        raise ValueError(f"axle must be in [1, {ident.n_axles}], got {axle}")
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    ax1.plot(*_envelope(ident.time, ident.slip[:, i], max_points), lw=0.8)
    ax1.set_ylabel("absolute slip [m/s]")
    mu = np.where(ident.use[:, i], ident.mu[:, i], np.nan)
    ax2.plot(*_envelope(ident.time, mu, max_points), lw=0.8, color="C1")
    w = ident.windows
    if len(w):
        w = w[w["axle"] == axle]
        for phase, colour in (("loss", "C3"), ("recovery", "C2")):
            sel = w[w["phase"] == phase]
            spans = list(zip(sel["start_time"], sel["end_time"] - sel["start_time"],
                             strict=True))
            if spans:
                ax2.broken_barh(spans, (0, 1), facecolors=colour, alpha=0.12, lw=0,
                                transform=ax2.get_xaxis_transform())
    ax2.set_ylabel("adhesion mu [-]")
    ax2.set_xlabel("time [s] (shaded: loss red, recovery green)")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"Axle {axle}: slip and adhesion (cf. seed 002 Fig. 7)")
    fig.tight_layout()
    return fig


def plot_adhesion_vs_slip(ident, law=None, max_points: int = 30000):
    """mu against absolute slip, loss and recovery apart, with the fitted curve (Figs. 8-9)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for phase, colour in (("loss", "C3"), ("recovery", "C2")):
        _, dv, _, mu, total = _sample_rows(ident, phase, max_points)
        ax.plot(dv, mu, ".", ms=1.5, color=colour, alpha=0.4,
                label=f"{phase} of adhesion ({total} samples)")
    if law is not None:
        _plot_curve(ax, law.overall, 1e-3, "k-", lw=2, label="fitted curve (all speeds)")
        for b in law.bands:
            _plot_curve(ax, b, 1e-3, "--", lw=1,
                        label=f"{b.speed_band[0]:g}-{b.speed_band[1]:g} m/s")  # fmt: skip
    return _finish(fig, ax, "absolute slip v - R omega [m/s]", "adhesion mu [-]",
                   "Adhesion against absolute slip (cf. seed 002 Figs. 8-9)", 7)  # fmt: skip


def plot_relative_slip(ident, law=None, max_points: int = 30000):
    """mu against relative slip, per speed band of the fitted law (Fig. 10)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    _, _, rel, mu, _ = _sample_rows(ident, "all", max_points)
    ax.plot(rel, mu, ".", ms=1.2, color="0.6", alpha=0.4, label="samples")
    if law is not None:
        for b in law.bands:
            _plot_curve(ax, b, 1e-4, lw=1.5, label=f"v {b.speed_band[0]:g}-{b.speed_band[1]:g} m/s")
    return _finish(fig, ax, "relative slip (v - R omega)/v [-]", "adhesion mu [-]",
                   "Adhesion against relative slip per speed band (cf. seed 002 Fig. 10)",
                   7)  # fmt: skip


def plot_surface(ds, phase: str = "all"):
    """Mean and variance of mu over the (speed, slip) grid, and the sample counts."""
    import matplotlib.pyplot as plt

    sub = ds.sel(phase=phase)
    se = np.r_[ds.speed_lower.values, ds.speed_upper.values[-1]]
    le = np.r_[ds.slip_lower.values, ds.slip_upper.values[-1]]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharey=True)
    for ax, name, title in zip(axes, ("mu_mean", "mu_var", "count"),
                               ("mean mu", "variance of mu", "samples"), strict=True):
        data = sub[name].values.astype(float)
        if name == "count":
            data = np.where(data > 0, data, np.nan)
        mesh = ax.pcolormesh(le, se, data, shading="flat")
        fig.colorbar(mesh, ax=ax)
        ax.set_title(title)
        ax.set_xlabel(f"{ds.attrs.get('slip_kind', 'absolute')} slip "
                      f"[{ds.slip.attrs.get('units', '')}]")
    axes[0].set_ylabel("train speed [m/s]")
    fig.suptitle(f"Adhesion surface, phase '{phase}' (seed 002 §5 grid)")
    fig.tight_layout()
    return fig


def save_identification_figures(ident, out_dir, *, surface=None, law=None, law_relative=None,
                                axle: int = 1) -> list:
    """Write the figures of an identification as PNG files into ``out_dir``; their paths."""
    from pathlib import Path

    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jobs = [
        ("log.png", lambda: plot_log(ident)),
        ("brake_coefficient.png", lambda: plot_brake_coefficient(ident)),
        (f"slip_adhesion_axle{axle}.png", lambda: plot_slip_and_adhesion(ident, axle)),
        ("adhesion_vs_slip.png", lambda: plot_adhesion_vs_slip(ident, law)),
        ("adhesion_vs_relative_slip.png", lambda: plot_relative_slip(ident, law_relative)),
    ]
    if surface is not None:
        jobs.append(("surface.png", lambda: plot_surface(surface)))
    paths = []
    for name, make in jobs:
        fig = make()
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        paths.append(out / name)
    return paths
