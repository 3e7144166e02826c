"""
A sweep on Dask: peak adhesion over water flow, speed and load
==============================================================

:func:`railadhesion.sweeps.run_sweep` evaluates a model over a labelled grid, chunk by
chunk, as Dask tasks; the result is an :class:`xarray.Dataset` with units and provenance. It
has no scheduler of its own: here a small ``distributed`` cluster in this process (two
workers of one thread each); ``client=`` takes any cluster, and ``scheduler="tcp://HOST:PORT"``
a remote one. Given ``out="map.zarr"`` it writes a resumable Zarr store instead of keeping the
map in memory (see :doc:`/sweeps`).
"""

import matplotlib.pyplot as plt
import numpy as np
from dask.distributed import Client, LocalCluster

from railadhesion.sweeps import WilacSweep, max_adhesion, run_sweep

grid = {
    "creep_long": np.geomspace(2e-3, 0.6, 30),  # braking creepage, fraction
    "water_flow": np.linspace(0.0, 80.0, 33),  # µl/s
    "speed": [5.0, 10.0, 20.0],  # m/s
    "normal_force": [3000.0, 6000.0],  # N
}
with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                  dashboard_address=None) as cluster, Client(cluster) as client:
    # chunk_points: about 1500 points per task, so that both workers get work
    result = run_sweep(WilacSweep(geometry="tram"), grid, client=client, chunk_points=1500)
    ds = result.dataset.compute()
    workers = len(client.scheduler_info()["workers"])
print(f"{result.chunks_total} chunks on {workers} workers, {result.elapsed:.2f} s")
print(ds)

# %%
# The peak of every creep curve (maximum over creepage), per flow rate, speed and load.
peak = max_adhesion(ds)
fig, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
for speed in grid["speed"]:
    for load, style in zip(grid["normal_force"], ("-", "--"), strict=True):
        line = peak.adhesion_max.sel(speed=speed, normal_force=load)
        ax.plot(ds.water_flow, line, style, label=f"{speed:g} m/s, {load / 1e3:g} kN")
ax.set_xlabel("water flow rate [µl/s]")
ax.set_ylabel("peak adhesion")
ax.set_title("WILAC, tram-rig geometry: peak of the creep curve")
ax.legend(fontsize=8, ncols=2)
