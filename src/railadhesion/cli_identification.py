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


def register(app: typer.Typer) -> None:
    """Add the identification commands to the main CLI."""
    app.command("detect")(detect)
