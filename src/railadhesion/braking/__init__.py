"""Braking under low adhesion: vehicle model, brake cylinders, WSP, simulation, logs.

See ``docs/braking.md``. Sign convention as everywhere in railadhesion (docs/CONVENTIONS.md):
creepage ξ = (V − ωR)/V, braking positive. Axle 1 is the leading axle.
"""

from railadhesion.braking._fields import BrakingFileError
from railadhesion.braking.adhesion import (
    AdhesionRecovery,
    AxleAdhesion,
    CallableAdhesion,
    ContactGeometry,
    ExactTableAdhesion,
    PolachAdhesion,
    WaterFlowProfile,
    WilacAdhesion,
)
from railadhesion.braking.bench import (
    WSPProgrammeResult,
    adhesion_limited_stop,
    load_wsp_programme,
    run_wsp_programme,
)
from railadhesion.braking.cylinders import APPLY, HOLD, VENT, BrakeCylinders
from railadhesion.braking.log import braking_log_frame, write_braking_log
from railadhesion.braking.metrics import slide_metrics
from railadhesion.braking.odometry import OdometrySettings, ReferenceOdometry
from railadhesion.braking.odometry_bench import (
    OdometryProgrammeResult,
    load_odometry_programme,
    run_odometry_programme,
)
from railadhesion.braking.run import BrakeDemand, BrakingResult, simulate
from railadhesion.braking.sensors import (
    AccelerometerSettings,
    EncoderFault,
    EncoderSettings,
    ExternalSpeedSettings,
    SensorModel,
)
from railadhesion.braking.simulator import (
    BrakingSimulator,
    BrakingState,
    SimulationError,
    largest_stable_step,
)
from railadhesion.braking.vehicle import GRAVITY, Vehicle, load_vehicle
from railadhesion.braking.wsp import WheelSlideProtection, WSPSettings

__all__ = [
    "APPLY",
    "HOLD",
    "VENT",
    "GRAVITY",
    "AccelerometerSettings",
    "AdhesionRecovery",
    "AxleAdhesion",
    "ExactTableAdhesion",
    "BrakeCylinders",
    "BrakeDemand",
    "BrakingFileError",
    "BrakingResult",
    "BrakingSimulator",
    "BrakingState",
    "CallableAdhesion",
    "ContactGeometry",
    "EncoderFault",
    "EncoderSettings",
    "ExternalSpeedSettings",
    "OdometryProgrammeResult",
    "OdometrySettings",
    "PolachAdhesion",
    "ReferenceOdometry",
    "SensorModel",
    "SimulationError",
    "WSPProgrammeResult",
    "WSPSettings",
    "WaterFlowProfile",
    "WheelSlideProtection",
    "WilacAdhesion",
    "adhesion_limited_stop",
    "load_odometry_programme",
    "load_wsp_programme",
    "run_odometry_programme",
    "run_wsp_programme",
    "simulate",
    "slide_metrics",
    "Vehicle",
    "braking_log_frame",
    "largest_stable_step",
    "load_vehicle",
    "write_braking_log",
]
