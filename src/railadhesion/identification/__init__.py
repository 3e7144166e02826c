"""Adhesion from measurements.

- :mod:`railadhesion.identification.detection`: low-adhesion detection from creep-force data
  at low creep (Fletcher 2013).
"""

from railadhesion.identification.detection import (
    RSSB_BRAKING_ADHESION,
    DetectionResult,
    detect_low_adhesion,
    fletcher_detection_study,
)

__all__ = [
    "RSSB_BRAKING_ADHESION",
    "DetectionResult",
    "detect_low_adhesion",
    "fletcher_detection_study",
]
