"""Sweeps at scale with Dask and xarray: adhesion maps over labelled grids.

* :mod:`~railadhesion.sweeps.models`: the library's models as sweep models (WILAC, Polach,
  Fletcher's 2D models) with named inputs, units and provenance.
* :mod:`~railadhesion.sweeps.plan`: a validated grid cut into chunks; pure chunk evaluation
  that records failing points instead of stopping.
* :mod:`~railadhesion.sweeps.run`: execution on Dask's local schedulers or a cluster, into
  memory, NetCDF, or a resumable Zarr store written chunk by chunk.
* :mod:`~railadhesion.sweeps.derived`: maximum adhesion and its creep, adhesion at a creep,
  the water flow rate of minimum adhesion.
* :mod:`~railadhesion.sweeps.spec`: TOML spec files (``railadhesion sweep SPEC.toml``).
* :mod:`~railadhesion.sweeps.study`: braking studies, many stops of the braking simulator over
  a factorial or Monte Carlo design (``railadhesion study SPEC.toml --out DIR``).
"""

from railadhesion.sweeps.derived import adhesion_at_creep, max_adhesion, min_adhesion_water_flow
from railadhesion.sweeps.models import (
    DIMENSIONS,
    SWEEP_MODELS,
    ContactSweep,
    ExactTableSweep,
    FunctionSweep,
    PolachSweep,
    SweepModel,
    TwoDSweep,
    WilacSweep,
    sweep_model,
)
from railadhesion.sweeps.plan import SweepPlan, full_factorial, monte_carlo, plan_sweep
from railadhesion.sweeps.run import (
    SweepResult,
    open_sweep,
    run_sweep,
    sweep_dataset,
    sweep_errors,
)
from railadhesion.sweeps.spec import SpecError, SweepSpec, load_sweep_spec
from railadhesion.sweeps.study import (
    BrakingStudy,
    load_study_spec,
    plot_extension_distribution,
    run_study,
)

__all__ = [
    "BrakingStudy",
    "DIMENSIONS",
    "SWEEP_MODELS",
    "ContactSweep",
    "ExactTableSweep",
    "FunctionSweep",
    "PolachSweep",
    "SweepModel",
    "SweepPlan",
    "SpecError",
    "SweepResult",
    "SweepSpec",
    "TwoDSweep",
    "WilacSweep",
    "adhesion_at_creep",
    "full_factorial",
    "load_study_spec",
    "load_sweep_spec",
    "max_adhesion",
    "min_adhesion_water_flow",
    "monte_carlo",
    "open_sweep",
    "plan_sweep",
    "plot_extension_distribution",
    "run_study",
    "run_sweep",
    "sweep_dataset",
    "sweep_errors",
    "sweep_model",
]
