"""The table model of Kalker's exact theory against Polach's model with the same friction:
creep curves and braking stops of the default coach, and where spin and long contacts change
the forces. Prints Markdown tables (the numbers of docs/exact-solver.md, "Using the table
model in braking, sweeps and FMUs").

Usage::

    PYTHONPATH=src MPLBACKEND=Agg nice -n 10 python3 scripts/compare_table_polach.py

Runtime: about a minute (the first run compiles the braking step for the table model).
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from railadhesion.braking import (
    BrakeCylinders,
    ContactGeometry,
    ExactTableAdhesion,
    PolachAdhesion,
    WheelSlideProtection,
    load_vehicle,
    simulate,
)
from railadhesion.contact import exact_table_forces
from railadhesion.models import polach_forces
from railadhesion.models.parameters import polach_parameters

SETS = ("polach2005_dry", "polach2005_wet")


def low_wet():
    """Polach's wet set at μ0 = 0.12 (a low-adhesion rail: the axles slide)."""
    return dataclasses.replace(polach_parameters("polach2005_wet"), mu0=0.12,
                               name="polach2005_wet at mu0 = 0.12")


def unreduced(p):
    """The set with k_A = k_S = 1: Polach's theory without his reduction of the slope."""
    return dataclasses.replace(p, k_A=1.0, k_S=1.0, name=f"{p.name}, k_A = k_S = 1")


def models(p, contact=None):
    p = polach_parameters(p) if isinstance(p, str) else p
    return {
        f"Polach {p.name}": PolachAdhesion(p, contact=contact),
        "Polach, k_A = k_S = 1": PolachAdhesion(unreduced(p), contact=contact),
        "table model": ExactTableAdhesion.from_polach(p, contact),
    }


def creep_curves(load=56e3, speed=30.0):
    creeps = np.array([2e-4, 1e-3, 3e-3, 1e-2, 0.1, 0.3])
    print(f"\n### Creep curves at the coach's contact (wheel load {load / 1e3:g} kN, "
          f"{speed:g} m/s)\n")
    c = ContactGeometry()
    print(f"Hertz contact: a = {1e3 * c.semi_axes(load)[0]:.2f} mm, "
          f"b = {1e3 * c.semi_axes(load)[1]:.2f} mm (a/b = {c.a0 / c.b0:.2f}).\n")
    print("| set | model | " + " | ".join(f"μ at ξ = {x:g}" for x in creeps)
          + " | peak μ | slope at 0 |")
    print("|---|---|" + "---|" * (len(creeps) + 2))
    for name in SETS:
        for label, m in models(name).items():
            m.bind(1, 0.46)
            m.prepare(speed, np.array([load]), np.zeros(1), 0.0)
            mu = [float(m.evaluate(np.array([x]), speed)[0][0]) for x in creeps]
            slope = float(m.evaluate(np.array([1e-7]), speed)[1][0])
            peak = float(m.available(speed)[0])
            print(f"| {name} | {label} | " + " | ".join(f"{v:.3f}" for v in mu)
                  + f" | {peak:.3f} | {slope:.0f} |")


def stops():
    coach = load_vehicle("coach_default")
    cyl = BrakeCylinders(max_pressure=6e5, fill_time_constant=0.3, vent_time_constant=0.15)
    print("\n### Emergency stops of the default coach from 30 m/s (5.5 bar, WSP, dt = 1 ms)\n")
    print("| set | model | stopping distance [m] | max slip [%] | vent actions "
          "| mean adhesion used | run time [s], best of 3 |")
    print("|---|---|---|---|---|---|---|")
    for name in (*SETS, low_wet()):
        for label, m in models(name).items():
            simulate(coach, m, 30.0, 5.5e5, cylinders=cyl, wsp=WheelSlideProtection(),
                     dt=1e-3, max_time=1.0)  # compile outside the timing
            times = []
            for _ in range(3):  # best of 3
                t = time.perf_counter()
                res = simulate(coach, models(name)[label], 30.0, 5.5e5, cylinders=cyl,
                               wsp=WheelSlideProtection(), dt=1e-3)
                times.append(time.perf_counter() - t)
            dt = min(times)
            s = res.summary
            set_name = name if isinstance(name, str) else name.name
            print(f"| {set_name} | {label} | {res.stopping_distance:.1f} | "
                  f"{100 * s['max_slip']:.2f} | {s['vent_actions']} | "
                  f"{s['mean_adhesion_utilisation']:.3f} | {dt:.2f} |")


def spin_and_shape(mu=0.3, q=1e5, c=6e-3, speed=10.0):
    """|ΔF|/(μQ) between the table model and Polach (Coulomb, k_A = k_S = 1) at a/b 0.2, 1, 5,
    longitudinal creepage with spin, and lateral creepage with spin."""
    g = 8.2e10
    print(f"\n### Spin and contact shape (Coulomb μ = {mu}, Q = {q / 1e3:g} kN, "
          f"c = √(ab) = {1e3 * c:g} mm)\n")
    print("Differences table − Polach (k_A = k_S = 1), in μQ; creepage given in units of "
          "μp0/G (full sliding from about 3 of them), spin φ in rad/m.\n")
    print("| a/b | creepage | φ [rad/m] | Fx table | Fx Polach | Fy table | Fy Polach "
          "| \\|ΔF\\| |")
    print("|---|---|---|---|---|---|---|---|")
    for aob in (0.2, 1.0, 5.0):
        a, b = c * math.sqrt(aob), c / math.sqrt(aob)
        tau = mu * 1.5 * q / (math.pi * a * b * g)  # μ p0 / G
        for direction, mag in (("ξ", 0.5), ("ξ", 2.0), ("η", 1.0)):
            for phi in (0.0, 1.0, 4.0):
                xi, eta = (mag * tau, 0.0) if direction == "ξ" else (0.0, mag * tau)
                ft = exact_table_forces(xi, eta, phi, q, a, b, mu)
                fp = polach_forces(xi, eta, phi, q, speed, a, b, mu0=mu)
                d = math.hypot(ft[0] - fp[0], ft[1] - fp[1]) / (mu * q)
                print(f"| {aob:g} | {direction} = {mag:g} μp0/G | {phi:g} | "
                      f"{-ft[0] / (mu * q):.3f} | {-fp[0] / (mu * q):.3f} | "
                      f"{-ft[1] / (mu * q):.3f} | {-fp[1] / (mu * q):.3f} | {d:.3f} |")


if __name__ == "__main__":
    creep_curves()
    stops()
    spin_and_shape()
