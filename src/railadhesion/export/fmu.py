"""FMI 2.0 co-simulation FMUs of the package's models, built with pythonfmu.

The FMU binary shipped by pythonfmu runs the slave class (a Python file stored in the FMU's
``resources/``) in the host's Python interpreter: the machine that runs the FMU needs a Python
with ``railadhesion`` (and its dependencies) installed. See ``docs/fmu.md`` for what the FMU
holds and what its host needs, and the gallery example "A creep-force FMU, run from FMPy"
(``examples/gallery/plot_fmu_fmpy.py``) for a worked FMPy run.

The module is split in two layers so that further FMUs (e.g. a braking vehicle) can be added:

* generic: :class:`FmuVariable` (name, causality, unit, description, start, bounds),
  :data:`UNIT_DEFINITIONS` and :func:`build_fmu`, which builds an FMU from a slave script, a
  variable list and resource files, then completes the ``modelDescription.xml`` that pythonfmu
  writes (units and ``UnitDefinitions``, bounds, ``InitialUnknowns``, vendor metadata);
* per FMU: :func:`build_creep_force_fmu` and its variable list
  :func:`creep_force_variables`, slave ``railadhesion_creepforce.py``.
"""

from __future__ import annotations

import contextlib
import hashlib
import html
import json
import math
import shutil
import sys
import tempfile
import zipfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

from railadhesion.export.slave import CONFIG_FILE
from railadhesion.plausibility import check_plausible

__all__ = [
    "FMU_MODELS",
    "UNIT_DEFINITIONS",
    "FmuVariable",
    "ResolvedParameters",
    "build_creep_force_fmu",
    "build_fmu",
    "check_friction",
    "creep_force_documentation",
    "creep_force_variables",
    "documentation_page",
    "resolve_parameters",
    "table_friction_text",
    "unit_definitions",
    "variables_table",
]

#: Models the creep-force FMU can wrap (``"table"``: the table model of Kalker's exact theory
#: with the friction of a Polach set; Python FMU only).
FMU_MODELS = ("wilac", "polach", "table")
#: Friction laws of the table model's FMU: the set's falling friction or Coulomb's (its mu0).
TABLE_FRICTION = ("falling", "coulomb")

#: FMI 2.0 unit definitions used by the FMUs: unit name -> BaseUnit attributes (SI exponents,
#: optional factor). Water flow is in µl/s as everywhere in the package (spelt ``ul/s``).
UNIT_DEFINITIONS: dict[str, dict[str, str]] = {
    "1": {},
    "s": {"s": "1"},
    "m": {"m": "1"},
    "m/s": {"m": "1", "s": "-1"},
    "m/s2": {"m": "1", "s": "-2"},
    "rad/s": {"rad": "1", "s": "-1"},
    "rad/m": {"m": "-1", "rad": "1"},
    "N": {"kg": "1", "m": "1", "s": "-2"},
    "Pa": {"kg": "1", "m": "-1", "s": "-2"},
    "N.m": {"kg": "1", "m": "2", "s": "-2"},
    "ul/s": {"m": "3", "s": "-1", "factor": "1e-09"},
}

_CAUSALITIES = ("input", "output", "parameter")
_PARAMETER_FILE = "parameters.toml"


