"""Readers and writers: parameter files (TOML) and measured creep curves (CSV).

The functions most used are importable from here::

    from railadhesion.io import read_creep_curve, load_parameter_file
"""

from railadhesion.io.creepcurves import (
    CreepCurve,
    CreepCurveWarning,
    read_creep_curve,
    read_creep_curves,
    write_creep_curve,
)
from railadhesion.io.paramfiles import (
    ParameterFileError,
    load_parameter_file,
    load_polach_parameters,
    load_wilac_parameters,
    read_provenance,
    save_polach_parameters,
    save_wilac_parameters,
)

__all__ = [
    "CreepCurve",
    "CreepCurveWarning",
    "ParameterFileError",
    "load_parameter_file",
    "load_polach_parameters",
    "load_wilac_parameters",
    "read_creep_curve",
    "read_creep_curves",
    "read_provenance",
    "save_polach_parameters",
    "save_wilac_parameters",
    "write_creep_curve",
]
