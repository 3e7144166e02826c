"""``railadhesion wsp-test``: run a WSP test programme on a controller (docs/wsp.md)."""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from railadhesion.cli_checks import EXIT_CHECKS_FAILED, OutputConsole, err_console, fail

console = OutputConsole()


def _fmt(value, spec):
    return "-" if not isinstance(value, int | float) or not math.isfinite(value) else (
        format(value, spec))


# The columns of the results table: (header, the case's key, format). Stop; its
# adhesion-limited distance; the stop without WSP; extension over the dry stop; longest lock;
# time in deep slide; mean braking creepage; vented free air; the checks passed.
_COLUMNS = (("stop [m]", "stopping_distance_m", ".1f"), ("/ideal", "distance_ratio", ".3f"),
            ("/no WSP", "distance_vs_no_wsp", ".3f"),
            ("dry+%", "extension_vs_dry_percent", ".0f"), ("lock [s]", "longest_lock_s", ".2f"),
            ("deep [s]", "deep_slide_s", ".2f"), ("creep", "mean_creep", ".3f"),
            ("air [l]", "vented_air_l", ".0f"))
# Where the table is split in two when it is wider than the console.
_SPLIT = 4


def _table(title: str, cases, columns, *, ok: bool) -> Table:
    table = Table(title=escape(title) if title else None)
    # the names and statuses may wrap (fold); numbers never: they keep their full width
    table.add_column("case", overflow="fold")
    table.add_column("status", overflow="fold")
    for header, _, _ in columns:
        table.add_column(escape(header), justify="right", no_wrap=True)
    if ok:
        table.add_column("ok", no_wrap=True)
    for c in cases:
        if c.get("status") == "error":
            cells = [""] * len(columns) + (["no"] if ok else [])
            table.add_row(escape(c["name"]), "[red]error[/red]", *cells)
            continue
        cells = [_fmt(c.get(key), spec) for _, key, spec in columns]
        if ok:
            cells.append("yes" if c.get("passed") else "[red]no[/red]")
        table.add_row(escape(c["name"]), escape(c["status"]), *cells)
    return table


def results_tables(title: str, cases, console: Console) -> list[Table]:
    """The results table of ``wsp-test``: one table, or two (the stops, then locks, slides,
    creep and air) when one is wider than ``console`` (80 columns when standard output is
    not a terminal), so that no number is cut.

    Parameters
    ----------
    title : str
        Title of the (first) table.
    cases : sequence of dict
        The programme's per-case results (``WSPProgrammeResult.cases``).
    console : rich.console.Console
        The console the tables are printed on (its width decides).
    """
    table = _table(title, cases, _COLUMNS, ok=True)
    natural = console.measure(table, options=console.options.update_width(10_000)).maximum
    if natural <= console.width:
        return [table]
    return [_table(title, cases, _COLUMNS[:_SPLIT], ok=True),
            _table("", cases, _COLUMNS[_SPLIT:], ok=False)]


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
        for table in results_tables(f"{prog.name or programme} — {result.controller}",
                                    result.cases, console):
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
