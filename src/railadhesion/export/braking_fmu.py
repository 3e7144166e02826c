"""The braking-vehicle FMU: the braking simulator's stepping API as an FMI 2.0 co-simulation FMU.

The shape a WSP hardware-in-the-loop rig or a train-level simulator connects to: inputs are the
commanded brake-cylinder pressure and the WSP valve state of every axle, outputs the wheel
speeds, the train speed and distance, the cylinder pressures and the creep forces. The vehicle,
the brake cylinders, the adhesion model and the track (water-flow sections) come from a
braking scenario file (``docs/braking.md``), embedded in the FMU with its provenance.
"""

from __future__ import annotations

import hashlib
import html
import json
import tempfile
from pathlib import Path
from xml.etree import ElementTree as ET

from railadhesion.export.fmu import (
    RUNS_PYTHON,
    FmuVariable,
    build_fmu,
    documentation_page,
    variables_table,
)
from railadhesion.export.slave import CONFIG_FILE

__all__ = [
    "braking_description",
    "braking_documentation",
    "braking_fmu_variables",
    "build_braking_fmu",
    "load_scenario_alone",
    "scenario_file",
    "valve_control_text",
]

_SCENARIO_FILE = "scenario.toml"


def braking_fmu_variables(n_axles: int, wsp: bool = False) -> list[FmuVariable]:
    """The variables of a braking FMU with ``n_axles`` axles (axle 1 leading).

    ``wsp=True``: the FMU runs the package's built-in WSP, and ``valve_k`` is an output (the
    valve state the WSP chose) instead of an input; the other variables are the same."""
    variables = []
    for k in range(1, n_axles + 1):
        variables.append(
            FmuVariable(f"pressure_command_{k}", "input", "Pa",
                        f"commanded brake-cylinder pressure of axle {k} (the cylinder "
                        "limits it to its maximum)", 0.0, 0.0))  # fmt: skip
        if not wsp:
            variables.append(
                FmuVariable(f"valve_{k}", "input", "1",
                            f"WSP valve state of axle {k}: 0 apply, 1 hold, 2 vent (rounded)",
                            0.0, 0.0, 2.0))  # fmt: skip
    variables += [
        FmuVariable("train_speed", "output", "m/s", "train speed"),
        FmuVariable("distance", "output", "m", "distance run since the start"),
        FmuVariable("deceleration", "output", "m/s2", "train deceleration (braking > 0)"),
        FmuVariable("stopped", "output", "1", "1 once the train has stopped, else 0"),
    ]
    for k in range(1, n_axles + 1):
        variables += [
            FmuVariable(f"wheel_speed_{k}", "output", "rad/s", f"angular speed of wheelset {k}"),
            FmuVariable(f"brake_pressure_{k}", "output", "Pa",
                        f"brake-cylinder pressure of axle {k}"),
            FmuVariable(f"creep_force_{k}", "output", "N",
                        f"longitudinal creep force of axle {k} (rail on wheelset, retarding "
                        "when braking)"),
            FmuVariable(f"adhesion_used_{k}", "output", "1",
                        f"adhesion used by axle {k}: creep force / normal load"),
            FmuVariable(f"normal_load_{k}", "output", "N",
                        f"normal load of axle {k} (with pitch load transfer)"),
        ]  # fmt: skip
        if wsp:
            variables.append(
                FmuVariable(f"valve_{k}", "output", "1",
                            f"valve state of axle {k} chosen by the built-in WSP: 0 apply, "
                            "1 hold, 2 vent"))  # fmt: skip
    return variables


def valve_control_text(wsp: bool, own: bool) -> str:
    """What commands the valves (the FMU description's words): the master (inputs), or the
    built-in WSP with the scenario's settings (``own``) or the default ones."""
    if not wsp:
        return "inputs: commanded cylinder pressure and WSP valve per axle"
    settings = "the scenario's [wsp] settings" if own else "the default WSP settings"
    return ("input: commanded cylinder pressure per axle; the built-in WSP "
            f"({settings}, ideal sensors) sets the valves (outputs)")


def scenario_file(scenario) -> Path:
    """``scenario`` (str or os.PathLike) as a path; ValueError unless it is an existing file."""
    path = Path(scenario)
    if not path.is_file():
        raise ValueError(f"scenario must be an existing TOML file, got {str(path)!r}")
    return path


