"""Fixtures of the monitor's tests: synthetic signals with an exact truth (monitor_signals.py)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import monitor_signals  # noqa: E402


@pytest.fixture(scope="session")
def low_run():
    """14 s: coasting 2.5 s (radii learned; wheel diameters off by up to 0.5 %), then light
    braking with a varying demand (adhesion in use 0.045 +- 25 %) on a Polach-shaped curve of
    friction 0.07 (available 0.07 < 0.14: low)."""
    return monitor_signals.make_signals(
        monitor_signals.braking_profile(level=0.045), duration=14.0, shape="polach", slope=40.0,
        mu=0.07, radius_error=[0.004, -0.003, 0.002, -0.005], seed=1)


@pytest.fixture(scope="session")
def low_levels(low_run):
    """What the monitor says on ``low_run``, sample by sample."""
    from railadhesion.monitor import AdhesionMonitor

    return monitor_signals.feed(AdhesionMonitor("coach_default"), low_run)
