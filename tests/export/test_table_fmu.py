"""The creep-force FMU of the table model of Kalker's exact theory (Python FMU, run with
FMPy, as the Polach and WILAC FMUs in test_fmu.py)."""

from __future__ import annotations

import math
import shutil
import sys
import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")

from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

from railadhesion.cli import app  # noqa: E402
from railadhesion.contact import exact_table_forces  # noqa: E402
from railadhesion.export import (  # noqa: E402
    build_creep_force_fmu,
    build_native_creep_force_fmu,
    creep_force_table,
    creep_force_variables,
    native,
)
from railadhesion.models import polach_parameters  # noqa: E402

INPUTS = ["creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b"]
OUTPUTS = ["Fx", "Fy", "adhesion", "Mz"]


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("tfmu")
    return {
        "falling": build_creep_force_fmu(tmp / "t.fmu", "table", parameter_set="polach2005_wet"),
        "coulomb": build_creep_force_fmu(tmp / "c.fmu", "table", parameter_set="polach2005_dry",
                                         friction="coulomb", poisson=0.26),
    }


class _Slave:
    def __init__(self, path):
        self.md = read_model_description(path)
        self.dir = extract(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier,
                             instanceName="t")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def set(self, **values):
        self.fmu.setReal([self.vr[k] for k in values], list(values.values()))

    def get(self, *names):
        return self.fmu.getReal([self.vr[k] for k in names])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def _direct(x, mu, ratio, decay, poisson=0.28):
    fx, fy, mz = exact_table_forces(*(x[k] for k in ("creep_long", "creep_lat", "spin",
                                                      "normal_force", "a", "b")), mu,
                                    poisson=poisson, speed=x["speed"], friction_ratio=ratio,
                                    friction_decay=decay)
    return fx, fy, math.hypot(fx, fy) / x["normal_force"], mz


@pytest.mark.parametrize("kind", ["falling", "coulomb"])
def test_table_fmu_is_valid_and_describes_its_friction(fmus, kind):
    assert validate_fmu(str(fmus[kind])) == []
    md = read_model_description(fmus[kind], validate=True)
    names = [v.name for v in md.modelVariables]
    assert names == [v.name for v in creep_force_variables("table")]
    assert "Mz" in names and "water_flow" not in names
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["Mz"] == "N.m"
    nu = next(v for v in md.modelVariables if v.name == "poisson")
    assert (float(nu.min), float(nu.max)) == (0.25, 0.3)
    with zipfile.ZipFile(fmus[kind]) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    text = root.get("description")
    assert "exact-theory table" in text
    assert ("Coulomb friction mu0 = 0.55" in text) == (kind == "coulomb")


@pytest.mark.filterwarnings("ignore::railadhesion.plausibility.PlausibilityWarning")
def test_table_fmu_steps_match_direct_calls(fmus):
    rng = np.random.default_rng(3)
    wet, dry = polach_parameters("polach2005_wet"), polach_parameters("polach2005_dry")
    for kind, law, nu in (("falling", (wet.mu0, wet.A, wet.B), 0.28),
                          ("coulomb", (dry.mu0, 1.0, 0.0), 0.26)):
        slave = _Slave(fmus[kind])
        try:
            t = 0.0
            for _ in range(12):
                b = rng.uniform(3e-3, 10e-3)
                x = {"creep_long": rng.uniform(-0.05, 0.05), "creep_lat": rng.uniform(-0.01, 0.01),
                     "spin": rng.uniform(-1.5, 1.5), "normal_force": rng.uniform(2e4, 1.2e5),
                     "speed": rng.uniform(0.5, 40.0), "b": b, "a": b * rng.uniform(0.25, 4.0)}
                slave.set(**x)
                slave.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
                t += 1e-3
                got = slave.get(*OUTPUTS)
                want = _direct(x, *law, poisson=nu)
                np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)
        finally:
            slave.close()


def test_table_fmu_lift_off_and_out_of_range_contact(fmus):
    slave = _Slave(fmus["falling"])
    try:
        slave.set(normal_force=0.0, creep_long=0.01)
        assert slave.get(*OUTPUTS) == [0.0, 0.0, 0.0, 0.0]
        # a/b = 10: outside the table; NaN outputs and a failed step
        slave.set(normal_force=5e4, a=10e-3, b=1e-3)
        assert all(math.isnan(v) for v in slave.get(*OUTPUTS))
        with pytest.raises(Exception, match="fmi2DoStep failed with status 2"):  # discard
            slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        slave.set(a=5e-3, b=5e-3)  # recovers once the input is valid again
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        assert slave.get("Fx")[0] < 0.0
    finally:
        slave.close()


def test_table_fmu_bad_requests_name_the_argument(tmp_path):
    with pytest.raises(ValueError, match="poisson"):
        build_creep_force_fmu(tmp_path / "x.fmu", "table", poisson=0.32)
    with pytest.raises(ValueError, match="friction"):
        build_creep_force_fmu(tmp_path / "x.fmu", "table", friction="dry")
    with pytest.raises(ValueError, match="friction"):
        build_creep_force_fmu(tmp_path / "x.fmu", "polach", friction="coulomb")
    with pytest.raises(ValueError, match="friction"):
        build_native_creep_force_fmu(tmp_path / "x.fmu", "table", friction="wet")
    with pytest.raises(ValueError, match="wilac or polach"):
        creep_force_table("table")