@dataclass(frozen=True)
class FmuVariable:
    """One Real variable of an FMU.

    Parameters
    ----------
    name : str
        Variable name (a Python identifier; the slave stores it as an attribute).
    causality : {"input", "output", "parameter"}
        FMI causality; parameters are ``fixed`` (set before initialisation).
    unit : str
        A key of :data:`UNIT_DEFINITIONS`.
    description : str
        One line shown by co-simulation tools.
    start : float, optional
        Start value (required for inputs and parameters).
    min, max : float, optional
        Bounds written to the model description.
    """

    name: str
    causality: str
    unit: str
    description: str
    start: float | None = None
    min: float | None = None
    max: float | None = None

    def __post_init__(self):
        if not self.name.isidentifier():
            raise ValueError(f"name must be a Python identifier, got {self.name!r}")
        if self.causality not in _CAUSALITIES:
            raise ValueError(f"causality must be one of {_CAUSALITIES}, got {self.causality!r}")
        if self.unit not in UNIT_DEFINITIONS:
            raise ValueError(f"unit must be one of {sorted(UNIT_DEFINITIONS)}, got {self.unit!r}")
        if self.causality != "output" and self.start is None:
            raise ValueError(f"{self.name}: inputs and parameters need a start value")

    def to_config(self) -> dict:
        """The JSON-able form the slave reads."""
        return {
            "name": self.name,
            "causality": self.causality,
            "unit": self.unit,
            "description": self.description,
            "start": self.start,
        }


# --------------------------------------------------------------------------------------------
# Generic builder


@contextlib.contextmanager
def _isolated_import_state():
    """pythonfmu's builder inserts the script folder into sys.path and imports the slave
    module; undo both so that building twice (or building then testing) starts clean.

    Only modules loaded from the folders the build put on sys.path (the slave script) are
    forgotten: libraries first imported during the build (numba, llvmlite, ...) stay, since
    other modules already hold references to them (a second copy of numba in one process
    corrupts its compiler state)."""
    path = list(sys.path)
    modules = set(sys.modules)
    try:
        yield
    finally:
        added = [str(Path(p).resolve()) for p in sys.path if p and p not in path]
        sys.path[:] = path
        for name in set(sys.modules) - modules:
            file = getattr(sys.modules[name], "__file__", None)
            if file and any(str(Path(file).resolve()).startswith(a) for a in added):
                del sys.modules[name]


def build_fmu(
    slave_script: Path,
    variables: Sequence[FmuVariable],
    out,
    *,
    resources: Mapping[str, str | bytes] = (),
    documentation: str | None = None,
    metadata: ET.Element | None = None,
) -> Path:
    """Build an FMI 2.0 co-simulation FMU with pythonfmu and complete its model description.

    Parameters
    ----------
    slave_script : pathlib.Path
        Python file with exactly one ``pythonfmu.Fmi2Slave`` subclass; it is copied into
        ``resources/``. The slave must register ``variables`` (same names, same order); it
        finds them in ``resources/railadhesion_fmu.json`` under ``"variables"``.
    variables : sequence of FmuVariable
        The variables, with units and descriptions.
    out : str or os.PathLike
        The ``.fmu`` file to write (overwritten).
    resources : mapping of str to str or bytes
        Further files for ``resources/`` (file name -> content), including the JSON config.
    documentation : str, optional
        HTML written as ``documentation/index.html``.
    metadata : xml.etree.ElementTree.Element, optional
        One element stored under ``VendorAnnotations/Tool[@name="railadhesion"]``.

    Returns
    -------
    pathlib.Path
        The path of the FMU written (``out``).
    """
    from pythonfmu import FmuBuilder

    out = Path(out)
    if out.suffix != ".fmu":
        raise ValueError(f"out must be a file name ending in .fmu, got {str(out)!r}")
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="railadhesion_fmu_") as tmp:
        tmp = Path(tmp)
        src = tmp / "src"
        src.mkdir()
        script = src / slave_script.name
        shutil.copyfile(slave_script, script)
        project = []
        for name, content in dict(resources).items():
            path = tmp / name
            if isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content, encoding="utf-8")
            project.append(path)
        doc_dir = None
        if documentation is not None:
            doc_dir = tmp / "documentation"
            doc_dir.mkdir()
            (doc_dir / "index.html").write_text(documentation, encoding="utf-8")
        built = tmp / "built.fmu"
        with _isolated_import_state():
            FmuBuilder.build_FMU(
                script, dest=built, project_files=project, documentation_folder=doc_dir
            )
        _complete_model_description(built, out, variables, metadata)
    return out


