"""Command-line interface: a thin shell over the public Python API.

Every command calls public functions that are also usable from Python; the CLI adds parsing
and printing only. Creepages on the command line are given in percent (``--creep-percent``),
water flow rates in µl/s, forces in N, speeds in m/s, lengths in m.
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table
from typer.core import TyperGroup

from railadhesion.cli_checks import (
    OutputConsole,
    allow_untrusted_option,
    err_console,
    fail,
    finish,
    note,
    progress_disabled,
    start_messages,
    stop_on_broken_pipe,
    warn,
)


class _Group(TyperGroup):
    """The command group of the app: a command whose standard output is closed by its reader
    (``railadhesion polach --format csv | head -1``) stops quietly with
    :data:`~railadhesion.cli_checks.EXIT_BROKEN_PIPE`, not with click's code 1 (a bug)."""

    def invoke(self, ctx):
        try:
            value = super().invoke(ctx)
            sys.stdout.flush()  # a closed pipe shows here, not in Python's flush at exit
            return value
        except BrokenPipeError:  # a write outside Rich (OutputConsole stops on its own)
            stop_on_broken_pipe()


# rich_markup_mode=None: help texts are plain text, so units such as "[m]" and "[m/s]" are
# shown as written (Rich markup would take them for tags and drop them).
app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode=None,
    help="Wheel-rail adhesion: contact mechanics, creep-force models (Polach, WILAC, Fletcher), "
    "calibration. Units: SI; creep in percent on the command line; water flow in µl/s.",
)
wilac_app = typer.Typer(
    no_args_is_help=True, rich_markup_mode=None, help="WILAC water-induced low adhesion model."
)
params_app = typer.Typer(
    no_args_is_help=True, rich_markup_mode=None, help="Named parameter sets and parameter files."
)
fit_app = typer.Typer(
    no_args_is_help=True, rich_markup_mode=None,
    help="Fit model parameters to measured creep curves.",
)  # fmt: skip
app.add_typer(wilac_app, name="wilac")
app.add_typer(params_app, name="params")
app.add_typer(fit_app, name="fit")

console = OutputConsole()

#: Output formats of the table commands.
FORMATS = ("table", "csv", "json")

# Options of the wilac commands (typer copies an option it reads: one serves all): --params,
# and the tram rig's normal force and speed.
_WILAC_PARAMS_OPTION = typer.Option(None, "--params", help="WILAC TOML file.")
_TRAM_NORMAL_FORCE_OPTION = typer.Option(4200.0, help="Normal force Q [N].")
_TRAM_SPEED_OPTION = typer.Option(5.0, help="Rolling speed [m/s].")


