"""Creep-force FMU: built with pythonfmu, run with FMPy (an FMI client written elsewhere).

One FMU per model is built per test module (a build takes well under a second). The FMU's
slave runs in this process's Python (pythonfmu), which imports railadhesion from the same
place as the tests (PYTHONPATH=src).
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")

from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.util import fmu_info  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import railadhesion  # noqa: E402
from railadhesion.export import (  # noqa: E402
    FmuVariable,
    build_creep_force_fmu,
    creep_force_variables,
    resolve_parameters,
)
from railadhesion.io.paramfiles import (  # noqa: E402
    load_parameter_file,
    save_polach_parameters,
)
from railadhesion.models import default_wilac_parameters, polach_parameters  # noqa: E402

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

INPUTS = ["creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b"]
OUTPUTS = ["Fx", "Fy", "adhesion"]
TOL = 1e-12  # agreement FMU vs direct call, relative to max(1, |value|)


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fmu")
    return {
        "wilac": build_creep_force_fmu(tmp / "wilac.fmu", "wilac"),
        "polach": build_creep_force_fmu(
            tmp / "polach.fmu", "polach", parameter_set="polach2005_wet"
        ),
    }


def _inputs(model):
    return INPUTS + (["water_flow"] if model == "wilac" else [])


def _direct(model, params, x, shear_modulus=8.2e10, poisson=0.28):
    """The library called directly with the same scalars: (Fx, Fy, adhesion)."""
    if model == "wilac":
        fx, fy = railadhesion.wilac_forces(
            *(x[k] for k in _inputs(model)), params,
            shear_modulus=shear_modulus, poisson=poisson,
        )  # fmt: skip
    else:
        fx, fy = railadhesion.polach_forces(
            *(x[k] for k in INPUTS), mu0=params.mu0, k_A=params.k_A, k_S=params.k_S,
            A=params.A, B=params.B, shear_modulus=shear_modulus, poisson=poisson,
        )  # fmt: skip
    return float(fx), float(fy), float(railadhesion.adhesion(fx, fy, x["normal_force"]))


def _random_inputs(rng, n):
    """Scalar inputs over the models' working range (braking and traction, water 0-400 µl/s)."""
    return [
        {
            "creep_long": rng.uniform(-0.4, 0.4),
            "creep_lat": rng.uniform(-0.05, 0.05),
            "spin": rng.uniform(-2.0, 2.0),
            "normal_force": rng.uniform(4e3, 150e3),
            "speed": rng.uniform(0.5, 40.0),
            "a": rng.uniform(2e-3, 10e-3),
            "b": rng.uniform(2e-3, 12e-3),
            "water_flow": rng.choice([0.0, rng.uniform(0.0, 60.0), rng.uniform(0.0, 400.0)]),
        }
        for _ in range(n)
    ]


