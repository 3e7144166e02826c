"""
Odometry on a sliding stop: the estimate and its interval
=========================================================

The odometry bench (:func:`railadhesion.braking.run_odometry_programme`,
``railadhesion odometry-test``) runs an odometry through low-adhesion runs of the braking
simulator and checks, above all, that the true position stays inside the odometry's interval
at every sample. Here the reference odometry shipped with the package runs one case of the
shipped programme: an emergency stop from 80 km/h with every axle sliding (μ = 0.03, the
default WSP in the loop), read from axles 1 and 4 (80-tooth encoders, wheel diameters ±1 %)
in four sensor fits: the wheels alone, with a radar, with an accelerometer, with both. The
guide :doc:`/guides/odometry` tests an odometry of one's own; :doc:`/odometry` describes the
bench and the reference odometry.
"""

import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

from railadhesion.braking import run_odometry_programme

folder = Path(tempfile.mkdtemp())
result = run_odometry_programme("default", "reference", cases=["mu030-080"], out=folder,
                                figures=False, histories=True)
frame = result.frame()
print(frame[["fit", "stop_error_m", "stop_error_fraction", "interval_below_at_stop_m",
             "interval_above_at_stop_m", "inside", "speed_error_max_m_s"]]
      .round(4).to_string(index=False))
print(f"stop: {frame['stopping_distance_m'].iloc[0]:.0f} m; the odometry axles slid "
      f"(creepage above 2 %) for {frame['slide_time_s'].iloc[0]:.1f} s")
h = pd.read_parquet(folder / "histories" / "mu030-080.parquet")
shutil.rmtree(folder)

# %%
# The speeds, relative to the train's: the WSP releases the brakes again and again and the
# wheels slide in between. From the wheels alone the estimate follows the fastest wheel,
# below the train most of the time (and above it at times: the odometry reads axle 1 1 % too
# fast, axle 4 1 % too slow, their wheel-diameter errors). With the accelerometer the
# estimate is carried through the slides, and corrected when a released wheel rolls again at
# the train speed.
t = h["time"]
v = h["train_speed"]
fig, ax = plt.subplots(figsize=(7.5, 4), layout="constrained")
for axle in (1, 4):
    ax.plot(t, -v * h[f"creep_{axle}"] * 3.6, lw=0.6, label=f"wheel of axle {axle} (true)")
for fit, style in [("wheels", "C2"), ("accelerometer", "C3")]:
    ax.plot(t, (h[f"{fit}:speed"] - v) * 3.6, style, lw=1.2, label=f"estimate, {fit}")
ax.axhline(0.0, color="k", lw=0.8)
ax.set(xlabel="time [s]", ylabel="minus the train speed [km/h]")
ax.legend(fontsize=8)
ax.grid(alpha=0.3)

# %%
# The position error of each fit's estimate and its interval, both around the true position.
# The interval is built from speed bounds that hold whatever the adhesion (under braking no
# wheel runs faster than the train; the accelerometer's bias is bounded): it always holds the
# truth (zero), and it is as wide as the sensors leave it. From the wheels alone nothing
# bounds the speed from above but physics, so the upper side grows with the time.
fig, axes = plt.subplots(2, 2, figsize=(8, 6), sharex=True, layout="constrained")
for ax, fit in zip(axes.flat, ["wheels", "radar", "accelerometer", "radar+accelerometer"],
                   strict=True):
    truth = h["distance"]
    ax.fill_between(t, h[f"{fit}:distance_min"] - truth, h[f"{fit}:distance_max"] - truth,
                    color="C0", alpha=0.25, lw=0, label="interval")
    ax.plot(t, h[f"{fit}:distance"] - truth, "C0", lw=1, label="estimate")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_title(fit, fontsize=10)
    ax.grid(alpha=0.3)
for ax in axes[:, 0]:
    ax.set_ylabel("minus the true position [m]")
for ax in axes[1]:
    ax.set_xlabel("time [s]")
axes[0, 0].legend(fontsize=8, loc="upper left")