def test_cli_export_fmu_model_table(tmp_path):
    out = tmp_path / "t.fmu"
    res = CliRunner().invoke(app, ["export", "fmu", "--model", "table", "--set",
                                   "polach2005_wet", "--friction", "coulomb", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert out.exists() and "table" in res.output
    res = CliRunner().invoke(app, ["export", "fmu", "--model", "polach", "--friction",
                                   "coulomb", "--out", str(tmp_path / "p.fmu")])
    assert res.exit_code != 0 and "friction" in res.output


NATIVE = pytest.mark.skipif(
    not sys.platform.startswith("linux") or native.find_c_compiler() is None,
    reason="native FMUs are built for linux64 with a C compiler",
)


@NATIVE
@pytest.mark.filterwarnings("ignore::railadhesion.plausibility.PlausibilityWarning")
def test_native_table_fmu_matches_direct_calls(tmp_path):
    # the 4-D table compiled into the binary's settings (one build, ~6 s on an idle core)
    fmu = build_native_creep_force_fmu(tmp_path / "n.fmu", "table",
                                       parameter_set="polach2005_wet")
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(fmu)
    assert [v.name for v in md.modelVariables] == [v.name for v in
                                                   creep_force_variables("table")]
    wet = polach_parameters("polach2005_wet")
    rng = np.random.default_rng(5)
    slave = _Slave(fmu)
    try:
        for _ in range(200):
            b = rng.uniform(3e-3, 10e-3)
            x = {"creep_long": rng.uniform(-0.05, 0.05),
                 "creep_lat": rng.uniform(-0.01, 0.01), "spin": rng.uniform(-1.5, 1.5),
                 "normal_force": rng.uniform(2e4, 1.2e5), "speed": rng.uniform(0.5, 40.0),
                 "b": b, "a": b * rng.uniform(0.2, 5.0)}
            slave.set(**x)
            slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
            np.testing.assert_allclose(slave.get(*OUTPUTS), _direct(x, wet.mu0, wet.A, wet.B),
                                       rtol=1e-12, atol=1e-9)
        slave.set(normal_force=0.0)
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        assert slave.get(*OUTPUTS) == [0.0, 0.0, 0.0, 0.0]
        slave.set(normal_force=5e4, a=10e-3, b=1e-3)  # a/b = 10: the step fails, named
        with pytest.raises(Exception, match="fmi2DoStep failed"):
            slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    finally:
        slave.close()


BRAKE_SCENARIO = """
format = "railadhesion-brake-scenario"
version = 1
name = "table"
[vehicle]
file = "coach_default"
[run]
initial_speed_m_s = 8.0
time_step_s = 0.002
[brake]
pressure_Pa = 3e5
[adhesion]
model = "table"
mu = 0.08
friction_ratio = 0.4
friction_decay_s_per_m = 0.6
"""


def test_braking_fmu_of_a_table_scenario_matches_the_stepping_api(tmp_path):
    from railadhesion.braking import BrakingSimulator
    from railadhesion.braking.scenario import load_scenario
    from railadhesion.export import build_braking_fmu, build_native_braking_fmu

    path = tmp_path / "t.toml"
    path.write_text(BRAKE_SCENARIO)
    fmu = build_braking_fmu(tmp_path / "b.fmu", path)
    assert validate_fmu(str(fmu)) == []
    sc = load_scenario(path)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           record=False)
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    dir_ = extract(fmu)
    s = FMU2Slave(guid=md.guid, unzipDirectory=dir_,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="b")
    names = [f"wheel_speed_{k}" for k in range(1, 5)] + ["train_speed", "distance"]
    try:
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        t, h = 0.0, 5e-3
        for k in range(200):
            command = [5e5] * 4 if k > 5 else [0.0] * 4  # hard enough to slide at mu 0.08
            s.setReal([vr[f"pressure_command_{j}"] for j in range(1, 5)], command)
            s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t += h
            state = sim.step(h, {"pressure_command": command, "valves": [0] * 4})
        got = s.getReal([vr[n] for n in names])
    finally:
        s.terminate()
        s.freeInstance()
        shutil.rmtree(dir_, ignore_errors=True)
    want = [*state.wheel_speeds, state.train_speed, state.distance]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert max(state.creep) > 0.01  # the wheels slide: the table's falling branch is used
    from railadhesion.export.native import NativeUnsupported

    with pytest.raises(NativeUnsupported, match="table model"):  # the CLI falls back on it
        build_native_braking_fmu(tmp_path / "n.fmu", path)


def test_cli_braking_fmu_of_a_table_scenario_falls_back_to_the_python_fmu(tmp_path):
    """The native braking FMU does not compile the table model: by default the export writes
    the Python FMU and says why; asked for --native, it is an error (exit 2)."""
    path = tmp_path / "t.toml"
    path.write_text(BRAKE_SCENARIO)
    out = tmp_path / "b.fmu"
    result = CliRunner().invoke(app, ["export", "braking-fmu", str(path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "table model" in text and "Python FMU: the host needs a Python" in text
    assert out.exists()
    result = CliRunner().invoke(app, ["export", "braking-fmu", str(path), "--native", "--out",
                                      str(tmp_path / "n.fmu")])  # fmt: skip
    assert result.exit_code == 2
    assert "table model" in " ".join(result.output.split())
