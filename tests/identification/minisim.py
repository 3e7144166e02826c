"""A small braking simulator of the tests' own, independent of railadhesion.braking.

One car body on two bogies, four wheelsets, a known adhesion law mu(slip velocity), brake
cylinders filling with a first-order lag and a bang-bang wheel-slide protection that vents an
axle's cylinder when its slip exceeds ``slip_high`` and refills below ``slip_low``. Normal
loads with the body's pitch load transfer written out here by hand (leading bogie gains
M_c h d / (2 l) under deceleration d). Integrated with semi-implicit Euler at ``substeps``
steps per log sample; the log is written here with pandas, not with the package's writer, so
that a mistake in either cannot hide in both.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

G = 9.80665


def law(w, mu_s=0.12, w0=0.15, a_ratio=0.45, b=0.35):
    """Falling adhesion law of the slip velocity w [m/s]: the form the identification fits."""
    w = np.maximum(w, 0.0)
    return mu_s * (1.0 - np.exp(-w / w0)) * (a_ratio + (1.0 - a_ratio) * np.exp(-b * w))


VEHICLE = dict(
    body_mass=32600.0, bogie_mass=3200.0, wheelset_mass=1500.0, wheel_radius=0.46,
    wheelset_inertia=150.0, brake_coefficient=0.02, cg_height=0.8, half_pivot_spacing=9.5,
)


def loads(d, veh=VEHICLE):
    """Axle loads [N] for deceleration d, by hand: bogie share / 2 + bogie / 2 + wheelset."""
    mc, mt, ma = veh["body_mass"], veh["bogie_mass"], veh["wheelset_mass"]
    dn = mc * veh["cg_height"] * d / (2.0 * veh["half_pivot_spacing"])
    front = (mc * G / 2 + dn) / 2 + mt * G / 2 + ma * G
    rear = (mc * G / 2 - dn) / 2 + mt * G / 2 + ma * G
    return np.array([front, front, rear, rear])


def simulate(v0=30.0, duration=20.0, period=2.4e-3, substeps=8, p_max=3.8e5, tau_fill=0.6,
             tau_vent=0.15, slip_high=3.0, slip_low=0.8, adhesion=law, veh=VEHICLE,
             wsp=True, v_stop=2.0, axle_scale=(1.0, 1.0, 1.0, 1.0)):
    """Histories sampled every ``period`` [s]: time, v, omega (n, 4), p (n, 4) [Pa], mu (n, 4)."""
    r, j, c = veh["wheel_radius"], veh["wheelset_inertia"], veh["brake_coefficient"]
    m_tot = veh["body_mass"] + 2 * veh["bogie_mass"] + 4 * veh["wheelset_mass"]
    h = period / substeps
    v = v0
    om = np.full(4, v0 / r)
    p = np.zeros(4)
    venting = np.zeros(4, bool)
    d = 0.0
    scale = np.asarray(axle_scale)
    out_t, out_v, out_w, out_p, out_mu = [], [], [], [], []
    n = int(duration / period)
    for k in range(n):
        out_t.append(k * period)
        out_v.append(v)
        out_w.append(om.copy())
        out_p.append(p.copy())
        out_mu.append(adhesion(v - r * om) * scale)
        if v < v_stop:
            break
        for _ in range(substeps):
            w = v - r * om
            mu = adhesion(w) * scale
            t_force = mu * loads(d, veh)
            torque = np.where(om > 0, c * p, 0.0)
            om = np.maximum(om + h * (t_force * r - torque) / j, 0.0)
            d = t_force.sum() / m_tot
            v = v - h * d
            if wsp:
                venting = np.where(w > slip_high, True, np.where(w < slip_low, False, venting))
            target = np.where(venting, 0.0, p_max)
            tau = np.where(venting, tau_vent, tau_fill)
            p = p + (target - p) * (1.0 - np.exp(-h / tau))
    return (np.array(out_t), np.array(out_v), np.array(out_w), np.array(out_p),
            np.array(out_mu))


def log_frame(t, v, om, p, noise=(0.0, 0.0, 0.0), seed=0):
    """The log as written by a test train: bar for pressures, optional Gaussian noise."""
    rng = np.random.default_rng(seed)
    cols = {"time": t, "train_speed": v + rng.normal(0, noise[0], t.size) if noise[0] else v}
    for i in range(om.shape[1]):
        x = om[:, i]
        cols[f"wheel_speed_{i + 1}"] = x + rng.normal(0, noise[1], t.size) if noise[1] else x
    for i in range(p.shape[1]):
        x = p[:, i] / 1e5
        cols[f"brake_pressure_{i + 1}"] = x + rng.normal(0, noise[2], t.size) if noise[2] else x
    return pd.DataFrame(cols)
