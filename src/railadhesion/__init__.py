"""railadhesion: wheel-rail adhesion models, contact mechanics and calibration.

Sign convention and units: see ``docs/CONVENTIONS.md``. In short: SI units; creepage
xi = (V - omega R)/V (braking positive); forces are exerted by the rail on the wheel and
oppose the creepage (Kalker's convention, as in CONTACT).
"""

# The public API at the top level.
from railadhesion.contact import (
    contact_semi_axes,
    fastsim,
    hertz_3d,
    kalker_coefficients,
    line_contact,
    linear_creep_forces,
)
from railadhesion.contact.traction import adhesion
from railadhesion.models import (
    Polach,
    PolachParameters,
    Wilac,
    WilacParameters,
    carter,
    default_wilac_parameters,
    elastic_foundation,
    fletcher,
    fletcher_condition,
    polach_forces,
    polach_parameters,
    wilac_forces,
    wilac_weights,
)

__version__ = "0.1.0"

__all__ = [
    "Polach",
    "PolachParameters",
    "Wilac",
    "WilacParameters",
    "adhesion",
    "carter",
    "contact_semi_axes",
    "default_wilac_parameters",
    "elastic_foundation",
    "fastsim",
    "fletcher",
    "fletcher_condition",
    "hertz_3d",
    "kalker_coefficients",
    "line_contact",
    "linear_creep_forces",
    "polach_forces",
    "polach_parameters",
    "wilac_forces",
    "wilac_weights",
]
