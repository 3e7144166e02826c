"""Use the models from other tools: FMI 2.0 co-simulation FMUs and creep-force tables.

* :func:`build_creep_force_fmu`: a WILAC or Polach creep-force law as an FMU (pythonfmu);
* :func:`build_native_creep_force_fmu`: the same law as a native FMU, compiled ahead of time
  (no Python at run time; :mod:`railadhesion.export.native` builds any step model so);
* :func:`build_braking_fmu`: the braking simulator's stepping API as an FMU (inputs: commanded
  pressure and WSP valve per axle, or with the built-in WSP the pressure only);
  :func:`build_native_braking_fmu`: the same, native (no Python at run time);
* :func:`build_monitor_fmu`: the on-board adhesion monitor as an FMU (inputs: speed
  reference, wheel speeds, pressures and/or torques; outputs: estimates, levels, reasons);
  :func:`build_native_monitor_fmu`: the same, native (no Python at run time);
* :func:`creep_force_table`: a model evaluated on a grid, written as NetCDF
  (:func:`write_table_netcdf`) and as a plain CSV (:func:`write_table_csv`), with the error
  of multilinear interpolation in the table measured at the cell midpoints.

See ``docs/fmu.md``, ``docs/creep-force-tables.md`` and the guide
``docs/guides/multibody.md``.
"""

from railadhesion.export.braking_fmu import braking_fmu_variables, build_braking_fmu
from railadhesion.export.fmu import (
    FMU_MODELS,
    FmuVariable,
    build_creep_force_fmu,
    build_fmu,
    creep_force_variables,
    resolve_parameters,
)
from railadhesion.export.monitor_fmu import (
    build_monitor_fmu,
    build_native_monitor_fmu,
    monitor_fmu_variables,
    monitor_step_model,
)
from railadhesion.export.native import NativeBuildError, NativeUnsupported
from railadhesion.export.native_braking import build_native_braking_fmu
from railadhesion.export.native_creepforce import build_native_creep_force_fmu
from railadhesion.export.tables import (
    DEFAULT_GRID,
    InterpolationError,
    creep_force_table,
    interpolation_error,
    read_table_csv,
    write_table_csv,
    write_table_netcdf,
)

__all__ = [
    "DEFAULT_GRID",
    "FMU_MODELS",
    "FmuVariable",
    "InterpolationError",
    "NativeBuildError",
    "NativeUnsupported",
    "braking_fmu_variables",
    "build_braking_fmu",
    "build_creep_force_fmu",
    "build_fmu",
    "build_monitor_fmu",
    "build_native_creep_force_fmu",
    "build_native_braking_fmu",
    "build_native_monitor_fmu",
    "creep_force_table",
    "creep_force_variables",
    "interpolation_error",
    "monitor_fmu_variables",
    "monitor_step_model",
    "read_table_csv",
    "resolve_parameters",
    "write_table_csv",
    "write_table_netcdf",
]
