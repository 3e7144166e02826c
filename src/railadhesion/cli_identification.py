"""CLI commands for adhesion from measurements: ``detect`` (and ``identify``).

Registered on the main app by :func:`register` (see ``railadhesion.cli``).
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape

console = Console()


def _fail(exc) -> None:
    console.print(f"[red]error:[/red] {escape(str(exc))}")
    raise typer.Exit(code=2)


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
) -> None:
    """Estimate the friction available at full slip from low-creep data, with a warning level."""
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
            curve.creep, curve.adhesion, model=model, threshold=threshold, **kwargs
        )
    except ValueError as exc:
        _fail(f"{csv}: {exc}")
    console.print(res.summary(), highlight=False, markup=False)
    if curve.excluded:
        console.print(f"({len(curve.excluded)} row(s) of the file excluded: "
                      + "; ".join(str(e) for e in curve.excluded[:5]) + ")", markup=False)
    colour = {"low": "red", "caution": "yellow", "normal": "green"}[res.level]
    console.print(f"[{colour}]{res.level.upper()}[/{colour}]")


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
) -> None:
    """Identify adhesion from a braking-test log: c, mu, surface (NetCDF), fitted law, figures."""
    import json

    import numpy as np
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from railadhesion.braking import load_vehicle
    from railadhesion.identification import (
        adhesion_surface,
        fit_adhesion_curves,
        identify_adhesion,
        read_braking_log,
        save_surface,
    )

    try:
        bands = [float(x) for x in speed_bands.split(",") if x.strip()]
    except ValueError:
        _fail(f"--speed-bands: expected numbers separated by commas, got {speed_bands!r}")
    stages = ["read the log", "derivatives and filters", "brake coefficient (eq. 14)",
              "normal loads and adhesion (eqs. 10-13)", "identification windows",
              "surface", "fitted curves", "figures", "summary"]
    import warnings

    from railadhesion.identification.logs import BrakingLogWarning

    with Progress(TextColumn("{task.description:<42}"), BarColumn(), TimeElapsedColumn(),
                  console=console, transient=False) as bar:
        task = bar.add_task("read the log", total=len(stages))

        def step(name):
            bar.update(task, advance=1, description=name)

        try:
            veh = load_vehicle(vehicle)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BrakingLogWarning)
                data = read_braking_log(log)
            ident = identify_adhesion(
                data, veh, filter_mode=filter_mode, vehicle_cutoff=vehicle_cutoff,
                wheel_cutoff=wheel_cutoff, progress=step,
            )
            step("surface")
            out.mkdir(parents=True, exist_ok=True)
            surface = adhesion_surface(ident)
            save_surface(surface, out / "surface.nc")
            surface_rel = adhesion_surface(ident, slip="relative")
            save_surface(surface_rel, out / "surface_relative.nc")
            step("fitted curves")
            law = fit_adhesion_curves(ident, speed_bands=bands)
            law.save(out / "adhesion_law.toml")
            law_rel = fit_adhesion_curves(ident, slip="relative", speed_bands=bands)
            law_rel.save(out / "adhesion_law_relative.toml")
            ident.windows.to_csv(out / "windows.csv", index=False)
            step("figures")
            if figures:
                from railadhesion.identification.figures import save_identification_figures

                save_identification_figures(ident, out / "figures", surface=surface, law=law,
                                            law_relative=law_rel)
            step("summary")
            summary = ident.summary_dict()
            summary["curves_absolute_slip"] = law.to_frame().replace({np.nan: None}).to_dict(
                orient="records")
            summary["curves_relative_slip"] = law_rel.to_frame().replace(
                {np.nan: None}).to_dict(orient="records")
            summary["curve_form"] = "mu_s * (1 - exp(-s/s0)) * (A + (1 - A) * exp(-B*s))"
            by_phase = {}
            for phase in ("loss", "recovery"):
                try:
                    fitted = fit_adhesion_curves(ident, speed_bands=bands, phase=phase).overall
                except ValueError as exc:  # too few samples in that phase
                    by_phase[phase] = {"error": str(exc)}
                    continue
                by_phase[phase] = {**fitted.params, "n_samples": fitted.n_samples,
                                   "r_squared": fitted.r_squared,
                                   "slip_range_m_s": list(fitted.slip_range)}
            summary["curves_by_phase_absolute_slip"] = by_phase
            (out / "summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
            bar.update(task, completed=len(stages), description="done")
        except (ValueError, OSError) as exc:
            _fail(exc)
    b = ident.brake
    console.print(f"log: {data.n_samples} samples, {data.n_axles} axles, "
                  f"{len(data.issues)} defect(s)", markup=False)
    for issue in data.issues:
        console.print(f"  {issue}", markup=False, highlight=False)
    console.print(
        f"brake coefficient c = {b.mean:.5g} N m/Pa ({b.mean_n_m_per_bar:.0f} N m/bar), "
        f"sd {b.std / b.mean * 100:.2f} %, window {b.window[0]:.2f}-{b.window[1]:.2f} s "
        f"({b.n_samples} samples)", markup=False, highlight=False)
    p = law.overall.params
    console.print(
        f"mu(slip) all speeds: mu_s = {p['mu_s']:.4f}, s0 = {p['s0']:.4g} m/s, "
        f"A = {p['A']:.3f}, B = {p['B']:.3g} s/m; R^2 = {law.overall.r_squared:.3f}, "
        f"slip {law.overall.slip_range[0]:.2f}-{law.overall.slip_range[1]:.2f} m/s",
        markup=False, highlight=False)
    console.print(f"outputs written to {escape(str(out))}")


def register(app: typer.Typer) -> None:
    """Add the identification commands to the main CLI."""
    app.command("detect")(detect)
    app.command("identify")(identify)
