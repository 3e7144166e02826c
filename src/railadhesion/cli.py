"""Command-line interface: a thin shell over the public Python API.

Every command calls public functions that are also usable from Python; the CLI adds parsing
and printing only. Creepages on the command line are given in percent (``--creep-percent``),
water flow rates in µl/s, forces in N, speeds in m/s, lengths in m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

app = typer.Typer(
    no_args_is_help=True,
    add_completion=False,
    help="Wheel-rail adhesion: contact mechanics, creep-force models (Polach, WILAC, Fletcher), "
    "calibration. Units: SI; creep in percent on the command line; water flow in µl/s.",
)
wilac_app = typer.Typer(no_args_is_help=True, help="WILAC water-induced low adhesion model.")
params_app = typer.Typer(no_args_is_help=True, help="Named parameter sets and parameter files.")
fit_app = typer.Typer(no_args_is_help=True, help="Fit model parameters to measured creep curves.")
app.add_typer(wilac_app, name="wilac")
app.add_typer(params_app, name="params")
app.add_typer(fit_app, name="fit")

console = Console()

# Locomotive-scale default contact (CONTACT's Eurosprinter example: 625 mm wheel radius,
# Q = 106.7 kN; MODELS.md §3) is computed with Hertz from these radii.
_LOCO = {"wheel_radius": 0.625, "wheel_lateral_radius": np.inf, "rail_lateral_radius": 0.3}


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


def _fail(exc: Exception) -> None:
    # escape(): messages hold brackets ("[low, high]", "[0, inf)") that Rich would otherwise
    # take for markup and drop from the output.
    console.print(f"[red]error:[/red] {escape(str(exc))}")
    raise typer.Exit(code=2)


def _save(fig, out: Path | None) -> None:
    if out is None:
        return
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=110, bbox_inches="tight")
    except (OSError, ValueError) as exc:  # unwritable folder, unknown image format
        _fail(f"cannot write the figure to {out}: {exc}")
    console.print(f"figure written to {escape(str(out))}")


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
    table = Table(title="Hertz contact")
    table.add_column("quantity")
    table.add_column("value", justify="right")
    for label, value in [
        ("a (rolling direction) [mm]", h.a * 1e3),
        ("b (lateral) [mm]", h.b * 1e3),
        ("a/b", h.a_over_b),
        ("max pressure p0 [MPa]", h.max_pressure / 1e6),
        ("approach [µm]", h.approach * 1e6),
        ("curvature A [1/m]", h.curvature_A),
        ("curvature B [1/m]", h.curvature_B),
    ]:
        table.add_row(escape(label), f"{float(value):.4g}")
    console.print(table)


@app.command()
def polach(
    parameter_set: str = typer.Option("polach2005_dry", "--set", help="Named Polach set."),
    creep_percent: str = typer.Option(
        "0.1,0.2,0.5,1,2,5,10,20,40", help="Longitudinal creepages [%], comma-separated."
    ),
    normal_force: float = typer.Option(110e3, help="Normal force Q [N]."),
    speed: float = typer.Option(10.0, help="Rolling speed V [m/s]."),
    out: Path | None = typer.Option(None, help="Write a creep-curve figure here."),
) -> None:
    """Polach creep curve (adhesion against longitudinal creep) for a named parameter set."""
    from railadhesion import adhesion
    from railadhesion.contact.hertz import hertz_3d
    from railadhesion.models.parameters import polach_parameters
    from railadhesion.models.polach import Polach

    try:
        params = polach_parameters(parameter_set)
        creep = _floats(creep_percent, "--creep-percent") / 100
        h = hertz_3d(normal_force, **_LOCO)
        fx, fy = Polach(params).forces(creep, 0.0, 0.0, normal_force, speed, h.a, h.b)
    except ValueError as exc:
        _fail(exc)
    mu = adhesion(fx, fy, normal_force)
    title = f"Polach '{params.name}' at Q = {normal_force:g} N, V = {speed:g} m/s"
    table = Table(title=escape(title))
    table.add_column(escape("creep [%]"), justify="right")
    table.add_column(escape("Fx [kN]"), justify="right")
    table.add_column(escape("adhesion |T|/Q"), justify="right")
    for c, f, m in zip(creep, np.atleast_1d(fx), np.atleast_1d(mu), strict=True):
        table.add_row(f"{c * 100:g}", f"{f / 1e3:.2f}", f"{m:.4f}")
    console.print(table)
    if out is not None:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(creep * 100, mu, marker="o")
        ax.set_xlabel("longitudinal creep [%]")
        ax.set_ylabel("adhesion |T|/Q [-]")
        ax.set_title(f"Polach {params.name}")
        ax.grid(True, alpha=0.3)
        _save(fig, out)


@wilac_app.command("curves")
def wilac_curves(
    water: str = typer.Option("0,25,35,60,350", help="Water flow rates [µl/s], comma-separated."),
    normal_force: float = typer.Option(4200.0, help="Normal force Q [N] (tram rig: 4.2 kN)."),
    speed: float = typer.Option(5.0, help="Rolling speed [m/s] (tram rig: 5 m/s)."),
    params_file: Path | None = typer.Option(None, "--params", help="WILAC TOML file."),
    out: Path = typer.Option(Path("wilac_curves.png"), help="Figure file."),
) -> None:
    """Creep curves at several water flow rates (paper Fig. 7)."""
    from railadhesion.plotting import plot_wilac_curves

    try:
        fig = plot_wilac_curves(
            water_flows=tuple(_floats(water, "--water")), normal_force=normal_force, speed=speed,
            params=_load_wilac(params_file),
        )
    except ValueError as exc:
        _fail(exc)
    _save(fig, out)


@wilac_app.command("weights")
def wilac_weights_cmd(
    params_file: Path | None = typer.Option(None, "--params", help="WILAC TOML file."),
    out: Path = typer.Option(Path("wilac_weights.png"), help="Figure file."),
) -> None:
    """Blending weights f_i(w) and transitions e_i(w) (paper Figs. 5 and 6)."""
    from railadhesion.plotting import plot_wilac_weights

    try:
        fig = plot_wilac_weights(params=_load_wilac(params_file))
    except ValueError as exc:
        _fail(exc)
    _save(fig, out)


@wilac_app.command("water")
def wilac_water(
    creep_percent: str = typer.Option("3,10,30,60", help="Fixed creepages [%], comma-separated."),
    normal_force: float = typer.Option(4200.0, help="Normal force Q [N]."),
    speed: float = typer.Option(5.0, help="Rolling speed [m/s]."),
    params_file: Path | None = typer.Option(None, "--params", help="WILAC TOML file."),
    out: Path = typer.Option(Path("wilac_water.png"), help="Figure file."),
) -> None:
    """Adhesion against water flow rate at fixed creepages (paper Fig. 8)."""
    from railadhesion.plotting import plot_wilac_water

    try:
        fig = plot_wilac_water(
            creeps=tuple(_floats(creep_percent, "--creep-percent") / 100),
            normal_force=normal_force, speed=speed, params=_load_wilac(params_file),
        )
    except ValueError as exc:
        _fail(exc)
    _save(fig, out)


@wilac_app.command("speeds")
def wilac_speeds(
    speeds: str = typer.Option("5,10,20", help="Rolling speeds [m/s], comma-separated."),
    water: float = typer.Option(0.0, help="Water flow rate [µl/s]."),
    normal_force: float = typer.Option(110e3, help="Normal force Q [N] (locomotive: 110 kN)."),
    params_file: Path | None = typer.Option(None, "--params", help="WILAC TOML file."),
    out: Path = typer.Option(Path("wilac_speeds.png"), help="Figure file."),
) -> None:
    """Creep curves at several speeds (paper Figs. 9 and 11)."""
    from railadhesion.plotting import plot_wilac_speeds

    try:
        fig = plot_wilac_speeds(
            speeds=tuple(_floats(speeds, "--speeds")), water_flow=water,
            normal_force=normal_force, params=_load_wilac(params_file),
        )
    except ValueError as exc:
        _fail(exc)
    _save(fig, out)


@wilac_app.command("table")
def wilac_table(
    water: str = typer.Option("0,25,35,60,350", help="Water flow rates [µl/s]."),
    creep_percent: str = typer.Option("1,3,10,30,60,90", help="Creepages [%] (braking sign)."),
    normal_force: float = typer.Option(4200.0, help="Normal force Q [N]."),
    speed: float = typer.Option(5.0, help="Rolling speed [m/s]."),
    params_file: Path | None = typer.Option(None, "--params", help="WILAC TOML file."),
) -> None:
    """Print WILAC adhesion |T|/Q over water flow rate and creep at the tram-rig contact."""
    from railadhesion.models.wilac import Wilac

    try:
        w = _floats(water, "--water")
        creep = _floats(creep_percent, "--creep-percent") / 100
        a, b = _tram_contact(normal_force)
        model = Wilac(_load_wilac(params_file))
        mu = model.adhesion(creep[None, :], 0.0, 0.0, normal_force, speed, a, b, w[:, None])
    except ValueError as exc:
        _fail(exc)
    table = Table(title=f"WILAC adhesion at Q = {normal_force:g} N, v = {speed:g} m/s")
    table.add_column(escape("w [µl/s]"), justify="right")
    for c in creep:
        table.add_column(escape(f"{c * 100:g} %"), justify="right")
    for wi, row in zip(w, mu, strict=True):
        table.add_row(f"{wi:g}", *[f"{x:.3f}" for x in row])
    console.print(table)


def _tram_contact(normal_force: float):
    """Hertz semi-axes of the Pardubice tram rig (seed 000 §4): 0.696 m wheel on 0.905 m roller."""
    from railadhesion.plotting import contact_semi_axes

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
def params_list() -> None:
    """List the named Polach parameter sets, their values and sources."""
    from railadhesion.models.parameters import POLACH_PARAMETER_SETS

    table = Table(title="Polach parameter sets")
    for col in ("name", "k_A", "k_S", "mu0", "A", "B [s/m]", "source"):
        table.add_column(escape(col))
    for name, p in POLACH_PARAMETER_SETS.items():
        table.add_row(
            name, f"{p.k_A:g}", f"{p.k_S:g}", f"{p.mu0:g}", f"{p.A:g}", f"{p.B:g}", p.source
        )
    console.print(table)


@params_app.command("check")
def params_check(path: Path = typer.Argument(..., help="A parameter file (TOML).")) -> None:
    """Validate a parameter file; print what it holds or exactly what is wrong."""
    from railadhesion.io.paramfiles import load_parameter_file

    try:
        params = load_parameter_file(path)
    except (ValueError, OSError) as exc:
        _fail(exc)
    console.print(
        f"[green]ok[/green]: {escape(str(path))} holds {type(params).__name__} "
        f"{escape(repr(params.name))}"
    )


@fit_app.command("polach")
def fit_polach_cmd(
    csv: Path = typer.Argument(..., help="Creep-curve CSV (docs/creep-curve-csv.md)."),
    fit: str = typer.Option("k_A,k_S,mu0,A,B", help="Parameters to fit, comma-separated."),
    out: Path | None = typer.Option(None, help="Write the fitted set as a Polach TOML file."),
) -> None:
    """Fit Polach parameters to one measured creep curve."""
    from railadhesion.calibration.fitting import fit_polach
    from railadhesion.io.creepcurves import read_creep_curve
    from railadhesion.io.paramfiles import save_polach_parameters

    try:
        curve = read_creep_curve(csv)
        curve.require("normal_force", "speed", "a", "b")
    except ValueError as exc:  # the message names the file
        _fail(exc)
    try:
        result = fit_polach(
            curve.creep, curve.adhesion, normal_force=curve.normal_force, speed=curve.speed,
            a=curve.a, b=curve.b, fit=tuple(s.strip() for s in fit.split(",") if s.strip()),
        )
    except ValueError as exc:
        _fail(f"{csv}: {exc}")
    console.print(str(result), highlight=False, markup=False)
    if out is not None:
        try:
            save_polach_parameters(result.as_polach_parameters(), out)
        except (OSError, ValueError) as exc:
            _fail(f"cannot write the parameter file {out}: {exc}")
        console.print(f"parameters written to {escape(str(out))}")


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
) -> None:
    """Calibrate a complete WILAC parameter file from a folder of creep curves."""
    from railadhesion.calibration.pipeline import calibrate_wilac_to_toml

    kwargs = {"name": name}
    for key, text in (("normal_force_range", normal_force_range), ("speed_range", speed_range)):
        if text is not None:
            values = _floats(text, "--" + key.replace("_", "-"))
            if values.size != 2:
                raise typer.BadParameter(f"--{key.replace('_', '-')}: expected 'low,high'")
            kwargs[key] = (float(values[0]), float(values[1]))
    try:
        calibration = calibrate_wilac_to_toml(folder, out, **kwargs)
    except ValueError as exc:
        _fail(exc)
    except OSError as exc:  # the output file cannot be written
        _fail(f"cannot write the parameter file {out}: {exc}")
    console.print(calibration.summary(), highlight=False, markup=False)
    console.print(f"WILAC parameters written to {escape(str(out))}")


if __name__ == "__main__":  # pragma: no cover
    app()


from railadhesion.cli_braking import register as _register_braking  # noqa: E402

_register_braking(app)

from railadhesion.cli_identification import register as _register_identification  # noqa: E402

_register_identification(app)
