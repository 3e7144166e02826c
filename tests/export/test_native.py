"""Native FMUs (issue 25): compiled ahead of time, run by a C host with no Python in its process.

The C host (``data/fmi2_host.c``, script mode) is compiled here and runs each FMU in a
subprocess without any preload or Python variable in its environment; it reports whether any
Python or numba library is mapped into it. Its outputs are compared with the library's
functions called here. FMPy's validator and FMPy's simulation check the same FMUs from Python.

A stand-in stepping model (one bogie, two wheelsets braking on Polach's law, explicit Euler)
exercises the generic part that the braking vehicle will use: a step function on named
records, an init function, integer inputs, sub-array fields, FMU states. It is not the braking
integrator; its reference is the same step compiled by numba in this process.
"""

from __future__ import annotations

import ctypes
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from numba import carray

fmpy = pytest.importorskip("fmpy")

from fmpy import read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import railadhesion  # noqa: E402
from railadhesion.export import (  # noqa: E402
    FmuVariable,
    NativeBuildError,
    build_native_creep_force_fmu,
    native,
)
from railadhesion.export.native import (  # noqa: E402
    ALLOWED_SYMBOLS,
    INIT_SIGNATURE,
    STEP_SIGNATURE,
    RecordVariable,
    StepModel,
    build_step_fmu,
    c_initializer,
    c_struct,
    compile_functions,
    undefined_symbols,
)
from railadhesion.models import default_wilac_parameters, polach_parameters  # noqa: E402
from railadhesion.models.kernels import polach_scalar  # noqa: E402

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux") or native.find_c_compiler() is None,
    reason="native FMUs are built for linux64 with a C compiler",
)

INPUTS = ["creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b"]
OUTPUTS = ["Fx", "Fy", "adhesion"]
POLACH_SET = "polach2005_wet"
# What the FMU binary may import: libm (via the compiled law and the layer's nearbyint) and
# these C library functions of the FMI layer. Nothing allocates: no malloc, calloc, free.
LAYER_LIBC = {"getenv", "memcpy", "memset", "strcmp", "strlen", "vsnprintf"}


# --------------------------------------------------------------------------------------------
# Fixtures and the C host


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    exe = tmp_path_factory.mktemp("host") / "fmi2_host"
    source = Path(__file__).with_name("data") / "fmi2_host.c"
    subprocess.run([*native.find_c_compiler(), "-O2", "-o", str(exe), str(source), "-ldl"],
                   check=True, timeout=120)  # fmt: skip
    return exe


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("native")
    return {
        "wilac": build_native_creep_force_fmu(tmp / "wilac.fmu", "wilac"),
        "polach": build_native_creep_force_fmu(tmp / "polach.fmu", "polach",
                                               parameter_set=POLACH_SET),  # fmt: skip
    }


class Unzipped:
    """An extracted FMU and the C host that runs it."""

    def __init__(self, fmu, host, where):
        self.fmu = Path(fmu)
        self.host = host
        self.dir = where / self.fmu.stem
        with zipfile.ZipFile(fmu) as z:
            z.extractall(self.dir)
        self.md = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        identifier = self.md.coSimulation.modelIdentifier
        self.binary = self.dir / "binaries" / "linux64" / f"{identifier}.so"

    def run(self, commands: str, binary=None, env=None):
        """Run the host in script mode with no Python in its environment (plus ``env``);
        (stdout lines, stderr)."""
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")
               and k not in ("LD_PRELOAD", "LD_LIBRARY_PATH", "RAILADHESION_FMU_GENERIC")
               } | dict(env or {})  # fmt: skip
        args = [str(self.host), "--script", str(binary or self.binary),
                (self.dir / "resources").as_uri(), self.md.guid]  # fmt: skip
        out = subprocess.run(args, input=commands, capture_output=True, text=True, env=env,
                             timeout=600)  # fmt: skip
        assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
        return out.stdout.splitlines(), out.stderr

    def refs(self, names):
        return " ".join(str(self.vr[n]) for n in names)

    def sweep(self, inputs: list[str], rows, outputs, instance=0, binary=None, setup="",
              env=None):
        """setReal(inputs), doStep(1 ms), getReal(outputs) for each row; (status, values)."""
        table = "\n".join(" ".join(repr(float(x)) for x in row) for row in rows)
        commands = (f"new {instance}\n{setup}init {instance}\nsweep {instance} {len(inputs)} "
                    f"{self.refs(inputs)} {len(outputs)} {self.refs(outputs)} {len(rows)}\n"
                    f"{table}\nmaps\n")  # fmt: skip
        lines, err = self.run(commands, binary, env)
        assert lines[0] == f"new {instance} ok", err[-2000:]
        assert lines[-1] == "maps 0"  # no Python, no numba in the host process
        body = [line.split() for line in lines[-1 - len(rows) : -1]]
        return np.array([int(b[0]) for b in body]), np.array([[float(v) for v in b[1:]]
                                                              for b in body])  # fmt: skip


@pytest.fixture(scope="module")
def unzipped(fmus, host, tmp_path_factory):
    where = tmp_path_factory.mktemp("unzipped")
    return {model: Unzipped(path, host, where) for model, path in fmus.items()}


def _inputs(model):
    return INPUTS + (["water_flow"] if model == "wilac" else [])


def _params(model):
    return default_wilac_parameters() if model == "wilac" else polach_parameters(POLACH_SET)


