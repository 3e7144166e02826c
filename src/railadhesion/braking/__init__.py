"""Braking under low adhesion: vehicle model, brake cylinders, WSP, simulation, logs.

See ``docs/braking.md``. Sign convention as everywhere in railadhesion (docs/CONVENTIONS.md):
creepage ξ = (V − ωR)/V, braking positive. Axle 1 is the leading axle.
"""

from railadhesion.braking._fields import BrakingFileError
from railadhesion.braking.log import braking_log_frame, write_braking_log
from railadhesion.braking.vehicle import GRAVITY, Vehicle, load_vehicle

__all__ = [
    "GRAVITY",
    "BrakingFileError",
    "Vehicle",
    "braking_log_frame",
    "load_vehicle",
    "write_braking_log",
]
