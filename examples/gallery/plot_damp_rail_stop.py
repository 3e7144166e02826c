"""
A stop on a damp rail against the same stop on a dry one
========================================================

A coach (the shipped ``coach_default``: four axles, 45 t) makes an emergency stop from
160 km/h. On the damp rail a patch of 25 µl/s of water lies between 50 m and 900 m; WILAC
gives the adhesion per axle, the default wheel slide protection (WSP) controls the brake
cylinders. The same stop on the dry rail is the reference. This is the scenario of
``examples/brake_damp.toml`` (``railadhesion brake examples/brake_damp.toml --out DIR`` runs
it from the command line); the guide :doc:`/guides/damp-rail-stop` explains the steps.
"""

import matplotlib.pyplot as plt

from railadhesion.braking import (
    BrakeCylinders,
    WaterFlowProfile,
    WheelSlideProtection,
    WilacAdhesion,
    load_vehicle,
    simulate,
)

coach = load_vehicle("coach_default")
rails = {
    "dry": WilacAdhesion(0.0),
    "damp, 50-900 m": WilacAdhesion(WaterFlowProfile.sections([(50.0, 900.0, 25.0)])),
}
results = {}
for name, adhesion in rails.items():
    results[name] = simulate(coach, adhesion, 160 / 3.6, 5.5e5,
                             cylinders=BrakeCylinders(max_pressure=6e5),
                             wsp=WheelSlideProtection())
    r = results[name]
    print(f"{name:15s} stopping distance {r.stopping_distance:6.1f} m, "
          f"time {r.summary['stopping_time_s']:5.1f} s, "
          f"WSP vent actions {r.summary['vent_actions']}")

extension = results["damp, 50-900 m"].stopping_distance - results["dry"].stopping_distance
print(f"extension on the damp rail: {extension:.1f} m "
      f"({100 * extension / results['dry'].stopping_distance:.1f} %)")

# %%
# Speed over distance, and the first axle's wheel speed where WSP releases the brake.
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 6), sharex=True, layout="constrained")
for name, r in results.items():
    h = r.histories
    ax1.plot(h["distance"], h["train_speed"] * 3.6, label=name)
    ax2.plot(h["distance"], h["creep_1"], label=name)
ax1.axvspan(50, 900, color="tab:blue", alpha=0.08, label="25 µl/s")
ax1.set_ylabel("train speed [km/h]")
ax1.legend()
ax2.set_ylabel("creepage of axle 1")
ax2.set_xlabel("distance [m]")
