"""Figures of an identification, after seed 002 (Allotta, Malvezzi, Toni) Figs. 4 and 6-10.

Each function returns a matplotlib Figure. Long logs are thinned for drawing (at most
``max_points`` points per line); the statistics are always computed on every sample.
"""

from __future__ import annotations

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


def _thin(n, max_points):
    step = max(1, int(np.ceil(n / max_points)))
    return slice(None, None, step)


def plot_log(ident, max_points: int = 20000):
    """Train speed, wheel peripheral speeds R omega and brake pressures over time (Fig. 4)."""
    import matplotlib.pyplot as plt

    log = ident.log
    k = _thin(log.n_samples, max_points)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ax1.plot(log.time[k], log.train_speed[k], color="k", lw=1.2, label="train speed")
    r = ident.vehicle.wheel_radius
    for i in range(log.n_axles):
        ax1.plot(log.time[k], r * log.wheel_speed[k, i], lw=0.7, label=f"axle {i + 1} R omega")
        ax2.plot(log.time[k], log.brake_pressure[k, i] / BAR, lw=0.8, label=f"axle {i + 1}")
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


def plot_brake_coefficient(ident, max_points: int = 20000):
    """Brake coefficient c per sample (eq. 14) and its mean over the window (Fig. 6)."""
    import matplotlib.pyplot as plt

    b = ident.brake
    k = _thin(ident.time.size, max_points)
    fig, ax = plt.subplots(figsize=(8, 4))
    c = b.per_sample * BAR
    ax.plot(ident.time[k], c[k], lw=0.7, color="0.5", label="c evaluated (eq. 14)")
    inw = np.where(b.in_window, c, np.nan)
    ax.plot(ident.time[k], inw[k], lw=0.9, color="C0", label="in the window")
    ax.axhline(b.mean * BAR, color="C3", lw=1.5,
               label=f"mean {b.mean * BAR:.0f} N m/bar (sd {b.std * BAR:.0f})")
    finite = c[b.in_window]
    if finite.size:
        lo, hi = np.percentile(finite, [1, 99])
        pad = 0.5 * (hi - lo) + 0.05 * abs(b.mean * BAR)
        ax.set_ylim(lo - pad, hi + pad)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("c [N m/bar]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Brake coefficient (cf. seed 002 Fig. 6)")
    fig.tight_layout()
    return fig


def plot_slip_and_adhesion(ident, axle: int = 1, max_points: int = 20000):
    """Absolute slip and adhesion coefficient of one axle over time (Fig. 7)."""
    import matplotlib.pyplot as plt

    i = int(axle) - 1
    if not 0 <= i < ident.n_axles:
        raise ValueError(f"axle must be in [1, {ident.n_axles}], got {axle}")
    k = _thin(ident.time.size, max_points)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    ax1.plot(ident.time[k], ident.slip[k, i], lw=0.8)
    ax1.set_ylabel("absolute slip [m/s]")
    mu = np.where(ident.use[:, i], ident.mu[:, i], np.nan)
    ax2.plot(ident.time[k], mu[k], lw=0.8, color="C1")
    for sign, colour in ((1, "C3"), (-1, "C2")):
        shade = ident.phase[:, i] == sign
        ax2.fill_between(ident.time[k], 0, 1, where=shade[k], color=colour, alpha=0.12,
                         transform=ax2.get_xaxis_transform(), lw=0)
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
        v, dv, _, mu, _ = ident.samples(phase)
        k = _thin(dv.size, max_points)
        ax.plot(dv[k], mu[k], ".", ms=1.5, color=colour, alpha=0.4,
                label=f"{phase} of adhesion ({dv.size} samples)")
    if law is not None:
        c = law.overall
        s = np.linspace(0.0, max(c.slip_range[1], 1e-3), 300)
        ax.plot(s, c(s), "k-", lw=2, label="fitted curve (all speeds)")
        for b in law.bands:
            s = np.linspace(0.0, max(b.slip_range[1], 1e-3), 300)
            ax.plot(s, b(s), "--", lw=1, label=f"{b.speed_band[0]:g}-{b.speed_band[1]:g} m/s")
    ax.set_xlabel("absolute slip v - R omega [m/s]")
    ax.set_ylabel("adhesion mu [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Adhesion against absolute slip (cf. seed 002 Figs. 8-9)")
    fig.tight_layout()
    return fig


def plot_relative_slip(ident, law=None, max_points: int = 30000):
    """mu against relative slip, per speed band of the fitted law (Fig. 10)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    v, _, rel, mu, _ = ident.samples()
    k = _thin(rel.size, max_points)
    ax.plot(rel[k], mu[k], ".", ms=1.2, color="0.6", alpha=0.4, label="samples")
    if law is not None:
        for b in law.bands:
            s = np.linspace(0.0, max(b.slip_range[1], 1e-4), 300)
            ax.plot(s, b(s), lw=1.5, label=f"v {b.speed_band[0]:g}-{b.speed_band[1]:g} m/s")
    ax.set_xlabel("relative slip (v - R omega)/v [-]")
    ax.set_ylabel("adhesion mu [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Adhesion against relative slip per speed band (cf. seed 002 Fig. 10)")
    fig.tight_layout()
    return fig


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