def _version(value: bool) -> None:
    if value:
        import railadhesion

        console.print(f"railadhesion {railadhesion.__version__}", highlight=False)
        raise typer.Exit()


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a Python warning as one plain line on standard error, without the source
    location; a message already printed in this run is not repeated."""
    warn(str(message))


@app.callback()
def _main(
    ctx: typer.Context,
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """Wheel-rail adhesion: contact mechanics, creep-force models, calibration."""
    # Warnings of the library (excluded CSV rows, an untrustworthy calibration) are shown to
    # the user as plain lines on standard error: no file name and line number of our source,
    # each distinct message once.
    start_messages()
    catcher = warnings.catch_warnings()
    catcher.__enter__()
    warnings.simplefilter("default")
    warnings.showwarning = _show_warning
    ctx.call_on_close(lambda: catcher.__exit__(None, None, None))


def _format_option():
    return typer.Option(
        "table", "--format", help="Output: 'table' (readable), 'csv' or 'json' (for other tools)."
    )


def _emit(title: str, columns, rows, fmt: str, out: Path | None, note: str = "") -> None:
    """Print or write a table.

    ``columns`` is a list of ``(key, label, fmt)``: ``key`` names the column in CSV/JSON
    (snake case with the unit, e.g. ``fx_kN``), ``label`` heads the readable table, ``fmt`` is
    a format spec for the readable table. ``rows`` hold raw values. ``out``: write there
    (format from ``fmt``, or from the file suffix .csv/.json when ``fmt`` is 'table').
    """
    if fmt not in FORMATS:
        _fail(f"--format must be one of {list(FORMATS)}, got {fmt!r}")
    if out is not None and fmt == "table":
        fmt = {".csv": "csv", ".json": "json"}.get(out.suffix.lower(), "table")
    keys = [c[0] for c in columns]
    if fmt == "table":
        table = Table(title=escape(title))
        for _, label, spec in columns:
            table.add_column(escape(label), justify="right" if spec else "left")
        for row in rows:
            table.add_row(*[_cell(v, c[2]) for v, c in zip(row, columns, strict=True)])
        if out is None:
            console.print(table)
            if note:
                console.print(escape(note), highlight=False, soft_wrap=True)
            return
        buffer = Console(file=io.StringIO(), width=200, color_system=None)
        buffer.print(table)
        if note:
            buffer.print(note, markup=False, highlight=False)
        text = buffer.file.getvalue()
    elif fmt == "csv":
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(keys)
        writer.writerows([[_plain(v) for v in row] for row in rows])
        text = buf.getvalue()
    else:
        records = [dict(zip(keys, [_plain(v) for v in row], strict=True)) for row in rows]
        text = json.dumps(records, indent=1, allow_nan=True) + "\n"
    if out is None:
        console.print(text, end="", markup=False, highlight=False, soft_wrap=True)
        return
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
    except OSError as exc:
        _fail(f"cannot write the table to {out}: {exc}")
    err_console.print(f"{title}: {fmt} written to {escape(str(out))}", highlight=False)


def _plain(value):
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def _cell(value, spec: str) -> str:
    if value is None:
        return "-"
    if isinstance(value, str) or not spec:
        return str(value)
    return format(value, spec)

def _floats(text: str, name: str) -> np.ndarray:
    """Parse a comma-separated list of numbers, naming the option on error."""
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise typer.BadParameter(
            f"{name}: expected numbers separated by commas, got {text!r}"
        ) from None
    if not values:
        raise typer.BadParameter(f"{name}: expected at least one number")
    return np.asarray(values)


def _creep_percent(text: str) -> np.ndarray:
    """Creepages given in percent: |creep| <= 100 % (a locked wheel is 100 %)."""
    values = _floats(text, "--creep-percent")
    if np.any(~np.isfinite(values)) or np.any(np.abs(values) > 100):
        raise typer.BadParameter(
            f"--creep-percent: creepages must be in [-100, 100] %, got {text!r}"
        )
    return values / 100


def _fail(exc: Exception) -> None:
    """``error: <exc>`` on standard error, exit code 2 (:func:`railadhesion.cli_checks.fail`)."""
    fail(exc)


def _save(fig, out: Path | None) -> None:
    if out is None:
        return
    if not out.suffix:  # matplotlib would add ".png" itself; say which file is written
        out = out.with_name(out.name + ".png")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=110, bbox_inches="tight")
    except (OSError, ValueError) as exc:  # unwritable folder, unknown image format
        _fail(f"cannot write the figure to {out}: {exc}")
    err_console.print(f"figure written to {escape(str(out))}")  # stdout may hold CSV/JSON


def _figure(out: Path | None, draw) -> None:
    """Save the figure ``draw()`` returns to ``out`` (:func:`_save`); a ValueError while
    drawing (an option value out of range, an unreadable parameter file) is a user error."""
    try:
        fig = draw()
    except ValueError as exc:
        _fail(exc)
    _save(fig, out)


@app.command()
def demo(
    out: Path = typer.Option(Path("demo-output"), help="Folder for the demo figures."),
) -> None:
    """Run the demo: Hertz, Kalker, Polach, FASTSIM, Fletcher and WILAC on realistic cases."""
    from railadhesion.demo import run_demo

    try:
        run_demo(out_dir=out, console=console)
    except OSError as exc:  # e.g. the output folder cannot be created
        _fail(f"cannot write the demo figures to {out}: {exc}")


@app.command()
def hertz(
    normal_force: float = typer.Option(110e3, help="Normal force Q [N]."),
    wheel_radius: float = typer.Option(0.625, help="Wheel rolling radius [m]."),
    wheel_lateral_radius: float = typer.Option(
        float("inf"), help="Wheel transverse profile radius [m] (negative if concave)."
    ),
    rail_lateral_radius: float = typer.Option(0.3, help="Rail head transverse radius [m]."),
    rail_radius: float = typer.Option(
        float("inf"), help="Rail (or roller) rolling radius [m]; inf for a rail."
    ),
    young: float = typer.Option(2.1e11, help="Young's modulus of both bodies [Pa]."),
    poisson: float = typer.Option(0.28, help="Poisson's ratio of both bodies."),
    fmt: str = _format_option(),
    out: Path | None = typer.Option(None, help="Write the table here (.csv, .json or text)."),
) -> None:
    """Hertz elliptical contact of a wheel on a rail or roller."""
    from railadhesion.contact.hertz import hertz_3d

    try:
        h = hertz_3d(
            normal_force, wheel_radius, wheel_lateral_radius, rail_lateral_radius, rail_radius,
            young=young, poisson=poisson,
        )
    except ValueError as exc:
        _fail(exc)
    rows = [
        ("a (rolling direction) [mm]", "a_mm", h.a * 1e3),
        ("b (lateral) [mm]", "b_mm", h.b * 1e3),
        ("a/b", "a_over_b", h.a_over_b),
        ("max pressure p0 [MPa]", "max_pressure_MPa", h.max_pressure / 1e6),
        ("approach [µm]", "approach_um", h.approach * 1e6),
        ("curvature A [1/m]", "curvature_A_per_m", h.curvature_A),
        ("curvature B [1/m]", "curvature_B_per_m", h.curvature_B),
    ]
    if fmt == "table" and (out is None or out.suffix.lower() not in (".csv", ".json")):
        _emit("Hertz contact", [("quantity", "quantity", ""), ("value", "value", ".4g")],
              [(label, float(v)) for label, _, v in rows], fmt, out)  # fmt: skip
    else:  # one record, one column per quantity (with its unit in the name)
        _emit("Hertz contact", [(key, key, ".4g") for _, key, _ in rows],
              [[float(v) for _, _, v in rows]], fmt, out)  # fmt: skip


@app.command()
def polach(
    parameter_set: str = typer.Option(
        "polach2005_dry", "--set", help="Named Polach set ('railadhesion params list'), or a "
        "Polach parameter file (TOML, e.g. written by 'railadhesion fit polach --out').",
    ),
    creep_percent: str = typer.Option(
        "0.1,0.2,0.5,1,2,5,10,20,40", help="Longitudinal creepages [%], comma-separated."
    ),
    normal_force: float = typer.Option(110e3, help="Normal force Q [N]."),
    speed: float = typer.Option(10.0, help="Rolling speed V [m/s]."),
    geometry: str = typer.Option(
        "locomotive",
        help="Named contact geometry ('locomotive': 0.625 m wheel on a rail head of lateral "
        "radius 0.3 m; 'tram': the tram wheel rig of Trummer et al.); Hertz gives a, b.",
    ),
    a: float | None = typer.Option(
        None, "--a", help="Semi-axis a in the rolling direction [m] (with --b: overrides "
        "--geometry).",
    ),
    b: float | None = typer.Option(None, "--b", help="Lateral semi-axis b [m] (with --a)."),
    fmt: str = _format_option(),
    out: Path | None = typer.Option(
        None, help="Write the creep-curve figure here (.png, .pdf, .svg), or the table (.csv, "
        ".json, or any file with --format csv|json).",
    ),
) -> None:
    """Polach creep curve (adhesion against longitudinal creep) for a named parameter set or
    a parameter file."""
    from railadhesion import adhesion
    from railadhesion.contact.geometry import contact_semi_axes, geometry_description
    from railadhesion.models.polach import Polach

    try:
        params = _polach_set(parameter_set)
        creep = _creep_percent(creep_percent)
        if (a is None) != (b is None):
            raise ValueError("give both --a and --b (the contact semi-axes in m), or neither")
        geo = (a, b) if a is not None else geometry
        ca, cb = contact_semi_axes(geo, normal_force)
        fx, fy = Polach(params).forces(creep, 0.0, 0.0, normal_force, speed, ca, cb)
    except ValueError as exc:
        _fail(exc)
    mu = adhesion(fx, fy, normal_force)
    where = "given semi-axes" if a is not None else geometry_description(geo)
    contact = f"contact: {where}\nHertz at Q = {normal_force:g} N: a = {ca * 1e3:.3g} mm, " \
        f"b = {cb * 1e3:.3g} mm"
    label = params.name or Path(parameter_set).name  # a file's set may have no name
    title = f"Polach '{label}' at Q = {normal_force:g} N, V = {speed:g} m/s"
    table_out = out is not None and (
        fmt != "table" or out.suffix.lower() in (".csv", ".json")
    )
    _emit(
        title,
        [("creep_percent", "creep [%]", "g"), ("fx_kN", "Fx [kN]", ".2f"),
         ("adhesion", "adhesion |T|/Q", ".4f")],
        [(c * 100, f / 1e3, m) for c, f, m in
         zip(creep, np.atleast_1d(fx), np.atleast_1d(mu), strict=True)],
        fmt, out if table_out else None, note=contact,
    )  # fmt: skip
    if out is not None and not table_out:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(creep * 100, mu, marker="o")
        ax.set_xlabel("longitudinal creep [%]")
        ax.set_ylabel("adhesion |T|/Q [-]")
        shown = geo if isinstance(geo, str) else "given a, b"
        ax.set_title(f"Polach {label}, {shown}")
        ax.grid(True, alpha=0.3)
        _save(fig, out)


def _polach_set(value: str):
    """The Polach parameters of ``--set``: a named set, or a Polach parameter file (a path
    ending in .toml, or an existing file; e.g. the file ``fit polach --out`` writes)."""
    from railadhesion.io.paramfiles import load_polach_parameters
    from railadhesion.models.parameters import POLACH_PARAMETER_SETS, polach_parameters

    path = Path(value)
    if value not in POLACH_PARAMETER_SETS and (path.suffix.lower() == ".toml" or path.is_file()):
        try:
            return load_polach_parameters(path)
        except OSError as exc:  # missing file, a folder, no permission: a user error
            raise ValueError(f"--set: cannot read {path}: {exc.strerror or exc}") from exc
    try:
        return polach_parameters(value)
    except ValueError as exc:
        raise ValueError(f"--set: {exc}; or give a Polach parameter file (TOML, as written by "
                         "'railadhesion fit polach --out')") from None


@wilac_app.command("curves", short_help="Creep curves at several water flow rates (paper Fig. 7).")
def wilac_curves(
    water: str = typer.Option("0,25,35,60,350", help="Water flow rates [µl/s], comma-separated."),
    normal_force: float = typer.Option(4200.0, help="Normal force Q [N] (tram rig: 4.2 kN)."),
    speed: float = typer.Option(5.0, help="Rolling speed [m/s] (tram rig: 5 m/s)."),
    params_file: Path | None = _WILAC_PARAMS_OPTION,
    out: Path = typer.Option(Path("wilac_curves.png"), help="Figure file."),
) -> None:
    """Creep curves at several water flow rates (paper Fig. 7)."""
    from railadhesion.plotting import plot_wilac_curves

    _figure(out, lambda: plot_wilac_curves(
        water_flows=tuple(_floats(water, "--water")), normal_force=normal_force, speed=speed,
        params=_load_wilac(params_file),
    ))  # fmt: skip


@wilac_app.command(
    "weights", short_help="Blending weights f_i(w) and transitions e_i(w) (paper Figs. 5, 6)."
)
def wilac_weights_cmd(
    params_file: Path | None = _WILAC_PARAMS_OPTION,
    out: Path = typer.Option(Path("wilac_weights.png"), help="Figure file."),
) -> None:
    """Blending weights f_i(w) and transitions e_i(w) (paper Figs. 5 and 6)."""
    from railadhesion.plotting import plot_wilac_weights

    _figure(out, lambda: plot_wilac_weights(params=_load_wilac(params_file)))


@wilac_app.command(
    "water", short_help="Adhesion against water flow rate at fixed creepages (paper Fig. 8)."
)
def wilac_water(
    creep_percent: str = typer.Option("3,10,30,60", help="Fixed creepages [%], comma-separated."),
    normal_force: float = _TRAM_NORMAL_FORCE_OPTION,
    speed: float = _TRAM_SPEED_OPTION,
    params_file: Path | None = _WILAC_PARAMS_OPTION,
    out: Path = typer.Option(Path("wilac_water.png"), help="Figure file."),
) -> None:
    """Adhesion against water flow rate at fixed creepages (paper Fig. 8)."""
    from railadhesion.plotting import plot_wilac_water

    _figure(out, lambda: plot_wilac_water(
        creeps=tuple(_creep_percent(creep_percent)),
        normal_force=normal_force, speed=speed, params=_load_wilac(params_file),
    ))  # fmt: skip


@wilac_app.command("speeds", short_help="Creep curves at several speeds (paper Figs. 9 and 11).")
def wilac_speeds(
    speeds: str = typer.Option("5,10,20", help="Rolling speeds [m/s], comma-separated."),
    water: float = typer.Option(0.0, help="Water flow rate [µl/s]."),
    normal_force: float = typer.Option(110e3, help="Normal force Q [N] (locomotive: 110 kN)."),
    params_file: Path | None = _WILAC_PARAMS_OPTION,
    out: Path = typer.Option(Path("wilac_speeds.png"), help="Figure file."),
) -> None:
    """Creep curves at several speeds (paper Figs. 9 and 11)."""
    from railadhesion.plotting import plot_wilac_speeds

    _figure(out, lambda: plot_wilac_speeds(
        speeds=tuple(_floats(speeds, "--speeds")), water_flow=water,
        normal_force=normal_force, params=_load_wilac(params_file),
    ))  # fmt: skip


@wilac_app.command(
    "table", short_help="WILAC adhesion over water flow rate and creep (tram rig)."
)
def wilac_table(
    water: str = typer.Option("0,25,35,60,350", help="Water flow rates [µl/s]."),
    creep_percent: str = typer.Option("1,3,10,30,60,90", help="Creepages [%] (braking sign)."),
    normal_force: float = _TRAM_NORMAL_FORCE_OPTION,
    speed: float = _TRAM_SPEED_OPTION,
    params_file: Path | None = _WILAC_PARAMS_OPTION,
    fmt: str = _format_option(),
    out: Path | None = typer.Option(None, help="Write the table here (.csv, .json or text)."),
) -> None:
    """Print WILAC adhesion |T|/Q over water flow rate and creep at the tram-rig contact."""
    from railadhesion.models.wilac import Wilac

    try:
        w = _floats(water, "--water")
        creep = _creep_percent(creep_percent)
        a, b = _tram_contact(normal_force)
        model = Wilac(_load_wilac(params_file))
        mu = model.adhesion(creep[None, :], 0.0, 0.0, normal_force, speed, a, b, w[:, None])
    except ValueError as exc:
        _fail(exc)
    columns = [("water_flow_ul_s", "w [µl/s]", "g")] + [
        (f"adhesion_at_{c * 100:g}_percent", f"{c * 100:g} %", ".3f") for c in creep
    ]
    _emit(
        f"WILAC adhesion at Q = {normal_force:g} N, v = {speed:g} m/s",
        columns, [(wi, *row) for wi, row in zip(w, mu, strict=True)], fmt, out,
    )  # fmt: skip


def _tram_contact(normal_force: float):
    """Hertz semi-axes of the Pardubice tram rig (seed 000 §4): 0.696 m wheel on 0.905 m roller."""
    from railadhesion.contact.geometry import contact_semi_axes

    return contact_semi_axes("tram", normal_force)


def _load_wilac(path: Path | None):
    if path is None:
        return None
    from railadhesion.io.paramfiles import load_wilac_parameters

    try:
        return load_wilac_parameters(path)
    except OSError as exc:  # missing file, a folder, no permission: a user error, no traceback
        raise ValueError(f"--params: cannot read {path}: {exc.strerror or exc}") from exc


@params_app.command("list")
def params_list(
    kind: str = typer.Option(
        "all", help="Which sets: 'polach', 'wilac', 'fletcher' or 'all' (readable/JSON only)."
    ),
    fmt: str = _format_option(),
    out: Path | None = typer.Option(None, help="Write the table(s) here (.csv, .json or text)."),
) -> None:
    """List the named parameter sets: Polach sets, WILAC sets, Fletcher's conditions."""
    kinds = ("polach", "wilac", "fletcher")
    if kind not in (*kinds, "all"):
        _fail(f"--kind must be one of {[*kinds, 'all']}, got {kind!r}")
    chosen = kinds if kind == "all" else (kind,)
    as_format = fmt
    if out is not None and fmt == "table":
        as_format = {".csv": "csv", ".json": "json"}.get(out.suffix.lower(), "table")
    if as_format == "csv" and len(chosen) > 1:
        _fail("CSV holds one table: choose --kind polach, wilac or fletcher")
    tables = {k: _parameter_sets(k) for k in chosen}
    if as_format == "json" and len(chosen) > 1:
        text = json.dumps(
            {k: [dict(zip([c[0] for c in cols], [_plain(v) for v in row], strict=True))
                 for row in rows] for k, (_, cols, rows) in tables.items()},
            indent=1,
        ) + "\n"  # fmt: skip
        if out is None:
            console.print(text, end="", markup=False, highlight=False, soft_wrap=True)
        else:
            try:
                out.parent.mkdir(parents=True, exist_ok=True)
                out.write_text(text, encoding="utf-8")
            except OSError as exc:
                _fail(f"cannot write the table to {out}: {exc}")
            err_console.print(f"parameter sets: json written to {escape(str(out))}")
        return
    if as_format == "table" and out is not None and len(chosen) > 1:
        _fail("a text file holds one table: choose --kind, or write --format json")
    for title, cols, rows in tables.values():
        _emit(title, cols, rows, fmt, out)


