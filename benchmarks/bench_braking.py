"""Braking simulator benchmarks (issue 6). Prints its figures; run from the repo root:

    PYTHONPATH=src python3 benchmarks/bench_braking.py

1. Real-time factor of the stepping API (``BrakingSimulator.step``): 4 axles, WILAC with a
   damp section (25 µl/s), one call per 1 ms control period (1 kHz), valves and pressure
   command passed each call as a HIL rig would. Real-time factor = simulated time / wall time.
2. The same with history recording off (a HIL loop usually logs elsewhere).
3. A whole 200 km/h -> 0 emergency stop with WSP on the damp rail (``simulate``), compiled
   loop, 1 ms step, 5 ms WSP period; and the same in the Python loop for comparison.

Timings are medians of repeats; the machine is shared, so they vary run to run.
"""

from __future__ import annotations

import statistics
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


def stepping(seconds: float, record: bool) -> float:
    sim = BrakingSimulator(VEHICLE, WilacAdhesion(PROFILE), 55.0, cylinders=CYL, max_step=1e-3,
                           record=record)
    valves = np.zeros(4, dtype=np.int64)
    inputs = {"pressure_command": 5.5e5, "valves": valves}
    sim.step(1e-3, inputs)  # compile / warm up
    steps = int(seconds / 1e-3)
    t0 = time.perf_counter()
    for k in range(steps):
        valves[:] = 2 if (k // 300) % 4 == 3 else 0  # some venting, as a WSP would
        sim.step(1e-3, inputs)
    wall = time.perf_counter() - t0
    return steps * 1e-3 / wall


def whole_stop(compiled: bool):
    t0 = time.perf_counter()
    res = simulate(VEHICLE, WilacAdhesion(PROFILE), 200 / 3.6, 5.5e5, cylinders=CYL,
                   wsp=WheelSlideProtection(), dt=1e-3, compiled=compiled)
    return time.perf_counter() - t0, res


def main() -> None:
    stepping(0.05, True)
    whole_stop(True)  # compile
    rtf = [stepping(5.0, True) for _ in range(3)]
    rtf_norec = [stepping(5.0, False) for _ in range(3)]
    print("stepping API, 4 axles, WILAC, 1 kHz calls (median of 3 x 5 s simulated):")
    print(f"  real-time factor with recording:    {statistics.median(rtf):8.0f}x")
    print(f"  real-time factor without recording: {statistics.median(rtf_norec):8.0f}x")
    print(f"  per call: {1e6 * 1e-3 / statistics.median(rtf_norec):.1f} us")
    walls = []
    for _ in range(3):
        wall, res = whole_stop(True)
        walls.append(wall)
    s = res.summary
    print("whole 200 km/h -> 0 stop, damp rail (WILAC 25 ul/s), WSP, dt 1 ms (compiled loop):")
    print(f"  wall time {statistics.median(walls):.3f} s (median of 3) for "
          f"{s['stopping_time_s']:.1f} s simulated -> "
          f"{s['stopping_time_s'] / statistics.median(walls):.0f}x real time")
    print(f"  stopping distance {s['stopping_distance_m']:.1f} m, {s['vent_actions']} vent "
          f"actions, longest lock {s['longest_lock_s']:.2f} s")
    wall_py, res_py = whole_stop(False)
    print(f"  Python loop (compiled=False): {wall_py:.2f} s, stopping distance "
          f"{res_py.summary['stopping_distance_m']:.1f} m")


if __name__ == "__main__":
    main()
