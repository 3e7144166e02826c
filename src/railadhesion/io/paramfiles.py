"""Parameter files: versioned, human-editable TOML for WILAC and Polach parameter sets.

The public path of the reader and writer documented in ``docs/parameter-files.md``. They live
in ``railadhesion.models.paramfiles``, below the models, because the WILAC model reads its
default set with them; this module re-exports the same objects (its ``__all__``).
"""

from __future__ import annotations

from railadhesion.models.paramfiles import *  # noqa: F403 - the same objects
from railadhesion.models.paramfiles import __all__  # noqa: F401 - and the same names
