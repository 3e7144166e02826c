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

from railadhesion.models.kernels import _condition_parameters as _wilac_condition_parameters
from railadhesion.models.kernels import _factors as _wilac_factors
from railadhesion.models.kernels import _weights as _wilac_weights

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
                        weights, params, stiffness, tol, guess):
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
        if torque >= inertia * omega0[i] / dt:  # else the wheel cannot stop in this step
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
        w = min(max(guess[i], lo), hi)
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
    """Largest μ per axle over creepage 1e-4 … 1 (the adhesion available).

    A 17-point log-spaced grid, then a golden-section search (16 evaluations) in log creepage
    between the neighbours of the best grid point.
    """
    n = weights.shape[0]
    out = np.zeros(n)
    g = 0.6180339887498949
    for i in range(n):
        best = -1.0
        jbest = 0
        for j in range(17):
            mu, _ = family_curve(10.0 ** (-4.0 + 0.25 * j), speed, weights[i], params[i],
                                 stiffness[i])
            if mu > best:
                best = mu
                jbest = j
        lo = -4.0 + 0.25 * max(jbest - 1, 0)
        hi = -4.0 + 0.25 * min(jbest + 1, 16)
        x1 = hi - g * (hi - lo)
        x2 = lo + g * (hi - lo)
        f1, _ = family_curve(10.0 ** x1, speed, weights[i], params[i], stiffness[i])
        f2, _ = family_curve(10.0 ** x2, speed, weights[i], params[i], stiffness[i])
        for _ in range(14):
            if f1 > f2:
                hi = x2
                x2 = x1
                f2 = f1
                x1 = hi - g * (hi - lo)
                f1, _ = family_curve(10.0 ** x1, speed, weights[i], params[i], stiffness[i])
            else:
                lo = x1
                x1 = x2
                f1 = f2
                x2 = lo + g * (hi - lo)
                f2, _ = family_curve(10.0 ** x2, speed, weights[i], params[i], stiffness[i])
        out[i] = max(best, f1, f2)
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
    v_prev = v
    r_prev = 0.0
    for it in range(30):
        omega, mu, status = solve_wheels_family(v, omega0, pbar, loads, dt, radius, inertia,
                                                brake_coefficient, weights, params, stiffness,
                                                tol, omega)
        if status != 0:
            return v, omega, p1, mu, loads, vented, 0.0, 0.0, 0.0, status
        total = 0.0
        for i in range(n):
            total += mu[i] * loads[i]
        v_new = v0 - dt * (total + external) / mass
        r = v_new - v
        if abs(r) < tol:
            v = v_new
            break
        # secant step on r(v) = F(v) - v (plain fixed point on the first pass)
        if it == 0 or r == r_prev:
            v_next = v_new
        else:
            v_next = v - r * (v - v_prev) / (r - r_prev)
        v_prev = v
        r_prev = r
        v = v_next
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

    ``packed`` is :func:`railadhesion.models.kernels.pack_wilac` (layout documented there);
    the weights (erf transitions, Trummer et al. §5.3) and the regressions on Q', v' (clamped
    into the calibrated ranges, clipped to the physical bounds, §5.2) are the WILAC kernel's
    own functions, so the two cannot drift apart.
    """
    fac = np.empty(7)
    for a in range(loads.shape[0]):
        f = _wilac_weights(water[a], packed)
        for i in range(4):
            weights[a, i] = f[i]
        _wilac_factors(loads[a], speed, packed, fac)
        flat = params[a].reshape(20)
        for i in range(4):
            _wilac_condition_parameters(packed, i, fac, flat)


# --------------------------------------------------------------------------------------------
# Whole-run loop for Polach-family adhesion and the default WSP (compiled fast path of
# railadhesion.braking.simulate). It performs, operation for operation, what
# BrakingSimulator._advance, WheelSlideProtection.__call__ and simulate() do in Python; the
# tests hold the two paths together.

# indices into the scalar state array
T_, X_, V_, D_, NEXT_, STOPPED_, STOP_T_, STOP_X_, WB_, WC_, WR_, WG_, INIT_, REF_, K_ = range(15)


@njit(cache=True)
def _water(x, values, over_time, linear, position, time):
    q = time if over_time else position
    if linear:
        return np.interp(q, x, values)
    idx = np.searchsorted(x, q, side="right") - 1
    if idx < 0:
        return values[0]
    if idx > values.size - 1:
        idx = values.size - 1
    return values[idx]


@njit(cache=True)
def _prepare(kind, sc, loads, offsets, forces, creep, polach_table, sec_start, sec_end,
             sec_idx, packed, prof_x, prof_v, over_time, linear, recovery, k0, qref,
             weights, params, stiffness):
    n = loads.shape[0]
    wheel = 0.5 * loads
    for i in range(n):
        stiffness[i] = k0 * (wheel[i] / qref) ** (2.0 / 3.0) / wheel[i]
    if kind == 0:  # Polach sets on sections
        for i in range(n):
            pos = sc[X_] - offsets[i]
            k = 0
            for s in range(sec_start.shape[0]):
                if pos >= sec_start[s] and pos < sec_end[s]:
                    k = sec_idx[s]
            for j in range(weights.shape[1]):
                weights[i, j] = 0.0
                for m in range(5):
                    params[i, j, m] = polach_table[j, m]
            weights[i, k] = 1.0
    else:  # WILAC
        water = np.empty(n)
        heat = 0.0
        for i in range(n):
            w = _water(prof_x, prof_v, over_time, linear, sc[X_] - offsets[i], sc[T_])
            if recovery > 0.0:
                w = w * math.exp(-heat / recovery)
            water[i] = w
            heat += forces[i] * abs(creep[i])
        wilac_table(packed, wheel, max(sc[V_], 0.0), water, weights, params)


@njit(cache=True)
def _wsp(t, omega, radius, ws, wst, released, forced, prev, wdec, sc, out):
    """WheelSlideProtection.__call__ (settings ws, state arrays); valve states into out."""
    period = ws[0]
    n = omega.shape[0]
    u = omega * radius
    if sc[INIT_] == 0.0:
        for i in range(n):
            prev[i] = u[i]
        sc[REF_] = u.max()
        sc[INIT_] = 1.0
    alpha = period / (ws[11] + period)
    for i in range(n):
        raw = (prev[i] - u[i]) / period
        wdec[i] += alpha * (raw - wdec[i])
        prev[i] = u[i]
    ref = sc[REF_]
    rate = ws[1]
    if u.max() < ref - max(ws[2] * ref, ws[3]):
        rate = ws[14]
    v_ref = max(u.max(), ref - rate * period)
    sc[REF_] = v_ref
    hold = max(ws[2] * v_ref, ws[3])
    vent = max(ws[4] * v_ref, ws[5])
    reapply = max(ws[6] * v_ref, ws[7])
    for i in range(n):
        slip = v_ref - u[i]
        a = wdec[i]
        st = wst[i]
        new = st
        want_vent = slip > vent or a > ws[9]
        want_hold = slip > hold or a > ws[8]
        if st == 0:
            new = 2 if want_vent else (1 if want_hold else 0)
        elif st == 2:
            if -a > ws[10]:
                new = 1
        else:
            accelerating = -a > ws[10]
            if want_vent and not accelerating:
                new = 2
            elif slip < reapply and not accelerating and a < ws[8]:
                new = 0
        if t < forced[i]:
            new = 0
        elif new != 0:
            if math.isnan(released[i]):
                released[i] = t
            elif t - released[i] >= ws[12] - 1e-12:
                new = 0
                forced[i] = t + ws[13]
        if new == 0:
            released[i] = math.nan
        wst[i] = new
        out[i] = new


@njit(cache=True)
def run_family(k_end, dt, sc, vp, static_load, transfer, offsets, cyl, demand, kind,
               polach_table, sec_start, sec_end, sec_idx, packed, prof_x, prof_v, over_time,
               linear, recovery, k0, qref, wsp_on, ratio, bogie, ws, wst, released, forced,
               prev, wdec, omega, pressure, valves, forces, mu, creep, loads, available,
               vented_total, vent_actions, weights, params, stiffness, rows, tol,
               cmd_axle):
    """Steps k = sc[K_] … k_end - 1 of simulate(); returns (rows written, status).

    ``cmd_axle``: per-axle commanded pressures that replace ``demand`` when its first element
    is >= 0 (the stepping API). status: 0 buffer full or k_end reached, 1 stopped,
    2 non-finite adhesion.
    """
    n = omega.shape[0]
    radius = vp[0]
    inertia = vp[1]
    c = vp[2]
    mass = vp[3]
    grade_force = vp[7]
    stop_speed = vp[8]
    period = vp[9]
    cmd_arr = np.empty(n)
    new_valves = np.empty(n, dtype=np.int64)
    nrow = 0
    k = int(sc[K_])
    while k < k_end and nrow < rows.shape[0]:
        t = k * dt
        cmd = 0.0
        if t >= demand[1]:
            if demand[2] <= 0.0:
                cmd = demand[0]
            else:
                cmd = demand[0] * min(1.0, (t - demand[1]) / demand[2])
        if wsp_on and k % ratio == 0:
            _wsp(t, omega, radius, ws, wst, released, forced, prev, wdec, sc, new_valves)
            if bogie:
                half = n // 2
                m1 = 0
                m2 = 0
                for i in range(half):
                    m1 = max(m1, new_valves[i])
                    m2 = max(m2, new_valves[half + i])
                for i in range(half):
                    new_valves[i] = m1
                    new_valves[half + i] = m2
            for i in range(n):
                if new_valves[i] == 2 and valves[i] != 2:
                    vent_actions[i] += 1
                valves[i] = new_valves[i]
        # --- BrakingSimulator._advance
        if sc[T_] >= sc[NEXT_] - 1e-12:
            for i in range(n):
                loads[i] = max(static_load[i] + transfer[i] * sc[D_], 0.0)
            _prepare(kind, sc, loads, offsets, forces, creep, polach_table, sec_start, sec_end,
                     sec_idx, packed, prof_x, prof_v, over_time, linear, recovery, k0, qref,
                     weights, params, stiffness)
            peak = family_peak(sc[V_], weights, params, stiffness)
            for i in range(n):
                available[i] = peak[i]
            sc[NEXT_] = (math.floor(sc[T_] / period + 1e-9) + 1) * period
        for i in range(n):
            cmd_arr[i] = cmd
        if cmd_axle[0] >= 0.0:
            cmd = 0.0
            for i in range(n):
                cmd_arr[i] = cmd_axle[i]
                cmd = max(cmd, cmd_axle[i])
        v0 = sc[V_]
        (v, om, p1, m, ld, vent, wb, wc, wr, status) = advance_family(
            v0, sc[D_], dt, omega, pressure, valves, cmd_arr, static_load, transfer, radius,
            inertia, c, mass, vp[4], vp[5], vp[6], grade_force, cyl[0], cyl[1], cyl[2],
            weights, params, stiffness, tol)
        if status != 0:
            sc[K_] = k
            return nrow, 2
        sc[WB_] += wb
        sc[WC_] += wc
        sc[WR_] += wr
        sc[WG_] += grade_force * v * dt
        vr = max(v, 1e-6)
        ke = 0.5 * mass * v * v
        for i in range(n):
            vented_total[i] += vent[i]
            omega[i] = om[i]
            pressure[i] = p1[i]
            mu[i] = m[i]
            loads[i] = ld[i]
            forces[i] = m[i] * ld[i]
            creep[i] = (v - om[i] * radius) / vr
            ke += 0.5 * inertia * om[i] * om[i]
        sc[D_] = (v0 - v) / dt
        sc[X_] += 0.5 * (v0 + v) * dt
        sc[T_] += dt
        sc[V_] = v
        stopped = False
        if v <= stop_speed:
            d = sc[D_]
            if v > 0 and d > 0:
                sc[STOP_X_] = sc[X_] + v * v / (2 * d)
                sc[STOP_T_] = sc[T_] + v / d
            else:
                sc[STOP_X_] = sc[X_]
                sc[STOP_T_] = sc[T_]
            sc[STOPPED_] = 1.0
            stopped = True
        r = rows[nrow]
        r[0] = sc[T_]
        r[1] = sc[X_]
        r[2] = v
        r[3] = sc[D_]
        for i in range(n):
            r[4 + i] = omega[i]
            r[4 + n + i] = pressure[i]
            r[4 + 2 * n + i] = valves[i]
            r[4 + 3 * n + i] = creep[i]
            r[4 + 4 * n + i] = forces[i]
            r[4 + 5 * n + i] = loads[i]
            r[4 + 6 * n + i] = mu[i]
            r[4 + 7 * n + i] = available[i]
        b = 4 + 8 * n
        r[b] = cmd
        r[b + 1] = ke
        r[b + 2] = sc[WB_]
        r[b + 3] = sc[WC_]
        r[b + 4] = sc[WR_] + sc[WG_]
        nrow += 1
        k += 1
        sc[K_] = k
        if stopped:
            return nrow, 1
    return nrow, 0