def _library(model, row):
    """The library called directly with one row of inputs: (Fx, Fy, adhesion); a normal
    force <= 0 (lift-off) gives zeros, as the FMUs document."""
    x = dict(zip(_inputs(model), row, strict=True))
    if x["normal_force"] <= 0.0:
        return 0.0, 0.0, 0.0
    p = _params(model)
    if model == "wilac":
        fx, fy = railadhesion.wilac_forces(*row, p)
    else:
        fx, fy = railadhesion.polach_forces(*row, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A,
                                            B=p.B)  # fmt: skip
    return float(fx), float(fy), float(railadhesion.adhesion(fx, fy, x["normal_force"]))


def _hard_inputs(model, n, seed):
    """n rows over and beyond the working range: creep 0 (10 %), full slide |creep| = 1
    (10 %), creepages from 1e-9 to 1 in magnitude, pure spin, large spin, zero and negative
    load (lift-off), a tiny load, speed 0, a/b from 0.05 to 20, water 0 and across the WILAC
    transitions up to 400 µl/s."""
    rng = np.random.default_rng(seed)
    kind = rng.integers(0, 10, n)
    sign = rng.choice([-1.0, 1.0], n)
    creep_long = np.where(kind < 4, rng.uniform(-0.05, 0.05, n),
                          sign * 10.0 ** rng.uniform(-9, 0, n))  # fmt: skip
    creep_long[kind == 4] = 0.0
    creep_long[kind == 5] = sign[kind == 5]  # full slide: a locked wheel, or spinning
    creep_lat = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(-0.05, 0.05, n))
    spin = np.select([rng.random(n) < 0.4, rng.random(n) < 0.5], [0.0, rng.uniform(-5, 5, n)],
                     rng.uniform(-60, 60, n))  # fmt: skip
    pure_spin = kind == 6
    creep_long[pure_spin] = 0.0
    creep_lat[pure_spin] = 0.0
    spin[pure_spin] = rng.uniform(-5, 5, pure_spin.sum())
    normal_force = rng.uniform(1e3, 2e5, n)
    normal_force[kind == 7] = 0.0
    normal_force[(kind == 8) & (rng.random(n) < 0.5)] = -5e3
    normal_force[(kind == 9) & (rng.random(n) < 0.3)] = 1e-3
    speed = np.where(rng.random(n) < 0.05, 0.0, rng.uniform(0.0, 100.0, n))
    a = rng.uniform(1e-3, 2e-2, n)
    b = rng.uniform(1e-3, 2e-2, n)
    columns = [creep_long, creep_lat, spin, normal_force, speed, a, b]
    if model == "wilac":
        water = np.select([rng.random(n) < 0.2, rng.random(n) < 0.5],
                          [0.0, rng.uniform(0.0, 60.0, n)], rng.uniform(0, 400, n))  # fmt: skip
        columns.append(water)
    return np.column_stack(columns)


# --------------------------------------------------------------------------------------------
# Equal to the library


# The hard inputs span the whole domain the FMU accepts (huge loads, speeds beyond WILAC's
# calibrated range): the library's plausibility warnings are expected there.
_DOMAIN = pytest.mark.filterwarnings("ignore::railadhesion.plausibility.RailadhesionWarning")


@_DOMAIN
@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_equals_the_library_on_10000_hard_inputs(unzipped, model):
    """The native FMU, run by a C host with no Python, equals polach_forces / wilac_forces to
    1e-12 relative on 10^4 inputs with creep 0, full slide, spin and zero load."""
    fmu = unzipped[model]
    rows = _hard_inputs(model, 10_000, seed=25)
    status, got = fmu.sweep(_inputs(model), rows, OUTPUTS)
    assert (status == 0).all()
    want = np.array([_library(model, row) for row in rows])
    error = np.abs(got - want)
    assert (error <= 1e-12 * np.abs(want)).all(), (
        f"max relative error {np.max(error / np.maximum(np.abs(want), 1e-300)):.3g} at "
        f"{rows[np.argmax(error.max(axis=1))]}"
    )
    # the hard cases were there
    assert (rows[:, 0] == 0).sum() > 500 and (np.abs(rows[:, 0]) == 1).sum() > 500
    assert (rows[:, 3] == 0).sum() > 500 and (got[rows[:, 3] <= 0] == 0).all()
    assert ((rows[:, 0] == 0) & (rows[:, 1] == 0) & (rows[:, 2] != 0)).sum() > 500


@_DOMAIN
@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_outputs_follow_the_inputs_without_a_step(unzipped, model):
    fmu = unzipped[model]
    row = _hard_inputs(model, 1, seed=3)[0]
    row[3] = 8e4
    sets = "".join(f"set 0 {fmu.vr[n]} {float(v)!r}\n" for n, v in zip(_inputs(model), row,
                                                                        strict=True))  # fmt: skip
    lines, _ = fmu.run(f"new 0\ninit 0\n{sets}get 0 {fmu.refs(OUTPUTS)}\n")
    got = [float(v) for v in lines[-1].split()[3:]]
    assert lines[-1].split()[:3] == ["get", "0", "0"]
    assert got == pytest.approx(_library(model, row), rel=1e-12, abs=0)