def _complete_model_description(
    built: Path, out: Path, variables: Sequence[FmuVariable], metadata: ET.Element | None
) -> None:
    """Rewrite the FMU with units, bounds, InitialUnknowns and metadata in its description."""
    with zipfile.ZipFile(built) as zin:
        root = ET.fromstring(zin.read("modelDescription.xml"))
        entries = [(info, zin.read(info)) for info in zin.infolist()]
    _add_units(root, variables)
    if metadata is not None:
        _add_vendor_annotation(root, metadata)
    _add_initial_unknowns(root)
    for node in root.iter():  # drop pythonfmu's pretty-printing whitespace, then indent anew
        if node.text is not None and not node.text.strip():
            node.text = None
        if node.tail is not None and not node.tail.strip():
            node.tail = None
    ET.indent(root, space="  ")
    text = ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for info, data in entries:
            if info.filename == "modelDescription.xml":
                data = text
            zout.writestr(info.filename, data)


def _child_index(root: ET.Element, after: Iterable[str]) -> int:
    """Position just after the last child whose tag is in ``after`` (schema order)."""
    index = 0
    for i, child in enumerate(root):
        if child.tag in after:
            index = i + 1
    return index


def _add_units(root: ET.Element, variables: Sequence[FmuVariable]) -> None:
    by_name = {v.name: v for v in variables}
    found = {sv.get("name"): sv for sv in root.iter("ScalarVariable")}
    if set(found) != set(by_name):
        raise RuntimeError(
            f"the slave registered {sorted(found)}, the builder expected {sorted(by_name)}"
        )
    used = []
    for name, sv in found.items():
        var = by_name[name]
        real = sv.find("Real")
        real.set("unit", var.unit)
        if var.min is not None:
            real.set("min", repr(float(var.min)))
        if var.max is not None:
            real.set("max", repr(float(var.max)))
        if var.unit not in used:
            used.append(var.unit)
    root.insert(_child_index(root, ("ModelExchange", "CoSimulation")), unit_definitions(used))


def unit_definitions(units: Iterable[str]) -> ET.Element:
    """The ``UnitDefinitions`` element of a model description for ``units`` (keys of
    :data:`UNIT_DEFINITIONS`), sorted by name."""
    node = ET.Element("UnitDefinitions")
    for unit in sorted(set(units)):
        ET.SubElement(ET.SubElement(node, "Unit", {"name": unit}), "BaseUnit",
                      UNIT_DEFINITIONS[unit])  # fmt: skip
    return node


def _add_vendor_annotation(root: ET.Element, metadata: ET.Element) -> None:
    annotations = ET.Element("VendorAnnotations")
    tool = ET.SubElement(annotations, "Tool", {"name": "railadhesion"})
    tool.append(metadata)
    after = ("ModelExchange", "CoSimulation", "UnitDefinitions", "TypeDefinitions",
             "LogCategories", "DefaultExperiment")  # fmt: skip
    root.insert(_child_index(root, after), annotations)


def _add_initial_unknowns(root: ET.Element) -> None:
    """Outputs are 'calculated' from the start: list them as InitialUnknowns (FMI 2.0 §2.2.8)."""
    structure = root.find("ModelStructure")
    outputs = structure.find("Outputs")
    if outputs is None or structure.find("InitialUnknowns") is not None:
        return
    initial = ET.SubElement(structure, "InitialUnknowns")
    for unknown in outputs:
        ET.SubElement(initial, "Unknown", {"index": unknown.get("index")})


# --------------------------------------------------------------------------------------------
# Creep-force FMU


