"""Creep-force models: Polach, WILAC and the 2D twin-disc models (Carter, elastic foundation,
Fletcher). Every model is a function that broadcasts over NumPy arrays; the classes only wrap
them with a parameter set."""

from railadhesion.models.parameters import (
    POLACH_PARAMETER_SETS,
    PolachParameters,
    polach_parameters,
)
from railadhesion.models.polach import Polach, PolachContact, polach_forces
from railadhesion.models.twod import (
    FLETCHER_CONDITIONS,
    FletcherCondition,
    TwoDTraction,
    carter,
    creep_from_surface_speeds,
    elastic_foundation,
    fletcher,
    fletcher_condition,
)
from railadhesion.models.wilac import (
    PAPER_TRANSITIONS,
    WILAC_CONDITIONS,
    WaterTransition,
    Wilac,
    WilacCondition,
    WilacParameters,
    default_wilac_parameters,
    wilac_forces,
    wilac_transitions,
    wilac_weights,
)

__all__ = [
    "FLETCHER_CONDITIONS",
    "PAPER_TRANSITIONS",
    "POLACH_PARAMETER_SETS",
    "WILAC_CONDITIONS",
    "FletcherCondition",
    "Polach",
    "PolachContact",
    "PolachParameters",
    "TwoDTraction",
    "WaterTransition",
    "Wilac",
    "WilacCondition",
    "WilacParameters",
    "carter",
    "creep_from_surface_speeds",
    "default_wilac_parameters",
    "elastic_foundation",
    "fletcher",
    "fletcher_condition",
    "polach_forces",
    "polach_parameters",
    "wilac_forces",
    "wilac_transitions",
    "wilac_weights",
]