def test_elastic_constants_are_parameters(unzipped):
    fmu = unzipped["polach"]
    row = [0.002, 0.0, 0.0, 1e5, 10.0, 6e-3, 9e-3]
    setup = f"set 0 {fmu.vr['shear_modulus']} 7e10\nset 0 {fmu.vr['poisson']} 0.3\n"
    _, got = fmu.sweep(INPUTS, [row], ["Fx"], setup=setup)
    p = polach_parameters(POLACH_SET)
    fx, _ = railadhesion.polach_forces(*row, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B,
                                       shear_modulus=7e10, poisson=0.3)  # fmt: skip
    assert got[0, 0] == pytest.approx(float(fx), rel=1e-12, abs=0)
    default = railadhesion.polach_forces(*row, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A, B=p.B)
    assert abs(got[0, 0] - default[0]) > 1.0  # the parameters did reach the law


def test_two_instances_side_by_side_and_determinism(unzipped):
    """Two instances in one process, steps interleaved, each with its own inputs and elastic
    constants, give what each gives alone; the same run twice gives the same bytes."""
    fmu = unzipped["wilac"]
    rows = _hard_inputs("wilac", 200, seed=7)
    rows[:, 3] = np.abs(rows[:, 3]) + 1e3
    ins, outs = fmu.refs(_inputs("wilac")), fmu.refs(OUTPUTS)
    alone0 = fmu.sweep(_inputs("wilac"), rows[::2], OUTPUTS)[1]
    alone1 = fmu.sweep(_inputs("wilac"), rows[1::2], OUTPUTS,
                       setup=f"set 0 {fmu.vr['poisson']} 0.25\n")[1]  # fmt: skip
    commands = [f"new 0\nnew 1\ninit 0\nset 1 {fmu.vr['poisson']} 0.25\ninit 1\n"]
    for k, row in enumerate(rows):
        i = k % 2
        commands.append(f"sweep {i} {len(row)} {ins} 3 {outs} 1\n"
                        + " ".join(repr(float(v)) for v in row) + "\n")  # fmt: skip
    lines, err = fmu.run("".join(commands))
    assert lines[:5] == ["new 0 ok", "new 1 ok", "init 0 0", "set 1 0", "init 1 0"]
    results = [[float(v) for v in line.split()[1:]] for line in lines[5:]]
    assert np.array_equal(np.array(results[0::2]), alone0), err[-1000:]
    assert np.array_equal(np.array(results[1::2]), alone1)
    assert fmu.run("".join(commands))[0] == lines


@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_the_law_in_the_binary_is_the_packages(unzipped, model):
    """Another parameter set gives other numbers: the set is compiled in, not looked up."""
    fmu = unzipped[model]
    row = _hard_inputs(model, 1, seed=5)[0]
    row[:5] = [0.01, 0.0, 0.0, 5e4, 20.0]
    _, got = fmu.sweep(_inputs(model), [row], OUTPUTS)
    assert got[0].tolist() == pytest.approx(_library(model, row), rel=1e-12, abs=0)
    if model == "polach":
        other = polach_parameters("polach2005_dry")
        fx, _ = railadhesion.polach_forces(*row, mu0=other.mu0, k_A=other.k_A, k_S=other.k_S,
                                           A=other.A, B=other.B)  # fmt: skip
        assert abs(got[0, 0] - fx) > 100.0


# --------------------------------------------------------------------------------------------
# No Python, no allocation


@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_binary_needs_only_libc_and_libm(unzipped, model):
    needed = {name.split("@")[0] for name in undefined_symbols(unzipped[model].binary.read_bytes())}
    weak = {"_ITM_deregisterTMCloneTable", "_ITM_registerTMCloneTable", "__cxa_finalize",
            "__gmon_start__"}  # fmt: skip (glibc start-up, weak)
    assert needed - weak <= ALLOWED_SYMBOLS | LAYER_LIBC, needed - weak - ALLOWED_SYMBOLS
    assert not any(n.startswith(("Py", "_Py", "numba", "NRT")) for n in needed)
    assert not needed & {"malloc", "calloc", "realloc", "free"}


def test_undefined_symbols_agrees_with_nm(unzipped):
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("nm is not installed")
    binary = unzipped["wilac"].binary
    out = subprocess.run([nm, "-D", "--undefined-only", str(binary)], capture_output=True,
                         text=True, check=True)  # fmt: skip
    listed = {line.split()[-1].split("@")[0] for line in out.stdout.splitlines() if line.strip()}
    assert listed == set(undefined_symbols(binary.read_bytes()))


@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_binary_loads_on_glibc_2_14(unzipped, model):
    """libm's functions are bound to their first x86-64 versions (exp@GLIBC_2.29 and
    hypot@GLIBC_2.35 would keep the binary off older systems); memcpy needs 2.14."""
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("nm is not installed")
    out = subprocess.run([nm, "-D", "--undefined-only", str(unzipped[model].binary)],
                         capture_output=True, text=True, check=True).stdout  # fmt: skip
    versions = [tuple(int(x) for x in v.split(".")) for v in
                re.findall(r"@GLIBC_([0-9.]+)", out)]  # fmt: skip
    assert versions and max(versions) <= (2, 14), out


