"""Helpers for the numba kernels (imported only by the kernel modules: importing it does not
import numba until :func:`serial_and_parallel` is called)."""

from __future__ import annotations

import types

__all__ = ["serial_and_parallel", "kernel_entry"]


def _renamed(py_func, suffix: str):
    """A copy of ``py_func`` (same code, globals and defaults) named ``<name><suffix>``."""
    func = types.FunctionType(py_func.__code__, py_func.__globals__, py_func.__name__ + suffix,
                              py_func.__defaults__, py_func.__closure__)  # fmt: skip
    func.__qualname__ = py_func.__qualname__ + suffix
    func.__module__ = py_func.__module__
    func.__doc__ = py_func.__doc__
    return func


def serial_and_parallel(py_func, **flags):
    """(parallel, serial) ``@njit(cache=True)`` compilations of one Python function.

    numba's on-disk cache is keyed by the function's qualified name, its line and the
    signature, not by the compile flags: two dispatchers of the same function, one with
    ``parallel=True`` and one without, would share one cache entry, and whichever compiled
    first would be loaded by both (a "parallel" kernel then runs serially, or the reverse).
    Each twin is therefore compiled from a renamed copy (``<name>_par``, ``<name>_ser``),
    which gives it a cache file of its own.
    """
    from numba import njit

    par = njit(cache=True, parallel=True, **flags)(_renamed(py_func, "_par"))
    ser = njit(cache=True, **flags)(_renamed(py_func, "_ser"))
    return par, ser


# numba keys a cached kernel on its own source file only. A kernel that calls (and inlines)
# njit helpers of another module keeps its cached machine code when that module changes; the
# guard below compiles a checksum of those modules' sources into a tiny cached function of the
# guarded module and, when the cached checksum differs from the current one, deletes every
# cache file of the guarded module so that its kernels compile afresh.


def source_checksum(*modules) -> int:
    """CRC-32 of the source files of ``modules`` (module objects), in the order given."""
    import zlib
    from pathlib import Path

    crc = 0
    for module in modules:
        crc = zlib.crc32(Path(module.__file__).read_bytes(), crc)
    return crc


def purge_module_cache(cache_dir, module_stem: str, compiled: int, current: int) -> list:
    """Delete the numba cache files of module ``module_stem`` (``<stem>.*.nbi``/``.nbc``) in
    ``cache_dir`` if ``compiled`` (the checksum the cached code was built with) differs from
    ``current``; return the deleted paths."""
    from pathlib import Path

    if compiled == current:
        return []
    gone = []
    for path in Path(cache_dir).glob(f"{module_stem}.*.nb[ic]"):
        path.unlink(missing_ok=True)
        gone.append(path)
    return gone


def guard_cache(fingerprint_dispatcher, module_file: str, current: int) -> list:
    """Run the guard: ``fingerprint_dispatcher`` is an ``@njit(cache=True)`` function of the
    guarded module (``module_file``) returning the checksum global it was compiled with."""
    from pathlib import Path

    cache_dir = fingerprint_dispatcher._cache._cache_path
    gone = purge_module_cache(cache_dir, Path(module_file).stem, fingerprint_dispatcher(), current)
    if gone:
        fingerprint_dispatcher.recompile()
    return gone


def kernel_entry(dispatcher, args):
    """The compiled entry point of the numba ``dispatcher`` for the types of ``args``: calling
    it skips the dispatcher's type resolution (a few hundred ns a call). ``args`` must make a
    call without harm (it compiles the kernel, or loads it from the cache); falls back to the
    dispatcher if numba's internals do not give the entry point."""
    dispatcher(*args)
    try:
        from numba import typeof

        entry = dispatcher.overloads[tuple(typeof(a) for a in args)].entry_point
    except Exception:  # pragma: no cover - numba internals changed: use the dispatcher
        entry = None
    return entry if callable(entry) else dispatcher
