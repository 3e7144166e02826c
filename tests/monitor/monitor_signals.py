"""Synthetic on-board signals with an exact truth, for the monitor's tests (no simulator).

A train at speed v(t) uses the adhesion ``mu_used(t)`` on every axle; the creep is read off a
known creep curve (Fletcher's or Polach's, :mod:`railadhesion.models.kernels`), the wheel
speeds follow (with a radius error per wheel if asked), and the brake pressures are those
that give this adhesion by seed 002's eq. 10 (``c p = mu N R - J omega_dot``) — or, for
traction, the torques. Sensor noise as issue 21's, seeded.
"""

from __future__ import annotations

import math

import numpy as np

from railadhesion.braking import GRAVITY, load_vehicle
from railadhesion.models.kernels import fletcher_scalar, polach_curve_scalar


def curve_values(creep, shape, slope, mu, ratio=1.0 / 3.0):
    """The adhesion of a creep curve at each creep (magnitudes)."""
    q = 0.0 if not math.isfinite(mu) else 1.0 / mu
    if shape == "fletcher":
        return np.array([fletcher_scalar(float(x), slope, q)[0] for x in np.abs(creep)])
    return np.array([polach_curve_scalar(float(x), slope, q, ratio)[0] for x in np.abs(creep)])


def creep_for(mu_used, shape, slope, mu, ratio=1.0 / 3.0):
    """Creep giving the adhesion ``mu_used`` (>= 0) on the rising part of the curve."""
    grid = np.concatenate(([0.0], np.geomspace(1e-7, 0.2, 6000)))
    vals = curve_values(grid, shape, slope, mu, ratio)
    top = int(np.argmax(vals >= vals.max() * (1 - 1e-9)))
    grid, vals = grid[:top + 1], vals[:top + 1]
    m = np.asarray(mu_used, float)
    if np.any(m > vals[-1]):
        raise ValueError("mu_used above the curve's maximum")
    return np.interp(m, vals, grid)


def make_signals(mu_used, *, duration=20.0, period=2.4e-3, speed=40.0, shape="fletcher",
                 slope=60.0, mu=0.06, traction=False, radius_error=None, noise=True, seed=0,
                 vehicle="coach_default", curve_at=None):
    """Signals of a run: ``mu_used(t)`` a function of time (adhesion in use, >= 0), the curve
    (``shape``, ``slope``, ``mu``; ``curve_at(t)`` may give (shape, slope, mu) per sample).

    Returns a dict: time, train_speed, wheel_speed (n, N), brake_pressure (n, N) [Pa], torque
    (n, N) [N m] (NaN unless traction), and the truth: creep (n,), mu_used (n,), mu (n,).
    """
    veh = load_vehicle(vehicle)
    n_ax = veh.n_axles
    t = period * np.arange(1, int(round(duration / period)) + 1)
    m = np.array([float(mu_used(x)) for x in t])
    if curve_at is None:
        creep = creep_for(m, shape, slope, mu)
        mus = np.full(t.size, mu)
    else:
        creep = np.empty(t.size)
        mus = np.empty(t.size)
        for k, x in enumerate(t):
            sh, sl, mm = curve_at(x)
            creep[k] = creep_for(m[k], sh, sl, mm)
            mus[k] = mm
    sign = -1.0 if traction else 1.0
    d = sign * m * GRAVITY  # the rail forces sum to mu M_tot g (eq. 7, no resistance)
    v = speed - np.concatenate(([0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(t))))
    r = veh.wheel_radius
    err = np.zeros(n_ax) if radius_error is None else np.asarray(radius_error, float)
    omega_true = (v * (1.0 - sign * creep))[:, None] / (r * (1.0 + err))[None, :]
    wdot = np.gradient(omega_true, t, axis=0)
    loads = veh.axle_normal_loads(d)
    # eq. 10 per axle: J wdot/R + c p/R - tau/R = mu N (signed: braking positive)
    force = sign * m[:, None] * loads * r - veh.wheelset_inertia * wdot * (1.0 + err)[None, :]
    if traction:
        pressure = np.zeros_like(force)
        torque = -force
    else:
        pressure = force / veh.brake_coefficient
        torque = np.full_like(force, np.nan)
    rng = np.random.default_rng(seed)
    wheel = omega_true.copy()
    v_meas = v.copy()
    if noise:
        v_meas = v + rng.normal(0.0, 0.01, t.size)
        wheel = wheel + rng.normal(0.0, 0.02, wheel.shape)
        pressure = pressure + rng.normal(0.0, 1e3, pressure.shape)
        if traction:
            torque = torque + rng.normal(0.0, 20.0, torque.shape)
    return {"time": t, "train_speed": v_meas, "wheel_speed": wheel, "brake_pressure": pressure,
            "torque": torque, "creep": sign * creep, "mu_used": sign * m, "mu": mus,
            "speed": v, "vehicle": veh}


def braking_profile(coast=2.5, level=0.04, modulation=0.25, ramp=1.0, freqs=(0.37, 0.61, 0.97),
                    phases=(0.3, 1.9, 4.1)):
    """Coasting, then a ramp to ``level`` with a varying demand (as the closed-loop cases)."""
    def mu_used(t):
        if t < coast:
            return 0.0
        m = sum(math.sin(2 * math.pi * f * t + p) for f, p in zip(freqs, phases, strict=True))
        return level * min(1.0, (t - coast) / ramp) * (1.0 + modulation * m / len(freqs))
    return mu_used


def feed(monitor, sig, start=0, stop=None, every=None):
    """Feed samples [start, stop) to the monitor; return per-sample levels, reasons and
    estimates (arrays (n, N))."""
    stop = sig["time"].size if stop is None else stop
    n = stop - start
    n_ax = monitor.n_axles
    levels = np.empty((n, n_ax), int)
    reasons = np.empty((n, n_ax), int)
    est = np.empty((n, n_ax))
    lo = np.empty((n, n_ax))
    hi = np.empty((n, n_ax))
    used = np.empty((n, n_ax))
    creep = np.empty((n, n_ax))
    press = sig["brake_pressure"] if monitor.has_pressure.any() else None
    torq = sig["torque"] if monitor.has_torque.any() else None
    for k in range(start, stop):
        out = monitor.update(sig["time"][k], sig["train_speed"][k], sig["wheel_speed"][k],
                             None if press is None else press[k],
                             None if torq is None else torq[k])
        j = k - start
        levels[j] = out.level
        reasons[j] = out.reason
        est[j] = out.estimate
        lo[j] = out.lower
        hi[j] = out.upper
        used[j] = out.adhesion_used
        creep[j] = out.creep
    return {"level": levels, "reason": reasons, "estimate": est, "lower": lo, "upper": hi,
            "used": used, "creep": creep, "time": sig["time"][start:stop]}