def load_scenario_alone(path: Path):
    """The text of the scenario file ``path`` and the scenario loaded from a copy of it alone,
    as the FMU holds it; ValueError if the copy does not load (a file it names by a relative
    path)."""
    from railadhesion.braking.scenario import load_scenario

    text = path.read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as tmp:  # the copy must load on its own, as in the FMU
        copy = Path(tmp) / _SCENARIO_FILE
        copy.write_text(text, encoding="utf-8")
        try:
            loaded = load_scenario(copy)
        except ValueError as exc:
            raise ValueError(
                f"scenario {str(path)!r} does not load on its own (files it names must be "
                f"built-in names or absolute paths): {exc}"
            ) from exc
    return text, loaded


def braking_description(loaded, wsp: bool, where: str) -> str:
    """The ``description`` of a braking FMU of the scenario ``loaded``: the vehicle, the
    scenario, what commands the valves, then ``where`` (where the FMU holds the scenario)."""
    import railadhesion

    vehicle = loaded.vehicle
    return (
        f"railadhesion {railadhesion.__version__}: braking vehicle '{vehicle.name}' "
        f"({vehicle.n_axles} axles) from scenario '{loaded.name}', initial speed "
        f"{loaded.initial_speed:g} m/s; {valve_control_text(wsp, loaded.wsp is not None)}. "
        f"{where}"
    )


def braking_documentation(description, variables, text, *, native: bool) -> str:
    """``documentation/index.html`` of a braking FMU: description, the variables and the
    scenario's ``text``; the Python FMU also says what its host needs."""
    esc = html.escape
    runs = "" if native else f"<p>{RUNS_PYTHON}</p>\n"
    return documentation_page(
        "Braking-vehicle FMU (native)" if native else "Braking-vehicle FMU",
        f"<p>{esc(description)}</p>\n{runs}{variables_table(variables)}\n"
        f"<h2>Scenario</h2>\n<pre>{esc(text)}</pre>\n",
        heading="Braking-vehicle FMU (railadhesion, native)" if native else None,
    )


def build_braking_fmu(out, scenario, *, wsp: bool = False) -> Path:
    """Write an FMI 2.0 co-simulation FMU of a braking vehicle (the stepping API).

    Parameters
    ----------
    out : str or os.PathLike
        The ``.fmu`` file to write.
    scenario : str or os.PathLike
        A braking scenario TOML file (``docs/braking.md``). Its vehicle, initial speed, brake
        cylinders, adhesion model, track and gradient are used; its brake demand and WSP
        settings are not (the co-simulation master commands pressures and valves). It is
        embedded verbatim as ``resources/scenario.toml``, so the files it names must be
        built-in names (``coach_default``, the ``default`` WILAC set) or absolute paths on
        the host.
    wsp : bool
        Run the package's WSP controller (the scenario's ``[wsp]`` settings, or the defaults
        of :class:`~railadhesion.braking.wsp.WSPSettings` if it has none) with ideal sensors
        inside the FMU: the valve states become outputs
        (:func:`braking_fmu_variables` with ``wsp=True``), as in the native braking FMU.

    Returns
    -------
    pathlib.Path
        The path of the braking FMU written (``out``): FMI 2.0 co-simulation, Python inside.

    Notes
    -----
    Each ``doStep(t, h)`` calls :meth:`railadhesion.braking.BrakingSimulator.step` with ``h``
    and the current inputs, so the FMU's outputs equal the stepping API's (tested to 1e-12
    under FMPy). Like the creep-force FMU it runs Python: the host needs a Python interpreter
    with ``railadhesion`` installed.
    """
    import railadhesion

    text, loaded = load_scenario_alone(scenario_file(scenario))
    vehicle = loaded.vehicle
    variables = braking_fmu_variables(vehicle.n_axles, wsp=wsp)
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    description = braking_description(
        loaded, wsp, f"Scenario embedded as resources/{_SCENARIO_FILE} (sha256 {sha[:12]}...)."
    )
    config = {
        "scenario_file": _SCENARIO_FILE,
        "railadhesion_version": railadhesion.__version__,
        "description": description,
        "fmu_version": f"railadhesion {railadhesion.__version__}, scenario {sha[:12]}",
        "variables": [v.to_config() for v in variables],
        "wsp": bool(wsp),
    }
    meta = ET.Element("Scenario", {"name": loaded.name, "file": f"resources/{_SCENARIO_FILE}",
                                   "sha256": sha, "railadhesionVersion": railadhesion.__version__})
    prov = ET.SubElement(meta, "VehicleProvenance")
    for key, value in dict(vehicle.provenance).items():
        prov.set(str(key), str(value))
    documentation = braking_documentation(description, variables, text, native=False)
    return build_fmu(
        Path(__file__).with_name("railadhesion_braking.py"),
        variables,
        out,
        resources={CONFIG_FILE: json.dumps(config, indent=2), _SCENARIO_FILE: text},
        documentation=documentation,
        metadata=meta,
    )
