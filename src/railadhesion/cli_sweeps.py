"""CLI commands for sweeps at scale: ``railadhesion sweep SPEC.toml --out map.zarr``.

A thin shell over :mod:`railadhesion.sweeps`: the spec is validated by
:func:`~railadhesion.sweeps.load_sweep_spec`, the sweep run by
:func:`~railadhesion.sweeps.run_sweep` with a Rich progress bar.
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from railadhesion.cli_checks import (
    OutputConsole,
    allow_untrusted_option,
    err_console,
    fail,
    finish,
    progress_disabled,
)

console = OutputConsole()


def _fail(message) -> None:
    """``error: ...`` on standard error, exit code 2."""
    fail(message)


def _failures(result, what: str) -> tuple[str, list[str]]:
    """(``failed <what>: N`` with the first reason, findings for the exit code)."""
    n = int(result.failed_points)
    if n == 0:
        return f"failed {what}: 0", []
    import json

    try:
        quoted = json.loads(result.dataset.attrs.get("failures", "[]"))
    except (TypeError, ValueError):
        quoted = []
    if quoted:
        point = ", ".join(f"{k}={v}" for k, v in quoted[0]["point"].items())
        first = f"{quoted[0]['message']} (at {point})"
    else:  # in-memory and NetCDF sweeps flag the points (error == 1) without messages
        first = "see the error variable of the output (1 where a point failed)"
    return f"failed {what}: {n} (first: {first})", [f"{n} failed {what}; first: {first}"]


# The --scheduler option of both commands (typer copies an option it reads: one serves both).
_SCHEDULER_OPTION = typer.Option(
    None, help="Dask cluster address (tcp://HOST:PORT), or a local scheduler: threads "
    "(default), processes, synchronous.")  # fmt: skip


def _plan(load, spec: Path):
    """``(the spec load(spec) reads, its plan, its dimensions as "dim n x dim n")``; a spec
    that is not valid (ValueError) is a user error."""
    try:
        loaded = load(spec)
        plan = loaded.plan()
    except ValueError as exc:
        _fail(exc)
    dims = " x ".join(f"{d} {n}" for d, n in zip(plan.dims, plan.shape, strict=True))
    return loaded, plan, dims


def _run(progress, run, cannot_write: str):
    """``run()``; on a ValueError (a user error) or an OSError (``cannot_write: ...``) the
    progress bar is stopped and the command fails."""
    try:
        return run()
    except ValueError as exc:
        progress.stop()
        _fail(exc)
    except OSError as exc:
        progress.stop()
        _fail(f"{cannot_write}: {exc}")


def sweep(
    spec: Path = typer.Argument(..., help="Sweep spec file (TOML; see examples/wilac_map.toml)."),
    out: Path = typer.Option(..., "--out", help="Output: a Zarr store (*.zarr, resumable) or "
                             "NetCDF file (*.nc)."),
    scheduler: str | None = _SCHEDULER_OPTION,
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace an existing output."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Evaluate a model over the grid of SPEC with Dask; write the map chunk by chunk.

    A re-run with the same spec and --out resumes: only chunks not yet written are computed.
    Exit code 3 when points failed (the first reason is printed), unless --allow-untrusted.
    """
    from railadhesion.sweeps import load_sweep_spec

    sweep_spec, plan, dims = _plan(load_sweep_spec, spec)
    console.print(f"{escape(plan.model.name)} over {escape(dims)} = {plan.size:,} points in "
                  f"{plan.n_chunks} chunks", highlight=False)  # fmt: skip
    progress = Progress(
        TextColumn("chunks"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
        console=err_console, transient=False, disable=progress_disabled(),
    )
    task = {"id": None}

    def on_start(result):
        if result.dashboard_link:
            console.print(f"Dask cluster dashboard: {escape(result.dashboard_link)}")
        if result.chunks_skipped:
            console.print(f"resuming: {result.chunks_skipped} of {result.chunks_total} chunks "
                          "already written")  # fmt: skip
        task["id"] = progress.add_task("sweep", total=result.chunks_computed)
        progress.start()

    def on_chunk(done, total):
        progress.update(task["id"], completed=done)

    try:
        result = _run(progress, lambda: sweep_spec.run(
            out, scheduler=scheduler, overwrite=overwrite, on_start=on_start, on_chunk=on_chunk,
        ), f"cannot write {out}")  # fmt: skip
    except KeyboardInterrupt:
        progress.stop()
        err_console.print("interrupted: chunks already written are kept; re-run the same command "
                      "to resume")  # fmt: skip
        raise typer.Exit(code=130) from None
    progress.update(task["id"], completed=result.chunks_computed)
    progress.stop()
    rate = result.points_per_second
    failed, findings = _failures(result, "points")
    console.print(
        f"{result.chunks_computed} chunks computed, {result.chunks_skipped} already written; "
        f"{result.elapsed:.1f} s" + (f", {rate:,.0f} points/s" if rate == rate else "")
        + f"; {escape(failed)}", highlight=False, soft_wrap=True,
    )  # fmt: skip
    console.print(f"map written to {escape(str(out))}")
    finish(findings, allow=allow_untrusted, what="sweep")


def study(
    spec: Path = typer.Argument(..., help="Study spec file (TOML; see "
                                "examples/braking_study.toml)."),
    out: Path = typer.Option(..., "--out", help="Output folder: study.zarr (resumable), "
                             "study.csv, extension.png."),
    scheduler: str | None = _SCHEDULER_OPTION,
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace an existing study."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Run many braking stops over a scenario design (factorial or Monte Carlo) with Dask.

    Each stop is one task; a re-run with the same spec and --out resumes. A stop that cannot
    be trusted (the train did not stop, NaN) is a failed stop; exit code 3 when there are
    any (the first reason is printed), unless --allow-untrusted.
    """
    from rich.table import Table

    from railadhesion.sweeps.study import load_study_spec, run_study

    study_spec, plan, dims = _plan(load_study_spec, spec)
    console.print(f"braking study over {escape(dims)} = {plan.size:,} stops", highlight=False)
    progress = Progress(TextColumn("stops"), BarColumn(), MofNCompleteColumn(),
                        TimeRemainingColumn(), console=err_console,
                        disable=progress_disabled())  # fmt: skip
    task = {"id": None}

    def on_start(result):
        if result.dashboard_link:
            console.print(f"Dask cluster dashboard: {escape(result.dashboard_link)}")
        task["id"] = progress.add_task("study", total=result.chunks_computed)
        progress.start()

    result = _run(progress, lambda: run_study(
        study_spec, out, scheduler=scheduler, overwrite=overwrite, on_start=on_start,
        on_chunk=lambda done, total: progress.update(task["id"], completed=done),
    ), f"cannot write to {out}")  # fmt: skip
    progress.stop()
    ds = result.dataset
    if "water_flow" in ds.dims:
        ext = ds["extension_percent"].where(ds["error"] == 0)
        others = [d for d in ext.dims if d != "water_flow"]
        table = Table(title="Stopping-distance extension against dry [%]")
        for col in ("w [µl/s]", "median", "min", "max"):
            table.add_column(escape(col), justify="right")
        for w in ds["water_flow"].values:
            e = ext.sel(water_flow=w)
            table.add_row(f"{w:g}", *(f"{float(f(e, others)):.2f}" for f in (
                lambda x, d: x.median(d), lambda x, d: x.min(d), lambda x, d: x.max(d))))
        console.print(table)
    failed, findings = _failures(result, "stops")
    console.print(f"{result.chunks_computed} chunks computed, {result.chunks_skipped} already "
                  f"written; {escape(failed)}", highlight=False, soft_wrap=True)  # fmt: skip
    console.print(f"study written to {escape(str(out))} (study.zarr, study.csv, extension.png)")
    finish(findings, allow=allow_untrusted, what="study")


def register(app: typer.Typer) -> None:
    """Add the sweep and study commands to the ``railadhesion`` app."""
    app.command("sweep")(sweep)
    app.command("study")(study)