def creep_force_variables(model: str, *, shear_modulus: float = 8.2e10,
                          poisson: float = 0.28) -> list[FmuVariable]:  # fmt: skip
    """The variables of the creep-force FMU of ``model`` (``"wilac"``, ``"polach"`` or
    ``"table"``).

    Inputs: creepages, spin, normal force, speed, semi-axes and (WILAC) water flow; fixed
    parameters: elastic constants, with start values ``shear_modulus`` [Pa] in (0, inf) and
    ``poisson`` [-] in [0, 0.5] (the table model: [0.25, 0.30]); outputs: Fx, Fy, adhesion
    (the table model also Mz). Signs: ``docs/CONVENTIONS.md``.
    """
    _check_model(model)
    g, nu = float(shear_modulus), float(poisson)
    nu_lo, nu_hi = (0.25, 0.30) if model == "table" else (0.0, 0.5)
    if not (0.0 < g < math.inf):
        raise ValueError(f"shear_modulus must be in (0, inf), got {shear_modulus!r}")
    if not (nu_lo <= nu <= nu_hi):
        raise ValueError(f"poisson must be in [{nu_lo:g}, {nu_hi:g}], got {poisson!r}")
    for name, value in (("shear_modulus", g), ("poisson", nu)):  # G = 82000 (N/mm^2): a warning
        check_plausible(value, name, where=f"{name} (start value)")
    inputs = [
        FmuVariable("creep_long", "input", "1",
                    "Longitudinal creepage xi = (V - omega R)/V; braking > 0, traction < 0", 0.0),
        FmuVariable("creep_lat", "input", "1", "Lateral creepage eta", 0.0),
        FmuVariable("spin", "input", "rad/m", "Spin creepage phi", 0.0),
        FmuVariable("normal_force", "input", "N",
                    "Normal force Q; Q <= 0 (lift-off) gives zero forces", 100e3),
        FmuVariable("speed", "input", "m/s", "Rolling speed V", 10.0, min=0.0),
        FmuVariable("a", "input", "m", "Contact semi-axis in the rolling direction (x)",
                    6.3e-3, min=0.0),
        FmuVariable("b", "input", "m", "Contact semi-axis in the lateral direction (y)",
                    12.6e-3, min=0.0),
    ]  # fmt: skip
    if model == "wilac":
        inputs.append(
            FmuVariable("water_flow", "input", "ul/s",
                        "Water flow rate to the rail surface, microlitres per second", 0.0,
                        min=0.0)
        )  # fmt: skip
    parameters = [
        FmuVariable("shear_modulus", "parameter", "Pa", "Combined shear modulus G", g,
                    min=0.0),
        FmuVariable("poisson", "parameter", "1", "Combined Poisson's ratio nu", nu,
                    min=nu_lo, max=nu_hi),
    ]  # fmt: skip
    outputs = [
        FmuVariable("Fx", "output", "N",
                    "Longitudinal force of the rail on the wheel (opposes creep_long)"),
        FmuVariable("Fy", "output", "N",
                    "Lateral force of the rail on the wheel (opposes creep_lat)"),
        FmuVariable("adhesion", "output", "1", "Adhesion coefficient sqrt(Fx^2 + Fy^2)/Q"),
    ]  # fmt: skip
    if model == "table":
        outputs.append(FmuVariable("Mz", "output", "N.m",
                                   "Spin moment of the rail on the wheel (Kalker's signs)"))
    return inputs + parameters + outputs


def check_friction(model: str, friction: str) -> None:
    """Raise ValueError unless ``friction`` is one of :data:`TABLE_FRICTION`, and
    ``"falling"`` (the default) for a model other than the table model."""
    if friction not in TABLE_FRICTION:
        raise ValueError(f"friction must be one of {', '.join(TABLE_FRICTION)}, got "
                         f"{friction!r}")
    if model != "table" and friction != "falling":
        raise ValueError("friction: only for the table model (model='table')")


def table_friction_text(params, friction: str) -> str:
    """The sentence of a table-model FMU's description on its friction: the Polach set
    ``params``' μ0 (and A, B with ``friction="falling"``), not its k_A, k_S."""
    law = (f"Coulomb friction mu0 = {params.mu0:g}" if friction == "coulomb" else
           f"falling friction mu0 = {params.mu0:g}, A = {params.A:g}, B = {params.B:g} s/m at "
           "the global slip velocity")
    return f"The table model uses the set's friction only ({law}; not k_A, k_S). "


