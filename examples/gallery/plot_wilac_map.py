"""
WILAC adhesion map over water flow and creep
============================================

WILAC (Trummer et al., Tribology International 109, 2017) blends four Polach creep curves,
dry, damp2, damp1 and wet, by the water flow rate on the rail. Its point is that a *little*
water (about 25 µl/s on the tram rig, with wear debris) gives a lower adhesion at large creep
than a flooded rail. This map shows it: adhesion over water flow rate and braking creepage at
the tram rig's contact (4.2 kN, 5 m/s), from the package's default parameter set (our
reconstruction, see :doc:`/wilac-default`).
"""

import matplotlib.pyplot as plt
import numpy as np

import railadhesion as ra

water = np.linspace(0.0, 100.0, 201)  # µl/s
creep = np.geomspace(1e-3, 0.9, 150)  # braking creepage, fraction
a, b = ra.contact_semi_axes("tram", 4200.0)  # Hertz semi-axes of the rig [m]

# Every argument broadcasts: one call evaluates the whole map.
mu = ra.Wilac().adhesion(creep[None, :], 0.0, 0.0, 4200.0, 5.0, a, b, water[:, None])

fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
mesh = ax.pcolormesh(creep * 100, water, mu, shading="auto", cmap="viridis")
lines = ax.contour(creep * 100, water, mu, levels=[0.06, 0.1, 0.15, 0.2, 0.3], colors="w",
                   linewidths=0.8)
ax.clabel(lines, fmt="%.2f", fontsize=8)
ax.set_xscale("log")
ax.set_xlabel("braking creepage [%]")
ax.set_ylabel("water flow rate [µl/s]")
ax.set_title("WILAC adhesion |T|/Q, tram rig 4.2 kN, 5 m/s")
fig.colorbar(mesh, ax=ax, label="adhesion")

# %%
# Where is adhesion lowest? At each creepage, the water flow rate of the minimum:
lowest = water[np.argmin(mu, axis=0)]
for c in (0.03, 0.1, 0.3, 0.6):
    i = np.argmin(abs(creep - c))
    print(f"creep {100 * creep[i]:5.1f} %: minimum {mu[:, i].min():.3f} at {lowest[i]:.1f} µl/s")