def test_no_allocation_in_set_step_get(unzipped):
    fmu = unzipped["wilac"]
    rows = _hard_inputs("wilac", 50, seed=1)
    rows[:, 3] = np.abs(rows[:, 3]) + 1e3
    table = "\n".join(" ".join(repr(float(x)) for x in row) for row in rows)
    lines, _ = fmu.run(f"new 0\ninit 0\nallocs\nbench 0 8 {fmu.refs(_inputs('wilac'))} 3 "
                       f"{fmu.refs(OUTPUTS)} 50 20\n{table}\nfree 0\nallocs\n")  # fmt: skip
    assert lines[2] == "allocs 2 0"  # the instance and a copy of its name
    bench = lines[3].split()
    assert bench[0] == "bench" and bench[3] == "0" and bench[4] == "0"  # 0 allocations, OK
    assert lines[-1] == "allocs 2 2"


# --------------------------------------------------------------------------------------------
# Bad input: refused, logged, named


def _error(fmu, commands, expected_status_line, message):
    lines, err = fmu.run(commands)
    assert expected_status_line in lines, lines
    assert message in err, err
    return lines, err


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("creep_long", "nan", "fmi2SetReal: creep_long = NaN"),
        ("spin", "-inf", "fmi2SetReal: spin = -inf is not finite"),
        ("speed", "-1", "fmi2SetReal: speed = -1 is out of range [0, inf)"),
        ("a", "0", "fmi2SetReal: a = 0 is out of range (0, inf)"),
        ("b", "-0.001", "fmi2SetReal: b = -0.001 is out of range (0, inf)"),
        ("water_flow", "-5", "fmi2SetReal: water_flow = -5 is out of range [0, inf)"),
        ("Fx", "1", "fmi2SetReal: Fx is an output"),
    ],
)
def test_bad_input_is_an_error_naming_the_variable(unzipped, name, value, message):
    fmu = unzipped["wilac"]
    lines, _ = _error(fmu, f"new 0\ninit 0\nset 0 {fmu.vr[name]} {value}\nstep 0 0 0.001\n"
                           f"reset 0\ninit 0\nstep 0 0 0.001\n",
                      "set 0 3", message)  # fmt: skip
    # after the error the instance refuses to step until it is reset; then it works again
    assert lines[3:] == ["step 0 3", "reset 0 0", "init 0 0", "step 0 0"]


def test_bad_parameters_are_refused_and_fixed_after_initialisation(unzipped):
    fmu = unzipped["polach"]
    _error(fmu, f"new 0\nset 0 {fmu.vr['poisson']} 0.6\n", "set 0 3",
           "fmi2SetReal: poisson = 0.59999999999999998 is out of range [0, 0.5]")  # fmt: skip
    _error(fmu, f"new 0\ninit 0\nset 0 {fmu.vr['shear_modulus']} 8e10\n", "set 0 3",
           "shear_modulus is a fixed parameter")  # fmt: skip
    _error(fmu, "new 0\ninit 0\nset 0 99 1\n", "set 0 3", "unknown value reference 99")


@pytest.mark.parametrize("h", ["0", "-0.001", "inf", "nan"])
def test_step_size_must_be_positive(unzipped, h):
    fmu = unzipped["polach"]
    _error(fmu, f"new 0\ninit 0\nstep 0 0 {h}\n", "step 0 3",
           "fmi2DoStep: communicationStepSize must be > 0 and finite")  # fmt: skip


def test_a_over_b_outside_kalkers_range_fails_the_step(unzipped):
    for model in ("polach", "wilac"):
        fmu = unzipped[model]
        _error(fmu, f"new 0\ninit 0\nset 0 {fmu.vr['a']} 1e-160\nset 0 {fmu.vr['b']} 1\n"
                    "step 0 0 0.001\n", "step 0 3",
               "a/b outside the range of Kalker's coefficients")  # fmt: skip


def test_wrong_guid_returns_null_with_a_reason(unzipped):
    fmu = unzipped["wilac"]
    lines, err = fmu.run("new 0 {00000000-0000-0000-0000-000000000000}\n")
    assert lines == ["new 0 null"]
    assert "fmi2Instantiate: wrong GUID {00000000-0000-0000-0000-000000000000}" in err
    assert fmu.md.guid in err


def test_no_resource_is_read(unzipped, tmp_path):
    """Everything is compiled in: a resource location that does not exist is no error."""
    fmu = unzipped["polach"]
    args = [str(fmu.host), "--script", str(fmu.binary), (tmp_path / "nowhere").as_uri(),
            fmu.md.guid]  # fmt: skip
    out = subprocess.run(args, input="new 0\ninit 0\nstep 0 0 0.001\n", capture_output=True,
                         text=True, timeout=60)  # fmt: skip
    assert out.stdout.split("\n")[:3] == ["new 0 ok", "init 0 0", "step 0 0"]


def test_fmu_state_rollback_and_serialisation(unzipped):
    fmu = unzipped["polach"]
    x = fmu.vr["creep_long"]
    lines, _ = fmu.run(f"new 0\ninit 0\nset 0 {x} 0.01\nstep 0 0 0.001\nsave 0 0\n"
                       f"set 0 {x} 0.05\nstep 0 0.001 0.001\nget 0 {fmu.vr['Fx']}\n"
                       f"load 0 0\nget 0 {fmu.vr['Fx']}\nroundtrip 0 0\nset 0 {x} 0.05\n"
                       f"load 0 0\nget 0 {fmu.vr['Fx']}\ndrop 0 0\nallocs\n")  # fmt: skip
    after, restored, deserialised = lines[7], lines[9], lines[13]
    assert restored == deserialised != after
    assert float(restored.split()[3]) == pytest.approx(
        _library("polach", [0.01, 0, 0, 1e5, 10.0, 6.3e-3, 12.6e-3])[0], rel=1e-12)
    assert lines[-1] == "allocs 4 2"  # instance, name, state, deserialised state