def _parameter_sets(kind: str):
    """(title, columns, rows) of one kind of named parameter set."""
    if kind == "polach":
        from railadhesion.models.parameters import POLACH_PARAMETER_SETS

        cols = [("name", "name", ""), ("k_A", "k_A", "g"), ("k_S", "k_S", "g"),
                ("mu0", "mu0", "g"), ("A", "A", "g"), ("B_s_per_m", "B [s/m]", "g"),
                ("source", "source", "")]  # fmt: skip
        rows = [(n, p.k_A, p.k_S, p.mu0, p.A, p.B, p.source)
                for n, p in POLACH_PARAMETER_SETS.items()]  # fmt: skip
        return "Polach parameter sets", cols, rows
    if kind == "wilac":
        from railadhesion.models.wilac import default_wilac_parameters

        p = default_wilac_parameters()
        prov = p.provenance
        cols = [("name", "name", ""), ("normal_force_range_N", "Q range [N]", ""),
                ("speed_range_m_s", "v range [m/s]", ""),
                ("reconstruction", "reconstruction", ""), ("source", "source", "")]  # fmt: skip
        source = str(prov.get("source", ""))
        first = source.split(" by ")[0].split(". ")[0]  # the first clause, for the table
        rows = [(
            p.name or "default",
            f"{p.normal_force_range[0]:g}-{p.normal_force_range[1]:g}",
            f"{p.speed_range[0]:g}-{p.speed_range[1]:g}",
            "yes" if prov.get("reconstruction") else "no",
            first + (" (...; railadhesion params check FILE)" if first != source else ""),
        )]  # fmt: skip
        return "WILAC parameter sets: the built-in default (yours: --params FILE)", cols, rows
    from railadhesion.models.twod import FLETCHER_CONDITIONS

    cols = [("test_code", "code", ""), ("lubricant", "lubricant", ""),
            ("max_pressure_MPa", "p0 [MPa]", "g"), ("mu", "mu", "g"), ("k_a", "k_a", "g"),
            ("k_s", "k_s", "g")]  # fmt: skip
    rows = [(c.test_code, c.lubricant, c.max_pressure / 1e6, c.mu, c.k_a, c.k_s)
            for c in FLETCHER_CONDITIONS.values()]  # fmt: skip
    return "Fletcher 2013 conditions (Tables 1 and 2)", cols, rows


