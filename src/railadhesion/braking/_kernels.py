"""Compiled inner loops of the braking simulator (numba, cache=True).

``family_curve`` is the closed form of :func:`railadhesion.braking.adhesion.polach_family_curve`
for one axle; ``solve_wheels_family`` the implicit (backward Euler) wheel update of
:class:`railadhesion.braking.simulator.BrakingSimulator` for Polach-family adhesion. Both
mirror the NumPy/Python versions, which the tests compare them with.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_TWO_OVER_PI = 2.0 / math.pi


@njit(cache=True)
def family_curve(xi, speed, weights, params, stiffness):
    """μ(ξ) and dμ/dξ for one axle: weights (K,), params (K, 5), stiffness scalar."""
    s = abs(xi)
    mu = 0.0
    dmu = 0.0
    for k in range(weights.shape[0]):
        w = weights[k]
        if w == 0.0:
            continue
        k_a = params[k, 0]
        k_s = params[k, 1]
        mu0 = params[k, 2]
        big_a = params[k, 3]
        big_b = params[k, 4]
        e = math.exp(-big_b * s * speed)
        mu_k = mu0 * ((1.0 - big_a) * e + big_a)
        dmu_k = -mu0 * (1.0 - big_a) * big_b * speed * e
        eps = min(stiffness * s / mu_k, 1e50)
        deps = stiffness / mu_k - stiffness * s * dmu_k / (mu_k * mu_k)
        x = k_a * eps
        y = k_s * eps
        bracket = x / (1.0 + x * x) + math.atan(y)
        dbracket = (k_a * (1.0 - x * x) / (1.0 + x * x) ** 2 + k_s / (1.0 + y * y)) * deps
        mu += w * _TWO_OVER_PI * mu_k * bracket
        dmu += w * _TWO_OVER_PI * (dmu_k * bracket + mu_k * dbracket)
    if xi < 0.0:
        mu = -mu
    return mu, dmu


@njit(cache=True)
def solve_wheels_family(v, omega0, pbar, loads, dt, radius, inertia, brake_coefficient,
                        weights, params, stiffness, tol):
    """Backward-Euler wheel speeds for a trial train speed v (see the simulator docstring).

    Returns (omega, mu, status) with status 0 = ok, 1 = non-finite adhesion.
    """
    n = omega0.shape[0]
    omega = np.empty(n)
    mu_out = np.empty(n)
    vr = max(v, 1e-6)
    for i in range(n):
        nl = loads[i]
        rn = radius * nl
        torque = brake_coefficient * pbar[i]
        mu1, _ = family_curve(1.0, v, weights[i], params[i], stiffness[i])
        g0 = -inertia * omega0[i] / dt - rn * mu1 + torque
        if not math.isfinite(g0):
            return omega, mu_out, 1
        if g0 >= 0.0:  # the wheel stops within the step: static brake friction holds it
            omega[i] = 0.0
            mu_out[i] = mu1
            continue
        lo = 0.0
        hi = omega0[i] + dt * rn * 2.0 / inertia + 1e-9
        w = min(max(omega0[i], lo), hi)
        mu = 0.0
        for _ in range(100):
            xi = (v - w * radius) / vr
            mu, dmu = family_curve(xi, v, weights[i], params[i], stiffness[i])
            if not (math.isfinite(mu) and math.isfinite(dmu)):
                return omega, mu_out, 1
            g = inertia * (w - omega0[i]) / dt - rn * mu + torque
            dg = inertia / dt + rn * dmu * radius / vr
            if dg > 0.0 and abs(g / dg) * radius < tol:  # converged Newton step
                w = w - g / dg
                break
            if g < 0.0:
                lo = w
            else:
                hi = w
            if dg > 0.0:
                new = w - g / dg
                if not (lo < new < hi):
                    new = 0.5 * (lo + hi)
            else:
                new = 0.5 * (lo + hi)
            done = (hi - lo) * radius < tol
            w = new
            if done:
                break
        xi = (v - w * radius) / vr
        mu, _ = family_curve(xi, v, weights[i], params[i], stiffness[i])
        omega[i] = w
        mu_out[i] = mu
    return omega, mu_out, 0


@njit(cache=True)
def family_evaluate(creep, speed, weights, params, stiffness):
    """μ and dμ/dξ for every axle (arrays (n,))."""
    n = creep.shape[0]
    mu = np.empty(n)
    dmu = np.empty(n)
    for i in range(n):
        mu[i], dmu[i] = family_curve(creep[i], speed, weights[i], params[i], stiffness[i])
    return mu, dmu


@njit(cache=True)
def family_peak(speed, weights, params, stiffness):
    """Largest μ per axle over 64 log-spaced creepages from 1e-4 to 1 (adhesion available)."""
    n = weights.shape[0]
    out = np.zeros(n)
    for i in range(n):
        for j in range(64):
            xi = 10.0 ** (-4.0 + 4.0 * j / 63.0)
            mu, _ = family_curve(xi, speed, weights[i], params[i], stiffness[i])
            if mu > out[i]:
                out[i] = mu
    return out


@njit(cache=True)
def advance_family(v0, decel0, dt, omega0, p0, valves, command, static_load, transfer,
                   radius, inertia, brake_coefficient, mass, davis_a, davis_b, davis_c,
                   grade_force, tau_fill, tau_vent, p_max, weights, params, stiffness, tol):
    """One step of the simulator for Polach-family adhesion (see simulator docstring).

    Returns (v, omega, p1, mu, loads, vented, brake_work, creep_work, resistance_work,
    status); status 0 ok, 1 non-finite adhesion.
    """
    n = omega0.shape[0]
    loads = np.empty(n)
    for i in range(n):
        loads[i] = max(static_load[i] + transfer[i] * decel0, 0.0)
    p1 = np.empty(n)
    pbar = np.empty(n)
    vented = np.zeros(n)
    for i in range(n):
        cmd = min(max(command[i], 0.0), p_max)
        if valves[i] == 2:
            target = 0.0
        elif valves[i] == 1:
            target = p0[i]
        else:
            target = cmd
        tau = tau_fill if target > p0[i] else tau_vent
        e = math.exp(-dt / tau)
        p1[i] = target + (p0[i] - target) * e
        pbar[i] = target + (p0[i] - target) * (tau / dt) * (1.0 - e)
        if valves[i] == 2:
            vented[i] = p0[i] - p1[i]
    resistance = 0.0
    if v0 > 0.0:
        resistance = davis_a + davis_b * v0 + davis_c * v0 * v0
    external = resistance + grade_force
    v = v0 - dt * decel0
    omega = omega0.copy()
    mu = np.zeros(n)
    for _ in range(20):
        omega, mu, status = solve_wheels_family(v, omega0, pbar, loads, dt, radius, inertia,
                                                brake_coefficient, weights, params, stiffness,
                                                tol)
        if status != 0:
            return v, omega, p1, mu, loads, vented, 0.0, 0.0, 0.0, status
        total = 0.0
        for i in range(n):
            total += mu[i] * loads[i]
        v_new = v0 - dt * (total + external) / mass
        done = abs(v_new - v) < tol
        v = v_new
        if done:
            break
    brake_work = 0.0
    creep_work = 0.0
    for i in range(n):
        brake_work += brake_coefficient * pbar[i] * omega[i] * dt
        creep_work += mu[i] * loads[i] * (v - omega[i] * radius) * dt
    return (v, omega, p1, mu, loads, vented, brake_work, creep_work, resistance * v * dt + 0.0,
            0)


@njit(cache=True)
def wilac_table(packed, loads, speed, water, weights, params):
    """Fill WILAC's blending weights (n, 4) and Polach parameters (n, 4, 5) per axle.

    ``packed`` is :func:`railadhesion.models.kernels.pack_wilac` (layout documented there):
    the erf transitions of Trummer et al. §5.3 for the weights, and per condition and
    parameter the regression on Q' = Q/Q_ref, v' = v/v_ref (clamped into the calibrated
    ranges, clipped to the physical bounds), §5.2.
    """
    header = 22
    nterm = int(packed[header])
    vn = min(max(speed, packed[4]), packed[5]) / packed[1]
    for a in range(loads.shape[0]):
        w = water[a]
        e1 = 0.5 * (math.erf((w - packed[6]) / packed[7]) + 1.0)
        e2 = 0.5 * (math.erf((w - packed[8]) / packed[9]) + 1.0)
        e3 = 0.5 * (math.erf((w - packed[10]) / packed[11]) + 1.0)
        weights[a, 0] = 1.0 - e1
        weights[a, 1] = e1 - e2
        weights[a, 2] = e2 - e3
        weights[a, 3] = e3
        qn = min(max(loads[a], packed[2]), packed[3]) / packed[0]
        fac = (qn, vn, 1.0 / qn, 1.0 / vn, math.exp(qn), math.exp(vn))
        for i in range(4):
            for j in range(5):
                total = 0.0
                base = header + 1 + (i * 5 + j) * nterm * 4
                for k in range(nterm):
                    p = base + 4 * k
                    value = packed[p]
                    if value == 0.0:
                        continue
                    for m in range(3):
                        f = int(packed[p + 1 + m])
                        if f >= 0:
                            value = value * fac[f]
                    total += value
                params[a, i, j] = min(max(total, packed[12 + 2 * j]), packed[13 + 2 * j])