# --------------------------------------------------------------------------------------------
# FMPy: validator, simulation, FMU states


@pytest.mark.parametrize("model", ["polach", "wilac"])
def test_fmpy_validates_the_model_description(fmus, model):
    assert validate_fmu(str(fmus[model])) == []


@_DOMAIN
def test_fmpy_simulation_with_inputs_changing_every_step(fmus):
    rows = _hard_inputs("wilac", 100, seed=11)
    rows[:, 3] = np.abs(rows[:, 3]) + 1e3
    names = _inputs("wilac")
    signal = np.zeros(len(rows), dtype=[("time", float)] + [(n, float) for n in names])
    signal["time"] = np.arange(len(rows)) * 1e-3
    for k, n in enumerate(names):
        signal[n] = rows[:, k]
    result = simulate_fmu(str(fmus["wilac"]), stop_time=signal["time"][-1], output_interval=1e-3,
                          input=signal, output=names + OUTPUTS)  # fmt: skip
    # FMPy records, after each step, the inputs the step used (those of the previous time)
    np.testing.assert_array_equal(result["creep_long"][1:], signal["creep_long"][:-1])
    for row in result:
        x = [float(row[n]) for n in names]
        assert [row[o] for o in OUTPUTS] == pytest.approx(_library("wilac", x), rel=1e-12, abs=0)


def test_fmpy_low_level_states(fmus, tmp_path):
    path = fmus["polach"]
    md = read_model_description(path)
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(tmp_path), instanceName="s",
                      modelIdentifier=md.coSimulation.modelIdentifier)  # fmt: skip
    slave.instantiate()
    slave.setDebugLogging(True, ["logStatusError", "logAll"])
    with pytest.raises(Exception, match="fmi2SetDebugLogging"):  # FMPy's FMICallException
        slave.setDebugLogging(True, ["logNothing"])
    slave.reset()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    slave.setReal([vr["creep_long"]], [0.02])
    slave.doStep(0.0, 1e-3)
    state = slave.getFMUstate()
    blob = slave.serializeFMUstate(state)
    before = slave.getReal([vr["Fx"]])
    slave.setReal([vr["creep_long"]], [-0.02])
    slave.doStep(1e-3, 1e-3)
    assert slave.getReal([vr["Fx"]]) != before
    slave.setFMUstate(slave.deSerializeFMUstate(blob))
    assert slave.getReal([vr["Fx"]]) == before
    slave.freeFMUstate(state)
    slave.terminate()
    slave.freeInstance()


# --------------------------------------------------------------------------------------------
# The sources: complete, and built as documented


def test_sources_rebuild_the_binary(unzipped, tmp_path):
    """sources/ holds all the FMU is built from: the shipped LLVM IR compiled to an object (what
    llc or clang do; here llvmlite) and the C layer compiled with the FMI headers give a
    binary with the same outputs."""
    import llvmlite.binding as llvm

    fmu = unzipped["wilac"]
    src = fmu.dir / "sources"
    assert sorted(p.name for p in src.iterdir()) == sorted([
        "README.txt", "buildDescription.xml", "ra_fmi2.c", "ra_fmu.h", "ra_model.h",
        "railadhesion_wilac.ll"])  # fmt: skip
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    module = llvm.parse_assembly((src / "railadhesion_wilac.ll").read_text())
    machine = llvm.Target.from_triple(module.triple).create_target_machine(
        cpu="x86-64", opt=3, reloc="pic")  # fmt: skip
    (tmp_path / "law.o").write_bytes(machine.emit_object(module))
    rebuilt = tmp_path / "rebuilt.so"
    subprocess.run([*native.find_c_compiler(), "-std=c11", "-O2", "-fPIC", "-shared",
                    "-fvisibility=hidden", "-Werror", "-Wall", "-Wextra", "-I",
                    str(native.fmi2_header_dir()), "-I", str(src), str(src / "ra_fmi2.c"),
                    str(tmp_path / "law.o"), "-o", str(rebuilt), "-lm"],
                   check=True, timeout=300)  # fmt: skip
    rows = _hard_inputs("wilac", 300, seed=9)
    a = fmu.sweep(_inputs("wilac"), rows, OUTPUTS)
    b = fmu.sweep(_inputs("wilac"), rows, OUTPUTS, binary=rebuilt)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_the_ir_compiles_for_another_target(unzipped):
    """The shipped IR is portable LLVM: llvmlite emits an AArch64 object from it that needs
    only libm (what `clang --target=aarch64-linux-gnu` does with the .ll)."""
    import llvmlite.binding as llvm

    llvm.initialize_all_targets()
    llvm.initialize_all_asmprinters()
    fmu = unzipped["polach"]
    module = llvm.parse_assembly((fmu.dir / "sources" / "railadhesion_polach.ll").read_text())
    triple = "aarch64-unknown-linux-gnu"
    machine = llvm.Target.from_triple(triple).create_target_machine(opt=2, reloc="pic")
    module.triple = triple
    module.data_layout = str(machine.target_data)
    obj = machine.emit_object(module)
    assert obj[18] == 183  # e_machine EM_AARCH64
    assert set(undefined_symbols(obj)) <= ALLOWED_SYMBOLS


