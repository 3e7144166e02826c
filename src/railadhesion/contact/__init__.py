"""Contact mechanics: Hertz, Kalker linear theory, FASTSIM, Kalker's exact rolling theory."""

from railadhesion.contact.fastsim import FastsimResult, fastsim
from railadhesion.contact.geometry import NAMED_GEOMETRIES, contact_semi_axes
from railadhesion.contact.hertz import (
    HertzContact,
    LineContact,
    combined_elastic_constants,
    hertz_3d,
    hertz_3d_from_curvatures,
    line_contact,
    line_contact_from_pressure,
)
from railadhesion.contact.kalker import (
    KalkerCoefficients,
    kalker_coefficients,
    linear_creep_forces,
)

# The exact solver and its table model compile with numba: it is imported on first use, so that
# ``import railadhesion`` stays fast and does not import numba.
_LAZY = {
    "ExactResult": "railadhesion.contact.exact",
    "NormalSolution": "railadhesion.contact.exact",
    "exact_rolling": "railadhesion.contact.exact",
    "hertz_curvatures": "railadhesion.contact.exact",
    "normal_influence": "railadhesion.contact.exact",
    "solve_normal": "railadhesion.contact.exact",
    "solve_tangential": "railadhesion.contact.exact",
    "tangential_influence": "railadhesion.contact.exact",
    "exact_table_arrays": "railadhesion.contact.table",
    "exact_table_forces": "railadhesion.contact.table",
    "exact_table_law": "railadhesion.contact.table",
}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'railadhesion.contact' has no attribute {name!r}")


__all__ = [
    "ExactResult",
    "NormalSolution",
    "NAMED_GEOMETRIES",
    "FastsimResult",
    "HertzContact",
    "KalkerCoefficients",
    "LineContact",
    "combined_elastic_constants",
    "exact_rolling",
    "contact_semi_axes",

    "exact_table_arrays",
    "exact_table_forces",
    "exact_table_law",
    "fastsim",
    "hertz_3d",
    "hertz_3d_from_curvatures",
    "hertz_curvatures",
    "kalker_coefficients",
    "line_contact",
    "line_contact_from_pressure",
    "linear_creep_forces",
    "normal_influence",
    "solve_normal",
    "solve_tangential",
    "tangential_influence",
]
