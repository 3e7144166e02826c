"""Per-step cost of the creep-force FMUs under FMPy, against direct calls of the library.

Run from the repository root:  PYTHONPATH=src python3 benchmarks/bench_export.py

For each FMU (WILAC default set, Polach 'polach2005_dry') it builds the FMU, instantiates it
with FMPy's low-level FMU2Slave and times steps in which every input changes: one setReal of
all inputs, one doStep, one getReal of Fx, Fy and adhesion. The same inputs go through the
library directly (wilac_forces / polach_forces with scalars, plus adhesion) for comparison.
Also timed: fmpy.simulate_fmu with an input table that changes every step (FMPy's own loop,
input interpolation and recording included). Figures are medians of several repeats; this
machine is shared, so they vary run to run: compare ratios.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import railadhesion
from railadhesion.export import build_creep_force_fmu

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


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t0 = time.perf_counter()
        wilac = build_creep_force_fmu(tmp / "wilac.fmu", "wilac")
        build_s = time.perf_counter() - t0
        polach = build_creep_force_fmu(tmp / "polach.fmu", "polach")
        print(f"build of one FMU: {build_s * 1e3:.0f} ms")
        print(f"per-step cost, median of {REPEATS} x {N_STEPS} steps, every input changing "
              "(µs/step; setReal + doStep + getReal):")
        print(f"{'case':<34}{'FMU (FMU2Slave)':>16}{'direct call':>13}{'ratio':>7}"
              f"{'simulate_fmu':>14}")
        for label, model, path, water in [
            ("WILAC, dry (w = 0)", "wilac", wilac, "dry"),
            ("WILAC, damp (w in 10-60 µl/s)", "wilac", wilac, "damp"),
            ("Polach polach2005_dry", "polach", polach, "dry"),
        ]:
            r = bench(model, path, water)
            print(f"{label:<34}{r['fmu']:>16.1f}{r['direct']:>13.1f}"
                  f"{r['fmu'] / r['direct']:>7.1f}{r['simulate']:>14.1f}")
        print(f"FMI + pythonfmu + FMPy overhead (FMU that copies its input, 8 values in, 3 out): "
              f"{bench_overhead(tmp):.1f} µs/step")
        fmu_us, direct_us = bench_braking(tmp)
        print(f"braking-vehicle FMU (4 axles, WILAC damp example, 1 ms steps): {fmu_us:.1f} "
              f"µs/step under FMPy, {direct_us:.1f} µs/step through BrakingSimulator.step "
              f"directly ({1e3 / fmu_us:.1f}x / {1e3 / direct_us:.1f}x real time)")


if __name__ == "__main__":
    main()
