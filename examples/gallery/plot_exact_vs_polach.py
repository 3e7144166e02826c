"""
Exact rolling contact: a traction map beside Polach's creep curve
=================================================================

The package solves Kalker's exact theory of steady rolling (the problem Vollebregt's CONTACT
solves in its default mode) on a grid of elements. Left: the tangential traction over the
contact area of the Eurosprinter wheel (a = 6.3 mm, b = 12.6 mm, 106.7 kN, μ = 0.33) at
ξ = 1.2 ‰, with the stick area at the leading edge and slip behind it. Right: the creep curve
of the exact theory against Polach's closed form with the same friction (k_A = k_S = 1,
constant μ: his 1999 model). Small grids (20 × 20) keep the build fast; the validation page
compares 40 × 40 and CONTACT's own grids.
"""

import matplotlib.pyplot as plt
import numpy as np

import railadhesion as ra
from railadhesion.contact import exact_rolling

a, b, load, mu = 6.304e-3, 12.61e-3, 106.7e3, 0.33
res = exact_rolling(1.2e-3, 0.0, 0.0, load, a, b, mu, nx=20, ny=20, return_fields=True)

creep = np.linspace(0.0, 3.2e-3, 9)[1:]
exact = exact_rolling(creep, 0.0, 0.0, load, a, b, mu, nx=20, ny=20)
polach, _ = ra.polach_forces(creep, 0.0, 0.0, load, 10.0, a, b, mu0=mu, k_A=1.0, k_S=1.0,
                             A=1.0, B=0.0)
for c, fe, fp in zip(creep, exact.fx, polach, strict=True):
    print(f"creep {1e3 * c:.1f} per mille: exact {fe / (mu * load):+.4f}, "
          f"Polach {fp / (mu * load):+.4f} (Fx / mu Q)")

# %%
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 4), layout="constrained")
traction = np.hypot(res.px, res.py) / 1e6
traction[res.state == 0] = np.nan
mesh = ax1.pcolormesh(res.x * 1e3, res.y * 1e3, traction, shading="nearest", cmap="magma")
ax1.contour(res.x * 1e3, res.y * 1e3, res.state, levels=[1.5], colors="c", linewidths=1.2)
ax1.set_aspect("equal")
ax1.set_xlabel("x, rolling direction [mm] (leading edge right)")
ax1.set_ylabel("y [mm]")
ax1.set_title("|traction| [MPa]; cyan: stick/slip boundary")
fig.colorbar(mesh, ax=ax1, shrink=0.8)

ax2.plot(creep * 1e3, -exact.fx / (mu * load), "o-", label="exact theory, 20 × 20")
ax2.plot(creep * 1e3, -polach / (mu * load), "s--", label="Polach (1999)")
ax2.set_xlabel("braking creepage ξ [‰]")
ax2.set_ylabel("−Fx / (μ Q)")
ax2.legend()
