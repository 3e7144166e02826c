"""Contact mechanics: Hertz, Kalker linear theory, FASTSIM, Kalker's exact rolling theory."""

from railadhesion.contact.exact import (
    ExactResult,
    exact_rolling,
    solve_tangential,
    tangential_influence,
)
from railadhesion.contact.fastsim import FastsimResult, fastsim
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
from railadhesion.contact.table import exact_table_forces

__all__ = [
    "ExactResult",
    "FastsimResult",
    "HertzContact",
    "KalkerCoefficients",
    "LineContact",
    "combined_elastic_constants",
    "exact_rolling",
    "exact_table_forces",
    "fastsim",
    "hertz_3d",
    "hertz_3d_from_curvatures",
    "kalker_coefficients",
    "line_contact",
    "line_contact_from_pressure",
    "linear_creep_forces",
    "solve_tangential",
    "tangential_influence",
]
