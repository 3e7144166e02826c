"""On-board low-adhesion monitor (issue 21; ``docs/monitor.md``).

Fletcher (2013, seed 001) built his 2D creep model for on-board detection of low adhesion
before braking; Allotta, Malvezzi and Toni (seed 002) identify adhesion from the signals a
train records. :class:`AdhesionMonitor` does both on board, sample by sample and axle by axle:
creepage and adhesion in use (causal seed 002 eqs. 10-14), the available adhesion with its
band from the low-creep part of the curve (a bank of Kalman filters on Fletcher's curve), and
a level ``unknown`` / ``normal`` / ``caution`` / ``low`` against a threshold (0.14, RSSB
GM/GN2642 as quoted by Fletcher) with the time of its last change and the reason.

Three ways in: the per-sample call (:meth:`AdhesionMonitor.update`, :meth:`~AdhesionMonitor.step`
for hardware-in-the-loop rates), the replay of a braking log (:func:`replay_log`, CSV or
Parquet, optional torque columns) and an FMI 2.0 co-simulation FMU
(:func:`railadhesion.export.build_monitor_fmu`); the command ``railadhesion monitor``.
"""

from railadhesion.monitor.estimator import (
    AdhesionMonitor,
    MonitorInputs,
    MonitorOutputs,
    MonitorSnapshot,
)
from railadhesion.monitor.layout import LEVELS, REASONS, reason_label, reason_text
from railadhesion.monitor.replay import MonitorReplay, read_monitor_log, replay_log
from railadhesion.monitor.settings import RSSB_BRAKING_ADHESION, MonitorSettings

__all__ = [
    "LEVELS",
    "REASONS",
    "RSSB_BRAKING_ADHESION",
    "AdhesionMonitor",
    "MonitorInputs",
    "MonitorOutputs",
    "MonitorReplay",
    "MonitorSettings",
    "MonitorSnapshot",
    "read_monitor_log",
    "reason_label",
    "reason_text",
    "replay_log",
]
