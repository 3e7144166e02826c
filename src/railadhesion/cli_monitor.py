"""CLI command ``monitor``: replay a log through the on-board adhesion monitor.

Registered on the main app by :func:`register` (see ``railadhesion.cli``).
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape

from railadhesion.cli_checks import OutputConsole, allow_untrusted_option, fail, finish, warn

console = OutputConsole()


def _fail(exc) -> None:
    """``error: ...`` on standard error, exit code 2."""
    fail(exc)


def monitor(
    log: Path = typer.Argument(..., help="Log, CSV or Parquet (docs/braking-log.md; optional "
                               "torque_i columns [N m])."),
    vehicle: str = typer.Option(..., "--vehicle", help="Vehicle TOML file or a shipped name."),
    out: Path = typer.Option(Path("monitor"), "--out", help="Output folder."),
    threshold: float = typer.Option(0.14, help="Level threshold on the available adhesion "
                                    "(RSSB GM/GN2642: 0.14)."),
    learn_radius: bool = typer.Option(True, help="Learn the wheel radii while coasting (else the "
                                      "vehicle file's radius is taken as exact)."),
    shapes: str = typer.Option("both", help="Curve shapes of the estimator: both, fletcher or "
                               "polach."),
    figures: bool = typer.Option(True, help="Write the figures (PNG)."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Run the adhesion monitor over a log: levels, estimates and reasons as a time series.

    Exit code 3, unless --allow-untrusted, when the replay cannot be trusted: log columns
    that look like another unit (a train speed in km/h, a time in ms, pressures in Pa;
    docs/checks.md). The outputs are written either way."""
    from railadhesion.monitor import MonitorSettings, read_monitor_log, replay_log
    from railadhesion.monitor.figures import replay_figures

    try:
        settings = MonitorSettings(threshold=threshold, learn_radius=learn_radius, shapes=shapes)
        data = read_monitor_log(log)
        rep = replay_log(data, vehicle, settings)
        rep.write(out)
        if figures:
            replay_figures(rep, out / "figures")
    except (ValueError, OSError) as exc:
        _fail(exc)
    s = rep.summary
    console.print(f"log: {s['samples']} samples over {s['duration_s']:.1f} s, "
                  f"{s['rejected_samples']} rejected (time not increasing or missing)",
                  markup=False, highlight=False, soft_wrap=True)
    for issue in s["log_issues"]:
        console.print(f"  {issue}", markup=False, highlight=False, soft_wrap=True)
    for ax in s["axles"]:
        share = ", ".join(f"{k} {v * 100:.1f} %" for k, v in ax["level_share"].items())
        first = ax["first_low_time_s"]
        low = f"{ax['low_episodes']} low episode(s)" + (f", first at {first:.2f} s"
                                                       if first is not None else "")
        radius = "learned" if ax["radius_learned"] else "NOT learned (no coasting?)"
        console.print(f"axle {ax['axle']}: {share}; {low}; radius {ax['radius_m']:.5f} m "
                      f"{radius}", markup=False, highlight=False, soft_wrap=True)
    if not any(ax["radius_learned"] for ax in s["axles"]) and learn_radius:
        warn("no wheel radius was learned (the log has no coasting): every level stays "
             "unknown; --no-learn-radius takes the vehicle file's radius as exact")
    console.print(f"outputs written to {escape(str(out))}", soft_wrap=True)
    finish(rep.warnings, allow=allow_untrusted, what="monitor replay")


def monitor_fmu(
    out: Path = typer.Argument(..., help="The .fmu file to write."),
    vehicle: str = typer.Option("coach_default", "--vehicle",
                                help="Vehicle TOML file or a shipped name."),
    threshold: float = typer.Option(0.14, help="Level threshold (RSSB GM/GN2642: 0.14)."),
    sample_period: float = typer.Option(2.4e-3, help="The master's communication step [s]."),
    pressure: bool = typer.Option(True, help="Brake-pressure inputs."),
    torque: bool = typer.Option(False, help="Torque inputs (N m, traction > 0)."),
    native: bool = typer.Option(False, help="Native FMU: compiled, no Python at run time "
                                "(needs a C compiler to build)."),
) -> None:
    """Write the adhesion monitor as an FMI 2.0 co-simulation FMU."""
    from railadhesion.export import (
        NativeBuildError,
        build_monitor_fmu,
        build_native_monitor_fmu,
    )
    from railadhesion.monitor import MonitorSettings

    build = build_native_monitor_fmu if native else build_monitor_fmu
    try:
        settings = MonitorSettings(threshold=threshold, sample_period=sample_period)
        path = build(out, vehicle, settings, pressure=pressure, torque=torque)
    except (ValueError, OSError, NativeBuildError) as exc:
        _fail(exc)
    console.print(f"monitor FMU written to {escape(str(path))}", soft_wrap=True)


def register(app: typer.Typer) -> None:
    """Add the ``monitor`` and ``monitor-fmu`` commands to the main CLI."""
    app.command("monitor")(monitor)
    app.command("monitor-fmu")(monitor_fmu)
