"""Fixtures of the identification tests: the tests' own braking simulator (minisim.py)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import minisim  # noqa: E402


@pytest.fixture(scope="session")
def mini_run():
    """20 s of braking from 30 m/s with WSP cycles, sampled every 2.4 ms (noise-free)."""
    return minisim.simulate(duration=20.0)


@pytest.fixture(scope="session")
def mini_vehicle():
    from railadhesion.braking import Vehicle

    return Vehicle(name="minisim coach", **minisim.VEHICLE)
