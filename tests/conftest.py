"""Test configuration.

Hypothesis explores new random examples on every local run (to find bugs); under CI (the CI
environment variable is set by `.ci/run`'s runner) it is derandomised so that a landing
never depends on luck. Run `CI=true python3 -m pytest` to reproduce CI exactly.
"""

import os
import sys
from pathlib import Path

from hypothesis import settings

settings.register_profile("ci", derandomize=True, database=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

# The CLI's messages are printed by rich, which wraps them at 80 columns when the output is not
# a terminal: a long temporary path (pytest-xdist's per-worker directories) would then split a
# file name that a test looks for. Tests read them unwrapped.
os.environ.setdefault("COLUMNS", "250")

# the independent oracles of the compiled laws (tests/oracles) import as ``oracles``
sys.path.insert(0, str(Path(__file__).parent))