@params_app.command("check")
def params_check(path: Path = typer.Argument(..., help="A parameter file (TOML).")) -> None:
    """Validate a parameter file; print what it holds or exactly what is wrong."""
    from railadhesion.io.paramfiles import load_parameter_file
    from railadhesion.models.wilac import WilacParameters

    try:
        params = load_parameter_file(path)
    except (ValueError, OSError) as exc:
        _fail(exc)
    console.print(
        f"[green]ok[/green]: {escape(str(path))} holds {type(params).__name__} "
        f"{escape(repr(params.name))}"
    )
    if isinstance(params, WilacParameters):
        prov = dict(params.provenance)
        rec = prov.pop("reconstruction", None)
        flag = {True: "YES: a reconstruction, not measured data (read its provenance)",
                False: "no", None: "not stated"}[rec]  # fmt: skip
        lines = [
            f"reconstruction: {flag}",
            f"normal force range: {params.normal_force_range[0]:g} to "
            f"{params.normal_force_range[1]:g} N (Q_ref {params.normal_force_ref:g} N)",
            f"speed range: {params.speed_range[0]:g} to {params.speed_range[1]:g} m/s "
            f"(v_ref {params.speed_ref:g} m/s)",
        ]
        lines += [f"{key}: {value}" for key, value in prov.items()]
        for line in lines:
            console.print("  " + line, markup=False, highlight=False)
    else:
        for key in ("source", "notes"):
            value = getattr(params, key, "")
            if value:
                console.print(f"  {key}: {value}", markup=False, highlight=False)


