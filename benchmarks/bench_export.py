"""Per-step cost of the creep-force FMUs under FMPy, against direct calls of the library.

Run from the repository root:  PYTHONPATH=src python3 benchmarks/bench_export.py

For each FMU (WILAC default set, Polach 'polach2005_dry') it builds the FMU, instantiates it
with FMPy's low-level FMU2Slave and times steps in which every input changes: one setReal of
all inputs, one doStep, one getReal of Fx, Fy and adhesion. The same inputs go through the
library directly (wilac_forces / polach_forces with scalars, plus adhesion) for comparison.
Also timed: fmpy.simulate_fmu with an input table that changes every step (FMPy's own loop,
input interpolation and recording included). Figures are medians of several repeats; this
machine is shared, so they vary run to run: compare ratios.

Native FMUs (``--native``, issue 25) are timed in the C host of the tests
(``tests/export/data/fmi2_host.c``, compiled here), a process with no Python: per step with
every input changing (setReal of all inputs, doStep, getReal of the three outputs) and doStep
alone; beside them, in the same run, the Python FMU of the same law in the same C host (with
libpython preloaded, as docs/fmu.md tells non-Python hosts) and both FMUs under FMPy.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

import railadhesion
from railadhesion.export import build_creep_force_fmu, build_native_creep_force_fmu
from railadhesion.export.native import find_c_compiler

N_STEPS = 2000
REPEATS = 5


def _inputs(model: str, n: int, water: str) -> list[dict]:
    rng = np.random.default_rng(0)
    rows = []
    for _ in range(n):
        x = {
            "creep_long": float(rng.uniform(-0.3, 0.3)),
            "creep_lat": float(rng.uniform(-0.02, 0.02)),
            "spin": float(rng.uniform(-0.5, 0.5)),
            "normal_force": float(rng.uniform(20e3, 120e3)),
            "speed": float(rng.uniform(2.0, 40.0)),
            "a": float(rng.uniform(4e-3, 8e-3)),
            "b": float(rng.uniform(5e-3, 12e-3)),
        }
        if model == "wilac":
            x["water_flow"] = 0.0 if water == "dry" else float(rng.uniform(10.0, 60.0))
        rows.append(x)
    return rows


def _median_us(fn, n: int) -> float:
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) / n * 1e6)
    return statistics.median(times)


def bench(model: str, fmu_path: Path, water: str = "dry") -> dict:
    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    rows = _inputs(model, N_STEPS, water)
    names = list(rows[0])
    in_refs = [vr[k] for k in names]
    out_refs = [vr[k] for k in ("Fx", "Fy", "adhesion")]
    values = [[x[k] for k in names] for x in rows]

    unzipped = extract(fmu_path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()

    def run_fmu():
        for i, v in enumerate(values):
            fmu.setReal(in_refs, v)
            fmu.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
            fmu.getReal(out_refs)

    if model == "wilac":
        params = railadhesion.default_wilac_parameters()

        def direct(x):
            fx, fy = railadhesion.wilac_forces(*x, params)
            return fx, fy, railadhesion.adhesion(fx, fy, x[3])
    else:
        p = railadhesion.polach_parameters("polach2005_dry")

        def direct(x):
            fx, fy = railadhesion.polach_forces(*x, mu0=p.mu0, k_A=p.k_A, k_S=p.k_S, A=p.A,
                                                B=p.B)
            return fx, fy, railadhesion.adhesion(fx, fy, x[3])

    def run_direct():
        for v in values:
            direct(v)

    run_fmu()  # warm-up
    fmu_us = _median_us(run_fmu, N_STEPS)
    direct_us = _median_us(run_direct, N_STEPS)
    fmu.terminate()
    fmu.freeInstance()

    signal = np.zeros(N_STEPS, dtype=[("time", float)] + [(k, float) for k in names])
    signal["time"] = np.arange(N_STEPS) * 1e-3
    for k in names:
        signal[k] = [x[k] for x in rows]

    def run_simulate():
        simulate_fmu(str(fmu_path), stop_time=signal["time"][-1], output_interval=1e-3,
                     input=signal, output=["Fx", "Fy", "adhesion"])

    sim_us = statistics.median(
        [_timed(run_simulate) / N_STEPS * 1e6 for _ in range(max(1, REPEATS // 2))]
    )
    return {"fmu": fmu_us, "direct": direct_us, "simulate": sim_us}


_ECHO_SLAVE = """
from pythonfmu import Fmi2Causality, Fmi2Slave, Real


