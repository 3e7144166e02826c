"""``railadhesion brake``: run a braking scenario (TOML) and write summary, histories, figures."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import typer
from rich.markup import escape
from rich.table import Table

from railadhesion.cli_checks import (
    OutputConsole,
    allow_untrusted_option,
    braking_findings,
    err_console,
    fail,
    finish,
    progress_disabled,
    warn,
)
from railadhesion.plausibility import RailadhesionWarning

console = OutputConsole()


def write_outputs(result, out: Path, *, figures: bool = True, parquet: bool = True,
                  log: bool = False, findings=None) -> list[Path]:
    """Write summary.json, histories.csv (+ .parquet), figures and optionally a test log.

    ``summary.json`` records ``trusted`` and ``warnings``: ``findings`` (default: those of
    the result, :func:`railadhesion.cli_checks.braking_findings`)."""
    from railadhesion.braking.bench import json_safe

    out.mkdir(parents=True, exist_ok=True)
    written = []
    findings = braking_findings(result) if findings is None else list(findings)
    summary = {"status": result.status, "message": result.message, **result.summary,
               "trusted": not findings, "warnings": findings, "settings": result.settings}
    path = out / "summary.json"
    path.write_text(json.dumps(json_safe(summary), indent=2, ensure_ascii=False) + "\n",
                    encoding="utf-8")
    written.append(path)
    path = out / "histories.csv"
    result.histories.to_csv(path, index=False, float_format="%.9g")
    written.append(path)
    if parquet:
        try:
            path = out / "histories.parquet"
            result.histories.to_parquet(path, index=False)
            written.append(path)
        except ImportError:  # pragma: no cover - pyarrow is a dependency
            pass
    if figures:
        from railadhesion.braking.figures import braking_figures

        for name, fig in braking_figures(result).items():
            path = out / f"{name}.png"
            fig.savefig(path, dpi=100, bbox_inches="tight")
            written.append(path)
    if log:
        from railadhesion.braking.log import write_braking_log

        path = out / "braking_log.csv"
        write_braking_log(result, path)
        written.append(path)
    return written


def register(app: typer.Typer) -> None:
    """Add the ``brake`` command to the main app."""

    @app.command("brake")
    def brake(
        scenario: Path = typer.Argument(..., help="Scenario TOML file (docs/braking.md)."),
        out: Path = typer.Option(..., "--out", help="Output folder."),
        dt: float | None = typer.Option(None, help="Override the time step [s]."),
        figures: bool = typer.Option(True, help="Write PNG figures."),
        log: bool = typer.Option(False, help="Also write a braking-test log (2.4 ms, CSV)."),
        quiet: bool = typer.Option(False, help="No progress bar."),
        allow_untrusted: bool = allow_untrusted_option(),
    ) -> None:
        """Simulate a braking scenario: summary JSON, CSV/Parquet histories, figures.

        Exit code 3, unless --allow-untrusted, when the result cannot be trusted (the train
        did not stop, NaN results; docs/checks.md). The outputs are written either way."""
        from rich.progress import Progress

        from railadhesion.braking.scenario import load_scenario, run_scenario
        from railadhesion.braking.simulator import SimulationError

        try:
            sc = load_scenario(scenario)
        except ValueError as exc:
            fail(exc)
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", RailadhesionWarning)
                if quiet or progress_disabled():
                    result, dry = run_scenario(sc, dt=dt)
                else:  # a live bar on standard error (off a terminal it would leave a line)
                    with Progress(console=err_console, transient=True) as bar:
                        task = bar.add_task("braking (speed lost)", total=1.0)
                        result, dry = run_scenario(
                            sc, dt=dt, progress=lambda f: bar.update(task, completed=f))
            findings = braking_findings(result)
            if dry is not None:
                findings += braking_findings(dry, "the dry-rail comparison")
            write_outputs(result, out, figures=figures, log=log, findings=findings)
        except (SimulationError, ValueError) as exc:
            fail(exc)
        for w in caught:  # the package's warnings, each once; others as Python shows them
            if not issubclass(w.category, RailadhesionWarning):
                warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        for w in caught:
            if issubclass(w.category, RailadhesionWarning):
                warn(str(w.message))
        s = result.summary
        table = Table(title=escape(sc.name or str(scenario)))
        table.add_column("quantity")
        table.add_column("value", justify="right")
        table.add_row("status", escape(result.message))
        table.add_row(escape("stopping distance [m]"), f"{s['stopping_distance_m']:.1f}")
        table.add_row(escape("stopping time [s]"), f"{s['stopping_time_s']:.2f}")
        if "extension_m" in s:
            table.add_row(escape("dry-rail stopping distance [m]"),
                          f"{s['dry_stopping_distance_m']:.1f}")
            table.add_row(escape("extension vs dry [m, %]"),
                          f"{s['extension_m']:.1f}  ({s['extension_percent']:.1f} %)")
        table.add_row(escape("max slip [%]"), f"{100 * s['max_slip']:.1f}")
        table.add_row(escape("longest lock [s] (wheel < 10 % of train speed)"),
                      f"{s['longest_lock_s']:.2f}")
        table.add_row(escape("deep slide [s, m slid] (creepage >= 0.5)"),
                      f"{s['deep_slide_s']:.2f}, {s['deep_slide_distance_m']:.1f}")
        table.add_row("mean adhesion utilisation", f"{s['mean_adhesion_utilisation']:.3f}")
        table.add_row(escape("WSP vent actions / vented air [l]"),
                      f"{s['vent_actions']} / {s['vented_air_l']:.0f}")
        if s.get("pressure_clipped"):
            demand, cap = s["highest_command_Pa"] / 1e5, s["max_pressure_Pa"] / 1e5
            table.add_row(escape("brake demand clipped to max_pressure [bar]"),
                          f"{demand:.3g} -> {cap:.3g}")
        table.add_row("trusted", "yes" if not findings else f"NO ({len(findings)} finding(s))")
        console.print(table)
        console.print(f"outputs written to {escape(str(out))}")
        finish(findings, allow=allow_untrusted, what="braking result")
