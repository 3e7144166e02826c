"""``railadhesion export``: FMUs and creep-force tables for co-simulation and table-driven tools.

A thin shell over :mod:`railadhesion.export`. Creepages on the command line are in percent,
like the other commands; forces in N, speeds in m/s, water flow rates in µl/s.
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape

from railadhesion.cli_checks import OutputConsole, err_console, fail, warn

export_app = typer.Typer(
    no_args_is_help=True,
    help="Use the models from other tools: FMI 2.0 co-simulation FMUs and creep-force tables.",
)
console = OutputConsole()

_MODEL_HELP = "Creep-force model: wilac or polach."
_FMU_MODEL_HELP = ("Creep-force model: wilac, polach, or table (the table model of Kalker's exact "
                   "theory, with the friction of a Polach set).")
_PARAMS_HELP = "Parameter file (TOML, docs/parameter-files.md); embedded in the export."
_SET_HELP = "Named parameter set: Polach, see 'railadhesion params list'; WILAC, 'default'."
_NATIVE_HELP = (
    "--native (the default): the model compiled into the FMU (linux64 binary and its C and "
    "LLVM sources), no Python on the host; needs Linux x86-64 and a C compiler here, else "
    "the Python FMU is written instead (said), or with an explicit --native an error. "
    "--python: the Python FMU (pythonfmu; the host needs Python with railadhesion)."
)


def _fail(message) -> None:
    """``error: ...`` on standard error, exit code 2."""
    fail(message)


def _floats(text: str | None, name: str, scale: float = 1.0):
    if text is None:
        return None
    try:
        values = [float(x) * scale for x in text.split(",") if x.strip()]
    except ValueError:
        _fail(f"{name}: expected numbers separated by commas, got {text!r}")
    if not values:
        _fail(f"{name}: expected at least one number")
    return values


def _creep_percent(text: str | None, name: str):
    """Creepages given in percent, as fractions: |creep| <= 100 % (a locked wheel is 100 %),
    as ``railadhesion polach --creep-percent``."""
    values = _floats(text, name)
    if values is not None and any(not abs(v) <= 100.0 for v in values):
        _fail(f"{name}: creepages must be in [-100, 100] % (a locked wheel is 100 %), got "
              f"{text!r}")  # fmt: skip
    return None if values is None else [v * 0.01 for v in values]


@export_app.command("fmu")
def export_fmu(
    model: str = typer.Option("wilac", help=_FMU_MODEL_HELP),
    params: Path | None = typer.Option(None, "--params", help=_PARAMS_HELP),
    parameter_set: str | None = typer.Option(None, "--set", help=_SET_HELP),
    out: Path = typer.Option(Path("creepforce.fmu"), help="The FMU file to write (.fmu)."),
    shear_modulus: float = typer.Option(8.2e10, help="Start value of parameter G [Pa]."),
    poisson: float = typer.Option(0.28, help="Start value of Poisson's ratio [-]."),
    native: bool | None = typer.Option(None, "--native/--python", help=_NATIVE_HELP),
    friction: str | None = typer.Option(
        None, help="Table model: 'falling' (the set's mu0, A, B; default) or 'coulomb' (its "
                   "mu0).",
    ),  # fmt: skip
) -> None:
    """Write an FMI 2.0 co-simulation FMU of a creep-force law: native by default (no Python
    on the host), --python for the Python FMU (pythonfmu)."""
    from railadhesion.export import (
        build_creep_force_fmu,
        build_native_creep_force_fmu,
        resolve_parameters,
    )
    from railadhesion.export.native_creepforce import NATIVE_MODELS

    try:
        resolved = resolve_parameters(model, params, parameter_set)
    except ValueError as exc:
        _fail(exc)
    if model not in NATIVE_MODELS and native is not False:
        served = f"the native creep-force FMU offers {', '.join(NATIVE_MODELS)}"
        if native:
            _fail(f"--native: {served}; export the {model} model as the Python FMU (--python)")
        console.print(f"{served}: writing the {model} model as the Python FMU")
        native = False
    extra = {} if friction is None else {"friction": friction}
    path, native = _write_either(native, build_native_creep_force_fmu, build_creep_force_fmu,
                                 out, model, params, parameter_set=parameter_set,
                                 shear_modulus=shear_modulus, poisson=poisson,
                                 **extra)  # fmt: skip
    console.print(escape(f"{model}: {resolved.summary()}"))
    _say_kind(native)
    _check_fmu(path, required=False)


@export_app.command("braking-fmu")
def export_braking_fmu(
    scenario: Path = typer.Argument(..., help="Braking scenario TOML (docs/braking.md)."),
    out: Path = typer.Option(Path("braking.fmu"), help="The FMU file to write (.fmu)."),
    native: bool | None = typer.Option(None, "--native/--python", help=_NATIVE_HELP),
    wsp: bool = typer.Option(
        False, "--wsp",
        help="Run the package's WSP inside the FMU (the scenario's [wsp] settings, ideal "
             "sensors): the valve states become outputs.",
    ),  # fmt: skip
) -> None:
    """Write the braking vehicle of SCENARIO as an FMI 2.0 co-simulation FMU (inputs: commanded
    pressure and WSP valve per axle, or with --wsp the pressure only): native by default (no
    Python on the host), --python for the Python FMU."""
    from railadhesion.export import build_braking_fmu, build_native_braking_fmu

    path, native = _write_either(native, build_native_braking_fmu, build_braking_fmu, out,
                                 scenario, wsp=wsp)  # fmt: skip
    if wsp:
        console.print("built-in WSP inside the FMU: valve_k are outputs")
    _say_kind(native)
    _check_fmu(path, required=True)



def _write_either(native, native_build, python_build, out, *args, **kwargs):
    """The native FMU (``native`` True: an error if it cannot be built), the Python FMU
    (False), or by default (None) the native FMU, falling back to the Python FMU, with a
    message saying why, where this machine cannot build one. Returns (path, native?)."""
    from railadhesion.export import NativeBuildError
    from railadhesion.export.native import native_unavailable

    if native is None:
        problem = native_unavailable()
        if problem is None:
            try:
                return _write_fmu(native_build, out, *args, fallback=True, **kwargs), True
            except NativeBuildError as exc:
                problem = str(exc)
        warn(f"no native FMU: {problem}")
        err_console.print("writing the Python FMU instead: the host needs Python with "
                          "railadhesion (--python asks for it, --native makes this an error)",
                          highlight=False, soft_wrap=True)  # fmt: skip
        native = False
    build = native_build if native else python_build
    return _write_fmu(build, out, *args, **kwargs), native


def _say_kind(native: bool) -> None:
    if native:
        console.print("native FMU: binaries/linux64 needs no Python on the host; sources in "
                      "sources/ (docs/fmu.md)")  # fmt: skip
    else:
        console.print("Python FMU: the host needs a Python with railadhesion installed "
                      "(docs/fmu.md)")  # fmt: skip


def _write_fmu(build, out, *args, fallback=False, **kwargs):
    """``build(out, *args, **kwargs)`` (an FMU builder); its errors become a red message and
    exit code 2 (``fallback``: a NativeBuildError is raised for the caller to fall back);
    says where the FMU was written and returns its path."""
    from railadhesion.export import NativeBuildError

    try:
        path = build(out, *args, **kwargs)
    except NativeBuildError as exc:
        if fallback:
            raise
        _fail(f"no native FMU: {exc}")
    except ValueError as exc:
        _fail(exc)
    except OSError as exc:
        _fail(f"cannot write {out}: {exc.strerror or exc}")
    console.print(f"FMU written to {escape(str(path))}")
    return path


def _check_fmu(path, *, required: bool) -> None:
    """Validate the FMU at ``path`` with FMPy (fail on a problem); without FMPy, an error if
    ``required``, else nothing."""
    try:
        from fmpy.validation import validate_fmu
    except ImportError:  # pragma: no cover - fmpy is optional at run time
        if required:
            raise
        return
    problems = validate_fmu(str(path))
    if problems:
        _fail("the FMU does not pass FMPy's validation: " + "; ".join(problems))
    console.print("modelDescription.xml passes FMPy's validation")


@export_app.command("table")
def export_table(
    model: str = typer.Option("wilac", help=_MODEL_HELP),
    params: Path | None = typer.Option(None, "--params", help=_PARAMS_HELP),
    parameter_set: str | None = typer.Option(None, "--set", help=_SET_HELP),
    out: Path = typer.Option(Path("creepforce_table.nc"), help="NetCDF file to write."),
    csv: Path | None = typer.Option(
        None, help="CSV file to write (default: OUT with suffix .csv)."
    ),
    no_csv: bool = typer.Option(False, "--no-csv", help="Write the NetCDF file only."),
    creep_long_percent: str | None = typer.Option(
        None, help="Longitudinal creepage grid [%], comma-separated (default: 39 values)."
    ),
    creep_lat_percent: str | None = typer.Option(
        None, help="Lateral creepage grid [%], comma-separated (default: 23 values)."
    ),
    normal_force: str | None = typer.Option(None, help="Normal force grid [N]."),
    speed: str | None = typer.Option(None, help="Rolling speed grid [m/s]."),
    water: str | None = typer.Option(None, help="Water flow grid [µl/s] (WILAC)."),
    spin: float = typer.Option(0.0, help="Spin creepage of the whole table [rad/m]."),
    wheel_radius: float = typer.Option(0.625, help="Wheel rolling radius for Hertz [m]."),
    rail_lateral_radius: float = typer.Option(0.3, help="Rail head radius for Hertz [m]."),
    digits: int = typer.Option(12, help="Significant digits in the CSV (17: exact)."),
) -> None:
    """Evaluate a model on a grid; write NetCDF and CSV; report the interpolation error."""
    from railadhesion.export import (
        DEFAULT_GRID,
        creep_force_table,
        write_table_csv,
        write_table_netcdf,
    )

    grid = {
        "creep_long": _creep_percent(creep_long_percent, "--creep-long-percent"),
        "creep_lat": _creep_percent(creep_lat_percent, "--creep-lat-percent"),
        "normal_force": _floats(normal_force, "--normal-force"),
        "speed": _floats(speed, "--speed"),
        "water_flow": _floats(water, "--water"),
    }
    grid = {k: DEFAULT_GRID[k] if v is None else v for k, v in grid.items()}
    csv_path = None if no_csv else (csv or out.with_suffix(".csv"))
    try:
        table = creep_force_table(
            model, params, parameter_set=parameter_set, spin=spin, wheel_radius=wheel_radius,
            rail_lateral_radius=rail_lateral_radius, **grid,
        )  # fmt: skip
        write_table_netcdf(table, out)
        if csv_path is not None:
            write_table_csv(table, csv_path, digits=digits)
    except ValueError as exc:
        _fail(exc)
    except OSError as exc:
        _fail(f"cannot write the table: {exc.strerror or exc}")
    sizes = " x ".join(f"{d} {n}" for d, n in table["Fx"].sizes.items())
    a = table.attrs
    console.print(escape(f"{model} table, parameter set '{a['parameter_set']}': {sizes} "
                         f"= {table['Fx'].size} points, spin {spin:g} rad/m"))  # fmt: skip
    err = {k: a[f"interpolation_{k}"] for k in (
        "max_error_Fx_over_Q", "rms_error_Fx_over_Q", "max_error_Fy_over_Q", "rms_error_Fy_over_Q"
    )}  # fmt: skip
    console.print(
        escape(
            f"interpolation error at {a['interpolation_check_points']} cell midpoints "
            f"(multilinear vs model, |error|/Q): Fx max {err['max_error_Fx_over_Q']:.3g} "
            f"RMS {err['rms_error_Fx_over_Q']:.3g}; Fy max {err['max_error_Fy_over_Q']:.3g} "
            f"RMS {err['rms_error_Fy_over_Q']:.3g}"
        )
    )
    per_axis = [
        f"{k[len('interpolation_max_error_over_Q_'):-len('_only')]} {v:.3g}"
        for k, v in a.items()
        if k.endswith("_only")
    ]
    console.print(escape("max error with one axis at midpoints: " + ", ".join(per_axis)))
    console.print(f"NetCDF written to {escape(str(out))}")
    if csv_path is not None:
        console.print(
            f"CSV written to {escape(str(csv_path))} (layout: docs/creep-force-tables.md)"
        )


def register(app: typer.Typer) -> None:
    """Add the ``export`` command group to the main CLI."""
    app.add_typer(export_app, name="export")