def _check_model(model: str) -> None:
    if model not in FMU_MODELS:
        raise ValueError(f"model must be one of {', '.join(FMU_MODELS)}, got {model!r}")


@dataclass(frozen=True)
class ResolvedParameters:
    """A parameter set ready for export: the object, its file text and its provenance."""

    model: str
    params: object
    toml: str
    provenance: dict
    origin: str

    @property
    def name(self) -> str:
        return self.params.name or "<unnamed>"

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.toml.encode("utf-8")).hexdigest()

    @property
    def label(self) -> str:
        """The law's name as printed: WILAC, Polach, or the table model."""
        return {"wilac": "WILAC", "table": "Kalker exact-theory table"}.get(self.model,
                                                                           "Polach")

    def describe(self, where: str) -> str:
        """The ``description`` of a creep-force FMU of this set: the law, the set, its
        provenance, then ``where`` (where the FMU holds the set)."""
        import railadhesion

        summary = self.summary()
        return (
            f"railadhesion {railadhesion.__version__}: {self.label} wheel-rail creep-force law "
            f"(forces of the rail on the wheel, Kalker's signs). {summary[0].upper()}"
            f"{summary[1:]}. {where}"
        )

    def metadata(self, file: str) -> ET.Element:
        """``ParameterSet`` element for the FMU's ``VendorAnnotations``: name, model, origin,
        the SHA-256 of ``file`` (the set's text, where the FMU holds it) and the provenance."""
        import railadhesion

        meta = ET.Element("ParameterSet", {
            "model": self.model, "name": self.name, "origin": self.origin, "file": file,
            "sha256": self.sha256, "railadhesionVersion": railadhesion.__version__,
        })  # fmt: skip
        prov = ET.SubElement(meta, "Provenance")
        for key, value in self.provenance.items():
            prov.set(key, str(value).lower() if isinstance(value, bool) else str(value))
        return meta

    def summary(self) -> str:
        """One paragraph: the set, where it comes from, whether it is a reconstruction."""
        prov = self.provenance
        parts = [f"parameter set '{self.name}' ({self.origin})"]
        if prov.get("reconstruction"):
            parts.append("RECONSTRUCTION, not the original authors' coefficients")
        for key in ("source", "created", "licence"):
            if prov.get(key):
                parts.append(f"{key}: {str(prov[key]).rstrip('.')}")
        return "; ".join(parts)


