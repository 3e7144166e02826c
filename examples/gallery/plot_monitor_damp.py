"""
The on-board adhesion monitor on a damp section
===============================================

:class:`railadhesion.monitor.AdhesionMonitor` reads what a train measures — the wheel
speeds, a speed reference and the brake-cylinder pressures — sample by sample, and says per
axle how much adhesion is available (an estimate with a band), and a level (``unknown``,
``normal``, ``caution``, ``low`` against 0.14) with its reason. Here it rides along a
simulated coach, fed every 2.4 ms as on a train or a hardware-in-the-loop rig: the coach
coasts at 40 m/s (the monitor learns the wheel radii), brakes lightly on a dry rail, then runs
over 240 m of damp rail (25 µl/s of water, WILAC). The brake demand varies a little (±25 %),
as service braking does: a steady force shows one point of the creep curve only, and one
point cannot show where the curve bends. The sensors have the noise of issue 21 and wheel
diameters off by ±0.5 %. :doc:`/monitor` describes the estimator and its limits; the guide
:doc:`/guides/adhesion-monitor` replays a recorded log.
"""

import matplotlib.pyplot as plt
import numpy as np

from railadhesion.braking import BrakingSimulator, WaterFlowProfile, WilacAdhesion, load_vehicle
from railadhesion.monitor import LEVELS, AdhesionMonitor, reason_text

coach = load_vehicle("coach_default")
n = coach.n_axles
damp = (280.0, 520.0)  # m along the track
sim = BrakingSimulator(coach, WilacAdhesion(WaterFlowProfile.sections([(*damp, 25.0)])), 40.0,
                       record=False)
monitor = AdhesionMonitor(coach)  # pressures on every axle, threshold 0.14
period = monitor.settings.sample_period

rng = np.random.default_rng(3)
diameter_error = np.array([0.005, -0.005, 0.005, -0.005])  # what the monitor must learn
phases = rng.uniform(0.0, 2.0 * np.pi, 3)


def brake_demand(t):
    """3.3 bar from t = 3 s (ramped over 1 s), varying by up to +-25 %."""
    if t < 3.0:
        return 0.0
    m = np.mean(np.sin(2.0 * np.pi * np.array([0.37, 0.61, 0.97]) * t + phases))
    return 3.3e5 * min(1.0, t - 3.0) * (1.0 + 0.25 * m)


live, out = sim.live, monitor.live
rows = []
for k in range(int(16.0 / period)):
    t = (k + 1) * period
    sim.inputs.pressure_command[:] = brake_demand(t)
    sim.advance(period)
    speed = live.train_speed + 0.01 * rng.standard_normal()               # m/s
    wheels = live.wheel_speeds * (1 + diameter_error) + 0.02 * rng.standard_normal(n)
    pressures = live.brake_pressures + 1e3 * rng.standard_normal(n)        # Pa
    monitor.update(t, speed, wheels, pressures)
    if k % 40 == 0:
        truth = sim.adhesion_available()                                   # the peaks
    rows.append((t, live.distance, out.level[0], out.reason[0], out.reason_v1[0],
                 out.reason_v2[0], out.estimate[0], out.lower[0], out.upper[0],
                 out.adhesion_used[0], truth[0]))
t, x, level, reason, v1, v2, estimate, lower, upper, used, truth = np.array(rows).T

# %%
# What axle 1 said, and why: every change of its level or reason.
last = None
for k in range(t.size):
    if (level[k], reason[k]) != last:
        last = (level[k], reason[k])
        print(f"{t[k]:5.2f} s {x[k]:5.0f} m  {LEVELS[int(level[k])]:8s} "
              f"{reason_text(reason[k], v1[k], v2[k])}")
on_damp = (x > damp[0] + 100) & (x < damp[1])
print(f"on the damp rail: available adhesion {np.nanmean(truth[on_damp]):.3f} (truth), "
      f"estimate {np.nanmedian(estimate[on_damp]):.3f}")

# %%
# Along the track: the adhesion axle 1 uses, the monitor's estimate of the available adhesion
# with its band, and the truth (the peak of the axle's creep curve in the simulator). On the
# damp rail the peak falls to about 0.18: above the threshold of 0.14 that a normal brake
# needs, so this damp rail is not "low" for this coach, and the band, which straddles the
# threshold, gives ``caution``, not a false ``low``.
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True, height_ratios=[4, 1],
                               layout="constrained")
finite_upper = np.where(np.isfinite(upper), upper, np.nan)
ax1.fill_between(x, lower, finite_upper, color="C0", alpha=0.25, lw=0, label="band")
ax1.plot(x, estimate, "C0", lw=1, label="estimate")
ax1.plot(x, truth, "k", lw=1.5, label="available (truth)")
ax1.plot(x, used, "C2", lw=0.8, label="in use")
ax1.axhline(monitor.settings.threshold, color="C3", ls="--", lw=1, label="threshold")
ax1.axvspan(*damp, color="0.92", lw=0, zorder=0, label="damp rail")
ax1.set(ylabel="adhesion, axle 1", ylim=(0.0, 0.65))
ax1.legend(fontsize=8, ncol=3, loc="upper right")
ax1.grid(alpha=0.3)
colors = {"unknown": "0.8", "normal": "tab:green", "caution": "tab:orange", "low": "tab:red"}
for code, name in enumerate(LEVELS):
    ax2.fill_between(x, 0, 1, where=level == code, step="post", color=colors[name], lw=0,
                     label=name)
ax2.set(xlabel="distance [m]", yticks=[], ylabel="level")
ax2.legend(fontsize=8, ncol=4, loc="upper left")
