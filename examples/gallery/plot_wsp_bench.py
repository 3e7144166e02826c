"""
A WSP bench run: the default controller against a naive one
===========================================================

The WSP bench (:func:`railadhesion.braking.run_wsp_programme`, ``railadhesion wsp-test``)
runs a programme of low-adhesion emergency stops on a wheel slide protection (WSP)
controller and reports, per stop, the distance against the adhesion-limited stop (the best
any WSP can do with these brakes), wheel locks, creep and vented air, with pass/fail against
the programme's criteria. Four of the 31 stops of the shipped programme run here on the
package's default controller and on a naive threshold controller written in a few lines (the
one of the guide :doc:`/guides/wsp-controller`); :doc:`/wsp` describes the bench.
"""

import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from railadhesion.braking import APPLY, HOLD, VENT, run_wsp_programme


class ThresholdWSP:
    """Slip against the fastest wheel: hold above 8 %, vent above 15 %, apply below 4 %."""

    period = 0.01  # s

    def reset(self, n_axles, wheel_radius):
        self.radius = wheel_radius
        self.valves = np.full(n_axles, APPLY)

    def __call__(self, time, wheel_speeds, pressure_command):
        speeds = np.asarray(wheel_speeds) * self.radius
        reference = max(speeds.max(), 0.1)
        slip = (reference - speeds) / reference
        self.valves = np.where(slip > 0.15, VENT,
                               np.where(slip > 0.08, HOLD,
                                        np.where(slip < 0.04, APPLY, self.valves)))
        return self.valves


CASES = ["mu050-040-noisy", "mu050-120-bogie-noisy", "step020-080-fall",
         "wilac25-section-160"]
folder = Path(tempfile.mkdtemp())
results = {}
for label, controller in [("default WSP", "default"), ("threshold WSP", ThresholdWSP())]:
    results[label] = run_wsp_programme("default", controller, cases=CASES,
                                       out=folder / label.split()[0], figures=False,
                                       histories=True)
    frame = results[label].frame()
    print(f"{label}: {results[label].overall['passed']} of {len(CASES)} cases passed")
    print(frame[["name", "stopping_distance_m", "distance_ratio", "longest_lock_s",
                 "mean_creep", "vented_air_l", "passed"]].round(3).to_string(index=False))
    print()

# %%
# The summary: each case's stop over the adhesion-limited one, and its longest wheel lock
# (the programme's limit is 1 s). A locked wheel on a constant low adhesion still gives the
# full friction, so the naive controller's stops are not longer there: only the locks show
# what happened to the wheels. On the damp section, where the adhesion falls with the creep,
# the locks cost distance.
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 6), sharex=True, layout="constrained")
x = np.arange(len(CASES))
for k, (label, res) in enumerate(results.items()):
    f = res.frame().set_index("name").loc[CASES]
    ax1.bar(x + (k - 0.5) * 0.38, f["distance_ratio"], 0.38, label=label)
    ax2.bar(x + (k - 0.5) * 0.38, f["longest_lock_s"], 0.38, label=label)
ax1.axhline(1.0, color="k", lw=0.8)
ax1.set_ylabel("stop / adhesion-limited stop")
ax1.set_ylim(0.9, None)
ax1.legend()
ax2.axhline(1.0, color="k", lw=0.8, ls="--", label="limit")
ax2.set_ylabel("longest lock [s]")
ax2.set_xticks(x, CASES, rotation=15)
for ax in (ax1, ax2):
    ax.grid(alpha=0.3, axis="y")

# %%
# One stop in detail: 160 km/h through 850 m of damp rail (25 µl/s of water, WILAC). The
# naive controller takes the fastest wheel as the train speed; when every axle slides at
# once that reference sinks with the wheels, the slip looks small, the brake stays applied
# and the wheels lock. The default controller limits how fast its reference may fall (the
# deceleration the measured brake pressures can give) and releases an axle on purpose to
# find the train speed again. The bench wrote each stop's histories to Parquet
# (``histories=True``); the figures it draws itself (``figures=True``) show every axle.
fig, axes = plt.subplots(2, 1, figsize=(7.5, 6), sharex=True, layout="constrained")
for ax, label in zip(axes, results, strict=True):
    h = pd.read_parquet(folder / label.split()[0] / "histories" / "wilac25-section-160.parquet")
    radius = 0.46  # the coach's wheel radius [m]
    ax.plot(h["time"], h["train_speed"] * 3.6, "k", lw=2, label="train")
    for i in (1, 4):
        ax.plot(h["time"], h[f"wheel_speed_{i}"] * radius * 3.6, lw=0.8, label=f"axle {i}")
    ax.set_ylabel("speed [km/h]")
    ax.set_title(label, fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
axes[-1].set_xlabel("time [s]")
shutil.rmtree(folder)
