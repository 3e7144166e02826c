"""``railadhesion odometry-test``: run an odometry programme on an odometry (docs/odometry.md)."""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.markup import escape
from rich.table import Table

from railadhesion.cli_checks import EXIT_CHECKS_FAILED, OutputConsole, err_console, fail

console = OutputConsole()
_ROUTINE = ("slide", "spin", "dead_reckoning")


def _fmt(value, spec):
    return "-" if not isinstance(value, int | float) or not math.isfinite(value) else (
        format(value, spec))


def register(app: typer.Typer) -> None:
    """Add the ``odometry-test`` command to the main app."""

    @app.command("odometry-test")
    def odometry_test(
        programme: str = typer.Argument(
            ..., help="Programme TOML file, or 'default' for the shipped programme."),
        odometry: str = typer.Option(
            "reference", "--odometry",
            help="'reference' (the package's odometry), a .fmu file (FMI 2.0 co-simulation "
                 "odometry), or a Python odometry as 'module:name' or 'file.py:name'."),
        out: Path = typer.Option(..., "--out", help="Output folder."),
        case: list[str] = typer.Option(None, "--case", help="Run only this case (repeatable)."),
        period: float | None = typer.Option(
            None, help="Period [s] of an odometry without one (an FMU without a default "
                       "step size)."),
        figures: bool = typer.Option(True, help="One PNG per case and a summary figure."),
        histories: bool = typer.Option(False, help="Also write each case's samples (Parquet)."),
        quiet: bool = typer.Option(False, help="No progress lines."),
    ) -> None:
        """Run an odometry programme: per case and fit JSON/CSV, every violation of the
        interval, figures; exit status 4 if a fit failed a check or could not run (the
        results of the others are written)."""
        from railadhesion.braking.odometry_bench import (
            OdometryInterfaceError,
            load_odometry,
            load_odometry_programme,
            run_odometry_programme,
        )

        try:
            prog = load_odometry_programme(programme)
            if case:
                prog = prog.select(case)
            odo = load_odometry(odometry, period=period)
        except (ValueError, ImportError, OdometryInterfaceError) as exc:
            fail(exc)

        def progress(k, n, name):
            if not quiet:
                console.print(f"case {k + 1}/{n}: {escape(name)}", highlight=False)

        result = run_odometry_programme(prog, odo, out=out, figures=figures,
                                        histories=histories, progress=progress)
        console.print(escape(f"{prog.name or programme} — {result.odometry}"),
                      style="bold", highlight=False)
        # per case: the error at the stop over the stopping distance; the largest speed
        # error; the interval below and above the true position at the stop; the checks
        # (violations of the interval counted); flags other than slide, spin, dead reckoning
        for c in result.cases:
            if c.get("status") == "error":
                console.print(f"[red]{escape(c['name'])}: error[/red]")
                continue
            table = Table(title=escape(f"{c['name']}: stop {_fmt(c['stopping_distance_m'], '.0f')}"
                                       f" m"), title_justify="left")
            for col in ("fit", "err [%]", "dv [m/s]", "-int [m]", "+int [m]", "check"):
                table.add_column(escape(col), justify="left" if col == "fit" else "right",
                                 no_wrap=True)
            alerts = []
            for f in c["fits"]:
                if f.get("status") == "error":
                    table.add_row(escape(f["fit"]), "", "", "", "", "[red]error[/red]")
                    continue
                alerts += [f"{f['fit']}: {k} from {v['first_s']:.2f} s"
                           for k, v in f["flags"].items() if k not in _ROUTINE]
                check = ("ok" if f.get("passed") else "[red]fail[/red]") if f["inside"] else (
                    f"[red]{len(f['violations'])} viol.[/red]")
                table.add_row(escape(f["fit"]), _fmt(100 * f["stop_error_fraction"], "+.2f"),
                              _fmt(f["speed_error_max_m_s"], ".2f"),
                              _fmt(f["interval_below_at_stop_m"], ".0f"),
                              _fmt(f["interval_above_at_stop_m"], ".0f"), check)
            console.print(table)
            for line in alerts:
                console.print(f"  flagged {escape(line)}", highlight=False)
        for c in result.cases:
            if c.get("status") == "error":
                err_console.print(f"[red]{escape(c['name'])}:[/red] {escape(c['message'])}",
                                  soft_wrap=True)
            for f in c.get("fits", []):
                if f.get("status") == "error":
                    err_console.print(f"[red]{escape(c['name'])} / {escape(f['fit'])}:[/red] "
                                      f"{escape(f['message'])}", soft_wrap=True)
                for e in f.get("violations", [])[:20]:
                    console.print(f"[red]violation[/red] {escape(c['name'])} / "
                                  f"{escape(f['fit'])}: {e['side']} from {e['start_s']:.3f} to "
                                  f"{e['end_s']:.3f} s, worst {e['worst_size_m']:.3g} m at "
                                  f"{e['worst_time_s']:.3f} s", highlight=False)
                if len(f.get("violations", [])) > 20:
                    console.print(f"... {len(f['violations']) - 20} more in violations.csv")
        o = result.overall
        console.print(
            f"{o['passed']}/{o['cases']} cases passed; true position inside every interval: "
            f"{'yes' if o['inside_everywhere'] else 'NO'}; worst stop error "
            f"{_fmt(100 * o['worst_stop_error_fraction_with_accelerometer'], '.2f')} % with an "
            f"accelerometer, "
            f"{_fmt(100 * o['worst_stop_error_fraction_without_accelerometer'], '.2f')} % "
            "without", highlight=False)
        console.print(f"outputs written to {escape(str(out))}")
        if result.failed or o["fit_errors"]:
            raise typer.Exit(code=EXIT_CHECKS_FAILED)
