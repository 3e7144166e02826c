"""The adhesion-monitor FMU (issue 21): built, validated and run with FMPy, checked sample by
sample against the per-sample call driven directly with the same inputs."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from railadhesion.export import build_monitor_fmu  # noqa: E402
from railadhesion.monitor import AdhesionMonitor, MonitorSettings  # noqa: E402


@pytest.fixture(scope="module")
def monitor_fmu(tmp_path_factory):
    return build_monitor_fmu(tmp_path_factory.mktemp("fmu") / "monitor.fmu", "coach_default")


def test_model_description(monitor_fmu):
    assert validate_fmu(str(monitor_fmu)) == []
    md = read_model_description(monitor_fmu)
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    assert inputs[0] == "train_speed" and "brake_pressure_4" in inputs and len(inputs) == 9
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["level_since_1"] == "s" and units["brake_pressure_2"] == "Pa"
    assert all(v.description for v in md.modelVariables)
    assert "adhesion monitor" in md.description


OUTPUTS = ["vehicle_level"] + [f"{q}_{k}" for k in range(1, 5) for q in (
    "creep", "adhesion_used", "adhesion_available", "adhesion_lower", "adhesion_upper", "level",
    "reason", "level_since")]
INPUTS = ["train_speed"] + [f"wheel_speed_{k}" for k in range(1, 5)] + [
    f"brake_pressure_{k}" for k in range(1, 5)]


def _against_the_per_sample_call(fmu, run, samples=3600):
    """Drive the FMU with ``run``'s signals and a per-sample monitor with the same inputs at
    the FMU's own clock (the sum of its steps); the largest relative difference of the
    outputs, and the monitor's last outputs."""
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    folder = extract(fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=folder,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="m")
    ref = AdhesionMonitor("coach_default")
    worst = 0.0
    try:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        t = 0.0
        for k in range(samples):  # 8.6 s: coasting, braking, low
            slave.setReal([vr[n] for n in INPUTS], [run["train_speed"][k],
                                                    *run["wheel_speed"][k],
                                                    *run["brake_pressure"][k]])
            h = run["time"][k] - (run["time"][k - 1] if k else 0.0)
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t += h
            out = ref.update(t, run["train_speed"][k], run["wheel_speed"][k],
                             run["brake_pressure"][k])
            got = slave.getReal([vr[n] for n in OUTPUTS])
            want = [float(ref.outputs["vehicle_level"][0])]
            for i in range(4):
                want += [out.creep[i], out.adhesion_used[i], out.estimate[i], out.lower[i],
                         out.upper[i], out.level[i], out.reason[i], out.level_since[i]]
            for a, b in zip(got, want, strict=True):
                if math.isnan(b) or math.isinf(b):
                    assert (math.isnan(a) and math.isnan(b)) or a == b
                else:
                    worst = max(worst, abs(a - b) / max(1.0, abs(b)))
        slave.terminate()
    finally:
        slave.freeInstance()
        shutil.rmtree(folder, ignore_errors=True)
    return worst, out


def test_outputs_equal_the_per_sample_call(monitor_fmu, low_run):
    worst, out = _against_the_per_sample_call(monitor_fmu, low_run)
    assert worst <= 1e-12
    assert np.any(out.level == 3)  # the run reached low


def test_builder_refuses_what_it_cannot_run(tmp_path):
    with pytest.raises(ValueError, match="pressure or torque"):
        build_monitor_fmu(tmp_path / "m.fmu", pressure=False, torque=False)
    with pytest.raises(ValueError, match="settings must be a MonitorSettings"):
        build_monitor_fmu(tmp_path / "m.fmu", settings={"threshold": 0.1})
    fmu = build_monitor_fmu(tmp_path / "t.fmu", settings=MonitorSettings(threshold=0.1),
                            pressure=False, torque=True)
    md = read_model_description(fmu)
    names = {v.name for v in md.modelVariables}
    assert "torque_1" in names and "brake_pressure_1" not in names
    assert {v.name: v.unit for v in md.modelVariables}["torque_3"] == "N.m"


def test_cli_writes_the_fmu(tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    out = tmp_path / "m.fmu"
    res = CliRunner().invoke(app, ["monitor-fmu", str(out), "--torque", "--no-pressure"])
    assert res.exit_code == 0, res.output
    assert validate_fmu(str(out)) == []
    bad = CliRunner().invoke(app, ["monitor-fmu", str(out), "--sample-period", "0"])
    assert bad.exit_code == 2 and "sample_period" in bad.output


@pytest.fixture(scope="module")
def native_fmu(tmp_path_factory):
    from railadhesion.export import NativeBuildError, build_native_monitor_fmu

    try:
        return build_native_monitor_fmu(tmp_path_factory.mktemp("nfmu") / "native.fmu")
    except NativeBuildError as exc:  # no C compiler here
        pytest.skip(str(exc))


def test_native_fmu_equals_the_per_sample_call(native_fmu, low_run):
    """The native FMU (no Python at run time) runs the same compiled step: same outputs as the
    per-sample call fed the same times (the FMU's time is the sum of its steps)."""
    import zipfile

    assert validate_fmu(str(native_fmu)) == []
    with zipfile.ZipFile(native_fmu) as z:
        names = z.namelist()
    assert "binaries/linux64/railadhesion_monitor.so" in names
    assert not any(n.endswith(".py") for n in names)  # nothing for Python to run
    worst, out = _against_the_per_sample_call(native_fmu, low_run)
    assert worst <= 1e-9
    assert np.any(out.level == 3)


def test_cli_native_flag(tmp_path, native_fmu):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    out = tmp_path / "n.fmu"
    res = CliRunner().invoke(app, ["monitor-fmu", str(out), "--native", "--threshold", "0.12"])
    assert res.exit_code == 0, res.output
    assert validate_fmu(str(out)) == []
    assert "threshold 0.12" in read_model_description(out).description