class _Slave:
    """FMPy's low-level FMU2Slave, instantiated and initialised."""

    def __init__(self, path, parameters=None):
        self.md = read_model_description(path)
        self.dir = extract(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.fmu = FMU2Slave(
            guid=self.md.guid, unzipDirectory=self.dir,
            modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="test",
        )  # fmt: skip
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        if parameters:
            self.set(**parameters)
        self.fmu.exitInitializationMode()
        self.params = load_parameter_file(self.dir / "resources" / "parameters.toml")

    def set(self, **values):
        self.fmu.setReal([self.vr[k] for k in values], list(values.values()))

    def get(self, *names):
        return self.fmu.getReal([self.vr[k] for k in names])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def _close(actual, expected):
    return all(
        abs(a - e) <= TOL * max(1.0, abs(e)) for a, e in zip(actual, expected, strict=True)
    )


# --------------------------------------------------------------------------------------------
# Model description


@pytest.mark.parametrize("model", ["wilac", "polach"])
def test_model_description_passes_fmpy_validation(fmus, model):
    assert validate_fmu(str(fmus[model])) == []
    read_model_description(fmus[model], validate=True)  # XML schema; raises on a violation


@pytest.mark.parametrize("model", ["wilac", "polach"])
def test_every_variable_has_a_defined_unit_and_a_description(fmus, model):
    md = read_model_description(fmus[model])
    defined = {u.name for u in md.unitDefinitions}
    names = [v.name for v in md.modelVariables]
    assert names == [v.name for v in creep_force_variables(model)]
    assert ("water_flow" in names) == (model == "wilac")
    expected_units = {v.name: v.unit for v in creep_force_variables(model)}
    for v in md.modelVariables:
        assert v.unit in defined and v.unit == expected_units[v.name]
        assert v.description
    listing = fmu_info(str(fmus[model]))  # FMPy's dump shows them too
    for v in creep_force_variables(model):
        if v.causality != "parameter":
            assert re.search(rf"^\s+{v.name}\s+{v.causality}\s.*\s{re.escape(v.unit)}\s", listing,
                             re.MULTILINE), v.name  # fmt: skip
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["normal_force"] == "N" and units["Fx"] == "N" and units["spin"] == "rad/m"
    if model == "wilac":
        ul_s = next(u for u in md.unitDefinitions if u.name == "ul/s").baseUnit
        assert (ul_s.m, ul_s.s, ul_s.factor) == (3, -1, 1e-9)  # µl/s in SI


def test_wilac_fmu_embeds_the_parameter_set_and_its_provenance(fmus):
    with zipfile.ZipFile(fmus["wilac"]) as z:
        toml = z.read("resources/parameters.toml")
        root = ET.fromstring(z.read("modelDescription.xml"))
        assert z.read("documentation/index.html").startswith(b"<!DOCTYPE html>")
    default = default_wilac_parameters()
    description = root.get("description")
    assert default.name in description and "RECONSTRUCTION" in description
    meta = root.find("VendorAnnotations/Tool[@name='railadhesion']/ParameterSet")
    assert meta.get("name") == default.name and meta.get("model") == "wilac"
    assert meta.get("sha256") == hashlib.sha256(toml).hexdigest()
    prov = meta.find("Provenance")
    assert prov.get("reconstruction") == "true"
    assert prov.get("source") == default.provenance["source"]
    assert prov.get("notes") == default.provenance["notes"]  # multi-line text kept intact


def test_polach_fmu_embeds_the_named_set(fmus, tmp_path):
    with zipfile.ZipFile(fmus["polach"]) as z:
        z.extract("resources/parameters.toml", tmp_path)
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert load_parameter_file(tmp_path / "resources/parameters.toml") == polach_parameters(
        "polach2005_wet"
    )
    assert "polach2005_wet" in root.get("description")
    meta = root.find("VendorAnnotations/Tool/ParameterSet")
    assert meta.find("Provenance").get("source") == polach_parameters("polach2005_wet").source


# --------------------------------------------------------------------------------------------
# Running under FMPy


@ANY_INPUT
@pytest.mark.parametrize("model", ["wilac", "polach"])
def test_low_level_stepping_matches_direct_calls(fmus, model):
    """Inputs change every step; each step's outputs equal the library's to 1e-12."""
    slave = _Slave(fmus[model])
    try:
        rng = np.random.default_rng(11)
        for i, x in enumerate(_random_inputs(rng, 150)):
            slave.set(**{k: x[k] for k in _inputs(model)})
            slave.fmu.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
            expected = _direct(model, slave.params, x)
            assert _close(slave.get(*OUTPUTS), expected), (x, slave.get(*OUTPUTS), expected)
    finally:
        slave.close()


@ANY_INPUT
def test_instances_are_independent(fmus):
    """Two WILAC instances and a Polach one, alive together (one per wheel, say), stepped
    alternately with different inputs: each returns its own library numbers."""
    slaves = [(_Slave(fmus["wilac"]), "wilac"), (_Slave(fmus["wilac"]), "wilac"),
              (_Slave(fmus["polach"]), "polach")]  # fmt: skip
    try:
        rng = np.random.default_rng(7)
        for step, xs in enumerate(zip(*[_random_inputs(rng, 20) for _ in slaves], strict=True)):
            for (slave, model), x in zip(slaves, xs, strict=True):
                slave.set(**{k: x[k] for k in _inputs(model)})
            for (slave, _), _x in zip(slaves, xs, strict=True):
                slave.fmu.doStep(currentCommunicationPoint=step * 1e-3, communicationStepSize=1e-3)
            for (slave, model), x in zip(slaves, xs, strict=True):
                assert _close(slave.get(*OUTPUTS), _direct(model, slave.params, x))
    finally:
        for slave, _ in slaves:
            slave.close()


def test_embedded_parameters_equal_the_requested_set(fmus):
    slave = _Slave(fmus["wilac"])
    try:
        assert slave.params == default_wilac_parameters()
    finally:
        slave.close()


@ANY_INPUT
def test_simulate_fmu_with_an_input_signal_changing_every_step(fmus):
    """fmpy.simulate_fmu drives the WILAC FMU through a creep/load/water/speed ramp."""
    model = "wilac"
    n = 40
    names = _inputs(model)
    signal = np.zeros(n, dtype=[("time", float)] + [(k, float) for k in names])
    signal["time"] = np.arange(n) * 0.01
    rng = np.random.default_rng(5)
    for k, v in zip(names, zip(*[x.values() for x in _random_inputs(rng, n)], strict=True),
                    strict=False):  # fmt: skip
        signal[k] = v
    result = fmpy.simulate_fmu(
        str(fmus[model]), start_time=0.0, stop_time=signal["time"][-1], output_interval=0.01,
        input=signal, output=names + OUTPUTS,
    )  # fmt: skip
    params = default_wilac_parameters()
    assert len(result) == n
    # FMPy records, after each step, the inputs the step used (those of the previous time).
    for k in names:
        np.testing.assert_array_equal(result[k][1:], signal[k][:-1])
    assert len(np.unique(result["creep_long"])) == n - 1  # a new input every step
    for row in result:
        x = {k: float(row[k]) for k in names}
        assert _close([row["Fx"], row["Fy"], row["adhesion"]], _direct(model, params, x))


def test_fixed_parameters_reach_the_model(fmus):
    slave = _Slave(fmus["polach"], parameters={"shear_modulus": 7.0e10, "poisson": 0.3})
    try:
        x = dict(creep_long=2e-3, creep_lat=1e-3, spin=0.5, normal_force=90e3, speed=12.0,
                 a=6e-3, b=9e-3)  # fmt: skip
        slave.set(**x)
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        got = slave.get(*OUTPUTS)
        assert _close(got, _direct("polach", slave.params, x, 7.0e10, 0.3))
        assert not _close(got, _direct("polach", slave.params, x))  # the parameters matter
    finally:
        slave.close()


def test_outputs_follow_inputs_without_a_step(fmus):
    """Direct feedthrough: reading after setting returns the forces of the new inputs."""
    slave = _Slave(fmus["wilac"])
    try:
        x = dict(creep_long=-0.05, creep_lat=0.0, spin=0.0, normal_force=4.2e3, speed=5.0,
                 a=3e-3, b=3e-3, water_flow=25.0)  # fmt: skip
        slave.set(**x)
        assert _close(slave.get(*OUTPUTS), _direct("wilac", slave.params, x))
    finally:
        slave.close()


def test_lift_off_gives_zero_force_and_bad_input_gives_nan_and_fails_the_step(fmus):
    slave = _Slave(fmus["wilac"])
    try:
        slave.set(creep_long=0.1, normal_force=0.0)
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        assert slave.get(*OUTPUTS) == [0.0, 0.0, 0.0]
        slave.set(normal_force=-math.inf)
        assert all(math.isnan(v) for v in slave.get(*OUTPUTS))  # not a lift-off: invalid
        slave.set(normal_force=50e3, a=-1e-3)
        assert all(math.isnan(v) for v in slave.get(*OUTPUTS))  # read without a step: NaN
        with pytest.raises(Exception, match="fmi2DoStep failed with status 2"):  # discard
            slave.fmu.doStep(currentCommunicationPoint=1e-3, communicationStepSize=1e-3)
        assert all(math.isnan(v) for v in slave.get(*OUTPUTS))
        slave.set(a=5e-3)  # recovers once the input is valid again
        slave.fmu.doStep(currentCommunicationPoint=1e-3, communicationStepSize=1e-3)
        assert slave.get("Fx")[0] < 0.0  # braking creep: the rail pulls the wheel back
    finally:
        slave.close()


# --------------------------------------------------------------------------------------------
# Builder inputs


def test_a_parameter_file_is_embedded_verbatim(tmp_path):
    params = polach_parameters("contact_eurosprinter").replace(mu0=0.31, name="site_A")
    path = save_polach_parameters(params, tmp_path / "site.toml", provenance={"script": "x.py"})
    out = build_creep_force_fmu(tmp_path / "site.fmu", "polach", path)
    with zipfile.ZipFile(out) as z:
        assert z.read("resources/parameters.toml") == path.read_bytes()
        description = ET.fromstring(z.read("modelDescription.xml")).get("description")
    assert "site_A" in description and "file site.toml" in description
    assert validate_fmu(str(out)) == []


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"model": "fletcher"}, "model must be one of wilac, polach"),
        ({"model": "polach", "parameter_set": "nope"}, "parameter_set must be one of"),
        ({"model": "wilac", "parameter_set": "polach2005_dry"}, "one named set, 'default'"),
        ({"model": "wilac", "params": polach_parameters("polach2005_dry")}, "needs a Wilac"),
        ({"model": "polach", "params": "missing.toml"}, "params: cannot read"),
        (
            {"model": "polach", "params": "x.toml", "parameter_set": "polach2005_dry"},
            "either params",
        ),
    ],
)
def test_resolve_parameters_rejects_bad_requests(kwargs, match):
    with pytest.raises(ValueError, match=match):
        resolve_parameters(**kwargs)


