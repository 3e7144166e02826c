"""Per-step cost of the native braking-vehicle FMU (issue 25) in the C host, beside the Python
braking FMU and the native creep-force FMU, in the same run.

Run from the repository root:  PYTHONPATH=src python3 benchmarks/bench_native_braking.py

The native FMU of ``examples/brake_damp.toml`` (4 axles, WILAC, damp section) runs in the C
host of the tests (``tests/export/data/fmi2_host.c``, no Python in its process): 1 ms steps,
the pressure commands and the valve states of all axles set every step (apply, hold, vent
changing), doStep, the train and wheel speeds read back; then doStep alone. The train is
moving throughout (2 x REPEAT x ROWS ms = 10 s; the script checks that it has not stopped).
The Python braking FMU (pythonfmu) of the same scenario is timed under FMPy
(``bench_export.bench_braking``), and the native WILAC creep-force FMU's doStep in the same
C host. The native braking FMU is timed twice, interleaved: with the binary's generic
x86-64 code forced (``RAILADHESION_FMU_GENERIC=1``: what the binary ran before it carried an
x86-64-v3 variant) and with its default (x86-64-v3 on processors that have it); and the FMU
with the built-in WSP (pressure commands in, valves out). Medians of the host's runs; the
machine is shared: compare the ratios.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_export import HOST_SOURCE, bench_braking, bench_c_host  # noqa: E402

from railadhesion.export import build_native_braking_fmu, build_native_creep_force_fmu  # noqa: E402
from railadhesion.export.native import find_c_compiler  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ROWS = 1000
REPEAT = 5
RUNS = 5
N = 4


def bench_native_braking(host: Path, fmu: Path, generic: bool = False) -> tuple[float, ...]:
    """(set + doStep + get, doStep alone) [µs per 1 ms step], wall and CPU, medians.
    ``generic``: force the binary's generic x86-64 code (RAILADHESION_FMU_GENERIC=1), the
    only code of the binaries before the x86-64-v3 variant."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    causality = {v.name: v.causality for v in md.modelVariables}
    inputs = [f"pressure_command_{k}" for k in range(1, N + 1)] + [
        f"valve_{k}" for k in range(1, N + 1)]
    wsp = causality["valve_1"] == "output"  # the built-in WSP sets the valves
    outputs = ["train_speed"] + [f"wheel_speed_{k}" for k in range(1, N + 1)]
    rows = []
    for j in range(ROWS):
        valves = [2.0 if (j // 120 + i) % 6 == 0 else 1.0 if (j // 120 + i) % 6 == 1 else 0.0
                  for i in range(N)]  # fmt: skip
        rows.append([5.5e5] * N + ([] if wsp else valves))
    if wsp:
        inputs = inputs[:N]
    where = Path(tempfile.mkdtemp(prefix="bench_nb_"))
    with zipfile.ZipFile(fmu) as z:
        z.extractall(where)
    binary = where / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    table = "\n".join(" ".join(repr(x) for x in row) for row in rows)
    commands = (f"new 0\ninit 0\nbench 0 {len(inputs)} {' '.join(str(vr[n]) for n in inputs)} "
                f"{len(outputs)} {' '.join(str(vr[n]) for n in outputs)} {ROWS} {REPEAT}\n"
                f"{table}\nget 0 {vr['train_speed']} {vr['stopped']}\nmaps\n")  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "PYTHONPATH",
                                                             "RAILADHESION_FMU_GENERIC")}
    if generic:
        env["RAILADHESION_FMU_GENERIC"] = "1"
    full, step, cpu_full, cpu_step = [], [], [], []
    for _ in range(RUNS):
        out = subprocess.run([str(host), "--script", str(binary), (where / "resources").as_uri(),
                              md.guid], input=commands, capture_output=True, text=True,
                             env=env, timeout=600)  # fmt: skip
        lines = out.stdout.split("\n")
        bench = next(line for line in lines if line.startswith("bench")).split()
        if bench[4] != "0" or bench[3] != "0":
            raise RuntimeError(f"the host reported status {bench[4]}, {bench[3]} allocations")
        speed, stopped = (float(v) for v in
                          next(x for x in lines if x.startswith("get")).split()[3:5])
        if stopped != 0.0:
            raise RuntimeError(f"the train stopped during the benchmark (speed {speed})")
        if "maps 0" not in lines:
            raise RuntimeError("a Python library was mapped into the host")
        full.append(float(bench[1]) / 1e3)
        step.append(float(bench[2]) / 1e3)
        cpu_full.append(float(bench[5]) / 1e3)
        cpu_step.append(float(bench[6]) / 1e3)
    return tuple(statistics.median(x) for x in (full, step, cpu_full, cpu_step))


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        host = tmp / "fmi2_host"
        subprocess.run([*find_c_compiler(), "-O2", "-o", str(host), str(HOST_SOURCE), "-ldl"],
                       check=True)  # fmt: skip
        scenario = ROOT / "examples" / "brake_damp.toml"
        native = build_native_braking_fmu(tmp / "nb.fmu", scenario)
        wsp = build_native_braking_fmu(tmp / "nbw.fmu", scenario, wsp=True)
        rows = []  # interleaved: the two codes of the binary side by side
        for _ in range(2):
            for fmu, generic in ((native, True), (native, False), (wsp, False)):
                rows.append((fmu, generic, bench_native_braking(host, fmu, generic)))
        wilac = build_native_creep_force_fmu(tmp / "wilac.fmu", "wilac")
        cf = bench_c_host(host, wilac, "wilac", "dry", 20)
        py_us, direct_us = bench_braking(tmp)
        print("braking vehicle, 4 axles, WILAC damp example, 1 ms steps, train moving")
        for fmu, generic, (full, alone, cpu_full, cpu_alone) in rows:
            code = "generic x86-64 (forced)" if generic else "default (x86-64-v3 here)"
            what = "built-in WSP" if fmu == wsp else "valves in"
            print(f"  native FMU, C host, {what}, {code}: set+doStep+get {full:.2f} µs "
                  f"(CPU {cpu_full:.2f}), doStep alone {alone:.2f} µs (CPU {cpu_alone:.2f}): "
                  f"{1e3 / full:.0f}x real time")
        print(f"  Python FMU, FMPy:   set+doStep+get {py_us:.1f} µs "
              f"({py_us / rows[1][2][0]:.0f}x the native FMU); stepping API directly "
              f"{direct_us:.1f} µs")
        print(f"native WILAC creep-force FMU, C host: set+doStep+get {cf[0]:.3f} µs, "
              f"doStep alone {cf[1]:.3f} µs")


if __name__ == "__main__":
    main()
