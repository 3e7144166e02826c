"""The braking-vehicle FMU (issue 11 item 2): built, validated and run with FMPy, a client
written elsewhere, and checked step by step against the stepping API driven directly."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from railadhesion.braking import BrakingSimulator  # noqa: E402
from railadhesion.braking.scenario import load_scenario  # noqa: E402
from railadhesion.export import build_braking_fmu  # noqa: E402

# the example stops run from 160 km/h, above the WILAC set's calibrated 40 m/s: the simulator
# warns of it (docs/checks.md), which is not what these tests check
pytestmark = pytest.mark.filterwarnings(
    "ignore:initial_speed = .* is outside the calibrated range"
    ":railadhesion.plausibility.AlteredResultWarning")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
OUTPUTS = ["train_speed", "distance", "deceleration", "stopped"] + [
    f"{q}_{k}" for q in ("wheel_speed", "brake_pressure", "creep_force", "adhesion_used",
                         "normal_load") for k in range(1, 5)
]  # fmt: skip


def _reference(state):
    return [state.train_speed, state.distance, state.deceleration, float(state.stopped),
            *state.wheel_speeds, *state.brake_pressures, *state.creep_forces,
            *state.adhesion_used, *state.normal_loads]  # fmt: skip


def _simulator(path):
    sc = load_scenario(path)
    return BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                            gradient=sc.gradient, refresh_period=sc.refresh_period,
                            record=False)  # fmt: skip


class _Slave:
    def __init__(self, fmu):
        md = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.md = md
        self.dir = extract(fmu)
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=self.dir,
                           modelIdentifier=md.coSimulation.modelIdentifier, instanceName="b")
        self.s.instantiate()
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def step(self, t, h, command, valves):
        self.s.setReal([self.vr[f"pressure_command_{k}"] for k in range(1, 5)], command)
        self.s.setReal([self.vr[f"valve_{k}"] for k in range(1, 5)], [float(v) for v in valves])
        return self.s.doStep(currentCommunicationPoint=t, communicationStepSize=h)

    def outputs(self):
        return self.s.getReal([self.vr[o] for o in OUTPUTS])

    def close(self):
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture(scope="module")
def damp_fmu(tmp_path_factory):
    return build_braking_fmu(tmp_path_factory.mktemp("fmu") / "brake.fmu",
                             EXAMPLES / "brake_damp.toml")


def test_model_description_passes_fmpys_validator(damp_fmu):
    assert validate_fmu(str(damp_fmu)) == []
    md = read_model_description(damp_fmu)
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    assert inputs == [f"{n}_{k}" for k in range(1, 5) for n in ("pressure_command", "valve")]
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["wheel_speed_1"] == "rad/s" and units["brake_pressure_4"] == "Pa"
    assert all(v.description for v in md.modelVariables)
    assert "scenario" in md.description


def test_outputs_equal_the_stepping_api_with_inputs_changing_every_step(damp_fmu):
    """Pressure ramp, valves cycling apply/hold/vent on one axle and pulsing on another."""
    slave = _Slave(damp_fmu)
    sim = _simulator(EXAMPLES / "brake_damp.toml")
    h, t, worst = 1e-3, 0.0, 0.0
    try:
        for i in range(800):
            command = [5.5e5 * min(1.0, i / 200.0) * (1.0 - 0.1 * k) for k in range(4)]
            valves = [0, 0, (i // 100) % 3, 1 if i % 7 == 0 else 0]
            slave.step(t, h, command, valves)  # FMPy raises if the step fails
            t += h
            state = sim.step(h, {"pressure_command": np.array(command),
                                 "valves": np.array(valves)})  # fmt: skip
            got, ref = slave.outputs(), _reference(state)
            pairs = zip(got, ref, strict=True)
            worst = max(worst, max(abs(a - b) / max(1.0, abs(b)) for a, b in pairs))
    finally:
        slave.close()
    assert worst <= 1e-12
    assert 0 < ref[1] < 40.0  # it moved, and braked (initial speed 44.4 m/s for 0.8 s)
    assert ref[8 + 2] < ref[8 + 1]  # axle 3 held and vented: less pressure than axle 2


def test_a_short_stop_completes(tmp_path):
    text = (EXAMPLES / "brake_dry.toml").read_text(encoding="utf-8")
    text = text.replace("initial_speed_m_s = ", "initial_speed_m_s = 3.0  # ", 1)
    scenario = tmp_path / "slow.toml"
    scenario.write_text(text, encoding="utf-8")
    fmu = build_braking_fmu(tmp_path / "slow.fmu", scenario)
    slave = _Slave(fmu)
    try:
        t, h = 0.0, 5e-3
        for _ in range(2000):
            slave.step(t, h, [4e5] * 4, [0] * 4)
            t += h
            out = dict(zip(OUTPUTS, slave.outputs(), strict=True))
            if out["stopped"] == 1.0:
                break
    finally:
        slave.close()
    assert out["stopped"] == 1.0
    assert out["train_speed"] < 0.1 and out["distance"] > 0.0


def test_scenario_that_does_not_load_on_its_own_is_refused(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((EXAMPLES / "brake_dry.toml").read_text(encoding="utf-8").replace(
        'file = "coach_default"', 'file = "my_vehicle.toml"'), encoding="utf-8")
    with pytest.raises(ValueError, match="does not load on its own"):
        build_braking_fmu(tmp_path / "x.fmu", bad)
    with pytest.raises(ValueError, match="scenario must be an existing TOML file"):
        build_braking_fmu(tmp_path / "x.fmu", tmp_path / "missing.toml")


def test_cli_writes_a_validated_braking_fmu(tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    out = tmp_path / "b.fmu"
    result = CliRunner().invoke(app, ["export", "braking-fmu", str(EXAMPLES / "brake_dry.toml"),
                                      "--python", "--out", str(out)])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert out.is_file() and "passes FMPy's validation" in result.output
    bad = CliRunner().invoke(app, ["export", "braking-fmu", str(tmp_path / "none.toml")])
    assert bad.exit_code == 2 and "scenario must be an existing TOML file" in bad.output


def test_built_in_wsp_equals_the_stepping_api(tmp_path):
    """wsp=True: the package's WSP inside the Python FMU, valve_k outputs, the same numbers as
    the stepping API of a simulator built with the scenario's WSP (2 s of the damp stop: the
    WSP holds from about 1.2 s, on the damp section)."""
    from railadhesion.braking.wsp import WheelSlideProtection

    path = EXAMPLES / "brake_damp.toml"
    fmu = build_braking_fmu(tmp_path / "w.fmu", path, wsp=True)
    assert validate_fmu(str(fmu)) == []
    slave = _Slave(fmu)
    causality = {v.name: v.causality for v in slave.md.modelVariables}
    assert causality["valve_1"] == "output" and causality["pressure_command_1"] == "input"
    sc = load_scenario(path)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           gradient=sc.gradient, refresh_period=sc.refresh_period,
                           record=False, wsp=WheelSlideProtection(sc.wsp))  # fmt: skip
    valve_refs = [slave.vr[f"valve_{k}"] for k in range(1, 5)]
    acted = False
    try:
        for j in range(2000):
            command = [5.5e5 if j < 1500 else 4e5] * 4
            slave.s.setReal([slave.vr[f"pressure_command_{k}"] for k in range(1, 5)], command)
            slave.s.doStep(currentCommunicationPoint=j * 1e-3, communicationStepSize=1e-3)
            state = sim.step(1e-3, {"pressure_command": command})
            np.testing.assert_allclose(slave.outputs(), _reference(state), rtol=1e-12,
                                       atol=1e-12)  # fmt: skip
            valves = slave.s.getReal(valve_refs)
            assert valves == [float(v) for v in state.valves]
            acted |= any(v != 0.0 for v in valves)
    finally:
        slave.s.terminate()
        slave.s.freeInstance()
        shutil.rmtree(slave.dir, ignore_errors=True)
    assert acted  # the WSP held or vented