def test_build_rejects_bad_output_name_and_elastic_constants(tmp_path):
    with pytest.raises(ValueError, match="ending in .fmu"):
        build_creep_force_fmu(tmp_path / "x.zip", "polach")
    with pytest.raises(ValueError, match="poisson"):
        build_creep_force_fmu(tmp_path / "x.fmu", "polach", poisson=0.7)


def test_fmu_variable_validates_its_fields():
    with pytest.raises(ValueError, match="unit must be one of"):
        FmuVariable("x", "input", "furlong", "d", 0.0)
    with pytest.raises(ValueError, match="need a start value"):
        FmuVariable("x", "input", "m", "d")
    with pytest.raises(ValueError, match="causality"):
        FmuVariable("x", "local", "m", "d", 0.0)


# --------------------------------------------------------------------------------------------
# A host without Python


def _libpython():
    import sysconfig

    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return None
    path = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")
    return path if path.is_file() else None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the C host uses dlopen (Linux)")
def test_runs_from_a_c_host_without_python(fmus, tmp_path):
    """A C program loads the FMU's binary; with the Python shared library preloaded and the
    package importable (what docs/fmu.md tells users), it gives the library's forces."""
    compiler = shutil.which("cc") or shutil.which("gcc")
    libpython = _libpython()
    if compiler is None or libpython is None:
        pytest.skip("needs a C compiler and a shared libpython")
    host = tmp_path / "fmi2_host"
    source = Path(__file__).with_name("data") / "fmi2_host.c"
    subprocess.run([compiler, "-o", str(host), str(source), "-ldl"], check=True, timeout=60)
    unzipped = tmp_path / "fmu"
    with zipfile.ZipFile(fmus["wilac"]) as z:
        z.extractall(unzipped)
    md = read_model_description(fmus["wilac"])
    vr = {v.name: v.valueReference for v in md.modelVariables}
    binary = unzipped / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    x = dict(creep_long=-0.03, creep_lat=0.004, spin=0.2, normal_force=80e3, speed=15.0,
             a=7e-3, b=9e-3, water_flow=28.0)  # fmt: skip
    args = [str(binary), (unzipped / "resources").as_uri(), md.guid, str(len(x))]
    for name, value in x.items():
        args += [str(vr[name]), repr(value)]
    args += [str(len(OUTPUTS))] + [str(vr[k]) for k in OUTPUTS]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    bare = subprocess.run([str(host), *args], capture_output=True, text=True, env=env,
                          timeout=120)  # fmt: skip
    assert bare.returncode == 3 and "undefined symbol" in bare.stdout  # needs libpython
    env["LD_PRELOAD"] = str(libpython)
    run = subprocess.run([str(host), *args], capture_output=True, text=True, env=env,
                         timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    lines = run.stdout.split()
    assert lines[:2] == ["status", "0"]
    got = [float(v) for v in lines[2:]]
    assert _close(got, _direct("wilac", default_wilac_parameters(), x))


# --------------------------------------------------------------------------------------------
# Property: any valid scalar input gives the library's numbers


@pytest.fixture(scope="module")
def wilac_slave(fmus):
    slave = _Slave(fmus["wilac"])
    yield slave
    slave.close()


@ANY_INPUT
@settings(max_examples=150, deadline=None)
@given(
    creep_long=st.floats(-1.0, 1.0),
    creep_lat=st.floats(-0.2, 0.2),
    spin=st.floats(-5.0, 5.0),
    normal_force=st.floats(1.0, 3e5),
    speed=st.floats(0.0, 100.0),
    a=st.floats(1e-4, 0.05),
    b=st.floats(1e-4, 0.05),
    water_flow=st.floats(0.0, 1e4),
)
def test_any_valid_input_matches_the_library(wilac_slave, **x):
    wilac_slave.set(**x)
    wilac_slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    got = wilac_slave.get(*OUTPUTS)
    assert _close(got, _direct("wilac", wilac_slave.params, x)), (x, got)


def test_building_leaves_no_slave_module_behind(tmp_path, monkeypatch):
    """The build imports the slave from a temporary folder; it must not stay importable (a
    later FMU instance in this process would otherwise reuse a module whose file is gone)."""
    monkeypatch.delitem(sys.modules, "railadhesion_creepforce", raising=False)
    path = list(sys.path)
    build_creep_force_fmu(tmp_path / "p.fmu", "polach")
    assert "railadhesion_creepforce" not in sys.modules
    assert sys.path == path