def test_model_description_and_contents(fmus):
    with zipfile.ZipFile(fmus["wilac"]) as z:
        names = set(z.namelist())
        md = z.read("modelDescription.xml").decode()
        header = z.read("sources/ra_model.h").decode()
        toml = z.read("documentation/parameters.toml").decode()
    assert "binaries/linux64/railadhesion_wilac.so" in names
    assert not any(n.startswith("resources/") for n in names)  # nothing read at run time
    for flag in ('canBeInstantiatedOnlyOncePerProcess="false"', 'canGetAndSetFMUstate="true"',
                 'needsExecutionTool="false"', 'canSerializeFMUstate="true"'):  # fmt: skip
        assert flag in md
    assert "RECONSTRUCTION" in md and "no Python at run time" in md
    info = read_model_description(fmus["wilac"])
    assert info.guid in header
    assert "wilac_default_reconstruction" in toml


def test_build_is_deterministic(fmus, tmp_path):
    again = build_native_creep_force_fmu(tmp_path / "p.fmu", "polach", parameter_set=POLACH_SET)
    with zipfile.ZipFile(fmus["polach"]) as a, zipfile.ZipFile(again) as b:
        for name in ("modelDescription.xml", "sources/ra_model.h",
                     "sources/railadhesion_polach.ll"):  # fmt: skip
            assert a.read(name) == b.read(name), name


# --------------------------------------------------------------------------------------------
# No compiler, a law that allocates


def test_without_a_compiler_the_export_says_so(monkeypatch, tmp_path):
    monkeypatch.setenv("CC", "/nonexistent/cc")
    assert native.find_c_compiler() is None
    with pytest.raises(NativeBuildError, match="no C compiler found.*Python FMU remains"):
        build_native_creep_force_fmu(tmp_path / "x.fmu", "polach")
    assert not (tmp_path / "x.fmu").exists()


ONE = np.dtype([("x", "f8")])


def _allocating(state, settings, inputs, dt):
    s = carray(state, 1, ONE)
    s[0].x = np.ones(int(dt * 10 + 3)).sum()
    return 0


def test_a_function_that_allocates_is_refused():
    with pytest.raises(NativeBuildError, match="NRT_MemInfo"):
        compile_functions({"alloc_step": (_allocating, STEP_SIGNATURE)})


# --------------------------------------------------------------------------------------------
# Records as C


NESTED = np.dtype([("v", "f8"), ("n", "i8", (2, 3)), ("flag", "u1"),
                   ("sub", np.dtype([("k", "i4"), ("w", "f8", (2,))], align=True)),
                   ("last", "i4"), ("single", "f4", (5,))], align=True)  # fmt: skip


def test_c_struct_reproduces_numpy_layout_and_values(tmp_path):
    """A C program built from c_struct and c_initializer writes the same bytes as NumPy."""
    record = np.zeros(1, NESTED)
    record["v"] = 0.1
    record["n"] = np.arange(6).reshape(1, 2, 3) - 3
    record["flag"] = 1
    record["sub"]["k"] = -7
    record["sub"]["w"] = [[math.pi, -1e-300]]
    record["last"] = 2**31 - 1
    # single precision (the table model's values): shortest texts as float literals, a
    # whole number, the largest float and a denormal among them
    record["single"] = [[0.1, -2.0, 3.4028235e38, 1e-45, -1.0e-7]]
    program = tmp_path / "layout.c"
    program.write_text("#include <math.h>\n#include <stddef.h>\n#include <stdint.h>\n"
                       "#include <stdio.h>\n" + c_struct(NESTED, "rec") + "\n"
                       f"static const rec R = {c_initializer(record[0])};\n"
                       "int main(void) { fwrite(&R, sizeof R, 1, stdout); return 0; }"
                       "\n")  # fmt: skip
    exe = tmp_path / "layout"
    subprocess.run([*native.find_c_compiler(), "-std=c11", "-Wall", "-Werror", "-o", str(exe),
                    str(program)], check=True, timeout=120)  # fmt: skip
    assert subprocess.run([str(exe)], capture_output=True, check=True).stdout == record.tobytes()


@pytest.mark.parametrize(
    ("dtype", "message"),
    [
        (np.dtype([("a", "u1"), ("b", "f8")]), "align=True"),
        (np.dtype([("a", "f2")], align=True), "float64, int64"),
        (np.dtype([("int", "f8")], align=True), "not a valid C identifier"),
        (np.dtype("f8"), "at least one field"),
    ],
)
def test_c_struct_refuses_what_c_would_not_reproduce(dtype, message):
    with pytest.raises(ValueError, match=message):
        c_struct(dtype, "rec")


# --------------------------------------------------------------------------------------------
# The generic step model: a stand-in for the braking vehicle


BOGIE_WHEELS = np.dtype([("omega", "f8", (2,)), ("force", "f8", (2,))], align=True)
BOGIE_STATE = np.dtype([("speed", "f8"), ("wheels", BOGIE_WHEELS), ("distance", "f8"),
                        ("stopped", "u1"), ("steps", "i8")], align=True)  # fmt: skip
BOGIE_SETTINGS = np.dtype([("mass", "f8"), ("inertia", "f8"), ("radius", "f8"), ("load", "f8"),
                           ("initial_speed", "f8"), ("polach", "f8", (5,))],
                          align=True)  # fmt: skip
BOGIE_INPUTS = np.dtype([("torque", "f8", (2,)), ("valve", "i8", (2,))], align=True)


