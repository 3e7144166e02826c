"""Parameter files: versioned, human-editable TOML for WILAC and Polach parameter sets.

The public path of the reader and writer documented in ``docs/parameter-files.md``. They live
in ``railadhesion.models.paramfiles``, below the models, because the WILAC model reads its
default set with them; this module re-exports the same objects.
"""

from __future__ import annotations

from railadhesion.models.paramfiles import (
    FORMAT_VERSION,
    POLACH_FORMAT,
    WILAC_FORMAT,
    ParameterFileError,
    load_parameter_file,
    load_polach_parameters,
    load_wilac_parameters,
    polach_parameters_to_toml,
    read_provenance,
    save_polach_parameters,
    save_wilac_parameters,
    wilac_parameters_to_toml,
)

__all__ = [
    "FORMAT_VERSION",
    "WILAC_FORMAT",
    "POLACH_FORMAT",
    "ParameterFileError",
    "load_wilac_parameters",
    "save_wilac_parameters",
    "load_polach_parameters",
    "save_polach_parameters",
    "load_parameter_file",
    "read_provenance",
    "wilac_parameters_to_toml",
    "polach_parameters_to_toml",
]
