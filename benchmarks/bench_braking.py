"""Braking simulator benchmarks (issue 6). Prints its figures; run from the repo root:

    PYTHONPATH=src python3 benchmarks/bench_braking.py [--quick]

1. Real-time factor of the stepping API for hardware in the loop: 4 axles, WILAC with a damp
   section (25 µl/s from 50 m on), one ``BrakingSimulator.advance(1e-3)`` call per 1 ms
   control period (1 kHz), from 55 m/s with 5.5 bar commanded; the valves vent all axles for
   0.3 s every 1.2 s (the wheels slide, lock and recover, as under a WSP). Inputs are written
   in place into ``sim.inputs`` (pressure command and valve state per axle), checked by the
   compiled code at every call; the loop writes them when they change, as a data-acquisition
   driver writing into those arrays would. Real-time factor = simulated time / wall time.
   The same loop is also timed with all 8 inputs copied in every call, and with recording.
2. The per-call cost broken into components: the Python loop, the Python side of the call
   (the method and the compiled entry point, measured on a stopped simulator, which returns at
   once), the compiled step itself (the same steps run inside one compiled loop), its
   refresh share, and the rest (the cost of entering compiled code from the interpreter:
   cold caches and branch predictors).
3. ``step(dt, {"pressure_command": ..., "valves": ...})``: the mapping API (inputs checked
   in Python, a snapshot returned), for comparison.
4. A whole 200 km/h -> 0 emergency stop with WSP on the damp rail (``simulate``), compiled
   loop, 1 ms step, 5 ms WSP period; and the same with ``compiled=False`` (a Python loop
   calling the WSP between steps, and the adhesion model's Python methods called back from
   the step).

Timings are the minimum over repeats (the machine is shared; the load average is printed).
The headline loop is also timed in CPU time (``time.process_time``), which waiting for a
core on a loaded machine does not inflate.
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from railadhesion.braking import (
    BrakeCylinders,
    BrakingSimulator,
    Vehicle,
    WaterFlowProfile,
    WheelSlideProtection,
    WilacAdhesion,
    simulate,
)

VEHICLE = Vehicle()
PROFILE = WaterFlowProfile.sections([(50.0, 5000.0, 25.0)])
CYL = BrakeCylinders(max_pressure=6e5)
DT = 1e-3
PERIOD = 300  # calls between valve changes


def new_sim(record=False, refresh_period=0.01):
    sim = BrakingSimulator(VEHICLE, WilacAdhesion(PROFILE), 55.0, cylinders=CYL, max_step=DT,
                           record=record, refresh_period=refresh_period)
    sim.inputs.pressure_command[:] = 5.5e5
    sim.advance(DT)  # compile or load the kernel; binds the fast advance
    return sim


def valve_state(k):
    return 2.0 if (k // PERIOD) % 4 == 3 else 0.0


def hil_loop(steps, record=False, clock=time.perf_counter):
    """The headline loop: inputs written in place when they change, one advance per 1 ms."""
    sim = new_sim(record)
    valves = sim.inputs.valves
    advance = sim.advance
    t0 = clock()
    for k in range(steps):
        if k % PERIOD == 0:
            valves[:] = valve_state(k)
        advance(DT)
    return (clock() - t0) / steps, sim


def hil_loop_copying(steps):
    """The same with the rig copying all 8 inputs into the simulator at every call."""
    sim = new_sim()
    inputs = sim.inputs
    rig_valves = np.zeros(4)
    rig_command = np.full(4, 5.5e5)
    advance = sim.advance
    t0 = time.perf_counter()
    for k in range(steps):
        if k % PERIOD == 0:
            rig_valves[:] = valve_state(k)
        inputs.valves[:] = rig_valves
        inputs.pressure_command[:] = rig_command
        advance(DT)
    return (time.perf_counter() - t0) / steps


def mapping_loop(steps):
    sim = BrakingSimulator(VEHICLE, WilacAdhesion(PROFILE), 55.0, cylinders=CYL, max_step=DT,
                           record=False)
    valves = np.zeros(4, dtype=np.int64)
    inputs = {"pressure_command": 5.5e5, "valves": valves}
    sim.step(DT, inputs)
    t0 = time.perf_counter()
    for k in range(steps):
        if k % PERIOD == 0:
            valves[:] = int(valve_state(k))
        sim.step(DT, inputs)
    return (time.perf_counter() - t0) / steps


def empty_loop(steps):
    t0 = time.perf_counter()
    for k in range(steps):
        if k % PERIOD == 0:
            pass
    return (time.perf_counter() - t0) / steps


def python_side(steps):
    """advance() on a stopped simulator: the method and the compiled entry point, no step."""
    sim = new_sim()
    sim._machine[0]["state"]["stopped"] = 1
    advance = sim.advance
    t0 = time.perf_counter()
    for _ in range(steps):
        advance(DT)
    return (time.perf_counter() - t0) / steps


def compiled_loop_kernel():
    from numba import njit

    from railadhesion.braking import step

    @njit
    def loop(machine, tables, steps, dt):
        valves = machine[0].inputs.valves
        for k in range(steps):
            if k % PERIOD == 0:
                v = 2.0 if (k // PERIOD) % 4 == 3 else 0.0
                for i in range(4):
                    valves[i] = v
            step.advance_unrecorded(machine, tables, dt, 0)

    return loop


def compiled_steps(loop, steps, refresh_period=0.01):
    sim = new_sim(refresh_period=refresh_period)
    t0 = time.perf_counter()
    loop(sim._machine, sim._tables, steps, DT)
    return (time.perf_counter() - t0) / steps, sim


def refresh_cost(repeats):
    """One refresh of the adhesion inputs (loads, water, WILAC parameters, lanes) [s]."""
    from numba import njit

    from railadhesion.braking import step

    @njit
    def loop(machine, tables, n):
        m = machine[0]
        for _ in range(n):
            m.state.speed += 1e-9
            step._refresh(m.state, m.settings, tables, 0)

    sim = new_sim()
    for _ in range(1000):  # into the damp section: all four WILAC conditions active
        sim.advance(DT)
    machine, tables = sim._machine.copy(), sim._tables
    loop(machine, tables, 10)
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        loop(machine, tables, 5000)
        best = min(best, (time.perf_counter() - t0) / 5000)
    return best


def whole_stop(compiled):
    t0 = time.perf_counter()
    res = simulate(VEHICLE, WilacAdhesion(PROFILE), 200 / 3.6, 5.5e5, cylinders=CYL,
                   wsp=WheelSlideProtection(), dt=DT, compiled=compiled)
    return time.perf_counter() - t0, res


def main() -> None:
    quick = "--quick" in sys.argv
    steps = 2000 if quick else 5000
    repeats = 3 if quick else 7
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} (2 cores shared); "
          f"minimum of {repeats} repeats")
    loop = compiled_loop_kernel()
    compiled_steps(loop, 10)
    whole_stop(True)

    def best(fn, *args):
        return min(fn(*args) for _ in range(repeats))

    headline = min(hil_loop(steps)[0] for _ in range(repeats))
    headline_cpu = min(hil_loop(steps, clock=time.process_time)[0] for _ in range(repeats))
    _, sim = hil_loop(steps)
    counts = sim.solver_counts
    copying = best(hil_loop_copying, steps)
    recording = min(hil_loop(steps, True)[0] for _ in range(repeats))
    mapping = best(mapping_loop, steps)
    empty = best(empty_loop, steps)
    side = best(python_side, steps)
    compiled = min(compiled_steps(loop, steps)[0] for _ in range(repeats))
    refresh = refresh_cost(repeats)
    print(f"stepping API, 4 axles, WILAC (damp, 25 ul/s), one advance(1 ms) per call, "
          f"{steps * DT:.0f} s simulated:")
    print(f"  per call {headline * 1e9:6.0f} ns -> real-time factor {DT / headline:6.0f}x "
          "(inputs written in place when they change)")
    print(f"  per call {headline_cpu * 1e9:6.0f} ns of CPU time -> {DT / headline_cpu:6.0f}x "
          "(the same loop in CPU time)")
    print(f"  per call {copying * 1e9:6.0f} ns -> real-time factor {DT / copying:6.0f}x "
          "(all 8 inputs copied in every call)")
    print(f"  per call {recording * 1e9:6.0f} ns -> real-time factor {DT / recording:6.0f}x "
          "(with recording of every step and the adhesion available)")
    print(f"  step(dt, mapping) -> snapshot: {mapping * 1e9:6.0f} ns per call "
          f"({DT / mapping:.0f}x)")
    rest = headline - empty - side - compiled
    print("  components of one advance() call:")
    print(f"    Python loop (for, if)                     {empty * 1e9:6.0f} ns")
    print(f"    Python side of the call (method + compiled entry point, one buffer + dt) "
          f"{side * 1e9:6.0f} ns")
    print(f"    compiled step (same steps in one compiled loop) {compiled * 1e9:6.0f} ns, of "
          f"which the 10 ms refresh {refresh * 1e9 / 10:.0f} ns "
          f"({refresh * 1e9:.0f} ns per refresh)")
    print(f"    rest (entering compiled code from the interpreter: cold caches) "
          f"{rest * 1e9:6.0f} ns")
    print(f"    solver: {counts['newton_iterations'] / counts['steps']:.3f} Newton iterations "
          f"(one creep-curve evaluation per axle each) per step, "
          f"{counts['safeguarded_steps']} of {counts['steps']} steps by the safeguarded solve")
    walls = []
    for _ in range(repeats):
        wall, res = whole_stop(True)
        walls.append(wall)
    s = res.summary
    wall = min(walls)
    print("whole 200 km/h -> 0 stop, damp rail (WILAC 25 ul/s), WSP, dt 1 ms (compiled loop):")
    print(f"  wall time {wall:.3f} s for {s['stopping_time_s']:.1f} s simulated -> "
          f"{s['stopping_time_s'] / wall:.0f}x real time "
          f"({wall / (len(res.histories) - 1) * 1e9:.0f} ns per step, result tables included)")
    print(f"  stopping distance {s['stopping_distance_m']:.1f} m, {s['vent_actions']} vent "
          f"actions, longest lock {s['longest_lock_s']:.2f} s")
    if not quick:
        wall_py, res_py = whole_stop(False)
        print(f"  Python loop (compiled=False): {wall_py:.2f} s, stopping distance "
              f"{res_py.summary['stopping_distance_m']:.1f} m")


if __name__ == "__main__":
    main()