@fit_app.command("polach")
def fit_polach_cmd(
    csv_file: Path = typer.Argument(..., metavar="CSV", help="Creep-curve CSV "
                                    "(docs/creep-curve-csv.md)."),
    fit: str = typer.Option("k_A,k_S,mu0,A,B", help="Parameters to fit, comma-separated."),
    fixed: str = typer.Option(
        "", help="Values of the parameters not fitted, e.g. 'A=0.4,B=0.3' (default: the "
        "model's A = 1, B = 0, k_A = k_S = 1: friction independent of slip velocity).",
    ),
    out: Path | None = typer.Option(None, help="Write the fitted set as a Polach TOML file."),
    figure: Path | None = typer.Option(None, help="Write the fit-vs-data figure here."),
    fmt: str = _format_option(),
    table: Path | None = typer.Option(None, help="Write the parameter table here."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Fit Polach parameters to one measured creep curve.

    Exit code 3 when the quality gate does not trust the fit (docs/checks.md), unless
    --allow-untrusted."""
    from railadhesion.calibration.fitting import POLACH_NAMES, fit_polach
    from railadhesion.io.creepcurves import read_creep_curve
    from railadhesion.io.paramfiles import save_polach_parameters

    try:
        curve = read_creep_curve(csv_file)
        curve.require("normal_force", "speed", "a", "b")
    except ValueError as exc:  # the message names the file
        _fail(exc)
    names = tuple(s.strip() for s in fit.split(",") if s.strip())
    initial = {}
    for item in (x.strip() for x in fixed.split(",") if x.strip()):
        key, sep, value = item.partition("=")
        try:
            initial[key.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep or key.strip() not in POLACH_NAMES:
            _fail(f"--fixed: expected NAME=VALUE with NAME in {list(POLACH_NAMES)}, got {item!r}")
        if key.strip() in names:
            _fail(f"--fixed: {key.strip()} is also in --fit; a parameter is fitted or fixed")
    try:
        result = fit_polach(
            curve.creep, curve.adhesion, normal_force=curve.normal_force, speed=curve.speed,
            a=curve.a, b=curve.b, fit=names, initial=initial or None, warn_untrusted=False,
        )  # fmt: skip
    except ValueError as exc:
        _fail(f"{csv_file}: {exc}")
    held = [n for n in POLACH_NAMES if n not in result.fitted]
    if fmt == "table" and table is None:
        console.print(str(result), highlight=False, markup=False, soft_wrap=True)
    else:
        _emit(
            f"Polach fit to {csv_file.name}",
            [("parameter", "parameter", ""), ("value", "value", ".6g"),
             ("stderr", "stderr", ".2g"), ("fitted", "fitted", "")],
            [(n, result.params[n], result.stderr.get(n, float("nan")),
              "yes" if n in result.fitted else "no (fixed)") for n in POLACH_NAMES],
            fmt, table,
        )  # fmt: skip
    if held:
        given = [n for n in held if n in initial]
        default = [n for n in held if n not in initial]
        parts = []
        if given:
            parts.append(", ".join(f"{n} = {result.params[n]:g}" for n in given) + " (--fixed)")
        if default:
            example = ",".join(f"{n}=..." for n in default)
            parts.append(
                ", ".join(f"{n} = {result.params[n]:g}" for n in default)
                + f" (model defaults; set them with --fixed {example})"
            )
        note("not fitted, held at " + "; ".join(parts))
    if figure is not None:
        from railadhesion.plotting import plot_fit

        _figure(figure, lambda: plot_fit(result, title=f"Polach fit to {csv_file.name}"))
    if out is not None:
        try:
            save_polach_parameters(result.as_polach_parameters(), out)
        except (OSError, ValueError) as exc:
            _fail(f"cannot write the parameter file {out}: {exc}")
        err_console.print(f"parameters written to {escape(str(out))}"
                          + (" (its notes say it is not trusted)" if result.warnings else ""))
    finish(result.warnings, allow=allow_untrusted, what="Polach fit")


@fit_app.command("wilac")
def fit_wilac_cmd(
    folder: Path = typer.Argument(..., help="Folder of creep-curve CSVs at several (Q, v, w)."),
    out: Path = typer.Option(Path("wilac.toml"), help="WILAC parameter file to write."),
    normal_force_range: str | None = typer.Option(
        None, help="Validity range of Q [N] as 'low,high' (default: span of the data)."
    ),
    speed_range: str | None = typer.Option(
        None, help="Validity range of v [m/s] as 'low,high' (default: span of the data)."
    ),
    name: str = typer.Option("", help="Name stored in the parameter file."),
    criterion: str = typer.Option(
        "cv", help="Term selection: 'cv' (leave-one-out cross-validation), 'aicc', 'bic' or "
        "'r2' (the paper's R² rule alone).",
    ),
    max_order: int = typer.Option(3, help="Largest number of factors in a regression term."),
    min_r2_gain: float = typer.Option(1e-4, help="Smallest R² gain for a term to enter."),
    max_terms: int | None = typer.Option(
        None, help="Most terms per regression (default: one per three curves of a condition)."
    ),
    min_curves: int = typer.Option(
        3, help="Conditions with fewer curves get constant parameters (the mean)."
    ),
    refine: bool = typer.Option(
        True, help="Refit each condition's regressions jointly to its measured adhesion."
    ),
    fmt: str = _format_option(),
    table: Path | None = typer.Option(None, help="Write the per-curve table here."),
    allow_untrusted: bool = allow_untrusted_option(),
) -> None:
    """Calibrate a complete WILAC parameter file from a folder of creep curves.

    Exit code 3 when the calibrated set cannot be trusted (docs/checks.md), unless
    --allow-untrusted."""
    from rich.progress import BarColumn, Progress, TextColumn

    from railadhesion.calibration.pipeline import calibrate_wilac_to_toml

    kwargs = {"name": name, "criterion": criterion, "max_order": max_order,
              "min_r2_gain": min_r2_gain, "max_terms": max_terms, "min_curves": min_curves,
              "refine": refine}  # fmt: skip
    for key, text in (("normal_force_range", normal_force_range), ("speed_range", speed_range)):
        if text is not None:
            values = _floats(text, "--" + key.replace("_", "-"))
            if values.size != 2:
                raise typer.BadParameter(f"--{key.replace('_', '-')}: expected 'low,high'")
            kwargs[key] = (float(values[0]), float(values[1]))
    labels = {"fit": "Polach fit per curve", "regress": "regressions per condition",
              "check": "check between the data"}  # fmt: skip
    progress = Progress(TextColumn("{task.description}"), BarColumn(),
                        TextColumn("{task.completed}/{task.total}"), console=err_console,
                        transient=True, disable=progress_disabled())  # fmt: skip
    tasks = {}

    def report(stage: str, done: int, total: int) -> None:
        if stage not in tasks:
            tasks[stage] = progress.add_task(labels.get(stage, stage), total=total)
        progress.update(tasks[stage], completed=done, total=total)

    try:
        with progress:
            calibration = calibrate_wilac_to_toml(folder, out, progress=report, **kwargs)
    except ValueError as exc:
        _fail(exc)
    except OSError as exc:  # the output file cannot be written
        _fail(f"cannot write the parameter file {out}: {exc}")
    if fmt == "table":  # the per-curve report, also when --table writes the table to a file
        console.print(calibration.summary(), highlight=False, markup=False, soft_wrap=True)
    if fmt != "table" or table is not None:
        rows = calibration.curve_table()
        keys = list(rows[0]) if rows else []
        _emit("WILAC calibration per curve", [(k, k, ".4g") for k in keys],
              [[r[k] for k in keys] for r in rows], fmt, table)  # fmt: skip
    err_console.print(f"WILAC parameters written to {escape(str(out))}")
    finish(calibration.warnings, allow=allow_untrusted, what="WILAC calibration")


# Commands of the other concerns, each in its own module.
from railadhesion import (  # noqa: E402
    cli_braking,
    cli_export,
    cli_identification,
    cli_monitor,
    cli_odometry,
    cli_sweeps,
    cli_wsp,
)

for _module in (cli_braking, cli_identification, cli_sweeps, cli_export, cli_wsp, cli_odometry,
                cli_monitor):
    _module.register(app)

if __name__ == "__main__":  # pragma: no cover
    app()
