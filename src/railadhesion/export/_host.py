"""Work-around, run inside a Python host, for a crash of pythonfmu's binary at process exit.

pythonfmu's FMU binary (0.6.x-0.7.x, Linux) keeps its interpreter state in a static
``std::shared_ptr`` and resets it again from a library destructor (``finalizePythonInterpreter``,
``__attribute__((destructor))``). At process exit the C++ static destructor runs first and frees
the shared state; the library destructor then reads and decrements the freed reference count
(valgrind: "Invalid read of size 4 in finalizePythonInterpreter ... inside a block of size 128
free'd"). Depending on what the freed memory holds, that ends in a double free and the process
aborts *after* it finished its work (``corrupted double-linked list``, exit status 134; measured
here: 1 run in 8-15 of ``benchmarks/bench_export.py``). Reported upstream as PythonFMU issue
#229.

The work-around: when a slave of ours is instantiated in a process whose interpreter was started
by Python itself (an FMPy or PyFMI host), register an ``atexit`` hook that calls the library's
exported ``finalizePythonInterpreter`` while everything is still alive. It releases the shared
state once, cleanly; the static destructor and the library destructor then find an empty pointer
and do nothing. Hosts that are not Python (the binary started the interpreter itself, and stops
it from its own thread) are left alone.
"""

from __future__ import annotations

import atexit
import ctypes
import os
import sys
from pathlib import Path

_registered: set[str] = set()


def _started_by_python() -> bool:
    """True when this interpreter was started by a Python executable (``python3 ...``), not
    embedded by the FMU's binary (which calls ``Py_Initialize`` with no command line)."""
    return bool(getattr(sys, "orig_argv", None))


def _release(library: str) -> None:
    try:  # only if the library is still loaded: RTLD_NOLOAD never loads it again
        lib = ctypes.CDLL(library, mode=os.RTLD_NOLOAD | os.RTLD_LAZY)
    except OSError:
        return
    release = getattr(lib, "finalizePythonInterpreter", None)
    if release is not None:
        release.restype = None
        release.argtypes = []
        release()


def release_pythonfmu_state_at_exit(resources: str | os.PathLike) -> list[str]:
    """Register the exit hook for the pythonfmu binaries of the FMU whose ``resources`` folder
    is given (once per binary); returns the binaries registered by this call.

    A no-op except on Linux in a Python host (see the module docstring)."""
    if not sys.platform.startswith("linux") or not _started_by_python():
        return []
    added = []
    for library in sorted((Path(resources).parent / "binaries" / "linux64").glob("*.so")):
        key = str(library.resolve())
        if key not in _registered:
            _registered.add(key)
            atexit.register(_release, key)
            added.append(key)
    return added