def resolve_parameters(model: str, params=None, parameter_set: str | None = None):
    """The parameter set of ``model`` to export, with its TOML text and provenance.

    Parameters
    ----------
    model : {"wilac", "polach", "table"}
    params : path-like, WilacParameters or PolachParameters, optional
        A parameter file (copied verbatim, after validation) or a parameter object (the
        table model takes a Polach set, of which it uses the friction μ0, A, B).
    parameter_set : str, optional
        A named set: Polach and table, a key of ``POLACH_PARAMETER_SETS``; WILAC,
        ``"default"``.
        Default when neither is given: ``"default"`` (WILAC) or ``"polach2005_dry"``.

    Returns
    -------
    ResolvedParameters
    """
    from railadhesion.io import paramfiles as pf
    from railadhesion.models.parameters import (
        POLACH_PARAMETER_SETS,
        PolachParameters,
        polach_parameters,
    )
    from railadhesion.models.wilac import DEFAULT_PARAMETER_FILE, WilacParameters

    _check_model(model)
    if params is not None and parameter_set is not None:
        raise ValueError("give either params (a file or a parameter object) or parameter_set")
    kind = WilacParameters if model == "wilac" else PolachParameters
    if params is None:
        if model == "wilac":
            if parameter_set not in (None, "default"):
                raise ValueError(
                    f"parameter_set: the WILAC model has one named set, 'default'; got "
                    f"{parameter_set!r} (give a WILAC parameter file instead)"
                )
            from importlib import resources

            res = resources.files("railadhesion").joinpath("data", DEFAULT_PARAMETER_FILE)
            text = res.read_text(encoding="utf-8")
            with resources.as_file(res) as path:
                obj = pf.load_wilac_parameters(path)
                prov = pf.read_provenance(path)
            return ResolvedParameters(model, obj, text, prov, "package default WILAC set")
        name = parameter_set or "polach2005_dry"
        if name not in POLACH_PARAMETER_SETS:
            raise ValueError(
                f"parameter_set must be one of {', '.join(POLACH_PARAMETER_SETS)}, got {name!r}"
            )
        obj = polach_parameters(name)
        text = pf.polach_parameters_to_toml(obj)
        return ResolvedParameters(
            model, obj, text, _polach_provenance(obj), "built-in named Polach set"
        )
    if isinstance(params, kind):
        if model == "wilac":
            text = pf.wilac_parameters_to_toml(params)
            prov = dict(params.provenance)
        else:
            text = pf.polach_parameters_to_toml(params)
            prov = _polach_provenance(params)
        return ResolvedParameters(model, params, text, prov, "parameter object")
    if isinstance(params, WilacParameters | PolachParameters):
        raise ValueError(
            f"params is a {type(params).__name__}, the {model} model needs a {kind.__name__}"
        )
    path = Path(params)
    loader = pf.load_wilac_parameters if model == "wilac" else pf.load_polach_parameters
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"params: cannot read {path}: {exc.strerror or exc}") from exc
    obj = loader(path)
    return ResolvedParameters(model, obj, text, pf.read_provenance(path), f"file {path.name}")


def _polach_provenance(params) -> dict:
    prov = {}
    if params.source:
        prov["source"] = params.source
    if params.notes:
        prov["notes"] = params.notes
    return prov


def build_creep_force_fmu(
    out,
    model: str = "wilac",
    params=None,
    *,
    parameter_set: str | None = None,
    shear_modulus: float = 8.2e10,
    poisson: float = 0.28,
    friction: str = "falling",
) -> Path:
    """Write an FMI 2.0 co-simulation FMU of a creep-force law (WILAC, Polach or the table
    model of Kalker's exact theory).

    Inputs: ``creep_long``, ``creep_lat`` [-], ``spin`` [rad/m], ``normal_force`` [N],
    ``speed`` [m/s], ``a``, ``b`` [m] and, for WILAC, ``water_flow`` [µl/s]; fixed parameters
    ``shear_modulus`` [Pa] and ``poisson`` [-]; outputs ``Fx``, ``Fy`` [N] (rail on wheel,
    Kalker's signs) and ``adhesion`` [-]. The parameter set is embedded as
    ``resources/parameters.toml`` (the file the slave loads) and its provenance is stated in
    the model description (``description`` and ``VendorAnnotations``) and in
    ``documentation/index.html``.

    Parameters
    ----------
    out : str or os.PathLike
        The ``.fmu`` file to write.
    model : {"wilac", "polach", "table"}
    params, parameter_set :
        The parameter set, see :func:`resolve_parameters`.
    shear_modulus, poisson : float
        Start values of the FMU's elastic-constant parameters [Pa], [-].
    friction : {"falling", "coulomb"}
        The table model's friction: the set's falling friction μ0 [(1 − A) exp(−B w) + A]
        at the global slip velocity (default), or Coulomb's μ0. Only for ``model="table"``.

    Returns
    -------
    pathlib.Path
        The path of the creep-force FMU written (``out``): FMI 2.0 co-simulation, Python inside.

    Notes
    -----
    The table model (:func:`railadhesion.contact.exact_table_forces`) has one more output,
    ``Mz`` [N m]; its inputs must be in the table's range (a/b in [0.2, 5]; Poisson's ratio
    in [0.25, 0.30]), otherwise the outputs are NaN and the step fails, as for any invalid
    input. The FMU runs Python: the host needs a Python interpreter with ``railadhesion`` installed
    (pythonfmu's binary runs the slave in the interpreter of the process that loads it, e.g.
    FMPy's). The slave calls :func:`railadhesion.wilac_forces`,
    :func:`railadhesion.polach_forces` or :func:`railadhesion.contact.exact_table_forces`
    with scalars, so its outputs equal direct calls.
    """
    import railadhesion

    resolved = resolve_parameters(model, params, parameter_set)
    check_friction(model, friction)
    variables = creep_force_variables(model, shear_modulus=shear_modulus, poisson=poisson)
    where = f"Embedded as resources/{_PARAMETER_FILE}."
    if model == "table":
        where = table_friction_text(resolved.params, friction) + where
    description = resolved.describe(where)
    config = {
        "model": model,
        "friction": friction,
        "parameter_file": _PARAMETER_FILE,
        "railadhesion_version": railadhesion.__version__,
        "description": description,
        "fmu_version": f"railadhesion {railadhesion.__version__}, {resolved.name}",
        "license": resolved.provenance.get("licence", ""),
        "variables": [v.to_config() for v in variables],
    }
    meta = resolved.metadata(f"resources/{_PARAMETER_FILE}")
    return build_fmu(
        Path(__file__).with_name("railadhesion_creepforce.py"),
        variables,
        out,
        resources={
            CONFIG_FILE: json.dumps(config, indent=2),
            _PARAMETER_FILE: resolved.toml,
        },
        documentation=creep_force_documentation(
            description, resolved, variables, runs=RUNS_PYTHON,
            file=f"resources/{_PARAMETER_FILE}",
        ),  # fmt: skip
        metadata=meta,
    )


