"""The native braking-vehicle FMU (issue 25) in the C host (no Python in its process).

Reference: the stepping API (:meth:`railadhesion.braking.BrakingSimulator.step`) driven with
the same inputs in this process. The C host and its helpers are those of test_native.py.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fmpy")

from fmpy.validation import validate_fmu  # noqa: E402

from railadhesion.braking import BrakingSimulator  # noqa: E402
from railadhesion.braking.scenario import load_scenario  # noqa: E402
from railadhesion.export import build_native_braking_fmu, native  # noqa: E402

from .test_native import Unzipped, host  # noqa: E402, F401

pytestmark = [
    pytest.mark.skipif(
        not sys.platform.startswith("linux") or native.find_c_compiler() is None,
        reason="native FMUs are built for linux64 with a C compiler",
    ),
    # the example stops run from 160 km/h, above the WILAC set's calibrated 40 m/s: the
    # simulator warns of it (docs/checks.md), which is not what these tests check
    pytest.mark.filterwarnings(
    "ignore:initial_speed = .* is outside the calibrated range"
    ":railadhesion.plausibility.AlteredResultWarning"),
]

SCENARIO = Path(__file__).parents[2] / "examples" / "brake_damp.toml"
N = 4
INPUTS = [f"pressure_command_{k}" for k in range(1, N + 1)] + [f"valve_{k}"
                                                               for k in range(1, N + 1)]
OUTPUTS = (["train_speed", "distance", "deceleration", "stopped"]
           + [f"{p}_{k}" for k in range(1, N + 1) for p in
              ("wheel_speed", "brake_pressure", "creep_force", "adhesion_used", "normal_load")])


@pytest.fixture(scope="module")
def fmu(host, tmp_path_factory):  # noqa: F811
    tmp = tmp_path_factory.mktemp("native_braking")
    path = build_native_braking_fmu(tmp / "braking.fmu", SCENARIO)
    return Unzipped(path, host, tmp)


def _rows(n_steps):
    """Emergency pressure on every axle, valve commands changing (apply, hold, vent) with a
    different phase per axle."""
    rows = np.zeros((n_steps, 2 * N))
    rows[:, :N] = 5.5e5
    k = np.arange(n_steps)
    for i in range(N):
        phase = (k // 120 + i) % 6
        rows[:, N + i] = np.where(phase == 0, 2.0, np.where(phase == 1, 1.0, 0.0))
    return rows


def _reference(rows):
    sc = load_scenario(SCENARIO)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           gradient=sc.gradient, refresh_period=sc.refresh_period,
                           record=False)  # fmt: skip
    out = np.empty((len(rows), len(OUTPUTS)))
    for j, row in enumerate(rows):
        s = sim.step(0.001, {"pressure_command": row[:N],
                             "valves": row[N:].astype(np.int64)})  # fmt: skip
        out[j, :4] = s.train_speed, s.distance, s.deceleration, float(s.stopped)
        for i in range(N):
            out[j, 4 + 5 * i: 9 + 5 * i] = (s.wheel_speeds[i], s.brake_pressures[i],
                                            s.creep_forces[i], s.adhesion_used[i],
                                            s.normal_loads[i])  # fmt: skip
    return out


def test_equals_the_stepping_api_over_a_damp_rail_stop(fmu):
    rows = _rows(40000)
    status, got = fmu.sweep(INPUTS, rows, OUTPUTS)
    assert (status == 0).all()
    want = _reference(rows)
    assert got[-1, OUTPUTS.index("stopped")] == 1.0  # the whole stop, to rest
    assert want[-1, OUTPUTS.index("stopped")] == 1.0
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
    assert 50.0 < want[-1, 1]  # reached the damp section


@pytest.fixture(scope="module")
def wsp_fmu(host, tmp_path_factory):  # noqa: F811
    tmp = tmp_path_factory.mktemp("native_braking_wsp")
    path = build_native_braking_fmu(tmp / "braking_wsp.fmu", SCENARIO, wsp=True)
    return Unzipped(path, host, tmp)


WSP_INPUTS = INPUTS[:N]
WSP_OUTPUTS = OUTPUTS + [f"valve_{k}" for k in range(1, N + 1)]


def _wsp_reference(rows):
    from railadhesion.braking.wsp import WheelSlideProtection

    sc = load_scenario(SCENARIO)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           gradient=sc.gradient, refresh_period=sc.refresh_period,
                           record=False, wsp=WheelSlideProtection(sc.wsp))  # fmt: skip
    out = np.empty((len(rows), len(WSP_OUTPUTS)))
    for j, row in enumerate(rows):
        s = sim.step(0.001, {"pressure_command": row})
        out[j, :4] = s.train_speed, s.distance, s.deceleration, float(s.stopped)
        for i in range(N):
            out[j, 4 + 5 * i: 9 + 5 * i] = (s.wheel_speeds[i], s.brake_pressures[i],
                                            s.creep_forces[i], s.adhesion_used[i],
                                            s.normal_loads[i])  # fmt: skip
        out[j, 4 + 5 * N:] = s.valves
    return out


def test_built_in_wsp_equals_the_stepping_api_over_a_damp_rail_stop(wsp_fmu):
    """The scenario's WSP inside the FMU: the valves are outputs, the pressure commands change
    (a partial release on axles 3-4 for 2 s), the WSP holds and vents on the damp section."""
    assert wsp_fmu.md.modelVariables[wsp_fmu.vr["valve_1"]].causality == "output"
    n_steps = 45000
    rows = np.full((n_steps, N), 5.5e5)
    rows[8000:10000, 2:] = 2.5e5
    status, got = wsp_fmu.sweep(WSP_INPUTS, rows, WSP_OUTPUTS)
    assert (status == 0).all()
    want = _wsp_reference(rows)
    stop = int(np.argmax(want[:, 3] == 1.0))
    assert stop > 0 and got[-1, 3] == 1.0  # the whole stop, to rest
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
    valves = want[:stop, 4 + 5 * N:]
    assert (valves == 2.0).any() and (valves == 1.0).any()  # the WSP vented and held
    assert 50.0 < want[-1, 1]  # reached the damp section
    # the binary's generic x86-64 code (forced) gives the same numbers, bit for bit, as the
    # x86-64-v3 code it runs on processors that have it
    status_generic, generic = wsp_fmu.sweep(WSP_INPUTS, rows, WSP_OUTPUTS,
                                            env={"RAILADHESION_FMU_GENERIC": "1"})
    assert (status_generic == 0).all()
    assert np.array_equal(generic, got)


def test_built_in_wsp_rollback_and_no_valve_inputs(wsp_fmu):
    v = wsp_fmu.vr
    sets = "".join(f"set 0 {v[f'pressure_command_{k}']} 550000\n" for k in range(1, N + 1))
    steps = "".join(f"step 0 {j * 1e-3!r} 0.001\n" for j in range(300))
    lines, err = wsp_fmu.run(f"new 0\ninit 0\n{sets}{steps}save 0 0\n{steps}"
                             f"get 0 {v['train_speed']}\nload 0 0\n{steps}"
                             f"get 0 {v['train_speed']}\nset 0 {v['valve_1']} 2\n")  # fmt: skip
    gets = [line for line in lines if line.startswith("get")]
    assert gets[0] == gets[1]  # the WSP's state is rolled back with the vehicle
    assert lines[-1] == "set 0 3"
    assert "fmi2SetReal: valve_1 is an output" in err


def test_state_rollback_gives_identical_results(fmu):
    v = fmu.vr
    speed, valve = v["train_speed"], v["valve_1"]
    sets = "".join(f"set 0 {v[f'pressure_command_{k}']} 550000\n" for k in range(1, N + 1))
    steps = "".join(f"step 0 {j * 1e-3!r} 0.001\n" for j in range(300))
    vent = f"set 0 {valve} 2\n"
    lines, _ = fmu.run(f"new 0\ninit 0\n{sets}{steps}save 0 0\n{vent}{steps}get 0 {speed}\n"
                       f"load 0 0\n{vent}{steps}get 0 {speed}\nload 0 0\n"
                       f"set 0 {valve} 0\n{steps}get 0 {speed}\n")  # fmt: skip
    # the FMU state holds the inputs too: the valve is set again after each load
    gets = [line for line in lines if line.startswith("get")]
    assert gets[0] == gets[1]  # rolled back, same inputs: bit-identical
    assert gets[2] != gets[0]  # other inputs after the rollback: another result
    assert all(line.split()[2] == "0" for line in lines if line.startswith(("step", "load")))


@pytest.mark.parametrize(("name", "value", "message"), [
    ("pressure_command_2", "nan", "fmi2SetReal: pressure_command_2 = NaN"),
    ("valve_3", "3", "fmi2SetReal: valve_3 = 3 is out of range [0, 2]"),
])  # fmt: skip
def test_bad_input_is_an_error_naming_the_variable(fmu, name, value, message):
    lines, err = fmu.run(f"new 0\ninit 0\nset 0 {fmu.vr[name]} {value}\n")
    assert lines[-1] == "set 0 3"
    assert message in err


def test_fmpy_validates(fmu):
    assert validate_fmu(str(fmu.fmu)) == []


def test_cli_writes_a_native_braking_fmu(tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    out = tmp_path / "b.fmu"
    result = CliRunner().invoke(app, ["export", "braking-fmu", str(SCENARIO), "--out", str(out),
                                      "--native"])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "passes FMPy's validation" in result.output
    import zipfile

    names = zipfile.ZipFile(out).namelist()
    assert "binaries/linux64/railadhesion_braking.so" in names
    assert "sources/buildDescription.xml" in names


def test_cli_default_is_native_with_or_without_the_built_in_wsp(tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    out = tmp_path / "w.fmu"
    result = CliRunner().invoke(app, ["export", "braking-fmu", str(SCENARIO), "--out", str(out),
                                      "--wsp"])  # fmt: skip
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "valve_k are outputs" in text and "needs no Python on the host" in text
    py = CliRunner().invoke(app, ["export", "braking-fmu", str(SCENARIO), "--out",
                                  str(tmp_path / "p.fmu"), "--wsp", "--python"])  # fmt: skip
    assert py.exit_code == 0, py.output
    text = " ".join(py.output.split())
    assert "valve_k are outputs" in text and "Python FMU: the host needs a Python" in text


def test_two_instances_side_by_side_and_no_allocation_in_steps(fmu):
    v = fmu.vr
    speed, valve = v["train_speed"], v["valve_2"]
    sets = "".join(f"set {i} {v[f'pressure_command_{k}']} 550000\n" for i in (0, 1)
                   for k in range(1, N + 1))  # fmt: skip
    steps = "".join(f"step 0 {j * 1e-3!r} 0.001\nstep 1 {j * 1e-3!r} 0.001\n"
                    for j in range(200))  # fmt: skip
    lines, _ = fmu.run(f"new 0\nnew 1\ninit 0\ninit 1\n{sets}set 1 {valve} 2\nallocs\n{steps}"
                       f"allocs\nget 0 {speed}\nget 1 {speed}\n")  # fmt: skip
    allocs = [line for line in lines if line.startswith("allocs")]
    assert allocs[0] == allocs[1]  # nothing allocated while stepping
    gets = [float(line.split()[3]) for line in lines if line.startswith("get")]
    assert gets[0] < gets[1]  # instance 1 vents axle 2: it brakes less than instance 0
    assert all(line.split()[2] == "0" for line in lines if line.startswith("step"))


@pytest.mark.parametrize("h", ["0", "-0.001", "nan"])
def test_step_size_must_be_positive(fmu, h):
    lines, err = fmu.run(f"new 0\ninit 0\nstep 0 0 {h}\n")
    assert lines[-1] == "step 0 3"
    assert "fmi2DoStep: communicationStepSize must be > 0 and finite" in err


def test_a_model_it_does_not_compile_is_a_native_unsupported_case():
    """An adhesion model evaluated in Python (here WILAC with compiled=False) is not served by
    the native FMU: NativeUnsupported (a NativeBuildError), which the CLI's default answers
    with the Python FMU."""
    from railadhesion.export import NativeBuildError, NativeUnsupported
    from railadhesion.export.native_braking import braking_step_model

    sc = load_scenario(SCENARIO)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           record=False, compiled=False)  # fmt: skip
    with pytest.raises(NativeUnsupported, match="use the Python braking FMU"):
        braking_step_model(sim)
    assert issubclass(NativeUnsupported, NativeBuildError)
