"""Adhesion from measurements (``docs/identification.md``).

- Identification from braking-test logs (Allotta, Malvezzi and Toni, seed 002):
  :func:`read_braking_log` (defects reported), :func:`identify_adhesion` (filters, brake
  coefficient eq. 14, loads eqs. 11-13, mu eq. 10, windows), :func:`adhesion_surface` (the
  40 x 40 surface), :func:`fit_adhesion_curves` (mu(slip) per speed band, saved as an adhesion
  law the braking simulator can use, :func:`load_adhesion_law`).
- Low-adhesion detection from creep-force data at low creep (Fletcher 2013):
  :func:`detect_low_adhesion`.
"""

from railadhesion.identification.brake_tests import (
    BrakeCoefficient,
    BrakingIdentification,
    brake_coefficient,
    identify_adhesion,
)
from railadhesion.identification.curves import (
    AdhesionLaw,
    CurveFit,
    falling_adhesion,
    fit_adhesion_curves,
    load_adhesion_law,
)
from railadhesion.identification.detection import (
    RSSB_BRAKING_ADHESION,
    DetectionResult,
    detect_low_adhesion,
    fletcher_detection_study,
)
from railadhesion.identification.logs import (
    BrakingLog,
    BrakingLogWarning,
    LogIssue,
    braking_log_from_frame,
    read_braking_log,
)
from railadhesion.identification.surface import adhesion_surface, save_surface, surface_section

__all__ = [
    "RSSB_BRAKING_ADHESION",
    "AdhesionLaw",
    "BrakeCoefficient",
    "BrakingIdentification",
    "BrakingLog",
    "BrakingLogWarning",
    "CurveFit",
    "DetectionResult",
    "LogIssue",
    "adhesion_surface",
    "brake_coefficient",
    "braking_log_from_frame",
    "detect_low_adhesion",
    "falling_adhesion",
    "fit_adhesion_curves",
    "fletcher_detection_study",
    "identify_adhesion",
    "load_adhesion_law",
    "read_braking_log",
    "save_surface",
    "surface_section",
]