#: What a Python FMU's documentation says its host needs.
RUNS_PYTHON = ("Runs Python: the host needs a Python interpreter with the railadhesion "
               "package installed.")  # fmt: skip


def documentation_page(title: str, body: str, heading: str | None = None) -> str:
    """``documentation/index.html`` of an FMU: the page titled ``title``, its heading
    (default: "``title`` (railadhesion)"), then ``body`` (HTML)."""
    heading = heading or f"{title} (railadhesion)"
    return (
        f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>{title}</title></head>"
        f"<body>\n<h1>{heading}</h1>\n{body}</body></html>\n"
    )


def variables_table(variables: Iterable[FmuVariable]) -> str:
    """The HTML table of an FMU's variables (name, causality, unit, description)."""
    esc = html.escape
    rows = "".join(
        f"<tr><td>{esc(v.name)}</td><td>{v.causality}</td><td>{esc(v.unit)}</td>"
        f"<td>{esc(v.description)}</td></tr>"
        for v in variables
    )
    return (
        "<table border='1'><tr><th>name</th><th>causality</th><th>unit</th>"
        f"<th>description</th></tr>{rows}</table>"
    )


def creep_force_documentation(description, resolved, variables, *, runs: str, file: str) -> str:
    """``documentation/index.html`` of a creep-force FMU: description, what the host needs
    (``runs``), the variables, the parameter set (held in ``file``) and its provenance."""
    esc = html.escape
    prov = "".join(
        f"<tr><td>{esc(k)}</td><td>{esc(str(v))}</td></tr>" for k, v in resolved.provenance.items()
    )
    return documentation_page(
        f"{resolved.label} creep-force FMU",
        f"<p>{esc(description)}</p>\n"
        f"<p>{esc(runs)} Sign convention: Kalker's (creepage (V - omega R)/V, braking "
        "positive; forces of the rail on the wheel oppose the creepages).</p>\n"
        f"<h2>Variables</h2>\n{variables_table(variables)}\n"
        f"<h2>Parameter set '{esc(resolved.name)}'</h2>\n<p>File: {esc(file)} "
        f"(sha256 {resolved.sha256}).</p>\n<table border='1'>{prov}</table>\n",
    )
