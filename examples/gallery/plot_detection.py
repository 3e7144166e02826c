"""
Detecting low adhesion from low-creep data
==========================================

Fletcher (2013) asks whether the friction available at full slip can be told from adhesion
measured at small creep, before a wheel slides. Below full slip only the bending of the creep
curve carries μ. :func:`railadhesion.identification.detect_low_adhesion` fits Fletcher's 2D
model to such data and returns μ with a 95 % profile-likelihood interval and a warning level
against 0.14 (the braking adhesion the RSSB guidance assumes, which Fletcher cites).

Here: his condition O1 (oil, μ = 0.055) and W1 (water, μ = 0.24), 40 noisy points
(σ = 0.002) up to 0.2 %, 0.5 % and 1 % creep.
"""

import matplotlib.pyplot as plt
import numpy as np

import railadhesion as ra
from railadhesion.identification import detect_low_adhesion

rng = np.random.default_rng(0)
fig, axes = plt.subplots(1, 2, figsize=(8, 3.6), sharey=True, layout="constrained")
for ax, code in zip(axes, ("O1", "W1"), strict=True):
    condition = ra.fletcher_condition(code)
    fine = np.linspace(0.0, 0.012, 300)
    ax.plot(fine * 100, condition.adhesion(fine), "k", lw=1, label="true curve")
    for up_to in (0.002, 0.005, 0.01):
        creep = np.linspace(up_to / 40, up_to, 40)
        measured = condition.adhesion(creep) + rng.normal(0.0, 0.002, creep.size)
        res = detect_low_adhesion(creep, measured)
        print(f"{code} up to {100 * up_to:.1f} % creep: mu = {res.mu:.3f} "
              f"[{res.interval[0]:.3f}, {res.interval[1]:.3f}] -> {res.level}")
        ax.plot(creep * 100, measured, ".", ms=3,
                label=f"≤ {100 * up_to:.1f} %: μ {res.mu:.3f}, {res.level}")
    ax.axhline(0.14, color="r", lw=0.8, ls="--")
    ax.set_title(f"{code}: true μ = {condition.mu}")
    ax.set_xlabel("creep [%]")
    ax.legend(fontsize=7)
axes[0].set_ylabel("adhesion")
