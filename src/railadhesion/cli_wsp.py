"""``railadhesion wsp-test``: run a WSP test programme on a controller (docs/wsp.md)."""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.markup import escape
from rich.table import Table

from railadhesion.cli_checks import EXIT_CHECKS_FAILED, OutputConsole, err_console, fail

console = OutputConsole()


def _fmt(value, spec):
    return "-" if not isinstance(value, int | float) or not math.isfinite(value) else (
        format(value, spec))


def register(app: typer.Typer) -> None:
    """Add the ``wsp-test`` command to the main app."""

    @app.command("wsp-test")
    def wsp_test(
        programme: str = typer.Argument(
            ..., help="Programme TOML file, or 'default' for the shipped 31-case programme."),
        controller: str = typer.Option(
            "default", "--controller",
            help="'default' (the package's WSP), a .fmu file (FMI 2.0 co-simulation WSP unit), "
                 "or a Python controller as 'module:name' or 'file.py:name'."),
        out: Path = typer.Option(..., "--out", help="Output folder."),
        case: list[str] = typer.Option(None, "--case", help="Run only this case (repeatable)."),
        period: float | None = typer.Option(
            None, help="Control period [s] of a plain-function controller or of an FMU "
                       "without a default step size."),
        figures: bool = typer.Option(True, help="One PNG per case and a summary figure."),
        histories: bool = typer.Option(False, help="Also write each case's histories "
                                                   "(Parquet)."),
        quiet: bool = typer.Option(False, help="No progress lines."),
    ) -> None:
        """Run a WSP test programme: per case and overall JSON/CSV, figures; exit status 4 if a
        case failed a check or could not run (the results of the others are written)."""
        from railadhesion.braking.bench import (
            WSPControllerError,
            load_controller,
            load_wsp_programme,
            run_wsp_programme,
        )

        try:
            prog = load_wsp_programme(programme)
            if case:
                prog = prog.select(case)
            ctrl = load_controller(controller, control_period=period,
                                   wsp_settings=prog.wsp or None)
        except (ValueError, ImportError, WSPControllerError) as exc:
            fail(exc)

        def progress(k, n, name):
            if not quiet:
                console.print(f"case {k + 1}/{n}: {escape(name)}", highlight=False)

        result = run_wsp_programme(prog, ctrl, out=out, figures=figures, histories=histories,
                                   progress=progress)
        table = Table(title=escape(f"{prog.name or programme} — {result.controller}"))
        # stop / its adhesion-limited distance; / the stop without WSP; extension over the
        # dry stop; longest lock; time in deep slide; mean braking creepage; vented free air
        for col in ("case", "status", "stop [m]", "/ideal", "/no WSP", "dry+%", "lock [s]",
                    "deep [s]", "creep", "air [l]", "ok"):
            table.add_column(escape(col), justify="left" if col in ("case", "status") else
                             "right", no_wrap=col == "case")
        for c in result.cases:
            if c.get("status") == "error":
                table.add_row(escape(c["name"]), "[red]error[/red]", "", "", "", "", "", "",
                              "", "", "no")
                continue
            table.add_row(escape(c["name"]), escape(c["status"]),
                          _fmt(c["stopping_distance_m"], ".1f"), _fmt(c["distance_ratio"], ".3f"),
                          _fmt(c["distance_vs_no_wsp"], ".3f"),
                          _fmt(c["extension_vs_dry_percent"], ".0f"),
                          _fmt(c["longest_lock_s"], ".2f"), _fmt(c["deep_slide_s"], ".2f"),
                          _fmt(c["mean_creep"], ".3f"), _fmt(c["vented_air_l"], ".0f"),
                          "yes" if c.get("passed") else "[red]no[/red]")
        console.print(table)
        for c in result.cases:
            if c.get("status") == "error":
                err_console.print(f"[red]{escape(c['name'])}:[/red] {escape(c['message'])}",
                                  soft_wrap=True)
        o = result.overall
        console.print(
            f"{o['passed']}/{o['cases']} cases passed; worst longest lock "
            f"{_fmt(o['worst_longest_lock_s'], '.2f')} s, worst distance ratio "
            f"{_fmt(o['worst_distance_ratio'], '.3f')} (against no WSP "
            f"{_fmt(o['worst_distance_vs_no_wsp'], '.3f')}), mean adhesion utilisation "
            f"{_fmt(o['mean_adhesion_utilisation'], '.3f')}, vented air "
            f"{_fmt(o['total_vented_air_l'], '.0f')} l", highlight=False)
        console.print(f"outputs written to {escape(str(out))}")
        if result.failed:
            raise typer.Exit(code=EXIT_CHECKS_FAILED)