def bogie_step(state, settings, inputs, dt):
    """Stand-in: two wheelsets on one mass, Polach's forces, explicit Euler; valve 0 applies
    the torque, 1 holds half of it, 2 vents (a stand-in law, not the package's WSP)."""
    s = carray(state, 1, BOGIE_STATE)
    p = carray(settings, 1, BOGIE_SETTINGS)[0]
    u = carray(inputs, 1, BOGIE_INPUTS)[0]
    if s[0].stopped:
        return 0
    v = s[0].speed
    total = 0.0
    for k in range(2):
        w = s[0].wheels
        creep = (v - w.omega[k] * p.radius) / v
        fx, _ = polach_scalar(creep, 0.0, 0.0, p.load, v, 6e-3, 9e-3, 8.2e10, 0.28, 0.0, 0.0,
                              0.0, p.polach[0], p.polach[1], p.polach[2], p.polach[3],
                              p.polach[4])  # fmt: skip
        torque = u.torque[k] if u.valve[k] == 0 else (0.5 * u.torque[k] if u.valve[k] == 1
                                                      else 0.0)  # fmt: skip
        w.omega[k] = max(w.omega[k] + dt * (-torque - fx * p.radius) / p.inertia, 0.0)
        w.force[k] = fx
        total += fx
    s[0].speed = v + dt * total / p.mass
    s[0].distance += dt * v
    s[0].steps += 1
    if not s[0].speed < math.inf:
        return 1
    if s[0].speed <= 0.5:
        s[0].speed = 0.5
        s[0].stopped = 1
    return 0


def bogie_init(state, settings, inputs):
    s = carray(state, 1, BOGIE_STATE)
    p = carray(settings, 1, BOGIE_SETTINGS)[0]
    s[0].speed = p.initial_speed
    for k in range(2):
        s[0].wheels.omega[k] = p.initial_speed / p.radius
    return 0


def _bogie_model():
    settings = np.zeros(1, BOGIE_SETTINGS)
    settings["mass"], settings["inertia"], settings["radius"] = 2e4, 120.0, 0.46
    settings["load"] = 9.81 * 2e4 / 4
    p = polach_parameters("polach2005_wet")
    settings["polach"] = [[p.k_A, p.k_S, p.mu0, p.A, p.B]]
    variables = []
    for k in (1, 2):
        variables += [
            RecordVariable(FmuVariable(f"torque_{k}", "input", "1", "brake torque [N m]", 0.0,
                                       min=0.0), "torque", (k - 1,)),
            RecordVariable(FmuVariable(f"valve_{k}", "input", "1", "0 apply, 1 hold, 2 vent",
                                       0.0, min=0.0, max=2.0), "valve", (k - 1,)),
        ]  # fmt: skip
    variables.append(RecordVariable(FmuVariable("initial_speed", "parameter", "m/s",
                                                "speed at the start", 15.0, min=1.0),
                                    "initial_speed"))  # fmt: skip
    variables += [RecordVariable(FmuVariable(n, "output", u, n), f, i) for n, u, f, i in [
        ("speed", "m/s", "speed", ()), ("omega_1", "rad/s", "wheels.omega", (0,)),
        ("omega_2", "rad/s", "wheels.omega", (1,)), ("force_1", "N", "wheels.force", (0,)),
        ("force_2", "N", "wheels.force", (1,)), ("distance", "m", "distance", ()),
        ("stopped", "1", "stopped", ()), ("steps", "1", "steps", ())]]  # fmt: skip
    return StepModel("standin_bogie", bogie_step, np.zeros(1, BOGIE_STATE), settings,
                     np.zeros(1, BOGIE_INPUTS), variables,
                     errors={1: "the speed is not finite"}, init=bogie_init)  # fmt: skip


