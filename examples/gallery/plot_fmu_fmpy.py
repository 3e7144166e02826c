"""
A creep-force FMU, run from FMPy
================================

Vehicle-dynamics and HIL tools load FMUs rather than call Python.
:func:`railadhesion.export.build_creep_force_fmu` writes an FMI 2.0 co-simulation FMU of the
WILAC (or Polach) law with its parameter set inside; here `FMPy
<https://github.com/CATIA-Systems/FMPy>`_ runs it as a host would: a braking wheel at 10 %
creep while the water flow on the rail changes every 0.1 s. That FMU is built with pythonfmu:
it runs the library in the host's Python interpreter. Beside it, the **native** FMU of the
same law (:func:`railadhesion.export.build_native_creep_force_fmu`, ``railadhesion export fmu
--native``): the law compiled ahead of time, no Python on the host; it is built only where a
C compiler is found. See :doc:`/fmu` and the guide :doc:`/guides/native-fmu`.
"""

import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from fmpy import read_model_description, simulate_fmu

import railadhesion as ra
from railadhesion.export import build_creep_force_fmu, build_native_creep_force_fmu
from railadhesion.export.native import find_c_compiler

folder = Path(tempfile.mkdtemp())
fmu = build_creep_force_fmu(folder / "creepforce.fmu", "wilac")
md = read_model_description(fmu)
for v in md.modelVariables:
    print(f"{v.causality:9s} {v.name:13s} [{v.unit}]")

# %%
# The inputs as FMPy wants them: a structured array with a time column.
names = [v.name for v in md.modelVariables if v.causality == "input"]
times = np.arange(0.0, 2.01, 0.1)
signal = np.zeros(times.size, dtype=[("time", float)] + [(n, float) for n in names])
signal["time"] = times
signal["creep_long"] = 0.1  # braking, 10 %
signal["normal_force"], signal["speed"] = 110e3, 10.0
contact = ra.hertz_3d(110e3, wheel_radius=0.625, wheel_lateral_radius=np.inf,
                      rail_lateral_radius=0.3)
a, b = float(contact.a), float(contact.b)
signal["a"], signal["b"] = a, b
signal["water_flow"] = np.interp(times, [0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 25.0, 40.0, 350.0, 0.0])
result = simulate_fmu(str(fmu), stop_time=2.0, output_interval=0.1, input=signal,
                      output=["water_flow", "Fx", "adhesion"])

# the FMU is the library: same number as a direct call
direct = ra.Wilac().adhesion(0.1, 0.0, 0.0, 110e3, 10.0, a, b, result["water_flow"])
print(f"largest difference FMU - library: {np.max(abs(result['adhesion'] - direct)):.1e}")

# %%
# The native FMU, under the same FMPy run (FMPy loads its binary like any other; a C or C++
# host does the same without Python, as the guide shows). Same variables, same numbers.
native = None
if find_c_compiler() is None:
    print("no C compiler found (set CC, or install gcc or clang): the native FMU is skipped")
else:
    native_fmu = build_native_creep_force_fmu(folder / "creepforce_native.fmu", "wilac")
    native = simulate_fmu(str(native_fmu), stop_time=2.0, output_interval=0.1, input=signal,
                          output=["water_flow", "Fx", "adhesion"])
    print(f"largest difference native FMU - library: "
          f"{np.max(abs(native['adhesion'] - direct)):.1e}")
shutil.rmtree(folder)

# %%
fig, ax1 = plt.subplots(figsize=(7.5, 4), layout="constrained")
ax1.step(result["time"], result["adhesion"], where="post", lw=3, alpha=0.5,
         label="adhesion, pythonfmu FMU")
if native is not None:
    ax1.step(native["time"], native["adhesion"], "k", where="post", lw=1,
             label="adhesion, native FMU")
ax1.set_xlabel("time [s]")
ax1.set_ylabel("adhesion at 10 % creep")
ax1.legend(loc="upper center", fontsize=8)
ax2 = ax1.twinx()
ax2.step(result["time"], result["water_flow"], "C1--", where="post", label="water flow")
ax2.set_ylabel("water flow [µl/s]", color="C1")
ax1.set_title("WILAC creep-force FMUs under FMPy")