class EchoSlave(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.x = 0.0
        self.y = 0.0
        self.register_variable(Real("x", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.y = self.x
        return True
"""


def bench_overhead(tmp: Path) -> float:
    """Per-step cost of a pythonfmu FMU that only copies its input: the FMI/pythonfmu/FMPy
    overhead the creep-force FMU pays on top of the model."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from railadhesion.export import FmuVariable, build_fmu

    script = tmp / "echo_slave.py"
    script.write_text(_ECHO_SLAVE, encoding="utf-8")
    path = build_fmu(script, [FmuVariable("x", "input", "1", "input", 0.0),
                              FmuVariable("y", "output", "1", "copy of x")], tmp / "echo.fmu")
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="echo")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    # Same number of values through setReal/getReal as the WILAC FMU (8 in, 3 out).
    refs_in, refs_out = [0] * 8, [1] * 3
    values = [float(i) for i in range(8)]

    def run():
        for i in range(N_STEPS):
            fmu.setReal(refs_in, values)
            fmu.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
            fmu.getReal(refs_out)

    run()
    us = _median_us(run, N_STEPS)
    fmu.terminate()
    fmu.freeInstance()
    return us


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def bench_braking(tmp: Path, steps: int = 2000) -> tuple[float, float]:
    """Per-step cost [µs] of the braking-vehicle FMU (damp example, 1 ms steps, every input
    changing) and of the stepping API driven directly with the same inputs."""
    import shutil

    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from railadhesion.braking import BrakingSimulator
    from railadhesion.braking.scenario import load_scenario
    from railadhesion.export import build_braking_fmu

    scenario = Path(__file__).resolve().parents[1] / "examples" / "brake_damp.toml"
    fmu = build_braking_fmu(tmp / "brake.fmu", scenario)
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    cmd_refs = [vr[f"pressure_command_{k}"] for k in range(1, 5)]
    valve_refs = [vr[f"valve_{k}"] for k in range(1, 5)]
    out_refs = [vr[n] for n in ("train_speed", "wheel_speed_1", "wheel_speed_2",
                                "wheel_speed_3", "wheel_speed_4")]  # fmt: skip
    unzipped = extract(fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="b")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    commands = [[3e5 + 1e3 * (i % 50)] * 4 for i in range(steps)]
    valves = [[0, 0, (i // 100) % 3, 0] for i in range(steps)]
    warm = 20  # the first steps load (or compile) the kernels: not timed
    for i in range(warm):
        slave.setReal(cmd_refs, commands[i])
        slave.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
    t0 = time.perf_counter()
    for i in range(warm, steps):
        slave.setReal(cmd_refs, commands[i])
        slave.setReal(valve_refs, [float(v) for v in valves[i]])
        slave.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
        slave.getReal(out_refs)
    fmu_us = (time.perf_counter() - t0) / (steps - warm) * 1e6
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    sc = load_scenario(scenario)
    sim = BrakingSimulator(sc.vehicle, sc.adhesion(), sc.initial_speed, cylinders=sc.cylinders,
                           record=False)
    for i in range(warm):
        sim.step(1e-3, {"pressure_command": np.array(commands[i])})
    t0 = time.perf_counter()
    for i in range(warm, steps):
        sim.step(1e-3, {"pressure_command": np.array(commands[i]),
                        "valves": np.array(valves[i])})  # fmt: skip
    direct_us = (time.perf_counter() - t0) / (steps - warm) * 1e6
    return fmu_us, direct_us


HOST_SOURCE = Path(__file__).resolve().parents[1] / "tests" / "export" / "data" / "fmi2_host.c"


def _libpython() -> str | None:
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return None
    path = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")
    return str(path) if path.is_file() else None


def bench_c_host(host: Path, fmu: Path, model: str, water: str, repeat: int,
                 preload: str | None = None) -> tuple[float, ...]:  # fmt: skip
    """(set + doStep + get, doStep alone) [µs] of ``fmu`` in the C host, wall clock and the
    host thread's CPU time: N_STEPS rows of inputs changing every step, ``repeat`` passes
    (medians of REPEATS runs of the host)."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    rows = _inputs(model, N_STEPS, water)
    names = list(rows[0])
    where = Path(tempfile.mkdtemp(prefix="bench_host_"))
    with zipfile.ZipFile(fmu) as z:
        z.extractall(where)
    binary = where / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    table = "\n".join(" ".join(repr(x[k]) for k in names) for x in rows)
    refs_in = " ".join(str(vr[k]) for k in names)
    refs_out = " ".join(str(vr[k]) for k in ("Fx", "Fy", "adhesion"))
    commands = (f"new 0\ninit 0\nbench 0 {len(names)} {refs_in} 3 {refs_out} {N_STEPS} "
                f"{repeat}\n{table}\nmaps\n")  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "PYTHONPATH")}
    if preload:  # the Python FMU: libpython preloaded, the package importable
        env["LD_PRELOAD"] = preload
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    full, step, cpu_full, cpu_step = [], [], [], []
    for _ in range(REPEATS):
        out = subprocess.run([str(host), "--script", str(binary), (where / "resources").as_uri(),
                              md.guid], input=commands, capture_output=True, text=True,
                             env=env, timeout=1200)  # fmt: skip
        lines = out.stdout.split("\n")
        bench = next(line for line in lines if line.startswith("bench")).split()
        if bench[4] != "0" or bench[3] != "0":
            raise RuntimeError(f"the host reported status {bench[4]}, {bench[3]} allocations")
        if preload is None and "maps 0" not in lines:
            raise RuntimeError("a Python library was mapped into the host running a native FMU")
        full.append(float(bench[1]) / 1e3)
        step.append(float(bench[2]) / 1e3)
        cpu_full.append(float(bench[5]) / 1e3)
        cpu_step.append(float(bench[6]) / 1e3)
    return tuple(statistics.median(x) for x in (full, step, cpu_full, cpu_step))


def main() -> None:
    print(f"load average at the start: {os.getloadavg()[0]:.2f} (2 cores, shared)")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t0 = time.perf_counter()
        wilac = build_creep_force_fmu(tmp / "wilac.fmu", "wilac")
        build_s = time.perf_counter() - t0
        polach = build_creep_force_fmu(tmp / "polach.fmu", "polach")
        print(f"build of one FMU: {build_s * 1e3:.0f} ms")
        native = {}
        if find_c_compiler() is not None:
            t0 = time.perf_counter()
            native["wilac"] = build_native_creep_force_fmu(tmp / "wilac_native.fmu", "wilac")
            native_s = time.perf_counter() - t0
            native["polach"] = build_native_creep_force_fmu(tmp / "polach_native.fmu", "polach")
            print(f"build of one native FMU (numba compile, LLVM, C compiler): {native_s:.1f} s")
        print(f"per-step cost, median of {REPEATS} x {N_STEPS} steps, every input changing "
              "(µs/step; setReal + doStep + getReal):")
        print(f"{'case':<34}{'FMU (FMU2Slave)':>16}{'direct call':>13}{'ratio':>7}"
              f"{'simulate_fmu':>14}")
        cases = [
            ("WILAC, dry (w = 0)", "wilac", "dry"),
            ("WILAC, damp (w in 10-60 µl/s)", "wilac", "damp"),
            ("Polach polach2005_dry", "polach", "dry"),
        ]
        python_fmus = {"wilac": wilac, "polach": polach}
        for label, model, water in cases:
            for kind, path in (("", python_fmus[model]), (" native", native.get(model))):
                if path is None:
                    continue
                r = bench(model, path, water)
                print(f"{label + kind:<34}{r['fmu']:>16.2f}{r['direct']:>13.2f}"
                      f"{r['fmu'] / r['direct']:>7.2f}{r['simulate']:>14.1f}")
        print(f"FMI + pythonfmu + FMPy overhead (FMU that copies its input, 8 values in, 3 out): "
              f"{bench_overhead(tmp):.1f} µs/step")
        if native:
            _c_host_table(tmp, native, python_fmus, cases)
        fmu_us, direct_us = bench_braking(tmp)
        print(f"braking-vehicle FMU (4 axles, WILAC damp example, 1 ms steps): {fmu_us:.1f} "
              f"µs/step under FMPy, {direct_us:.1f} µs/step through BrakingSimulator.step "
              f"directly ({1e3 / fmu_us:.1f}x / {1e3 / direct_us:.1f}x real time)")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")


def _c_host_table(tmp: Path, native: dict, python_fmus: dict, cases) -> None:
    """Native FMUs and the Python FMUs in the same C host, same inputs, same run."""
    host = tmp / "fmi2_host"
    subprocess.run([*find_c_compiler(), "-O2", "-o", str(host), str(HOST_SOURCE), "-ldl"],
                   check=True, timeout=120)  # fmt: skip
    libpython = _libpython()
    print("in a C host (no Python in the process for the native FMU; the Python FMU with "
          "libpython preloaded), µs/step, wall clock [CPU time of the host thread]:")
    print(f"{'case':<34}{'native set+step+get':>22}{'native doStep':>18}{'Python FMU':>18}"
          f"{'ratio':>7}")
    for label, model, water in cases:
        full, step, cfull, cstep = bench_c_host(host, native[model], model, water, repeat=50)
        if libpython is not None:
            py_full, _, py_cfull, _ = bench_c_host(host, python_fmus[model], model, water,
                                                   repeat=1, preload=libpython)  # fmt: skip
            py = f"{py_full:>9.1f} [{py_cfull:5.1f}]{py_full / full:>7.0f}"
        else:
            py = f"{'(no libpython)':>25}"
        print(f"{label:<34}{full:>13.3f} [{cfull:5.3f}]{step:>9.3f} [{cstep:5.3f}]{py}")


if __name__ == "__main__":
    main()
