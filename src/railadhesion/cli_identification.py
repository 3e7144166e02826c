"""CLI commands for adhesion from measurements: ``detect`` (and ``identify``).

Registered on the main app by :func:`register` (see ``railadhesion.cli``).
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape

from railadhesion.cli_checks import (
    OutputConsole,
    allow_untrusted_option,
    err_console,
    fail,
    finish,
    progress_disabled,
)

console = OutputConsole()


def _fail(exc) -> None:
    """``error: ...`` on standard error, exit code 2."""
    fail(exc)


def detect(
    csv: Path = typer.Argument(..., help="Creep-curve CSV at low creep (docs/creep-curve-csv.md)."),
    model: str = typer.Option("fletcher", help="Model: fletcher (default) or polach."),
    half_width: float | None = typer.Option(
        None, help="Contact half-width a [m] (Fletcher); default: the file's a_m, else 0.204 mm."
    ),
    radius: float | None = typer.Option(
        None, help="Reduced radius R [m] (Fletcher); default: the file's radius_m, else 11.75 mm."
    ),
    threshold: float = typer.Option(0.14, help="Warning threshold on mu (RSSB GM/GN2642: 0.14)."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Estimate the friction available at full slip from low-creep data, with a warning level.

    The level is UNKNOWN, with exit code 3 unless --allow-untrusted, when the fit cannot be
    trusted to bound mu (docs/checks.md)."""
    from railadhesion.identification.detection import detect_low_adhesion
    from railadhesion.io.creepcurves import read_creep_curve

    try:
        curve = read_creep_curve(csv)
    except (ValueError, OSError) as exc:
        _fail(exc)
    kwargs = {}
    if model == "fletcher":
        a = half_width if half_width is not None else (curve.a or 0.204e-3)
        r = radius
        if r is None:
            try:
                r = float(curve.info.get("radius_m", 11.75e-3))
            except ValueError:
                _fail(f"{csv}: radius_m must be a number, got {curve.info['radius_m']!r}")
        kwargs = dict(half_width=a, radius=r)
    elif model == "polach":
        kwargs = dict(normal_force=curve.normal_force, speed=curve.speed, a=curve.a, b=curve.b)
    try:
        res = detect_low_adhesion(
            curve.creep, curve.adhesion, model=model, threshold=threshold,
            warn_untrusted=False, **kwargs,
        )  # fmt: skip
    except ValueError as exc:
        _fail(f"{csv}: {exc}")
    console.print(res.summary(), highlight=False, markup=False)
    if curve.excluded:
        console.print(f"({len(curve.excluded)} row(s) of the file excluded: "
                      + "; ".join(str(e) for e in curve.excluded[:5]) + ")", markup=False)
    colour = {"low": "red", "caution": "yellow", "normal": "green", "unknown": "magenta"}
    console.print(f"[{colour[res.level]}]{res.level.upper()}[/{colour[res.level]}]")
    finish(res.warnings, allow=allow_untrusted, what="detection")


def identify(
    log: Path = typer.Argument(..., help="Braking-test log, CSV or Parquet (docs/braking-log.md)."),
    vehicle: str = typer.Option(
        ..., "--vehicle", help="Vehicle TOML file (railadhesion-vehicle) or a shipped name."
    ),
    out: Path = typer.Option(Path("identification"), "--out", help="Output folder."),
    filter_mode: str = typer.Option("zero-phase", help="zero-phase (default) or causal."),
    vehicle_cutoff: float = typer.Option(0.5, help="Deceleration filter cut-off [Hz]."),
    wheel_cutoff: float = typer.Option(2.0, help="Angular-acceleration filter cut-off [Hz]."),
    speed_bands: str = typer.Option("0,10,20,30,40", help="Speed-band edges of the fits [m/s]."),
    figures: bool = typer.Option(True, help="Write the figures (PNG)."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Identify adhesion from a braking-test log: c, mu, surface (NetCDF), fitted law, figures.

    Exit code 3, unless --allow-untrusted, when the identification cannot be trusted: log
    columns in another unit, a brake coefficient far from the vehicle's, a fitted curve the
    quality gate flags (docs/checks.md). The outputs are written either way."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from railadhesion.braking import load_vehicle
    from railadhesion.identification.pipeline import STAGES, run_identification

    try:
        bands = [float(x) for x in speed_bands.split(",") if x.strip()]
    except ValueError:
        _fail(f"--speed-bands: expected numbers separated by commas, got {speed_bands!r}")
    try:
        veh = load_vehicle(vehicle)
    except (ValueError, OSError) as exc:
        _fail(exc)
    error = None
    with Progress(TextColumn("{task.description:<42}"), BarColumn(), TimeElapsedColumn(),
                  console=err_console, transient=False, disable=progress_disabled()) as bar:
        task = bar.add_task(STAGES[0], total=len(STAGES))

        def step(name):
            bar.update(task, advance=1, description=name)

        try:
            run = run_identification(
                log, veh, out, filter_mode=filter_mode, vehicle_cutoff=vehicle_cutoff,
                wheel_cutoff=wheel_cutoff, speed_bands=bands, figures=figures, progress=step,
            )
            bar.update(task, completed=len(STAGES), description="done")
        except (ValueError, OSError) as exc:  # no progress line after the error message
            bar.remove_task(task)
            error = exc
    if error is not None:
        _fail(error)
    data, law = run.log, run.law
    b = run.ident.brake
    console.print(f"log: {data.n_samples} samples, {data.n_axles} axles, "
                  f"{len(data.issues)} defect(s)", markup=False)
    for issue in data.issues:
        console.print(f"  {issue}", markup=False, highlight=False)
    console.print(
        f"brake coefficient c = {b.mean:.5g} N m/Pa ({b.mean_n_m_per_bar:.5g} N m/bar), "
        f"sd {b.std / b.mean * 100:.2f} %, window {b.window[0]:.2f}-{b.window[1]:.2f} s "
        f"({b.n_samples} samples)", markup=False, highlight=False)
    p = law.overall.params
    console.print(
        f"mu(slip) all speeds: mu_s = {p['mu_s']:.4f}, s0 = {p['s0']:.4g} m/s, "
        f"A = {p['A']:.3f}, B = {p['B']:.3g} s/m; R^2 = {law.overall.r_squared:.3f}, "
        f"slip {law.overall.slip_range[0]:.2f}-{law.overall.slip_range[1]:.2f} m/s",
        markup=False, highlight=False)
    console.print(f"outputs written to {escape(str(out))}")
    finish(run.warnings, allow=allow_untrusted, what="identification")


def register(app: typer.Typer) -> None:
    """Add the identification commands to the main CLI."""
    app.command("detect")(detect)
    app.command("identify")(identify)