@pytest.fixture(scope="module")
def bogie(host, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bogie")
    path = build_step_fmu(_bogie_model(), tmp / "bogie.fmu", model_name="stand-in bogie",
                          description="test stand-in for a braking vehicle")  # fmt: skip
    return Unzipped(path, host, tmp)


def _bogie_commands(n):
    """Torques and valve commands changing: apply, hold, vent per axle, phase-shifted."""
    rows = []
    for i in range(n):
        torque = 1.2e4 + 5e3 * math.sin(i / 37.0)
        rows.append([torque, float((i // 150) % 3), 1.1 * torque, float((i // 110 + 1) % 3)])
    return rows


def _bogie_reference(model, rows, initial_speed=15.0):
    """The same step and init compiled by numba in this process (JIT), driven through ctypes
    on NumPy records."""
    from numba import cfunc

    records = model.records()
    records["settings"]["initial_speed"] = initial_speed
    step = cfunc(STEP_SIGNATURE, error_model="numpy")(bogie_step).ctypes
    init = cfunc(INIT_SIGNATURE, error_model="numpy")(bogie_init).ctypes
    ptr = {k: ctypes.c_void_p(v.ctypes.data) for k, v in records.items()}
    assert init(ptr["state"], ptr["settings"], ptr["inputs"]) == 0
    out = []
    for row in rows:
        records["inputs"]["torque"] = [[row[0], row[2]]]
        records["inputs"]["valve"] = [[round(row[1]), round(row[3])]]
        assert step(ptr["state"], ptr["settings"], ptr["inputs"], 1e-3) == 0
        s = records["state"][0]
        out.append([float(s["speed"]), *map(float, s["wheels"]["omega"]),
                    *map(float, s["wheels"]["force"]),
                    float(s["distance"]), float(s["stopped"]), float(s["steps"])])  # fmt: skip
    return np.array(out)


BOGIE_INS = ["torque_1", "valve_1", "torque_2", "valve_2"]
BOGIE_OUTS = ["speed", "omega_1", "omega_2", "force_1", "force_2", "distance", "stopped", "steps"]


def test_step_model_equals_the_same_step_run_in_python(bogie):
    """A whole stop with valve commands changing: the native FMU equals the step compiled in
    this process, step by step (here exactly; asked: 1e-9)."""
    rows = _bogie_commands(20_000)
    status, got = bogie.sweep(BOGIE_INS, rows, BOGIE_OUTS)
    want = _bogie_reference(_bogie_model(), rows)
    assert (status == 0).all()
    assert np.max(np.abs(got - want) / np.maximum(np.abs(want), 1e-300)) <= 1e-9
    assert np.array_equal(got, want)
    assert got[-1, 6] == 1.0  # it stopped, with wheels locked and released on the way
    assert (got[:, 1] == 0).any() and np.ptp(got[:, 3]) > 1e3


def test_step_model_parameter_init_and_rollback(bogie):
    ins, outs = bogie.refs(BOGIE_INS), bogie.refs(BOGIE_OUTS)
    rows = _bogie_commands(300)
    table = "\n".join(" ".join(repr(v) for v in row) for row in rows)
    vr = bogie.vr
    lines, err = bogie.run(
        f"new 0\nset 0 {vr['initial_speed']} 20\ninit 0\nget 0 {vr['speed']}\n"
        f"sweep 0 4 {ins} 8 {outs} 300\n{table}\nsave 0 1\n"
        f"sweep 0 4 {ins} 8 {outs} 300\n{table}\nload 0 1\n"
        f"sweep 0 4 {ins} 8 {outs} 300\n{table}\nset 0 {vr['initial_speed']} 25\n")  # fmt: skip
    assert lines[3] == "get 0 0 20"  # init derived the state from the parameter
    second, again = lines[305:605], lines[606:906]
    assert lines[304] == "save 0 0" and lines[605] == "load 0 0"
    assert second == again  # rollback: the same 300 steps after fmi2SetFMUstate
    want = _bogie_reference(_bogie_model(), rows + rows, initial_speed=20.0)
    got = np.array([[float(v) for v in line.split()[1:]] for line in second])
    assert np.array_equal(got, want[300:])
    assert lines[-1] == "set 0 3" and "initial_speed is a fixed parameter" in err


def test_step_model_integer_inputs_are_rounded_and_checked(bogie):
    """valve 1.5 -> 2 and 0.5 -> 0: the nearest integer, ties to even (Python's round, as
    the Python braking FMU); 2.5 is above max = 2: refused."""
    rows = [[8e3, 1.5, 8e3, 0.5]] * 5
    _, got = bogie.sweep(BOGIE_INS, rows, BOGIE_OUTS)
    want = _bogie_reference(_bogie_model(), [[8e3, 2.0, 8e3, 0.0]] * 5)
    assert np.array_equal(got, want)
    _error(bogie, f"new 0\ninit 0\nset 0 {bogie.vr['valve_1']} 2.5\n", "set 0 3",
           "fmi2SetReal: valve_1 = 2.5 is out of range [0, 2]")  # fmt: skip


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"poisson": 0.7}, r"poisson must be in \[0, 0.5\], got 0.7"),
    ({"shear_modulus": math.inf}, r"shear_modulus must be in \(0, inf\), got inf"),
    ({"shear_modulus": 0.0}, r"shear_modulus must be in \(0, inf\)"),
])  # fmt: skip
def test_build_refuses_bad_elastic_constants(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        build_native_creep_force_fmu(tmp_path / "x.fmu", "polach", **kwargs)
    assert not (tmp_path / "x.fmu").exists()


def test_step_model_checks_its_variables():
    model = _bogie_model()
    unbounded = RecordVariable(FmuVariable("valve_x", "input", "1", "no bounds", 0.0), "valve",
                               (0,))  # fmt: skip
    missing = RecordVariable(FmuVariable("nope", "output", "1", "no such field"), "wheels.mass")
    twice = model.variables[0]
    cases = [(unbounded, "integer field: its min and max must be given"),
             (missing, "which is not a field"), (twice, "appears twice")]
    for extra, message in cases:
        broken = StepModel(model.identifier, model.step, model.state, model.settings,
                           model.inputs, [*model.variables, extra])  # fmt: skip
        with pytest.raises(ValueError, match=message):
            broken.check()


def test_the_binary_carries_generic_and_x86_64_v3_code(unzipped):
    """The linux64 binary links the model twice, generic x86-64 and x86-64-v3 (chosen at
    instantiation); the sources hold the generic IR only (test_sources_rebuild_the_binary
    holds the two to the same numbers)."""
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("nm is not installed")
    out = subprocess.run([nm, str(unzipped["wilac"].binary)], capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    names = {line.split()[-1] for line in out.splitlines() if line.strip()}
    assert {"railadhesion_wilac_step", "railadhesion_wilac_step_x86_64_v3"} <= names
    ir = (unzipped["wilac"].dir / "sources" / "railadhesion_wilac.ll").read_text()
    assert "x86_64_v3" not in ir
