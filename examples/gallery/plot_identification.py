"""
Adhesion identified from a braking-test log
===========================================

Allotta, Malvezzi and Toni identify the adhesion coefficient from the channels a test train
records (train speed, wheelset angular speeds, brake-cylinder pressures, every 2.4 ms). Here
the log comes from the package's own braking simulator on a low-adhesion rail (a Polach set
with μ0 = 0.13 and falling friction), written with sensor noise; the identification recovers
the brake coefficient, μ of every axle at every sample, and a fitted law μ(slip). The test
suite closes the same loop and checks the identified law against the simulated one (RMS
difference 0.0033 in μ, :doc:`/validation`).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from railadhesion.braking import PolachAdhesion, Vehicle, simulate, write_braking_log
from railadhesion.identification import fit_adhesion_curves, identify_adhesion, read_braking_log
from railadhesion.models import PolachParameters

vehicle = Vehicle(name="coach")
low = PolachParameters(k_A=0.3, k_S=0.1, mu0=0.13, A=0.4, B=0.3, name="low adhesion")
result = simulate(vehicle, PolachAdhesion(low), 30.0, brake=3.8e5, wsp=True, dt=2.5e-3,
                  max_time=10.0)

# the test train's log: 2.4 ms samples, noise 0.01 m/s, 0.02 rad/s, 0.01 bar
log_path = Path(tempfile.mkdtemp()) / "braking_log.csv"
write_braking_log(result, log_path, period=2.4e-3, seed=11,
                  noise={"train_speed": 0.01, "wheel_speed": 0.02, "brake_pressure": 0.01})

# %%
# Identify: read the log (every defect would be reported), then c, μ per axle and sample.
log = read_braking_log(log_path)
ident = identify_adhesion(log, vehicle)
error = ident.brake.mean / vehicle.brake_coefficient - 1
print(f"brake coefficient: identified {ident.brake.mean:.6f} N m/Pa, "
      f"true {vehicle.brake_coefficient:.6f} ({100 * error:+.3f} %)")
print(f"{ident.use.sum()} usable samples on {ident.use.shape[1]} axles")
law = fit_adhesion_curves(ident)  # mu(slip) per speed band and over all speeds

# %%
# The samples (every 20th), the fitted law at 25 m/s and the simulated (true) law there.
rows, axles = np.nonzero(ident.use)
slip = ident.slip[rows, axles]
mu = ident.mu[rows, axles]
grid = np.linspace(0.01, slip.max(), 200)
fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
ax.plot(slip[::20], mu[::20], ".", ms=2, alpha=0.3, label="identified μ (samples)")
ax.plot(grid, law.of_slip(grid, np.full_like(grid, 25.0)), "k", label="fitted law at 25 m/s")
ax.set_xlabel("absolute slip v − ωR [m/s]")
ax.set_ylabel("adhesion μ")
ax.set_ylim(0, 0.2)
ax.legend()
